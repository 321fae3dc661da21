//! What a step reports: its cost, and why it was rejected.

use super::IntegratorKind;
use crate::sim::linalg::CgReport;
use serde::Serialize;
use std::time::Instant;
use thiserror::Error;

/// Why a step was rejected.
#[derive(Debug, Clone, Error, PartialEq)]
pub enum StepError {
    #[error(
        "the simulation diverged with {integrator} at dt = {dt:e} s (t = {time:.6} s): {reason}. \
         The last good state is kept. {}",
        divergence_advice(*.integrator)
    )]
    Diverged { integrator: IntegratorKind, dt: f64, time: f64, reason: String },
}

/// What to change after a divergence: an implicit integrator only where the run is not on
/// one already.
fn divergence_advice(integrator: IntegratorKind) -> &'static str {
    if integrator.is_explicit() {
        "Use a smaller solver.dt or an implicit integrator (solver.integrator = \"implicit-euler\")"
    } else {
        "Use a smaller solver.dt, or more damping (solver.damping)"
    }
}

/// What one step cost.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepReport {
    pub newton_iterations: usize,
    /// Iterations of the quasi-Newton step (`Minimizer::QuasiNewton`), before any Newton
    /// iterations that finished its solve.
    pub quasi_newton_iterations: usize,
    pub cg_iterations: usize,
    /// Preconditioners built (factorisations, complete or incomplete; failed ones included).
    pub factorizations: usize,
    /// Linear solves stopped at `NewtonSettings::cg_max_iterations` above their tolerance.
    pub truncated_solves: usize,
    /// True when Newton stopped at its iteration limit before reaching its tolerance.
    pub newton_unconverged: bool,
    /// Newton's last step (the largest vertex move) over the mean edge length: below
    /// `newton_tolerance` where Newton converged, 0 for the explicit integrator.
    pub newton_residual: f64,
    /// The tolerance this step's Newton solve stopped at, over the mean edge length:
    /// `NewtonSettings::tolerance`, or more where `NewtonSettings::error_share` loosened it.
    pub newton_tolerance: f64,
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

/// A step's Newton solve counts as converged when its last step was at most this many
/// times its tolerance: Newton itself accepts that much when its line search can no longer
/// lower the energy (round-off), so only a solve cut short by its iteration limit exceeds it.
pub const UNCONVERGED_FACTOR: f64 = 10.0;

impl StepReport {
    /// Whether the step's Newton solve converged (within `UNCONVERGED_FACTOR` of its
    /// tolerance; always for the explicit integrator).
    pub fn converged(&self) -> bool {
        self.newton_residual <= UNCONVERGED_FACTOR * self.newton_tolerance
    }

    /// Counts a linear solve: its CG iterations, and whether it stopped at the limit.
    pub(super) fn count_solve(&mut self, cg: &CgReport) {
        self.cg_iterations += cg.iterations;
        self.truncated_solves += usize::from(cg.stopped_short());
    }

    /// Adds another attempt's work (iterations and time).
    pub(super) fn add_work(&mut self, other: &StepReport) {
        self.newton_iterations += other.newton_iterations;
        self.quasi_newton_iterations += other.quasi_newton_iterations;
        self.cg_iterations += other.cg_iterations;
        self.factorizations += other.factorizations;
        self.truncated_solves += other.truncated_solves;
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

/// Charges the wall time since its last lap to one phase of a step.
pub(super) struct Stopwatch {
    clock: Instant,
    pub timings: StepTimings,
}

impl Stopwatch {
    pub fn start() -> Self {
        Self { clock: Instant::now(), timings: StepTimings::default() }
    }

    /// Seconds since the last lap (or the start), restarting the clock.
    fn lap(&mut self) -> f64 {
        let now = Instant::now();
        let seconds = (now - self.clock).as_secs_f64();
        self.clock = now;
        seconds
    }

    /// Restarts the clock without charging the time since the last lap to any phase.
    pub fn restart(&mut self) {
        self.clock = Instant::now();
    }

    pub fn forces(&mut self) {
        self.timings.forces += self.lap();
    }

    pub fn solve(&mut self) {
        self.timings.solve += self.lap();
    }

    pub fn contact(&mut self) {
        self.timings.contact += self.lap();
    }
}
