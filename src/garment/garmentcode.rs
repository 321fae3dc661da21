//! Patterns in GarmentCode's specification format (the JSON that GarmentCode and its
//! dataset write: panels as 2D vertex loops with curved edges, each placed in 3D by a
//! rotation and a translation around the body, and stitches between edges), turned into a
//! `[garment]` section (docs/garments.md, "Importing a GarmentCode pattern").
//!
//! The format, as this reader takes it:
//! - lengths in `properties.units_in_meter` (100: centimetres, the default);
//! - a panel's edges form one loop (each starts where the last ended), counter-clockwise
//!   seen from the garment's outside;
//! - an edge's `curvature` is absent (straight), a quadratic Bézier control point, two cubic
//!   ones, or a circular arc `[radius, large_arc, right]`; control points are in the edge's
//!   own frame (`curvature_coords = "relative"`: x along the edge from its start, y the edge
//!   turned a quarter counter-clockwise, both in edge lengths) or in the panel's;
//! - a panel's points go to 3D as R·(x, y, 0) + translation, R the intrinsic x-y-z Euler
//!   rotation (degrees), in a frame with y up from the floor and the body facing +z;
//! - a stitch joins the end of its first edge to the start of its second (right sides
//!   together) unless it carries `"right_wrong"`, which joins start to start.
//!
//! Rosette's panels start on vertical planes facing out from the form's axis
//! (`Around::Plane`), so each panel's plane must be vertical; the rotation within it is
//! taken into the outline, and a panel whose loop runs clockwise in its own coordinates
//! (its outside faces its −z, the back panels) is mirrored so that it reads as seen from
//! outside. Every point then lands where GarmentCode's own placement puts it.

use super::GarmentError;
use super::form::FormConfig;
use super::import::{Imported, Origin, garment, hem_edges, hem_note};
use super::pattern::{Around, EdgeConfig, PanelConfig, PlacementConfig};
use super::seams::{Direction, SeamConfig};
use glam::{DMat3, DVec2, DVec3};
use serde::Deserialize;
use serde_json::Value;
use std::collections::BTreeMap;

#[derive(Deserialize)]
struct Spec {
    pattern: SpecPattern,
    #[serde(default)]
    properties: Properties,
}

#[derive(Deserialize)]
struct SpecPattern {
    panels: UniqueKeys<SpecPanel>,
    #[serde(default)]
    stitches: Vec<Vec<Value>>,
    #[serde(default)]
    panel_order: Option<Vec<String>>,
}

/// A JSON object whose keys must differ: serde_json keeps the last of two equal keys,
/// which would drop a panel in silence.
struct UniqueKeys<V>(BTreeMap<String, V>);

impl<'de, V: Deserialize<'de>> Deserialize<'de> for UniqueKeys<V> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visit<V>(std::marker::PhantomData<V>);
        impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Visit<V> {
            type Value = UniqueKeys<V>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of panels by name")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut out = BTreeMap::new();
                while let Some((name, value)) = map.next_entry::<String, V>()? {
                    if out.contains_key(&name) {
                        return Err(serde::de::Error::custom(format!("two panels are named '{name}'; give each its own name")));
                    }
                    out.insert(name, value);
                }
                Ok(UniqueKeys(out))
            }
        }
        deserializer.deserialize_map(Visit(std::marker::PhantomData))
    }
}

impl<V> std::ops::Deref for UniqueKeys<V> {
    type Target = BTreeMap<String, V>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

#[derive(Deserialize, Default)]
struct Properties {
    #[serde(default)]
    curvature_coords: Option<String>,
    #[serde(default)]
    units_in_meter: Option<f64>,
}

#[derive(Deserialize)]
struct SpecPanel {
    translation: [f64; 3],
    rotation: [f64; 3],
    vertices: Vec<[f64; 2]>,
    edges: Vec<SpecEdge>,
}

#[derive(Deserialize)]
struct SpecEdge {
    endpoints: [usize; 2],
    #[serde(default)]
    curvature: Option<Value>,
}

/// Options of an import.
pub struct ImportOptions {
    /// The form the garment goes on.
    pub form: FormConfig,
    /// The warp's angle in every panel's own coordinates as GarmentCode drafts them,
    /// degrees from its x axis (90: the straight grain runs up and down the panel).
    pub grain_deg: f64,
}

impl Default for ImportOptions {
    /// The largest bundled form and the straight grain.
    fn default() -> Self {
        Self { form: super::import::default_form(), grain_deg: 90.0 }
    }
}

/// Where the panels of a GarmentCode import come from, for the scene file's header.
pub const ORIGIN: Origin<'static> = Origin {
    format: "GarmentCode's pattern specification",
    short: "GarmentCode",
    placement: "each panel starts where GarmentCode places it, on a vertical plane facing out.",
};

