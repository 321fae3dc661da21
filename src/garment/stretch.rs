//! Seams between stretches of panels' outlines, from point to point: what a seams file
//! says (piece, notch to notch, piece, notch to notch) and what two clicks on each of two
//! outlines in the viewer's flat pattern give. A stretch may pass corners; the seam is then
//! cut where either side turns a corner, each part sewing one edge (or a stretch of one) to
//! one edge, in proportion along both sides, so that it ends in `[garment]` seams as a
//! designer would write them (docs/garments.md, "Seams for a DXF pattern").

use super::GarmentError;
use super::pattern::PanelConfig;
use super::seams::{Direction, SeamConfig};

/// A panel's outline as its edges' lengths, in the garment's units.
#[derive(Debug, Clone)]
pub struct Outline {
    /// Each edge's name, its start's distance along the outline from the panel's start,
    /// and its length.
    pub edges: Vec<(String, f64, f64)>,
    pub perimeter: f64,
}

impl Outline {
    /// The outline of `panel` (its edges sampled as a run samples them).
    pub fn new(panel: &PanelConfig) -> Result<Self, GarmentError> {
        let curves = panel.curves(1.0)?;
        let mut edges = Vec::with_capacity(curves.len());
        let mut at = 0.0;
        for (edge, curve) in panel.edges.iter().zip(&curves) {
            edges.push((edge.name.clone(), at, curve.length()));
            at += curve.length();
        }
        Ok(Self { edges, perimeter: at })
    }

    /// Where the named point lies along the outline: a notch's name, or `cK`, the corner
    /// where edge `eK` starts (a DXF import's names), or an edge's name, its start.
    pub fn point(&self, panel: &PanelConfig, name: &str) -> Option<f64> {
        if let Some(notch) = panel.notches.iter().find(|n| n.name == name) {
            let (_, start, length) = self.edges.iter().find(|e| e.0 == notch.edge)?;
            return Some(start + notch.at.clamp(0.0, *length));
        }
        let edge = name.strip_prefix('c').map(|k| format!("e{k}")).unwrap_or_else(|| name.to_string());
        self.edges.iter().find(|e| e.0 == edge).map(|e| e.1)
    }

    /// The names of the points [`Outline::point`] takes, in order along the outline.
    pub fn point_names(&self, panel: &PanelConfig) -> Vec<(String, f64)> {
        let mut names: Vec<(String, f64)> = self
            .edges
            .iter()
            .filter_map(|(edge, start, _)| edge.strip_prefix('e').filter(|k| k.parse::<u32>().is_ok()).map(|k| (format!("c{k}"), *start)))
            .chain(panel.notches.iter().filter_map(|n| self.point(panel, &n.name).map(|at| (n.name.clone(), at))))
            .collect();
        names.sort_by(|a, b| a.1.total_cmp(&b.1));
        names
    }

    /// The edge holding position `at` along the outline (wrapped into it), and the
    /// position along that edge; at a corner, the edge that starts there when
    /// `forward`, the one that ends there otherwise.
    fn locate(&self, at: f64, forward: bool) -> (usize, f64) {
        let at = at.rem_euclid(self.perimeter);
        let n = self.edges.len();
        for (k, (_, start, length)) in self.edges.iter().enumerate() {
            let end = start + length;
            let inside = if forward { at >= *start - 1e-9 && at < end - 1e-9 } else { at > *start + 1e-9 && at <= end + 1e-9 };
            if inside {
                return (k, (at - start).clamp(0.0, *length));
            }
        }
        // At the outline's start going backwards: the end of the last edge.
        if forward { (0, 0.0) } else { (n - 1, self.edges[n - 1].2) }
    }
}

/// A stretch of one panel's outline: from `from` to `to` (distances along it from the
/// panel's start), counter-clockwise (along the outline's direction) or clockwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stretch {
    pub panel: usize,
    pub from: f64,
    pub to: f64,
    pub counter_clockwise: bool,
}

impl Stretch {
    /// The stretch from `from` to `to` the shorter way round.
    pub fn shorter(panel: usize, from: f64, to: f64, perimeter: f64) -> Self {
        let forward = (to - from).rem_euclid(perimeter);
        Self { panel, from, to, counter_clockwise: forward <= perimeter - forward }
    }

    /// Its length along the outline.
    pub fn length(&self, perimeter: f64) -> f64 {
        let forward = (self.to - self.from).rem_euclid(perimeter);
        if self.counter_clockwise { forward } else { perimeter - forward }
    }

    /// The position reached after `s` along the stretch.
    fn at(&self, s: f64) -> f64 {
        if self.counter_clockwise { self.from + s } else { self.from - s }
    }

