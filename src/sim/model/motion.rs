//! Prescribed motion: pinned and driven vertices, and the rigs' grip paths.

use super::Model;
use glam::DVec3;

/// Prescribed motion of a group of vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Straight line: displacement `velocity · clamp(t − start, 0, stop − start)`.
    Linear {
        /// Velocity while moving, m/s.
        velocity: DVec3,
        /// Time the motion starts, s.
        start: f64,
        /// Time the motion stops (the group then holds still), s.
        stop: f64,
    },
    /// Swing along a circle of `radius` in the xy plane, as the free end of a rigid link
    /// hinged below the group: displacement (R sin a, R cos a − R, 0) with
    /// a = `angular_speed` · min(t, stop). A trellis (picture-frame) shear.
    Swing {
        /// Link length, m.
        radius: f64,
        /// Rad/s.
        angular_speed: f64,
        /// Time the swing stops, s.
        stop: f64,
    },
    /// Rigid grip at the end of a strip rolled into an arc (pure bending, KES-B style): the
    /// strip's free length `length` from x = 0 along +x is wrapped onto a circle of
    /// curvature κ(t) = `curvature` · min(t / `ramp`, 1) curling towards +z, and the grip,
    /// whose rest x is ≥ `length`, continues rigidly along the end tangent.
    Roll {
        /// Free length between the clamp line and the grip line, m.
        length: f64,
        /// Final curvature, 1/m.
        curvature: f64,
        /// Time to reach it, s.
        ramp: f64,
    },
}

impl Motion {
    /// Position at time `t` of a vertex of the group whose rest position is `anchor`.
    pub fn position(&self, anchor: DVec3, t: f64) -> DVec3 {
        match *self {
            Motion::Roll { length, curvature, ramp } => {
                let kappa = curvature * (t / ramp).clamp(0.0, 1.0);
                let phi = kappa * length;
                let end = if kappa.abs() < 1e-12 {
                    DVec3::new(length, anchor.y, 0.0)
                } else {
                    DVec3::new(phi.sin() / kappa, anchor.y, (1.0 - phi.cos()) / kappa)
                };
                end + (anchor.x - length) * DVec3::new(phi.cos(), 0.0, phi.sin()) + DVec3::new(0.0, 0.0, anchor.z)
            }
            Motion::Linear { velocity, start, stop } => anchor + velocity * (t - start).clamp(0.0, (stop - start).max(0.0)),
            Motion::Swing { radius, angular_speed, stop } => {
                let a = angular_speed * t.clamp(0.0, stop);
                anchor + DVec3::new(radius * a.sin(), radius * (a.cos() - 1.0), 0.0)
            }
        }
    }

    pub const STILL: Motion = Motion::Linear { velocity: DVec3::ZERO, start: 0.0, stop: 0.0 };
}

impl Model {

    /// Holds vertex `v` at `position` for the whole run.
    pub fn pin(&mut self, v: u32, position: DVec3) {
        self.fixed[v as usize] = true;
        self.anchor[v as usize] = position;
        self.driver[v as usize] = 0;
    }


    /// Moves the given vertices, starting from `positions`, with `motion`.
    pub fn drive(&mut self, vertices: &[u32], positions: &[DVec3], motion: Motion) {
        self.motions.push(motion);
        let id = (self.motions.len() - 1) as u16;
        for &v in vertices {
            self.fixed[v as usize] = true;
            self.anchor[v as usize] = positions[v as usize];
            self.driver[v as usize] = id;
        }
    }


    /// Whether every prescribed motion has come to rest by time `t`.
    pub fn motions_finished(&self, t: f64) -> bool {
        self.motions.iter().all(|m| match *m {
            Motion::Linear { stop, .. } | Motion::Swing { stop, .. } => t >= stop,
            Motion::Roll { ramp, .. } => t >= ramp,
        })
    }


    /// Prescribed position of a fixed vertex at time `t`.
    pub fn prescribed_position(&self, v: usize, t: f64) -> DVec3 {
        self.motions[self.driver[v] as usize].position(self.anchor[v], t)
    }
}