/// Reads a GarmentCode specification (`text`, from `source`) into a `[garment]` section
/// in centimetres.
pub fn import(text: &str, source: &str, options: &ImportOptions) -> Result<Imported, GarmentError> {
    let bad = |m: String| GarmentError::new(format!("{source}: {m}"));
    let spec: Spec = serde_json::from_str(text).map_err(|e| bad(format!("not a GarmentCode pattern specification ({e})")))?;
    let mut notes = Vec::new();
    let units_in_meter = match spec.properties.units_in_meter {
        Some(u) if u.is_finite() && u > 0.0 => u,
        Some(u) => return Err(bad(format!("properties.units_in_meter = {u} must be a positive number"))),
        None => {
            notes.push("properties.units_in_meter is missing: lengths taken as centimetres".into());
            100.0
        }
    };
    let relative = match spec.properties.curvature_coords.as_deref() {
        None | Some("relative") => true,
        Some("absolute") => false,
        Some(other) => return Err(bad(format!("properties.curvature_coords = \"{other}\": use \"relative\" or \"absolute\""))),
    };
    if !options.grain_deg.is_finite() {
        return Err(bad(format!("the grain angle {} must be a finite number of degrees", options.grain_deg)));
    }
    let order: Vec<String> = match &spec.pattern.panel_order {
        Some(order) => {
            for name in order {
                if !spec.pattern.panels.contains_key(name) {
                    return Err(bad(format!("pattern.panel_order names '{name}', which is not among pattern.panels")));
                }
            }
            let mut order = order.clone();
            order.extend(spec.pattern.panels.keys().filter(|k| !order.contains(k)).cloned().collect::<Vec<_>>());
            order
        }
        None => spec.pattern.panels.keys().cloned().collect(),
    };
    if order.is_empty() {
        return Err(bad("pattern.panels is empty".into()));
    }
    let to_cm = 100.0 / units_in_meter;
    let mut panels = Vec::with_capacity(order.len());
    // Each panel's lowest point and each edge's end heights, cm: the hem is found from them.
    let mut heights: Vec<Vec<[f64; 2]>> = Vec::with_capacity(order.len());
    for name in &order {
        let (panel, edge_heights) = convert_panel(name, &spec.pattern.panels[name], relative, to_cm, options.grain_deg).map_err(bad)?;
        panels.push(panel);
        heights.push(edge_heights);
    }
    let (seams, sides) = stitches(&spec.pattern.stitches, &order, &panels).map_err(bad)?;
    let mut stitched = vec![Vec::new(); order.len()];
    for &((pa, ea), (pb, eb)) in &sides {
        stitched[pa].push(ea);
        stitched[pb].push(eb);
    }
    // GarmentCode gathers a seam whose sides differ (a bodice into a narrower skirt): the
    // ease is set to the pattern's largest difference, up to what Rosette sews.
    let mut ease = super::default_seam_ease();
    let mut eased = Vec::new();
    let lengths: Vec<Vec<f64>> = panels
        .iter()
        .map(|p| p.curves(1.0).map(|c| c.iter().map(|e| e.length()).collect()))
        .collect::<Result<_, _>>()
        .map_err(|e| bad(e.message))?;
    for (i, &((pa, ea), (pb, eb))) in sides.iter().enumerate() {
        let (la, lb) = (lengths[pa][ea], lengths[pb][eb]);
        let share = (la - lb).abs() / la.max(lb);
        if share >= MAX_EASE {
            return Err(bad(format!(
                "pattern.stitches[{i}]: {}.e{ea} ({la:.1} cm) and {}.e{eb} ({lb:.1} cm) differ by {:.0} %; Rosette gathers a seam by at most {:.0} %",
                order[pa],
                order[pb],
                100.0 * share,
                100.0 * MAX_EASE
            )));
        }
        if share > super::default_seam_ease() {
            eased.push(format!("stitch {i} ({:.0} %)", 100.0 * share));
            ease = ease.max(((100.0 * share + 1.0).ceil() / 100.0).min(MAX_EASE));
        }
    }
    if !eased.is_empty() {
        notes.push(format!("garment.seam_ease = {ease}: GarmentCode gathers {}", eased.join(", ")));
    }
    let hem = hem_edges(&panels, &heights, &stitched);
    notes.push(hem_note(&hem));
    Ok(Imported { garment: garment(options.form.clone(), panels, seams, hem, ease), notes })
}

