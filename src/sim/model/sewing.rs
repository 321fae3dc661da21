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
    /// Each vertex's place on the flat pattern (panels laid side by side as cut), m. A
    /// vertex shared by two panels (a welded seam) takes the first panel's.
    pub pattern: Vec<DVec2>,
    /// Each vertex's place in the texture space (each panel turned into its warp frame,
    /// the panels laid side by side), m: what the viewer draws the weave on and what an
    /// export takes as texture coordinates, so that the weave follows each panel's grain.
    pub texture: Vec<DVec2>,
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

/// Sewing springs: ½ k max(0, d − L)² for each seam pair at distance d and for each
/// attached vertex at distance d from its anchor, with one stiffness k and a rest length L
/// that the scene shrinks while it sews: L = s·d₀, d₀ the spring's length when the sewing
/// began and s its slack, going from 1 to 0. A spring only pulls where the seam lags its
/// schedule, so the seams close at the pace the slack sets, however far apart the panels
/// start (a zero-length spring's pull grows with the gap, and snaps distant panels
/// together in a few steps); at s = 0 the springs have zero length.
#[derive(Debug, Clone, Default)]
pub struct Sewing {
    /// Seam vertex pairs the springs join.
    pub pairs: Vec<[u32; 2]>,
    /// Attached vertices and the points they are pulled to, m.
    pub anchors: Vec<(u32, DVec3)>,
    /// Spring stiffness, N/m (zero: the springs are off).
    pub stiffness: f64,
    /// Each spring's length when the sewing began, m: the pairs', then the anchors'
    /// (empty: zero-length springs).
    pub start_lengths: Vec<f64>,
    /// The share of its starting length each spring may still have, 1 to 0.
    pub slack: f64,
    /// Per vertex, the seams whose sides it lies near (bit s mod 64 for seam s; empty: no
    /// seams). While the seams close, self-collision leaves out pairs whose two sides lie
    /// near a common seam, whose sides must meet, and keeps every other panel from
    /// passing through (`seam_bands`).
    pub bands: Vec<u64>,
    /// Per vertex, its vertex once the seams are welded (empty: none).
    pub welded: Vec<u32>,
}

/// How many rings of triangles around a seam's vertices its band takes in: a seam's sides
/// meet at an angle, and a vertex two edges from the seam line stays farther than the
/// self-collision layer (a fifth of an edge at most) from the other side wherever the two
/// sides meet at more than about 6°.
const BAND_RINGS: usize = 2;

/// Each vertex's seam bits (see [`Sewing::bands`]): the vertices of each `open` seam's
/// sides and those within `BAND_RINGS` edges of them over `triangles` (n vertices).
pub fn seam_bands(seams: &[Vec<[u32; 2]>], open: &[bool], triangles: &[[u32; 3]], n: usize) -> Vec<u64> {
    let mut neighbours = vec![Vec::new(); n];
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            neighbours[a].push(b as u32);
            neighbours[b].push(a as u32);
        }
    }
    let mut bands = vec![0u64; n];
    for (s, seam) in seams.iter().enumerate().filter(|(s, _)| open[*s]) {
        let bit = 1u64 << (s % 64);
        let mut ring: Vec<u32> = seam.iter().flatten().copied().filter(|&v| bands[v as usize] & bit == 0).collect();
        ring.sort_unstable();
        ring.dedup();
        for &v in &ring {
            bands[v as usize] |= bit;
        }
        for _ in 0..BAND_RINGS {
            let mut next = Vec::new();
            for &v in &ring {
                for &w in &neighbours[v as usize] {
                    if bands[w as usize] & bit == 0 {
                        bands[w as usize] |= bit;
                        next.push(w);
                    }
                }
            }
            ring = next;
        }
    }
    bands
}

impl Sewing {
    pub fn is_active(&self) -> bool {
        self.stiffness > 0.0 && !(self.pairs.is_empty() && self.anchors.is_empty())
    }

