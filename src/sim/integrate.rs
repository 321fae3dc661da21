//! Time integrators. Each advances a [`State`] by one step of a [`Model`].
//!
//! - Symplectic (semi-implicit) Euler: explicit, the paper's style; cheap per step, stable
//!   only below a CFL-like limit set by the stiffest membrane wave and bending mode.
//! - Implicit Euler: each step minimises the incremental potential
//!   Φ(y) = Σ m/(2h²)|y − x̃|² + Σ ζm/(2h)|y − x_n|² + E(y) by Newton's method with a
//!   block-Jacobi preconditioned conjugate gradient and a backtracking line search on Φ.
//!   Unconditionally stable, strongly damped at large steps.
//! - BDF2: the same minimisation with h = 2Δt/3 and a two-step history; second order, with
//!   far less numerical damping than implicit Euler at the same Δt.
//!
//! A step that produces a non-finite or exploding state is rejected: the state is left as
//! it was and the error names the integrator, Δt and time.

use crate::sim::contact::{ContactModel, ContactStats, StepContacts};
use crate::sim::model::{CompressedEdges, Model};
use crate::sim::multigrid::Multigrid;
use crate::sim::direct::{DirectFactor, DirectPattern};
use crate::sim::sparse::{BlockCsr, CgReport, Preconditioner, SystemMatrix, pcg};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::sync::Arc;
use std::time::Instant;
use thiserror::Error;

/// Positions and velocities at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Positions, m.
    pub x: Vec<DVec3>,
    /// Velocities, m/s.
    pub v: Vec<DVec3>,
    /// Simulated time, s.
    pub time: f64,
    /// Steps taken.
    pub steps: u64,
    /// Previous positions and velocities (for BDF2), cleared when the history is invalid.
    previous: Option<(Vec<DVec3>, Vec<DVec3>)>,
}

impl State {
    pub fn at_rest(x: Vec<DVec3>) -> Self {
        let v = vec![DVec3::ZERO; x.len()];
        Self { x, v, time: 0.0, steps: 0, previous: None }
    }

    /// Kinetic energy, J.
    pub fn kinetic_energy(&self, model: &Model) -> f64 {
        self.v.iter().zip(&model.mass).map(|(v, m)| 0.5 * m * v.length_squared()).sum()
    }

    /// Total linear momentum, kg·m/s.
    pub fn momentum(&self, model: &Model) -> DVec3 {
        self.v.iter().zip(&model.mass).map(|(v, m)| *m * *v).sum()
    }

    /// Total angular momentum about the origin, kg·m²/s.
    pub fn angular_momentum(&self, model: &Model) -> DVec3 {
        self.x.iter().zip(&self.v).zip(&model.mass).map(|((x, v), m)| *m * x.cross(*v)).sum()
    }
}

/// The available integrators; names as typed in presets and on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    SymplecticEuler,
    #[default]
    ImplicitEuler,
    Bdf2,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 3] = [Self::SymplecticEuler, Self::ImplicitEuler, Self::Bdf2];

    pub fn name(self) -> &'static str {
        match self {
            Self::SymplecticEuler => "symplectic-euler",
            Self::ImplicitEuler => "implicit-euler",
            Self::Bdf2 => "bdf2",
        }
    }

    pub fn is_explicit(self) -> bool {
        self == Self::SymplecticEuler
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Newton and conjugate-gradient settings of the implicit integrators.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSettings {
    /// Maximum Newton iterations per step.
    pub max_iterations: usize,
    /// Newton stops when no vertex moves more than this fraction of the mean edge length.
    pub tolerance: f64,
    /// Relative residual at which the conjugate gradient stops.
    pub cg_tolerance: f64,
    /// Maximum conjugate-gradient iterations per Newton iteration.
    pub cg_max_iterations: usize,
    /// Inexact Newton (Eisenstat and Walker's second forcing term): early iterations, far
    /// from the solution, solve their linear systems only to η_k = 0.9(|g_k|/|g_{k−1}|)²
    /// (at most 0.1, at least `cg_tolerance`) instead of `cg_tolerance`.
    pub forcing: bool,
    /// Newton starts from x_n + Δt(2v_n − v_{n−1}), where the last step's acceleration would
    /// carry the cloth, when Φ is lower there than at the inertial guess (the solution is
    /// the same to the Newton tolerance; only the start moves closer to it when the motion
    /// is smooth). Off by default: it saves 18–20 % of the Newton iterations on the drape,
    /// Euler buckling and the cantilever but costs 46 % more in shear buckling, and on the
    /// drape its tolerance-sized differences, amplified by the choice of folds, took the
    /// scatter of three seeds from 0.040 to 0.054 (README, Speed).
    pub warm_start: bool,
    /// The conjugate gradient's preconditioner.
    pub preconditioner: PreconditionerChoice,
}

/// Which factor preconditions the Newton systems' conjugate gradient.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum PreconditionerChoice {
    /// The complete factor from `AUTO_CHOLESKY_VERTICES` vertices up, the incomplete one below.
    #[default]
    Auto,
    /// Block incomplete LDLᵀ on the matrix's pattern: cheap to build, and enough on coarse
    /// meshes, where the bending modes it misses are few.
    IncompleteCholesky,
    /// Sparse Cholesky (faer, with a fill-reducing ordering): more memory and a costlier
    /// build, but CG iterations that stay at a few per Newton iteration at any mesh size.
    Cholesky,
    /// Smoothed-aggregation multigrid with the rigid modes as coarse spaces (`multigrid`):
    /// a cycle whose cost grows linearly with the mesh, but CG iterations that grow too;
    /// slower than the complete factor at every drape size measured, so `Auto` never takes
    /// it.
    Multigrid,
}

/// The global preconditioners, solved for with the exact matrix shifted where it is
/// indefinite (`Integrator::solve_shifted`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GlobalPreconditioner {
    Cholesky,
    Multigrid,
}