    /// Distances along the stretch at which it passes a corner (strictly inside it).
    fn corners(&self, outline: &Outline) -> Vec<f64> {
        let length = self.length(outline.perimeter);
        let mut found: Vec<f64> = outline
            .edges
            .iter()
            .map(|(_, start, _)| {
                let d = if self.counter_clockwise { start - self.from } else { self.from - start };
                d.rem_euclid(outline.perimeter)
            })
            .filter(|&d| d > 1e-9 && d < length - 1e-9)
            .collect();
        found.sort_by(f64::total_cmp);
        found
    }
}

/// Two stretches shorter than this (garment units: a millimetre in cm) are one point.
const SAME_POINT: f64 = 0.1;

/// The seams that sew stretch `a` to stretch `b` (each on its panel's outline), `a`'s
/// first point to `b`'s: one seam per part between the corners either side passes, both
/// sides cut in proportion to their lengths.
pub fn seams(panels: &[PanelConfig], outlines: &[Outline], a: Stretch, b: Stretch) -> Result<Vec<SeamConfig>, GarmentError> {
    let (oa, ob) = (&outlines[a.panel], &outlines[b.panel]);
    let (la, lb) = (a.length(oa.perimeter), b.length(ob.perimeter));
    for (s, l, p) in [(a, la, &panels[a.panel]), (b, lb, &panels[b.panel])] {
        if l.partial_cmp(&SAME_POINT) != Some(std::cmp::Ordering::Greater) {
            return Err(GarmentError::new(format!("the stretch of '{}' from {:.1} to {:.1} has no length; pick two different points", p.name, s.from, s.to)));
        }
    }
    // Cut points as shares of each side's length, each side keeping its own corners exactly:
    // a corner of one side within SAME_POINT (in proportion) of the other's is one cut.
    let mut cuts: Vec<(f64, Option<f64>, Option<f64>)> = Vec::new();
    for d in a.corners(oa) {
        cuts.push((d / la, Some(d), None));
    }
    for d in b.corners(ob) {
        let share = d / lb;
        match cuts.iter_mut().find(|c| c.2.is_none() && ((c.0 - share).abs() * la.max(lb)) < SAME_POINT) {
            Some(c) => c.2 = Some(d),
            None => cuts.push((share, None, Some(d))),
        }
    }
    cuts.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut ends: Vec<(f64, f64)> = vec![(0.0, 0.0)];
    ends.extend(cuts.iter().map(|&(share, da, db)| (da.unwrap_or(share * la), db.unwrap_or(share * lb))));
    ends.push((la, lb));
    let mut out = Vec::with_capacity(ends.len() - 1);
    for w in ends.windows(2) {
        let ((a0, b0), (a1, b1)) = (w[0], w[1]);
        let side = |stretch: Stretch, outline: &Outline, s0: f64, s1: f64| -> (String, Option<[f64; 2]>) {
            // The part's middle says which edge it is on; its ends are measured along it.
            let (edge, _) = outline.locate(stretch.at(0.5 * (s0 + s1)), true);
            let (name, start, length) = &outline.edges[edge];
            // A point of the part lies on the edge up to rounding: one a hair before the
            // edge's start wraps round the outline and is taken back to the start, one a
            // hair past its end is its end.
            let along = |s: f64| {
                let d = (stretch.at(s) - start).rem_euclid(outline.perimeter);
                if d <= *length {
                    d
                } else if outline.perimeter - d < d - length {
                    0.0
                } else {
                    *length
                }
            };
            let (mut p, mut q) = (along(s0), along(s1));
            // A part that ends at its edge's end wraps to 0 there.
            if stretch.counter_clockwise && q < p {
                q = *length;
            }
            if !stretch.counter_clockwise && p < q {
                p = *length;
            }
            let (lo, hi) = if p <= q { (p, q) } else { (q, p) };
            // An end within rounding of the edge's end is its end, written in full, so that
            // no sliver of the edge is left beside the seam.
            let (lo, hi) = (if lo < SNAP { 0.0 } else { round(lo) }, if length - hi < SNAP { *length } else { round(hi) });
            let whole = lo == 0.0 && hi == *length;
            (format!("{}.{name}", panels[stretch.panel].name), (!whole).then_some([lo, hi]))
        };
        let (ka, span_a) = side(a, oa, a0, a1);
        let (kb, span_b) = side(b, ob, b0, b1);
        let direction = if a.counter_clockwise == b.counter_clockwise { Direction::Same } else { Direction::Opposite };
        out.push(SeamConfig { a: ka, b: kb, direction, a_span: span_a, b_span: span_b });
    }
    Ok(out)
}

/// A span end nearer an edge's end than this (garment units: a micrometre in cm) is at it.
const SNAP: f64 = 1e-4;

