//! Reading a pattern file with the `dxf` crate into [`DxfPattern`]: pieces from blocks,
//! their layers sorted into cut line, sew line, grain, notches and text, every length in
//! millimetres, every refusal naming the piece and the fix.

use super::{BINARY_SENTINEL, DxfPattern, LengthUnit, Notch, NotchShape, Piece, ReadOptions};
use crate::garment::GarmentError;
use dxf::Drawing;
use dxf::entities::{Entity, EntityType};
use glam::DVec2;

/// Most entities one piece may hold (a piece has tens: its lines, notches and text). A
/// block of many thousands is a marker, a nest or a drawing, not a pattern piece.
pub const MAX_PIECE_ENTITIES: usize = 5_000;
/// Most points a piece's outline may have (pattern CAD flattens a curved edge into tens).
pub const MAX_OUTLINE_POINTS: usize = 5_000;
/// Most pieces a file may hold.
pub const MAX_PIECES: usize = 500;
/// The largest a piece may be across, mm: a floor-length gown's front is about 1.6 m long;
/// a piece larger than this is a file read in the wrong unit.
pub const MAX_PIECE_SIZE: f64 = 1_800.0;
/// The smallest the largest piece of a pattern may be across, mm: a pattern whose largest
/// piece is smaller is drawn in larger units than it was read in (inches read as mm).
pub const MIN_LARGEST_PIECE: f64 = 30.0;
/// Ends of a line closer than this are one point, mm.
const JOIN: f64 = 0.05;

/// A drawing entity brought into the piece's frame, in file units.
enum Shape {
    /// A line, polyline, arc or circle, flattened.
    Path { points: Vec<DVec2>, closed: bool },
    /// A POINT: where, its z (a notch's depth), its thickness (a notch's width) and the
    /// direction its angle (group 50) gives.
    Point { at: DVec2, depth: f64, width: f64, direction: DVec2 },
    Text(String),
    /// A block reference inside a piece's block.
    Insert(String),
    Other,
}

/// An INSERT's map from its block's coordinates to the drawing's.
#[derive(Clone, Copy)]
struct Transform {
    base: DVec2,
    scale: DVec2,
    rotation: f64,
    location: DVec2,
}

impl Transform {
    const IDENTITY: Transform = Transform { base: DVec2::ZERO, scale: DVec2::ONE, rotation: 0.0, location: DVec2::ZERO };

    fn point(&self, p: DVec2) -> DVec2 {
        self.location + DVec2::from_angle(self.rotation).rotate((p - self.base) * self.scale)
    }

    fn direction(&self, d: DVec2) -> DVec2 {
        DVec2::from_angle(self.rotation).rotate(d * self.scale).normalize_or_zero()
    }

    fn length(&self) -> f64 {
        (self.scale.x * self.scale.y).abs().sqrt()
    }
}

/// One piece's entities before they are sorted, in file units.
struct Source {
    block: String,
    shapes: Vec<(String, Shape)>,
}

