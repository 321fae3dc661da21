//! ASTM D1388 option A / BS 3356: the bending length of a strip under its own weight.

use super::{Direction, LabError, measure, run, scene_config};
use crate::fabric::bias::STANDARD_CHORD_ANGLE_DEG;
use crate::physics::{bending_length, weight_per_area};
use crate::settings::FabricConfig;

/// What the virtual cantilever test reports.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverTest {
    pub direction: Direction,
    /// Width of the strip, m.
    pub strip_width: f64,
    /// Overhang at which the chord from the bench edge to the tip makes 41.5°, m.
    pub overhang: f64,
    /// The standard's bending length, half that overhang, m.
    pub bending_length: f64,
    /// The chord angle of the last run, degrees (41.5° within the search's tolerance).
    pub chord_angle_deg: f64,
    /// Cantilevers run in the search.
    pub runs: usize,
}

/// How close the search brings the chord to 41.5°, degrees: about 0.02 % of the overhang.
const ANGLE_TOLERANCE_DEG: f64 = 0.01;

/// Cells along the overhang; the tip drop converges to about 0.3 % here (tests/bending.rs).
const CELLS: f64 = 20.0;

/// Slides a strip of `fabric`, cut along `direction` and `strip_width` wide (the
/// standard's 25 mm), over the bench edge until its chord makes 41.5° with the horizontal,
/// and reports half that overhang: the bending length by the standard's definition.
///
/// Each trial overhang is a `cantilever` scene run until the strip is still; the overhang
/// is found by the secant method on its logarithm. The first guess is twice eq. 3's
/// (B_θ/w)^⅓; it only shortens the search.
pub fn cantilever_bending_length(fabric: &FabricConfig, direction: Direction, strip_width: f64) -> Result<CantileverTest, LabError> {
    const TEST: &str = "cantilever";
    let target = STANDARD_CHORD_ANGLE_DEG;
    let chord = |overhang: f64| -> Result<f64, LabError> {
        let config = scene_config(TEST, "cantilever", fabric, |c| {
            c.cloth.warp_angle_deg = direction.warp_angle_deg();
            c.cloth.length = overhang;
            c.cloth.width = strip_width;
            c.mesh.edge_length = overhang / CELLS;
            c.test.clamp_length = Some(overhang / 8.0);
        })?;
        measure(TEST, &run(TEST, config)?, "chord_angle_deg")
    };
    let guess = {
        let f = fabric.to_fabric().map_err(|e| LabError::Setup { test: TEST, message: e.to_string() })?;
        let b = crate::sim::BendingStiffness::new(&f).map_err(|e| LabError::Setup { test: TEST, message: e.to_string() })?;
        let rigidity = b.rigidity_at(-direction.warp_angle_deg().to_radians());
        2.0 * bending_length(rigidity, weight_per_area(fabric.properties.areal_density))
    };
    let (mut x0, mut x1) = (guess.ln(), guess.ln() + 0.05);
    let (mut f0, mut f1) = (chord(x0.exp())? - target, chord(x1.exp())? - target);
    let mut runs = 2;
    while f1.abs() > ANGLE_TOLERANCE_DEG {
        if runs >= 12 || f1 == f0 {
            return Err(LabError::NoReading { test: TEST, message: format!("the overhang search did not settle on 41.5° ({:.3}° off)", f1) });
        }
        // Secant step, held to a factor 1.5 either way.
        let step = (-f1 * (x1 - x0) / (f1 - f0)).clamp(-0.4, 0.4);
        (x0, f0) = (x1, f1);
        x1 += step;
        f1 = chord(x1.exp())? - target;
        runs += 1;
    }
    let overhang = x1.exp();
    Ok(CantileverTest { direction, strip_width, overhang, bending_length: 0.5 * overhang, chord_angle_deg: f1 + target, runs })
}
