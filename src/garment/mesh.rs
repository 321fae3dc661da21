//! Meshing a panel: its outline resampled at the points the seams agree on, then a
//! constrained Delaunay triangulation refined to the target edge length (spade).

use super::GarmentError;
use glam::DVec2;
use spade::{AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};

/// A meshed panel in its own plane, metres.
#[derive(Debug, Clone)]
pub struct PanelMesh {
    /// Vertex positions; the outline's vertices come first, in order around it.
    pub points: Vec<DVec2>,
    /// Counter-clockwise triangles.
    pub triangles: Vec<[u32; 3]>,
    /// For each edge of the outline, its vertices from its start to its end (the end is
    /// the next edge's first vertex).
    pub edge_vertices: Vec<Vec<u32>>,
}

/// Points along one edge: the arc lengths (m) where the outline is cut into vertices,
/// from 0 to the edge's length.
pub type Cuts = Vec<f64>;

/// Meshes a panel whose edges are `curves`, cut at `cuts` (one list per edge), with
/// interior triangles of about `edge_length` (m).
pub fn mesh_panel(name: &str, curves: &[super::pattern::Polyline], cuts: &[Cuts], edge_length: f64) -> Result<PanelMesh, GarmentError> {
    let mut outline: Vec<DVec2> = Vec::new();
    let mut edge_vertices = Vec::with_capacity(curves.len());
    for (curve, cut) in curves.iter().zip(cuts) {
        let first = outline.len() as u32;
        // The edge's last point is the next edge's first.
        outline.extend(cut[..cut.len() - 1].iter().map(|&s| curve.at(s)));
        edge_vertices.push((first..first + cut.len() as u32).collect::<Vec<u32>>());
    }
    let count = outline.len() as u32;
    if let Some(last) = edge_vertices.last_mut() {
        *last.last_mut().expect("an edge has two ends") = 0;
    }
    for e in &mut edge_vertices {
        for v in e.iter_mut() {
            *v %= count;
        }
    }
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> = ConstrainedDelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(outline.len());
    for p in &outline {
        let handle = cdt.insert(Point2::new(p.x, p.y)).map_err(|e| GarmentError::new(format!("garment.panels '{name}': cannot mesh the outline ({e:?})")))?;
        handles.push(handle);
    }
    if handles.iter().enumerate().any(|(i, h)| h.index() != i) {
        return Err(GarmentError::new(format!("garment.panels '{name}': two outline points coincide; use a larger mesh.edge_length or fix the outline")));
    }
    for i in 0..handles.len() {
        let (a, b) = (handles[i], handles[(i + 1) % handles.len()]);
        if !cdt.can_add_constraint(a, b) {
            return Err(GarmentError::new(format!("garment.panels '{name}': the outline comes closer to itself than the mesh can resolve; use a smaller mesh.edge_length")));
        }
        cdt.add_constraint(a, b);
    }
    // Triangles of the target edge are (√3/4) h² in area; refinement splits every triangle
    // larger than twice that, which leaves a mean edge close to h.
    let max_area = 0.866 * edge_length * edge_length;
    let limit = (4.0 * outline.len() as f64).max(outline_area(&outline) / (0.1 * max_area)) as usize;
    let parameters = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(25.0))
        .with_max_allowed_area(max_area)
        .with_max_additional_vertices(limit);
    let result = cdt.refine(parameters);
    if !result.refinement_complete {
        return Err(GarmentError::new(format!("garment.panels '{name}': the mesh refinement did not finish; use a larger mesh.edge_length")));
    }
    let outer: std::collections::HashSet<_> = result.excluded_faces.iter().copied().collect();
    let points: Vec<DVec2> = cdt.vertices().map(|v| DVec2::new(v.position().x, v.position().y)).collect();
    let triangles: Vec<[u32; 3]> = cdt
        .inner_faces()
        .filter(|f| !outer.contains(&f.fix()))
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    if points.len() < outline.len() || points[..outline.len()].iter().zip(&outline).any(|(a, b)| a != b) {
        return Err(GarmentError::new(format!("garment.panels '{name}': meshing moved the outline's points; use a smaller mesh.edge_length")));
    }
    Ok(PanelMesh { points, triangles, edge_vertices })
}

fn outline_area(points: &[DVec2]) -> f64 {
    (0..points.len()).map(|i| 0.5 * points[i].perp_dot(points[(i + 1) % points.len()])).sum::<f64>().abs()
}

/// Cuts for a stretch of `length` (m) into `count` equal parts, offset by `start`.
pub fn even_cuts(start: f64, length: f64, count: usize) -> Vec<f64> {
    (0..=count).map(|i| start + length * i as f64 / count as f64).collect()
}
