//! Pieces of a pattern file as a garment's panels: each outline cut into edges at its
//! corners, its notches named points on them, a piece cut twice as two panels (the second
//! mirrored), and every panel placed around the form from its name (docs/garments.md,
//! "Patterns from pattern CAD").
//!
//! Names. A panel is named after its piece, in lower case with dashes (`Front Panel` →
//! `front-panel`); a piece cut twice gives `NAME-right`, as drawn, and `NAME-left`, its
//! mirror image (pattern pieces are drafted as the wearer's right half, seen from outside);
//! more copies are numbered, odd ones as drawn. Corners are `c1`, `c2`, ... counter-clockwise
//! from the lowest (then leftmost) corner of the piece as drawn, edge `eK` runs from corner
//! `cK` to the next, and notches are `n1`, `n2`, ... in the same order; a mirrored copy
//! keeps the names of the points it mirrors, so `c2` of `back-left` is `c2` of
//! `back-right` turned over.
//!
//! Placement (CLO's and Marvelous Designer's arrangement, without typed coordinates): a
//! piece named with `front` goes to the form's front, `back` to its back, `sleeve` to the
//! arms' side, the rest to the sides, unless the options name them. A skirt (every piece
//! but an upper-body one) is wrapped on one cone around the hips, its pieces round it in
//! order, the top of each at the waist: the cone's radius at the waist clears the form,
//! and its flare opens it from the pieces' widths at their tops to their widths overall,
//! at least enough to clear the hips. An upper-body garment (a piece named as a bodice,
//! sleeve, collar, shirt, dress and so on) is laid flat on vertical planes in front, behind
//! and beside the form, as the bundled shift dress is, its tops at the neck.

use super::{DxfPattern, Piece};
use crate::garment::form::Measurements;
use crate::garment::pattern::{Around, EdgeConfig, NotchConfig, PanelConfig, PlacementConfig};
use glam::DVec2;

/// Where a piece goes around the form.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Front,
    Back,
    Sleeve,
    Side,
}

/// Which level of the form the pieces' tops go to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Top {
    /// A skirt or trousers: the waist.
    Waist,
    /// An upper-body garment: the neck.
    Shoulder,
}

/// What the user says about the arrangement: pieces (by the name of the piece or of the
/// panel) that go to the front, the back or the arms, and where the tops go. Everything
/// unsaid comes from the names.
#[derive(Debug, Clone, Default)]
pub struct Arrangement {
    pub front: Vec<String>,
    pub back: Vec<String>,
    pub sleeves: Vec<String>,
    pub top: Option<Top>,
}

/// A panel made from a piece, with what placement needs to know of it.
#[derive(Debug, Clone)]
pub struct PiecePanel {
    pub panel: PanelConfig,
    /// The piece it was cut from (its name in the file).
    pub piece: String,
    pub role: Role,
    /// Whether this copy is the piece's mirror image.
    pub mirrored: bool,
}

/// The name of a panel made from a piece: lower case, spaces and underscores as dashes,
/// other characters (the dot that separates a panel from its edge among them) left out.
pub fn panel_name(piece: &str) -> String {
    let mut name = String::new();
    for c in piece.trim().chars().flat_map(char::to_lowercase) {
        match c {
            'a'..='z' | '0'..='9' => name.push(c),
            ' ' | '_' | '-' if !name.is_empty() && !name.ends_with('-') => name.push('-'),
            _ => {}
        }
    }
    let name = name.trim_end_matches('-').to_string();
    if name.is_empty() { "piece".into() } else { name }
}

/// Turn above which a point of an outline is a corner, degrees: a curve flattened by
/// pattern CAD turns by a few degrees a point, a corner by tens.
const CORNER_TURN_DEG: f64 = 30.0;
/// Corners closer together than this along the outline are one, mm (a chamfer).
const CORNER_GAP: f64 = 5.0;

