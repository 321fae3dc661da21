//! Garments: flat pattern pieces cut on the grain a designer chooses, placed around a
//! dress form, sewn together and draped (docs/garments.md).
//!
//! ```text
//!   panels (outlines, grain) ─▶ cut points agreed along seams ─▶ CDT meshes (spade)
//!        │                                                          │
//!   placement around the form ─────────────▶ one cloth of panels, seam vertex pairs
//!        │                                                          │
//!   sewing springs ramped up, attachments pulled to the form ─▶ welded into one surface
//! ```
//!
//! This module builds the pattern and the form (`Garment`); `scene::garment` runs them.

pub mod dxf;
pub mod flat;
pub mod form;
pub mod garmentcode;
pub mod import;
pub mod mesh;
pub mod pattern;
pub mod place;
pub mod seams;
pub mod stretch;

use crate::sim::model::PanelSurface;
use glam::{DVec2, DVec3};
use mesh::PanelMesh;
use pattern::{PanelConfig, Polyline, Units};
use seams::{AttachmentConfig, Direction, SeamConfig, Side};
use serde::{Deserialize, Serialize};

/// A pattern that cannot be made: the message names the panel and the edge.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct GarmentError {
    pub message: String,
}

impl GarmentError {
    pub fn new(message: String) -> Self {
        Self { message }
    }
}

/// `[garment]`: the pattern, its seams, the form and the sewing.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentConfig {
    /// Unit of every length in this section: "cm" (default) or "m".
    #[serde(default)]
    pub units: Units,
    pub form: form::FormConfig,
    pub panels: Vec<PanelConfig>,
    #[serde(default)]
    pub seams: Vec<SeamConfig>,
    #[serde(default)]
    pub attachments: Vec<AttachmentConfig>,
    /// The edges whose vertices are the hem (`panel.edge`); default: every edge named `hem`.
    #[serde(default)]
    pub hem: Vec<String>,
    /// Largest relative difference between the lengths of a seam's two sides (easing
    /// beyond it is a pattern error).
    #[serde(default = "default_seam_ease")]
    pub seam_ease: f64,
    /// The sewing springs' stiffness, N/m (doubled every 0.05 s past the ramp while a
    /// seam is still open).
    #[serde(default = "default_sewing_stiffness")]
    pub sewing_stiffness: f64,
    /// Time over which the springs' rest lengths shrink from the seams' starting gaps to
    /// zero (the seams close on this schedule), s.
    #[serde(default = "default_sewing_ramp")]
    pub sewing_ramp: f64,
    /// Air damping while the seams close, 1/s (the scene's `solver.damping` from the weld):
    /// strong enough that the panels are drawn together without overshoot, whose sides
    /// would pass each other and be welded folded.
    #[serde(default = "default_sewing_damping")]
    pub sewing_damping: f64,
    /// Time by which every seam must be closed, s; a garment still open then is reported as
    /// not sewn.
    #[serde(default = "default_sewing_time")]
    pub sewing_time: f64,
    /// A seam is closed (and welded) once every pair of its vertices is within this share
    /// of the contact thickness.
    #[serde(default = "default_closed_share")]
    pub closed_share: f64,
}

pub(crate) fn default_seam_ease() -> f64 {
    0.05
}
pub(crate) fn default_sewing_stiffness() -> f64 {
    50.0
}
fn default_sewing_ramp() -> f64 {
    0.5
}
fn default_sewing_damping() -> f64 {
    50.0
}
fn default_sewing_time() -> f64 {
    1.5
}
pub(crate) fn default_closed_share() -> f64 {
    0.25
}

