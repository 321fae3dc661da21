//! The flat pattern as a designer reads it: each panel's outline as cut, laid side by side
//! the way the texture space lays them ([`lay_out`], shared with the cloth's texture
//! coordinates), its grain line, and each seam's two stretches, for the viewer's pattern
//! window. Built from the `[garment]` section alone (no meshing), so it follows the grain
//! being edited before the garment is recut.

use super::pattern::{Polyline, Units};
use super::stretch::Outline;
use super::{GarmentConfig, GarmentError, check_names, seams};
use glam::DVec2;

/// Gap between panels laid side by side on the flat pattern (the viewer's and the export's
/// texture space), m.
pub const PATTERN_GAP: f64 = 0.05;

/// Each set of points moved by the shift that lays it beside the one before, with
/// [`PATTERN_GAP`] between them: its bounding box's lower left corner at (x, 0), x the
/// widths laid before plus the gaps.
pub fn lay_out<'a>(shapes: impl IntoIterator<Item = &'a [DVec2]>) -> Vec<DVec2> {
    let mut shifts = Vec::new();
    let mut x = 0.0;
    for points in shapes {
        let (lo, hi) = bounds(points);
        shifts.push(DVec2::new(x, 0.0) - lo);
        x += hi.x - lo.x + PATTERN_GAP;
    }
    shifts
}

/// Lower left and upper right corners of the points' bounding box.
pub fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

/// One panel, laid out: m, in the pattern's plane.
#[derive(Debug, Clone, PartialEq)]
pub struct FlatPanel {
    pub name: String,
    /// The closed outline, counter-clockwise, its first point not repeated at the end.
    pub outline: Vec<DVec2>,
    /// The warp's direction, radians from the panel's x axis (`grain_deg`).
    pub grain: f64,
    /// Centre of the outline's bounding box, where the grain line is drawn.
    pub centre: DVec2,
    /// Width and height of the bounding box.
    pub size: DVec2,
    /// Its named points (corners `cK` of a DXF import's edges `eK`, notches), each with its
    /// distance along the outline from its start (garment units) and where it is drawn.
    pub points: Vec<(String, f64, DVec2)>,
    /// Distance along the outline (garment units) at each point of `outline`, and at its
    /// end (the perimeter) last.
    pub arc: Vec<f64>,
}

/// One seam's two stretches, laid out, each from its start to its end along its edge;
/// `a[0]` is sewn to `b[0]` (the `direction` resolved).
#[derive(Debug, Clone, PartialEq)]
pub struct FlatSeam {
    pub a: Vec<DVec2>,
    pub b: Vec<DVec2>,
    /// The two stretches' lengths, in the garment's units.
    pub lengths: [f64; 2],
}

#[derive(Debug, Clone, PartialEq)]
pub struct FlatPattern {
    pub panels: Vec<FlatPanel>,
    pub seams: Vec<FlatSeam>,
    /// The unit of the lengths along outlines and seams.
    pub units: Units,
}

/// The point `at` along a closed outline (garment units, `arc` its distances).
pub fn along(outline: &[DVec2], arc: &[f64], at: f64) -> DVec2 {
    let perimeter = *arc.last().unwrap_or(&0.0);
    let at = if perimeter > 0.0 { at.rem_euclid(perimeter) } else { 0.0 };
    let i = arc.partition_point(|&a| a <= at).clamp(1, outline.len()) - 1;
    let (a0, a1) = (arc[i], arc[i + 1]);
    let t = if a1 > a0 { (at - a0) / (a1 - a0) } else { 0.0 };
    outline[i].lerp(outline[(i + 1) % outline.len()], t)
}

/// Points sampled along each seam stretch.
const SEAM_SAMPLES: usize = 24;

