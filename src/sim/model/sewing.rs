//! Cloths of flat panels (garments) and the springs that sew them: each triangle keeps its
//! own rest shape and warp frame, and zero-length springs pull matched seam vertices
//! together (and attached vertices onto their anchors) until the seams can be welded.

use super::{Model, sorted_edge};
use crate::sim::linalg::BlockCsr;
use crate::sim::mesh::MeshError;
use glam::{DMat3, DVec2, DVec3};

/// A cloth of flat panels: triangles over shared vertices, each with its own flat rest
/// shape given in its own warp frame.
#[derive(Debug, Clone, Default)]
pub struct PanelSurface {
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's corners in its warp frame (x along the warp, y along the weft), m,
    /// counter-clockwise.
    pub corners: Vec<[DVec2; 3]>,
    /// Each vertex's place on the flat pattern (panels laid side by side), m: what the
    /// viewer draws the weave on and what an export takes as texture coordinates. A vertex
    /// shared by two panels (a welded seam) takes the first panel's.
    pub pattern: Vec<DVec2>,
}

impl PanelSurface {
    /// Checks indices, that every rest triangle has an area and is counter-clockwise.
    pub fn validate(&self) -> Result<(), MeshError> {
        let vertex_count = self.pattern.len();
        let scale = self.mean_edge_length().max(1e-12);
        for (triangle, (tri, c)) in self.triangles.iter().zip(&self.corners).enumerate() {
            if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= vertex_count) {
                return Err(MeshError::BadIndex { triangle, vertex, vertex_count });
            }
            let area = 0.5 * (c[1] - c[0]).perp_dot(c[2] - c[0]);
            if area.is_nan() || area.abs() <= 1e-6 * scale * scale {
                return Err(MeshError::Degenerate { triangle, area });
            }
            if area < 0.0 {
                return Err(MeshError::Clockwise { triangle });
            }
        }
        Ok(())
    }

    /// Mean rest edge length over all triangle edges, m.
    pub fn mean_edge_length(&self) -> f64 {
        if self.corners.is_empty() {
            return 0.0;
        }
        let total: f64 = self.corners.iter().map(|p| (p[1] - p[0]).length() + (p[2] - p[1]).length() + (p[0] - p[2]).length()).sum();
        total / (3 * self.corners.len()) as f64
    }

    /// The rest length of each edge in `edges` (sorted, as the model keeps them): the mean
    /// over the triangles that hold it (the two sides of a welded seam may differ by the
    /// ease the pattern allows).
    pub fn edge_rest_lengths(&self, edges: &[[u32; 2]]) -> Vec<f64> {
        let mut sum = vec![(0.0, 0u32); edges.len()];
        for (tri, c) in self.triangles.iter().zip(&self.corners) {
            for k in 0..3 {
                let (a, b) = ((k + 1) % 3, (k + 2) % 3);
                if let Ok(i) = edges.binary_search(&sorted_edge(tri[a], tri[b])) {
                    sum[i].0 += (c[b] - c[a]).length();
                    sum[i].1 += 1;
                }
            }
        }
        sum.iter().map(|&(s, count)| s / count.max(1) as f64).collect()
    }
}

/// Zero-length springs: ½ k |x_a − x_b|² for each seam pair and ½ k |x_v − p|² for each
/// attached vertex v and its anchor p, with one stiffness k that the scene ramps up while
/// it sews (a fixed model would snap the panels together in one step).
#[derive(Debug, Clone, Default)]
pub struct Sewing {
    /// Seam vertex pairs the springs join.
    pub pairs: Vec<[u32; 2]>,
    /// Attached vertices and the points they are pulled to, m.
    pub anchors: Vec<(u32, DVec3)>,
    /// Spring stiffness, N/m (zero: the springs are off).
    pub stiffness: f64,
}

impl Sewing {
    pub fn is_active(&self) -> bool {
        self.stiffness > 0.0 && !(self.pairs.is_empty() && self.anchors.is_empty())
    }

    /// Energy of the springs, J.
    pub fn energy(&self, x: &[DVec3]) -> f64 {
        let k = self.stiffness;
        let seams: f64 = self.pairs.iter().map(|&[a, b]| 0.5 * k * x[a as usize].distance_squared(x[b as usize])).sum();
        let anchors: f64 = self.anchors.iter().map(|&(v, p)| 0.5 * k * x[v as usize].distance_squared(p)).sum();
        seams + anchors
    }

    /// Adds the springs' forces −∇E to `f`.
    ///
    /// ```text
    ///   a ●~~~~~~~~● b     a seam pair: f_a = k (x_b − x_a), f_b = −f_a
    ///   v ●~~~~~~~~○ p     an attachment: f_v = k (p − x_v)
    /// ```
    pub fn add_forces(&self, x: &[DVec3], f: &mut [DVec3]) {
        let k = self.stiffness;
        for &[a, b] in &self.pairs {
            let pull = k * (x[b as usize] - x[a as usize]);
            f[a as usize] += pull;
            f[b as usize] -= pull;
        }
        for &(v, p) in &self.anchors {
            f[v as usize] += k * (p - x[v as usize]);
        }
    }

    /// Adds the springs' (constant) Hessian to `k`, whose pattern holds every pair.
    pub fn add_stiffness(&self, k: &mut BlockCsr) {
        let block = DMat3::from_diagonal(DVec3::splat(self.stiffness));
        for &[a, b] in &self.pairs {
            for (r, c, sign) in [(a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)] {
                let slot = k.slot(r, c);
                k.values[slot] += block * sign;
            }
        }
        for &(v, _) in &self.anchors {
            let slot = k.slot(v, v);
            k.values[slot] += block;
        }
    }

    /// The largest distance between a seam pair's vertices, m (zero without seams).
    pub fn largest_gap(&self, x: &[DVec3]) -> f64 {
        self.pairs.iter().map(|&[a, b]| x[a as usize].distance(x[b as usize])).fold(0.0, f64::max)
    }
}

impl Model {
    /// Whether the model is a cloth of panels (a garment).
    pub fn has_panels(&self) -> bool {
        self.frames.is_some()
    }
}