impl PreconditionerChoice {
    /// From this many vertices `Auto` takes the complete factor. Measured (CPU seconds per
    /// simulated second, incomplete against complete): the Cusick drape's first two steps,
    /// 2.0 and 2.7 at 475 vertices, 31 and 26 at 2737, 498 and 135 at 10 412; its first
    /// 0.1 s at 5153 vertices, 83 and 40; the whole `tablecloth` run (1681 vertices, much
    /// contact), 23 and 97.
    pub const AUTO_CHOLESKY_VERTICES: usize = 3000;

    /// The global preconditioner for a mesh of `vertices`, or None for the incomplete factor.
    fn global(self, vertices: usize) -> Option<GlobalPreconditioner> {
        match self {
            Self::Auto => (vertices >= Self::AUTO_CHOLESKY_VERTICES).then_some(GlobalPreconditioner::Cholesky),
            Self::IncompleteCholesky => None,
            Self::Cholesky => Some(GlobalPreconditioner::Cholesky),
            Self::Multigrid => Some(GlobalPreconditioner::Multigrid),
        }
    }
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self { max_iterations: 30, tolerance: 1e-5, cg_tolerance: 1e-3, cg_max_iterations: 3000, forcing: true, warm_start: false, preconditioner: PreconditionerChoice::Auto }
    }
}

/// Adaptive time steps for the implicit integrators: each step's local position error is
/// estimated and the next Δt chosen to keep it near `tolerance`; a step whose error is more
/// than twice that, or whose Newton solve did not converge, is taken again with a smaller Δt.
///
/// Implicit Euler's position after one step is x_n + h v_n + h² a_{n+1} where the exact
/// motion gives x_n + h v_n + ½h² a: the local error is ½h²|a| = ½h|v_{n+1} − v_n|, largest
/// where the cloth accelerates (a fall, a buckling snap) and vanishing when it moves
/// steadily or rests. Δt then grows as h ∝ √(tolerance/|a|). For BDF2 the same estimate is
/// conservative (its error is third order); its two-step history is restarted whenever Δt
/// changes, as its fixed-step formula requires.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AdaptiveStep {
    /// Off: Δt stays at `solver.dt` (so that a preset's adaptive section can be switched off
    /// from the command line).
    pub enabled: bool,
    /// Largest local position error per step, m.
    pub tolerance: f64,
    /// Smallest and largest Δt, s.
    pub dt_min: f64,
    pub dt_max: f64,
}

impl Default for AdaptiveStep {
    fn default() -> Self {
        Self { enabled: true, tolerance: 1e-4, dt_min: 1e-5, dt_max: 0.02 }
    }
}

impl AdaptiveStep {
    /// The factor by which Δt should change after a step whose error estimate was `error`.
    fn factor(&self, error: f64) -> f64 {
        if error <= 0.0 {
            return 1.5;
        }
        (0.9 * (self.tolerance / error).sqrt()).clamp(0.25, 1.5)
    }
}

/// Why a step was rejected.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum StepError {
    #[error(
        "the simulation diverged with {integrator} at dt = {dt:e} s (t = {time:.6} s): {reason}. \
         The last good state is kept. Use a smaller solver.dt or an implicit integrator \
         (solver.integrator = \"implicit-euler\")"
    )]
    Diverged { integrator: IntegratorKind, dt: f64, time: f64, reason: String },
}

/// What one step cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepReport {
    pub newton_iterations: usize,
    pub cg_iterations: usize,
    /// Preconditioners built (factorisations, complete or incomplete; failed ones included).
    pub factorizations: usize,
    /// True when Newton stopped at its iteration limit before reaching its tolerance.
    pub newton_unconverged: bool,
    /// Newton's last step (the largest vertex move) over the mean edge length: below
    /// `NewtonSettings::tolerance` where Newton converged, 0 for the explicit integrator.
    pub newton_residual: f64,
    /// Where the step's time went.
    pub timings: StepTimings,
    /// The time step taken, s.
    pub dt: f64,
    /// Attempts thrown away by the adaptive step control before this one stood.
    pub rejected: usize,
    /// The largest shift Newton's matrix took to stay positive definite, as a share of the
    /// inertia (meshes with a complete factor; `Integrator::solve_shifted`).
    pub shift: f64,
}

impl StepReport {
    /// Adds another attempt's work (iterations and time).
    fn add_work(&mut self, other: &StepReport) {
        self.newton_iterations += other.newton_iterations;
        self.cg_iterations += other.cg_iterations;
        self.factorizations += other.factorizations;
        self.timings += other.timings;
        self.shift = self.shift.max(other.shift);
    }
}

/// Wall-clock seconds of one step (or a sum of steps) by phase, on the calling thread.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StepTimings {
    /// Elastic forces and energies (line search included) and Hessian assembly.
    pub forces: f64,
    /// The linear solves (preconditioner set-up and conjugate gradient).
    pub solve: f64,
    /// Collision detection and response: planes, cloth–cloth pairs, CCD, contact forces
    /// and Hessians, the self-crossing fail-safe.
    pub contact: f64,
}

impl std::ops::AddAssign for StepTimings {
    fn add_assign(&mut self, o: Self) {
        self.forces += o.forces;
        self.solve += o.solve;
        self.contact += o.contact;
    }
}

/// Seconds since `start`, resetting it to now.
fn lap(start: &mut Instant) -> f64 {
    let now = Instant::now();
    let seconds = (now - *start).as_secs_f64();
    *start = now;
    seconds
}

