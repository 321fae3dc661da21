//! Writing a garment's panels as a pattern file in the AAMA / ASTM D6673 convention, R12
//! ASCII: one block per panel (its cut line on layer 1, its sew line on layer 14, its grain
//! line on layer 7, its notches on layer 4, its name and quantity as text), inserted once
//! each; the style's name and units as text outside them (docs/garments.md, "Export").
//!
//! The file is written here rather than with the `dxf` crate, which reads these files
//! well but writes R12 that pattern CAD rejects: its tables carry R13 subclass markers and
//! extra application ids, every VERTEX gets an R13 marker and layer 0 instead of its
//! polyline's, handles go on every entity (which Richpeace's importer refuses), and a
//! LWPOLYLINE is dropped without a word, since R12 has none. What is written here is what
//! ezdxf's Gerber exporter writes: a HEADER with the version alone, a LAYER table without
//! subclass markers, BLOCKS, ENTITIES, no handles, 7-bit ASCII text, and the same bytes for
//! the same pattern (no dates).

use super::LengthUnit;
use crate::garment::pattern::Polyline;
use crate::garment::{GarmentConfig, GarmentError, flat};
use glam::DVec2;
use std::fmt::Write;

/// How a pattern is written.
#[derive(Debug, Clone)]
pub struct WriteOptions {
    /// Millimetres (`Units: METRIC`) or inches (`Units: ENGLISH`).
    pub units: LengthUnit,
    /// The style's name (`Style Name:`), ASCII.
    pub style: String,
    /// Notches as AAMA's short lines from the cut line inwards instead of ASTM's points.
    pub aama_notches: bool,
}

/// Depth of a notch written, mm.
pub const NOTCH_DEPTH: f64 = 5.0;

/// The first line of every file written, which the output guard recognises.
pub const FIRST_LINES: &str = "999\nWritten by rosette pattern export";

/// The layers written, in the order of the LAYER table.
const LAYERS: [&str; 5] = ["1", "4", "7", "14", "15"];

/// A DXF file of group codes and values.
struct Dxf {
    text: String,
    /// File units per metre.
    scale: f64,
}

impl Dxf {
    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = write!(self.text, "{code:>3}\n{value}\n");
    }

    /// A length in file units, to a thousandth of a millimetre or better.
    fn number(&mut self, code: i32, metres: f64) {
        let value = metres * self.scale;
        let mut text = format!("{value:.6}");
        while text.ends_with('0') {
            text.pop();
        }
        if text.ends_with('.') {
            text.push('0');
        }
        if text == "-0.0" {
            text = "0.0".into();
        }
        self.pair(code, text);
    }

    fn point(&mut self, p: DVec2) {
        self.number(10, p.x);
        self.number(20, p.y);
    }

    fn polyline(&mut self, layer: &str, points: &[DVec2]) {
        self.pair(0, "POLYLINE");
        self.pair(8, layer);
        self.pair(66, 1);
        self.pair(10, "0.0");
        self.pair(20, "0.0");
        self.pair(30, "0.0");
        self.pair(70, 1);
        for &p in points {
            self.pair(0, "VERTEX");
            self.pair(8, layer);
            self.point(p);
            self.pair(30, "0.0");
        }
        self.pair(0, "SEQEND");
        self.pair(8, layer);
    }

    fn line(&mut self, layer: &str, a: DVec2, b: DVec2) {
        self.pair(0, "LINE");
        self.pair(8, layer);
        self.point(a);
        self.pair(30, "0.0");
        self.number(11, b.x);
        self.number(21, b.y);
        self.pair(31, "0.0");
    }

    fn text(&mut self, layer: &str, at: DVec2, height: f64, value: &str) {
        self.pair(0, "TEXT");
        self.pair(8, layer);
        self.point(at);
        self.pair(30, "0.0");
        self.number(40, height);
        self.pair(1, value);
    }
}

/// Text as 7-bit ASCII (the convention's), anything else as `?`.
fn ascii(text: &str) -> String {
    text.chars().map(|c| if c.is_ascii_graphic() || c == ' ' { c } else { '?' }).collect()
}

