//! Newton's method on the incremental potential, in its phases: the gradient, the last step
//! taken from the preconditioner, the forcing term that sets how exactly each linear
//! system is solved, the solve itself (`preconditioning.rs` decides its factor and how an
//! indefinite matrix is handled), and the line search.

use super::implicit::ImplicitStep;
use super::report::{StepReport, Stopwatch};
use super::Integrator;
use super::settings::Indefinite;
use crate::sim::contact::StepContacts;
use crate::sim::linalg::{BlockCsr, Coupling, ScalarCsr, SystemMatrix};
use crate::sim::model::CompressedEdges;
use glam::DVec3;

/// The share of inertia (m/h² + ζm/h) that compressed edges' negative geometric stiffness
/// may take in Newton's matrix, which keeps at least 1 − SOFTENING_SHARE of it.
const SOFTENING_SHARE: f64 = 0.9;

/// The longest step, in Newton steps, that the line search tries along a direction where Φ
/// is nearly flat.
const EXTRAPOLATION: f64 = 8.0;

/// Units in the last place of Φ below which a promised decrease cannot be measured.
const ROUNDOFF_ULPS: f64 = 1000.0;

/// What stays fixed through one Newton solve: the step's potential, its contacts and the
/// constant parts of Newton's matrix.
pub(super) struct NewtonProblem<'a> {
    pub step: &'a ImplicitStep<'a>,
    pub contacts: Option<&'a StepContacts>,
    /// m/h² + ζm/h per vertex, the inertia in Newton's matrix.
    pub mass_diagonal: Vec<f64>,
    /// How much of that each free vertex's compressed edges may take back (the bounded
    /// matrix, `CompressedEdges::Within`); infinite on fixed vertices.
    pub softening: Vec<f64>,
    /// Newton stops at a step shorter than this, m: `base_tolerance`, or the step's own
    /// integration error's share where that is more (updated at each iterate).
    pub tolerance: f64,
    /// `NewtonSettings::tolerance` in metres.
    base_tolerance: f64,
    /// `NewtonSettings::error_share`.
    error_share: f64,
    /// The local error the loosened tolerance may take at most: the previous step's, so that
    /// an iterate whose own error estimate is inflated by its being wrong cannot loosen the
    /// tolerance that accepts it (infinite on an integrator's first step, after a transfer
    /// to a finer mesh).
    error_cap: f64,
    /// With nothing fixed and nothing touched, the elastic forces are internal: momentum is
    /// conserved, and each Newton direction is corrected to keep it so.
    pub all_free: bool,
    /// Directions solved on the bounded matrix are judged by their estimated distance to
    /// the solution, not their own length (`NewtonSettings::retry_exact` off).
    judge_contraction: bool,
}

impl<'a> NewtonProblem<'a> {
    /// Newton's tolerance is `tolerance` mean edges, or `error_share` of the step's local
    /// error where that is more; `judge_contraction` as the field.
    pub(super) fn new(step: &'a ImplicitStep<'a>, contacts: Option<&'a StepContacts>, tolerance: f64, error_share: f64, error_cap: f64, judge_contraction: bool) -> Self {
        let ImplicitStep { model, h, .. } = *step;
        let zeta = model.options.damping;
        let mass_diagonal: Vec<f64> = model.mass.iter().map(|m| m * (1.0 / (h * h) + zeta / h)).collect();
        // Compressed edges may take back up to this share of each vertex's inertia in
        // Newton's matrix: it stays positive definite, and Newton converges quadratically
        // where the cloth buckles unless the compression outweighs inertia.
        let softening = mass_diagonal.iter().zip(step.fixed).map(|(&d, &f)| if f { f64::INFINITY } else { SOFTENING_SHARE * d }).collect();
        let all_free = !step.fixed.iter().any(|&f| f) && contacts.is_none_or(|c| c.is_empty());
        let base_tolerance = tolerance * model.mean_edge_length;
        Self { step, contacts, mass_diagonal, softening, tolerance: base_tolerance, base_tolerance, error_share, error_cap, all_free, judge_contraction }
    }

    /// Sets the tolerance for an iterate `y`: a solve an order of magnitude more exact than
    /// the step it serves (`NewtonSettings::error_share` of its local error, estimated at
    /// `y` and at most the previous step's) adds nothing a user could see in a moving cloth,
    /// and at rest the base tolerance holds.
    pub(super) fn update_tolerance(&mut self, y: &[DVec3]) {
        self.tolerance = if self.error_share > 0.0 {
            self.base_tolerance.max(self.error_share * self.step.local_error(y).min(self.error_cap))
        } else {
            self.base_tolerance
        };
    }