/// The corners of a closed counter-clockwise outline (indices, in order), at least two.
pub fn corners(outline: &[DVec2]) -> Vec<usize> {
    let n = outline.len();
    let turn = |i: usize| {
        let (a, b, c) = (outline[(i + n - 1) % n], outline[i], outline[(i + 1) % n]);
        (b - a).angle_to(c - b).abs().to_degrees()
    };
    let arc = arcs(outline);
    let mut found: Vec<usize> = (0..n).filter(|&i| turn(i) > CORNER_TURN_DEG).collect();
    // Of corners within CORNER_GAP of each other, the sharpest is kept.
    let mut kept: Vec<usize> = Vec::new();
    found.sort_by(|&a, &b| turn(b).total_cmp(&turn(a)));
    let perimeter = arc[n];
    for i in found {
        let close = |j: &usize| {
            let d = (arc[i] - arc[*j]).abs();
            d.min(perimeter - d) < CORNER_GAP
        };
        if !kept.iter().any(close) {
            kept.push(i);
        }
    }
    kept.sort_unstable();
    // A curved outline (a circle) has no corner: two are made, at the lowest point and
    // halfway round from it.
    if kept.len() < 2 {
        let lowest = lowest_left(outline, &(0..n).collect::<Vec<_>>());
        let target = (arc[lowest] + 0.5 * perimeter) % perimeter;
        let opposite = (0..n).min_by(|&a, &b| (arc[a] - target).abs().total_cmp(&(arc[b] - target).abs())).expect("points");
        kept = if kept.len() == 1 && kept[0] != lowest { vec![kept[0], opposite] } else { vec![lowest, opposite] };
        kept.sort_unstable();
        kept.dedup();
        if kept.len() < 2 {
            kept = vec![0, n / 2];
        }
    }
    kept
}

/// Arc length at each point of a closed outline from its first, and the perimeter last.
fn arcs(outline: &[DVec2]) -> Vec<f64> {
    let n = outline.len();
    let mut arc = Vec::with_capacity(n + 1);
    arc.push(0.0);
    for i in 0..n {
        arc.push(arc[i] + outline[i].distance(outline[(i + 1) % n]));
    }
    arc
}

/// Of `candidates` (indices into `outline`), the lowest point, the leftmost among equals.
fn lowest_left(outline: &[DVec2], candidates: &[usize]) -> usize {
    let (lo, hi) = bounds(outline);
    let tolerance = 1e-6 * (hi - lo).max_element();
    *candidates
        .iter()
        .min_by(|&&a, &&b| {
            let (p, q) = (outline[a], outline[b]);
            if (p.y - q.y).abs() > tolerance { p.y.total_cmp(&q.y) } else { p.x.total_cmp(&q.x) }
        })
        .expect("candidates")
}

fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