/// Reads a pattern file's bytes (from `source`, named in messages) into its pieces.
pub fn read(bytes: &[u8], source: &str, options: &ReadOptions) -> Result<DxfPattern, GarmentError> {
    let bad = |m: String| GarmentError::new(format!("{source}: {m}"));
    if bytes.starts_with(BINARY_SENTINEL) || bytes.starts_with(b"AutoCAD DXB") {
        return Err(bad("a binary DXF file, which Rosette does not read; export the pattern from the CAD as ASCII DXF (AAMA or ASTM, R12)".into()));
    }
    if let Some(g) = options.grain_deg
        && !(g.is_finite() && g.abs() <= 360.0)
    {
        return Err(bad(format!("--grain-deg {g}: give an angle in degrees between -360 and 360")));
    }
    let drawing = load(bytes).map_err(|e| bad(format!("not a DXF file Rosette can read ({e}); a pattern is ASCII DXF, AAMA or ASTM, R12 or later")))?;
    let mut notes = Vec::new();
    let style_text: Vec<(String, String)> = drawing
        .entities()
        .filter_map(|e| match &e.specific {
            EntityType::Text(t) => keyword(&t.value),
            _ => None,
        })
        .collect();
    let style = style_text.iter().find(|(k, _)| k == "style name").map(|(_, v)| v.clone());
    let units = units(&drawing, &style_text, options, &mut notes).map_err(bad)?;
    let sources = sources(&drawing).map_err(bad)?;
    if sources.is_empty() {
        return Err(bad("no pattern piece: no block holds a cut line on layer 1 (is it a pattern exported as AAMA or ASTM DXF?)".into()));
    }
    if sources.len() > MAX_PIECES {
        return Err(bad(format!("{} pieces, more than the {MAX_PIECES} a pattern has; export the pieces of one garment", sources.len())));
    }
    let mut pieces: Vec<Piece> = Vec::with_capacity(sources.len());
    for source in &sources {
        let piece = piece(source, units.mm(), options, &mut notes).map_err(bad)?;
        if let Some(other) = pieces.iter().find(|p| p.name.eq_ignore_ascii_case(&piece.name)) {
            return Err(bad(format!(
                "two pieces are named '{}' (blocks '{}' and '{}'); give each piece its own name in the CAD (its `Piece Name:` text or its block's name)",
                piece.name, other.block, piece.block
            )));
        }
        pieces.push(piece);
    }
    let largest = pieces.iter().map(|p| (p, extent(&p.outline))).max_by(|a, b| a.1.max_element().total_cmp(&b.1.max_element())).expect("a piece");
    if largest.1.max_element() < MIN_LARGEST_PIECE {
        return Err(bad(format!(
            "the largest piece, '{}', is only {:.1} mm across, read in {}: the file is drawn in larger units than that; give --units (in or cm)",
            largest.0.name,
            largest.1.max_element(),
            units.name()
        )));
    }
    Ok(DxfPattern { pieces, units, style, notes })
}

/// The `dxf` crate's reading of `bytes`. A panic in the crate on a malformed file is
/// caught and reported as the file's fault, never passed on.
fn load(bytes: &[u8]) -> Result<Drawing, String> {
    match std::panic::catch_unwind(|| Drawing::load(&mut &bytes[..])) {
        Ok(Ok(drawing)) => Ok(drawing),
        Ok(Err(e)) => Err(e.to_string()),
        Err(_) => Err("the DXF reader failed on its contents".into()),
    }
}

/// `Keyword: value` of an AAMA / ASTM text, the keyword in lower case.
fn keyword(text: &str) -> Option<(String, String)> {
    let (key, value) = text.split_once(':')?;
    Some((key.trim().to_ascii_lowercase(), value.trim().to_string()))
}

/// The unit the file is read in: the option, else its `Units:` text, else its header's
/// `$INSUNITS` (R2000 and later), else millimetres with a note.
fn units(drawing: &Drawing, style_text: &[(String, String)], options: &ReadOptions, notes: &mut Vec<String>) -> Result<LengthUnit, String> {
    if let Some(u) = options.units {
        return Ok(u);
    }
    if let Some((_, value)) = style_text.iter().find(|(k, _)| k == "units") {
        return match value.to_ascii_uppercase().as_str() {
            "METRIC" | "MM" | "MILLIMETERS" | "MILLIMETRES" => Ok(LengthUnit::Mm),
            "ENGLISH" | "IN" | "INCH" | "INCHES" => Ok(LengthUnit::In),
            "CM" | "CENTIMETERS" | "CENTIMETRES" => Ok(LengthUnit::Cm),
            other => Err(format!("its text `Units: {other}` names no unit Rosette knows (METRIC or ENGLISH); give --units (mm, cm or in)")),
        };
    }
    use dxf::enums::Units;
    match drawing.header.default_drawing_units {
        Units::Millimeters => Ok(LengthUnit::Mm),
        Units::Centimeters => Ok(LengthUnit::Cm),
        Units::Inches => Ok(LengthUnit::In),
        Units::Unitless => {
            notes.push("the file names no unit (no `Units:` text, no $INSUNITS): read in millimetres, as AAMA / ASTM METRIC files are; give --units in for inches".into());
            Ok(LengthUnit::Mm)
        }
        other => Err(format!("its header's $INSUNITS is {other:?}, not a pattern unit; give --units (mm, cm or in)")),
    }
}