/// A block name from a panel's: upper case letters, digits, `_` and `-`, at most 31
/// characters (R12's limit), unique among `taken`.
fn block_name(panel: &str, taken: &[String]) -> String {
    let mut name: String = panel.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c.to_ascii_uppercase() } else { '_' }).take(28).collect();
    if name.is_empty() {
        name = "PIECE".into();
    }
    let mut candidate = name.clone();
    let mut k = 2;
    while taken.contains(&candidate) {
        candidate = format!("{name}{k}");
        k += 1;
    }
    candidate
}

/// The points of a sampled edge that keep it within `tolerance` (m) of its samples
/// (Douglas–Peucker): a straight edge's two ends, a curve's bends.
fn simplify(points: &[DVec2], tolerance: f64) -> Vec<DVec2> {
    fn keep(points: &[DVec2], tolerance: f64, out: &mut Vec<DVec2>) {
        let (a, b) = (points[0], *points.last().unwrap());
        let chord = b - a;
        let distance = |p: DVec2| if chord.length() > 0.0 { (p - a).perp_dot(chord).abs() / chord.length() } else { p.distance(a) };
        let (far, d) = points[1..points.len() - 1].iter().enumerate().map(|(i, &p)| (i + 1, distance(p))).fold((0, 0.0), |best, x| if x.1 > best.1 { x } else { best });
        if d > tolerance {
            keep(&points[..=far], tolerance, out);
            keep(&points[far..], tolerance, out);
        } else {
            out.push(b);
        }
    }
    let mut out = vec![points[0]];
    if points.len() > 1 {
        keep(points, tolerance, &mut out);
    }
    out
}

/// The closed outline `points` (counter-clockwise) moved outwards by `width`: each corner
/// where its two offset sides meet, cut off (two points) where that lies more than four
/// widths out.
fn offset(points: &[DVec2], width: f64) -> Vec<DVec2> {
    let n = points.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let (a, b, c) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
        // Outwards of a counter-clockwise outline is to the right of each side.
        let (n1, n2) = (-(b - a).perp().normalize_or_zero(), -(c - b).perp().normalize_or_zero());
        let bisector = n1 + n2;
        let cos_half = 0.5 * bisector.length();
        if cos_half > 0.25 {
            out.push(b + bisector.normalize() * (width / cos_half));
        } else {
            out.push(b + n1 * width);
            out.push(b + n2 * width);
        }
    }
    out
}

