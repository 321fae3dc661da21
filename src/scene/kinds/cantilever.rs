//! The heavy cantilever (Peirce, ASTM D1388): a strip clamped at one end bends under its
//! own weight; its tip drop against the bending length.

use super::{Kind, Rig, Specimen, clamp_strip};
use crate::physics::{bending_length, cantilever_lambda, weight_per_area};
use crate::scene::measures::{CantileverMeasures, Measures};
use crate::scene::strip::Columns;
use crate::scene::{SceneConfig, SceneError};
use crate::sim::{Model, State};
use glam::DVec3;

pub struct Cantilever;

impl Kind for Cantilever {
    fn name(&self) -> &'static str {
        "cantilever"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: true, grip: false }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["clamp_length"]
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let (columns, rigid) = clamp_strip(config, model, x, clamp_band);
        model.set_clamped_region(&rigid)?;
        Ok(Box::new(CantileverRig { columns, length: config.cloth.length }))
    }

    /// The tip falls under gravity from the horizontal.
    fn plot_series(&self) -> &'static str {
        "tip_drop"
    }
}

struct CantileverRig {
    columns: Columns,
    length: f64,
}

impl Rig for CantileverRig {
    fn finish(&self, model: &Model, state: &State) -> Measures {
        let line = self.columns.centre_line(&state.x);
        let n = line.len();
        let (tip, before) = (line[n - 1], line[n - 2]);
        let drop = -tip.z;
        let tangent = tip - before;
        let weight = weight_per_area(model.mass.iter().sum::<f64>() / model.vertex_area.iter().sum::<f64>());
        let b = model.bending_stiffness.rigidity_at(-model.warp_angle);
        Measures::Cantilever(CantileverMeasures {
            tip_drop: drop,
            tip_reach: tip.x,
            tip_angle_deg: (-tangent.z).atan2(tangent.x).to_degrees(),
            chord_angle_deg: drop.atan2(tip.x).to_degrees(),
            lambda: cantilever_lambda(weight, self.length, b),
            bending_length: bending_length(b, weight),
        })
    }

    super::any_rig!();
}