/// The pieces' sources: each INSERT of a block in the drawing's entities; without any,
/// each block (other than the model and paper spaces) that holds a cut line.
fn sources(drawing: &Drawing) -> Result<Vec<Source>, String> {
    let blocks: Vec<&dxf::Block> = drawing.blocks().filter(|b| !b.name.starts_with('$') && !b.name.starts_with('*')).collect();
    let mut sources = Vec::new();
    for entity in drawing.entities() {
        let EntityType::Insert(insert) = &entity.specific else { continue };
        let Some(block) = blocks.iter().find(|b| b.name == insert.name) else { continue };
        let values = [insert.location.x, insert.location.y, insert.x_scale_factor, insert.y_scale_factor, insert.rotation];
        if values.iter().any(|v| !v.is_finite()) || insert.x_scale_factor == 0.0 || insert.y_scale_factor == 0.0 {
            return Err(format!("the reference (INSERT) to block '{}' has a place, scale or rotation that is not a finite, non-zero number", insert.name));
        }
        let transform = Transform {
            base: DVec2::new(block.base_point.x, block.base_point.y),
            scale: DVec2::new(insert.x_scale_factor, insert.y_scale_factor),
            rotation: insert.rotation.to_radians(),
            location: DVec2::new(insert.location.x, insert.location.y),
        };
        sources.push(source(block, transform)?);
    }
    if sources.is_empty() {
        for block in blocks {
            if block.entities.iter().any(|e| e.common.layer == "1" && matches!(e.specific, EntityType::Polyline(_) | EntityType::LwPolyline(_) | EntityType::Line(_))) {
                sources.push(source(block, Transform::IDENTITY)?);
            }
        }
    }
    Ok(sources)
}

fn source(block: &dxf::Block, transform: Transform) -> Result<Source, String> {
    let count: usize = block
        .entities
        .iter()
        .map(|e| match &e.specific {
            EntityType::Polyline(p) => 1 + p.vertices().count(),
            _ => 1,
        })
        .sum();
    if count > MAX_PIECE_ENTITIES + MAX_OUTLINE_POINTS {
        return Err(format!(
            "piece '{}' holds {count} entities and points, more than a pattern piece has (at most {MAX_PIECE_ENTITIES} entities and {MAX_OUTLINE_POINTS} outline points); is the block a marker, a nest or a drawing? Export the pattern's pieces alone",
            block.name
        ));
    }
    if block.entities.len() > MAX_PIECE_ENTITIES {
        return Err(format!(
            "piece '{}' holds {} entities, more than the {MAX_PIECE_ENTITIES} a pattern piece has; is the block a marker, a nest or a drawing? Export the pattern's pieces alone",
            block.name,
            block.entities.len()
        ));
    }
    let shapes = block.entities.iter().map(|e| (e.common.layer.trim().to_string(), shape(e, &transform))).collect();
    Ok(Source { block: block.name.clone(), shapes })
}

/// An entity as a shape in the drawing's frame (file units).
fn shape(entity: &Entity, t: &Transform) -> Shape {
    let p2 = |p: &dxf::Point| DVec2::new(p.x, p.y);
    match &entity.specific {
        EntityType::Line(l) => Shape::Path { points: vec![t.point(p2(&l.p1)), t.point(p2(&l.p2))], closed: false },
        EntityType::Polyline(p) => {
            // Polyface and polygon meshes (flags 16 and 64) are not outlines.
            if p.flags & (16 | 64) != 0 {
                return Shape::Other;
            }
            let vertices: Vec<(DVec2, f64)> = p.vertices().map(|v| (p2(&v.location), v.bulge)).collect();
            let closed = p.is_closed();
            Shape::Path { points: flatten(&vertices, closed).into_iter().map(|q| t.point(q)).collect(), closed }
        }
        EntityType::LwPolyline(p) => {
            let vertices: Vec<(DVec2, f64)> = p.vertices.iter().map(|v| (DVec2::new(v.x, v.y), v.bulge)).collect();
            let closed = p.is_closed();
            Shape::Path { points: flatten(&vertices, closed).into_iter().map(|q| t.point(q)).collect(), closed }
        }
        EntityType::Arc(a) => {
            let (start, end) = (a.start_angle.to_radians(), a.end_angle.to_radians());
            let sweep = (end - start).rem_euclid(std::f64::consts::TAU);
            let sweep = if sweep == 0.0 { std::f64::consts::TAU } else { sweep };
            let n = arc_segments(sweep);
            let centre = p2(&a.center);
            let points = (0..=n).map(|i| t.point(centre + a.radius * DVec2::from_angle(start + sweep * i as f64 / n as f64))).collect();
            Shape::Path { points, closed: false }
        }
        EntityType::Circle(c) => {
            let n = arc_segments(std::f64::consts::TAU);
            let centre = p2(&c.center);
            let points = (0..n).map(|i| t.point(centre + c.radius * DVec2::from_angle(std::f64::consts::TAU * i as f64 / n as f64))).collect();
            Shape::Path { points, closed: true }
        }
        EntityType::ModelPoint(p) => Shape::Point {
            at: t.point(p2(&p.location)),
            depth: p.location.z.abs() * t.length(),
            width: p.thickness.abs() * t.length(),
            direction: t.direction(DVec2::from_angle(p.angle.to_radians())),
        },
        EntityType::Text(text) => Shape::Text(text.value.clone()),
        EntityType::Insert(i) => Shape::Insert(i.name.clone()),
        _ => Shape::Other,
    }
}

