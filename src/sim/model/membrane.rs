//! The in-plane model: every triangle a strain rosette (paper eq. 1–2), its energy from
//! the measured tensile curves ([`MembraneLaw`]), its forces as edge tensions and its
//! Hessian in 3×3 blocks.

use super::{Model, TEAM_TRIANGLES, map_in_order, outer, sum_of};
use crate::sim::linalg::{BlockCsr, ScalarCsr};
use crate::sim::material::MembraneLaw;
use glam::{DMat3, DVec2, DVec3};

/// Rest data of one triangle's strain rosette (paper Fig. 1).
#[derive(Debug, Clone)]
pub(super) struct RosetteTriangle {
    vertices: [u32; 3],
    /// Rest area, m².
    area: f64,
    /// Rest length of edge k (opposite vertex k, from vertex k+1 to vertex k+2), m.
    rest_length: [f64; 3],
    /// Unit direction of edge k at rest, in the warp frame.
    rest_direction: [DVec2; 3],
    /// Maps the three edge strains to `[ε_xx, ε_yy, γ_xy]` in the warp frame.
    strain_from_edges: [[f64; 3]; 3],
    /// Slots in the stiffness matrix of block (vertex a, vertex b), row-major a·3+b.
    slots: [u32; 9],
}

impl Model {
    /// Membrane energy Σ A ψ(ε), J (zero without a membrane).
    pub(super) fn membrane_energy(&self, x: &[DVec3]) -> f64 {
        let Some(law) = &self.membrane_law else { return 0.0 };
        sum_of(self.rosettes.len(), |t| {
            let tri = &self.rosettes[t];
            tri.area * law.energy(rosette_strain(tri, x).0)
        })
    }


    /// In-plane (strain rosette) forces.
    ///
    /// ```text
    ///        v2            Each triangle is a strain rosette: its edge strains
    ///       /  \           ε_k = l_k/L_k − 1 give [ε_xx, ε_yy, γ_xy] = T⁻¹ ε (paper §1),
    ///   e1 /    \ e0       the law gives σ = ∂ψ/∂ε, and each edge carries the tension
    ///     /      \         A (T⁻ᵀσ)_k / L_k along its current direction: the paper's
    ///   v0 ------ v1       "stresses converted to edge forces", here as −∂(Aψ)/∂x.
    ///         e2
    /// ```
    pub(super) fn add_membrane_forces(&self, x: &[DVec3], f: &mut [DVec3]) {
        let Some(law) = &self.membrane_law else { return };
        let pulls = |tri: &RosetteTriangle| {
            let (strain, dirs, _) = rosette_strain(tri, x);
            let tension = edge_tensions(tri, law.stress(strain));
            [0, 1, 2].map(|k| tension[k] * dirs[k])
        };
        let add = |f: &mut [DVec3], tri: &RosetteTriangle, pull: [DVec3; 3]| {
            for (k, pull) in pull.into_iter().enumerate() {
                let (a, b) = edge_vertices(tri, k);
                f[a as usize] += pull;
                f[b as usize] -= pull;
            }
        };
        // Both paths add the same pulls in the same order: the forces do not depend on
        // the number of threads.
        if self.rosettes.len() < TEAM_TRIANGLES {
            for tri in &self.rosettes {
                add(f, tri, pulls(tri));
            }
        } else {
            let all = map_in_order(&self.rosettes, pulls);
            for (tri, pull) in self.rosettes.iter().zip(all.into_iter().flatten()) {
                add(f, tri, pull);
            }
        }
    }


    /// Adds the membrane forces to `f` and returns the membrane energy, J: both from one
    /// pass over the triangles (the quasi-Newton step evaluates them at every trial).
    pub(super) fn add_membrane_energy_and_forces(&self, x: &[DVec3], f: &mut [DVec3]) -> f64 {
        let Some(law) = &self.membrane_law else { return 0.0 };
        let evaluate = |tri: &RosetteTriangle| {
            let (strain, dirs, _) = rosette_strain(tri, x);
            let (psi, stress) = law.energy_and_stress(strain);
            let tension = edge_tensions(tri, stress);
            (tri.area * psi, [0, 1, 2].map(|k| tension[k] * dirs[k]))
        };
        let mut energy = 0.0;
        let mut add = |tri: &RosetteTriangle, (e, pull): (f64, [DVec3; 3])| {
            energy += e;
            for (k, pull) in pull.into_iter().enumerate() {
                let (a, b) = edge_vertices(tri, k);
                f[a as usize] += pull;
                f[b as usize] -= pull;
            }
        };
        if self.rosettes.len() < TEAM_TRIANGLES {
            for tri in &self.rosettes {
                add(tri, evaluate(tri));
            }
        } else {
            let all = map_in_order(&self.rosettes, evaluate);
            for (tri, item) in self.rosettes.iter().zip(all.into_iter().flatten()) {
                add(tri, item);
            }
        }
        energy
    }