/// A built garment, before sewing: the panels' meshes in one cloth, where it starts, and
/// which vertices the seams, the attachments and the hem are.
#[derive(Debug, Clone)]
pub struct Garment {
    pub names: Vec<(String, Vec<String>)>,
    pub meshes: Vec<PanelMesh>,
    /// Grain angle of each panel, radians from its x axis.
    pub grains: Vec<f64>,
    /// First vertex of each panel in the cloth.
    pub offsets: Vec<u32>,
    pub surface: PanelSurface,
    /// Starting positions, m.
    pub positions: Vec<DVec3>,
    /// Each seam's vertex pairs, side a then side b, in order along side a.
    pub seams: Vec<Vec<[u32; 2]>>,
    /// Pinned vertices, and the edges pulled onto the form (their vertices in order) with
    /// the height they go to (m).
    pub pinned: Vec<u32>,
    pub attached_edges: Vec<(Vec<u32>, f64)>,
    pub hem: Vec<u32>,
    /// Seam side lengths along the panels (m): (a, b) per seam.
    pub seam_lengths: Vec<(f64, f64)>,
}

impl Garment {
    /// All seam pairs.
    pub fn seam_pairs(&self) -> Vec<[u32; 2]> {
        let mut pairs: Vec<[u32; 2]> = self.seams.iter().flatten().map(|&[a, b]| if a < b { [a, b] } else { [b, a] }).collect();
        pairs.sort_unstable();
        pairs.dedup();
        pairs
    }
}

