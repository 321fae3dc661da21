//! The quasi-Newton step for cloth in motion: the same incremental potential Φ as Newton's
//! (`newton.rs`), minimised by L-BFGS whose initial inverse Hessian is a constant matrix
//! factored once per scene and time step (Liu, Bouaziz and Kavan 2017,
//! docs/references.md).
//!
//! The constant matrix is S ⊗ I₃ with S = M(1/h² + ζ/h) + the membrane's rest stiffness
//! made isotropic + the bending matrix Q (`Model::quasi_newton_matrix`): the matrix of
//! projective dynamics for this model. It does not change as the cloth moves, rotates or
//! buckles, so it needs no assembly and no factorisation per iteration, and it is positive
//! definite by construction: a buckling cloth, whose exact Hessian is indefinite along the
//! buckling modes, costs Newton shifted or bounded matrices and refactorisations
//! (docs/fast-path.md); here it costs nothing extra. What S misses (the tangent stiffness's
//! change with the strain, the softening of compressed edges, contact and friction) the
//! L-BFGS pairs (s, Δ∇Φ) of the last iterations correct. Each iteration costs one gradient,
//! one energy per line-search trial and one solve with the factor.
//!
//! Convergence is judged as Newton's is: the step the method predicts (its direction,
//! whose length estimates the distance to the minimum) and, while iterations contract by θ
//! per iteration, that length times θ/(1 − θ), must be under the step's tolerance.

use super::implicit::ImplicitStep;
use super::newton::{NewtonProblem, keep_momentum};
use super::report::{StepReport, Stopwatch};
use super::Integrator;
use crate::sim::contact::StepContacts;
use crate::sim::linalg::{ScalarCsr, ScalarFactor, ScalarPattern};
use glam::DVec3;
use std::collections::VecDeque;

/// The quasi-Newton step's matrix for one model: its constant part and pattern (made
/// once) and the current step's factor.
pub(super) struct StepMatrices {
    /// The membrane's isotropic rest stiffness and the one-ring bending matrix
    /// (`Model::quasi_newton_matrices`), summed.
    constant: ScalarCsr,
    pattern: ScalarPattern,
    factor: Option<ScalarFactor>,
    vertices: usize,
}

/// The largest contraction factor the convergence test assumes: a step is taken to be at
/// most 1/(1 − 0.97) = 33 times the distance still to go.
const MAX_THETA: f64 = 0.97;

/// The fewest iterations the quasi-Newton step gets before Newton takes over.
const MIN_BUDGET: usize = 4;

/// The longest step the line search takes along a direction, in multiples of it.
const MAX_STRETCH: f64 = 16.0;

/// The lengths of the last steps, and from them how fast the iteration converges.
#[derive(Default)]
struct Contraction {
    lengths: VecDeque<f64>,
}

impl Contraction {
    /// Steps over which the contraction factor is measured.
    const WINDOW: usize = 6;

    fn push(&mut self, length: f64) {
        if self.lengths.len() == Self::WINDOW + 1 {
            self.lengths.pop_front();
        }
        self.lengths.push_back(length);
    }

    /// The distance a step of `length` and the steps after it cover, were each θ times the
    /// one before: length/(1 − θ), θ the geometric mean of the last steps' ratios (L-BFGS
    /// steps shrink unevenly; the mean over a window is steadier than the last ratio). With
    /// no ratio measured yet, or steps not shrinking, θ is taken as `MAX_THETA`: a single
    /// short step is not taken as convergence, as linear convergence with θ near 1 would be
    /// many such steps from the minimum.
    fn distance(&self, length: f64) -> f64 {
        // L-BFGS steps shrink unevenly: a short step among longer ones is not the
        // iteration's pace, so the longest over the window stands for it (stopped at the
        // step itself, steps on a crumpled sheet at 1 ms ended up to 1.13 tolerances from
        // the converged one; at the window's longest, 0.64; tests/conservation.rs).
        let longest = self.lengths.iter().fold(length, |a, &b| a.max(b));
        longest / (1.0 - self.theta().unwrap_or(MAX_THETA).min(MAX_THETA))
    }

    /// The geometric mean of the last steps' ratios, once there are two steps.
    fn theta(&self) -> Option<f64> {
        match (self.lengths.front(), self.lengths.back()) {
            (Some(&first), Some(&last)) if self.lengths.len() > 1 && first > 0.0 => Some((last / first).powf(1.0 / (self.lengths.len() - 1) as f64)),
            _ => None,
        }
    }

}