/// Segments for an arc of `sweep` radians: one per 5 degrees.
fn arc_segments(sweep: f64) -> usize {
    ((sweep.abs() / 5f64.to_radians()).ceil() as usize).clamp(1, 72)
}

/// A polyline's points with its bulges (arcs between vertices: the bulge is the tangent of
/// a quarter of the arc's angle) flattened into segments.
fn flatten(vertices: &[(DVec2, f64)], closed: bool) -> Vec<DVec2> {
    let mut points = Vec::with_capacity(vertices.len());
    let n = vertices.len();
    for i in 0..n {
        let (p, bulge) = vertices[i];
        points.push(p);
        let next = if i + 1 < n { Some(vertices[i + 1].0) } else if closed { Some(vertices[0].0) } else { None };
        let Some(q) = next else { continue };
        if !(bulge.is_finite() && bulge.abs() > 1e-9) || p.distance(q) == 0.0 {
            continue;
        }
        let angle = 4.0 * bulge.atan();
        let chord = q - p;
        let radius = chord.length() / (2.0 * (angle / 2.0).sin());
        // The centre lies on the chord's perpendicular bisector, on the left for a positive
        // (counter-clockwise) bulge.
        let middle = p + 0.5 * chord;
        let offset = radius * (angle / 2.0).cos();
        let centre = middle + chord.perp().normalize() * offset;
        let start = (p - centre).to_angle();
        let segments = arc_segments(angle);
        for k in 1..segments {
            points.push(centre + radius.abs() * DVec2::from_angle(start + angle * k as f64 / segments as f64));
        }
    }
    points
}

/// The twice-signed area of a closed outline (positive: counter-clockwise).
fn signed_area(points: &[DVec2]) -> f64 {
    (0..points.len()).map(|i| points[i].perp_dot(points[(i + 1) % points.len()])).sum::<f64>() * 0.5
}

/// The outline's bounding box's width and height.
fn extent(points: &[DVec2]) -> DVec2 {
    let (lo, hi) = points.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).max(DVec2::ZERO)
}

/// A closed outline from a path: consecutive points closer than a micrometre merged, the
/// closing point not repeated, counter-clockwise.
fn tidy(points: &[DVec2]) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(points.len());
    for &p in points {
        if out.last().is_none_or(|q| q.distance(p) > 1e-3) {
            out.push(p);
        }
    }
    while out.len() > 1 && out[0].distance(*out.last().unwrap()) <= JOIN {
        out.pop();
    }
    if signed_area(&out) < 0.0 {
        out.reverse();
    }
    out
}

/// One closed line from a layer's paths (mm): its largest closed path, else its open paths
/// chained end to end. `Err` gives where an open chain ends and starts.
fn closed_line(paths: &[(&Vec<DVec2>, bool)]) -> Option<Result<Vec<DVec2>, (DVec2, DVec2)>> {
    let closed = paths
        .iter()
        .filter(|(points, closed)| points.len() >= 3 && (*closed || points[0].distance(*points.last().unwrap()) <= JOIN))
        .map(|(points, _)| tidy(points))
        .max_by(|a, b| signed_area(a).abs().total_cmp(&signed_area(b).abs()));
    if let Some(line) = closed {
        return Some(Ok(line));
    }
    let mut open: Vec<Vec<DVec2>> = paths.iter().filter(|(p, _)| p.len() >= 2).map(|(p, _)| p.to_vec()).collect();
    if open.is_empty() {
        return None;
    }
    // The longest path starts the chain; the path whose end meets the chain's end is added
    // (turned round where needed) until the chain closes or nothing meets it.
    let longest = (0..open.len()).max_by(|&a, &b| open[a].len().cmp(&open[b].len())).expect("a path");
    let mut chain = open.swap_remove(longest);
    loop {
        let (start, end) = (chain[0], *chain.last().unwrap());
        if chain.len() > 2 && start.distance(end) <= JOIN {
            return Some(Ok(tidy(&chain)));
        }
        let next = open.iter().position(|p| p[0].distance(end) <= JOIN || p.last().unwrap().distance(end) <= JOIN);
        let Some(i) = next else { return Some(Err((end, start))) };
        let mut path = open.swap_remove(i);
        if path[0].distance(end) > JOIN {
            path.reverse();
        }
        chain.extend(path.into_iter().skip(1));
    }
}