    /// Assembles the in-plane stiffness (the Hessian of the membrane energy, with the
    /// geometric stiffness of compressed edges dropped so that it stays positive
    /// semi-definite) into `k`, which must have this model's pattern.
    pub fn assemble_membrane_stiffness(&self, x: &[DVec3], k: &mut BlockCsr) {
        self.assemble_membrane_stiffness_within(x, k, CompressedEdges::Dropped);
    }


    /// The in-plane stiffness with as much of the compressed edges' (negative) geometric
    /// stiffness as `compressed` lets in.
    ///
    /// Dropping it all makes Newton converge only linearly on a buckling cloth (the Cusick
    /// drape included): the dropped term is the softening that lets compressed cloth bend
    /// out of plane, so every Newton step falls short along the buckling modes. A compressed edge's term −(|t|/l)(I − uuᵀ) on its two vertices is at
    /// least −2(|t|/l)(|d_a|² + |d_b|²) in any direction d; scaling the edges at vertex i so
    /// that their 2|t|/l sum to at most `allowance[i]` bounds their total below by
    /// −Σ allowance[i] |d_i|².
    pub fn assemble_membrane_stiffness_within(&self, x: &[DVec3], k: &mut BlockCsr, compressed: CompressedEdges) {
        k.clear();
        if self.sewing.is_active() {
            self.sewing.add_stiffness(x, k);
        }
        let Some(law) = &self.membrane_law else { return };
        // Each vertex's scale for the compressed edges it ends (0: dropped).
        let ratio: Vec<f64> = match compressed {
            CompressedEdges::Dropped => vec![0.0; x.len()],
            CompressedEdges::Exact => vec![1.0; x.len()],
            CompressedEdges::Within(allowance) => {
                self.compressed_demand(x).iter().zip(allowance).map(|(&d, &a)| if d <= a { 1.0 } else { a / d }).collect()
            }
        };
        let add = |k: &mut BlockCsr, tri: &RosetteTriangle, blocks: &[DMat3; 6]| {
            for (i, &(a, b)) in UPPER_BLOCKS.iter().enumerate() {
                k.values[tri.slots[a * 3 + b] as usize] += blocks[i];
                if a != b {
                    k.values[tri.slots[b * 3 + a] as usize] += blocks[i].transpose();
                }
            }
        };
        if self.rosettes.len() < TEAM_TRIANGLES {
            for tri in &self.rosettes {
                add(k, tri, &triangle_stiffness(tri, law, x, &ratio));
            }
        } else {
            let blocks = map_in_order(&self.rosettes, |tri| triangle_stiffness(tri, law, x, &ratio));
            for (tri, b) in self.rosettes.iter().zip(blocks.iter().flatten()) {
                add(k, tri, b);
            }
        }
    }


    /// Adds the membrane's rest stiffness, made to act alike on x, y and z, to `s` (whose
    /// pattern must hold the mesh's edges): for each triangle Σ_pq s_pa s_qb K_pq (u_p·u_q),
    /// where the true rest Hessian has the blocks Σ_pq s_pa s_qb K_pq u_p u_qᵀ
    /// (`triangle_stiffness` at zero strain). The Hadamard product of K (positive
    /// semi-definite) and the Gram matrix of the edge directions is positive semi-definite
    /// (Schur's product theorem), and it annihilates rigid translations. Like the matrix of
    /// projective dynamics it does not change as the cloth moves or rotates: the
    /// quasi-Newton step factors it once.
    pub fn add_isotropic_rest_stiffness(&self, s: &mut ScalarCsr) {
        let Some(law) = &self.membrane_law else { return };
        let c = law.tangent([0.0; 3]);
        for tri in &self.rosettes {
            let g = &tri.strain_from_edges;
            let dirs = tri.rest_direction;
            let mut ke = [[0.0; 3]; 3];
            for p in 0..3 {
                for q in 0..3 {
                    let mut sum = 0.0;
                    for i in 0..3 {
                        for j in 0..3 {
                            sum += g[i][p] * c[i][j] * g[j][q];
                        }
                    }
                    ke[p][q] = tri.area * sum / (tri.rest_length[p] * tri.rest_length[q]) * dirs[p].dot(dirs[q]);
                }
            }
            let edges_of = |a: usize| [((a + 1) % 3, 1.0), ((a + 2) % 3, -1.0)];
            for a in 0..3 {
                for b in 0..3 {
                    let mut value = 0.0;
                    for (p, sp) in edges_of(a) {
                        for (q, sq) in edges_of(b) {
                            value += sp * sq * ke[p][q];
                        }
                    }
                    let slot = s.slot(tri.vertices[a], tri.vertices[b]);
                    s.values[slot] += value;
                }
            }
        }
    }