    /// Records every spring's present length as its starting length.
    pub fn start(&mut self, x: &[DVec3]) {
        let pairs = self.pairs.iter().map(|&[a, b]| x[a as usize].distance(x[b as usize]));
        self.start_lengths = pairs.chain(self.anchors.iter().map(|&(v, p)| x[v as usize].distance(p))).collect();
    }

    /// Every spring: its two ends (the second a point for an anchor) and its rest length.
    fn springs<'a>(&'a self, x: &'a [DVec3]) -> impl Iterator<Item = (u32, Option<u32>, DVec3, f64)> + 'a {
        let rest = move |i: usize| self.slack * self.start_lengths.get(i).copied().unwrap_or(0.0);
        let pairs = self.pairs.iter().map(|&[a, b]| (a, Some(b), x[b as usize]));
        let anchors = self.anchors.iter().map(|&(v, p)| (v, None, p));
        pairs.chain(anchors).enumerate().map(move |(i, (a, b, to))| (a, b, to, rest(i)))
    }

    /// Energy of the springs, J.
    pub fn energy(&self, x: &[DVec3]) -> f64 {
        let k = self.stiffness;
        self.springs(x).map(|(a, _, to, rest)| 0.5 * k * (x[a as usize].distance(to) - rest).max(0.0).powi(2)).sum()
    }

    /// Adds the springs' forces −∇E to `f`.
    ///
    /// ```text
    ///   a ●~~~~~~~~● b     a seam pair: f_a = k (d − L) n, n = (x_b − x_a)/d, f_b = −f_a
    ///   v ●~~~~~~~~○ p     an attachment: f_v = k (d − L) n, n = (p − x_v)/d
    /// ```
    pub fn add_forces(&self, x: &[DVec3], f: &mut [DVec3]) {
        let k = self.stiffness;
        for (a, b, to, rest) in self.springs(x) {
            let r = to - x[a as usize];
            let d = r.length();
            if d <= rest || d == 0.0 {
                continue;
            }
            let pull = k * (d - rest) / d * r;
            f[a as usize] += pull;
            if let Some(b) = b {
                f[b as usize] -= pull;
            }
        }
    }

