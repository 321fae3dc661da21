//! Flat triangle meshes of the cloth's rest shape: rectangles (four triangulations) and discs.
//!
//! Coordinates are in the *sample frame*, metres: for a rectangle `x ∈ [0, length]` along
//! the sample's length and `y ∈ [0, width]`; for a disc the centre is the origin. The warp
//! direction is given separately (see `Model`), so the same mesh can be cut at any angle.

use glam::DVec2;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A flat triangle mesh: rest positions and counter-clockwise triangles.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// Rest positions in the sample plane, m.
    pub rest: Vec<DVec2>,
    /// Vertex indices of each triangle, counter-clockwise in the rest plane.
    pub triangles: Vec<[u32; 3]>,
}

/// How a rectangle is cut into triangles. Several are offered so that tests can show the
/// physics does not depend on the triangulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Pattern {
    /// Square cells, every cell cut along the same diagonal.
    Regular,
    /// Square cells, diagonals alternating in a checkerboard ("union jack").
    #[default]
    Alternating,
    /// Rows of near-equilateral triangles, alternate rows shifted by half an edge.
    Equilateral,
    /// The alternating grid with interior vertices moved randomly by up to 20 % of an edge:
    /// an irregular triangulation.
    Jittered,
}

/// Why a mesh cannot be built or used.
#[derive(Debug, Error, PartialEq)]
pub enum MeshError {
    #[error("{what} must be a positive, finite length in metres, got {value}")]
    BadSize { what: &'static str, value: f64 },
    #[error(
        "edge length {edge_length} m gives {count} vertices, more than the limit of {limit}; \
         use a larger mesh.edge_length"
    )]
    TooManyVertices { edge_length: f64, count: usize, limit: usize },
    #[error(
        "triangle {triangle} is degenerate (area {area:.3e} m², its vertices are nearly collinear); \
         remove it or fix its vertices"
    )]
    Degenerate { triangle: usize, area: f64 },
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has only {vertex_count} vertices")]
    BadIndex { triangle: usize, vertex: u32, vertex_count: usize },
    #[error("triangle {triangle} is clockwise in the rest plane; list its vertices counter-clockwise")]
    Clockwise { triangle: usize },
    #[error("edge {a}–{b} is shared by more than two triangles; cloth must be a manifold surface")]
    NonManifold { a: u32, b: u32 },
}

/// Upper bound on generated vertex counts, so a typo in `mesh.edge_length` fails fast
/// instead of exhausting memory.
pub const MAX_VERTICES: usize = 2_000_000;

fn check_size(what: &'static str, value: f64) -> Result<(), MeshError> {
    if value.is_finite() && value > 0.0 { Ok(()) } else { Err(MeshError::BadSize { what, value }) }
}

fn check_count(edge_length: f64, count: usize) -> Result<(), MeshError> {
    if count > MAX_VERTICES {
        return Err(MeshError::TooManyVertices { edge_length, count, limit: MAX_VERTICES });
    }
    Ok(())
}

/// The vertex count each generator checks against [`MAX_VERTICES`] before it builds: a
/// `length × width` rectangle with `pattern`, or (`width` = None) a disc of diameter
/// `length`. Lets a scene be checked before its fabric, whose buckling branch divides by
/// the edge length squared.
pub fn planned_vertices(length: f64, width: Option<f64>, edge_length: f64, pattern: Pattern) -> usize {
    let cells = |extent: f64, spacing: f64| ((extent / spacing).round() as usize).max(1);
    match width {
        None => {
            let ring_count = cells(length / 2.0, edge_length);
            (std::f64::consts::PI * (ring_count as f64 + 1.0).powi(2) * 1.2) as usize
        }
        Some(width) if pattern == Pattern::Equilateral => {
            cells(length, edge_length).saturating_add(2).saturating_mul(cells(width, edge_length * 3f64.sqrt() / 2.0).saturating_add(1))
        }
        Some(width) => cells(length, edge_length).saturating_add(1).saturating_mul(cells(width, edge_length).saturating_add(1)),
    }
}