    /// Φ at `y`, contact included.
    pub fn objective(&self, y: &[DVec3]) -> f64 {
        self.step.potential(y) + self.contacts.map_or(0.0, |c| c.energy(y))
    }

    /// Assembles the in-plane stiffness at `y` with `compressed` edges, and contact's
    /// Hessian, into `k`.
    pub fn assemble(&self, y: &[DVec3], k: &mut BlockCsr, compressed: CompressedEdges) {
        self.step.model.assemble_membrane_stiffness_within(y, k, compressed);
        if let Some(c) = self.contacts {
            c.add_hessian(y, k);
        }
    }
}

/// The work arrays of one Newton solve.
pub(super) struct NewtonWork {
    /// The exact in-plane stiffness (and contact's Hessian).
    pub stiffness: BlockCsr,
    /// The same with compressed edges bounded (`CompressedEdges::Within`).
    pub bounded: BlockCsr,
    /// ∇Φ, zero on fixed vertices.
    pub gradient: Vec<DVec3>,
    /// −∇Φ, the right-hand side of Newton's system.
    pub rhs: Vec<DVec3>,
    pub direction: Vec<DVec3>,
    pub trial: Vec<DVec3>,
    /// Cloth–cloth contact's couplings in Newton's matrix.
    pub couplings: Vec<Coupling>,
}

/// What one iteration hands the next.
#[derive(Default)]
struct NewtonHistory {
    /// |∇Φ| of the previous iteration.
    previous_norm: Option<f64>,
    /// The length of the previous step taken (after the line search).
    previous_step: Option<f64>,
    /// The last Newton step's length, if it was taken whole.
    previous_full_step: Option<f64>,
    /// Φ at the current iterate, where the line search accepted it.
    phi_current: Option<f64>,
    /// This step's solves take the bounded matrix from now on (`solve_direction`).
    bounded_throughout: bool,
    /// The length of the previous Newton direction, whatever part of it was taken: how far
    /// the solution still was, as far as Newton could tell.
    previous_direction: Option<f64>,
    /// This iteration's direction was solved on the bounded matrix, which is not Φ's
    /// Hessian along the buckling modes: Newton converges linearly there.
    bounded_direction: bool,
    /// This iteration's solve stopped at CG's iteration limit: its direction is shorter
    /// than Newton's step (CG's iterates grow in length), so it cannot show convergence.
    truncated: bool,
}

/// How an iteration's line search ended.
enum Progress {
    /// The step taken is under Newton's tolerance, or Φ cannot be lowered measurably at
    /// round-off level: converged.
    Converged,
    Continue,
}