/// The pattern file of `garment`.
pub fn write(garment: &GarmentConfig, options: &WriteOptions) -> Result<String, GarmentError> {
    let metres = garment.units.metres();
    let scale = 1000.0 / options.units.mm();
    let mut dxf = Dxf { text: String::new(), scale };
    let text_height = 0.0025;
    // Each panel's sew line (its outline), simplified to a hundredth of a millimetre.
    let mut outlines: Vec<Vec<DVec2>> = Vec::with_capacity(garment.panels.len());
    let mut curves_all: Vec<Vec<Polyline>> = Vec::with_capacity(garment.panels.len());
    for panel in &garment.panels {
        let curves = panel.curves(metres)?;
        let mut outline = Vec::new();
        for curve in &curves {
            let kept = simplify(&curve.points, 1e-5);
            outline.extend_from_slice(&kept[..kept.len() - 1]);
        }
        outlines.push(outline);
        curves_all.push(curves);
    }
    let shifts = flat::lay_out(outlines.iter().map(Vec::as_slice));
    dxf.text.push_str(FIRST_LINES);
    dxf.text.push('\n');
    dxf.pair(0, "SECTION");
    dxf.pair(2, "HEADER");
    dxf.pair(9, "$ACADVER");
    dxf.pair(1, "AC1009");
    dxf.pair(0, "ENDSEC");
    dxf.pair(0, "SECTION");
    dxf.pair(2, "TABLES");
    dxf.pair(0, "TABLE");
    dxf.pair(2, "LAYER");
    dxf.pair(70, LAYERS.len());
    for layer in LAYERS {
        dxf.pair(0, "LAYER");
        dxf.pair(2, layer);
        dxf.pair(70, 0);
        dxf.pair(62, 7);
        dxf.pair(6, "CONTINUOUS");
    }
    dxf.pair(0, "ENDTAB");
    dxf.pair(0, "ENDSEC");
    dxf.pair(0, "SECTION");
    dxf.pair(2, "BLOCKS");
    let mut blocks: Vec<String> = Vec::new();
    for ((panel, outline), curves) in garment.panels.iter().zip(&outlines).zip(&curves_all) {
        let block = block_name(&panel.name, &blocks);
        let allowance = panel.seam_allowance.filter(|w| *w > 0.0).map(|w| w * metres);
        dxf.pair(0, "BLOCK");
        dxf.pair(8, "1");
        dxf.pair(2, &block);
        dxf.pair(70, 0);
        dxf.pair(10, "0.0");
        dxf.pair(20, "0.0");
        dxf.pair(30, "0.0");
        dxf.pair(3, &block);
        let cut = allowance.map_or_else(|| outline.clone(), |w| offset(outline, w));
        dxf.polyline("1", &cut);
        if allowance.is_some() {
            dxf.polyline("14", outline);
        }
        // The grain line through the middle of the piece, half its smaller side long.
        let (lo, hi) = flat::bounds(outline);
        let middle = 0.5 * (lo + hi);
        let half = 0.25 * (hi - lo).min_element();
        let along = DVec2::from_angle(panel.grain_deg.to_radians()) * half;
        dxf.line("7", middle - along, middle + along);
        for (edge, at) in panel.notch_positions(curves, metres)? {
            let curve = &curves[edge];
            let p = curve.at(at);
            let (a, b) = (curve.at((at - 1e-4).max(0.0)), curve.at((at + 1e-4).min(curve.length())));
            // Into the piece is to the left of a counter-clockwise outline.
            let inwards = (b - a).perp().normalize_or_zero();
            let base = p - inwards * allowance.unwrap_or(0.0);
            if options.aama_notches {
                dxf.line("4", base, base + inwards * (NOTCH_DEPTH / 1000.0));
            } else {
                dxf.pair(0, "POINT");
                dxf.pair(8, "4");
                dxf.point(base);
                dxf.number(30, NOTCH_DEPTH / 1000.0);
                dxf.pair(39, "0.0");
                let angle = inwards.y.atan2(inwards.x).to_degrees().rem_euclid(360.0);
                dxf.pair(50, format!("{angle:.6}"));
            }
        }
        let name = ascii(&panel.name);
        let label = middle + DVec2::new(-0.2 * (hi - lo).x, 0.1 * (hi - lo).y);
        dxf.text("1", label, text_height, &format!("Piece Name: {name}"));
        dxf.text("1", label - DVec2::new(0.0, 2.0 * text_height), text_height, "Quantity: 1");
        dxf.text("15", label - DVec2::new(0.0, 4.0 * text_height), text_height, &name);
        dxf.pair(0, "ENDBLK");
        dxf.pair(8, "1");
        blocks.push(block);
    }
    dxf.pair(0, "ENDSEC");
    dxf.pair(0, "SECTION");
    dxf.pair(2, "ENTITIES");
    for (block, shift) in blocks.iter().zip(&shifts) {
        dxf.pair(0, "INSERT");
        dxf.pair(8, "1");
        dxf.pair(2, block);
        dxf.point(*shift);
        dxf.pair(30, "0.0");
    }
    let units = match options.units {
        LengthUnit::In => "ENGLISH",
        _ => "METRIC",
    };
    if options.units == LengthUnit::Cm {
        return Err(GarmentError::new("a pattern file is written in mm (METRIC) or inches (ENGLISH), not cm".into()));
    }
    for (k, line) in [format!("Style Name: {}", ascii(&options.style)), format!("Units: {units}")].iter().enumerate() {
        dxf.text("1", DVec2::new(0.0, -(k as f64 + 2.0) * 2.0 * text_height), text_height, line);
    }
    dxf.pair(0, "ENDSEC");
    dxf.pair(0, "EOF");
    Ok(dxf.text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_edge_keeps_its_ends_and_a_square_grows_by_its_allowance() {
        let line: Vec<DVec2> = (0..=10).map(|i| DVec2::new(i as f64, 0.0)).collect();
        assert_eq!(simplify(&line, 1e-9), vec![DVec2::ZERO, DVec2::new(10.0, 0.0)]);
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let out = offset(&square, 0.1);
        assert_eq!(out.len(), 4);
        assert!((out[0] - DVec2::new(-0.1, -0.1)).length() < 1e-12 && (out[2] - DVec2::new(1.1, 1.1)).length() < 1e-12, "{out:?}");
        assert_eq!(block_name("back-right", &["BACK-RIGHT".into()]), "BACK-RIGHT2");
    }
}