impl Mesh {
    /// A `length × width` rectangle with edges of about `edge_length`.
    pub fn rectangle(length: f64, width: f64, edge_length: f64, pattern: Pattern, seed: u64) -> Result<Self, MeshError> {
        check_size("cloth.length", length)?;
        check_size("cloth.width", width)?;
        check_size("mesh.edge_length", edge_length)?;
        match pattern {
            Pattern::Equilateral => Self::equilateral_rectangle(length, width, edge_length),
            _ => Self::grid_rectangle(length, width, edge_length, pattern, seed),
        }
    }

    fn grid_rectangle(length: f64, width: f64, edge_length: f64, pattern: Pattern, seed: u64) -> Result<Self, MeshError> {
        let nx = ((length / edge_length).round() as usize).max(1);
        let ny = ((width / edge_length).round() as usize).max(1);
        check_count(edge_length, (nx + 1).saturating_mul(ny + 1))?;
        let (dx, dy) = (length / nx as f64, width / ny as f64);
        let index = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut rest = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                rest.push(DVec2::new(i as f64 * dx, j as f64 * dy));
            }
        }
        if pattern == Pattern::Jittered {
            // Interior vertices move freely; boundary vertices slide along their edge only, so
            // the outline stays a rectangle. 20 % of an edge keeps every triangle valid.
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
            for j in 0..=ny {
                for i in 0..=nx {
                    let (on_x_end, on_y_end) = (i == 0 || i == nx, j == 0 || j == ny);
                    let jx = if on_x_end { 0.0 } else { rng.random_range(-0.2..0.2) * dx };
                    let jy = if on_y_end { 0.0 } else { rng.random_range(-0.2..0.2) * dy };
                    rest[index(i, j) as usize] += DVec2::new(jx, jy);
                }
            }
        }
        let mut triangles = Vec::with_capacity(2 * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c, d) = (index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1));
                let flip = matches!(pattern, Pattern::Alternating | Pattern::Jittered) && (i + j) % 2 == 1;
                if flip {
                    triangles.push([a, b, d]);
                    triangles.push([b, c, d]);
                } else {
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        let mesh = Self { rest, triangles };
        mesh.validate()?;
        Ok(mesh)
    }

    fn equilateral_rectangle(length: f64, width: f64, edge_length: f64) -> Result<Self, MeshError> {
        let row_spacing = edge_length * 3f64.sqrt() / 2.0;
        let ny = ((width / row_spacing).round() as usize).max(1);
        let nx = ((length / edge_length).round() as usize).max(1);
        check_count(edge_length, (nx + 2).saturating_mul(ny + 1))?;
        let dx = length / nx as f64;
        let mut rest = Vec::new();
        let mut rows: Vec<Vec<u32>> = Vec::with_capacity(ny + 1);
        for j in 0..=ny {
            let y = width * j as f64 / ny as f64;
            let mut xs: Vec<f64> = if j % 2 == 0 {
                (0..=nx).map(|i| i as f64 * dx).collect()
            } else {
                // Odd rows are shifted by half an edge and closed by vertices on both ends.
                std::iter::once(0.0).chain((0..nx).map(|i| (i as f64 + 0.5) * dx)).chain(std::iter::once(length)).collect()
            };
            xs.dedup();
            let row = xs
                .into_iter()
                .map(|x| {
                    rest.push(DVec2::new(x, y));
                    (rest.len() - 1) as u32
                })
                .collect();
            rows.push(row);
        }
        let mut triangles = Vec::new();
        for pair in rows.windows(2) {
            stitch_rows(&rest, &pair[0], &pair[1], |p| p.x, false, &mut triangles);
        }
        let mesh = Self { rest, triangles };
        mesh.validate()?;
        Ok(mesh)
    }

    /// A disc of the given diameter centred on the origin, in concentric rings about
    /// `edge_length` apart, each ring with vertices about `edge_length` apart.
    pub fn disc(diameter: f64, edge_length: f64) -> Result<Self, MeshError> {
        check_size("cloth.diameter", diameter)?;
        check_size("mesh.edge_length", edge_length)?;
        let radius = diameter / 2.0;
        let ring_count = ((radius / edge_length).round() as usize).max(1);
        let estimate = (std::f64::consts::PI * (ring_count as f64 + 1.0).powi(2) * 1.2) as usize;
        check_count(edge_length, estimate)?;
        let mut rest = vec![DVec2::ZERO];
        let mut rings: Vec<Vec<u32>> = vec![vec![0]];
        for k in 1..=ring_count {
            let r = radius * k as f64 / ring_count as f64;
            let count = ((2.0 * std::f64::consts::PI * r / edge_length).round() as usize).max(6);
            // Alternate rings are rotated by half a step so the rings do not line up radially.
            let phase = if k % 2 == 0 { 0.5 } else { 0.0 };
            let ring = (0..count)
                .map(|i| {
                    let angle = 2.0 * std::f64::consts::PI * (i as f64 + phase) / count as f64;
                    rest.push(r * DVec2::new(angle.cos(), angle.sin()));
                    (rest.len() - 1) as u32
                })
                .collect();
            rings.push(ring);
        }
        let mut triangles = Vec::new();
        let angle = |p: DVec2| p.y.atan2(p.x).rem_euclid(2.0 * std::f64::consts::PI);
        for k in 0..ring_count {
            if k == 0 {
                let ring = &rings[1];
                for i in 0..ring.len() {
                    triangles.push([0, ring[i], ring[(i + 1) % ring.len()]]);
                }
            } else {
                stitch_rows(&rest, &rings[k], &rings[k + 1], angle, true, &mut triangles);
            }
        }
        let mesh = Self { rest, triangles };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Checks indices, that no triangle is degenerate and that all are counter-clockwise.
    /// Used for generated meshes and for meshes from files.
    pub fn validate(&self) -> Result<(), MeshError> {
        let vertex_count = self.rest.len();
        let scale = self.mean_edge_length().max(1e-12);
        for (triangle, tri) in self.triangles.iter().enumerate() {
            for &vertex in tri {
                if vertex as usize >= vertex_count {
                    return Err(MeshError::BadIndex { triangle, vertex, vertex_count });
                }
            }
            let area = self.signed_area(triangle);
            // NaN areas (non-finite input) count as degenerate too.
            if area.is_nan() || area.abs() <= 1e-6 * scale * scale {
                return Err(MeshError::Degenerate { triangle, area });
            }
            if area < 0.0 {
                return Err(MeshError::Clockwise { triangle });
            }
        }
        Ok(())
    }

    /// Signed rest area of a triangle, m² (positive when counter-clockwise).
    pub fn signed_area(&self, triangle: usize) -> f64 {
        let [a, b, c] = self.triangles[triangle].map(|v| self.rest[v as usize]);
        0.5 * (b - a).perp_dot(c - a)
    }

    /// Mean rest edge length over all triangle edges, m.
    pub fn mean_edge_length(&self) -> f64 {
        if self.triangles.is_empty() {
            return 0.0;
        }
        let total: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let p = t.map(|v| self.rest[v as usize]);
                (p[1] - p[0]).length() + (p[2] - p[1]).length() + (p[0] - p[2]).length()
            })
            .sum();
        total / (3 * self.triangles.len()) as f64
    }
}