/// A stitch's two sides, each as (panel, edge) by index.
type StitchSides = ((usize, usize), (usize, usize));

/// GarmentCode's stitches as Rosette's seams, with each one's sides.
fn stitches(stitches: &[Vec<Value>], order: &[String], panels: &[PanelConfig]) -> Result<(Vec<SeamConfig>, Vec<StitchSides>), String> {
    let mut seams = Vec::with_capacity(stitches.len());
    let mut sides: Vec<StitchSides> = Vec::with_capacity(stitches.len());
    for (i, stitch) in stitches.iter().enumerate() {
        let side = |j: usize| -> Result<(usize, usize), String> {
            let key = format!("pattern.stitches[{i}][{j}]");
            let entry = stitch.get(j).ok_or_else(|| format!("{key} is missing: a stitch joins two edges"))?;
            let panel = entry.get("panel").and_then(Value::as_str).ok_or_else(|| format!("{key} needs a \"panel\" name"))?;
            let edge = entry.get("edge").and_then(Value::as_u64).ok_or_else(|| format!("{key} needs an \"edge\" index"))? as usize;
            let p = order.iter().position(|n| n == panel).ok_or_else(|| format!("{key}: no panel '{panel}'"))?;
            if edge >= panels[p].edges.len() {
                return Err(format!("{key}: panel '{panel}' has {} edges, no edge {edge}", panels[p].edges.len()));
            }
            Ok((p, edge))
        };
        let (a, b) = (side(0)?, side(1)?);
        let edge = |(p, e): (usize, usize)| format!("panel '{}' edge {e}", order[p]);
        if a == b {
            return Err(format!("pattern.stitches[{i}] joins {} to itself", edge(a)));
        }
        // GarmentCode stitches whole edges, so an edge in two stitches is sewn twice over.
        if let Some((j, twice)) = sides.iter().enumerate().find_map(|(j, &(x, y))| [a, b].into_iter().find(|s| *s == x || *s == y).map(|s| (j, s))) {
            return Err(format!("pattern.stitches[{j}] and pattern.stitches[{i}] both sew {}: an edge takes one stitch", edge(twice)));
        }
        let direction = match stitch.get(2).and_then(Value::as_str) {
            Some("right_wrong") => Direction::Same,
            _ => Direction::Opposite,
        };
        sides.push((a, b));
        let key = |(p, e): (usize, usize)| format!("{}.{}", order[p], panels[p].edges[e].name);
        seams.push(SeamConfig { a: key(a), b: key(b), direction, a_span: None, b_span: None });
    }
    Ok((seams, sides))
}

/// The largest relative difference between a seam's sides that an import sets
/// `garment.seam_ease` to (Rosette takes shares under a half).
const MAX_EASE: f64 = 0.49;

/// GarmentCode's frame (y up, the body facing +z) in Rosette's (z up, the form facing −y).
fn to_rosette(v: DVec3) -> DVec3 {
    DVec3::new(v.x, -v.z, v.y)
}

/// GarmentCode's rotation: intrinsic x-y-z Euler angles in degrees, R = Rz·Ry·Rx.
fn rotation(euler: [f64; 3]) -> DMat3 {
    let [x, y, z] = euler.map(f64::to_radians);
    DMat3::from_rotation_z(z) * DMat3::from_rotation_y(y) * DMat3::from_rotation_x(x)
}

