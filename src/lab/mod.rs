//! The virtual laboratory: the standard tests run on a fabric and read by the standards'
//! own definitions, as a textile laboratory would report them.
//!
//! - [`kes_tensile`]: a strip pulled to Fm = 500 gf/cm; EMT, LT and WT (KES-FB1).
//! - [`pure_bending`]: the moment slope between 0.5 and 1.5 cm⁻¹, B (KES-FB2).
//! - [`shear`]: the mean slope of shear force against angle from 0.5° to 5°, G (KES-FB1).
//! - [`cantilever_bending_length`]: half the overhang at which a 25 mm strip's tip meets
//!   the 41.5° plane (ASTM D1388, BS 3356).
//! - [`tensile_pull`]: a strip pulled to a strain, its stress–strain curve (the fabric
//!   card's bias pull); [`strain_pull`] the same on any strip, sampled every step.
//! - [`arcsim::readback`]: an ARCSim material's samples read back by pulls and bends.
//!
//! Definitions and units: docs/references.md §8. Each test builds on a bundled scene
//! (tensile-warp, arc, shear-buckling, cantilever), takes the fabric as given and reports
//! what it measured; [`readback`] compares that with the sheet the fabric came from.
//! Nothing here reads the fabric's own parameters back as a result: where a test needs a
//! starting guess (the cantilever's first overhang) it only shortens the search.

pub mod arcsim;
mod bending;
mod cantilever;
pub mod readback;
pub mod report;
mod shear;
mod tensile;

pub use bending::{PureBending, bend_to, pure_bending};
pub use cantilever::{CantileverTest, cantilever_bending_length};
pub use readback::{LabRuns, readback, readback_with};
pub use report::{Property, ReadBack};
pub use shear::{ShearTest, shear};
pub use tensile::{KesTensile, Strip, TensilePull, kes_tensile, load_at, strain_pull, tensile_pull};

use crate::settings::FabricConfig;
use crate::scene::{Metrics, RunOptions, Scene, SceneConfig, load_scene, run_scene};
use thiserror::Error;

/// Which way a specimen is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// Along the warp (0°).
    Warp,
    /// Along the weft (90°).
    Weft,
    /// At 45° to both.
    Bias,
}

impl Direction {
    pub const ALL: [Direction; 3] = [Direction::Warp, Direction::Weft, Direction::Bias];

    /// Angle of the warp from the specimen's length, degrees (`cloth.warp_angle_deg`).
    pub fn warp_angle_deg(self) -> f64 {
        match self {
            Direction::Warp => 0.0,
            Direction::Weft => 90.0,
            Direction::Bias => 45.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Direction::Warp => "warp",
            Direction::Weft => "weft",
            Direction::Bias => "bias",
        }
    }
}

/// Why a virtual test could not report.
#[derive(Debug, Error)]
pub enum LabError {
    #[error("{test}: {message}")]
    Setup { test: &'static str, message: String },
    #[error("{test}: the simulation failed: {message}")]
    Diverged { test: &'static str, message: String },
    #[error("{test}: {message}")]
    NoReading { test: &'static str, message: String },
}

/// A bundled scene with `fabric` in it; `edit` sets the test's geometry.
fn scene_config(test: &'static str, preset: &str, fabric: &FabricConfig, edit: impl FnOnce(&mut SceneConfig)) -> Result<SceneConfig, LabError> {
    let mut config = load_scene(preset, &[]).map_err(|e| LabError::Setup { test, message: e.to_string() })?.0.into_config();
    // Drape-only settings of the fabric (the scene's own overrides) are not carried over:
    // the test sees the fabric as given.
    config.fabric = fabric.clone();
    edit(&mut config);
    Ok(config)
}

/// Builds and runs a scene to its end (or until it settles).
fn run(test: &'static str, config: SceneConfig) -> Result<Metrics, LabError> {
    let mut scene = Scene::new(config).map_err(|e| LabError::Setup { test, message: e.to_string() })?;
    let (metrics, error) = run_scene(&mut scene, test, RunOptions::default());
    match error {
        Some(e) => Err(LabError::Diverged { test, message: e.to_string() }),
        None => Ok(metrics),
    }
}

fn measure(test: &'static str, m: &Metrics, key: &str) -> Result<f64, LabError> {
    m.measures.scalar(key).ok_or_else(|| LabError::NoReading { test, message: format!("the scene reported no {key}") })
}