/// One L-BFGS pair: the step s, the change of the gradient over it, and 1/(s·Δg).
struct Pair {
    s: Vec<DVec3>,
    dg: Vec<DVec3>,
    rho: f64,
}

impl StepMatrices {
    /// z = (S ⊗ I₃)⁻¹ r.
    fn apply(&self, r: &[DVec3], z: &mut [DVec3]) {
        self.factor.as_ref().expect("factored for the step").solve(&self.pattern, r, z);
    }
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

fn max_length(d: &[DVec3]) -> f64 {
    d.iter().map(|v| v.length()).fold(0.0, f64::max)
}

impl Integrator {
    /// Factors this step's matrix at `y`, the step's start: the constant part, the inertia
    /// M(1/h² + ζ/h) and contact's stiffness in its stiffest direction. False if that fails
    /// (non-finite input).
    fn factor_step_matrix(&mut self, problem: &NewtonProblem, y: &[DVec3], report: &mut StepReport) -> bool {
        let model = problem.step.model;
        let n = model.vertex_count();
        if self.quasi.as_ref().is_none_or(|c| c.vertices != n) {
            let (mut constant, bending) = model.quasi_newton_matrices();
            for (v, b) in constant.values.iter_mut().zip(&bending.values) {
                *v += b;
            }
            let Some(pattern) = ScalarPattern::new(&constant, problem.step.fixed) else { return false };
            self.quasi = Some(StepMatrices { constant, pattern, factor: None, vertices: n });
        }
        let quasi = self.quasi.as_mut().expect("made above");
        let mut diagonal = problem.mass_diagonal.clone();
        if let Some(c) = problem.contacts {
            c.add_isotropic_stiffness(y, &mut diagonal);
        }
        quasi.factor = ScalarFactor::new(&quasi.pattern, &diagonal, &quasi.constant);
        report.factorizations += 1;
        quasi.factor.is_some()
    }