/// Whether `p` lies inside the closed outline (or within `slack` of it).
fn inside(points: &[DVec2], p: DVec2, slack: f64) -> bool {
    let mut crossings = false;
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            crossings = !crossings;
        }
    }
    crossings || nearest(points, p).1 <= slack
}

/// The nearest point of the closed outline to `p`: its distance along the outline from the
/// first point, and its distance from `p`.
fn nearest(points: &[DVec2], p: DVec2) -> (f64, f64) {
    let (mut best, mut along, mut arc) = (f64::INFINITY, 0.0, 0.0);
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
        let d = p.distance(a + t * ab);
        if d < best {
            best = d;
            along = arc + t * ab.length();
        }
        arc += ab.length();
    }
    (along, best)
}

/// Where the ray from `p` along `direction` first meets the closed outline within `reach`:
/// its distance along the outline from the first point.
fn ray_hit(points: &[DVec2], p: DVec2, direction: DVec2, reach: f64) -> Option<f64> {
    let (mut best, mut along, mut arc) = (reach, None, 0.0);
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        let ab = b - a;
        let denominator = direction.perp_dot(ab);
        if denominator.abs() > 1e-12 {
            let t = (a - p).perp_dot(ab) / denominator;
            let u = (a - p).perp_dot(direction) / denominator;
            if (0.0..=1.0).contains(&u) && t >= -1e-9 && t <= best {
                best = t;
                along = Some(arc + u * ab.length());
            }
        }
        arc += ab.length();
    }
    along
}

/// The perimeter of a closed outline.
fn perimeter(points: &[DVec2]) -> f64 {
    (0..points.len()).map(|i| points[i].distance(points[(i + 1) % points.len()])).sum()
}

/// The seam allowance between a sew line and its cut line: least, mean and most.
fn allowance_between(sew_line: &[DVec2], cut_line: &[DVec2]) -> [f64; 3] {
    let distances: Vec<f64> = sew_line.iter().map(|&q| nearest(cut_line, q).1).collect();
    let mean = distances.iter().sum::<f64>() / distances.len() as f64;
    [distances.iter().copied().fold(f64::INFINITY, f64::min), mean, distances.iter().copied().fold(0.0, f64::max)]
}