/// Triangulates the band between two rows of vertices, each sorted by `param`, always
/// advancing along the row whose next vertex comes first. With `closed`, both rows are
/// loops (disc rings) and the band wraps around.
fn stitch_rows(
    rest: &[DVec2],
    lower: &[u32],
    upper: &[u32],
    param: impl Fn(DVec2) -> f64,
    closed: bool,
    triangles: &mut Vec<[u32; 3]>,
) {
    let period = 2.0 * std::f64::consts::PI;
    // Walk both rows as sequences of (vertex, parameter); loops repeat their first vertex
    // one period later so the last band closes.
    let walk = |row: &[u32]| -> Vec<(u32, f64)> {
        let mut seq: Vec<(u32, f64)> = row.iter().map(|&v| (v, param(rest[v as usize]))).collect();
        if closed {
            seq.sort_by(|a, b| a.1.total_cmp(&b.1));
            let first = seq[0];
            seq.push((first.0, first.1 + period));
        }
        seq
    };
    let (a, b) = (walk(lower), walk(upper));
    let (mut i, mut j) = (0, 0);
    let mut push = |t: [u32; 3]| {
        let [p, q, r] = t.map(|v| rest[v as usize]);
        if (q - p).perp_dot(r - p) >= 0.0 { triangles.push(t) } else { triangles.push([t[0], t[2], t[1]]) }
    };
    while i + 1 < a.len() || j + 1 < b.len() {
        let advance_lower = if i + 1 == a.len() {
            false
        } else if j + 1 == b.len() {
            true
        } else {
            a[i + 1].1 <= b[j + 1].1
        };
        if advance_lower {
            push([a[i].0, a[i + 1].0, b[j].0]);
            i += 1;
        } else {
            push([a[i].0, b[j + 1].0, b[j].0]);
            j += 1;
        }
    }
}