    /// Each vertex's Σ 2|t|/l over the compressed edges it ends (N/m): the compressed
    /// edges' geometric stiffness −(|t|/l)(I − uuᵀ) is at least −diag(demand) ⊗ I₃.
    fn compressed_demand(&self, x: &[DVec3]) -> Vec<f64> {
        let mut demand = vec![0.0; x.len()];
        let Some(law) = &self.membrane_law else { return demand };
        for tri in &self.rosettes {
            let (strain, _, lengths) = rosette_strain(tri, x);
            let tension = edge_tensions(tri, law.stress(strain));
            for p in 0..3 {
                if tension[p] < 0.0 {
                    let (a, b) = edge_vertices(tri, p);
                    let c = -2.0 * tension[p] / lengths[p];
                    demand[a as usize] += c;
                    demand[b as usize] += c;
                }
            }
        }
        demand
    }


    /// Membrane strains `[ε_xx, ε_yy, γ_xy]` of every triangle in the warp frame.
    pub fn triangle_strains(&self, x: &[DVec3]) -> Vec<[f64; 3]> {
        self.rosettes.iter().map(|tri| rosette_strain(tri, x).0).collect()
    }
}

/// The vertex pairs (a, b), a ≤ b, of a triangle's upper stiffness blocks.
const UPPER_BLOCKS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];

/// One triangle's membrane stiffness blocks (a, b) in [`UPPER_BLOCKS`] order: the Hessian of
/// its energy with the geometric stiffness of compressed edges dropped.
///
/// With l_p the edge lengths and u_p their directions, ∂l_p/∂x_a = s_pa u_p where vertex a
/// ends edge a+1 (s = +1) and starts edge a+2 (s = −1). The material part of block (a, b)
/// is Σ_pq s_pa s_qb K_pq u_p u_qᵀ, K = A·GᵀCG/(L_p L_q) in edge-strain space; a stretched
/// edge adds its geometric stiffness (t/l)(I − u uᵀ) with signs s_pa s_pb.
/// A compressed edge's geometric stiffness enters scaled by the smaller `ratio` of its two
/// vertices.
fn triangle_stiffness(tri: &RosetteTriangle, law: &MembraneLaw, x: &[DVec3], ratio: &[f64]) -> [DMat3; 6] {
    let (strain, dirs, lengths) = rosette_strain(tri, x);
    let (stress, c) = law.stress_and_tangent(strain);
    let g = &tri.strain_from_edges;
    let mut ke = [[0.0; 3]; 3];
    for p in 0..3 {
        for q in p..3 {
            let mut s = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    s += g[i][p] * c[i][j] * g[j][q];
                }
            }
            ke[p][q] = tri.area * s / (tri.rest_length[p] * tri.rest_length[q]);
            ke[q][p] = ke[p][q];
        }
    }
    let tension = edge_tensions(tri, stress);
    let geometric: [DMat3; 3] = [0, 1, 2].map(|p| {
        let scale = if tension[p] > 0.0 {
            1.0
        } else {
            let (a, b) = edge_vertices(tri, p);
            ratio[a as usize].min(ratio[b as usize])
        };
        if scale > 0.0 && lengths[p] > 0.0 { (DMat3::IDENTITY - outer(dirs[p], dirs[p])) * (scale * tension[p] / lengths[p]) } else { DMat3::ZERO }
    });
    // Block (a, b) = Σ_p s_pa u_p w_bpᵀ with w_bp = Σ_q s_qb K_pq u_q: two outer products a
    // block instead of four.
    let edges_of = |a: usize| [((a + 1) % 3, 1.0), ((a + 2) % 3, -1.0)];
    let w: [[DVec3; 3]; 3] = [0, 1, 2].map(|b| {
        let [(q0, s0), (q1, s1)] = edges_of(b);
        [0, 1, 2].map(|p| dirs[q0] * (s0 * ke[p][q0]) + dirs[q1] * (s1 * ke[p][q1]))
    });
    UPPER_BLOCKS.map(|(a, b)| {
        let [(p0, s0), (p1, s1)] = edges_of(a);
        let mut block = outer(dirs[p0] * s0, w[b][p0]) + outer(dirs[p1] * s1, w[b][p1]);
        if a == b {
            block += geometric[(a + 1) % 3] + geometric[(a + 2) % 3];
        } else {
            // The edge joining a and b is the one opposite the third vertex; it starts at
            // one and ends at the other.
            block -= geometric[3 - a - b];
        }
        block
    })
}

