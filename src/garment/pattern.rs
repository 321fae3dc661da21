//! Pattern pieces as a designer draws them: closed outlines of named edges (straight
//! lines, circular arcs through a point, cubic Bézier curves) in the panel's own plane,
//! each panel with its grain line and its place around the form.

use super::GarmentError;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The unit of every length in a garment section.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Units {
    /// Centimetres, as pattern makers draw (the default).
    #[default]
    Cm,
    /// Metres, as the rest of Rosette's files.
    M,
}

impl Units {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            Units::Cm => 0.01,
            Units::M => 1.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Units::Cm => "cm",
            Units::M => "m",
        }
    }
}

/// One edge of an outline, from the end of the previous edge (or the panel's `start`) to
/// `to`: straight, an arc through `through`, a cubic Bézier with `controls`, or a polyline
/// through `points` (a curve as pattern CAD exports it, already flattened).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EdgeConfig {
    /// Unique within the panel: seams and attachments name it as `panel.edge`.
    pub name: String,
    /// End point, in the garment's units.
    pub to: [f64; 2],
    /// A circular arc through this point (neither first nor last point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub through: Option<[f64; 2]>,
    /// A cubic Bézier curve with these two control points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controls: Option<[[f64; 2]; 2]>,
    /// A polyline through these points, in order, between the edge's start and `to`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
}

/// A notch: the pattern maker's matching mark, a named point on an edge. Seams files and
/// the flat pattern name it; it does not change the cloth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NotchConfig {
    /// Unique within the panel (a DXF import numbers them n1, n2, ... around the outline).
    pub name: String,
    /// The edge it lies on.
    pub edge: String,
    /// Distance along the edge from its start, in the garment's units.
    pub at: f64,
}

/// How a panel starts around the form (the arrangement point of CLO and Marvelous).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Around {
    /// Wrapped without stretch onto a cone around the form's axis whose side leans out by
    /// `flare_deg` from the vertical: 0 is an upright cylinder (a straight skirt's panels),
    /// a few degrees an A-line's, 90 a flat ring in the horizontal plane (a circle skirt).
    Cone,
    /// Flat in the vertical plane `distance` from the axis, facing out.
    Plane,
}

/// Where a panel starts.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacementConfig {
    pub around: Around,
    /// Direction from the form's axis to the panel's anchor, degrees counter-clockwise
    /// from +x seen from above (the form faces −y: 270 is the front, 90 the back).
    pub angle_deg: f64,
    /// Distance of the anchor from the form's axis, in the garment's units.
    pub distance: f64,
    /// Height of the anchor above the floor, in the garment's units.
    pub height: f64,
    /// Cone: how far its side leans out from the vertical, degrees (0 to 90).
    #[serde(default)]
    pub flare_deg: f64,
}

/// One pattern piece.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelConfig {
    pub name: String,
    /// The warp (straight grain) direction, degrees counter-clockwise from the panel's x
    /// axis: 90 runs the warp up and down a panel drawn upright (straight grain), 45 or 135
    /// cuts it on the bias.
    pub grain_deg: f64,
    /// First point of the outline, in the garment's units.
    pub start: [f64; 2],
    /// The outline's edges, counter-clockwise seen from the right side of the fabric
    /// (outside the garment); the last ends at `start`.
    pub edges: Vec<EdgeConfig>,
    /// The panel point placed at the arrangement point (default: the middle of the top of
    /// its bounding box), in the garment's units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<[f64; 2]>,
    pub placement: PlacementConfig,
    /// Notches on the outline's edges.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notches: Vec<NotchConfig>,
    /// The seam allowance the piece is cut with, in the garment's units: the width between
    /// its cut line and this outline, which is its sew line. A fact of the piece, kept for
    /// `rosette pattern export`; the cloth simulated is the outline alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seam_allowance: Option<f64>,
}

impl PanelConfig {
    /// The diagonal of the bounding box of the outline's corners, in the garment's units.
    pub fn extent(&self) -> f64 {
        let corners = std::iter::once(self.start).chain(self.edges.iter().map(|e| e.to)).map(DVec2::from_array);
        let (lo, hi) = corners.fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        if lo.x <= hi.x { lo.distance(hi) } else { 0.0 }
    }
}

/// A sampled curve: points from start to end with their arc lengths.
#[derive(Debug, Clone)]
pub struct Polyline {
    pub points: Vec<DVec2>,
    /// Arc length at each point, m.
    pub arc: Vec<f64>,
}

impl Polyline {
    fn new(points: Vec<DVec2>) -> Self {
        let mut arc = vec![0.0];
        for w in points.windows(2) {
            arc.push(arc.last().unwrap() + w[0].distance(w[1]));
        }
        Self { points, arc }
    }

