//! A pattern file as a garment: its pieces read, made panels, sewn by a seams file where
//! one is given, placed around the form, its hem found (docs/garments.md, "Patterns from
//! pattern CAD").

use super::panels::{self, Arrangement, PiecePanel, Top};
use super::seams::{SeamsFile, resolve};
use super::{DxfPattern, ReadOptions, read};
use crate::garment::form::FormConfig;
use crate::garment::import::{Imported, Origin, garment, hem_edges, hem_note};
use crate::garment::pattern::{PanelConfig, Units};
use crate::garment::place::Placement;
use crate::garment::seams::SeamConfig;
use crate::garment::stretch::Outline;
use crate::garment::{GarmentError, default_seam_ease};
use glam::DVec2;

/// How a pattern file becomes a garment.
#[derive(Debug, Clone)]
pub struct ImportOptions {
    pub read: ReadOptions,
    /// Which pieces go where, beyond what their names say.
    pub arrangement: Arrangement,
    /// The form the garment goes on (a bundled size: placement needs its measurements).
    pub form: FormConfig,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self { read: ReadOptions::default(), arrangement: Arrangement::default(), form: crate::garment::import::default_form() }
    }
}

/// Where the panels of a DXF import come from, for the scene file's header.
pub const ORIGIN: Origin<'static> = Origin {
    format: "the pattern CAD file (DXF, AAMA / ASTM)",
    short: "pattern CAD",
    placement: "each panel starts around the form where its name puts it (front, back, sleeve, sides), outlines as drawn (sew lines).",
};

/// The largest relative difference between a seam's sides an import sets
/// `garment.seam_ease` to (a sleeve cap eased into its armhole is a few per cent).
const MAX_EASE: f64 = 0.2;

/// The pattern read and its panels placed around the form with their tops at the level
/// returned, the seams file's placement taken in; what `rosette pattern seams` suggests from.
pub fn placed(bytes: &[u8], source: &str, options: &ImportOptions, seams: Option<&SeamsFile>) -> Result<(DxfPattern, Vec<PiecePanel>, Top), GarmentError> {
    let bad = |m: String| GarmentError::new(format!("{source}: {m}"));
    let pattern = read(bytes, source, &options.read)?;
    let mut arrangement = options.arrangement.clone();
    if let Some(file) = seams {
        file.placement.merge_into(&mut arrangement).map_err(bad)?;
    }
    let mut pieces = panels::panels(&pattern, &arrangement).map_err(bad)?;
    let measurements = options
        .form
        .measurements(Units::Cm)
        .map_err(|e| bad(e.message))?
        .ok_or_else(|| bad("the pieces are placed around a generated form: give a form size, not an OBJ body".into()))?;
    let top = panels::top(&pattern, &arrangement);
    panels::arrange(&mut pieces, &measurements, top);
    Ok((pattern, pieces, top))
}

/// Reads a pattern file's bytes (from `source`) and, where given, its seams file (its
/// text and where it came from) into a garment section in centimetres.
pub fn import(bytes: &[u8], source: &str, options: &ImportOptions, seams_file: Option<(&SeamsFile, &str)>) -> Result<Imported, GarmentError> {
    let (pattern, mut pieces, _) = placed(bytes, source, options, seams_file.map(|s| s.0))?;
    let mut notes = pattern.notes.clone();
    notes.push(format!("read in {}{}", pattern.units.name(), pattern.style.as_ref().map_or(String::new(), |s| format!("; style '{s}'"))));
    for piece in &pattern.pieces {
        let copies: Vec<&str> = pieces.iter().filter(|p| p.piece == piece.name).map(|p| p.panel.name.as_str()).collect();
        let allowance = piece.seam_allowance.map_or_else(|| "no sew line".to_string(), |[lo, mean, hi]| {
            if hi - lo > 0.5 { format!("seam allowance {lo:.1} to {hi:.1} mm (kept as {mean:.1})") } else { format!("seam allowance {mean:.1} mm") }
        });
        let extras = if piece.drill_holes.is_empty() && piece.internal_lines == 0 {
            String::new()
        } else {
            format!("; {} drill hole(s) and {} internal line(s), not simulated", piece.drill_holes.len(), piece.internal_lines)
        };
        notes.push(format!(
            "piece '{}' → {}: {allowance}, grain {:.1}°{}, {} notch(es){extras}",
            piece.name,
            copies.join(" and "),
            piece.grain_deg,
            if piece.grain_given { "" } else { " (--grain-deg)" },
            piece.notches.len()
        ));
    }
    let configs: Vec<PanelConfig> = pieces.iter().map(|p| p.panel.clone()).collect();
    let seams = match seams_file {
        Some((file, seams_source)) => resolve(file, &configs, seams_source)?,
        None => Vec::new(),
    };
    if let Some((_, seams_source)) = seams_file {
        let sewn = |name: &str| seams.iter().any(|s| [&s.a, &s.b].iter().any(|k| k.split('.').next() == Some(name)));
        let left: Vec<String> = pieces.iter().filter(|p| !sewn(&p.panel.name)).map(|p| p.panel.name.clone()).collect();
        if left.len() == pieces.len() {
            return Err(GarmentError::new(format!("{seams_source}: it sews no piece; add [[seams]] entries (`rosette pattern seams {source}` suggests some)")));
        }
        if !left.is_empty() {
            notes.push(format!("left out, in no seam of {seams_source}: {}", left.join(", ")));
            pieces.retain(|p| !left.contains(&p.panel.name));
        }
    } else {
        notes.push(format!("no seams file: the panels are not sewn; write one (`rosette pattern seams {source}` suggests seams), or sew them in the viewer's flat pattern"));
    }
    let panels: Vec<PanelConfig> = pieces.into_iter().map(|p| p.panel).collect();
    let ease = seam_ease(&panels, &seams, source, &mut notes)?;
    let (heights, stitched) = heights_and_stitched(&panels, &seams)?;
    let hem = hem_edges(&panels, &heights, &stitched);
    notes.push(hem_note(&hem));
    Ok(Imported { garment: garment(options.form.clone(), panels, seams, hem, ease), notes })
}