/// How much of the compressed edges' geometric stiffness, which is negative, goes into an
/// assembled in-plane stiffness.
#[derive(Debug, Clone, Copy)]
pub enum CompressedEdges<'a> {
    /// None: the stiffness is positive semi-definite.
    Dropped,
    /// All of it: the exact Hessian, which may be indefinite.
    Exact,
    /// At most `allowance[i]` (N/m) at vertex i in the Gershgorin sense, so that
    /// K + diag(allowance) ⊗ I₃ is positive semi-definite.
    Within(&'a [f64]),
}

/// Edge k of a triangle runs from vertex k+1 to vertex k+2.
fn edge_vertices(tri: &RosetteTriangle, k: usize) -> (u32, u32) {
    (tri.vertices[(k + 1) % 3], tri.vertices[(k + 2) % 3])
}

/// Current rosette strains, unit edge directions and edge lengths.
fn rosette_strain(tri: &RosetteTriangle, x: &[DVec3]) -> ([f64; 3], [DVec3; 3], [f64; 3]) {
    let mut edge_strain = [0.0; 3];
    let mut dirs = [DVec3::ZERO; 3];
    let mut lengths = [0.0; 3];
    for k in 0..3 {
        let (a, b) = edge_vertices(tri, k);
        let d = x[b as usize] - x[a as usize];
        let l = d.length();
        lengths[k] = l;
        dirs[k] = if l > 0.0 { d / l } else { DVec3::ZERO };
        edge_strain[k] = l / tri.rest_length[k] - 1.0;
    }
    let g = &tri.strain_from_edges;
    let strain = [0, 1, 2].map(|i| g[i][0] * edge_strain[0] + g[i][1] * edge_strain[1] + g[i][2] * edge_strain[2]);
    (strain, dirs, lengths)
}

/// Edge tensions ∂(Aψ)/∂l_k = A (T⁻ᵀ σ)_k / L_k, N.
fn edge_tensions(tri: &RosetteTriangle, stress: [f64; 3]) -> [f64; 3] {
    let g = &tri.strain_from_edges;
    [0, 1, 2].map(|k| tri.area * (g[0][k] * stress[0] + g[1][k] * stress[1] + g[2][k] * stress[2]) / tri.rest_length[k])
}

/// The rosette of triangle `tri` whose corners in its warp frame are `p` and whose rest area
/// is `area` (m²).
pub(super) fn rosette(p: [DVec2; 3], area: f64, tri: [u32; 3], pattern: &BlockCsr) -> RosetteTriangle {
    let mut rows = [[0.0; 3]; 3];
    let mut rest_length = [0.0; 3];
    let mut rest_direction = [DVec2::ZERO; 3];
    for k in 0..3 {
        let d = p[(k + 2) % 3] - p[(k + 1) % 3];
        let l = d.length();
        rest_length[k] = l;
        rest_direction[k] = d / l;
        let (c, s) = (d.x / l, d.y / l);
        // Strain gauge along the edge: ε_k = ε_xx c² + ε_yy s² + γ_xy c s.
        rows[k] = [c * c, s * s, c * s];
    }
    let strain_from_edges = invert3(rows).expect("a non-degenerate triangle has three distinct edge directions");
    let mut slots = [0u32; 9];
    for a in 0..3 {
        for b in 0..3 {
            slots[a * 3 + b] = pattern.slot(tri[a], tri[b]) as u32;
        }
    }
    RosetteTriangle { vertices: tri, area, rest_length, rest_direction, strain_from_edges, slots }
}

fn invert3(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let a = DMat3::from_cols_array_2d(&m).transpose();
    let det = a.determinant();
    if !det.is_finite() || det.abs() < 1e-14 {
        return None;
    }
    Some(a.inverse().transpose().to_cols_array_2d())
}