/// A coordinate in cm written to a micrometre, so the scene file reads cleanly.
fn round(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

/// A panel from an outline in cm (counter-clockwise, starting at its first corner), its
/// corners as (index, number K) in order around it, its notches as (distance along the
/// outline from its start, cm, name): edge `eK` from corner `cK` to the next.
fn panel(name: &str, outline: &[DVec2], corners: &[(usize, usize)], notches: &[(f64, String)], grain_deg: f64, seam_allowance: Option<f64>) -> PanelConfig {
    let n = outline.len();
    let arc = arcs(outline);
    let mut edges = Vec::with_capacity(corners.len());
    let mut edge_arcs = Vec::with_capacity(corners.len());
    for (k, &(start, number)) in corners.iter().enumerate() {
        let end = corners.get(k + 1).map_or(n, |c| c.0);
        let points: Vec<[f64; 2]> = (start + 1..end).map(|i| outline[i].to_array().map(round)).collect();
        edges.push(EdgeConfig { name: format!("e{number}"), to: outline[end % n].to_array().map(round), through: None, controls: None, points: (!points.is_empty()).then_some(points) });
        edge_arcs.push((arc[start], arc[end]));
    }
    let notches = notches
        .iter()
        .map(|(at, name)| {
            let k = edge_arcs.iter().position(|&(from, to)| *at <= to + 1e-9 && *at >= from - 1e-9).unwrap_or(edge_arcs.len() - 1);
            let (from, to) = edge_arcs[k];
            NotchConfig { name: name.clone(), edge: edges[k].name.clone(), at: round((at - from).clamp(0.0, to - from)) }
        })
        .collect();
    PanelConfig {
        name: name.to_string(),
        grain_deg: round(grain_deg),
        start: outline[0].to_array().map(round),
        edges,
        anchor: None,
        placement: PlacementConfig { around: Around::Plane, angle_deg: 0.0, distance: 1.0, height: 1.0, flare_deg: 0.0 },
        notches,
        seam_allowance: seam_allowance.map(round),
    }
}

/// The panels of a piece in cm: one as drawn, and for each further copy the drawn one or
/// its mirror image in turn. Names as the module says.
pub fn piece_panels(piece: &Piece, role: Role) -> Vec<PiecePanel> {
    let outline_mm = &piece.outline;
    let n = outline_mm.len();
    let found = corners(outline_mm);
    let first = lowest_left(outline_mm, &found);
    // The outline from the first corner, in cm.
    let outline: Vec<DVec2> = (0..n).map(|i| outline_mm[(first + i) % n] * 0.1).collect();
    let shifted: Vec<usize> = found.iter().map(|&c| (c + n - first) % n).collect();
    let mut order = shifted.clone();
    order.sort_unstable();
    let corners: Vec<(usize, usize)> = order.iter().enumerate().map(|(k, &i)| (i, k + 1)).collect();
    let perimeter_mm = arcs(outline_mm)[n];
    let start_mm = arcs(outline_mm)[first];
    let notches: Vec<(f64, String)> = {
        let mut at: Vec<f64> = piece.notches.iter().map(|notch| (notch.at - start_mm).rem_euclid(perimeter_mm) * 0.1).collect();
        at.sort_by(f64::total_cmp);
        at.into_iter().enumerate().map(|(i, a)| (a, format!("n{}", i + 1))).collect()
    };
    let allowance = piece.seam_allowance.map(|a| a[1] * 0.1);
    let base = panel_name(&piece.name);
    let names: Vec<String> = match piece.quantity {
        1 => vec![base.clone()],
        2 => vec![format!("{base}-right"), format!("{base}-left")],
        q => (1..=q).map(|k| format!("{base}-{k}")).collect(),
    };
    let drawn = panel(&names[0], &outline, &corners, &notches, piece.grain_deg, allowance);
    // The mirror image about the outline's vertical middle, listed the other way round so
    // that it stays counter-clockwise: point i of the mirror is point n − i of the drawn.
    let (lo, hi) = bounds(&outline);
    let middle = lo.x + hi.x;
    let mirror_outline: Vec<DVec2> = (0..n).map(|i| outline[(n - i) % n]).map(|p| DVec2::new(middle - p.x, p.y)).collect();
    let mirror_corners: Vec<(usize, usize)> = std::iter::once((0, 1)).chain(corners[1..].iter().rev().map(|&(i, k)| (n - i, k))).collect();
    let perimeter = arcs(&outline)[n];
    let mut mirror_notches: Vec<(f64, String)> = notches.iter().map(|(at, name)| ((perimeter - at) % perimeter, name.clone())).collect();
    mirror_notches.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mirror = panel(&names[0], &mirror_outline, &mirror_corners, &mirror_notches, (180.0 - piece.grain_deg).rem_euclid(180.0), allowance);
    names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let mirrored = k % 2 == 1;
            let mut panel = if mirrored { mirror.clone() } else { drawn.clone() };
            panel.name = name.clone();
            PiecePanel { panel, piece: piece.name.clone(), role, mirrored }
        })
        .collect()
}

/// The role a piece's name gives, or the arrangement's.
pub fn role(piece: &str, arrangement: &Arrangement) -> Role {
    let named = |list: &[String]| list.iter().any(|n| n.eq_ignore_ascii_case(piece) || panel_name(n) == panel_name(piece));
    if named(&arrangement.front) {
        return Role::Front;
    }
    if named(&arrangement.back) {
        return Role::Back;
    }
    if named(&arrangement.sleeves) {
        return Role::Sleeve;
    }
    let name = piece.to_ascii_lowercase();
    if name.contains("sleeve") {
        Role::Sleeve
    } else if name.contains("front") {
        Role::Front
    } else if name.contains("back") {
        Role::Back
    } else {
        Role::Side
    }
}

/// Words in a piece's name that say the garment is worn from the shoulders.
const UPPER_BODY: &[&str] = &["sleeve", "bodice", "collar", "cuff", "shirt", "blouse", "dress", "yoke", "jacket", "coat", "top", "shoulder", "neck", "armhole"];