impl Integrator {
    /// Newton's method on the incremental potential Φ (plus contact), from `y` in place.
    pub(super) fn newton(&mut self, step: &ImplicitStep, contacts: Option<&StepContacts>, y: &mut Vec<DVec3>, report: &mut StepReport) {
        let model = step.model;
        let mut problem = NewtonProblem::new(step, contacts, self.newton.tolerance, self.newton.error_share, self.last_step_error, !self.newton.retry_exact);
        let n = y.len();
        let mut work = NewtonWork {
            stiffness: model.stiffness_matrix(),
            bounded: model.stiffness_matrix(),
            gradient: vec![DVec3::ZERO; n],
            rhs: Vec::new(),
            direction: vec![DVec3::ZERO; n],
            trial: y.clone(),
            couplings: Vec::new(),
        };
        let mut history = NewtonHistory { bounded_throughout: self.newton.indefinite == Indefinite::Bound, ..NewtonHistory::default() };
        let mut watch = Stopwatch::start();
        report.newton_unconverged = true;
        for _ in 0..self.newton.max_iterations {
            if self.deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                break;
            }
            problem.update_tolerance(y);
            let norm = self.gradient(&problem, y, &mut work.gradient, &mut watch);
            work.rhs = work.gradient.iter().map(|g| -*g).collect();
            if let Some(length) = self.last_step_from_preconditioner(&problem, &history, norm, &mut work, y, &mut watch) {
                history.previous_step = Some(length);
                history.previous_direction = Some(length);
                report.newton_unconverged = false;
                break;
            }
            let bending = model.bending_newton_matrix(y);
            let cg_tolerance = self.forcing_tolerance(&history, norm, problem.tolerance);
            history.previous_norm = Some(norm);
            let truncated_before = report.truncated_solves;
            history.bounded_direction = self.solve_direction(&problem, &mut work, y, bending.as_deref(), cg_tolerance, &mut history.bounded_throughout, report, &mut watch);
            history.truncated = report.truncated_solves > truncated_before;
            if problem.all_free {
                keep_momentum(&problem.mass_diagonal, &work.gradient, &mut work.direction);
            }
            report.newton_iterations += 1;
            if let Progress::Converged = line_search(&problem, &mut work, &mut history, y, &mut watch) {
                report.newton_unconverged = false;
                break;
            }
        }
        report.timings += watch.timings;
        report.newton_residual = history.previous_direction.map_or(f64::INFINITY, |step| step / model.mean_edge_length);
        report.newton_tolerance = problem.tolerance / model.mean_edge_length;
    }

    /// ∇Φ at `y` into `gradient` (zero on fixed vertices), and its norm.
    pub(super) fn gradient(&mut self, problem: &NewtonProblem, y: &[DVec3], gradient: &mut [DVec3], watch: &mut Stopwatch) -> f64 {
        let step = problem.step;
        let ImplicitStep { model, fixed, .. } = *step;
        let n = y.len();
        self.forces.resize(n, DVec3::ZERO);
        model.forces(y, &mut self.forces);
        for i in 0..n {
            gradient[i] = if fixed[i] { DVec3::ZERO } else { step.inertial_gradient(i, y[i], self.forces[i]) };
        }
        watch.forces();
        if let Some(c) = problem.contacts {
            c.add_gradient(y, gradient, fixed);
            for (g, &f) in gradient.iter_mut().zip(fixed) {
                if f {
                    *g = DVec3::ZERO;
                }
            }
            watch.contact();
        }
        gradient.iter().map(|g| g.length_squared()).sum::<f64>().sqrt()
    }

    /// Newton stops at a step under the tolerance. Where the next step promises to be one,
    /// it is taken with the last preconditioner instead of being assembled and solved for:
    /// while Newton converges the step shrinks as the gradient does, so the last full step
    /// scaled by the gradient's decrease predicts it, and the preconditioner (a factor of a
    /// recent Newton matrix) gives it to within that factor's error. The step's length if it
    /// was taken (Newton has converged); otherwise the iteration goes on as usual. A converging
    /// Newton solve's last iteration would otherwise be a whole assembly and solve for a
    /// step under the tolerance.
    fn last_step_from_preconditioner(&self, problem: &NewtonProblem, history: &NewtonHistory, norm: f64, work: &mut NewtonWork, y: &mut [DVec3], watch: &mut Stopwatch) -> Option<f64> {
        let (Some(before), Some(full), Some(cached)) = (history.previous_norm, history.previous_full_step, self.preconditioner.as_ref()) else {
            return None;
        };
        if !(cached.fits(problem.step.fixed) && norm < 0.5 * before && full * norm / before < problem.tolerance) {
            return None;
        }
        cached.preconditioner.apply(&work.rhs, &mut work.direction);
        if problem.all_free {
            keep_momentum(&problem.mass_diagonal, &work.gradient, &mut work.direction);
        }
        let length = work.direction.iter().map(|d| d.length()).fold(0.0, f64::max);
        watch.solve();
        if length < problem.tolerance && problem.contacts.is_none_or(|c| c.step_limit(y, &work.direction) >= 1.0) {
            let fixed = problem.step.fixed;
            for (i, d) in work.direction.iter().enumerate() {
                if !fixed[i] {
                    y[i] += *d;
                }
            }
            return Some(length);
        }
        None
    }

    /// The relative residual to solve this iteration's linear system to.
    fn forcing_tolerance(&self, history: &NewtonHistory, norm: f64, tolerance: f64) -> f64 {
        if !self.newton.forcing {
            return self.newton.cg_tolerance;
        }
        // Eisenstat and Walker's safeguard against tightening too fast, 0.9·η²_{k−1},
        // only acts above 0.1, which this term never exceeds.
        let eta = history.previous_norm.map_or(0.1, |before| 0.9 * (norm / before).powi(2));
        // A solve need not be more exact than the tolerance Newton stops at: with
        // relative residual η the step misses Newton's by about η times its length,
        // which the last step's length scaled by the gradient's decrease predicts.
        // Solving to an error of a tenth of the tolerance is enough; tighter solves
        // of the last, sub-tolerance step would spend CG iterations on digits Newton
        // throws away.
        let floor = match (history.previous_norm, history.previous_step) {
            (Some(before), Some(length)) if length > 0.0 && before > 0.0 => 0.1 * tolerance / (length * norm / before),
            _ => 0.0,
        };
        eta.max(floor).clamp(self.newton.cg_tolerance, 0.1)
    }

    /// Solves Newton's system for `work.direction`.
    ///
    /// Newton's matrix takes the exact Hessian of the compressed edges: a buckling cloth's
    /// softening is what makes Newton converge quadratically. Where it outweighs inertia and
    /// bending the matrix is indefinite. With the incomplete factor (coarse meshes) CG then
    /// meets a direction of negative curvature or returns no descent, and the solve is
    /// repeated with the softening bounded so that the matrix stays positive definite. With a
    /// global preconditioner (fine meshes) the exact matrix is shifted instead
    /// (`solve_shifted`). Returns whether the direction was solved on the bounded matrix.
    #[allow(clippy::too_many_arguments)]
    fn solve_direction(
        &mut self,
        problem: &NewtonProblem,
        work: &mut NewtonWork,
        y: &[DVec3],
        bending: Option<&ScalarCsr>,
        cg_tolerance: f64,
        bounded_throughout: &mut bool,
        report: &mut StepReport,
        watch: &mut Stopwatch,
    ) -> bool {
        if let Some(c) = problem.contacts {
            work.couplings.clear();
            c.couplings(y, &mut work.couplings);
            watch.contact();
        }
        // Once this step has given up the exact matrix (`NewtonSettings::retry_exact`
        // decides for the incomplete factor), only the bounded one is assembled, where the
        // solve needs it.
        let global = self.newton.preconditioner.global(y.len()).is_some();
        let exact_first = !*bounded_throughout || (!global && self.newton.retry_exact);
        if exact_first {
            problem.assemble(y, &mut work.stiffness, CompressedEdges::Exact);
            watch.forces();
        }
        let system = SystemMatrix { mass_diagonal: &problem.mass_diagonal, stiffness: &work.stiffness, bending, fixed: problem.step.fixed, couplings: &work.couplings };
        if global {
            self.solve_global(problem, &system, &mut work.bounded, y, &work.rhs, &mut work.direction, cg_tolerance, bounded_throughout, report, watch);
            *bounded_throughout
        } else {
            self.solve_incomplete(problem, &system, &mut work.bounded, y, &work.gradient, &work.rhs, &mut work.direction, cg_tolerance, exact_first, bounded_throughout, report, watch)
        }
    }
}

