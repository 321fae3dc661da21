//! Pure bending: a clamped strip rolled into an arc by a grip at its far end; the moment
//! against the curvature gives the bending rigidity.

use super::{Kind, MotionTime, ON_EDGE, Rig, Specimen, clamp_strip, need};
use crate::io::number::short;
use crate::scene::measures::{ArcMeasures, Measures};
use crate::scene::strip::{Columns, fit_circle_radius, vertices_where};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid};
use crate::sim::{Model, Motion, State};
use glam::DVec3;

pub struct Arc;

impl Kind for Arc {
    fn name(&self) -> &'static str {
        "arc"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: true, grip: true }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["curvature", "clamp_length"]
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        let k = need(self.name(), "test.curvature", c.test.curvature)?;
        // Rolled further the strip would pass through its own clamp.
        let length = c.cloth.length;
        let most = std::f64::consts::TAU / length;
        if k > most {
            return Err(invalid("test.curvature", format!("test.curvature = {} 1/m rolls the {} m strip past a full circle; use at most {}", short(k), short(length), short(most))));
        }
        Ok(())
    }

    /// The grip rolls the strip in over the first half of the run, then holds.
    fn motion_time(&self, c: &SceneConfig) -> Option<MotionTime> {
        Some(MotionTime { key: "test.curvature", extent: c.test.curvature?, seconds: 0.5 * c.scene.duration })
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let (length, width) = (config.cloth.length, config.cloth.width);
        let (columns, mut rigid) = clamp_strip(config, model, x, clamp_band);
        // The far grip rolls the strip into an arc of the target curvature, then holds
        // while it settles.
        let grip = vertices_where(&model.rest, |p| p.x > length - ON_EDGE);
        grip.iter().for_each(|&v| rigid[v as usize] = true);
        let roll = self.motion_time(config).expect("checked when loading");
        model.drive(&grip, x, Motion::Roll { length, curvature: roll.extent, ramp: roll.seconds });
        model.set_clamped_region(&rigid)?;
        Ok(Box::new(ArcRig { columns, length, width, grip }))
    }

    /// The moment follows the curvature the grip rolls in.
    fn plot_series(&self) -> &'static str {
        "moment"
    }
}

struct ArcRig {
    columns: Columns,
    length: f64,
    width: f64,
    grip: Vec<u32>,
}

impl Rig for ArcRig {
    fn finish(&self, model: &Model, state: &State) -> Measures {
        let line = self.columns.centre_line(&state.x);
        let points: Vec<(f64, f64)> = self
            .columns
            .rest_x
            .iter()
            .zip(&line)
            .filter(|(x, _)| **x >= 0.25 * self.length && **x <= 0.75 * self.length)
            .map(|(_, p)| (p.x, p.z))
            .collect();
        let curvature = fit_circle_radius(&points).map_or(0.0, |radius| 1.0 / radius);
        // Bending moment per unit width at the midspan section, where the curvature is
        // fitted: by the balance of the half strip between it and the grip, it is the
        // moment of the grip's forces about the midspan centre line. (About the grip line
        // instead, any residual axial force would add itself times the arc's sagitta.)
        let mut f = vec![DVec3::ZERO; state.x.len()];
        model.forces(&state.x, &mut f);
        let pivot = line[self.columns.nearest(0.5 * self.length)];
        let torque: f64 = self.grip.iter().map(|&v| (state.x[v as usize] - pivot).cross(f[v as usize]).y).sum();
        let moment = torque / self.width;
        Measures::Arc(ArcMeasures { curvature, moment, rigidity: (curvature > 0.0).then(|| moment / curvature) })
    }

    super::any_rig!();
}
