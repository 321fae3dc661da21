//! Time integrators. Each advances a [`State`] by one step of a [`Model`].
//!
//! - Symplectic (semi-implicit) Euler (`explicit.rs`): the paper's style; cheap per step,
//!   stable only below a CFL-like limit set by the stiffest membrane wave and bending mode.
//! - Implicit Euler (`implicit.rs`): each step minimises the incremental potential
//!   Φ(y) = Σ m/(2h²)|y − x̃|² + Σ ζm/(2h)|y − x_n|² + E(y) by Newton's method
//!   (`newton.rs`: a preconditioned conjugate gradient whose factor `preconditioning.rs`
//!   chooses, and a line search on Φ). Unconditionally stable, strongly damped at large
//!   steps.
//! - BDF2: the same minimisation with h = 2Δt/3 and a two-step history; second order, with
//!   far less numerical damping than implicit Euler at the same Δt.
//! - Adaptive steps (`adaptive.rs`) for the implicit integrators; what a user sets is in
//!   `settings.rs`, what a step reports in `report.rs`.
//!
//! A step that produces a non-finite or exploding state is rejected: the state is left as
//! it was and the error names the integrator, Δt and time.

mod adaptive;
mod explicit;
mod implicit;
mod newton;
mod preconditioning;
mod quasi_newton;
mod report;
mod settings;

pub use report::{StepError, StepReport, StepTimings, UNCONVERGED_FACTOR};
pub use settings::{AdaptiveStep, DEFAULT_MAX_ITERATIONS, Indefinite, Minimizer, NewtonSettings, PreconditionerChoice};

use crate::sim::contact::{ContactModel, ContactStats, NearPairs};
use crate::sim::linalg::DirectPattern;
use crate::sim::model::Model;
use glam::DVec3;
use preconditioning::{CachedPreconditioner, PatternChoice};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

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
    pub(super) previous: Option<(Vec<DVec3>, Vec<DVec3>)>,
    /// Where each vertex resting on a prop sticks from, by vertex (`StepContacts::stuck_after`):
    /// part of the state, so that a rejected step leaves it as it was.
    pub(super) stuck: Vec<Option<DVec3>>,
    /// The vertices held where they are over the next step because they stick to a prop
    /// (`ContactSettings::hold_sticking`), by vertex: the prop's outward normal there.
    pub(super) held: Vec<Option<DVec3>>,
}

impl State {
    pub fn at_rest(x: Vec<DVec3>) -> Self {
        let v = vec![DVec3::ZERO; x.len()];
        Self { x, v, time: 0.0, steps: 0, previous: None, stuck: Vec::new(), held: Vec::new() }
    }

    /// Forgets the previous step (BDF2's history), as a change of time step requires.
    pub fn clear_history(&mut self) {
        self.previous = None;
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
    /// The pattern of the incomplete factors, chosen by what each has cost so far.
    incomplete_pattern: PatternChoice,
    /// Where the incomplete factors' diagonal shifts start.
    incomplete_shift: crate::sim::linalg::ShiftMemory,
    /// Earlier Newton directions the incomplete factor's solves start from.
    recycled: crate::sim::linalg::Recycled,
    /// Ordering and symbolic factor for complete Cholesky factors, made once per model.
    direct_pattern: Option<Arc<DirectPattern>>,
    /// What contact did so far.
    pub contact_stats: ContactStats,
    /// Cloth–cloth pairs near enough to meet soon, kept from step to step (contact's
    /// changing state; the props and settings stay with the model).
    near_pairs: NearPairs,
    /// The share of inertia added to Newton's matrix on meshes with a complete factor, to
    /// keep it positive definite (`solve_shifted`).
    shift: f64,
    /// The last shift that a failure had to be raised to: where the next failure starts.
    needed_shift: f64,
    /// The last step's local error estimate ½Δt·max|v_{n+1} − v_n|, m; infinite before the
    /// first step (`NewtonSettings::error_share`).
    last_step_error: f64,
    /// The quasi-Newton step's matrices (`Minimizer::QuasiNewton`).
    quasi: Option<quasi_newton::StepMatrices>,
    /// The quasi-Newton step's iteration budget for the next step (`quasi_newton.rs`).
    quasi_budget: usize,
    /// The wall-clock time past which Newton starts no further iteration, leaving its step
    /// unconverged (and counted so), so that a run's wall-time bound holds within a step
    /// however long one iteration of a pathological scene takes. None: no bound.
    pub deadline: Option<std::time::Instant>,
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
            incomplete_pattern: PatternChoice::default(),
            incomplete_shift: Default::default(),
            recycled: Default::default(),
            direct_pattern: None,
            contact_stats: ContactStats::default(),
            near_pairs: NearPairs::default(),
            shift: 0.0,
            needed_shift: 0.0,
            last_step_error: f64::INFINITY,
            quasi: None,
            quasi_budget: usize::MAX,
            deadline: None,
        }
    }

    /// Advances `state` by one step (of `self.dt`, or as the adaptive control decides). On
    /// error `state` is unchanged.
    pub fn step(&mut self, model: &Model, state: &mut State) -> Result<StepReport, StepError> {
        match self.adaptive.filter(|a| a.enabled && !self.kind.is_explicit()) {
            Some(adaptive) => self.adaptive_step(model, state, adaptive),
            None => self.fixed_step(model, state),
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
            IntegratorKind::SymplecticEuler => self.symplectic_euler(model, &mut next),
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

    /// The end of every step with contact: the self-crossing fail-safe and the penetration
    /// record.
    fn finish_contact(&mut self, model: &Model, contact: &ContactModel, start: &[DVec3], s: &mut State) {
        if contact.settings.self_collision {
            self.contact_stats.impacts += contact.stop_self_crossings(model.cloth(), &mut self.near_pairs, start, &mut s.x, &mut s.v);
        }
        let depth = contact.penetration(&s.x, &model.fixed);
        self.contact_stats.max_penetration = self.contact_stats.max_penetration.max(depth);
    }
}