    pub fn length(&self) -> f64 {
        *self.arc.last().unwrap()
    }

    /// The point at arc length `s` (clamped to the curve).
    pub fn at(&self, s: f64) -> DVec2 {
        let i = self.arc.partition_point(|&a| a < s).clamp(1, self.points.len() - 1);
        let (a0, a1) = (self.arc[i - 1], self.arc[i]);
        let t = if a1 > a0 { ((s - a0) / (a1 - a0)).clamp(0.0, 1.0) } else { 0.0 };
        self.points[i - 1].lerp(self.points[i], t)
    }
}

/// Points per edge when an outline is sampled: dense enough that the chord of a curve
/// differs from the curve by far less than any mesh edge.
const SAMPLES: usize = 256;

/// A finite point in metres, or an error naming the panel and the key.
fn point(panel: &str, key: &str, p: [f64; 2], metres: f64) -> Result<DVec2, GarmentError> {
    if p.iter().all(|c| c.is_finite() && c.abs() < 1e5) {
        Ok(DVec2::from_array(p) * metres)
    } else {
        Err(GarmentError::new(format!("garment.panels '{panel}': {key} = {p:?} must be two finite coordinates under 100 000 in size")))
    }
}

impl PanelConfig {
    /// Each edge sampled densely, in metres, in the panel's own plane.
    pub fn curves(&self, metres: f64) -> Result<Vec<Polyline>, GarmentError> {
        let name = &self.name;
        if self.edges.len() < 2 {
            return Err(GarmentError::new(format!("garment.panels '{name}': an outline needs at least two edges (a closed shape)")));
        }
        let mut from = point(name, "start", self.start, metres)?;
        let mut curves = Vec::with_capacity(self.edges.len());
        for e in &self.edges {
            let key = format!("edge '{}'", e.name);
            let to = point(name, &format!("{key}: to"), e.to, metres)?;
            let points = match (e.through, e.controls) {
                _ if e.points.is_some() && (e.through.is_some() || e.controls.is_some()) => {
                    return Err(GarmentError::new(format!("garment.panels '{name}': {key} gives `points` (a polyline) with `through` or `controls`; keep one")));
                }
                (Some(_), Some(_)) => {
                    return Err(GarmentError::new(format!("garment.panels '{name}': {key} gives both `through` (an arc) and `controls` (a Bézier curve); keep one")));
                }
                (None, None) if e.points.is_some() => {
                    let mut points = vec![from];
                    for &p in e.points.as_deref().unwrap_or_default() {
                        points.push(point(name, &format!("{key}: points"), p, metres)?);
                    }
                    points.push(to);
                    points
                }
                (Some(through), None) => arc_through(from, point(name, &format!("{key}: through"), through, metres)?, to)
                    .ok_or_else(|| GarmentError::new(format!("garment.panels '{name}': {key}: the arc's three points lie on a line; drop `through` for a straight edge")))?,
                (None, Some([c1, c2])) => bezier(from, point(name, &format!("{key}: controls"), c1, metres)?, point(name, &format!("{key}: controls"), c2, metres)?, to),
                (None, None) => (0..=SAMPLES).map(|i| from.lerp(to, i as f64 / SAMPLES as f64)).collect(),
            };
            let line = Polyline::new(points);
            if line.length() <= 1e-6 {
                return Err(GarmentError::new(format!("garment.panels '{name}': {key} has no length; remove it or move its end point")));
            }
            curves.push(line);
            from = to;
        }
        if from.distance(point(name, "start", self.start, metres)?) > 1e-9 {
            return Err(GarmentError::new(format!(
                "garment.panels '{name}': the last edge '{}' must end at start = {:?} to close the outline",
                self.edges.last().unwrap().name,
                self.start
            )));
        }
        Ok(curves)
    }
}

impl PanelConfig {
    /// Each notch resolved to its edge (by index) and its distance along it (m), or an
    /// error naming the panel and the notch. `curves` are the panel's edges sampled in
    /// metres ([`PanelConfig::curves`]).
    pub fn notch_positions(&self, curves: &[Polyline], metres: f64) -> Result<Vec<(usize, f64)>, GarmentError> {
        let name = &self.name;
        let mut positions = Vec::with_capacity(self.notches.len());
        for (i, notch) in self.notches.iter().enumerate() {
            let key = format!("garment.panels '{name}': notch '{}'", notch.name);
            if self.notches[..i].iter().any(|n| n.name == notch.name) {
                return Err(GarmentError::new(format!("garment.panels '{name}': two notches are named '{}'; give each its own name", notch.name)));
            }
            let edge = self.edges.iter().position(|e| e.name == notch.edge).ok_or_else(|| {
                let edges: Vec<&str> = self.edges.iter().map(|e| e.name.as_str()).collect();
                GarmentError::new(format!("{key}: no edge '{}'; the edges are {}", notch.edge, edges.join(", ")))
            })?;
            let length = curves[edge].length();
            let at = notch.at * metres;
            if !(at.is_finite() && (-1e-9..=length + 1e-9).contains(&at)) {
                return Err(GarmentError::new(format!(
                    "{key}: at = {} must lie on edge '{}', between 0 and its length {:.4} (garment units)",
                    notch.at,
                    notch.edge,
                    length / metres
                )));
            }
            positions.push((edge, at.clamp(0.0, length)));
        }
        Ok(positions)
    }
}