/// Backtracking line search on Φ along `work.direction` (with a steepest-descent fallback
/// where the solve gave no descent), extended past a full step where Φ is flatter than the
/// matrix says; moves `y` to the accepted point.
fn line_search(problem: &NewtonProblem, work: &mut NewtonWork, history: &mut NewtonHistory, y: &mut Vec<DVec3>, watch: &mut Stopwatch) -> Progress {
    let model = problem.step.model;
    let n = y.len();
    let (gradient, direction) = (&work.gradient, &mut work.direction);
    let slope: f64 = gradient.iter().zip(direction.iter()).map(|(g, d)| g.dot(*d)).sum();
    if slope >= 0.0 {
        // Not a descent direction (the CG broke down): fall back to steepest descent
        // scaled by the mass term.
        for i in 0..n {
            direction[i] = if problem.step.fixed[i] { DVec3::ZERO } else { -gradient[i] / problem.mass_diagonal[i] };
        }
    }
    let slope: f64 = gradient.iter().zip(direction.iter()).map(|(g, d)| g.dot(*d)).sum();
    // Φ at the current iterate is the previous iteration's accepted trial value.
    let phi0 = *history.phi_current.get_or_insert_with(|| problem.objective(y));
    let limit = problem.contacts.map_or(f64::INFINITY, |c| c.step_limit(y, direction));
    let mut alpha = limit.min(1.0);
    let mut accepted = false;
    let mut phi = phi0;
    let trial = &mut work.trial;
    // Where the decrease a full step promises, −Φ'(0), is within Φ's own rounding, no trial
    // can tell a better point from a worse one: the backtracking then accepts or refuses
    // steps of 10⁻⁹ by the sign of round-off and Newton repeats the same direction until its
    // iteration limit (the 20 463-triangle drape on its exact path, a 0.6 µm direction
    // against a 0.035 µm tolerance, docs/performance-log.md). The step is then taken whole
    // (short of any cloth–cloth pair) and the next iteration judges it.
    let unresolvable = -slope <= ROUNDOFF_ULPS * f64::EPSILON * phi0.abs();
    for _ in 0..30 {
        for i in 0..n {
            trial[i] = y[i] + alpha * direction[i];
        }
        phi = problem.objective(trial);
        if phi.is_finite() && (unresolvable || phi <= phi0 + 1e-4 * alpha * slope) {
            accepted = true;
            break;
        }
        alpha *= 0.5;
    }
    let length = direction.iter().map(|d| d.length()).fold(0.0, f64::max);
    if accepted && alpha == 1.0 && length > 10.0 * problem.tolerance {
        // Where Φ is flatter along d than the matrix says, a full step is accepted yet falls
        // short of the minimum along d. The parabola through Φ(0), Φ'(0) and Φ(1) places that
        // minimum; a step towards it (at most EXTRAPOLATION times the full step, short of any
        // cloth–cloth pair and of a tenth of an edge per vertex) is kept if Φ is lower there.
        // On a quadratic Φ with Newton's direction the parabola's minimum is at 1 and nothing
        // is tried. It is meant for fine meshes, where Newton can otherwise creep in tiny
        // steps along the soft modes.
        let curvature = 2.0 * (phi - phi0 - slope);
        let best = if curvature > 0.0 { -slope / curvature } else { f64::INFINITY };
        let reach = 0.1 * model.mean_edge_length / length;
        let target = best.min(EXTRAPOLATION).min(0.9 * limit).min(reach);
        if target > 1.5 {
            let further: Vec<DVec3> = (0..n).map(|i| y[i] + target * direction[i]).collect();
            let phi_further = problem.objective(&further);
            if phi_further < phi {
                alpha = target;
                phi = phi_further;
                *trial = further;
            }
        }
    }
    history.phi_current = Some(phi).filter(|_| accepted);
    watch.forces();
    let step_size = alpha * length;
    // On the bounded matrix Newton converges linearly along the buckling modes: directions
    // shrinking by θ per iteration leave the solution about θ/(1 − θ) times the last one
    // away, more than the last direction itself once θ > ½ (the stopping test of a
    // simplified Newton iteration, docs/solvers.md). A landing cloth's bounded iterations
    // shrink by 0.85–0.95 near the end: stopped at the last direction's length they are
    // several tolerances short. Where the path decides the result (drops, with
    // `retry_exact` off) that is judged; on a slowly loaded drape it cost the 20k drape a
    // sixth more time for the same drape (docs/fast-path.md). A direction from the exact
    // matrix converges quadratically, and its own length is the honest test.
    let remaining = match history.previous_direction {
        Some(before) if problem.judge_contraction && history.bounded_direction && length < before => {
            let theta = length / before;
            length * theta / (1.0 - theta)
        }
        _ => 0.0,
    };
    history.previous_step = Some(step_size);
    history.previous_full_step = Some(length).filter(|_| accepted && alpha == 1.0 && !history.truncated);
    history.previous_direction = Some(length);
    // Newton has converged when its whole step is under the tolerance, not the part of it
    // the line search or a cloth–cloth pair's step limit let it take: a step cut to a
    // tenth by a pair about to meet, or halved where Φ is not convex, can be under the
    // tolerance while the solution is still many tolerances away (the sphere drop's
    // landing steps stopped up to 60 tolerances short that way; docs/performance-log.md).
    if !accepted {
        // Φ cannot be decreased measurably: at round-off level we are converged; otherwise
        // take the smallest tried step and let the iteration limit speak.
        if length < 10.0 * problem.tolerance {
            return Progress::Converged;
        }
    }
    std::mem::swap(y, trial);
    if !history.truncated && length.max(step_size).max(remaining) < problem.tolerance { Progress::Converged } else { Progress::Continue }
}

/// With nothing fixed and nothing touched, corrects a Newton direction d so that momentum
/// is conserved to round-off whatever the solve's error. The elastic Hessian annihilates
/// translations, so adding a constant c to d changes only the mass term of H d; choosing c
/// so that Σ M (d + c) = −Σ g removes the net force the residual would leave.
pub(super) fn keep_momentum(mass_diagonal: &[f64], gradient: &[DVec3], direction: &mut [DVec3]) {
    let (mut mass_sum, mut residual) = (0.0, DVec3::ZERO);
    for ((&m, &g), &d) in mass_diagonal.iter().zip(gradient).zip(direction.iter()) {
        mass_sum += m;
        residual += g + m * d;
    }
    let shift = -residual / mass_sum;
    direction.iter_mut().for_each(|d| *d += shift);
}
