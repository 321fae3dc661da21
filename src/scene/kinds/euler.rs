//! Euler buckling: a strip compressed between pinned ends that approach at a constant speed
//! (paper Figs. 7–8); the end force against the Euler load and the elastica.

use super::{Kind, MotionTime, ON_EDGE, Rig, Specimen, need};
use crate::io::number::short;
use crate::scene::measures::{EulerMeasures, Measures};
use crate::scene::strip::{Columns, count_half_waves, group_force, vertices_where};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid};
use crate::sim::{Model, Motion, State};
use glam::DVec3;

/// Largest out-of-balance load on the free vertices, Σ|f_i| over the Euler load's total
/// P_cr·w, at which an Euler-buckling sample counts as quasi-static.
///
/// As in dynamic relaxation, a state is static when the force left unbalanced on its free
/// vertices (what accelerates them, or is damped) is small against the load the structure
/// carries. By the momentum balance of each half of the strip, the end force then differs
/// from the force carried through the midspan by less than 2 % of P_cr, and the shape is
/// close to an equilibrium at the current end shortening, which is what the elastica
/// describes. The bundled scene's fast compression (10 % in 0.2 s, under half the first
/// mode's period) is never quasi-static by this measure (Σ|f_i| is 5–15 P_cr·w); its hold
/// becomes so once the ringing has decayed, within 1 % of its final force.
pub const QUASI_STATIC_IMBALANCE: f64 = 0.02;

pub struct Euler;

impl Kind for Euler {
    fn name(&self) -> &'static str {
        "euler-buckling"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: false, grip: false }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["end_shortening", "speed"]
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        let s = need(self.name(), "test.end_shortening", c.test.end_shortening)?;
        if s >= 0.9 {
            return Err(invalid("test.end_shortening", format!("test.end_shortening = {} leaves almost no strip; use a fraction below 0.9", short(s))));
        }
        need(self.name(), "test.speed", c.test.speed)?;
        Ok(())
    }

    fn motion_time(&self, c: &SceneConfig) -> Option<MotionTime> {
        let shortening = c.test.end_shortening?;
        Some(MotionTime { key: "test.end_shortening", extent: shortening, seconds: shortening * c.cloth.length / c.test.speed? })
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let (length, width, h) = (config.cloth.length, config.cloth.width, config.mesh.edge_length);
        let rest = model.rest.clone();
        let left = vertices_where(&rest, |p| p.x < ON_EDGE);
        let right = vertices_where(&rest, |p| p.x > length - ON_EDGE);
        let speed = config.test.speed.expect("checked when loading");
        let stop = self.motion_time(config).expect("checked when loading").seconds;
        // Both ends move, each at half the approach speed, so the midspan stays put.
        model.drive(&left, x, Motion::Linear { velocity: DVec3::new(0.5 * speed, 0.0, 0.0), start: 0.0, stop });
        model.drive(&right, x, Motion::Linear { velocity: DVec3::new(-0.5 * speed, 0.0, 0.0), start: 0.0, stop });
        let columns = Columns::new(&rest, length, h);
        Ok(Box::new(EulerRig { left, right, columns, width, length, history: Vec::new(), speed }))
    }

    /// The strip bows out once the end force passes the Euler load.
    fn plot_series(&self) -> &'static str {
        "midspan_deflection"
    }
}

/// One sample: (t, end shortening fraction, end force N/m, amplitude m, lobes,
/// out-of-balance force over the Euler load).
type Sample = (f64, f64, f64, f64, usize, f64);

struct EulerRig {
    left: Vec<u32>,
    right: Vec<u32>,
    columns: Columns,
    width: f64,
    length: f64,
    history: Vec<Sample>,
    speed: f64,
}

impl EulerRig {
    /// The Euler load of the pinned strip, π²B_θ/L² (N/m), B_θ across the strip's length.
    fn euler_load(&self, model: &Model) -> f64 {
        std::f64::consts::PI.powi(2) * model.bending_stiffness.rigidity_at(-model.warp_angle) / self.length.powi(2)
    }
}

impl Rig for EulerRig {
    fn sample(&mut self, model: &Model, state: &State) {
        let mut f = vec![DVec3::ZERO; state.x.len()];
        model.forces(&state.x, &mut f);
        // Compressed cloth pushes the left end towards −x and the right end towards +x.
        let force = 0.5 * (-group_force(&f, &self.left).x + group_force(&f, &self.right).x) / self.width;
        let span = model.prescribed_position(self.right[0] as usize, state.time).x - model.prescribed_position(self.left[0] as usize, state.time).x;
        let shortening = 1.0 - span / self.length;
        let line = self.columns.centre_line(&state.x);
        let z: Vec<f64> = line.iter().map(|p| p.z).collect();
        let amplitude = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // The load left unbalanced on the free vertices, what accelerates them (or is
        // damped): zero in static equilibrium. See QUASI_STATIC_IMBALANCE.
        let unbalanced: f64 = f.iter().zip(&model.fixed).filter(|(_, fixed)| !**fixed).map(|(fi, _)| fi.length()).sum();
        let imbalance = unbalanced / (self.euler_load(model) * self.width);
        self.history.push((state.time, shortening, force, amplitude, count_half_waves(&z, 0.2), imbalance));
    }

    fn continue_history(&mut self, earlier: Box<dyn Rig>) {
        if let Ok(earlier) = earlier.into_any().downcast::<EulerRig>() {
            self.history.splice(0..0, earlier.history).for_each(drop);
        }
    }

    fn finish(&self, model: &Model, state: &State) -> Measures {
        let critical = self.history.iter().find(|h| h.3 > 0.05 * self.length).map(|h| h.2);
        let line = self.columns.centre_line(&state.x);
        let mid = self.columns.nearest(0.5 * self.length);
        let last = self.history.last().copied().unwrap_or_default();
        let (quasi_static, dynamic): (Vec<_>, Vec<_>) = self.history.iter().partition(|h| h.5 < QUASI_STATIC_IMBALANCE);
        let force_curve = |samples: &[&Sample]| -> Vec<[f64; 2]> { samples.iter().step_by((samples.len() / 100).max(1)).map(|h| [h.1, h.2]).collect() };
        // Lobe history as (t, lobes) at each change.
        let mut lobe_history: Vec<(f64, usize)> = Vec::new();
        for h in &self.history {
            if h.3 > 1e-3 * self.length && lobe_history.last().is_none_or(|l| l.1 != h.4) {
                lobe_history.push((h.0, h.4));
            }
        }
        Measures::Euler(EulerMeasures {
            critical_load: critical,
            critical_load_definition: EulerMeasures::CRITICAL_LOAD_DEFINITION.to_string(),
            euler_load: self.euler_load(model),
            end_force: last.2,
            end_shortening: last.1,
            midspan_deflection: line[mid].z.abs(),
            lobes: last.4,
            lobe_history,
            compression_speed: self.speed,
            out_of_balance: last.5,
            out_of_balance_definition: EulerMeasures::OUT_OF_BALANCE_DEFINITION.to_string(),
            quasi_static_force: force_curve(&quasi_static),
            dynamic_force: force_curve(&dynamic),
            force_history: self.history.iter().step_by((self.history.len() / 100).max(1)).map(|h| [h.0, h.1, h.2, h.3]).collect(),
        })
    }

    super::any_rig!();
}
