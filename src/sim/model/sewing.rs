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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::material::Fabric;
    use crate::sim::mesh::{Mesh, Pattern};
    use crate::sim::model::PhysicsOptions;

    fn fabric() -> Fabric {
        crate::scene::load_scene("cusick-drape", &[]).unwrap().0.material().unwrap()
    }

    /// A smooth, non-developable deformation of the rest plane (bending and stretching).
    fn shape(p: DVec2) -> DVec3 {
        DVec3::new(p.x + 0.02 * p.y * p.y, p.y - 0.01 * p.x * p.y, 0.6 * p.x * p.x - 0.4 * p.x * p.y + 0.9 * p.y * p.y)
    }

    /// A rectangle cut into two panels along x = 0.05 (the right one drawn turned by 30°
    /// and moved, its grain turned with it) and welded back stores the same membrane and
    /// bending energy, to round-off, as the rectangle cut in one piece: the charts unfolded
    /// across the seam see the rest plane the single piece has.
    #[test]
    fn a_welded_seam_bends_and_stretches_as_uncut_cloth() {
        let warp = 0.3;
        let mesh = Mesh::rectangle(0.1, 0.06, 0.01, Pattern::Alternating, 1).unwrap();
        let options = PhysicsOptions::default();
        let whole = Model::new(&mesh, &fabric(), warp, options).unwrap();
        // The right panel is drawn turned by 30°.
        const TURN: f64 = std::f64::consts::FRAC_PI_6;
        let turn = DVec2::from_angle(TURN);
        let moved = |p: DVec2| turn.rotate(p) + DVec2::new(0.3, -0.2);
        let right = |t: &[u32; 3]| t.iter().map(|&v| mesh.rest[v as usize].x).sum::<f64>() / 3.0 > 0.05;
        // The right panel's pattern is the moved copy; its warp in its own drawing is the
        // whole cloth's warp turned the same way.
        let corners = mesh
            .triangles
            .iter()
            .map(|t| {
                let (p, grain) = if right(t) { (t.map(|v| moved(mesh.rest[v as usize])), warp + TURN) } else { (t.map(|v| mesh.rest[v as usize]), warp) };
                p.map(|q| DVec2::from_angle(-grain).rotate(q))
            })
            .collect();
        let surface = PanelSurface { triangles: mesh.triangles.clone(), corners, pattern: mesh.rest.clone() };
        let welded = Model::from_panels(&surface, &[], &fabric(), options).unwrap();
        let x: Vec<DVec3> = mesh.rest.iter().map(|&p| shape(p)).collect();
        let (m0, b0) = whole.elastic_energy(&x);
        let (m1, b1) = welded.elastic_energy(&x);
        assert!(b0 > 0.0 && m0 > 0.0);
        assert!((b1 / b0 - 1.0).abs() < 1e-9, "bending {b1} vs {b0}");
        assert!((m1 / m0 - 1.0).abs() < 1e-9, "membrane {m1} vs {m0}");
    }

    /// Sewing springs: energy, forces and Hessian agree (central differences).
    #[test]
    fn springs_are_conservative() {
        let sewing = Sewing { pairs: vec![[0, 1]], anchors: vec![(2, DVec3::new(0.1, 0.2, 0.3))], stiffness: 40.0 };
        let x = vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.05, -0.02, 0.01), DVec3::new(0.2, 0.1, 0.0)];
        let mut f = vec![DVec3::ZERO; 3];
        sewing.add_forces(&x, &mut f);
        let e = 1e-6;
        for v in 0..3 {
            for axis in 0..3 {
                let (mut plus, mut minus) = (x.clone(), x.clone());
                plus[v][axis] += e;
                minus[v][axis] -= e;
                let derivative = (sewing.energy(&plus) - sewing.energy(&minus)) / (2.0 * e);
                assert!((derivative + f[v][axis]).abs() < 1e-6, "vertex {v} axis {axis}");
            }
        }
        assert!((sewing.largest_gap(&x) - x[0].distance(x[1])).abs() < 1e-15);
    }
}
