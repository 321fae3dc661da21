//! KES-FB2 pure bending: the slope of moment against curvature between 0.5 and 1.5 cm⁻¹.

use super::{Direction, LabError, measure, run, scene_config};
use crate::fabric::units::GF_CM2_PER_CM;
use crate::settings::FabricConfig;

/// The curvatures KES-FB2 reads its slope between, 1/m (0.5 and 1.5 cm⁻¹).
pub const KES_CURVATURES: [f64; 2] = [50.0, 150.0];

/// What the virtual pure-bending test reports.
#[derive(Debug, Clone, PartialEq)]
pub struct PureBending {
    pub direction: Direction,
    /// Bending rigidity B: the moment's slope between the two curvatures, N·m.
    pub rigidity: f64,
    /// The two readings, (curvature 1/m, moment per width N·m/m).
    pub readings: [(f64, f64); 2],
}

impl PureBending {
    /// B in gf·cm²/cm, as KES prints it.
    pub fn kes(&self) -> f64 {
        self.rigidity / GF_CM2_PER_CM
    }
}

/// Bends a strip of `fabric` cut along `direction` between rigid grips (the `arc` rig) to
/// 0.5 and 1.5 cm⁻¹ and reads B as KES-FB2 does: ΔM/Δκ between them. The strip is 2 cm
/// long (KES: 1 cm) and 1 cm wide on 1 mm edges, short enough that 1.5 cm⁻¹ bends it
/// through 1.7 rad and fine enough that an element turns by 0.15 rad.
pub fn pure_bending(fabric: &FabricConfig, direction: Direction) -> Result<PureBending, LabError> {
    let mut readings = [(0.0, 0.0); 2];
    for (reading, curvature) in readings.iter_mut().zip(KES_CURVATURES) {
        *reading = bend_to(fabric, direction, curvature)?;
    }
    let [(k1, m1), (k2, m2)] = readings;
    Ok(PureBending { direction, rigidity: (m2 - m1) / (k2 - k1), readings })
}

/// Bends KES's strip (below) of `fabric` cut along `direction` to `curvature` (1/m) and
/// reads (the curvature fitted to its middle half, the moment per unit width at midspan,
/// N·m/m).
pub fn bend_to(fabric: &FabricConfig, direction: Direction, curvature: f64) -> Result<(f64, f64), LabError> {
    const TEST: &str = "KES pure bending";
    let config = scene_config(TEST, "arc", fabric, |c| {
        c.cloth.warp_angle_deg = direction.warp_angle_deg();
        c.cloth.length = 0.02;
        c.cloth.width = 0.01;
        c.mesh.edge_length = 0.001;
        c.test.clamp_length = Some(0.002);
        c.test.curvature = Some(curvature);
    })?;
    let m = run(TEST, config)?;
    Ok((measure(TEST, &m, "curvature")?, measure(TEST, &m, "moment")?))
}