/// Builds the garment's panels at `edge_length` (m) around a form whose axis stands at
/// `axis` (m), with `levels` giving the height (m) of a named level of the form.
pub fn build(config: &GarmentConfig, edge_length: f64, axis: DVec2, levels: &dyn Fn(&str) -> Option<f64>) -> Result<Garment, GarmentError> {
    let metres = config.units.metres();
    let names: Vec<(String, Vec<String>)> = config.panels.iter().map(|p| (p.name.clone(), p.edges.iter().map(|e| e.name.clone()).collect())).collect();
    check_names(&names)?;
    let mut curves: Vec<Vec<Polyline>> = Vec::with_capacity(config.panels.len());
    for panel in &config.panels {
        if !(panel.grain_deg.is_finite() && panel.grain_deg.abs() <= 360.0) {
            return Err(GarmentError::new(format!(
                "garment.panels '{}': grain_deg = {} must be a finite angle in degrees, between -360 and 360",
                panel.name, panel.grain_deg
            )));
        }
        let c = panel.curves(metres)?;
        // A panel wider than the reach on both sides of the form is a unit slip (cm numbers
        // read as m); caught here, before the mesh's size is judged by it.
        let (lo, hi) = c.iter().flat_map(|e| &e.points).fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let across = (hi - lo).max_element();
        if across > MAX_PANEL_ACROSS {
            return Err(GarmentError::new(format!(
                "garment.panels '{}' is {across:.1} m across, more than a garment's {} m; check garment.units (now {})",
                panel.name,
                2.0 * MAX_REACH,
                config.units.name()
            )));
        }
        let edge_names: Vec<&str> = panel.edges.iter().map(|e| e.name.as_str()).collect();
        pattern::check_simple(&panel.name, &edge_names, &c)?;
        panel.notch_positions(&c, metres)?;
        if let Some(allowance) = panel.seam_allowance
            && !(allowance.is_finite() && allowance >= 0.0 && allowance * metres <= MAX_SEAM_ALLOWANCE)
        {
            return Err(GarmentError::new(format!(
                "garment.panels '{}': seam_allowance = {allowance} must be a width between 0 and {} {} (it is kept for export, not sewn)",
                panel.name,
                MAX_SEAM_ALLOWANCE / metres,
                config.units.name()
            )));
        }
        curves.push(c);
    }
    // Refinement leaves triangles of about (√3/4) h²: refuse a mesh past the vertex cap
    // before making it (or the seams' samples, whose counts go as 1/h).
    let area: f64 = curves.iter().map(|c| c.iter().flat_map(|e| e.points.windows(2)).map(|w| 0.5 * w[0].perp_dot(w[1])).sum::<f64>()).sum();
    let planned = 0.5 * area / (0.433 * edge_length * edge_length);
    let limit = crate::sim::mesh::MAX_VERTICES as f64;
    if planned.is_nan() || planned > limit {
        use crate::io::number::short;
        // The edge that gives the limit: the count goes as 1/h².
        let least = (0.5 * area / (0.433 * limit)).sqrt();
        return Err(GarmentError::new(format!(
            "mesh.edge_length = {} m gives about {} vertices, more than the limit of {}; use at least {}",
            short(edge_length),
            short(planned),
            crate::sim::mesh::MAX_VERTICES,
            short(least)
        )));
    }
    let lengths: Vec<Vec<f64>> = curves.iter().map(|c| c.iter().map(Polyline::length).collect()).collect();
    let (sides, counts) = seam_sides(config, &names, &lengths, edge_length)?;
    let cuts = seams::cuts(&lengths, &sides, &counts, edge_length, &names)?;
    let meshes: Vec<PanelMesh> =
        config.panels.iter().zip(&curves).zip(&cuts).map(|((p, c), cut)| mesh::mesh_panel(&p.name, c, cut, edge_length)).collect::<Result<_, _>>()?;
    let grains: Vec<f64> = config.panels.iter().map(|p| p.grain_deg.to_radians()).collect();
    let (surface, offsets) = assemble(&meshes, &grains);
    let mut positions = Vec::with_capacity(surface.pattern.len());
    for (panel, m) in config.panels.iter().zip(&meshes) {
        let anchor = match panel.anchor {
            Some(a) => DVec2::from_array(a) * metres,
            None => {
                let (lo, hi) = m.points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
                DVec2::new(0.5 * (lo.x + hi.x), hi.y)
            }
        };
        check_placement(panel, config.units)?;
        let place = place::Placement::new(&panel.placement, anchor, axis, metres);
        let start = positions.len();
        positions.extend(m.points.iter().map(|&p| place.position(p)));
        check_reach(panel, config.units, &positions[start..], axis)?;
    }
    let seams = seam_pairs(&sides, &cuts, &meshes, &offsets, config);
    let seam_lengths = sides.iter().map(|(a, b)| (a.to - a.from, b.to - b.from)).collect();
    let edge_vertices = |key: &str, text: &str| -> Result<Vec<u32>, GarmentError> {
        let (p, e) = seams::resolve(key, text, &names)?;
        Ok(meshes[p].edge_vertices[e].iter().map(|v| v + offsets[p]).collect())
    };
    let (mut pinned, mut attached_edges) = (Vec::new(), Vec::new());
    for (i, a) in config.attachments.iter().enumerate() {
        let key = format!("garment.attachments[{i}].edge");
        let vertices = edge_vertices(&key, &a.edge)?;
        match (a.pin, &a.level, a.height) {
            (true, None, None) => pinned.extend(vertices),
            (false, Some(level), None) => {
                let z = levels(level).ok_or_else(|| {
                    GarmentError::new(format!("garment.attachments[{i}].level = \"{level}\": the form has no such level; use waist, hip or bust (a generated form), or height"))
                })?;
                attached_edges.push((vertices, z));
            }
            (false, None, Some(h)) if h.is_finite() && h > 0.0 && h * metres <= MAX_REACH => attached_edges.push((vertices, h * metres)),
            (false, None, Some(h)) if h.is_finite() => {
                return Err(GarmentError::new(format!(
                    "garment.attachments[{i}].height = {h} {} is not on the form: give a height above the floor, at most {MAX_REACH} m",
                    config.units.name()
                )));
            }
            _ => return Err(GarmentError::new(format!("garment.attachments[{i}]: give exactly one of pin = true, level or height (finite)"))),
        }
    }
    let hem_keys: Vec<String> = if config.hem.is_empty() {
        names.iter().flat_map(|(p, edges)| edges.iter().filter(|e| *e == "hem").map(move |e| format!("{p}.{e}"))).collect()
    } else {
        config.hem.clone()
    };
    let mut hem = Vec::new();
    for text in &hem_keys {
        hem.extend(edge_vertices("garment.hem", text)?);
    }
    hem.sort_unstable();
    hem.dedup();
    Ok(Garment { names, meshes, grains, offsets, surface, positions, seams, pinned, attached_edges, hem, seam_lengths })
}