/// The circular arc from `a` through `b` to `c`, sampled; None when the points are collinear.
fn arc_through(a: DVec2, b: DVec2, c: DVec2) -> Option<Vec<DVec2>> {
    let d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    if d.abs() < 1e-12 * (a.distance_squared(c) + 1e-30) {
        return None;
    }
    let sq = |p: DVec2| p.length_squared();
    let centre = DVec2::new(
        (sq(a) * (b.y - c.y) + sq(b) * (c.y - a.y) + sq(c) * (a.y - b.y)) / d,
        (sq(a) * (c.x - b.x) + sq(b) * (a.x - c.x) + sq(c) * (b.x - a.x)) / d,
    );
    let angle = |p: DVec2| (p - centre).to_angle();
    let (t0, tb, tc) = (angle(a), angle(b), angle(c));
    // Sweep from a to c the way that passes b.
    let ccw = |t: f64| (t - t0).rem_euclid(std::f64::consts::TAU);
    let sweep = if ccw(tb) <= ccw(tc) { ccw(tc) } else { ccw(tc) - std::f64::consts::TAU };
    let radius = a.distance(centre);
    let mut points: Vec<DVec2> = (0..=SAMPLES).map(|i| centre + radius * DVec2::from_angle(t0 + sweep * i as f64 / SAMPLES as f64)).collect();
    // The ends exactly where they were given.
    points[0] = a;
    points[SAMPLES] = c;
    Some(points)
}

fn bezier(p0: DVec2, p1: DVec2, p2: DVec2, p3: DVec2) -> Vec<DVec2> {
    (0..=SAMPLES)
        .map(|i| {
            let t = i as f64 / SAMPLES as f64;
            let u = 1.0 - t;
            u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 + t * t * t * p3
        })
        .collect()
}

/// Refuses an outline that crosses itself, naming the panel and the two edges.
pub fn check_simple(panel: &str, names: &[&str], curves: &[Polyline]) -> Result<(), GarmentError> {
    let segments: Vec<(usize, DVec2, DVec2)> = curves.iter().enumerate().flat_map(|(e, c)| c.points.windows(2).map(move |w| (e, w[0], w[1]))).collect();
    if let Some((i, j)) = first_crossing(&segments) {
        return Err(GarmentError::new(format!(
            "garment.panels '{panel}': the outline crosses itself where edge '{}' meets edge '{}'; a panel must be a simple closed shape",
            names[segments[i].0], names[segments[j].0]
        )));
    }
    let area: f64 = curves.iter().flat_map(|c| c.points.windows(2)).map(|w| 0.5 * w[0].perp_dot(w[1])).sum();
    if area <= 0.0 {
        return Err(GarmentError::new(format!(
            "garment.panels '{panel}': the outline runs clockwise; list its edges counter-clockwise as seen from the right side of the fabric"
        )));
    }
    Ok(())
}

