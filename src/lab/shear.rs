//! KES-FB1 shear: the mean slope of shear force against shear angle from 0.5° to 5°.

use super::{LabError, scene_config};
use crate::fabric::units::GF_PER_CM_DEG;
use crate::scene::Scene;
use crate::settings::{FabricConfig, ShearKinematics};
use glam::DVec3;

/// The angles KES-FB1 reads its shear slope between, degrees.
pub const KES_SHEAR_ANGLES: [f64; 2] = [0.5, 5.0];

/// What the virtual shear test reports.
#[derive(Debug, Clone, PartialEq)]
pub struct ShearTest {
    /// Shear rigidity G: the mean slope of force per grip length against angle, N/m per
    /// radian.
    pub modulus: f64,
    /// The loading curve, [angle in degrees, force per unit grip length N/m].
    pub curve: Vec<[f64; 2]>,
}

impl ShearTest {
    /// G in gf/(cm·deg), as KES prints it.
    pub fn kes(&self) -> f64 {
        self.modulus / GF_PER_CM_DEG
    }
}

/// Shears KES-FB1's specimen, 20 cm along the grips and 5 cm between them, of `fabric` on
/// the `shear-buckling` rig (one long edge clamped, the other swung on the cross yarns) to
/// 6° and reads G by KES's definition: (F(5°) − F(0.5°)) / 4.5°, F the force along the
/// grip's motion per unit grip length.
///
/// Two things stand in for KES's set-up. KES holds its specimen under 10 gf/cm across the
/// gap so that it shears without wrinkling; here the specimen stays flat because nothing
/// pushes it out of plane (no gravity, no perturbation, bending off: a flat membrane in
/// shear has no force out of its plane). And the force is summed over the middle half of
/// the grip: the free short edges carry no shear, so the sheet beside them shears less,
/// and over the whole grip the same specimens read 3–5 % below G (1–4 % lower still on a
/// 10 cm specimen), while the middle half reads within 1 % (docs/fabric-sheets.md).
pub fn shear(fabric: &FabricConfig) -> Result<ShearTest, LabError> {
    const TEST: &str = "KES shear";
    let final_angle = 6.0_f64;
    let config = scene_config(TEST, "shear-buckling", fabric, |c| {
        c.test.shear_angle_deg = Some(final_angle);
        c.test.shear_kinematics = Some(ShearKinematics::Trellis);
        c.test.perturbation = None;
        c.physics.gravity = false;
        c.physics.bending = false;
        c.cloth.length = 0.20;
        c.cloth.width = 0.05;
        c.mesh.edge_length = 0.005;
        let speed = c.test.speed.unwrap_or(0.01);
        c.scene.duration = final_angle.to_radians() * c.cloth.width / speed + 0.02;
        c.scene.settle_speed = None;
    })?;
    let (length, width) = (config.cloth.length, config.cloth.width);
    let mut scene = Scene::new(config).map_err(|e| LabError::Setup { test: TEST, message: e.to_string() })?;
    let rest = scene.model.rest.clone();
    let grip: Vec<usize> = (0..rest.len()).filter(|&v| rest[v].y > width - 1e-9).collect();
    let middle: Vec<usize> = grip.iter().copied().filter(|&v| (rest[v].x - 0.5 * length).abs() <= 0.25 * length + 1e-9).collect();
    // The middle half's share of the grip's length: its vertices' extent, plus half a
    // cell at each end (each vertex carries the force of the half cells beside it).
    let xs: Vec<f64> = middle.iter().map(|&v| rest[v].x).collect();
    let spacing = length / (grip.len() - 1).max(1) as f64;
    let span = xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - xs.iter().cloned().fold(f64::INFINITY, f64::min) + spacing;
    let mut curve = Vec::new();
    let mut f = vec![DVec3::ZERO; rest.len()];
    while scene.state.time < scene.config.scene.duration - 1e-9 {
        scene.step().map_err(|e| LabError::Diverged { test: TEST, message: e.to_string() })?;
        let t = scene.state.time;
        // The grip's angle from its prescribed position: it swings on a circle of radius
        // the gap about its rest point on the clamped edge.
        let v0 = grip[0];
        let p = scene.model.prescribed_position(v0, t);
        let angle = (p.x - rest[v0].x).atan2(p.y);
        let motion = DVec3::new(angle.cos(), -angle.sin(), 0.0);
        f.iter_mut().for_each(|fi| *fi = DVec3::ZERO);
        scene.model.forces(&scene.state.x, &mut f);
        // The cloth pulls the grip back; the grip carries the opposite.
        let force: f64 = -middle.iter().map(|&v| f[v].dot(motion)).sum::<f64>();
        curve.push([angle.to_degrees(), force / span]);
    }
    let at = |deg: f64| -> Option<f64> {
        let i = curve.iter().position(|p| p[0] >= deg)?;
        let (a, b) = (curve.get(i.checked_sub(1)?)?, curve[i]);
        Some(a[1] + (deg - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
    };
    let [lo, hi] = KES_SHEAR_ANGLES;
    let (f_lo, f_hi) = at(lo)
        .zip(at(hi))
        .ok_or_else(|| LabError::NoReading { test: TEST, message: format!("the grip did not sweep {lo}° to {hi}°") })?;
    Ok(ShearTest { modulus: (f_hi - f_lo) / (hi - lo).to_radians(), curve })
}