/// One panel as Rosette's, with each edge's end heights above the floor (cm).
fn convert_panel(name: &str, panel: &SpecPanel, relative: bool, to_cm: f64, grain_deg: f64) -> Result<(PanelConfig, Vec<[f64; 2]>), String> {
    let at = |m: String| format!("panel '{name}': {m}");
    let finite = panel.translation.iter().chain(&panel.rotation).chain(panel.vertices.iter().flatten()).all(|v| v.is_finite());
    if !finite {
        return Err(at("a translation, rotation or vertex value is not a finite number".into()));
    }
    if panel.rotation.iter().any(|r| r.abs() > 360.0) {
        return Err(at(format!("its rotation {:?} must be angles in degrees between -360 and 360", panel.rotation)));
    }
    // Beyond 10 m a value is a unit slip, and the outline's area would overflow.
    const MAX_CM: f64 = 1000.0;
    if let Some(k) = panel.vertices.iter().position(|v| v.iter().any(|x| (x * to_cm).abs() > MAX_CM)) {
        let [x, y] = panel.vertices[k];
        return Err(at(format!("vertex {k} at ({x}, {y}) lies more than {MAX_CM} cm from the panel's origin; check properties.units_in_meter")));
    }
    if panel.translation.iter().any(|x| (x * to_cm).abs() > MAX_CM) {
        return Err(at(format!("its translation {:?} places it more than {MAX_CM} cm from the body; check properties.units_in_meter", panel.translation)));
    }
    let n = panel.edges.len();
    if n < 2 {
        return Err(at(format!("{n} edges cannot close an outline")));
    }
    for (i, e) in panel.edges.iter().enumerate() {
        if let Some(&v) = e.endpoints.iter().find(|&&v| v >= panel.vertices.len()) {
            return Err(at(format!("edge {i} names vertex {v}, but the panel has {} vertices", panel.vertices.len())));
        }
        let next = &panel.edges[(i + 1) % n];
        if e.endpoints[1] != next.endpoints[0] {
            return Err(at(format!("edge {i} ends at vertex {} but edge {} starts at vertex {}: the edges must form one loop", e.endpoints[1], (i + 1) % n, next.endpoints[0])));
        }
    }
    let vertex = |i: usize| DVec2::from_array(panel.vertices[i]);
    // Counter-clockwise seen from outside: a loop that runs clockwise in the panel's own
    // coordinates faces out along its −z and is mirrored (x → −x) to read from outside.
    let area: f64 = panel.edges.iter().map(|e| vertex(e.endpoints[0]).perp_dot(vertex(e.endpoints[1]))).sum::<f64>() * 0.5;
    if area.abs() < 1e-12 {
        return Err(at("its outline encloses no area".into()));
    }
    let mirror = if area > 0.0 { 1.0 } else { -1.0 };
    let r = rotation(panel.rotation);
    let outward = to_rosette(mirror * r.z_axis);
    if outward.z.abs() > 1e-6 {
        return Err(at(format!(
            "its rotation {:?} tilts it out of the vertical; Rosette starts panels on vertical planes around the form",
            panel.rotation
        )));
    }
    let out = DVec2::new(outward.x, outward.y).normalize();
    let tangent = DVec3::new(-out.y, out.x, 0.0);
    // The panel's axes as seen from outside, in Rosette's frame: x' = mirror·x, y' = y; the
    // rotation within the plane is θ from the plane's horizontal tangent.
    let (ex, ey) = (to_rosette(mirror * r.x_axis), to_rosette(r.y_axis));
    let theta = ex.z.atan2(ex.dot(tangent));
    let (sin, cos) = theta.sin_cos();
    if (ey.dot(tangent) + sin).abs() > 1e-6 || (ey.z - cos).abs() > 1e-6 {
        return Err(at("its rotation is not a rotation (the panel's axes do not stay square)".into()));
    }
    let plane = |p: DVec2| -> DVec2 {
        let q = DVec2::new(mirror * p.x, p.y);
        DVec2::new(cos * q.x - sin * q.y, sin * q.x + cos * q.y) * to_cm
    };
    let translation = to_rosette(DVec3::from_array(panel.translation)) * to_cm;
    let horizontal = DVec2::new(translation.x, translation.y);
    let distance = horizontal.dot(out);
    if distance <= 0.0 {
        return Err(at(format!("it faces the body's axis from {:.1} cm behind it; its outside must face away from the body", -distance)));
    }
    let along = horizontal.dot(DVec2::new(tangent.x, tangent.y));
    let placement = PlacementConfig { around: Around::Plane, angle_deg: out.y.atan2(out.x).to_degrees().rem_euclid(360.0), distance, height: translation.z, flare_deg: 0.0 };
    let anchor = DVec2::new(-along, 0.0);
    let height = |p: DVec2| translation.z + p.y;
    let mut edges = Vec::with_capacity(n);
    let mut edge_heights = Vec::with_capacity(n);
    for (i, e) in panel.edges.iter().enumerate() {
        let (start, end) = (vertex(e.endpoints[0]), vertex(e.endpoints[1]));
        let (through, controls) = edge_curve(e.curvature.as_ref(), start, end, relative).map_err(|m| at(format!("edge {i}: {m}")))?;
        edges.push(EdgeConfig {
            name: format!("e{i}"),
            to: plane(end).to_array(),
            through: through.map(|t| plane(t).to_array()),
            controls: controls.map(|[a, b]| [plane(a).to_array(), plane(b).to_array()]),
            points: None,
        });
        edge_heights.push([height(plane(start)), height(plane(end))]);
    }
    let grain = if mirror > 0.0 { grain_deg } else { 180.0 - grain_deg } + theta.to_degrees();
    let panel = PanelConfig {
        name: name.to_string(),
        grain_deg: grain.rem_euclid(360.0),
        start: plane(vertex(panel.edges[0].endpoints[0])).to_array(),
        edges,
        anchor: Some(anchor.to_array()),
        placement,
        notches: Vec::new(),
        seam_allowance: None,
    };
    Ok((panel, edge_heights))
}