/// The ease the seams need: the default, or raised to the largest difference between a
/// seam's sides up to [`MAX_EASE`] (with a note); beyond it the seam is refused.
fn seam_ease(panels: &[PanelConfig], seams: &[SeamConfig], source: &str, notes: &mut Vec<String>) -> Result<f64, GarmentError> {
    let outlines: Vec<Outline> = panels.iter().map(Outline::new).collect::<Result<_, _>>()?;
    let length = |key: &str, span: Option<[f64; 2]>| -> Option<f64> {
        let (panel, edge) = key.split_once('.')?;
        let p = panels.iter().position(|x| x.name == panel)?;
        let e = outlines[p].edges.iter().find(|x| x.0 == edge)?;
        Some(span.map_or(e.2, |[a, b]| b - a))
    };
    let mut ease = default_seam_ease();
    for s in seams {
        let (Some(la), Some(lb)) = (length(&s.a, s.a_span), length(&s.b, s.b_span)) else { continue };
        let share = (la - lb).abs() / la.max(lb);
        if share >= MAX_EASE {
            return Err(GarmentError::new(format!(
                "{source}: the seam of {} ({la:.1} cm) and {} ({lb:.1} cm) differs by {:.0} %, more than the {:.0} % a seam eases; check the seams file's points",
                s.a,
                s.b,
                100.0 * share,
                100.0 * MAX_EASE
            )));
        }
        if share > ease {
            ease = ((100.0 * share + 1.0).ceil() / 100.0).min(MAX_EASE);
            notes.push(format!("garment.seam_ease = {ease}: the seam of {} and {} differs by {:.1} %", s.a, s.b, 100.0 * share));
        }
    }
    Ok(ease)
}

/// Each edge's end heights where the panels start (cm above the floor), and each panel's
/// edges that a seam sews (in whole or in part).
type HeightsAndStitched = (Vec<Vec<[f64; 2]>>, Vec<Vec<usize>>);

fn heights_and_stitched(panels: &[PanelConfig], seams: &[SeamConfig]) -> Result<HeightsAndStitched, GarmentError> {
    let mut heights = Vec::with_capacity(panels.len());
    let mut stitched = vec![Vec::new(); panels.len()];
    for (p, panel) in panels.iter().enumerate() {
        let curves = panel.curves(1.0)?;
        let (lo, hi) = crate::garment::flat::bounds(&curves.iter().flat_map(|c| c.points.iter().copied()).collect::<Vec<_>>());
        let anchor = panel.anchor.map_or(DVec2::new(0.5 * (lo.x + hi.x), hi.y), DVec2::from_array);
        let place = Placement::new(&panel.placement, anchor, DVec2::ZERO, 1.0);
        heights.push(curves.iter().map(|c| [place.position(c.points[0]).z, place.position(*c.points.last().unwrap()).z]).collect());
        for s in seams {
            for key in [&s.a, &s.b] {
                if let Some((name, edge)) = key.split_once('.')
                    && name == panel.name
                    && let Some(e) = panel.edges.iter().position(|x| x.name == edge)
                {
                    stitched[p].push(e);
                }
            }
        }
    }
    Ok((heights, stitched))
}