/// The first pair of segments of a closed outline that cross, leaving out neighbours along
/// the outline (which share an end point). The segments are binned in a square grid of
/// about one segment per cell, and only those sharing a cell are tested: linear in the
/// outline's length where all-pairs took minutes on an outline of a few hundred edges
/// (each sampled into hundreds of segments).
fn first_crossing(segments: &[(usize, DVec2, DVec2)]) -> Option<(usize, usize)> {
    let n = segments.len();
    if n < 4 {
        return None;
    }
    let (lo, hi) = segments.iter().fold((DVec2::MAX, DVec2::MIN), |(lo, hi), &(_, a, b)| (lo.min(a).min(b), hi.max(a).max(b)));
    let extent = (hi - lo).max_element().max(1e-12);
    let side = (n as f64).sqrt().ceil().clamp(1.0, 4096.0);
    let cell = extent / side;
    let index = |p: DVec2| ((p - lo) / cell).floor().clamp(DVec2::ZERO, DVec2::splat(side - 1.0)).as_uvec2();
    let mut bins: std::collections::HashMap<(u32, u32), Vec<usize>> = std::collections::HashMap::new();
    for (k, &(_, a, b)) in segments.iter().enumerate() {
        let (c0, c1) = (index(a.min(b)), index(a.max(b)));
        for x in c0.x..=c1.x {
            for y in c0.y..=c1.y {
                bins.entry((x, y)).or_default().push(k);
            }
        }
    }
    let neighbours = |i: usize, j: usize| j == i + 1 || (i == 0 && j == n - 1);
    let mut found: Option<(usize, usize)> = None;
    for members in bins.values() {
        for (p, &i) in members.iter().enumerate() {
            for &j in &members[p + 1..] {
                let (i, j) = (i.min(j), i.max(j));
                if neighbours(i, j) || found.is_some_and(|f| f <= (i, j)) {
                    continue;
                }
                let ((_, a, b), (_, c, d)) = (segments[i], segments[j]);
                if segments_cross(a, b, c, d) {
                    found = Some((i, j));
                }
            }
        }
    }
    found
}

/// Whether segments ab and cd intersect (touching included).
fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (d1, d2, d3, d4) = (orient(c, d, a), orient(c, d, b), orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| orient(p, q, r).abs() < 1e-15 && r.cmpge(p.min(q)).all() && r.cmple(p.max(q)).all();
    on(c, d, a) || on(c, d, b) || on(a, b, c) || on(a, b, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_through_a_point_has_the_circle_length() {
        let arc = Polyline::new(arc_through(DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0), DVec2::new(-1.0, 0.0)).unwrap());
        assert!((arc.length() - std::f64::consts::PI).abs() < 1e-4, "{}", arc.length());
        // The other way round, through the lower half.
        let arc = Polyline::new(arc_through(DVec2::new(1.0, 0.0), DVec2::new(0.0, -1.0), DVec2::new(-1.0, 0.0)).unwrap());
        assert!(arc.points[SAMPLES / 2].y < -0.99);
    }

    /// The grid finds what all pairs find: a wavy ring of many short segments is simple, a
    /// circle with two points visited in the wrong order is not.
    #[test]
    fn the_crossing_check_agrees_with_all_pairs() {
        let all_pairs = |s: &[(usize, DVec2, DVec2)]| {
            let n = s.len();
            (0..n).flat_map(|i| (i + 2..n).map(move |j| (i, j))).find(|&(i, j)| !(i == 0 && j == n - 1) && segments_cross(s[i].1, s[i].2, s[j].1, s[j].2))
        };
        let ring = |k: usize, bend: bool| {
            // A wavy ring, or a circle with two points visited in the wrong order: the two
            // chords beside them cross (the diagonals of a convex quadrilateral).
            let wave = if bend { 0.0 } else { 0.3 };
            let mut points: Vec<DVec2> = (0..k)
                .map(|i| {
                    let t = std::f64::consts::TAU * i as f64 / k as f64;
                    (1.0 + wave * (7.0 * t).sin()) * DVec2::from_angle(t)
                })
                .collect();
            if bend {
                points.swap(k / 2, k / 2 + 1);
            }
            (0..k).map(|i| (i, points[i], points[(i + 1) % k])).collect::<Vec<_>>()
        };
        for k in [5, 40, 700] {
            for bend in [false, true] {
                let s = ring(k, bend);
                assert_eq!(first_crossing(&s).is_some(), bend, "{k} segments, bent {bend}");
                assert_eq!(all_pairs(&s).is_some(), bend, "{k} segments, bent {bend}");
            }
        }
        let star: Vec<DVec2> = (0..9).map(|i| DVec2::from_angle(std::f64::consts::TAU * (4 * i) as f64 / 9.0)).collect();
        let s: Vec<_> = (0..9).map(|i| (i, star[i], star[(i + 1) % 9])).collect();
        assert!(first_crossing(&s).is_some() && all_pairs(&s).is_some(), "a nine-pointed star crosses itself");
    }

    #[test]
    fn a_bowtie_is_refused_naming_its_edges() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let line = |a: DVec2, b: DVec2| Polyline::new(vec![a, b]);
        let curves = vec![line(p(0.0, 0.0), p(1.0, 1.0)), line(p(1.0, 1.0), p(1.0, 0.0)), line(p(1.0, 0.0), p(0.0, 1.0)), line(p(0.0, 1.0), p(0.0, 0.0))];
        let err = check_simple("front", &["a", "b", "c", "d"], &curves).unwrap_err().to_string();
        assert!(err.contains("front") && err.contains("'a'") && err.contains("'c'"), "{err}");
    }
}
