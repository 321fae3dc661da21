//! Shear buckling: one edge clamped, the opposite edge moved along the warp (paper Figs.
//! 9–10); the wrinkles' direction, count and wavelength.

use super::{Kind, MotionTime, ON_EDGE, Rig, Specimen, need, pin_all};
use crate::io::number::short;
use crate::scene::measures::{Measures, ShearMeasures};
use crate::scene::strip::{count_half_waves, vertices_where};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::ShearKinematics;
use crate::settings::rule::{Invalid, invalid};
use crate::sim::{Model, Motion, State};
use glam::{DVec2, DVec3};

pub struct Shear;

impl Kind for Shear {
    fn name(&self) -> &'static str {
        "shear-buckling"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: false, grip: false }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["shear_angle_deg", "speed", "shear_kinematics"]
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        let a = need(self.name(), "test.shear_angle_deg", c.test.shear_angle_deg)?;
        if a >= 60.0 {
            return Err(invalid("test.shear_angle_deg", format!("test.shear_angle_deg = {} is beyond any fabric's locking angle; use less than 60", short(a))));
        }
        need(self.name(), "test.speed", c.test.speed)?;
        Ok(())
    }

    fn motion_time(&self, c: &SceneConfig) -> Option<MotionTime> {
        let degrees = c.test.shear_angle_deg?;
        let angle = degrees.to_radians();
        let travel = match c.test.shear_kinematics.unwrap_or_default() {
            // The grip slides along the warp by width·tan γ.
            ShearKinematics::Simple => c.cloth.width * angle.tan(),
            // The grip swings through γ on a link of the width.
            ShearKinematics::Trellis => c.cloth.width * angle,
        };
        Some(MotionTime { key: "test.shear_angle_deg", extent: degrees, seconds: travel / c.test.speed? })
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let (length, width) = (config.cloth.length, config.cloth.width);
        let clamped = vertices_where(&model.rest, |p| p.y < ON_EDGE);
        let moving = vertices_where(&model.rest, |p| p.y > width - ON_EDGE);
        let speed = config.test.speed.expect("checked when loading");
        let stop = self.motion_time(config).expect("checked when loading").seconds;
        pin_all(model, x, &clamped);
        let motion = match config.test.shear_kinematics.unwrap_or_default() {
            // The moving grip slides along the warp; the gap stays, so the cross yarns stretch.
            ShearKinematics::Simple => Motion::Linear { velocity: DVec3::new(speed, 0.0, 0.0), start: 0.0, stop },
            // The moving grip swings on the cross yarns, which keep their length.
            ShearKinematics::Trellis => Motion::Swing { radius: width, angular_speed: speed / width, stop },
        };
        model.drive(&moving, x, motion);
        Ok(Box::new(ShearRig { moving, width, length }))
    }

    /// The wrinkles grow as the grip shears the sheet.
    fn plot_series(&self) -> &'static str {
        "wrinkle_amplitude"
    }
}

struct ShearRig {
    moving: Vec<u32>,
    width: f64,
    length: f64,
}

impl Rig for ShearRig {
    fn finish(&self, model: &Model, state: &State) -> Measures {
        Measures::Shear(shear_measures(self, model, state))
    }

    super::any_rig!();
}

/// Wrinkle direction, count and wavelength from the normal deflection field.
fn shear_measures(r: &ShearRig, model: &Model, state: &State) -> ShearMeasures {
    // Angle between the deformed cross direction (clamp to grip) and its rest direction.
    let grip = state.x[r.moving[0] as usize] - DVec3::new(model.rest[r.moving[0] as usize].x, 0.0, 0.0);
    let shear_angle = grip.x.atan2(grip.y);
    // Structure tensor of the deflection gradient over the central region, in the deformed
    // plane: wrinkle crests run across the dominant gradient direction.
    let inside = |p: DVec2| p.y > 0.15 * r.width && p.y < 0.85 * r.width && p.x > 0.15 * r.length && p.x < 0.85 * r.length;
    let mut j = [0.0f64; 3];
    let mut amplitude = 0.0f64;
    for tri in &model.triangles {
        let rest_c = tri.iter().map(|&v| model.rest[v as usize]).sum::<DVec2>() / 3.0;
        if !inside(rest_c) {
            continue;
        }
        let p = tri.map(|v| state.x[v as usize]);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let det = e1.x * e2.y - e2.x * e1.y;
        if det.abs() < 1e-14 {
            continue;
        }
        // Gradient of the linear interpolant of z over the triangle's xy projection.
        let (dz1, dz2) = (e1.z, e2.z);
        let gx = (dz1 * e2.y - dz2 * e1.y) / det;
        let gy = (dz2 * e1.x - dz1 * e2.x) / det;
        let area = 0.5 * det.abs();
        j[0] += area * gx * gx;
        j[1] += area * gy * gy;
        j[2] += area * gx * gy;
        for q in &p {
            amplitude = amplitude.max(q.z.abs());
        }
    }
    // Principal direction of the larger eigenvalue of [[j0, j2], [j2, j1]].
    let gradient_angle = 0.5 * (2.0 * j[2]).atan2(j[0] - j[1]);
    let crest_angle = (gradient_angle + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI);
    // Sample z along the line through the centre across the crests.
    let centre = state.x.iter().sum::<DVec3>() / state.x.len() as f64;
    let across = DVec2::from_angle(gradient_angle);
    let half = 0.5 * r.length.min(r.width / crest_angle.sin().abs().max(0.2));
    let samples = 240;
    let mut profile = Vec::with_capacity(samples);
    for k in 0..samples {
        let s = -half + 2.0 * half * k as f64 / (samples - 1) as f64;
        let q = DVec2::new(centre.x, centre.y) + s * across;
        if let Some(z) = interpolate_z(model, state, q) {
            profile.push((s, z - centre.z));
        }
    }
    let zs: Vec<f64> = profile.iter().map(|p| p.1).collect();
    let half_waves = count_half_waves(&zs, 0.2);
    let span = profile.last().map_or(0.0, |p| p.0) - profile.first().map_or(0.0, |p| p.0);
    let wavelength = if half_waves >= 2 { 2.0 * span / half_waves as f64 } else { 0.0 };
    ShearMeasures {
        shear_angle_deg: shear_angle.to_degrees(),
        wrinkle_angle_deg: crest_angle.to_degrees(),
        wrinkle_count: half_waves.div_ceil(2),
        wrinkle_wavelength: wavelength,
        wrinkle_amplitude: amplitude,
    }
}

/// z of the deformed surface above the point `q` of the xy plane (first triangle found).
fn interpolate_z(model: &Model, state: &State, q: DVec2) -> Option<f64> {
    for tri in &model.triangles {
        let p = tri.map(|v| state.x[v as usize]);
        let (a, b, c) = (p[0].truncate(), p[1].truncate(), p[2].truncate());
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-14 {
            continue;
        }
        let la = (b - q).perp_dot(c - q) / area;
        let lb = (c - q).perp_dot(a - q) / area;
        let lc = 1.0 - la - lb;
        if la >= -1e-9 && lb >= -1e-9 && lc >= -1e-9 {
            return Some(la * p[0].z + lb * p[1].z + lc * p[2].z);
        }
    }
    None
}