    /// Minimises Φ (plus contact) from `y` in place by L-BFGS on the step's factor, for at
    /// most `quasi_newton_iterations`. Whether it converged.
    pub(super) fn quasi_newton(&mut self, step: &ImplicitStep, contacts: Option<&StepContacts>, y: &mut Vec<DVec3>, report: &mut StepReport) -> bool {
        let model = step.model;
        let mut problem = NewtonProblem::new(step, contacts, self.newton.tolerance, self.newton.error_share, self.last_step_error, true);
        let mut watch = Stopwatch::start();
        if !self.factor_step_matrix(&problem, y, report) {
            // S is positive definite by construction; a failure means non-finite input.
            return false;
        }
        watch.solve();
        let n = y.len();
        let memory = self.newton.quasi_newton_history.max(1);
        let mut pairs: VecDeque<Pair> = VecDeque::with_capacity(memory);
        let mut gradient = vec![DVec3::ZERO; n];
        let mut trial = vec![DVec3::ZERO; n];
        let mut trial_gradient = vec![DVec3::ZERO; n];
        let mut direction = vec![DVec3::ZERO; n];
        let mut phi = self.evaluate(&problem, y, &mut gradient, &mut watch);
        let mut steps = Contraction::default();
        let mut stretch = 1.0f64;
        let mut extra = vec![DVec3::ZERO; n];
        let mut extra_gradient = vec![DVec3::ZERO; n];
        let mut last_estimate = f64::INFINITY;
        report.newton_unconverged = true;
        let budget = self.quasi_budget.min(self.newton.quasi_newton_iterations).max(MIN_BUDGET);
        for _ in 0..budget {
            problem.update_tolerance(y);
            self.lbfgs_direction(&pairs, &gradient, &mut direction, &mut watch);
            if problem.all_free {
                keep_momentum(&problem.mass_diagonal, &gradient, &mut direction);
            }
            let mut slope = dot(&gradient, &direction);
            if slope >= 0.0 {
                // The pairs no longer describe Φ here: start afresh from the constant matrix.
                pairs.clear();
                self.lbfgs_direction(&pairs, &gradient, &mut direction, &mut watch);
                if problem.all_free {
                    keep_momentum(&problem.mass_diagonal, &gradient, &mut direction);
                }
                slope = dot(&gradient, &direction);
                if slope >= 0.0 {
                    break;
                }
            }
            let length = max_length(&direction);
            // How far the minimum still is, as far as the method can tell: the direction,
            // stretched by as much as the last line search had to extend its direction, and
            // what the steps after it would add while they contract as they have.
            let predicted = length * stretch;
            last_estimate = steps.distance(predicted);
            report.quasi_newton_iterations += 1;
            let limit = problem.contacts.map_or(f64::INFINITY, |c| c.step_limit(y, &direction));
            watch.contact();
            if last_estimate < problem.tolerance && limit >= 1.0 {
                // The predicted step is under the tolerance: take it and stop.
                for i in 0..n {
                    y[i] += direction[i];
                }
                report.newton_unconverged = false;
                break;
            }
            // Backtracking (Armijo) on Φ, short of any cloth–cloth pair meeting; Φ and its
            // gradient are evaluated together at each trial.
            let accepted = self.backtrack(&problem, y, &direction, (phi, slope), limit.min(1.0), (&mut trial, &mut trial_gradient), &mut watch);
            let Some((mut alpha, mut value)) = accepted else {
                // Φ cannot be lowered along the direction: round-off level if it is short.
                // A short direction is still taken: it changes Φ by round-off, and on a free
                // sheet it leaves no net force (momentum is kept).
                if pairs.is_empty() {
                    report.newton_unconverged = length >= problem.tolerance;
                    if !report.newton_unconverged {
                        for i in 0..n {
                            y[i] += direction[i];
                        }
                    }
                    break;
                }
                pairs.clear();
                continue;
            };
            if alpha == 1.0 {
                // Where Φ still falls steeply at the full step, the direction was short (the
                // constant matrix is stiffer than Φ along it): the secant of the slopes at 0
                // and 1 places the minimum along d, and a step there is kept if Φ is lower.
                (alpha, value) = self.extend(&problem, y, &direction, slope, limit, value, &mut trial, &mut trial_gradient, &mut extra, &mut extra_gradient, &mut watch);
            }
            stretch = alpha.max(1.0);
            let step_length = alpha * length;
            steps.push(step_length);
            remember(&mut pairs, memory, y, &trial, &gradient, &trial_gradient);
            std::mem::swap(y, &mut trial);
            std::mem::swap(&mut gradient, &mut trial_gradient);
            phi = value;
            // The step taken is judged as Newton's is, by the distance it and the steps
            // after it would still cover.
            let left = steps.distance(step_length);
            if left < problem.tolerance {
                last_estimate = left;
                report.newton_unconverged = false;
                break;
            }
        }
        report.timings += watch.timings;
        report.newton_residual = last_estimate / model.mean_edge_length;
        report.newton_tolerance = problem.tolerance / model.mean_edge_length;
        // The next step's budget: halved after a solve Newton had to finish, doubled after
        // one converged, so that a cloth coming to rest, whose tight tolerances the linear
        // convergence of L-BFGS reaches slowly, spends little before Newton takes over,
        // while a moving one keeps the whole budget.
        self.quasi_budget = if report.newton_unconverged { budget / 2 } else { 2 * budget }.clamp(MIN_BUDGET, self.newton.quasi_newton_iterations.max(MIN_BUDGET));
        !report.newton_unconverged
    }

    /// Backtracking (Armijo) from `y` along `direction` (Φ and its slope there in `start`),
    /// from the step `alpha`: the first step that lowers Φ enough, as (step, Φ), with the
    /// point and its gradient left in `at`; None where 30 halvings do not.
    #[allow(clippy::too_many_arguments)]
    fn backtrack(
        &mut self,
        problem: &NewtonProblem,
        y: &[DVec3],
        direction: &[DVec3],
        start: (f64, f64),
        mut alpha: f64,
        at: (&mut Vec<DVec3>, &mut Vec<DVec3>),
        watch: &mut Stopwatch,
    ) -> Option<(f64, f64)> {
        let ((phi, slope), (trial, trial_gradient)) = (start, at);
        for _ in 0..30 {
            for i in 0..y.len() {
                trial[i] = y[i] + alpha * direction[i];
            }
            let value = self.evaluate(problem, trial, trial_gradient, watch);
            if value.is_finite() && value <= phi + 1e-4 * alpha * slope {
                return Some((alpha, value));
            }
            alpha *= 0.5;
        }
        None
    }