impl FlatPattern {
    /// The pattern of `config`, its panels cut on `grains_deg` (one per panel; the
    /// section's own where `None`).
    pub fn new(config: &GarmentConfig, grains_deg: Option<&[f64]>) -> Result<Self, GarmentError> {
        let metres = config.units.metres();
        let names: Vec<(String, Vec<String>)> = config.panels.iter().map(|p| (p.name.clone(), p.edges.iter().map(|e| e.name.clone()).collect())).collect();
        check_names(&names)?;
        let curves: Vec<Vec<Polyline>> = config.panels.iter().map(|p| p.curves(metres)).collect::<Result<_, _>>()?;
        let outlines: Vec<Vec<DVec2>> = curves.iter().map(|c| c.iter().flat_map(|e| e.points[..e.points.len() - 1].iter().copied()).collect()).collect();
        let shifts = lay_out(outlines.iter().map(Vec::as_slice));
        let panels = config
            .panels
            .iter()
            .zip(&outlines)
            .zip(&shifts)
            .enumerate()
            .map(|(i, ((panel, outline), &shift))| {
                let outline: Vec<DVec2> = outline.iter().map(|&p| p + shift).collect();
                let (lo, hi) = bounds(&outline);
                let grain = grains_deg.and_then(|g| g.get(i).copied()).unwrap_or(panel.grain_deg).to_radians();
                let mut arc = vec![0.0];
                for k in 0..outline.len() {
                    arc.push(arc[k] + outline[k].distance(outline[(k + 1) % outline.len()]) / metres);
                }
                let named = Outline::new(panel).map(|o| o.point_names(panel)).unwrap_or_default();
                let points = named
                    .into_iter()
                    .map(|(name, at)| {
                        let position = along(&outline, &arc, at);
                        (name, at, position)
                    })
                    .collect();
                FlatPanel { name: panel.name.clone(), outline, grain, centre: 0.5 * (lo + hi), size: hi - lo, points, arc }
            })
            .collect::<Vec<FlatPanel>>();
        let mut flat_seams = Vec::with_capacity(config.seams.len());
        for (i, s) in config.seams.iter().enumerate() {
            let key = format!("garment.seams[{i}]");
            let stretch = |side: &str, text: &str, span| -> Result<Vec<DVec2>, GarmentError> {
                let (p, e) = seams::resolve(&format!("{key}.{side}"), text, &names)?;
                let edge = &curves[p][e];
                let side = seams::side(&format!("{key}.{side}"), (p, e), span, edge.length(), metres)?;
                Ok((0..=SEAM_SAMPLES).map(|k| edge.at(side.from + (side.to - side.from) * k as f64 / SEAM_SAMPLES as f64) + shifts[p]).collect())
            };
            let a = stretch("a", &s.a, s.a_span)?;
            let mut b = stretch("b", &s.b, s.b_span)?;
            if s.direction == seams::Direction::Opposite {
                b.reverse();
            }
            let length = |text: &str, span: Option<[f64; 2]>| -> Result<f64, GarmentError> {
                let (p, e) = seams::resolve(&key, text, &names)?;
                Ok(span.map_or(curves[p][e].length() / metres, |[from, to]| to - from))
            };
            flat_seams.push(FlatSeam { a, b, lengths: [length(&s.a, s.a_span)?, length(&s.b, s.b_span)?] });
        }
        Ok(Self { panels, seams: flat_seams, units: config.units })
    }

    /// Lower left and upper right corners of everything drawn.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        let (lo, hi) = bounds(&self.panels.iter().flat_map(|p| p.outline.iter().copied()).collect::<Vec<_>>());
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `[garment]` of a bundled scene, over its bundled base.
    fn garment(name: &str) -> GarmentConfig {
        let bundled = crate::settings::SCENES.iter().find(|s| s.name == name).unwrap();
        let (table, _) = crate::settings::read::with_base(bundled.text.parse().unwrap(), name).unwrap();
        toml::Value::Table(table["garment"].as_table().unwrap().clone()).try_into().unwrap()
    }

    /// Panels lie side by side without overlap; each seam's stretches have the lengths of
    /// the edges they sew (within the ease the pattern allows) and start where the edges
    /// they name start or end; a grain override turns only the grain.
    #[test]
    fn the_gored_skirt_lies_flat_with_its_seams_on_their_edges() {
        let config = garment("skirt-gored-straight");
        let flat = FlatPattern::new(&config, None).unwrap();
        assert_eq!(flat.panels.len(), config.panels.len());
        for w in flat.panels.windows(2) {
            let right = w[0].outline.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
            let left = w[1].outline.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
            assert!((left - right - PATTERN_GAP).abs() < 1e-9, "{} then {}: gap {}", w[0].name, w[1].name, left - right);
        }
        let length = |points: &[DVec2]| points.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>();
        assert_eq!(flat.seams.len(), config.seams.len());
        for (seam, s) in flat.seams.iter().zip(&config.seams) {
            let (la, lb) = (length(&seam.a), length(&seam.b));
            assert!((la - lb).abs() <= config.seam_ease * la.max(lb), "{} / {}: {la} against {lb}", s.a, s.b);
            let on_outline = |p: DVec2| flat.panels.iter().any(|panel| panel.outline.iter().any(|q| q.distance(p) < 1e-9));
            for p in [seam.a[0], *seam.a.last().unwrap(), seam.b[0], *seam.b.last().unwrap()] {
                assert!(on_outline(p), "{} / {}: end {p} is not a corner of an outline", s.a, s.b);
            }
        }
        let bias = FlatPattern::new(&config, Some(&vec![45.0; config.panels.len()])).unwrap();
        for (b, s) in bias.panels.iter().zip(&flat.panels) {
            assert_eq!(b.outline, s.outline);
            assert!((b.grain - 45f64.to_radians()).abs() < 1e-12 && (s.grain - 90f64.to_radians()).abs() < 1e-12);
        }
    }
}