/// An edge's curve: the middle point of an arc, or the two control points of a cubic
/// Bézier; neither for a straight edge.
type Curve = (Option<DVec2>, Option<[DVec2; 2]>);

/// The curve of an edge from `start` to `end` (panel coordinates) with GarmentCode's
/// `curvature`, a quadratic raised to degree three (the same curve).
fn edge_curve(curvature: Option<&Value>, start: DVec2, end: DVec2, relative: bool) -> Result<Curve, String> {
    let point = |p: [f64; 2]| -> DVec2 {
        let p = DVec2::from_array(p);
        if relative {
            let chord = end - start;
            start + p.x * chord + p.y * chord.perp()
        } else {
            p
        }
    };
    let (mut through, mut controls) = (None, None);
    match curvature {
        None | Some(Value::Null) => {}
        Some(c) => {
            let kind = if c.is_array() { "quadratic" } else { c.get("type").and_then(Value::as_str).ok_or_else(|| "curvature has no \"type\"".to_string())? };
            let params = if c.is_array() { Value::Array(vec![c.clone()]) } else { c.get("params").cloned().unwrap_or(Value::Null) };
            let pair = |v: &Value| -> Result<[f64; 2], String> {
                let p: [f64; 2] = serde_json::from_value(v.clone()).map_err(|_| "a control point must be two numbers".to_string())?;
                if p.iter().all(|x| x.is_finite()) { Ok(p) } else { Err("a control point is not finite".to_string()) }
            };
            let list = params.as_array().cloned().unwrap_or_default();
            match kind {
                "quadratic" => {
                    let q = point(pair(list.first().ok_or_else(|| "a quadratic curve needs one control point".to_string())?)?);
                    // The same curve as a cubic: control points two thirds of the way to q.
                    controls = Some([start + (q - start) * (2.0 / 3.0), end + (q - end) * (2.0 / 3.0)]);
                }
                "cubic" => {
                    if list.len() != 2 {
                        return Err("a cubic curve needs two control points".to_string());
                    }
                    controls = Some([point(pair(&list[0])?), point(pair(&list[1])?)]);
                }
                "circle" => {
                    let radius = list.first().and_then(Value::as_f64).filter(|r| r.is_finite() && *r > 0.0).ok_or_else(|| "a circle needs a positive radius".to_string())?;
                    let flag = |j: usize| list.get(j).and_then(|v| v.as_bool().or_else(|| v.as_f64().map(|x| x != 0.0)));
                    let (Some(large), Some(right)) = (flag(1), flag(2)) else {
                        return Err("a circle's params are [radius, large_arc, right]".to_string());
                    };
                    let middle = arc_midpoint(start, end, radius, large, right).ok_or_else(|| format!("radius {} is shorter than half the edge's chord", crate::io::number::short(radius)))?;
                    let chord = start.distance(end);
                    if !(middle.is_finite() && middle.distance(0.5 * (start + end)) <= 1e3 * chord) {
                        return Err(format!("radius {} makes the large arc over a {chord:.3} chord bulge beyond a thousand chords", crate::io::number::short(radius)));
                    }
                    // An arc too flat to tell from its chord is drawn straight.
                    through = (middle.distance(0.5 * (start + end)) > 1e-9 * chord).then_some(middle);
                }
                other => return Err(format!("unknown curvature type \"{other}\" (quadratic, cubic or circle)")),
            }
        }
    }
    Ok((through, controls))
}