/// Sorts one piece's shapes by layer into a [`Piece`] in millimetres (`mm` per file unit).
fn piece(source: &Source, mm: f64, options: &ReadOptions, notes: &mut Vec<String>) -> Result<Piece, String> {
    let block = &source.block;
    let mut texts: Vec<(String, String)> = Vec::new();
    let mut paths: Vec<(&str, Vec<DVec2>, bool)> = Vec::new();
    let mut points: Vec<(&str, DVec2, f64, f64, DVec2)> = Vec::new();
    for (layer, shape) in &source.shapes {
        match shape {
            Shape::Path { points: p, closed } => {
                if p.iter().any(|q| !q.is_finite()) {
                    return Err(format!("piece '{block}': a line on layer {layer} has a point that is not a finite number; fix it in the CAD"));
                }
                paths.push((layer, p.iter().map(|&q| q * mm).collect(), *closed));
            }
            Shape::Point { at, depth, width, direction } => {
                if !at.is_finite() {
                    return Err(format!("piece '{block}': a point on layer {layer} is not at a finite position; fix it in the CAD"));
                }
                points.push((layer, *at * mm, depth * mm, width * mm, *direction));
            }
            Shape::Text(t) if layer == "1" => texts.extend(keyword(t)),
            Shape::Insert(name) => {
                return Err(format!("piece '{block}' holds a reference to block '{name}', which Rosette does not read inside a piece; explode the reference in the CAD"));
            }
            _ => {}
        }
    }
    let text = |key: &str| texts.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone()).filter(|v| !v.is_empty());
    let name = text("piece name").unwrap_or_else(|| block.clone());
    let at = |m: String| format!("piece '{name}': {m}");
    if paths.iter().any(|(layer, _, _)| *layer == "6") {
        return Err(at("it is drawn as half of itself, with a fold (mirror) line on layer 6, which Rosette does not unfold; export the piece unfolded".into()));
    }
    let quantity = match text("quantity") {
        None => 1,
        Some(q) => q.parse::<u32>().ok().filter(|q| (1..=100).contains(q)).ok_or_else(|| at(format!("its text `Quantity: {q}` must be a whole number of pieces to cut, 1 to 100")))?,
    };
    let layer = |name: &str| -> Vec<(&Vec<DVec2>, bool)> { paths.iter().filter(|(l, _, _)| *l == name).map(|(_, p, c)| (p, *c)).collect() };
    let cut_paths = layer("1");
    let cut_line = match closed_line(&cut_paths) {
        None => return Err(at("no cut line: layer 1 holds no polyline or lines around the piece; draw its outline on layer 1".into())),
        Some(Err((end, start))) => {
            return Err(at(format!(
                "its cut line (layer 1) does not close: it ends at ({:.1}, {:.1}) mm, {:.1} mm from where it starts at ({:.1}, {:.1}) mm; close the outline in the CAD and export it again",
                end.x,
                end.y,
                end.distance(start),
                start.x,
                start.y
            )));
        }
        Some(Ok(line)) => line,
    };
    check_outline(&cut_line, "cut line (layer 1)").map_err(at)?;
    let eight = layer("8");
    let (sew_line, sew_from_eight) = sew_line(&cut_line, &layer("14"), &eight).map_err(at)?;
    let internal_lines = layer("11").len() + eight.len() - usize::from(sew_from_eight);
    if let Some(line) = &sew_line {
        check_outline(line, "sew line").map_err(at)?;
        if let Some(p) = line.iter().find(|&&q| !inside(&cut_line, q, 0.5)) {
            return Err(at(format!(
                "its sew line passes outside its cut line (layer 1), at ({:.1}, {:.1}) mm; the sew line lies inside the cut line, the seam allowance between them: fix the layers in the CAD",
                p.x, p.y
            )));
        }
    }
    let outline = sew_line.clone().unwrap_or_else(|| cut_line.clone());
    let size = extent(&outline);
    if size.max_element() > MAX_PIECE_SIZE {
        return Err(at(format!(
            "it is {:.0} × {:.0} mm, larger than any pattern piece (at most {MAX_PIECE_SIZE:.0} mm across): is the file drawn in other units than it was read in ({:.4} mm a unit)? Give --units (mm, cm or in)",
            size.x, size.y, mm
        )));
    }
    let seam_allowance = sew_line.as_deref().map(|line| allowance_between(line, &cut_line));
    let grain = layer("7")
        .into_iter()
        .filter(|(p, _)| p.len() >= 2)
        .map(|(p, _)| *p.last().unwrap() - p[0])
        .filter(|d| d.length() > 0.0)
        .max_by(|a, b| a.length().total_cmp(&b.length()));
    let (grain_deg, grain_given) = match (grain, options.grain_deg) {
        (Some(d), _) => (d.y.atan2(d.x).to_degrees().rem_euclid(180.0), true),
        (None, Some(g)) => (g.rem_euclid(180.0), false),
        (None, None) => {
            return Err(at(
                "it has no grain line (a LINE on layer 7); draw the grain line in the CAD, or give --grain-deg D to cut pieces without one with the warp at D degrees from their x axis (90: up and down the piece)"
                    .into(),
            ));
        }
    };
    let allowance = seam_allowance.map_or(0.0, |a| a[2]);
    let notches = notches(&points, &layer("4"), &cut_line, &outline, sew_line.is_some(), allowance, &name, notes);
    let drill_holes: Vec<DVec2> = points
        .iter()
        .filter(|(l, ..)| *l == "13")
        .map(|(_, p, ..)| *p)
        .chain(layer("13").iter().filter(|(p, c)| *c && p.len() >= 3).map(|(p, _)| p.iter().copied().sum::<DVec2>() / p.len() as f64))
        .collect();
    if sew_line.is_none() {
        notes.push(format!("piece '{name}': no sew line (layer 14): its cut line is sewn as the seam line"));
    }
    Ok(Piece {
        name,
        block: block.clone(),
        quantity,
        size: text("size"),
        outline,
        sew_line: sew_line.is_some(),
        cut_line,
        seam_allowance,
        grain_deg,
        grain_given,
        notches,
        drill_holes,
        internal_lines,
    })
}