/// Where the pieces' tops go: the arrangement's choice, else the shoulders where a piece is
/// named as an upper-body garment's, else the waist.
pub fn top(pattern: &DxfPattern, arrangement: &Arrangement) -> Top {
    arrangement.top.unwrap_or_else(|| {
        let upper = pattern.pieces.iter().any(|p| {
            let name = p.name.to_ascii_lowercase();
            UPPER_BODY.iter().any(|w| name.contains(w))
        });
        if upper { Top::Shoulder } else { Top::Waist }
    })
}

/// Every piece's panels, in the file's order.
pub fn panels(pattern: &DxfPattern, arrangement: &Arrangement) -> Result<Vec<PiecePanel>, String> {
    let mut all: Vec<PiecePanel> = Vec::new();
    for piece in &pattern.pieces {
        for p in piece_panels(piece, role(&piece.name, arrangement)) {
            if let Some(other) = all.iter().find(|o| o.panel.name == p.panel.name) {
                return Err(format!(
                    "pieces '{}' and '{}' both make a panel named '{}'; rename one in the CAD",
                    other.piece, p.piece, p.panel.name
                ));
            }
            all.push(p);
        }
    }
    Ok(all)
}

/// The least and greatest x of a panel's outline within 3 cm of its top, cm.
fn top_span(panel: &PanelConfig) -> (f64, f64) {
    let outline = outline_of(panel);
    let (_, hi) = bounds(&outline);
    // The outline's points, with points every centimetre along its segments, near the top.
    let mut top_lo = f64::INFINITY;
    let mut top_hi = f64::NEG_INFINITY;
    for i in 0..outline.len() {
        let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
        let steps = (a.distance(b).ceil() as usize).max(1);
        for s in 0..=steps {
            let p = a.lerp(b, s as f64 / steps as f64);
            if p.y >= hi.y - 3.0 {
                top_lo = top_lo.min(p.x);
                top_hi = top_hi.max(p.x);
            }
        }
    }
    (top_lo, top_hi)
}

/// A panel's width overall, cm.
fn width(panel: &PanelConfig) -> f64 {
    let (lo, hi) = bounds(&outline_of(panel));
    hi.x - lo.x
}

/// A panel's outline's corners and polyline points, cm.
fn outline_of(panel: &PanelConfig) -> Vec<DVec2> {
    let mut points = vec![DVec2::from_array(panel.start)];
    for e in &panel.edges {
        points.extend(e.points.iter().flatten().map(|&p| DVec2::from_array(p)));
        points.push(DVec2::from_array(e.to));
    }
    points.pop();
    points
}

/// Half-width of the form at a level from its girth there (cm), with the sections' depth
/// taken as 0.78 of their width (docs/garments.md, the form): π(a + b) ≈ girth.
fn half_width(girth: f64) -> f64 {
    girth / (std::f64::consts::PI * 1.78)
}

/// Places every panel around a form of `m` (m): sets its anchor (the middle of the top of
/// its bounding box) and placement, in cm.
pub fn arrange(panels: &mut [PiecePanel], m: &Measurements, top: Top) {
    let cm = |x: f64| 100.0 * x;
    match top {
        Top::Waist => arrange_ring(panels, m),
        Top::Shoulder => {
            let neck = cm(m.waist_height + m.torso_length);
            // Clear of the form's deepest section in front and behind by 3 cm.
            let depth = 0.78 * half_width(cm(m.bust_girth.max(m.hip_girth))) + 3.0;
            let width = half_width(cm(m.bust_girth.max(m.hip_girth))) + 4.0;
            for (role, angle, distance, height) in [
                (Role::Front, 270.0, depth, neck + 5.0),
                (Role::Back, 90.0, depth, neck + 5.0),
                (Role::Side, 180.0, width, neck - 5.0),
                (Role::Sleeve, 180.0, cm(0.5 * m.shoulder_width) + 10.0, neck - 3.0),
            ] {
                arrange_plane(panels, role, angle, distance, height);
            }
        }
    }
}