/// Advances states with a chosen integrator and time step, reusing its work buffers.
pub struct Integrator {
    pub kind: IntegratorKind,
    /// Time step, s (the next one to try, when adaptive).
    pub dt: f64,
    /// Adaptive time steps (implicit integrators only); None: Δt stays fixed.
    pub adaptive: Option<AdaptiveStep>,
    pub newton: NewtonSettings,
    /// A state whose largest edge stretch exceeds this ratio has blown up.
    pub max_stretch: f64,
    forces: Vec<DVec3>,
    /// The linear solves' preconditioner, kept from step to step while it stays good.
    preconditioner: Option<CachedPreconditioner>,
    /// Ordering and symbolic factor for complete Cholesky factors, made once per model.
    direct_pattern: Option<Arc<DirectPattern>>,
    /// What contact did so far.
    pub contact_stats: ContactStats,
    /// The share of inertia added to Newton's matrix on meshes with a complete factor, to
    /// keep it positive definite (`solve_shifted`).
    shift: f64,
    /// The last shift that a failure had to be raised to: where the next failure starts.
    needed_shift: f64,
}

impl Integrator {
    pub fn new(kind: IntegratorKind, dt: f64) -> Self {
        Self {
            kind,
            dt,
            adaptive: None,
            newton: NewtonSettings::default(),
            max_stretch: 4.0,
            forces: Vec::new(),
            preconditioner: None,
            direct_pattern: None,
            contact_stats: ContactStats::default(),
            shift: 0.0,
            needed_shift: 0.0,
        }
    }

