//! The checks of a garment scene's `[garment]` section and its pattern.

use super::{Invalid, invalid, non_negative, positive, positive_at_most};
use crate::garment;
use crate::settings::SceneConfig;
use crate::sim::mesh::MAX_VERTICES;
use crate::io::number::short;
use glam::DVec2;

/// The stiffest sewing spring a scene may ask for, N/m.
pub const MAX_SEWING_STIFFNESS: f64 = 1e6;

/// The checks a garment scene passes when it is loaded (`check::checked`): the
/// `[garment]` section, no `[cloth]` keys, the sewing settings, and the pattern itself
/// (outlines, grains, seams, attachments, meshing). Returns the smallest panel's smaller
/// side, m, and the garment meshed at the scene's edge length, which the scene is built
/// from.
pub fn check(c: &SceneConfig) -> Result<(f64, garment::Garment), Invalid> {
    let g = c.garment.as_ref().ok_or_else(|| invalid("garment", "a garment scene needs a [garment] section with its panels and form".into()))?;
    let cloth = &c.cloth;
    if cloth.length != 0.0 || cloth.width != 0.0 || cloth.diameter != 0.0 || cloth.warp_angle_deg != 0.0 || cloth.position != [0.0; 3] {
        return Err(invalid("cloth", "a garment's cloth is its [garment] pattern; remove the [cloth] section (each panel has its own grain_deg and placement)".into()));
    }
    let h = positive("mesh.edge_length", c.mesh.edge_length)?;
    // Springs far stiffer than the cloth they close only make the step's solve
    // ill-conditioned: at the limit a 1 µm gap already pulls with 1 N.
    let stiffness_bound = format!("a sewing spring's stiffness in N/m; the default is {}", short(garment::default_sewing_stiffness()));
    positive_at_most("garment.sewing_stiffness", g.sewing_stiffness, MAX_SEWING_STIFFNESS, &stiffness_bound)?;
    positive("garment.sewing_ramp", g.sewing_ramp)?;
    positive("garment.sewing_time", g.sewing_time)?;
    positive_at_most(
        "garment.closed_share",
        g.closed_share,
        1.0,
        &format!(
            "a seam is welded once its sides are within this share of the contact layer; farther apart they would be welded out of shape; the default is {}",
            short(garment::default_closed_share())
        ),
    )?;
    non_negative("garment.sewing_damping", g.sewing_damping)?;
    if !g.seams.is_empty() && g.sewing_ramp >= g.sewing_time {
        return Err(invalid(
            "garment.sewing_ramp",
            format!(
                "garment.sewing_ramp = {} s is not shorter than garment.sewing_time = {} s: the seams close only once the ramp has drawn them together; shorten the ramp or lengthen the sewing time",
                g.sewing_ramp, g.sewing_time
            ),
        ));
    }
    if let Some(scale) = g.form.scale {
        if g.form.obj.is_none() {
            return Err(invalid("garment.form.scale", "garment.form.scale scales an OBJ body (garment.form.obj); remove it, or give the obj".into()));
        }
        positive_at_most("garment.form.scale", scale, 1e4, "the factor the OBJ body's coordinates are multiplied by")?;
    }
    if !g.form.axis.iter().all(|v| v.is_finite() && v.abs() * g.units.metres() <= 100.0) {
        return Err(invalid("garment.form.axis", format!("garment.form.axis = {:?} must be two finite coordinates within 100 m, in {}", g.form.axis, g.units.name())));
    }
    if g.sewing_time > c.scene.duration {
        return Err(invalid("garment.sewing_time", format!("garment.sewing_time = {} s is longer than scene.duration = {} s", g.sewing_time, c.scene.duration)));
    }
    let measurements = g.form.measurements(g.units).map_err(|e| invalid("garment.form", e.to_string()))?;
    let level = |name: &str| measurements.as_ref()?.level(name);
    let metres = g.units.metres();
    check_size(c, g, h)?;
    let garment = garment::build(g, h, DVec2::from_array(g.form.axis) * metres, &level).map_err(|e| invalid("garment", e.to_string()))?;
    let extent = garment
        .meshes
        .iter()
        .map(|m| {
            let (lo, hi) = m.points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
            (hi - lo).min_element()
        })
        .fold(f64::INFINITY, f64::min);
    if h > 0.5 * extent {
        return Err(invalid("mesh.edge_length", format!("mesh.edge_length = {h} m leaves fewer than 2 elements across the smallest panel ({extent:.3} m); use at most {:.4}", 0.5 * extent)));
    }
    Ok((extent, garment))
}


/// Refuses, before any panel is meshed, a pattern whose mesh at edge length `h` would pass
/// the vertex cap or the memory this run has: the count is estimated from the outlines'
/// areas (an equilateral mesh has 2/(√3·h²) vertices per square metre) and perimeters.
fn check_size(c: &SceneConfig, g: &garment::GarmentConfig, h: f64) -> Result<(), Invalid> {
    let metres = g.units.metres();
    let (mut area, mut perimeter) = (0.0, 0.0);
    for panel in &g.panels {
        let Ok(curves) = panel.curves(metres) else { continue };
        let (lo, hi) = curves.iter().flat_map(|c| &c.points).fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        if (hi - lo).max_element() > garment::MAX_PANEL_ACROSS {
            // A unit slip: the pattern's own check names garment.units.
            return Ok(());
        }
        let points = curves.iter().flat_map(|c| c.points.windows(2));
        area += points.clone().map(|w| 0.5 * w[0].perp_dot(w[1])).sum::<f64>().abs();
        perimeter += curves.iter().map(|c| c.length()).sum::<f64>();
    }
    let planned = |h: f64| 2.0 * area / (3f64.sqrt() * h * h) + perimeter / h;
    let vertices = planned(h);
    if vertices > MAX_VERTICES as f64 {
        let least = 1.001 * h * (vertices / MAX_VERTICES as f64).sqrt();
        return Err(invalid(
            "mesh.edge_length",
            format!(
                "mesh.edge_length = {} m gives about {} vertices over the panels' {} m², more than the limit of {MAX_VERTICES}; use at least {least:.3e} m",
                short(h),
                short(vertices),
                short(area)
            ),
        ));
    }
    if let Some(available) = super::memory::available_bytes() {
        super::memory::check(vertices as usize, h, c.solver.newton.preconditioner, available).map_err(|e| invalid("mesh.edge_length", e))?;
    }
    Ok(())
}