/// A span end written to a micrometre (in cm).
fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(name: &str) -> PanelConfig {
        let text = format!(
            r#"name = "{name}"
grain_deg = 90
start = [0, 0]
edges = [ {{ name = "e1", to = [10, 0] }}, {{ name = "e2", to = [10, 20] }}, {{ name = "e3", to = [0, 20] }}, {{ name = "e4", to = [0, 0] }} ]
notches = [ {{ name = "n1", edge = "e2", at = 5 }} ]
placement = {{ around = "plane", angle_deg = 0, distance = 20, height = 100 }}"#
        );
        toml::from_str(&text).unwrap()
    }

    /// A stretch from a notch round a corner to the next corner, sewn to a straight one of
    /// the same length the other way: two seams, cut where each side turns its corner.
    #[test]
    fn a_stretch_round_a_corner_is_cut_at_the_corners_of_both_sides() {
        let panels = vec![square("a"), square("b")];
        let outlines: Vec<Outline> = panels.iter().map(|p| Outline::new(p).unwrap()).collect();
        // a: from n1 (15 along) counter-clockwise to c4 (start of e4, 40 along): 15 up e2,
        // then all of e3 (10): 25.
        let (n1, c4) = (outlines[0].point(&panels[0], "n1").unwrap(), outlines[0].point(&panels[0], "c4").unwrap());
        assert_eq!((n1, c4), (15.0, 40.0));
        let a = Stretch::shorter(0, n1, c4, outlines[0].perimeter);
        assert!(a.counter_clockwise && (a.length(60.0) - 25.0).abs() < 1e-12);
        // b: from c1 (0) clockwise to 25 before it: all of e4 (20 long, backwards), then 5 of e3.
        let b = Stretch { panel: 1, from: 0.0, to: 35.0, counter_clockwise: false };
        let sewn = seams(&panels, &outlines, a, b).unwrap();
        // a's corner at 15 along the stretch (share 0.6), b's at 20 (0.8): three parts.
        assert_eq!(sewn.len(), 3, "{sewn:?}");
        assert_eq!((sewn[0].a.as_str(), sewn[0].b.as_str()), ("a.e2", "b.e4"));
        assert_eq!(sewn[0].a_span, Some([5.0, 20.0]));
        assert_eq!(sewn[0].b_span, Some([5.0, 20.0]));
        assert_eq!(sewn[0].direction, Direction::Opposite);
        assert_eq!((sewn[1].a.as_str(), sewn[1].b.as_str()), ("a.e3", "b.e4"));
        assert_eq!(sewn[1].a_span, Some([0.0, 5.0]));
        assert_eq!(sewn[1].b_span, Some([0.0, 5.0]));
        assert_eq!((sewn[2].a.as_str(), sewn[2].b.as_str()), ("a.e3", "b.e3"));
        assert_eq!(sewn[2].a_span, Some([5.0, 10.0]));
        assert_eq!(sewn[2].b_span, Some([5.0, 10.0]));
    }

    /// A stretch that ends, going clockwise, exactly where an edge starts (a notch to the
    /// corner below it) is that edge from its start to the notch, not a stretch of no length
    /// at the edge's end: the corner's position, one rounding below the edge's start, wraps
    /// round the outline otherwise.
    #[test]
    fn a_stretch_clockwise_to_an_edges_start_keeps_its_length() {
        let panels = vec![square("a"), square("b")];
        let outlines: Vec<Outline> = panels.iter().map(|p| Outline::new(p).unwrap()).collect();
        // a: n1 (15) clockwise to c2 (10), 5 down e2; b: c4 (40) clockwise to 35, on e3.
        let a = Stretch { panel: 0, from: 15.0, to: 10.0 - 1e-15, counter_clockwise: false };
        let b = Stretch { panel: 1, from: 40.0, to: 35.0, counter_clockwise: false };
        let sewn = seams(&panels, &outlines, a, b).unwrap();
        assert_eq!(sewn.len(), 1, "{sewn:?}");
        assert_eq!((sewn[0].a.as_str(), sewn[0].a_span), ("a.e2", Some([0.0, 5.0])));
        assert_eq!((sewn[0].b.as_str(), sewn[0].b_span), ("b.e3", Some([5.0, 10.0])));
        assert_eq!(sewn[0].direction, Direction::Same);
    }

    #[test]
    fn whole_edges_have_no_span_and_points_are_named() {
        let panels = vec![square("a"), square("b")];
        let outlines: Vec<Outline> = panels.iter().map(|p| Outline::new(p).unwrap()).collect();
        let a = Stretch::shorter(0, 10.0, 30.0, 60.0);
        let b = Stretch::shorter(1, 60.0, 40.0, 60.0);
        let sewn = seams(&panels, &outlines, a, b).unwrap();
        assert_eq!(sewn.len(), 1);
        assert_eq!((sewn[0].a.as_str(), sewn[0].b.as_str(), sewn[0].a_span, sewn[0].b_span), ("a.e2", "b.e4", None, None));
        assert_eq!(sewn[0].direction, Direction::Opposite);
        let names: Vec<String> = outlines[0].point_names(&panels[0]).into_iter().map(|n| n.0).collect();
        assert_eq!(names, ["c1", "c2", "n1", "c3", "c4"]);
        assert!(seams(&panels, &outlines, Stretch::shorter(0, 5.0, 5.0, 60.0), b).is_err());
    }
}