/// A piece's sew line: a closed line on layer 14, else (older AAMA files) a closed layer-8
/// line inside the cut line that encloses most of it, said by the flag; None without one.
fn sew_line(cut_line: &[DVec2], fourteen: &[(&Vec<DVec2>, bool)], eight: &[(&Vec<DVec2>, bool)]) -> Result<(Option<Vec<DVec2>>, bool), String> {
    let cut_area = signed_area(cut_line);
    match closed_line(fourteen) {
        Some(Ok(line)) => Ok((Some(line), false)),
        Some(Err((end, start))) => Err(format!(
            "its sew line (layer 14) does not close: it ends {:.1} mm from where it starts at ({:.1}, {:.1}) mm; close it in the CAD and export it again",
            end.distance(start),
            start.x,
            start.y
        )),
        None => {
            let candidate = eight
                .iter()
                .filter(|(p, c)| p.len() >= 3 && (*c || p[0].distance(*p.last().unwrap()) <= JOIN))
                .map(|(p, _)| tidy(p))
                .filter(|p| signed_area(p) > 0.5 * cut_area && p.iter().all(|&q| inside(cut_line, q, 0.5)))
                .max_by(|a, b| signed_area(a).total_cmp(&signed_area(b)));
            let from_eight = candidate.is_some();
            Ok((candidate, from_eight))
        }
    }
}

/// Refuses an outline with too many points or no area.
fn check_outline(line: &[DVec2], what: &str) -> Result<(), String> {
    if line.len() > MAX_OUTLINE_POINTS {
        return Err(format!(
            "its {what} has {} points, more than the {MAX_OUTLINE_POINTS} a pattern piece's outline has; export it with a coarser curve tolerance",
            line.len()
        ));
    }
    if line.len() < 3 || signed_area(line).abs() < 1.0 {
        return Err(format!("its {what} encloses no area; draw the piece's outline as a closed polyline"));
    }
    Ok(())
}