/// Lays the panels of `role` side by side on vertical planes at `angle` (degrees) and
/// `distance` from the axis, their tops at `height` (cm): drawn copies to the wearer's
/// right of the middle, mirrored copies to the left. Sleeves and side pieces go to both
/// sides of the form, the drawn copies on the wearer's right (180°), the mirrored on the left.
fn arrange_plane(panels: &mut [PiecePanel], role: Role, angle: f64, distance: f64, height: f64) {
    const GAP: f64 = 2.0;
    let two_sided = matches!(role, Role::Side | Role::Sleeve);
    for side in [false, true] {
        // Panels on this plane, in order from the wearer's right to the left as seen from
        // outside.
        let mut members: Vec<usize> = (0..panels.len()).filter(|&i| panels[i].role == role && (!two_sided || panels[i].mirrored == side)).collect();
        if members.is_empty() {
            continue;
        }
        let plane_angle = if two_sided && side { (angle + 180.0) % 360.0 } else { angle };
        if !two_sided {
            members.sort_by_key(|&i| panels[i].mirrored);
        }
        let widths: Vec<f64> = members.iter().map(|&i| width(&panels[i].panel)).collect();
        let total: f64 = widths.iter().sum::<f64>() + GAP * (widths.len() - 1) as f64;
        // Seen from outside a plane facing out at `plane_angle`, the panel's +x runs
        // counter-clockwise around the form: at the front that is towards the wearer's left,
        // at the back towards the wearer's right. Drawn copies go to the wearer's right.
        let towards_right = (plane_angle - 90.0).abs() < 1e-9;
        let mut x = -0.5 * total;
        let order: Vec<usize> = if towards_right { members.iter().rev().copied().collect() } else { members.clone() };
        let width_of = |i: usize| widths[members.iter().position(|&m| m == i).expect("a member")];
        for i in order {
            let w = width_of(i);
            let panel = &mut panels[i].panel;
            let outline = outline_of(panel);
            let (lo, hi) = bounds(&outline);
            let centre = 0.5 * (lo.x + hi.x);
            // The anchor goes to the arrangement point, so a panel whose middle is to lie at
            // x along the plane has its anchor x − ... to the other side of its middle.
            panel.anchor = Some([round(centre - (x + 0.5 * w)), round(hi.y)]);
            panel.placement = PlacementConfig { around: Around::Plane, angle_deg: plane_angle, distance: round(distance), height: round(height), flare_deg: 0.0 };
            x += w + GAP;
        }
    }
}