fn check_names(names: &[(String, Vec<String>)]) -> Result<(), GarmentError> {
    if names.is_empty() {
        return Err(GarmentError::new("garment.panels: a garment needs at least one [[garment.panels]] table".into()));
    }
    for (i, (panel, edges)) in names.iter().enumerate() {
        if names[..i].iter().any(|(n, _)| n == panel) {
            return Err(GarmentError::new(format!("garment.panels: two panels are named '{panel}'; give each its own name")));
        }
        for (j, e) in edges.iter().enumerate() {
            if edges[..j].contains(e) {
                return Err(GarmentError::new(format!("garment.panels '{panel}': two edges are named '{e}'; give each its own name")));
            }
        }
    }
    Ok(())
}

fn check_placement(panel: &PanelConfig, units: Units) -> Result<(), GarmentError> {
    let p = &panel.placement;
    let finite = [p.angle_deg, p.distance, p.height, p.flare_deg].iter().all(|v| v.is_finite());
    if !finite || p.distance <= 0.0 || p.height <= 0.0 || p.angle_deg.abs() > 360.0 || !(0.0..=90.0).contains(&p.flare_deg) {
        return Err(GarmentError::new(format!(
            "garment.panels '{}': placement needs angle_deg between -360 and 360, a positive distance and height (above the floor) in {} and flare_deg between 0 and 90",
            panel.name,
            units.name()
        )));
    }
    Ok(())
}

/// The widest seam allowance a piece may carry, m: hems are turned up by a few centimetres,
/// never by a tenth of a metre.
const MAX_SEAM_ALLOWANCE: f64 = 0.1;

/// How far from the form's axis, and above or below its floor point, a placed panel may
/// start, m. A designer arranges panels around the body; a panel metres away (an anchor or
/// distance typed in the wrong units) would fall for seconds before its seams could close.
const MAX_REACH: f64 = 5.0;
/// The widest a panel may be, m: a garment's reach on both sides of the form.
pub const MAX_PANEL_ACROSS: f64 = 2.0 * MAX_REACH;

/// Refuses a panel whose placed points (m) are not finite or lie beyond [`MAX_REACH`].
fn check_reach(panel: &PanelConfig, units: Units, placed: &[DVec3], axis: DVec2) -> Result<(), GarmentError> {
    // The axis itself is checked with the settings (`garment.form.axis`); a NaN distance
    // counts as out of reach.
    let reach = placed.iter().map(|p| (p.truncate() - axis).length().max(p.z.abs())).fold(0.0, |r: f64, d| if d.is_nan() { f64::INFINITY } else { r.max(d) });
    if reach <= MAX_REACH {
        return Ok(());
    }
    let shown = match reach {
        r if r < 1e4 => format!("{r:.2} m"),
        r if r.is_finite() => format!("{r:.2e} m"),
        _ => "at no finite position (a value is not a number)".into(),
    };
    Err(GarmentError::new(format!(
        "garment.panels '{}': placed, its farthest point lies {shown} from the form's axis or floor (at most {MAX_REACH} m); check its anchor and placement (distance, height), in {}",
        panel.name,
        units.name()
    )))
}

/// Every seam's two sides, and the number of parts each seam is cut into.
type SeamSides = (Vec<(Side, Side)>, Vec<usize>);