    /// Advances `state` by one step (of `self.dt`, or as the adaptive control decides). On
    /// error `state` is unchanged.
    pub fn step(&mut self, model: &Model, state: &mut State) -> Result<StepReport, StepError> {
        let Some(adaptive) = self.adaptive.filter(|a| a.enabled && !self.kind.is_explicit()) else {
            return self.fixed_step(model, state);
        };
        let mut discarded = StepReport::default();
        loop {
            let dt = self.dt;
            let outcome = self.attempt(model, state);
            let smaller = (dt * 0.25).max(adaptive.dt_min);
            let at_floor = dt <= adaptive.dt_min * (1.0 + 1e-9);
            match outcome {
                Ok((trial, mut report)) => {
                    let error = (0..trial.x.len())
                        .filter(|&i| !model.fixed[i])
                        .map(|i| 0.5 * dt * (trial.v[i] - state.v[i]).length())
                        .fold(0.0, f64::max);
                    let factor = adaptive.factor(error);
                    if !at_floor && (error > 2.0 * adaptive.tolerance || report.newton_unconverged) {
                        discarded.add_work(&report);
                        discarded.rejected += 1;
                        self.dt = (dt * factor.min(0.5)).max(adaptive.dt_min);
                        continue;
                    }
                    *state = trial;
                    // Small changes are not worth BDF2's restart.
                    if !(0.9..=1.25).contains(&factor) {
                        self.dt = (dt * factor).clamp(adaptive.dt_min, adaptive.dt_max);
                    }
                    if self.dt != dt {
                        state.previous = None;
                    }
                    report.add_work(&discarded);
                    report.rejected = discarded.rejected;
                    return Ok(report);
                }
                Err(_) if !at_floor => {
                    self.dt = smaller;
                    discarded.rejected += 1;
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// One step of `self.dt`. On error `state` is unchanged.
    fn fixed_step(&mut self, model: &Model, state: &mut State) -> Result<StepReport, StepError> {
        let (next, report) = self.attempt(model, state)?;
        *state = next;
        Ok(report)
    }

    /// One step of `self.dt` from `state`: the state it reaches, or why it was rejected.
    fn attempt(&mut self, model: &Model, state: &State) -> Result<(State, StepReport), StepError> {
        let mut next = state.clone();
        let report = match self.kind {
            IntegratorKind::SymplecticEuler => {
                let mut report = StepReport::default();
                self.symplectic_euler(model, &mut next, &mut report.timings);
                report
            }
            IntegratorKind::ImplicitEuler => self.implicit(model, &mut next, false),
            IntegratorKind::Bdf2 => self.implicit(model, &mut next, true),
        };
        next.time = state.time + self.dt;
        next.steps = state.steps + 1;
        if let Err(StepError::Diverged { integrator, dt, time, mut reason }) = self.check(model, &next, state.time) {
            if self.kind.is_explicit() {
                let limit = model.explicit_step_limit(&state.x);
                reason += &format!("; this explicit method is stable here only below dt ≈ {limit:.3e} s");
            }
            return Err(StepError::Diverged { integrator, dt, time, reason });
        }
        Ok((next, StepReport { dt: self.dt, ..report }))
    }

    fn check(&self, model: &Model, next: &State, time: f64) -> Result<(), StepError> {
        let diverged = |reason: String| StepError::Diverged { integrator: self.kind, dt: self.dt, time, reason };
        if let Some(i) = next.x.iter().zip(&next.v).position(|(x, v)| !x.is_finite() || !v.is_finite()) {
            return Err(diverged(format!("vertex {i} has a non-finite position or velocity")));
        }
        if let Some((i, speed)) = model.outrunning_vertex(&next.v) {
            return Err(diverged(format!(
                "vertex {i} moves at {speed:.3e} m/s, faster than the cloth's fastest in-plane wave ({:.0} m/s)",
                model.max_wave_speed
            )));
        }
        if model.has_membrane() {
            let stretch = model.max_stretch(&next.x);
            if stretch > self.max_stretch {
                return Err(diverged(format!(
                    "an edge is stretched to {stretch:.1} times its rest length (limit {:.1})",
                    self.max_stretch
                )));
            }
        }
        Ok(())
    }

    /// v ← (v + Δt f/m) / (1 + ζΔt); x ← x + Δt v. Damping is taken implicitly so that it
    /// never limits the step; fixed vertices follow their prescribed motion.
    fn symplectic_euler(&mut self, model: &Model, s: &mut State, timings: &mut StepTimings) {
        let dt = self.dt;
        let mut clock = Instant::now();
        self.forces.resize(s.x.len(), DVec3::ZERO);
        model.forces(&s.x, &mut self.forces);
        let damping = 1.0 / (1.0 + model.options.damping * dt);
        let t_next = s.time + dt;
        let start = s.x.clone();
        for i in 0..s.x.len() {
            if model.fixed[i] {
                let target = model.prescribed_position(i, t_next);
                s.v[i] = (target - s.x[i]) / dt;
                s.x[i] = target;
            } else {
                s.v[i] = (s.v[i] + dt * self.forces[i] / model.mass[i]) * damping;
                s.x[i] += dt * s.v[i];
            }
        }
        timings.forces += lap(&mut clock);
        // A step that blew up is left for `check` to reject: its paths can span the scene
        // many times over, and sweeping them for collisions would take forever.
        let blown_up = model.outrunning_vertex(&s.v).is_some();
        if let Some(contact) = model.contact.as_ref().filter(|_| !blown_up) {
            contact.project_explicit(&start, &mut s.x, &mut s.v, &model.fixed);
            self.finish_contact(model, contact, &start, s);
            timings.contact += lap(&mut clock);
        }
        s.previous = None;
    }

    /// The end of every step with contact: the self-crossing fail-safe and the penetration
    /// record.
    fn finish_contact(&mut self, model: &Model, contact: &ContactModel, start: &[DVec3], s: &mut State) {
        if contact.settings.self_collision {
            self.contact_stats.impacts += contact.stop_self_crossings(model, start, &mut s.x, &mut s.v);
        }
        let depth = contact.penetration(&s.x, &model.fixed);
        self.contact_stats.max_penetration = self.contact_stats.max_penetration.max(depth);
    }

    fn implicit(&mut self, model: &Model, s: &mut State, bdf2: bool) -> StepReport {
        let n = s.x.len();
        let dt = self.dt;
        // Both methods minimise Φ(y) = Σ m/(2h²)|y − x̃|² + Σ ζm/(2h)|y − x̂|² + E(y) and set
        // v = (y − x̂)/h. Implicit Euler: h = Δt, x̂ = x_n, x̃ = x_n + h v_n. BDF2:
        // h = 2Δt/3, x̂ = (4x_n − x_{n−1})/3, x̃ = x̂ + h(4v_n − v_{n−1})/3.
        let (h, anchor, inertial): (f64, Vec<DVec3>, Vec<DVec3>) = match (&s.previous, bdf2) {
            (Some((xp, vp)), true) => {
                let h = 2.0 * dt / 3.0;
                let anchor: Vec<DVec3> = (0..n).map(|i| (4.0 * s.x[i] - xp[i]) / 3.0).collect();
                let inertial = (0..n).map(|i| anchor[i] + h * (4.0 * s.v[i] - vp[i]) / 3.0).collect();
                (h, anchor, inertial)
            }
            _ => (dt, s.x.clone(), (0..n).map(|i| s.x[i] + dt * s.v[i]).collect()),
        };
        let t_next = s.time + dt;
        let step = ImplicitStep { model, h, anchor: &anchor, inertial: &inertial };
        let prescribe = |mut y: Vec<DVec3>| {
            for (i, yi) in y.iter_mut().enumerate() {
                if model.fixed[i] {
                    *yi = model.prescribed_position(i, t_next);
                }
            }
            y
        };
        let mut y = prescribe(inertial.clone());
        if let (Some((_, vp)), true) = (&s.previous, self.newton.warm_start) {
            // Where the last step's acceleration would carry the cloth; kept only if it is
            // the better start (it is not when the motion reverses, as in a vibration).
            let extrapolated = prescribe((0..n).map(|i| s.x[i] + dt * (2.0 * s.v[i] - vp[i])).collect());
            if step.potential(&extrapolated) < step.potential(&y) {
                y = extrapolated;
            }
        }
        let mut report = StepReport::default();
        let mut step_contacts = None;
        match &model.contact {
            None => self.newton(&step, None, &mut y, &mut report),
            Some(contact) => {
                let mut clock = Instant::now();
                // The prediction includes gravity's pull over the step, so that contacts a
                // falling cloth is about to make are there from the first iteration.
                let predicted: Vec<DVec3> = (0..n).map(|i| inertial[i] + h * h * model.options.gravity).collect();
                let mut contacts = contact.begin_step(model, &s.x, &predicted, h);
                // Newton's path must start where the cloth is: jumping straight to the
                // inertial guess could carry a vertex through a layer before any contact
                // force acts. Start from x_n moved towards the guess as far as no cloth–cloth
                // pair can meet.
                if contacts.pair_count() > 0 {
                    let guess: Vec<DVec3> = (0..n).map(|i| if model.fixed[i] { DVec3::ZERO } else { y[i] - s.x[i] }).collect();
                    let alpha = contacts.max_step(&s.x, &guess);
                    for i in 0..n {
                        if !model.fixed[i] {
                            y[i] = s.x[i] + alpha * guess[i];
                        }
                    }
                }
                report.timings.contact += lap(&mut clock);
                // Solve; a path that enters a prop without a plane adds one and solves again.
                for pass in 0..4 {
                    self.newton(&step, Some(&contacts), &mut y, &mut report);
                    clock = Instant::now();
                    let missed = contact.add_missed(&mut contacts, model, &s.x, &y, h);
                    report.timings.contact += lap(&mut clock);
                    if missed == 0 {
                        break;
                    }
                    self.contact_stats.resolves += 1;
                    if pass == 3 {
                        report.newton_unconverged = true;
                    }
                }
                step_contacts = Some(contacts);
            }
        }
        let mut previous = (s.x.clone(), s.v.clone());
        let start = s.x.clone();
        for i in 0..n {
            s.v[i] = (y[i] - anchor[i]) / h;
        }
        if let Some(contacts) = &step_contacts {
            // A vertex whose rebound was absorbed gets a history of steady motion at its new
            // velocity, or BDF2's extrapolation from its falling past would lift it again.
            for i in contacts.absorb_rebound(&y, &mut s.v) {
                let i = i as usize;
                previous.0[i] = y[i] - dt * s.v[i];
                previous.1[i] = s.v[i];
            }
        }
        s.x = y;
        if let Some(contact) = &model.contact {
            let mut clock = Instant::now();
            self.finish_contact(model, contact, &start, s);
            report.timings.contact += lap(&mut clock);
        }
        s.previous = Some(previous);
        report
    }

    /// Whether the kept preconditioner should be rebuilt. A factor serves later iterations,
    /// and later steps: the matrix changes little from one to the next, and a factorisation
    /// costs several CG iterations. It is rebuilt once the iterations it has cost beyond
    /// what it took when new add up to what building it cost (the rent-or-buy rule: never
    /// more than twice the best choice made in hindsight).
    fn preconditioner_is_stale(&self, n: usize) -> bool {
        self.preconditioner.as_ref().is_none_or(|p| p.size != n || p.excess >= p.preconditioner.cost_in_iterations())
    }

    /// Solves Newton's system with a global preconditioner (the complete factor or the
    /// multigrid hierarchy) and the exact matrix H plus a shift s·M/h² (s = `self.shift`, a
    /// share of the inertia), s as small as keeps it positive definite (Levenberg and
    /// Marquardt's regularisation, in the mass metric). False, with nothing solved, if that
    /// takes more than `MAX_SHIFT`.
    ///
    /// A factor that fails (a pivot not positive) or a CG that meets negative curvature or
    /// returns no descent doubles s (from `MIN_SHIFT`), or sets it to the last shift a
    /// failure needed if that is more; the matrix is factored again only if the kept factor
    /// was made for a smaller shift. After each solve the next iteration tries half the
    /// shift with the same factor: a shift kept through a step slowed Newton to 30
    /// iterations on a compressed sheet (`tests/conservation.rs`), where a shift is needed
    /// for only an iteration or two. The need returns in jumps, from zero to about 3 within
    /// an iteration on the 20 463-triangle drape, and climbing there by doubling failed 94
    /// of 214 factorisations over its first 0.3 s; starting from the last need, 16 of 139
    /// (a sixth fewer CG iterations and less CPU, the same Newton iterations).
    ///
    /// Fine meshes do not take the bounded matrix of `CompressedEdges::Within` throughout,
    /// which scales the compressed edges' term at each vertex to at most 90 % of the
    /// inertia. The bound guards against the shortest waves, where a compressed edge's
    /// softening is largest, and inertia per vertex falls as the edge length squared: on the
    /// 20 463-triangle drape nearly every free vertex is bounded, most to a fiftieth of its
    /// softening, so that matrix is wrong in the long waves too and Newton converges
    /// linearly (steps of a few µm for up to 30 iterations, the gradient not falling). The
    /// exact matrix is positive definite in most of those iterations, and a shift makes it
    /// so in most of the rest. Over the first 0.3 s of that drape: 1110 Newton iterations
    /// with the bound, 781 with shifts of at most 0.4, 566 with at most 6.4.
    fn solve_shifted(&mut self, exact: &SystemMatrix, positions: &[DVec3], direction: &mut [DVec3], solve: &mut Solve) -> bool {
        let n = exact.fixed.len();
        let mut rebuild = false;
        let mut raised = false;
        loop {
            let shifted: Vec<f64> = exact.mass_diagonal.iter().map(|d| d * (1.0 + self.shift)).collect();
            let system = SystemMatrix { mass_diagonal: &shifted, ..*exact };
            // Doubles the shift, or takes the last one that had to be raised to; false once
            // it is at its largest.
            let needed = self.needed_shift;
            let mut raise = |shift: &mut f64| {
                if *shift >= MAX_SHIFT {
                    return false;
                }
                *shift = (2.0 * *shift).max(needed).clamp(MIN_SHIFT, MAX_SHIFT);
                raised = true;
                true
            };
            if rebuild || self.preconditioner_is_stale(n) {
                let factor = self.global_factor(&system, positions);
                solve.report.factorizations += 1;
                solve.timings.solve += lap(solve.clock);
                match factor {
                    Some(factor) => self.preconditioner = Some(CachedPreconditioner { shift: self.shift, ..CachedPreconditioner::new(n, factor) }),
                    None if raise(&mut self.shift) => {
                        rebuild = true;
                        continue;
                    }
                    None => return false,
                }
            }
            let cached = self.preconditioner.as_mut().expect("built above");
            let cg = pcg(&system, &cached.preconditioner, solve.rhs, direction, solve.cg_tolerance, self.newton.cg_max_iterations);
            solve.report.cg_iterations += cg.iterations;
            solve.timings.solve += lap(solve.clock);
            let descent = solve.rhs.iter().zip(direction.iter()).map(|(r, d)| r.dot(*d)).sum::<f64>() > 0.0;
            if cg.negative_curvature || !descent {
                if !raise(&mut self.shift) {
                    return false;
                }
                // A factor made for at least this shift is already at hand.
                rebuild = self.shift > cached.shift;
                continue;
            }
            cached.record(&cg);
            solve.report.shift = solve.report.shift.max(self.shift);
            if raised {
                self.needed_shift = self.shift;
            }
            // The next iteration tries half the shift, with the same factor.
            self.shift = if self.shift / 2.0 < MIN_SHIFT { 0.0 } else { self.shift / 2.0 };
            return true;
        }
    }

    /// The global preconditioner of `system` (the cloth at `positions`): the complete factor
    /// on the model's pattern (made once) or the multigrid hierarchy; None if it is not
    /// positive definite (or the symbolic analysis failed).
    fn global_factor(&mut self, system: &SystemMatrix, positions: &[DVec3]) -> Option<Preconditioner> {
        if self.newton.preconditioner.global(system.fixed.len()) == Some(GlobalPreconditioner::Multigrid) {
            return Multigrid::new(system, positions).map(Preconditioner::Multigrid);
        }
        if self.direct_pattern.as_ref().is_none_or(|p| !p.fits(system)) {
            self.direct_pattern = DirectPattern::new(system).map(Arc::new);
        }
        let pattern = self.direct_pattern.clone()?;
        DirectFactor::new(pattern, system).map(Preconditioner::Cholesky)
    }

    /// Newton's method on the incremental potential Φ (plus contact), from `y` in place.
    fn newton(&mut self, step: &ImplicitStep, contacts: Option<&StepContacts>, y: &mut Vec<DVec3>, report: &mut StepReport) {
        let ImplicitStep { model, h, anchor, inertial } = *step;
        let n = y.len();
        let zeta = model.options.damping;
        let mass_diagonal: Vec<f64> = model.mass.iter().map(|m| m * (1.0 / (h * h) + zeta / h)).collect();
        // Compressed edges may take back up to this share of each vertex's inertia in
        // Newton's matrix: it stays positive definite, and Newton converges quadratically
        // where the cloth buckles unless the compression outweighs inertia.
        let softening: Vec<f64> = mass_diagonal.iter().zip(&model.fixed).map(|(&d, &f)| if f { f64::INFINITY } else { SOFTENING_SHARE * d }).collect();
        let objective = |y: &[DVec3]| -> f64 { step.potential(y) + contacts.map_or(0.0, |c| c.energy(y, anchor)) };
        let mut stiffness = model.stiffness_matrix();
        let mut bounded = model.stiffness_matrix();
        let mut gradient = vec![DVec3::ZERO; n];
        let mut direction = vec![DVec3::ZERO; n];
        let mut trial = y.clone();
        let tolerance = self.newton.tolerance * model.mean_edge_length;
        // With nothing fixed and nothing touched, the elastic forces are internal: momentum
        // is conserved, and the Newton direction is corrected to keep it so.
        let all_free = !model.fixed.iter().any(|&f| f) && contacts.is_none_or(|c| c.is_empty());
        report.newton_unconverged = true;
        let mut phi_current: Option<f64> = None;
        let mut couplings = Vec::new();
        let mut previous_norm: Option<f64> = None;
        let mut previous_step: Option<f64> = None;
        // The last Newton step's length, if it was taken whole.
        let mut previous_full_step: Option<f64> = None;
        let mut clock = Instant::now();
        let mut timings = StepTimings::default();
        let mut bounded_throughout = false;
        for _ in 0..self.newton.max_iterations {
            self.forces.resize(n, DVec3::ZERO);
            model.forces(y, &mut self.forces);
            let forces = &self.forces;
            for i in 0..n {
                gradient[i] = if model.fixed[i] {
                    DVec3::ZERO
                } else {
                    model.mass[i] / (h * h) * (y[i] - inertial[i]) + zeta * model.mass[i] / h * (y[i] - anchor[i]) - forces[i]
                };
            }
            timings.forces += lap(&mut clock);
            if let Some(c) = contacts {
                c.add_gradient(y, anchor, &mut gradient, &model.fixed);
                for (g, &f) in gradient.iter_mut().zip(&model.fixed) {
                    if f {
                        *g = DVec3::ZERO;
                    }
                }
                timings.contact += lap(&mut clock);
            }
            let norm = gradient.iter().map(|g| g.length_squared()).sum::<f64>().sqrt();
            let rhs: Vec<DVec3> = gradient.iter().map(|g| -*g).collect();
            // Newton stops at a step under the tolerance. Where the next step promises to
            // be one, it is taken with the last preconditioner instead of being assembled
            // and solved for: while Newton converges the step shrinks as the gradient does,
            // so the last full step scaled by the gradient's decrease predicts it, and the
            // preconditioner (a factor of a recent Newton matrix) gives it to within that
            // factor's error. If the step it gives is not under the tolerance, the
            // iteration goes on as usual. On the paper's drape a quarter of all Newton
            // iterations had done nothing but take such a step.
            if let (Some(before), Some(full), Some(cached)) = (previous_norm, previous_full_step, self.preconditioner.as_ref())
                && cached.size == n
                && norm < 0.5 * before
                && full * norm / before < tolerance
            {
                cached.preconditioner.apply(&rhs, &mut direction);
                if all_free {
                    keep_momentum(&mass_diagonal, &gradient, &mut direction);
                }
                let length = direction.iter().map(|d| d.length()).fold(0.0, f64::max);
                timings.solve += lap(&mut clock);
                if length < tolerance && contacts.is_none_or(|c| c.step_limit(y, &direction) >= 1.0) {
                    for (i, d) in direction.iter().enumerate() {
                        if !model.fixed[i] {
                            y[i] += *d;
                        }
                    }
                    report.newton_unconverged = false;
                    previous_step = Some(length);
                    break;
                }
            }
            let bending = model.bending_newton_matrix(y);
            let cg_tolerance = if self.newton.forcing {
                // Eisenstat and Walker's safeguard against tightening too fast, 0.9·η²_{k−1},
                // only acts above 0.1, which this term never exceeds.
                let eta = previous_norm.map_or(0.1, |before| 0.9 * (norm / before).powi(2));
                // A solve need not be more exact than the tolerance Newton stops at: with
                // relative residual η the step misses Newton's by about η times its length,
                // which the last step's length scaled by the gradient's decrease predicts.
                // Solving to an error of a tenth of the tolerance is enough; tighter solves
                // of the last, sub-tolerance step cost a third of the drape's CG iterations.
                let floor = match (previous_norm, previous_step) {
                    (Some(before), Some(length)) if length > 0.0 && before > 0.0 => 0.1 * tolerance / (length * norm / before),
                    _ => 0.0,
                };
                eta.max(floor).clamp(self.newton.cg_tolerance, 0.1)
            } else {
                self.newton.cg_tolerance
            };
            previous_norm = Some(norm);
            // Newton's matrix takes the exact Hessian of the compressed edges: a buckling
            // cloth's softening is what makes Newton converge quadratically. Where it
            // outweighs inertia and bending the matrix is indefinite. With the incomplete
            // factor (coarse meshes) CG then meets a direction of negative curvature or
            // returns no descent, and the solve is repeated with the softening bounded so
            // that the matrix stays positive definite. With a complete factor (fine meshes)
            // the exact matrix is shifted instead (`solve_shifted`).
            if let Some(c) = contacts {
                couplings.clear();
                c.couplings(y, &mut couplings);
                timings.contact += lap(&mut clock);
            }
            let assemble = |k: &mut BlockCsr, compressed: CompressedEdges| {
                model.assemble_membrane_stiffness_within(y, k, compressed);
                if let Some(c) = contacts {
                    c.add_hessian(y, anchor, k);
                }
            };
            assemble(&mut stiffness, CompressedEdges::Exact);
            timings.forces += lap(&mut clock);
            let system = SystemMatrix { mass_diagonal: &mass_diagonal, stiffness: &stiffness, bending: bending.as_deref(), fixed: &model.fixed, couplings: &couplings };
            if self.newton.preconditioner.global(n).is_some() {
                let mut solve = Solve { rhs: &rhs, cg_tolerance, report: &mut *report, timings: &mut timings, clock: &mut clock };
                if !bounded_throughout && !self.solve_shifted(&system, y, &mut direction, &mut solve) {
                    // This step's remaining iterations take the bounded matrix, positive
                    // definite, and a factor of it.
                    bounded_throughout = true;
                    self.preconditioner = None;
                }
                if bounded_throughout {
                    assemble(&mut bounded, CompressedEdges::Within(&softening));
                    timings.forces += lap(&mut clock);
                    let system = SystemMatrix { stiffness: &bounded, ..system };
                    if self.preconditioner_is_stale(n) {
                        let preconditioner = self.global_factor(&system, y).unwrap_or_else(|| system.preconditioner());
                        report.factorizations += 1;
                        self.preconditioner = Some(CachedPreconditioner::new(n, preconditioner));
                        timings.solve += lap(&mut clock);
                    }
                    let cached = self.preconditioner.as_mut().expect("built above");
                    let cg = pcg(&system, &cached.preconditioner, &rhs, &mut direction, cg_tolerance, self.newton.cg_max_iterations);
                    report.cg_iterations += cg.iterations;
                    timings.solve += lap(&mut clock);
                    cached.record(&cg);
                }
            } else {
                let mut bounded_ready = false;
                if self.preconditioner_is_stale(n) {
                    // Factors are made from the bounded matrix. Made from the exact one, the
                    // Euler strip's onset under BDF2 came 4.1 % above π²B/L² (1.5 % from the
                    // bounded one; the test allows 3 %): near the bifurcation the exact
                    // matrix is nearly singular, its incomplete factor breaks down and is
                    // shifted, and Newton's steps along the soft mode likely fell below the
                    // tolerance while the mode lagged.
                    assemble(&mut bounded, CompressedEdges::Within(&softening));
                    bounded_ready = true;
                    timings.forces += lap(&mut clock);
                    let preconditioner = SystemMatrix { stiffness: &bounded, ..system }.preconditioner();
                    report.factorizations += 1;
                    self.preconditioner = Some(CachedPreconditioner::new(n, preconditioner));
                    timings.solve += lap(&mut clock);
                }
                let cached = self.preconditioner.as_mut().expect("built above");
                let mut cg = pcg(&system, &cached.preconditioner, &rhs, &mut direction, cg_tolerance, self.newton.cg_max_iterations);
                report.cg_iterations += cg.iterations;
                timings.solve += lap(&mut clock);
                let descent = gradient.iter().zip(&direction).map(|(g, d)| g.dot(*d)).sum::<f64>() < 0.0;
                // (A bounded matrix is positive definite: a failure there is left to the
                // line search and its steepest-descent fallback.)
                if cg.negative_curvature || !descent {
                    if !bounded_ready {
                        assemble(&mut bounded, CompressedEdges::Within(&softening));
                        timings.forces += lap(&mut clock);
                    }
                    let system = SystemMatrix { stiffness: &bounded, ..system };
                    cg = pcg(&system, &cached.preconditioner, &rhs, &mut direction, cg_tolerance, self.newton.cg_max_iterations);
                    report.cg_iterations += cg.iterations;
                    timings.solve += lap(&mut clock);
                }
                cached.record(&cg);
            }
            if all_free {
                keep_momentum(&mass_diagonal, &gradient, &mut direction);
            }
            report.newton_iterations += 1;
            let slope: f64 = gradient.iter().zip(&direction).map(|(g, d)| g.dot(*d)).sum();
            if slope >= 0.0 {
                // Not a descent direction (the CG broke down): fall back to steepest descent
                // scaled by the mass term.
                for i in 0..n {
                    direction[i] = if model.fixed[i] { DVec3::ZERO } else { -gradient[i] / mass_diagonal[i] };
                }
            }
            let slope: f64 = gradient.iter().zip(&direction).map(|(g, d)| g.dot(*d)).sum();
            // Φ at the current iterate is the previous iteration's accepted trial value.
            let phi0 = *phi_current.get_or_insert_with(|| objective(y));
            let limit = contacts.map_or(f64::INFINITY, |c| c.step_limit(y, &direction));
            let mut alpha = limit.min(1.0);
            let mut accepted = false;
            let mut phi = phi0;
            for _ in 0..30 {
                for i in 0..n {
                    trial[i] = y[i] + alpha * direction[i];
                }
                phi = objective(&trial);
                if phi.is_finite() && phi <= phi0 + 1e-4 * alpha * slope {
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            let length = direction.iter().map(|d| d.length()).fold(0.0, f64::max);
            if accepted && alpha == 1.0 && length > 10.0 * tolerance {
                // Where Φ is flatter along d than the matrix says, a full step is accepted
                // yet falls short of the minimum along d. The parabola through Φ(0), Φ'(0)
                // and Φ(1) places that minimum; a step towards it (at most EXTRAPOLATION
                // times the full step, short of any cloth–cloth pair and of a tenth of an
                // edge per vertex) is kept if Φ is lower there. On a quadratic Φ with
                // Newton's direction the parabola's minimum is at 1 and nothing is tried.
                // At 20 463 triangles, where Newton creeps in steps of a few µm, it fired in
                // about 40 % of the iterations over the first 0.3 s and saved a tenth of them;
                // it never fires on the coarse scenes.
                let curvature = 2.0 * (phi - phi0 - slope);
                let best = if curvature > 0.0 { -slope / curvature } else { f64::INFINITY };
                let reach = 0.1 * model.mean_edge_length / length;
                let target = best.min(EXTRAPOLATION).min(0.9 * limit).min(reach);
                if target > 1.5 {
                    let further: Vec<DVec3> = (0..n).map(|i| y[i] + target * direction[i]).collect();
                    let phi_further = objective(&further);
                    if phi_further < phi {
                        alpha = target;
                        phi = phi_further;
                        trial = further;
                    }
                }
            }
            phi_current = Some(phi).filter(|_| accepted);
            timings.forces += lap(&mut clock);
            let step_size = alpha * length;
            previous_step = Some(step_size);
            previous_full_step = Some(length).filter(|_| accepted && alpha == 1.0);
            if !accepted {
                // Φ cannot be decreased measurably: at round-off level we are converged;
                // otherwise take the smallest tried step and let the iteration limit speak.
                if step_size < 10.0 * tolerance {
                    report.newton_unconverged = false;
                    break;
                }
            }
            std::mem::swap(y, &mut trial);
            if step_size < tolerance {
                report.newton_unconverged = false;
                break;
            }
        }
        report.timings += timings;
        report.newton_residual = previous_step.map_or(f64::INFINITY, |step| step / model.mean_edge_length);
    }
}

/// The share of inertia (m/h² + ζm/h) that compressed edges' negative geometric stiffness
/// may take in Newton's matrix, which keeps at least 1 − SOFTENING_SHARE of it.
const SOFTENING_SHARE: f64 = 0.9;

/// With nothing fixed and nothing touched, corrects a Newton direction d so that momentum
/// is conserved to round-off whatever the solve's error. The elastic Hessian annihilates
/// translations, so adding a constant c to d changes only the mass term of H d; choosing c
/// so that Σ M (d + c) = −Σ g removes the net force the residual would leave.
fn keep_momentum(mass_diagonal: &[f64], gradient: &[DVec3], direction: &mut [DVec3]) {
    let (mut mass_sum, mut residual) = (0.0, DVec3::ZERO);
    for ((&m, &g), &d) in mass_diagonal.iter().zip(gradient).zip(direction.iter()) {
        mass_sum += m;
        residual += g + m * d;
    }
    let shift = -residual / mass_sum;
    direction.iter_mut().for_each(|d| *d += shift);
}

/// The longest step, in Newton steps, that the line search tries along a direction where Φ
/// is nearly flat.
const EXTRAPOLATION: f64 = 8.0;

/// The smallest and largest shifts `solve_shifted` adds, as shares of the inertia.
const MIN_SHIFT: f64 = 0.05;
const MAX_SHIFT: f64 = 6.4;

/// One Newton iteration's linear solve: its right-hand side and tolerance, and where its
/// work is counted.
struct Solve<'a> {
    rhs: &'a [DVec3],
    cg_tolerance: f64,
    report: &'a mut StepReport,
    timings: &'a mut StepTimings,
    clock: &'a mut Instant,
}

/// A preconditioner with what it was built for and how quick it made CG when new.
struct CachedPreconditioner {
    /// Vertices of the matrix it was built from.
    size: usize,
    preconditioner: Preconditioner,
    /// CG iterations per e-fold of residual reduction on its first solve.
    fresh_rate: Option<f64>,
    /// CG iterations spent beyond that rate since.
    excess: f64,
    /// The shift of the matrix it was made from (`Integrator::solve_shifted`).
    shift: f64,
}

impl CachedPreconditioner {
    fn new(size: usize, preconditioner: Preconditioner) -> Self {
        Self { size, preconditioner, fresh_rate: None, excess: 0.0, shift: 0.0 }
    }

    /// Counts a solve's iterations beyond the rate this preconditioner had when new.
    fn record(&mut self, cg: &CgReport) {
        // Iterations per e-fold of residual reduction: comparable across tolerances.
        let efolds = (-cg.relative_residual.max(1e-16).ln()).max(1.0);
        let fresh_rate = *self.fresh_rate.get_or_insert(cg.iterations as f64 / efolds);
        self.excess += (cg.iterations as f64 - fresh_rate * efolds).max(0.0);
    }
}

/// What one implicit step minimises over: Φ's inertial target x̃, the anchor x̂ of the
/// step's velocity, and the effective step h.
#[derive(Clone, Copy)]
struct ImplicitStep<'a> {
    model: &'a Model,
    h: f64,
    anchor: &'a [DVec3],
    inertial: &'a [DVec3],
}

impl ImplicitStep<'_> {
    /// The incremental potential Φ at `y` without contact.
    fn potential(&self, y: &[DVec3]) -> f64 {
        let (model, h) = (self.model, self.h);
        let zeta = model.options.damping;
        let inertia: f64 = (0..y.len())
            .filter(|&i| !model.fixed[i])
            .map(|i| {
                let m = model.mass[i];
                m / (2.0 * h * h) * (y[i] - self.inertial[i]).length_squared()
                    + zeta * m / (2.0 * h) * (y[i] - self.anchor[i]).length_squared()
            })
            .sum();
        inertia + model.potential_energy(y)
    }
}