/// The piece's notches on its outline: ASTM POINTs (layers 4 and 80 to 83) and AAMA short
/// LINEs from the cut line inwards (layer 4), each moved inwards along its direction onto
/// the sew line where the outline is one (the cut line carries the notches).
#[allow(clippy::too_many_arguments)]
fn notches(
    points: &[(&str, DVec2, f64, f64, DVec2)],
    lines: &[(&Vec<DVec2>, bool)],
    cut_line: &[DVec2],
    outline: &[DVec2],
    sew_line: bool,
    allowance: f64,
    name: &str,
    notes: &mut Vec<String>,
) -> Vec<Notch> {
    // Each mark: its base on the cut line, its direction into the piece, depth and shape.
    let mut marks: Vec<(DVec2, DVec2, f64, NotchShape)> = Vec::new();
    for &(layer, at, depth, width, direction) in points {
        let shape = match layer {
            "4" if width > 0.0 => NotchShape::V,
            "4" => NotchShape::Slit,
            "80" => NotchShape::T,
            "81" => NotchShape::Castle,
            "82" => NotchShape::Check,
            "83" => NotchShape::U,
            _ => continue,
        };
        marks.push((at, direction, depth, shape));
    }
    // AAMA notches: lines with an end on the cut line; lines within 3 mm of each other's
    // bases are one notch (a V is two lines, a double slit two parallel ones).
    let mut groups: Vec<(Vec<DVec2>, Vec<DVec2>, f64)> = Vec::new();
    for (path, _) in lines {
        let (a, b) = (path[0], *path.last().unwrap());
        let (da, db) = (nearest(cut_line, a).1, nearest(cut_line, b).1);
        let (base, tip) = if da <= db { (a, b) } else { (b, a) };
        if da.min(db) > 1.0 || base.distance(tip) == 0.0 {
            continue;
        }
        match groups.iter_mut().find(|(bases, ..)| bases.iter().any(|q| q.distance(base) <= 3.0)) {
            Some((bases, directions, depth)) => {
                bases.push(base);
                directions.push((tip - base).normalize());
                *depth = depth.max(base.distance(tip));
            }
            None => groups.push((vec![base], vec![(tip - base).normalize()], base.distance(tip))),
        }
    }
    for (bases, directions, depth) in groups {
        let base = bases.iter().copied().sum::<DVec2>() / bases.len() as f64;
        let direction = directions.iter().copied().sum::<DVec2>().normalize_or_zero();
        let shape = if directions.len() == 2 && directions[0].dot(directions[1]) < 0.999 { NotchShape::V } else { NotchShape::Slit };
        marks.push((base, direction, depth, shape));
    }
    let length = perimeter(outline);
    let mut notches: Vec<Notch> = Vec::new();
    let mut lost = 0;
    for (base, direction, depth, shape) in marks {
        let at = if sew_line {
            let reach = 3.0 * allowance + 5.0;
            let hit = if direction != DVec2::ZERO { ray_hit(outline, base, direction, reach) } else { None };
            hit.or_else(|| {
                let (along, distance) = nearest(outline, base);
                (distance <= allowance + 2.0).then_some(along)
            })
        } else {
            let (along, distance) = nearest(outline, base);
            (distance <= 2.0).then_some(along)
        };
        match at {
            Some(at) if !notches.iter().any(|n| (n.at - at).abs().min(length - (n.at - at).abs()) < 1.0) => notches.push(Notch { at, shape, depth }),
            Some(_) => {}
            None => lost += 1,
        }
    }
    if lost > 0 {
        notes.push(format!("piece '{name}': {lost} notch(es) lie off its outline and were left out"));
    }
    notches.sort_by(|a, b| a.at.total_cmp(&b.at));
    notches
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bulge_of_one_is_a_half_circle() {
        // From (1, 0) to (-1, 0) with bulge 1: counter-clockwise through (0, 1).
        let points = flatten(&[(DVec2::new(1.0, 0.0), 1.0), (DVec2::new(-1.0, 0.0), 0.0)], false);
        assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-12), "{points:?}");
        assert!(points.iter().any(|p| p.y > 0.99));
        assert_eq!(points.last(), Some(&DVec2::new(-1.0, 0.0)));
    }

    #[test]
    fn open_lines_chain_into_a_closed_outline_or_say_where_they_break() {
        let square = [DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0), DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0)];
        let segments: Vec<Vec<DVec2>> = (0..4).map(|i| vec![square[i], square[(i + 1) % 4]]).collect();
        // One segment turned round: chaining takes it either way.
        let mut turned = segments.clone();
        turned[2].reverse();
        let paths: Vec<(&Vec<DVec2>, bool)> = turned.iter().map(|p| (p, false)).collect();
        let line = closed_line(&paths).unwrap().unwrap();
        assert_eq!(line.len(), 4);
        assert!((signed_area(&line) - 100.0).abs() < 1e-9);
        let broken: Vec<(&Vec<DVec2>, bool)> = segments[..3].iter().map(|p| (p, false)).collect();
        let (end, start) = closed_line(&broken).unwrap().unwrap_err();
        assert!((end.distance(start) - 10.0).abs() < 1e-9, "{end} {start}");
    }

    #[test]
    fn a_notch_goes_inwards_onto_the_sew_line() {
        let cut = vec![DVec2::new(0.0, 0.0), DVec2::new(100.0, 0.0), DVec2::new(100.0, 100.0), DVec2::new(0.0, 100.0)];
        let sew = vec![DVec2::new(10.0, 10.0), DVec2::new(90.0, 10.0), DVec2::new(90.0, 90.0), DVec2::new(10.0, 90.0)];
        // A slit on the right edge, 40 mm up, pointing in (-x).
        let points = [("4", DVec2::new(100.0, 40.0), 5.0, 0.0, DVec2::new(-1.0, 0.0))];
        let mut notes = Vec::new();
        let found = notches(&points, &[], &cut, &sew, true, 10.0, "p", &mut notes);
        // Along the sew line from (10, 10): 80 along the bottom, then 30 up the right side.
        assert_eq!(found.len(), 1);
        assert!((found[0].at - 110.0).abs() < 1e-9, "{found:?}");
        assert_eq!(found[0].shape, NotchShape::Slit);
        // The same notch as an AAMA line from the cut line inwards.
        let line = vec![DVec2::new(100.0, 40.0), DVec2::new(95.0, 40.0)];
        let found = notches(&[], &[(&line, false)], &cut, &sew, true, 10.0, "p", &mut notes);
        assert!((found[0].at - 110.0).abs() < 1e-9 && (found[0].depth - 5.0).abs() < 1e-12, "{found:?}");
        assert!(notes.is_empty(), "{notes:?}");
    }
}