/// Resolves every seam's sides and the number of parts each is cut into.
fn seam_sides(config: &GarmentConfig, names: &[(String, Vec<String>)], lengths: &[Vec<f64>], edge_length: f64) -> Result<SeamSides, GarmentError> {
    let metres = config.units.metres();
    if !(config.seam_ease.is_finite() && (0.0..0.5).contains(&config.seam_ease)) {
        return Err(GarmentError::new(format!("garment.seam_ease = {} must be a share between 0 and 0.5", config.seam_ease)));
    }
    let mut sides = Vec::with_capacity(config.seams.len());
    let mut counts = Vec::with_capacity(config.seams.len());
    for (i, s) in config.seams.iter().enumerate() {
        let key = format!("garment.seams[{i}]");
        let (pa, ea) = seams::resolve(&format!("{key}.a"), &s.a, names)?;
        let (pb, eb) = seams::resolve(&format!("{key}.b"), &s.b, names)?;
        let a = seams::side(&format!("{key}.a"), (pa, ea), s.a_span, lengths[pa][ea], metres)?;
        let b = seams::side(&format!("{key}.b"), (pb, eb), s.b_span, lengths[pb][eb], metres)?;
        let (la, lb) = (a.to - a.from, b.to - b.from);
        if (la - lb).abs() > config.seam_ease * la.max(lb) {
            return Err(GarmentError::new(format!(
                "{key}: side a ({}, {:.2} {u}) and side b ({}, {:.2} {u}) differ in length by {:.1} %, more than garment.seam_ease = {} allows; \
                 fix the pattern or sew only a stretch with a_span / b_span",
                s.a,
                la / metres,
                s.b,
                lb / metres,
                100.0 * (la - lb).abs() / la.max(lb),
                config.seam_ease,
                u = config.units.name()
            )));
        }
        sides.push((a, b));
        counts.push(((la.max(lb) / edge_length).round() as usize).max(1));
    }
    Ok((sides, counts))
}

/// The vertices of each seam side, matched pair by pair.
fn seam_pairs(sides: &[(Side, Side)], cuts: &[Vec<mesh::Cuts>], meshes: &[PanelMesh], offsets: &[u32], config: &GarmentConfig) -> Vec<Vec<[u32; 2]>> {
    let side_vertices = |s: &Side| -> Vec<u32> {
        let cut = &cuts[s.panel][s.edge];
        let nearest = |x: f64| (0..cut.len()).min_by(|&i, &j| (cut[i] - x).abs().total_cmp(&(cut[j] - x).abs())).expect("an edge has cuts");
        let (i0, i1) = (nearest(s.from), nearest(s.to));
        meshes[s.panel].edge_vertices[s.edge][i0..=i1].iter().map(|v| v + offsets[s.panel]).collect()
    };
    sides
        .iter()
        .zip(&config.seams)
        .map(|((a, b), s)| {
            let (va, mut vb) = (side_vertices(a), side_vertices(b));
            if s.direction == Direction::Opposite {
                vb.reverse();
            }
            va.into_iter().zip(vb).map(|(x, y)| [x, y]).collect()
        })
        .collect()
}

/// The panels as one cloth: vertices in panel order, each triangle's corners in its
/// panel's warp frame, the flat pattern with the panels side by side as cut, and the
/// texture space with each panel turned into its warp frame (the weave along its grain).
fn assemble(meshes: &[PanelMesh], grains: &[f64]) -> (PanelSurface, Vec<u32>) {
    let mut surface = PanelSurface::default();
    let mut offsets = Vec::with_capacity(meshes.len());
    let in_warp: Vec<Vec<DVec2>> = meshes.iter().zip(grains).map(|(m, &grain)| m.points.iter().map(|&p| DVec2::from_angle(-grain).rotate(p)).collect()).collect();
    let pattern_shifts = flat::lay_out(meshes.iter().map(|m| m.points.as_slice()));
    let texture_shifts = flat::lay_out(in_warp.iter().map(Vec::as_slice));
    for (((m, points), pattern_shift), texture_shift) in meshes.iter().zip(&in_warp).zip(pattern_shifts).zip(texture_shifts) {
        let offset = surface.pattern.len() as u32;
        offsets.push(offset);
        surface.pattern.extend(m.points.iter().map(|&p| p + pattern_shift));
        surface.texture.extend(points.iter().map(|&p| p + texture_shift));
        for t in &m.triangles {
            surface.triangles.push(t.map(|v| v + offset));
            surface.corners.push(t.map(|v| points[v as usize]));
        }
    }
    (surface, offsets)
}