    /// After a full step accepted at `trial` (Φ = `value`, gradient `trial_gradient`): where
    /// Φ's slope along d there is still more than a quarter of its slope at the start, the
    /// direction fell short. The secant of the two slopes places the minimum along d; a step
    /// there (at most `MAX_STRETCH` times d, short of any cloth–cloth pair) replaces the trial
    /// if Φ is lower, and is extended again the same way. Returns the step's multiple of d
    /// and Φ there.
    #[allow(clippy::too_many_arguments)]
    fn extend(
        &mut self,
        problem: &NewtonProblem,
        y: &[DVec3],
        direction: &[DVec3],
        slope: f64,
        limit: f64,
        mut value: f64,
        trial: &mut Vec<DVec3>,
        trial_gradient: &mut Vec<DVec3>,
        extra: &mut Vec<DVec3>,
        extra_gradient: &mut Vec<DVec3>,
        watch: &mut Stopwatch,
    ) -> (f64, f64) {
        let mut alpha = 1.0;
        for _ in 0..4 {
            let slope_here = dot(trial_gradient, direction);
            if slope_here > 0.25 * slope {
                break;
            }
            let target = (alpha * slope / (slope - slope_here)).min(MAX_STRETCH).min(0.9 * limit);
            if target <= 1.5 * alpha {
                break;
            }
            for i in 0..y.len() {
                extra[i] = y[i] + target * direction[i];
            }
            let further = self.evaluate(problem, extra, extra_gradient, watch);
            if !(further.is_finite() && further < value) {
                break;
            }
            std::mem::swap(trial, extra);
            std::mem::swap(trial_gradient, extra_gradient);
            (alpha, value) = (target, further);
        }
        (alpha, value)
    }

    /// Φ (contact included) at `y`, and its gradient into `gradient` (zero on fixed
    /// vertices), from one pass over the elements.
    fn evaluate(&mut self, problem: &NewtonProblem, y: &[DVec3], gradient: &mut [DVec3], watch: &mut Stopwatch) -> f64 {
        let ImplicitStep { model, h, anchor, inertial, .. } = *problem.step;
        let zeta = model.options.damping;
        self.forces.resize(y.len(), DVec3::ZERO);
        let mut phi = model.energy_and_forces(y, &mut self.forces);
        for i in 0..y.len() {
            gradient[i] = if problem.step.fixed[i] {
                DVec3::ZERO
            } else {
                let m = model.mass[i];
                let (to_inertial, to_anchor) = (y[i] - inertial[i], y[i] - anchor[i]);
                phi += m / (2.0 * h * h) * to_inertial.length_squared() + zeta * m / (2.0 * h) * to_anchor.length_squared();
                problem.step.inertial_gradient(i, y[i], self.forces[i])
            };
        }
        watch.forces();
        if let Some(c) = problem.contacts {
            phi += c.energy_and_gradient(y, gradient, problem.step.fixed);
            for (g, &f) in gradient.iter_mut().zip(problem.step.fixed) {
                if f {
                    *g = DVec3::ZERO;
                }
            }
            watch.contact();
        }
        phi
    }

    /// The L-BFGS direction −H∇Φ by the two-loop recursion, H₀ = (S ⊗ I₃)⁻¹.
    fn lbfgs_direction(&self, pairs: &VecDeque<Pair>, gradient: &[DVec3], direction: &mut [DVec3], watch: &mut Stopwatch) {
        let mut q: Vec<DVec3> = gradient.to_vec();
        let mut alphas = vec![0.0; pairs.len()];
        for (k, p) in pairs.iter().enumerate().rev() {
            let a = p.rho * dot(&p.s, &q);
            alphas[k] = a;
            for (qi, dgi) in q.iter_mut().zip(&p.dg) {
                *qi -= a * *dgi;
            }
        }
        watch.forces();
        self.quasi.as_ref().expect("made before the iterations").apply(&q, direction);

        watch.solve();
        for (k, p) in pairs.iter().enumerate() {
            let b = p.rho * dot(&p.dg, direction);
            for (di, si) in direction.iter_mut().zip(&p.s) {
                *di += (alphas[k] - b) * *si;
            }
        }
        for d in direction.iter_mut() {
            *d = -*d;
        }
        watch.forces();
    }
}

/// Keeps the step from `y` to `trial` and its change of gradient as an L-BFGS pair, the
/// oldest dropped past `memory`, where its curvature is positive (a pair without it would
/// make the inverse estimate indefinite).
fn remember(pairs: &mut VecDeque<Pair>, memory: usize, y: &[DVec3], trial: &[DVec3], gradient: &[DVec3], trial_gradient: &[DVec3]) {
    let s: Vec<DVec3> = y.iter().zip(trial).map(|(a, b)| b - a).collect();
    let dg: Vec<DVec3> = gradient.iter().zip(trial_gradient).map(|(a, b)| b - a).collect();
    let curvature = dot(&s, &dg);
    if curvature > 1e-12 * dot(&s, &s).sqrt() * dot(&dg, &dg).sqrt() && curvature > 0.0 {
        if pairs.len() == memory {
            pairs.pop_front();
        }
        pairs.push_back(Pair { s, dg, rho: 1.0 / curvature });
    }
}