    /// Adds the springs' Hessian to `k`, whose pattern holds every pair: for a stretched
    /// spring k[(1 − L/d) I + (L/d) n nᵀ], positive semi-definite.
    pub fn add_stiffness(&self, x: &[DVec3], k: &mut BlockCsr) {
        for (a, b, to, rest) in self.springs(x) {
            let r = to - x[a as usize];
            let d = r.length();
            if d <= rest {
                continue;
            }
            let share = if d > 0.0 { rest / d } else { 0.0 };
            let n = if d > 0.0 { r / d } else { DVec3::ZERO };
            let block = self.stiffness * (DMat3::from_diagonal(DVec3::splat(1.0 - share)) + share * DMat3::from_cols(n * n.x, n * n.y, n * n.z));
            let mut add = |r: u32, c: u32, sign: f64| {
                let slot = k.slot(r, c);
                k.values[slot] += block * sign;
            };
            add(a, a, 1.0);
            if let Some(b) = b {
                add(b, b, 1.0);
                add(a, b, -1.0);
                add(b, a, -1.0);
            }
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
        crate::sim::model::tests::wool_suiting()
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
        let surface = PanelSurface { triangles: mesh.triangles.clone(), corners, pattern: mesh.rest.clone(), texture: mesh.rest.clone() };
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
        let x = vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.05, -0.02, 0.01), DVec3::new(0.2, 0.1, 0.0)];
        let mut sewing = Sewing { pairs: vec![[0, 1]], anchors: vec![(2, DVec3::new(0.1, 0.2, 0.3))], stiffness: 40.0, ..Sewing::default() };
        sewing.start(&x);
        // Zero-length springs, then springs at 40 % of their starting length.
        for slack in [0.0, 0.4] {
            sewing.slack = slack;
            let mut f = vec![DVec3::ZERO; 3];
            sewing.add_forces(&x, &mut f);
            let e = 1e-6;
            for v in 0..3 {
                for axis in 0..3 {
                    let (mut plus, mut minus) = (x.clone(), x.clone());
                    plus[v][axis] += e;
                    minus[v][axis] -= e;
                    let derivative = (sewing.energy(&plus) - sewing.energy(&minus)) / (2.0 * e);
                    assert!((derivative + f[v][axis]).abs() < 1e-6, "slack {slack}: vertex {v} axis {axis}");
                    // The Hessian's column: the change of −f over a step along this axis.
                    let (mut fp, mut fm) = (vec![DVec3::ZERO; 3], vec![DVec3::ZERO; 3]);
                    sewing.add_forces(&plus, &mut fp);
                    sewing.add_forces(&minus, &mut fm);
                    let mut k = BlockCsr::with_pattern(3, [(0, 1)].into_iter());
                    sewing.add_stiffness(&x, &mut k);
                    let mut unit = vec![DVec3::ZERO; 3];
                    unit[v][axis] = 1.0;
                    let mut hessian_column = vec![DVec3::ZERO; 3];
                    k.multiply(&unit, &mut hessian_column);
                    for w in 0..3 {
                        let column = -(fp[w] - fm[w]) / (2.0 * e);
                        assert!((column - hessian_column[w]).length() < 1e-5, "slack {slack}: Hessian ({w}, {v}) axis {axis}: {column} vs {}", hessian_column[w]);
                    }
                }
            }
        }
        // A spring shorter than its rest length pulls nothing.
        sewing.slack = 1.0;
        let mut f = vec![DVec3::ZERO; 3];
        sewing.add_forces(&x, &mut f);
        assert!(f.iter().all(|fi| fi.length() < 1e-15) && sewing.energy(&x) == 0.0);
        assert!((sewing.largest_gap(&x) - x[0].distance(x[1])).abs() < 1e-15);
    }

    /// A seam's band is its sides' vertices and two rings of neighbours, and only while
    /// the seam is open; pairs sharing a vertex once welded, or near a common open seam,
    /// are left out of self-collision, and no other pair is.
    #[test]
    fn a_seam_band_takes_in_its_sides_and_two_rings_while_the_seam_is_open() {
        use crate::sim::contact::Cloth;
        // A strip of 6 by 2 squares, vertex (i, j) = 7j + i, sewn into a tube: column 0
        // to column 6.
        let id = |i: u32, j: u32| 7 * j + i;
        let mut triangles = Vec::new();
        for j in 0..2 {
            for i in 0..6 {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let seams = vec![(0..3).map(|j| [id(0, j), id(6, j)]).collect::<Vec<_>>()];
        let bands = seam_bands(&seams, &[true], &triangles, 21);
        for j in 0..3 {
            for i in 0..7 {
                assert_eq!(bands[id(i, j) as usize], if i == 3 { 0 } else { 1 }, "vertex ({i}, {j})");
            }
        }
        assert!(seam_bands(&seams, &[false], &triangles, 21).iter().all(|&b| b == 0), "a closed seam has no band");
        // Welded, column 6 becomes column 0.
        let welded: Vec<u32> = (0..21).map(|v| if v % 7 == 6 { v - 6 } else { v }).collect();
        let open = Cloth { triangles: &[], edges: &[], fixed: &[], mass: &[], mean_edge_length: 1.0, seam_bands: &bands, welded: &welded };
        assert!(open.sewn_together(&[id(1, 1)], &[id(5, 0), id(6, 0), id(5, 1)]), "near the open seam, either side");
        assert!(!open.sewn_together(&[id(3, 1)], &[id(4, 0), id(5, 0), id(5, 1)]), "the middle of the strip is not near the seam");
        let closed = Cloth { seam_bands: &[], ..open };
        assert!(closed.sewn_together(&[id(0, 0)], &[id(5, 0), id(6, 0), id(5, 1)]), "neighbours once welded");
        assert!(!closed.sewn_together(&[id(1, 1)], &[id(5, 0), id(6, 0), id(5, 1)]), "a closed seam's sides collide as the welded cloth's");
    }
}