/// The middle of the circular arc of `radius` from `start` to `end`: the short or long
/// arc (`large`), bulging to the right of the chord when `right` (GarmentCode draws it
/// counter-clockwise from start to end then). None when the radius cannot span the chord.
fn arc_midpoint(start: DVec2, end: DVec2, radius: f64, large: bool, right: bool) -> Option<DVec2> {
    let chord = end - start;
    let half = 0.5 * chord.length();
    // A radius equal to half the chord, written to a few digits, may fall short of it by
    // rounding: a half circle.
    if radius < half * (1.0 - 1e-6) || half == 0.0 {
        return None;
    }
    // Written so that no square overflows: a radius of 1e300 is a straight edge.
    let rise = radius * (1.0 - (half / radius).powi(2)).max(0.0).sqrt();
    let sagitta = if large { radius + rise } else { half * half / (radius + rise) };
    let normal = DVec2::new(chord.y, -chord.x) / chord.length();
    Some(0.5 * (start + end) + sagitta * if right { normal } else { -normal })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::garment::place::Placement;

    fn options() -> ImportOptions {
        ImportOptions { form: FormConfig { size: Some("uk-12".into()), ..FormConfig::default() }, grain_deg: 90.0 }
    }

    /// A front and a back panel (the back clockwise in its own coordinates, as GarmentCode
    /// writes it) and a sleeve turned within its plane, with the three curve kinds.
    const SPEC: &str = r#"{
      "pattern": {
        "panels": {
          "front": { "translation": [-20, 80, 25], "rotation": [0, 0, 0],
            "vertices": [[0, 0], [40, 0], [38, 30], [2, 30]],
            "edges": [ {"endpoints": [0, 1]}, {"endpoints": [1, 2]},
                       {"endpoints": [2, 3], "curvature": {"type": "quadratic", "params": [[0.5, 0.1]]}},
                       {"endpoints": [3, 0]} ] },
          "back": { "translation": [20, 80, -20], "rotation": [0, 0, 0],
            "vertices": [[0, 0], [-40, 0], [-38, 30], [-2, 30]],
            "edges": [ {"endpoints": [0, 1]}, {"endpoints": [1, 2]},
                       {"endpoints": [2, 3], "curvature": {"type": "cubic", "params": [[0.3, -0.1], [0.7, -0.1]]}},
                       {"endpoints": [3, 0]} ] },
          "sleeve": { "translation": [40, 100, 5], "rotation": [0, 0, -50],
            "vertices": [[0, 0], [20, 0], [20, 10], [0, 10]],
            "edges": [ {"endpoints": [0, 1]}, {"endpoints": [1, 2]},
                       {"endpoints": [2, 3], "curvature": {"type": "circle", "params": [12, 0, 1]}},
                       {"endpoints": [3, 0]} ] }
        },
        "stitches": [
          [{"panel": "front", "edge": 1}, {"panel": "back", "edge": 3}],
          [{"panel": "front", "edge": 3}, {"panel": "back", "edge": 1}, "right_wrong"]
        ]
      },
      "properties": {"curvature_coords": "relative", "units_in_meter": 100}
    }"#;

    /// Every panel point lands, through Rosette's placement, where GarmentCode's own
    /// transform R·(x, y, 0) + t puts it (computed here from the specification directly).
    #[test]
    fn panels_land_where_garmentcode_places_them() {
        let imported = import(SPEC, "test.json", &options()).unwrap();
        let spec: Spec = serde_json::from_str(SPEC).unwrap();
        for panel in &imported.garment.panels {
            let source = &spec.pattern.panels[&panel.name];
            let r = rotation(source.rotation);
            let place = Placement::new(&panel.placement, DVec2::from_array(panel.anchor.unwrap()) * 0.01, DVec2::ZERO, 0.01);
            let ours = std::iter::once(panel.start).chain(panel.edges.iter().map(|e| e.to));
            let theirs = source.edges.iter().map(|e| source.vertices[e.endpoints[0]]).chain(std::iter::once(source.vertices[source.edges[0].endpoints[0]]));
            for (p, q) in ours.zip(theirs) {
                let expect = 0.01 * DVec3::new(
                    (r * DVec3::new(q[0], q[1], 0.0)).x + source.translation[0],
                    -((r * DVec3::new(q[0], q[1], 0.0)).z + source.translation[2]),
                    (r * DVec3::new(q[0], q[1], 0.0)).y + source.translation[1],
                );
                let got = place.position(DVec2::from_array(p) * 0.01);
                assert!((got - expect).length() < 1e-12, "{}: {got} against {expect}", panel.name);
            }
        }
    }

    /// Outlines come out counter-clockwise (the back mirrored), lengths kept; stitches
    /// keep GarmentCode's pairing; the hem is the free bottom edges.
    #[test]
    fn outlines_seams_and_hem() {
        let imported = import(SPEC, "test.json", &options()).unwrap();
        let g = &imported.garment;
        for panel in &g.panels {
            let points: Vec<DVec2> = std::iter::once(panel.start).chain(panel.edges.iter().map(|e| e.to)).map(DVec2::from_array).collect();
            let area: f64 = points.windows(2).map(|w| w[0].perp_dot(w[1])).sum();
            assert!(area > 0.0, "{} runs clockwise", panel.name);
        }
        let front = &g.panels.iter().find(|p| p.name == "front").unwrap();
        // Straight edge 1 of the front, (40, 0) to (38, 30), keeps its length.
        let e1 = DVec2::from_array(front.edges[1].to).distance(DVec2::from_array(front.edges[0].to));
        assert!((e1 - (4.0f64 + 900.0).sqrt()).abs() < 1e-12);
        // A quadratic with control q: cubic controls at 2/3 towards q; q = mid-chord + 0.1 × the
        // chord (−36, 0) turned counter-clockwise = (20, 30) + (0, −3.6).
        let [c1, _] = front.edges[2].controls.unwrap();
        let q = DVec2::new(20.0, 26.4);
        let expect = DVec2::new(38.0, 30.0) + (q - DVec2::new(38.0, 30.0)) * (2.0 / 3.0);
        assert!((DVec2::from_array(c1) - expect).length() < 1e-9, "{c1:?}");
        assert_eq!(g.seams[0].direction, Direction::Opposite);
        assert_eq!(g.seams[1].direction, Direction::Same);
        assert_eq!((g.seams[0].a.as_str(), g.seams[0].b.as_str()), ("front.e1", "back.e3"));
        assert_eq!(g.hem, vec!["back.e0".to_string(), "front.e0".to_string()]);
        // The front panel faces −y (angle 270°) at 25 cm; the back +y at 20 cm.
        assert!((front.placement.angle_deg - 270.0).abs() < 1e-9 && (front.placement.distance - 25.0).abs() < 1e-9);
        let back = g.panels.iter().find(|p| p.name == "back").unwrap();
        assert!((back.placement.angle_deg - 90.0).abs() < 1e-9 && (back.placement.distance - 20.0).abs() < 1e-9);
    }

    /// GarmentCode's circle: the short arc of radius 12 over a 20-long chord, drawn
    /// counter-clockwise (bulging right of the chord), has its middle 12 − √(144 − 100) off
    /// the chord.
    #[test]
    fn arc_middle_from_radius_and_flags() {
        let (a, b) = (DVec2::new(20.0, 10.0), DVec2::new(0.0, 10.0));
        let sagitta = 12.0 - (44.0f64).sqrt();
        let right = arc_midpoint(a, b, 12.0, false, true).unwrap();
        assert!((right - DVec2::new(10.0, 10.0 + sagitta)).length() < 1e-12, "{right}");
        let long_left = arc_midpoint(a, b, 12.0, true, false).unwrap();
        assert!((long_left - DVec2::new(10.0, 10.0 - (12.0 + 44f64.sqrt()))).length() < 1e-12);
        assert!(arc_midpoint(a, b, 9.0, false, true).is_none());
    }

    /// Bad specifications are refused naming the panel and the edge.
    #[test]
    fn bad_specifications_name_the_panel_and_edge() {
        // The front panel comes first in the text: its edge 1 made to end at vertex 3.
        let broken = SPEC.replacen(r#"{"endpoints": [1, 2]}"#, r#"{"endpoints": [1, 3]}"#, 1);
        let e = import(&broken, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'front'") && e.contains("edge 1") && e.contains("loop"), "{e}");
        let tilted = SPEC.replace(r#""rotation": [0, 0, -50]"#, r#""rotation": [30, 0, 0]"#);
        let e = import(&tilted, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'sleeve'") && e.contains("vertical"), "{e}");
        let twice = SPEC.replace(r#""sleeve": {"#, r#""front": {"#);
        let e = import(&twice, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("two panels are named 'front'"), "{e}");
        let unknown = SPEC.replace(r#""type": "cubic""#, r#""type": "spline""#);
        let e = import(&unknown, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'back'") && e.contains("edge 2") && e.contains("spline"), "{e}");
        let missing = SPEC.replace(r#"{"panel": "back", "edge": 3}"#, r#"{"panel": "back", "edge": 7}"#);
        let e = import(&missing, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("stitches[0][1]") && e.contains("no edge 7"), "{e}");
        let gathered = SPEC.replacen(r#""stitches": ["#, r#""stitches": [[{"panel": "front", "edge": 0}, {"panel": "sleeve", "edge": 1}], "#, 1);
        let e = import(&gathered, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("stitches[0]") && e.contains("front.e0 (40.0 cm)") && e.contains("sleeve.e1 (10.0 cm)") && e.contains("75 %"), "{e}");
        let twice = SPEC.replacen(r#""stitches": ["#, r#""stitches": [[{"panel": "front", "edge": 0}, {"panel": "back", "edge": 3}], "#, 1);
        let e = import(&twice, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("stitches[0] and pattern.stitches[1]") && e.contains("panel 'back' edge 3"), "{e}");
        let itself = SPEC.replacen(r#"{"panel": "back", "edge": 3}"#, r#"{"panel": "front", "edge": 1}"#, 1);
        let e = import(&itself, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("stitches[0] joins panel 'front' edge 1 to itself"), "{e}");
        let flat = SPEC.replace(r#""params": [12, 0, 1]"#, r#""params": [1e300, 0, 1]"#);
        let sleeve = import(&flat, "x.json", &options()).unwrap().garment.panels.into_iter().find(|p| p.name == "sleeve").unwrap();
        assert!(sleeve.edges[2].through.is_none(), "an arc of radius 1e300 is its chord");
        let e = import(&SPEC.replace(r#""params": [12, 0, 1]"#, r#""params": [1e300, 1, 1]"#), "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'sleeve'") && e.contains("edge 2") && e.contains("radius 1e300"), "{e}");
        let e = import(&SPEC.replace("[0, 0, -50]", "[0, 0, 1e300]"), "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'sleeve'") && e.contains("between -360 and 360"), "{e}");
        let huge = SPEC.replacen("[40, 0]", "[1e300, 0]", 1);
        let e = import(&huge, "x.json", &options()).err().unwrap().message;
        assert!(e.contains("panel 'front'") && e.contains("vertex 1") && e.contains("units_in_meter"), "{e}");
        assert!(import("{", "x.json", &options()).is_err());
    }
}