/// Where a point of one rest plane lies on another mesh: the triangle it falls in (or, for
/// a point outside the mesh, the nearest one) and its barycentric weights there, which sum
/// to one and extrapolate linearly outside the triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Embedding {
    pub triangle: [u32; 3],
    pub weights: [f64; 3],
}

impl Embedding {
    /// The embedded point's position on the mesh's deformed surface `x`.
    pub fn position(&self, x: &[glam::DVec3]) -> glam::DVec3 {
        let [a, b, c] = self.triangle.map(|v| x[v as usize]);
        self.weights[0] * a + self.weights[1] * b + self.weights[2] * c
    }
}

impl Mesh {
    /// Embeds each of `points` (rest positions in the same sample plane) in this mesh: the
    /// transfer from a coarse mesh's state to a finer mesh of the same specimen.
    ///
    /// Triangles are binned on a grid of cells about an edge wide; a point takes the
    /// triangle that contains it, else the nearest triangle within the neighbouring cells,
    /// widening the search until one is found (points just outside a disc's polygonal rim).
    pub fn embed(&self, points: &[DVec2]) -> Vec<Embedding> {
        let (lo, hi) = self.rest.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let cell = self.mean_edge_length().max(1e-9);
        let dims = ((hi - lo) / cell).ceil().max(DVec2::ONE);
        let (nx, ny) = (dims.x as usize, dims.y as usize);
        let cell_of = |p: DVec2| {
            let c = ((p - lo) / cell).floor();
            ((c.x.max(0.0) as usize).min(nx - 1), (c.y.max(0.0) as usize).min(ny - 1))
        };
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
        for (t, tri) in self.triangles.iter().enumerate() {
            let corners = tri.map(|v| self.rest[v as usize]);
            let (a, b) = (cell_of(corners[0].min(corners[1]).min(corners[2])), cell_of(corners[0].max(corners[1]).max(corners[2])));
            for i in a.0..=b.0 {
                for j in a.1..=b.1 {
                    bins[j * nx + i].push(t as u32);
                }
            }
        }
        let weights_in = |t: u32, p: DVec2| -> [f64; 3] {
            let [a, b, c] = self.triangles[t as usize].map(|v| self.rest[v as usize]);
            let area = (b - a).perp_dot(c - a);
            let wb = (p - a).perp_dot(c - a) / area;
            let wc = (b - a).perp_dot(p - a) / area;
            [1.0 - wb - wc, wb, wc]
        };
        // Distance from p to the triangle in units of how far outside it lies: zero inside.
        let outside = |w: [f64; 3]| -w[0].min(w[1]).min(w[2]).min(0.0);
        points
            .iter()
            .map(|&p| {
                let (ci, cj) = cell_of(p);
                let mut best: Option<(f64, u32, [f64; 3])> = None;
                for ring in 0..nx.max(ny) {
                    let (i0, i1) = (ci.saturating_sub(ring), (ci + ring).min(nx - 1));
                    let (j0, j1) = (cj.saturating_sub(ring), (cj + ring).min(ny - 1));
                    for i in i0..=i1 {
                        for j in j0..=j1 {
                            // Only the ring's new cells.
                            if ring > 0 && i != i0 && i != i1 && j != j0 && j != j1 {
                                continue;
                            }
                            for &t in &bins[j * nx + i] {
                                let w = weights_in(t, p);
                                let d = outside(w);
                                if best.is_none_or(|(bd, bt, _)| d < bd || (d == bd && t < bt)) {
                                    best = Some((d, t, w));
                                }
                            }
                        }
                    }
                    // Inside a triangle, or the nearest one found and the next ring can hold
                    // nothing nearer.
                    if best.is_some_and(|(d, _, _)| d == 0.0) || (best.is_some() && ring >= 1) {
                        break;
                    }
                }
                let (_, t, weights) = best.expect("a mesh has at least one triangle");
                Embedding { triangle: self.triangles[t as usize], weights }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_area(mesh: &Mesh) -> f64 {
        (0..mesh.triangles.len()).map(|t| mesh.signed_area(t)).sum()
    }

    #[test]
    fn every_rectangle_pattern_tiles_the_rectangle() {
        for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
            let mesh = Mesh::rectangle(0.1, 0.05, 0.01, pattern, 7).unwrap();
            assert!((total_area(&mesh) - 0.005).abs() < 1e-12, "{pattern:?}");
            let h = mesh.mean_edge_length();
            assert!(h > 0.008 && h < 0.013, "{pattern:?}: mean edge {h}");
        }
    }

    #[test]
    fn disc_area_converges_to_the_circle() {
        let mesh = Mesh::disc(0.36, 0.01).unwrap();
        let circle = std::f64::consts::PI * 0.18 * 0.18;
        let area = total_area(&mesh);
        // An inscribed polygon with ~113 sides loses about 2π²/n² of the area.
        assert!(area < circle && area > circle * 0.998, "{area} vs {circle}");
        assert!((mesh.mean_edge_length() - 0.01).abs() < 0.002);
    }

    #[test]
    fn bad_sizes_are_named() {
        let err = Mesh::rectangle(-0.1, 0.05, 0.01, Pattern::Regular, 0).unwrap_err();
        assert!(err.to_string().contains("cloth.length"));
        let err = Mesh::rectangle(0.1, 0.05, 1e-7, Pattern::Regular, 0).unwrap_err();
        assert!(matches!(err, MeshError::TooManyVertices { .. }));
    }

    #[test]
    fn degenerate_triangle_is_reported() {
        let mesh = Mesh {
            rest: vec![DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0), DVec2::Y],
            triangles: vec![[0, 1, 3], [0, 1, 2]],
        };
        assert!(matches!(mesh.validate(), Err(MeshError::Degenerate { triangle: 1, .. })));
        let flipped = Mesh { rest: mesh.rest.clone(), triangles: vec![[0, 1, 3], [0, 3, 1]] };
        assert_eq!(flipped.validate(), Err(MeshError::Clockwise { triangle: 1 }));
    }

    /// Embedding a fine disc in a coarse one transfers any affine deformation exactly,
    /// inside the coarse polygon and on the fine rim just outside it.
    #[test]
    fn embedding_transfers_affine_deformations_exactly() {
        let coarse = Mesh::disc(0.36, 0.03).unwrap();
        let fine = Mesh::disc(0.36, 0.011).unwrap();
        let map = |p: DVec2| glam::DVec3::new(1.1 * p.x - 0.3 * p.y + 0.01, 0.2 * p.x + 0.9 * p.y, 0.5 * p.x - 0.7 * p.y + 0.2);
        let x: Vec<_> = coarse.rest.iter().map(|&p| map(p)).collect();
        let embedded = coarse.embed(&fine.rest);
        let mut outside = 0;
        for (e, &p) in embedded.iter().zip(&fine.rest) {
            assert!((e.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            outside += usize::from(e.weights.iter().any(|&w| w < -1e-12));
            assert!((e.position(&x) - map(p)).length() < 1e-12, "at {p}");
        }
        // The fine rim bulges past the coarse polygon's chords.
        assert!(outside > 0);
    }

}
