//! Symplectic Euler, the explicit integrator.

use super::Integrator;
use super::State;
use super::report::{StepReport, Stopwatch};
use crate::sim::model::Model;
use glam::DVec3;

impl Integrator {
    /// v ← (v + Δt f/m) / (1 + ζΔt); x ← x + Δt v. Damping is taken implicitly so that it
    /// never limits the step; fixed vertices follow their prescribed motion.
    pub(super) fn symplectic_euler(&mut self, model: &Model, s: &mut State) -> StepReport {
        let dt = self.dt;
        let mut watch = Stopwatch::start();
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
        watch.forces();
        // A step that blew up is left for `check` to reject: its paths can span the scene
        // many times over, and sweeping them for collisions would take forever.
        let blown_up = model.outrunning_vertex(&s.v).is_some();
        if let Some(contact) = model.contact.as_ref().filter(|_| !blown_up) {
            contact.project_explicit(&start, &mut s.x, &mut s.v, &model.fixed);
            self.finish_contact(model, contact, &start, s);
            watch.contact();
        }
        s.previous = None;
        StepReport { timings: watch.timings, ..StepReport::default() }
    }
}
