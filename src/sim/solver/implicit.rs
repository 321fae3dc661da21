//! The implicit step: implicit Euler and BDF2 as one minimisation of the incremental
//! potential, with contact inside it.

use super::report::{Stopwatch, StepReport};
use super::{Integrator, State};
use crate::sim::contact::HOLD_MARGIN;
use crate::sim::model::Model;
use glam::DVec3;
use std::borrow::Cow;

impl Integrator {
    /// One implicit Euler (or, with `bdf2` and a history, BDF2) step of `s`, in place.
    pub(super) fn implicit(&mut self, model: &Model, s: &mut State, bdf2: bool) -> StepReport {
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
        let start_velocity = s.v.clone();
        let holding = model.contact.as_ref().is_some_and(|c| c.settings.hold_sticking) && self.newton.minimizer == super::Minimizer::Newton;
        let fixed = step_fixed(model, &mut s.held, holding);
        let fixed = &*fixed;
        let step = ImplicitStep { model, h, dt, anchor: &anchor, inertial: &inertial, velocity: &start_velocity, fixed };
        let prescribe = |mut y: Vec<DVec3>| {
            for (i, yi) in y.iter_mut().enumerate() {
                if model.fixed[i] {
                    *yi = model.prescribed_position(i, t_next);
                } else if fixed[i] {
                    *yi = s.x[i];
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
            None => self.minimize(&step, None, &mut y, &mut report),
            Some(contact) => {
                let mut watch = Stopwatch::start();
                // The prediction includes gravity's pull over the step, so that contacts a
                // falling cloth is about to make are there from the first iteration.
                let predicted: Vec<DVec3> = (0..n).map(|i| inertial[i] + h * h * model.options.gravity).collect();
                let cloth = crate::sim::contact::Cloth { fixed, ..model.cloth() };
                let mut contacts = contact.begin_step(cloth, &mut self.near_pairs, &s.x, &s.stuck, &predicted, h);
                // Newton's path must start where the cloth is: jumping straight to the
                // inertial guess could carry a vertex through a layer before any contact
                // force acts. Start from x_n moved towards the guess as far as no cloth–cloth
                // pair can meet.
                if contacts.pair_count() > 0 {
                    let guess: Vec<DVec3> = (0..n).map(|i| if fixed[i] { DVec3::ZERO } else { y[i] - s.x[i] }).collect();
                    let alpha = contacts.max_step(&s.x, &guess);
                    for i in 0..n {
                        if !fixed[i] {
                            y[i] = s.x[i] + alpha * guess[i];
                        }
                    }
                }
                watch.contact();
                // Solve; a path that enters a prop without a plane adds one, a vertex that
                // ended inside a prop renews its plane there, and the step is solved again.
                for pass in 0..4 {
                    self.minimize(&step, Some(&contacts), &mut y, &mut report);
                    watch.restart();
                    let mut changed = contact.add_missed(&mut contacts, cloth, &s.x, &s.stuck, &y, h);
                    if pass < 2 {
                        // Planes are renewed twice at most: a vertex still inside after
                        // that is left to the penetration measure, not to the step's
                        // convergence.
                        changed += contact.refresh_planes(&mut contacts, cloth, &y);
                    }
                    watch.contact();
                    if changed == 0 {
                        break;
                    }
                    self.contact_stats.resolves += 1;
                    if pass == 3 {
                        report.newton_unconverged = true;
                    }
                }
                contacts.stuck_after(&y, &mut s.stuck);
                if holding {
                    self.hold_sticking(&step, &contacts, &y, &mut s.held);
                    watch.contact();
                }
                report.timings += watch.timings;
                step_contacts = Some(contacts);
            }
        }
        let mut previous = (s.x.clone(), s.v.clone());
        let start = s.x.clone();
        self.last_step_error = step.local_error(&y);
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
            let mut watch = Stopwatch::start();
            self.finish_contact(model, contact, &start, s);
            watch.contact();
            report.timings += watch.timings;
        }
        s.previous = Some(previous);
        report
    }
}

/// The step's prescribed vertices: the model's, and those `held` where they stick to a prop
/// (all released where the scene does not hold them).
fn step_fixed<'a>(model: &'a Model, held: &mut Vec<Option<DVec3>>, holding: bool) -> Cow<'a, [bool]> {
    held.resize(model.fixed.len(), None);
    if !holding {
        held.fill(None);
    }
    if held.iter().any(Option::is_some) {
        Cow::Owned(model.fixed.iter().zip(held.iter()).map(|(&f, h)| f || h.is_some()).collect())
    } else {
        Cow::Borrowed(&model.fixed)
    }
}

