//! Adaptive time steps: implicit Euler's local error sets the next Δt.

use super::{AdaptiveStep, Integrator, State, StepError, StepReport};
use crate::sim::model::Model;

impl Integrator {
    /// One step whose Δt the adaptive control chooses, retried smaller where its error or
    /// its Newton solve says so. On error `state` is unchanged.
    pub(super) fn adaptive_step(&mut self, model: &Model, state: &mut State, adaptive: AdaptiveStep) -> Result<StepReport, StepError> {
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
}
