//! The swing: a strip hung from its top edge and released in the first mode of the
//! hanging chain (docs/references.md §10). Its period against the chain's is the error a
//! time step and a solver make on a moving cloth, which the equilibrium problems of the
//! chart cannot show.
//!
//! ```text
//!   clamp band (x ≤ 0) ─────────── top edge, pinned
//!        │ u(s) = a·J₀(j₀,₁ √(s/L))      s = L − x, height above the free end
//!        │
//!   free edge (x = L): its mean sideways displacement is sampled, and the period taken
//!   from its zero crossings
//! ```
//!
//! The strip's rest plane maps to the vertical plane: rest x runs down (−z), rest y across
//! (+x), and the swing is along +y.

use super::{Kind, Rig, Specimen, need};
use crate::io::number::short;
use crate::physics::STANDARD_GRAVITY;
use crate::reference::{hanging_chain_mode, hanging_chain_period};
use crate::scene::measures::{Measures, SwingMeasures};
use crate::scene::strip::vertices_where;
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid};
use crate::sim::{Model, State};
use glam::{DVec2, DVec3};

pub struct Swing;

impl Kind for Swing {
    fn name(&self) -> &'static str {
        "swing"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: true, grip: false }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["swing_amplitude", "clamp_length"]
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        let (t, length) = (&c.test, c.cloth.length);
        let a = need(self.name(), "test.swing_amplitude", t.swing_amplitude)?;
        // The chain's small-amplitude period holds for swings small against the length.
        if a > 0.1 * length {
            return Err(invalid(
                "test.swing_amplitude",
                format!("test.swing_amplitude = {} m is more than a tenth of the strip's {} m: the swing would not be small; use at most {}", short(a), short(length), short(0.1 * length)),
            ));
        }
        if t.perturbation.is_some() {
            return Err(invalid("test.perturbation", "test.perturbation has no effect on a swing scene (it starts in the chain's mode); remove it".into()));
        }
        Ok(())
    }

    fn start(&self, config: &SceneConfig, rest: &[DVec2]) -> Vec<DVec3> {
        let origin = DVec3::from_array(config.cloth.position);
        hanging_positions(rest, origin, config.cloth.length, config.test.swing_amplitude.unwrap_or(0.0))
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        Ok(Box::new(SwingRig::attach(config, model, x, STANDARD_GRAVITY)?))
    }

    /// The period settles as the free edge crosses the plumb line.
    fn plot_series(&self) -> &'static str {
        "swing_period"
    }

    fn moves_freely(&self) -> bool {
        true
    }
}

/// The swing's rig: the free edge's vertices and its samples.
struct SwingRig {
    bottom: Vec<u32>,
    /// The sideways coordinate the strip hangs at, m.
    rest_y: f64,
    chain_period: f64,
    samples: Vec<[f64; 2]>,
}

/// Where each rest point of the strip starts: hung from the clamp line at `origin`, displaced
/// sideways by `amplitude` in the chain's first mode (zero in the clamp band).
pub fn hanging_positions(rest: &[DVec2], origin: DVec3, length: f64, amplitude: f64) -> Vec<DVec3> {
    rest.iter()
        .map(|p| {
            let sideways = if p.x > 0.0 { amplitude * hanging_chain_mode(length - p.x, length) } else { 0.0 };
            origin + DVec3::new(p.y, sideways, -p.x)
        })
        .collect()
}

impl SwingRig {
    /// Pins the clamp band (rest x ≤ 0) where it hangs and finds the free edge.
    pub fn attach(config: &SceneConfig, model: &mut Model, x: &[DVec3], gravity: f64) -> Result<Self, crate::sim::ModelError> {
        let rest = model.rest.clone();
        let length = config.cloth.length;
        let clamp = vertices_where(&rest, |p| p.x < 1e-9);
        let mut rigid = vec![false; rest.len()];
        for &v in &clamp {
            model.pin(v, x[v as usize]);
            rigid[v as usize] = true;
        }
        model.set_clamped_region(&rigid)?;
        let bottom = vertices_where(&rest, |p| p.x > length - 1e-9);
        Ok(Self { bottom, rest_y: config.cloth.position[1], chain_period: hanging_chain_period(length, gravity), samples: Vec::new() })
    }

    fn sample_edge(&mut self, state: &State) {
        let y = self.bottom.iter().map(|&v| state.x[v as usize].y).sum::<f64>() / self.bottom.len() as f64;
        self.samples.push([state.time, y - self.rest_y]);
    }

    fn measures(&self) -> SwingMeasures {
        let crossings = zero_crossings(&self.samples);
        let half_periods = crossings.len().saturating_sub(1);
        let swing_period = (half_periods >= 2).then(|| 2.0 * (crossings[crossings.len() - 1] - crossings[0]) / half_periods as f64);
        SwingMeasures { bottom_history: self.samples.clone(), chain_period: self.chain_period, half_periods, swing_period }
    }
}

impl Rig for SwingRig {
    fn sample(&mut self, _model: &Model, state: &State) {
        self.sample_edge(state);
    }

    fn finish(&self, _model: &Model, _state: &State) -> Measures {
        Measures::Swing(self.measures())
    }

    super::any_rig!();
}

/// The times at which a sampled signal changes sign, interpolated linearly between samples.
fn zero_crossings(samples: &[[f64; 2]]) -> Vec<f64> {
    samples
        .windows(2)
        .filter(|w| (w[0][1] > 0.0) != (w[1][1] > 0.0) && w[0][1] != w[1][1])
        .map(|w| {
            let ([t0, u0], [t1, u1]) = (w[0], w[1]);
            t0 + (t1 - t0) * u0 / (u0 - u1)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_crossings_of_a_sampled_cosine_give_its_period() {
        let period = 1.3;
        let samples: Vec<[f64; 2]> = (0..400).map(|i| {
            let t = i as f64 * 0.01;
            [t, 0.01 * (std::f64::consts::TAU * t / period).cos()]
        }).collect();
        let crossings = zero_crossings(&samples);
        let measured = 2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
        assert!((measured - period).abs() < 1e-3 * period, "{measured} against {period}");
    }

    #[test]
    fn the_strip_starts_in_the_chain_mode_with_its_clamp_band_still() {
        let rest = [DVec2::new(-0.01, 0.0), DVec2::new(0.0, 0.0), DVec2::new(0.5, 0.02), DVec2::new(1.0, 0.0)];
        let x = hanging_positions(&rest, DVec3::new(0.0, 0.0, 2.0), 1.0, 0.02);
        assert_eq!(x[0], DVec3::new(0.0, 0.0, 2.01));
        assert!(x[1].y.abs() < 1e-15, "the clamp line does not move");
        assert!((x[3].y - 0.02).abs() < 1e-15, "the free edge carries the amplitude");
        assert!(x[2].y > 0.0 && x[2].y < 0.02 && x[2].x == 0.02 && x[2].z == 1.5);
    }
}