impl Integrator {
    /// Which vertices the next step holds (`ContactSettings::hold_sticking`), into `held`:
    /// one held over this step stays held while the force holding it, −∂Φ/∂y without
    /// contact, pushes it against the prop's surface and lies within `HOLD_MARGIN` of
    /// Coulomb's cone about it (|f_t| ≤ margin·μ_s·f_n); one not held is held from the next
    /// step where it ends this one sticking with its friction within that margin.
    fn hold_sticking(&mut self, step: &ImplicitStep, contacts: &crate::sim::contact::StepContacts, y: &[DVec3], held: &mut Vec<Option<DVec3>>) {
        let model = step.model;
        let Some(contact) = &model.contact else { return };
        let mu = contact.settings.friction_static;
        let n = y.len();
        let mut next = vec![None; n];
        if held.iter().any(Option::is_some) {
            self.forces.resize(n, DVec3::ZERO);
            model.forces(y, &mut self.forces);
            for i in 0..n {
                let Some(normal) = held[i] else { continue };
                let holding = step.inertial_gradient(i, y[i], self.forces[i]);
                let push = holding.dot(normal);
                if push > 0.0 && (holding - push * normal).length() <= HOLD_MARGIN * mu * push {
                    next[i] = Some(normal);
                }
            }
        }
        for (v, normal) in contacts.sticking(y, HOLD_MARGIN) {
            next[v as usize] = Some(normal);
        }
        *held = next;
    }

    /// Minimises Φ from `y` with the step's method: Newton, or the quasi-Newton step with
    /// Newton finishing what it has not converged (its linear convergence is slow where
    /// the tolerance is tight, as when the cloth comes to rest; Newton's is quadratic from
    /// a start that close).
    fn minimize(&mut self, step: &ImplicitStep, contacts: Option<&crate::sim::contact::StepContacts>, y: &mut Vec<DVec3>, report: &mut StepReport) {
        match self.newton.minimizer {
            super::Minimizer::Newton => self.newton(step, contacts, y, report),
            super::Minimizer::QuasiNewton => {
                if !self.quasi_newton(step, contacts, y, report) {
                    self.newton(step, contacts, y, report);
                }
            }
        }
    }
}

/// What one implicit step minimises over: Φ's inertial target x̃, the anchor x̂ of the
/// step's velocity, and the effective step h.
#[derive(Clone, Copy)]
pub(super) struct ImplicitStep<'a> {
    pub model: &'a Model,
    pub h: f64,
    /// The time step Δt, s (h is 2Δt/3 for BDF2).
    pub dt: f64,
    pub anchor: &'a [DVec3],
    pub inertial: &'a [DVec3],
    /// Velocities at the start of the step, m/s.
    pub velocity: &'a [DVec3],
    /// The step's prescribed vertices: the model's fixed ones and those held where they
    /// stick to a prop (`ContactSettings::hold_sticking`).
    pub fixed: &'a [bool],
}

impl ImplicitStep<'_> {
    /// Implicit Euler's local error estimate ½Δt·max|v_{n+1} − v_n| of the step were it to
    /// end at `y` (v_{n+1} = (y − x̂)/h), m; over the free vertices.
    pub fn local_error(&self, y: &[DVec3]) -> f64 {
        (0..y.len())
            .filter(|&i| !self.fixed[i])
            .map(|i| 0.5 * self.dt * ((y[i] - self.anchor[i]) / self.h - self.velocity[i]).length())
            .fold(0.0, f64::max)
    }

    /// ∂Φ/∂y at vertex `i` without contact, m/h²(y − x̃) + ζm/h(y − x̂) − f, for the vertex
    /// at `y` with the elastic forces and gravity `force` on it: what holds a prescribed
    /// vertex where it is, and Newton's and quasi-Newton's gradient on a free one.
    #[inline]
    pub fn inertial_gradient(&self, i: usize, y: DVec3, force: DVec3) -> DVec3 {
        let (model, h) = (self.model, self.h);
        let m = model.mass[i];
        m / (h * h) * (y - self.inertial[i]) + model.options.damping * m / h * (y - self.anchor[i]) - force
    }

    /// The incremental potential Φ at `y` without contact.
    pub fn potential(&self, y: &[DVec3]) -> f64 {
        let (model, h) = (self.model, self.h);
        let zeta = model.options.damping;
        let inertia: f64 = (0..y.len())
            .filter(|&i| !self.fixed[i])
            .map(|i| {
                let m = model.mass[i];
                m / (2.0 * h * h) * (y[i] - self.inertial[i]).length_squared()
                    + zeta * m / (2.0 * h) * (y[i] - self.anchor[i]).length_squared()
            })
            .sum();
        inertia + model.potential_energy(y)
    }
}