/// Wraps every panel but the sleeves on one cone around the hips, tops at the waist, in
/// order round the form: the front's drawn copies on the wearer's right, its pieces cut
/// once in the middle, its mirrored copies on the left, then the side pieces, the back (its
/// mirrored copies on the wearer's left) and the side pieces' drawn copies. Equal gaps
/// between them, the front's middle at the front (270°).
fn arrange_ring(panels: &mut [PiecePanel], m: &Measurements) {
    let cm = |x: f64| 100.0 * x;
    let waist = cm(m.waist_height);
    let hip_drop = cm(m.waist_height - m.hip_height);
    let (waist_r, hip_r) = (half_width(cm(m.waist_girth)), half_width(cm(m.hip_girth)));
    let ring: Vec<usize> = {
        let of = |role: Role, mirrored: Option<bool>| -> Vec<usize> { (0..panels.len()).filter(|&i| panels[i].role == role && mirrored.is_none_or(|m| panels[i].mirrored == m)).collect() };
        let once = |role: Role| -> Vec<usize> { of(role, Some(false)).into_iter().filter(|&i| !panels.iter().any(|p| p.piece == panels[i].piece && p.mirrored)).collect() };
        let drawn_pair = |role: Role| -> Vec<usize> { of(role, Some(false)).into_iter().filter(|&i| panels.iter().any(|p| p.piece == panels[i].piece && p.mirrored)).collect() };
        let mut order = Vec::new();
        // Counter-clockwise from the wearer's right side (180°): the front from its right
        // to its left, the left side, the back from its left to its right, the right side.
        order.extend(drawn_pair(Role::Front).into_iter().rev());
        order.extend(once(Role::Front));
        order.extend(of(Role::Front, Some(true)));
        order.extend(of(Role::Side, Some(true)));
        order.extend(of(Role::Back, Some(true)).into_iter().rev());
        order.extend(once(Role::Back));
        order.extend(drawn_pair(Role::Back));
        order.extend(of(Role::Side, Some(false)));
        order
    };
    // Each panel's reach to either side of its anchor (the middle of its bounding box),
    // at its top and overall, and its height, cm: a piece whose top is not centred over
    // its widest (a half back with a straight centre back and a flared side) reaches
    // further to one side at the waist than at the hem.
    struct Reach {
        top: [f64; 2],
        overall: [f64; 2],
        height: f64,
    }
    let reaches: Vec<Reach> = ring
        .iter()
        .map(|&i| {
            let (top_lo, top_hi) = top_span(&panels[i].panel);
            let (lo, hi) = bounds(&outline_of(&panels[i].panel));
            let centre = 0.5 * (lo.x + hi.x);
            Reach { top: [centre - top_lo, top_hi - centre], overall: [centre - lo.x, hi.x - centre], height: hi.y - lo.y }
        })
        .collect();
    let top_total: f64 = reaches.iter().map(|r| r.top[0] + r.top[1]).sum();
    let overall_total: f64 = reaches.iter().map(|r| r.overall[0] + r.overall[1]).sum();
    let length = reaches.iter().map(|r| r.height).fold(1.0, f64::max);
    // Each panel's share of the circle to either side of its anchor: its top on the waist
    // circle, its widest on the hem's circle.
    let shares_at = |radius: f64, hem_radius: f64| -> Vec<[f64; 2]> { reaches.iter().map(|r| [0, 1].map(|k| (r.top[k] / radius).max(r.overall[k] / hem_radius))).collect() };
    // The cone: its radius at the waist clears the form by 4 cm and takes the pieces' tops
    // with room; its flare opens the tops to the pieces' widths over their length, and
    // clears the hips by 2 cm.
    let mut radius = (waist_r + 4.0).max(1.15 * top_total / std::f64::consts::TAU);
    let mut flare = 0.0f64;
    for _ in 0..60 {
        let develop = ((overall_total - top_total) / (std::f64::consts::TAU * length)).clamp(0.0, 0.95).asin();
        let clear = ((hip_r + 2.0 - radius) / hip_drop).max(0.0).atan();
        flare = develop.max(clear).min(80f64.to_radians());
        // The panels must leave room between them.
        let used: f64 = shares_at(radius, radius + length * flare.sin()).iter().map(|s| s[0] + s[1]).sum();
        if used <= 0.85 * std::f64::consts::TAU {
            break;
        }
        radius *= 1.1;
    }
    let shares = shares_at(radius, radius + length * flare.sin());
    let gap = (std::f64::consts::TAU - shares.iter().map(|s| s[0] + s[1]).sum::<f64>()) / shares.len().max(1) as f64;
    let mut angle = 0.0;
    let mut centres = Vec::with_capacity(ring.len());
    for share in &shares {
        centres.push(angle + share[0]);
        angle += share[0] + share[1] + gap;
    }
    // Turn the ring so that the front's middle (or, without a front, the back's) faces its
    // side of the form.
    let front: Vec<usize> = (0..ring.len()).filter(|&k| panels[ring[k]].role == Role::Front).collect();
    let (group, target) = if front.is_empty() { ((0..ring.len()).filter(|&k| panels[ring[k]].role == Role::Back).collect(), 90f64) } else { (front, 270f64) };
    let middle = match (group.first(), group.last()) {
        (Some(&first), Some(&last)) => 0.5 * (centres[first] - shares[first][0] + centres[last] + shares[last][1]),
        _ => 0.0,
    };
    let turn = target.to_radians() - middle;
    for (k, &i) in ring.iter().enumerate() {
        let panel = &mut panels[i].panel;
        let (lo, hi) = bounds(&outline_of(panel));
        panel.anchor = Some([round(0.5 * (lo.x + hi.x)), round(hi.y)]);
        panel.placement = PlacementConfig {
            around: Around::Cone,
            angle_deg: round((centres[k] + turn).to_degrees().rem_euclid(360.0)),
            distance: round(radius),
            height: round(waist),
            flare_deg: round(flare.to_degrees()),
        };
    }
    // Sleeves of a skirt pattern (named so by the user) hang beside the form.
    let neck = cm(m.waist_height + m.torso_length);
    arrange_plane(panels, Role::Sleeve, 180.0, cm(0.5 * m.shoulder_width) + 10.0, neck - 3.0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::garment::dxf::{Notch, NotchShape};

    fn piece(outline: Vec<DVec2>, notches: Vec<f64>, quantity: u32) -> Piece {
        Piece {
            name: "Back Half".into(),
            block: "BACK".into(),
            quantity,
            size: None,
            cut_line: outline.clone(),
            outline,
            sew_line: false,
            seam_allowance: None,
            grain_deg: 90.0,
            grain_given: true,
            notches: notches.into_iter().map(|at| Notch { at, shape: NotchShape::Slit, depth: 5.0 }).collect(),
            drill_holes: Vec::new(),
            internal_lines: 0,
        }
    }

    #[test]
    fn names_are_lower_case_with_dashes() {
        assert_eq!(panel_name("Front Panel"), "front-panel");
        assert_eq!(panel_name("  BACK_YOKE. (2) "), "back-yoke-2");
        assert_eq!(panel_name("..."), "piece");
    }

    /// A trapezoid with a curved top: four corners, the curve's points not among them;
    /// corners numbered from the lowest-left; a piece cut twice gives a mirror whose points
    /// keep their names and places.
    #[test]
    fn corners_notches_and_the_mirrored_copy() {
        let mut outline = vec![DVec2::new(0.0, 0.0), DVec2::new(400.0, 0.0), DVec2::new(300.0, 600.0)];
        // A shallow arc from (300, 600) to (100, 600), 20 points.
        for i in 1..20 {
            let t = i as f64 / 20.0;
            outline.push(DVec2::new(300.0 - 200.0 * t, 600.0 + 40.0 * (std::f64::consts::PI * t).sin()));
        }
        outline.push(DVec2::new(100.0, 600.0));
        // Start the list at the top right, so that numbering must find the lowest-left.
        outline.rotate_left(2);
        let found = corners(&outline);
        assert_eq!(found.len(), 4, "{found:?}");
        // A notch 100 mm up the right side from (400, 0): the outline starts at (300, 600)
        // and ends with the right side, so that is its perimeter less the right side's
        // length, plus 100.
        let right = DVec2::new(400.0, 0.0).distance(DVec2::new(300.0, 600.0));
        let perimeter = arcs(&outline)[outline.len()];
        let at = perimeter - right + 100.0;
        let panels = piece_panels(&piece(outline, vec![at], 2), Role::Back);
        assert_eq!(panels.len(), 2);
        let (drawn, mirror) = (&panels[0].panel, &panels[1].panel);
        assert_eq!((drawn.name.as_str(), mirror.name.as_str()), ("back-half-right", "back-half-left"));
        assert_eq!(drawn.start, [0.0, 0.0]);
        let names: Vec<&str> = drawn.edges.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["e1", "e2", "e3", "e4"]);
        assert_eq!(drawn.edges[0].to, [40.0, 0.0]);
        assert_eq!(drawn.notches, vec![NotchConfig { name: "n1".into(), edge: "e2".into(), at: 10.0 }]);
        // The mirror, about x = 20 cm: c1 at (40, 0), its first edge e1 up to c4, (10, 60)
        // mirrored to (30, 60). The drawn side c2–c3 is the mirror's edge from c3 to c2, e3,
        // and the notch lies 10 cm from its end.
        assert_eq!(mirror.start, [40.0, 0.0]);
        let names: Vec<&str> = mirror.edges.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["e1", "e4", "e3", "e2"]);
        assert_eq!(mirror.edges[0].to, [30.0, 60.0]);
        assert_eq!(mirror.edges[2].to, [0.0, 0.0]);
        assert_eq!(mirror.notches.len(), 1);
        assert_eq!((mirror.notches[0].edge.as_str(), mirror.notches[0].name.as_str()), ("e3", "n1"));
        assert!((mirror.notches[0].at - (right / 10.0 - 10.0)).abs() < 1e-3, "{:?}", mirror.notches);
        assert!((mirror.grain_deg - 90.0).abs() < 1e-12);
        // Both outlines close and run counter-clockwise.
        for p in [drawn, mirror] {
            let curves = p.curves(0.01).unwrap();
            let names: Vec<&str> = p.edges.iter().map(|e| e.name.as_str()).collect();
            crate::garment::pattern::check_simple(&p.name, &names, &curves).unwrap();
            p.notch_positions(&curves, 0.01).unwrap();
        }
    }
}
