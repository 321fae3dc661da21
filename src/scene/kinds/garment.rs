//! Pattern pieces sewn into a garment on a dress form (`[garment]`, docs/garments.md). The
//! pieces, seams, form and rig are built by `scene::garment` (its rig, `GarmentRig`, is
//! made with the sewing); this file says what the kind checks, plots and compares.

use super::{Kind, Rig, Specimen};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid};
use crate::sim::Model;
use glam::DVec3;

pub struct Garment;

impl Kind for Garment {
    fn name(&self) -> &'static str {
        "garment"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Garment
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        if c.test.perturbation.is_some() {
            return Err(invalid("test.perturbation", "test.perturbation has no effect on a garment scene (its panels start where their placement puts them); remove it".into()));
        }
        Ok(())
    }

    fn attach(&self, _config: &SceneConfig, _model: &mut Model, _x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        Err(SceneError::Setup("garment scenes build their own rig (scene::garment)".into()))
    }

    /// The hem falls as the sewn garment drapes on the form.
    fn plot_series(&self) -> &'static str {
        "hem_height_mean"
    }

    fn drapes(&self) -> bool {
        true
    }
}
