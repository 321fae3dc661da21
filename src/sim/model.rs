//! The fixed part of a simulation: rest geometry, masses, material laws, topology,
//! constraints and loads. Positions and velocities live in [`State`](crate::sim::State).
//!
//! Energies and their gradients (forces) and Hessians are all here, so every integrator
//! sees the same conservative model. Everything that a scene switches off (membrane,
//! bending, gravity) is absent from the model, not multiplied by zero.

use crate::sim::contact::ContactModel;
use crate::sim::curve::PiecewiseLinear;
use crate::sim::material::{BendingStiffness, Fabric, FabricError, MembraneLaw};
use crate::sim::mesh::{Mesh, MeshError};
use crate::sim::sparse::{BlockCsr, ScalarCsr};
use glam::{DMat2, DMat3, DVec2, DVec3};
use std::collections::HashMap;
use thiserror::Error;

/// Which physics a scene enables. Anything off costs nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicsOptions {
    /// In-plane strain-rosette elasticity.
    pub membrane: bool,
    /// Out-of-plane bending.
    pub bending: bool,
    /// Gravitational acceleration, m/s² (zero turns gravity off).
    pub gravity: DVec3,
    /// Mass-proportional (air) damping rate ζ, 1/s: the drag force is −ζ·m·v.
    pub damping: f64,
}

impl Default for PhysicsOptions {
    fn default() -> Self {
        Self { membrane: true, bending: true, gravity: DVec3::new(0.0, 0.0, -9.81), damping: 0.0 }
    }
}

#[derive(Debug, Error)]
pub enum ModelError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    #[error(transparent)]
    Fabric(#[from] FabricError),
    #[error(
        "the bending stencil of triangle {triangle} is singular (its neighbours are nearly collinear \
         with it); use a less distorted mesh or another mesh.pattern"
    )]
    SingularBendingStencil { triangle: usize },
    #[error("solver.damping must be zero or positive (1/s), got {0}")]
    BadDamping(f64),
}

/// Prescribed motion of a group of vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Straight line: displacement `velocity · clamp(t − start, 0, stop − start)`.
    Linear {
        /// Velocity while moving, m/s.
        velocity: DVec3,
        /// Time the motion starts, s.
        start: f64,
        /// Time the motion stops (the group then holds still), s.
        stop: f64,
    },
    /// Swing along a circle of `radius` in the xy plane, as the free end of a rigid link
    /// hinged below the group: displacement (R sin a, R cos a − R, 0) with
    /// a = `angular_speed` · min(t, stop). A trellis (picture-frame) shear.
    Swing {
        /// Link length, m.
        radius: f64,
        /// Rad/s.
        angular_speed: f64,
        /// Time the swing stops, s.
        stop: f64,
    },
    /// Rigid grip at the end of a strip rolled into an arc (pure bending, KES-B style): the
    /// strip's free length `length` from x = 0 along +x is wrapped onto a circle of
    /// curvature κ(t) = `curvature` · min(t / `ramp`, 1) curling towards +z, and the grip,
    /// whose rest x is ≥ `length`, continues rigidly along the end tangent.
    Roll {
        /// Free length between the clamp line and the grip line, m.
        length: f64,
        /// Final curvature, 1/m.
        curvature: f64,
        /// Time to reach it, s.
        ramp: f64,
    },
}

impl Motion {
    /// Position at time `t` of a vertex of the group whose rest position is `anchor`.
    pub fn position(&self, anchor: DVec3, t: f64) -> DVec3 {
        match *self {
            Motion::Roll { length, curvature, ramp } => {
                let kappa = curvature * (t / ramp).clamp(0.0, 1.0);
                let phi = kappa * length;
                let end = if kappa.abs() < 1e-12 {
                    DVec3::new(length, anchor.y, 0.0)
                } else {
                    DVec3::new(phi.sin() / kappa, anchor.y, (1.0 - phi.cos()) / kappa)
                };
                end + (anchor.x - length) * DVec3::new(phi.cos(), 0.0, phi.sin()) + DVec3::new(0.0, 0.0, anchor.z)
            }
            Motion::Linear { velocity, start, stop } => anchor + velocity * (t - start).clamp(0.0, (stop - start).max(0.0)),
            Motion::Swing { radius, angular_speed, stop } => {
                let a = angular_speed * t.clamp(0.0, stop);
                anchor + DVec3::new(radius * a.sin(), radius * (a.cos() - 1.0), 0.0)
            }
        }
    }

    pub const STILL: Motion = Motion::Linear { velocity: DVec3::ZERO, start: 0.0, stop: 0.0 };
}

/// Nonlinear bending data: the warp moment–curvature curve and each triangle's
/// (slot, value) share of Q, re-weighted by secant factors into Newton's matrix.
#[derive(Debug, Clone)]
struct NonlinearBending {
    curve: PiecewiseLinear,
    contributions: Vec<Vec<(u32, f64)>>,
    /// The hinges' part of Q (see [`Hinge`]), which stays linear.
    hinges: Option<ScalarCsr>,
}

/// Rest data of one triangle's strain rosette (paper Fig. 1).
#[derive(Debug, Clone)]
struct RosetteTriangle {
    vertices: [u32; 3],
    /// Rest area, m².
    area: f64,
    /// Rest length of edge k (opposite vertex k, from vertex k+1 to vertex k+2), m.
    rest_length: [f64; 3],
    /// Maps the three edge strains to `[ε_xx, ε_yy, γ_xy]` in the warp frame.
    strain_from_edges: [[f64; 3]; 3],
    /// Slots in the stiffness matrix of block (vertex a, vertex b), row-major a·3+b.
    slots: [u32; 9],
}

/// The model: rest state, material, topology, constraints and loads.
#[derive(Debug, Clone)]
pub struct Model {
    pub options: PhysicsOptions,
    /// Rest positions in the sample plane, m.
    pub rest: Vec<DVec2>,
    pub triangles: Vec<[u32; 3]>,
    /// Lumped vertex masses, kg.
    pub mass: Vec<f64>,
    /// Lumped vertex areas, m² (a third of each adjacent triangle).
    pub vertex_area: Vec<f64>,
    /// Warp direction in the sample plane, radians from the sample's x axis.
    pub warp_angle: f64,
    pub mean_edge_length: f64,
    membrane_law: Option<MembraneLaw>,
    rosettes: Vec<RosetteTriangle>,
    pub bending_stiffness: BendingStiffness,
    /// The bending energy is ½ Σ Q_ab x_a·x_b (see [`Model::bending_matrix`]).
    bending: Option<ScalarCsr>,
    /// Per-triangle bending stencils (the Hessian x_,ij = Σ_a W_a x_a on each triangle).
    bending_patches: Vec<BendingPatch>,
    /// Nonlinear bending, when the fabric has a moment–curvature curve.
    bending_curve: Option<NonlinearBending>,
    /// Pattern of the in-plane stiffness matrix.
    stiffness_pattern: BlockCsr,
    /// Vertices whose positions are prescribed.
    pub fixed: Vec<bool>,
    anchor: Vec<DVec3>,
    driver: Vec<u16>,
    motions: Vec<Motion>,
    /// Undirected edges (a < b), for strain checks and drawing.
    pub edges: Vec<[u32; 2]>,
    /// Props and contact settings; None where the cloth touches nothing.
    pub contact: Option<ContactModel>,
    /// The fastest in-plane wave, √(E_max/ρ_A) with E_max the steepest slope of the
    /// tensile curves, m/s (infinite without a membrane). No part of a cloth driven by its
    /// own elasticity, gravity over the scene's height or the rigs' slow grips moves this
    /// fast: a vertex that does is a blow-up, even where contact keeps its positions tame.
    pub max_wave_speed: f64,
}

/// Rotates a sample-plane vector into the warp frame (x along the warp).
fn to_warp_frame(p: DVec2, warp_angle: f64) -> DVec2 {
    DVec2::from_angle(-warp_angle).rotate(p)
}

impl Model {
    /// Builds a model of `mesh` cut from `fabric` with the warp at `warp_angle` radians from
    /// the sample's x axis.
    pub fn new(mesh: &Mesh, fabric: &Fabric, warp_angle: f64, options: PhysicsOptions) -> Result<Self, ModelError> {
        mesh.validate()?;
        fabric.validate()?;
        if !(options.damping >= 0.0 && options.damping.is_finite()) {
            return Err(ModelError::BadDamping(options.damping));
        }
        let n = mesh.rest.len();
        let mut vertex_area = vec![0.0; n];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let a = mesh.signed_area(t);
            for &v in tri {
                vertex_area[v as usize] += a / 3.0;
            }
        }
        let mass = vertex_area.iter().map(|a| a * fabric.areal_density).collect();
        let mut edge_set: Vec<[u32; 2]> =
            mesh.triangles.iter().flat_map(|t| (0..3).map(move |k| sorted_edge(t[(k + 1) % 3], t[(k + 2) % 3]))).collect();
        edge_set.sort_unstable();
        edge_set.dedup();

        let stiffness_pattern = BlockCsr::with_pattern(n, edge_set.iter().map(|e| (e[0], e[1])));
        let membrane_law = if options.membrane { Some(MembraneLaw::new(fabric)?) } else { None };
        let rosettes = if options.membrane {
            mesh.triangles
                .iter()
                .enumerate()
                .map(|(t, tri)| rosette(mesh, t, *tri, warp_angle, &stiffness_pattern))
                .collect()
        } else {
            Vec::new()
        };
        let bending_stiffness = BendingStiffness::new(fabric)?;
        // Filled in by `build_bending` below when bending is on.
        let bending_curve = fabric
            .bending_curve
            .clone()
            .filter(|_| options.bending)
            .map(|curve| NonlinearBending { curve, contributions: Vec::new(), hinges: None });
        let mut model = Self {
            options,
            rest: mesh.rest.clone(),
            triangles: mesh.triangles.clone(),
            mass,
            vertex_area,
            warp_angle,
            mean_edge_length: mesh.mean_edge_length(),
            membrane_law,
            rosettes,
            bending_stiffness,
            bending: None,
            bending_patches: Vec::new(),
            bending_curve,
            stiffness_pattern,
            fixed: vec![false; n],
            anchor: vec![DVec3::ZERO; n],
            driver: vec![0; n],
            motions: vec![Motion::STILL],
            edges: edge_set,
            contact: None,
            max_wave_speed: if options.membrane {
                (fabric.tensile_warp.max_slope().max(fabric.tensile_weft.max_slope()) / fabric.areal_density).sqrt()
            } else {
                f64::INFINITY
            },
        };
        if options.bending {
            model.build_bending(&vec![false; n])?;
        }
        Ok(model)
    }

    /// The fastest free vertex of velocities `v`, (index, speed m/s), if it moves faster
    /// than the cloth's fastest in-plane wave or at no finite speed: a blow-up.
    pub fn outrunning_vertex(&self, v: &[DVec3]) -> Option<(usize, f64)> {
        let (i, speed) = v
            .iter()
            .map(|v| v.length())
            .enumerate()
            .filter(|&(i, _)| !self.fixed[i])
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        (speed.is_nan() || speed > self.max_wave_speed).then_some((i, speed))
    }

    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Holds vertex `v` at `position` for the whole run.
    pub fn pin(&mut self, v: u32, position: DVec3) {
        self.fixed[v as usize] = true;
        self.anchor[v as usize] = position;
        self.driver[v as usize] = 0;
    }

    /// Moves the given vertices, starting from `positions`, with `motion`.
    pub fn drive(&mut self, vertices: &[u32], positions: &[DVec3], motion: Motion) {
        self.motions.push(motion);
        let id = (self.motions.len() - 1) as u16;
        for &v in vertices {
            self.fixed[v as usize] = true;
            self.anchor[v as usize] = positions[v as usize];
            self.driver[v as usize] = id;
        }
    }

    /// Declares the vertices of a clamp: a region held rigidly (its vertices must also be
    /// pinned or driven together). Bending stencils are rebuilt so that they do not fit
    /// across the clamp line (see `bending_patches`).
    pub fn set_clamped_region(&mut self, rigid: &[bool]) -> Result<(), ModelError> {
        if self.options.bending { self.build_bending(rigid) } else { Ok(()) }
    }

    /// Builds the bending stencils, Q and (for nonlinear bending) each triangle's share of
    /// Q, with `rigid` marking clamped vertices.
    fn build_bending(&mut self, rigid: &[bool]) -> Result<(), ModelError> {
        let mesh = Mesh { rest: self.rest.clone(), triangles: self.triangles.clone() };
        let (patches, hinges) = bending_patches(&mesh, self.warp_angle, rigid)?;
        let (q, hinge_values) = bending_matrix(self.rest.len(), &patches, &hinges, &self.bending_stiffness);
        if let Some(nonlinear) = &mut self.bending_curve {
            nonlinear.contributions = triangle_contributions(&q, &patches, &self.bending_stiffness);
            let mut hinge_part = q.clone();
            hinge_part.values = hinge_values;
            symmetrize_with_zero_row_sums(&mut hinge_part);
            nonlinear.hinges = Some(hinge_part);
        }
        self.bending = Some(q);
        self.bending_patches = patches;
        Ok(())
    }

    /// Whether every prescribed motion has come to rest by time `t`.
    pub fn motions_finished(&self, t: f64) -> bool {
        self.motions.iter().all(|m| match *m {
            Motion::Linear { stop, .. } | Motion::Swing { stop, .. } => t >= stop,
            Motion::Roll { ramp, .. } => t >= ramp,
        })
    }

    /// Prescribed position of a fixed vertex at time `t`.
    pub fn prescribed_position(&self, v: usize, t: f64) -> DVec3 {
        self.motions[self.driver[v] as usize].position(self.anchor[v], t)
    }

    /// Total potential energy (elastic + gravity), J.
    pub fn potential_energy(&self, x: &[DVec3]) -> f64 {
        let mut energy = 0.0;
        if let Some(law) = &self.membrane_law {
            energy += sum_of(self.rosettes.len(), |t| {
                let tri = &self.rosettes[t];
                tri.area * law.energy(rosette_strain(tri, x).0)
            });
        }
        energy += self.bending_energy(x);
        if self.options.gravity != DVec3::ZERO {
            let g = self.options.gravity;
            energy -= sum_of(x.len(), |i| self.mass[i] * g.dot(x[i]));
        }
        energy
    }

    /// Elastic energy only (membrane + bending), J.
    pub fn elastic_energy(&self, x: &[DVec3]) -> (f64, f64) {
        let membrane = match &self.membrane_law {
            Some(law) => self.rosettes.iter().map(|tri| tri.area * law.energy(rosette_strain(tri, x).0)).sum(),
            None => 0.0,
        };
        (membrane, self.bending_energy(x))
    }

    /// Bending energy, J: ½ xᵀQx, or with a moment–curvature curve Σ_T A_T B_x Φ̂(κ_eq),
    /// where κ_eq = √(2ψ_lin/B_x) is the warp curvature that stores the triangle's linear
    /// energy density ψ_lin and Φ̂ is the curve's energy over its initial slope (so that a
    /// bend along the warp follows the measured moments exactly).
    fn bending_energy(&self, x: &[DVec3]) -> f64 {
        let Some(q) = &self.bending else { return 0.0 };
        match &self.bending_curve {
            None => quadratic_energy(q, x),
            Some(NonlinearBending { curve, hinges, .. }) => {
                let b_ref = self.bending_stiffness.d11;
                let fitted: f64 = self
                    .bending_patches
                    .iter()
                    .map(|patch| {
                        let kappa = self.equivalent_curvature(&patch.hessian(x));
                        patch.area * b_ref * curve.integral(kappa) / curve.initial_slope()
                    })
                    .sum();
                fitted + hinges.as_ref().map_or(0.0, |h| quadratic_energy(h, x))
            }
        }
    }

    /// κ_eq = √(2ψ_lin/B_x): the warp curvature storing the linear energy density of a
    /// triangle whose Hessian is `h`, 1/m.
    fn equivalent_curvature(&self, h: &[DVec3; 3]) -> f64 {
        (2.0 * linear_bending_density(&self.bending_stiffness, h) / self.bending_stiffness.d11).sqrt()
    }

    /// Secant factor M(κ)/(M'(0) κ): how much stiffer (> 1) or softer (< 1) than linear a
    /// triangle with Hessian `h` bends under `curve`.
    fn bending_secant(&self, curve: &PiecewiseLinear, h: &[DVec3; 3]) -> f64 {
        let kappa = self.equivalent_curvature(h);
        if kappa * 1e6 < 1.0 { 1.0 } else { curve.value(kappa) / (curve.initial_slope() * kappa) }
    }

    /// The bending part of Newton's matrix at `x`: Q itself for linear bending, otherwise
    /// the secant matrix Σ_T s_T A_T WᵀDW (positive semi-definite; the curvature-derivative
    /// term is left out, so Newton converges linearly rather than quadratically there).
    pub fn bending_newton_matrix(&self, x: &[DVec3]) -> Option<std::borrow::Cow<'_, ScalarCsr>> {
        let q = self.bending.as_ref()?;
        let Some(NonlinearBending { curve, contributions, hinges }) = &self.bending_curve else {
            return Some(std::borrow::Cow::Borrowed(q));
        };
        // The secant matrix starts from the hinges' part, which stays linear.
        let mut secant = hinges.clone().expect("build_bending sets the hinges with Q");
        for (patch, entries) in self.bending_patches.iter().zip(contributions) {
            let s = self.bending_secant(curve, &patch.hessian(x));
            for &(slot, value) in entries {
                secant.values[slot as usize] += s * value;
            }
        }
        Some(std::borrow::Cow::Owned(secant))
    }

    /// Total conservative force −∇E on every vertex, N (overwrites `f`).
    pub fn forces(&self, x: &[DVec3], f: &mut [DVec3]) {
        f.fill(DVec3::ZERO);
        if self.options.gravity != DVec3::ZERO {
            for (fi, m) in f.iter_mut().zip(&self.mass) {
                *fi += *m * self.options.gravity;
            }
        }
        self.add_membrane_forces(x, f);
        if let (Some(_), Some(NonlinearBending { curve, hinges, .. })) = (&self.bending, &self.bending_curve) {
            // Nonlinear: each triangle's linear force scaled by its secant factor.
            let d = self.bending_stiffness.voigt();
            for patch in &self.bending_patches {
                let h = patch.hessian(x);
                let s = self.bending_secant(curve, &h);
                let moment: [DVec3; 3] = [0, 1, 2].map(|i| d[i][0] * h[0] + d[i][1] * h[1] + d[i][2] * h[2]);
                for (v, w) in patch.vertices.iter().zip(&patch.weights) {
                    f[*v as usize] -= patch.area * s * (w[0] * moment[0] + w[1] * moment[1] + w[2] * moment[2]);
                }
            }
            if let Some(h) = hinges {
                subtract_quadratic_force(h, x, f);
            }
        } else if let Some(q) = &self.bending {
            subtract_quadratic_force(q, x, f);
        }
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
    fn add_membrane_forces(&self, x: &[DVec3], f: &mut [DVec3]) {
        use rayon::prelude::*;
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
        if self.rosettes.len() < PARALLEL_TRIANGLES {
            for tri in &self.rosettes {
                add(f, tri, pulls(tri));
            }
        } else {
            let all: Vec<[DVec3; 3]> = self.rosettes.par_iter().map(pulls).collect();
            for (tri, pull) in self.rosettes.iter().zip(all) {
                add(f, tri, pull);
            }
        }
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
    /// Dropping it all made Newton converge linearly on a buckling cloth, and on the Cusick
    /// drape at a ratio of 0.5–0.7 per iteration: the dropped term is the softening that
    /// lets compressed cloth bend out of plane, so every Newton step fell short along the
    /// buckling modes. A compressed edge's term −(|t|/l)(I − uuᵀ) on its two vertices is at
    /// least −2(|t|/l)(|d_a|² + |d_b|²) in any direction d; scaling the edges at vertex i so
    /// that their 2|t|/l sum to at most `allowance[i]` bounds their total below by
    /// −Σ allowance[i] |d_i|².
    pub fn assemble_membrane_stiffness_within(&self, x: &[DVec3], k: &mut BlockCsr, compressed: CompressedEdges) {
        use rayon::prelude::*;
        k.clear();
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
        if self.rosettes.len() < PARALLEL_TRIANGLES {
            for tri in &self.rosettes {
                add(k, tri, &triangle_stiffness(tri, law, x, &ratio));
            }
        } else {
            let blocks: Vec<[DMat3; 6]> = self.rosettes.par_iter().map(|tri| triangle_stiffness(tri, law, x, &ratio)).collect();
            for (tri, b) in self.rosettes.iter().zip(&blocks) {
                add(k, tri, b);
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

    /// A zero matrix with the in-plane stiffness pattern.
    pub fn stiffness_matrix(&self) -> BlockCsr {
        self.stiffness_pattern.clone()
    }

    /// Curvature `[κ_xx, κ_yy, κ_xy]` (1/m, warp frame) of every triangle, signed by the
    /// triangle's normal (x_,ij · n). Empty when bending is off.
    pub fn triangle_curvatures(&self, x: &[DVec3]) -> Vec<[f64; 3]> {
        self.bending_patches
            .iter()
            .zip(&self.triangles)
            .map(|(patch, tri)| {
                let [a, b, c] = tri.map(|v| x[v as usize]);
                let normal = (b - a).cross(c - a).normalize_or_zero();
                let h = patch.hessian(x);
                h.map(|v| v.dot(normal))
            })
            .collect()
    }

    /// Linear bending energy of each triangle's patch, J: they sum to ½ xᵀQx less the
    /// hinges' share (see [`Hinge`]), which is zero on any quadratic surface.
    pub fn triangle_bending_energies(&self, x: &[DVec3]) -> Vec<f64> {
        self.bending_patches.iter().map(|patch| patch.area * linear_bending_density(&self.bending_stiffness, &patch.hessian(x))).collect()
    }

    /// Whether triangle `t` has a neighbour across each of its edges.
    pub fn is_interior_triangle(&self, t: usize) -> bool {
        self.bending_patches.get(t).is_some_and(|p| p.interior)
    }

    pub fn has_membrane(&self) -> bool {
        self.membrane_law.is_some()
    }

    /// Membrane strains `[ε_xx, ε_yy, γ_xy]` of every triangle in the warp frame.
    pub fn triangle_strains(&self, x: &[DVec3]) -> Vec<[f64; 3]> {
        self.rosettes.iter().map(|tri| rosette_strain(tri, x).0).collect()
    }

    /// Largest stretch ratio l/L over all edges (a blow-up shows as a huge value).
    pub fn max_stretch(&self, x: &[DVec3]) -> f64 {
        self.edges
            .iter()
            .map(|&[a, b]| {
                let rest = (self.rest[a as usize] - self.rest[b as usize]).length();
                (x[a as usize] - x[b as usize]).length() / rest
            })
            .fold(0.0, f64::max)
    }

    /// Largest time step at which symplectic Euler is stable at state `x`, s: 2/ω_max, with
    /// ω_max² the largest eigenvalue of M⁻¹K over the free vertices (K the membrane tangent
    /// plus bending stiffness at `x`). Found by power iteration on M^{-½} K M^{-½}; its
    /// Rayleigh quotient approaches ω_max² from below, so the limit is approached from above
    /// and 400 iterations put it within about a percent on cloth meshes.
    pub fn explicit_step_limit(&self, x: &[DVec3]) -> f64 {
        let n = x.len();
        let mut k = self.stiffness_matrix();
        self.assemble_membrane_stiffness(x, &mut k);
        let bending = self.bending_newton_matrix(x);
        let inv_sqrt_mass: Vec<f64> = (0..n).map(|i| if self.fixed[i] { 0.0 } else { 1.0 / self.mass[i].sqrt() }).collect();
        // A deterministic start vector with energy in every mode.
        let mut v: Vec<DVec3> = (0..n)
            .map(|i| {
                let t = i as f64;
                DVec3::new((t * 12.9898).sin(), (t * 78.233).sin(), (t * 37.719).sin()) * inv_sqrt_mass[i].signum()
            })
            .collect();
        let (mut u, mut w) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        let mut lambda: f64 = 0.0;
        for _ in 0..400 {
            let norm = v.iter().map(|p| p.length_squared()).sum::<f64>().sqrt();
            if norm == 0.0 {
                return f64::INFINITY;
            }
            for i in 0..n {
                v[i] /= norm;
                u[i] = v[i] * inv_sqrt_mass[i];
            }
            k.multiply(&u, &mut w);
            if let Some(q) = &bending {
                q.multiply_add(&u, &mut w);
            }
            for i in 0..n {
                w[i] *= inv_sqrt_mass[i];
            }
            lambda = lambda.max(v.iter().zip(&w).map(|(a, b)| a.dot(*b)).sum::<f64>());
            std::mem::swap(&mut v, &mut w);
        }
        if lambda > 0.0 { 2.0 / lambda.sqrt() } else { f64::INFINITY }
    }

    /// Largest membrane tangent stiffness the material can reach, N/m.
    pub fn max_membrane_stiffness(&self) -> f64 {
        self.membrane_law.as_ref().map_or(0.0, |l| l.max_stiffness())
    }
}

/// ½ Σ Q_ab x_a·x_b, J.
fn quadratic_energy(q: &ScalarCsr, x: &[DVec3]) -> f64 {
    if x.len() < PARALLEL_TRIANGLES {
        return 0.5 * q.entries().map(|(a, b, v)| v * x[a as usize].dot(x[b as usize])).sum::<f64>();
    }
    0.5 * sum_of(x.len(), |a| q.entries_of_row(a as u32).map(|(b, v)| v * x[a].dot(x[b as usize])).sum::<f64>())
}

/// Above this many triangles (or vertices) the per-element loops of forces, energies and
/// stiffness run on rayon's threads. Below it a loop takes tens of microseconds, about what
/// handing it to another thread costs.
const PARALLEL_TRIANGLES: usize = 4096;

/// Σ term(i) for i < count: in order on one thread for small counts; above
/// `PARALLEL_TRIANGLES`, as partial sums over fixed chunks added in order, so that the
/// result does not depend on the number of threads.
fn sum_of(count: usize, term: impl Fn(usize) -> f64 + Sync) -> f64 {
    use rayon::prelude::*;
    const CHUNK: usize = 1024;
    if count < PARALLEL_TRIANGLES {
        return (0..count).map(term).sum();
    }
    let partial: Vec<f64> = (0..count.div_ceil(CHUNK)).into_par_iter().map(|c| (c * CHUNK..((c + 1) * CHUNK).min(count)).map(&term).sum()).collect();
    partial.iter().sum()
}

/// f −= Q x for an energy ½ Σ Q_ab x_a·x_b whose rows sum to zero, written as
/// −Σ_b Q_ab (x_b − x_a): the same force, but independent of where the origin is, so it
/// keeps its round-off small far from the origin.
fn subtract_quadratic_force(q: &ScalarCsr, x: &[DVec3], f: &mut [DVec3]) {
    use rayon::prelude::*;
    let row = |(a, fa): (usize, &mut DVec3)| {
        let xa = x[a];
        *fa -= q.entries_of_row(a as u32).map(|(b, v)| v * (x[b as usize] - xa)).sum::<DVec3>();
    };
    if f.len() < PARALLEL_TRIANGLES {
        f.iter_mut().enumerate().for_each(row);
    } else {
        f.par_iter_mut().enumerate().for_each(row);
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

fn sorted_edge(a: u32, b: u32) -> [u32; 2] {
    if a < b { [a, b] } else { [b, a] }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
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

fn rosette(mesh: &Mesh, t: usize, tri: [u32; 3], warp_angle: f64, pattern: &BlockCsr) -> RosetteTriangle {
    let p = tri.map(|v| to_warp_frame(mesh.rest[v as usize], warp_angle));
    let mut rows = [[0.0; 3]; 3];
    let mut rest_length = [0.0; 3];
    for k in 0..3 {
        let d = p[(k + 2) % 3] - p[(k + 1) % 3];
        let l = d.length();
        rest_length[k] = l;
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
    RosetteTriangle { vertices: tri, area: mesh.signed_area(t), rest_length, strain_from_edges, slots }
}

fn invert3(m: [[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let a = DMat3::from_cols_array_2d(&m).transpose();
    let det = a.determinant();
    if !det.is_finite() || det.abs() < 1e-14 {
        return None;
    }
    Some(a.inverse().transpose().to_cols_array_2d())
}

/// Builds every triangle's bending stencil: its surface Hessian x_,ij as a linear
/// combination of nearby vertex positions.
///
/// ```text
///        c                The curvature of triangle T is the divergence form
///       / \               H_T = (1/A_T) Σ_k L_k sym(n_k ⊗ G_k) = (1/A_T) ∫_T ∇∇x,
///   G1 •   • G0           with n_k the outward normal of edge k and G_k the gradient
///     /     \             ∇x at edge k's midpoint, estimated by a least-squares
///    a---•---b            quadratic fit over the vertices around that edge (the
///        G2               wings across it: the paper's cantilevers across the edge).
/// ```
/// Two properties make it converge on any triangulation: the fit is exact for quadratic
/// surfaces, so H_T is exact for any constant curvature; and both triangles of an edge use
/// the same G_k, so Σ_T A_T H_T telescopes to boundary terms and a uniformly curved sheet is
/// in equilibrium away from its edges (the finite-element patch test). A per-triangle fit
/// without the shared edge gradients fails the second and is twice too soft on some meshes.
///
/// For a nearly inextensible sheet bent from flat, x_,ij = II_ij n (Gauss's formula with a
/// flat metric), so ψ_b = ½ D:II:II = ½ Σ D_ijkl x_,ij·x_,kl: the energy is quadratic in
/// positions and its Hessian is a constant matrix Q (the anisotropic counterpart of Bergou et
/// al.'s quadratic bending model). It is invariant to rigid motions, so the forces sum to
/// zero and conserve momentum.
fn bending_patches(mesh: &Mesh, warp_angle: f64, rigid: &[bool]) -> Result<(Vec<BendingPatch>, Vec<Hinge>), ModelError> {
    let n = mesh.rest.len();
    let mut edge_owner: HashMap<[u32; 2], Vec<(usize, usize)>> = HashMap::new();
    let mut vertex_triangles: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            edge_owner.entry(sorted_edge(tri[(k + 1) % 3], tri[(k + 2) % 3])).or_default().push((t, k));
            vertex_triangles[tri[k] as usize].push(t as u32);
        }
    }
    for (edge, owners) in &edge_owner {
        if owners.len() > 2 {
            return Err(MeshError::NonManifold { a: edge[0], b: edge[1] }.into());
        }
    }
    let warp: Vec<DVec2> = mesh.rest.iter().map(|&p| to_warp_frame(p, warp_angle)).collect();
    let scale = mesh.mean_edge_length();
    // A clamped region moves rigidly: its curvature is zero while the cloth beside it bends,
    // so a fit across the clamp line would smear that jump and make the root too soft.
    // Edges inside the clamp (both ends rigid) fit rigid vertices only, which gives the
    // clamp's exact slope; other edges fit free vertices plus the clamp line itself.
    let on_clamp_line: Vec<bool> = (0..n)
        .map(|v| rigid[v] && vertex_triangles[v].iter().any(|&t| mesh.triangles[t as usize].iter().any(|&u| !rigid[u as usize])))
        .collect();
    // One gradient stencil per edge, shared by its triangles.
    let mut gradient_of_edge: HashMap<[u32; 2], Vec<(u32, DVec2)>> = HashMap::new();
    for (&edge, owners) in &edge_owner {
        let midpoint = 0.5 * (warp[edge[0] as usize] + warp[edge[1] as usize]);
        let inside_clamp = rigid[edge[0] as usize] && rigid[edge[1] as usize];
        let usable = |v: u32| if inside_clamp { rigid[v as usize] } else { !rigid[v as usize] || on_clamp_line[v as usize] };
        let stencil = edge_gradient_stencil(mesh, &vertex_triangles, &warp, edge, midpoint, scale, usable)
            .ok_or(ModelError::SingularBendingStencil { triangle: owners[0].0 })?;
        gradient_of_edge.insert(edge, stencil);
    }
    let mut patches = Vec::with_capacity(mesh.triangles.len());
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let area = mesh.signed_area(t);
        let mut weights: Vec<(u32, [f64; 3])> = Vec::new();
        let mut interior = true;
        for k in 0..3 {
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let key = sorted_edge(a, b);
            interior &= edge_owner[&key].len() == 2;
            let edge = warp[b as usize] - warp[a as usize];
            // Outward normal times edge length, for a counter-clockwise triangle.
            let ln = DVec2::new(edge.y, -edge.x);
            for &(v, c) in &gradient_of_edge[&key] {
                let w = [ln.x * c.x / area, ln.y * c.y / area, 0.5 * (ln.x * c.y + ln.y * c.x) / area];
                match weights.iter_mut().find(|(u, _)| *u == v) {
                    Some((_, acc)) => (0..3).for_each(|i| acc[i] += w[i]),
                    None => weights.push((v, w)),
                }
            }
        }
        let (vertices, weights) = weights.into_iter().unzip();
        patches.push(BendingPatch { vertices, weights, area, interior });
    }
    // Two half hinges per interior edge, one on each triangle's fitted Hessian; edges in a
    // fixed order, so that Q sums the same way in every run.
    let mut edges: Vec<[u32; 2]> = edge_owner.keys().copied().collect();
    edges.sort_unstable();
    let mut hinges = Vec::new();
    for edge in edges {
        if let [(t0, k0), (t1, k1)] = edge_owner[&edge][..] {
            let wings = [mesh.triangles[t0][k0], mesh.triangles[t1][k1]];
            if !edge.iter().chain(&wings).any(|&v| rigid[v as usize]) {
                hinges.extend([t0, t1].into_iter().filter_map(|t| Hinge::new(&patches[t], &warp, edge, wings)));
            }
        }
    }
    Ok((patches, hinges))
}

/// A stabilisation of the fitted bending stencils against mesh-scale oscillation.
///
/// The fits that give the edge gradients average over a ring or more, so a deflection that
/// zigzags from vertex to vertex can have nearly flat fits everywhere and almost no bending
/// energy: on the paper's drape mesh about 7 % of the bending operator's modes are such
/// oscillations, with under 1 % (down to 0.16 %) of the continuum's stiffness B k⁴ at their
/// wavenumber, and on square grids a zigzag along the grid has 3 % of it. A compressed sheet
/// buckles into them at the scale of the mesh (hourglass modes, as in under-integrated
/// finite elements). Each interior edge therefore adds the energy of a hinge, the paper's
/// cantilever across the edge, acting only on what the fitted curvature does not explain:
///
/// ```text
///        c            J is the jump of the normal slope across edge ab of the piecewise-
///       / \           linear surface through a, b, c, d, and J_T the same jump of the
///      a---b  → m     quadratic with triangle T's fitted Hessian H_T. Each of the edge's
///       \ /           two triangles T holds half of E = ½ B_m ((J − J_T)/d)² A, with d the
///        d            distance between the triangles' centroids along m, A a third of
///                     their areas and B_m the flexural rigidity across the edge (eq. 3).
/// ```
///
/// H_T is exact on any quadratic surface, so there J = J_T and the term adds nothing: it
/// leaves the patch test, the cylindrical and twisted curvatures and the rigid motions as
/// they were, and stiffens only what the fitted stencils miss: the oscillations, and the
/// shortfall of the fitted stencils on features a few edges wide, which they bend too
/// easily (unit test `smooth_bumps_bend_as_a_plate`).
struct Hinge {
    /// The patch's vertices and each one's weight in J − J_T.
    vertices: Vec<u32>,
    stencil: Vec<f64>,
    /// Unit normal of the edge in the warp frame, towards wing d.
    normal: DVec2,
    /// A/(2d²), the half hinge's energy per unit rigidity and squared J − J_T.
    weight: f64,
}

impl Hinge {
    /// The half hinge of edge `e` between the triangles (e, wings[0]) and (e, wings[1]) on
    /// `patch`, the fitted Hessian of one of them; None if either triangle is degenerate.
    fn new(patch: &BendingPatch, warp: &[DVec2], e: [u32; 2], wings: [u32; 2]) -> Option<Self> {
        let p = |v: u32| warp[v as usize];
        let along = p(e[1]) - p(e[0]);
        let mut normal = DVec2::new(along.y, -along.x).normalize();
        if (p(wings[1]) - p(e[0])).dot(normal) < 0.0 {
            normal = -normal;
        }
        // Gradient weights of the linear interpolant on triangle (e0, e1, wing), projected
        // on the normal.
        let normal_slope = |wing: u32| -> Option<[f64; 3]> {
            let m = DMat2::from_cols(p(e[1]) - p(e[0]), p(wing) - p(e[0]));
            if m.determinant().abs() < 1e-12 * along.length_squared() {
                return None;
            }
            let inverse_t = m.inverse().transpose();
            let (w1, w2) = (inverse_t.col(0).dot(normal), inverse_t.col(1).dot(normal));
            Some([-w1 - w2, w1, w2])
        };
        let (s0, s1) = (normal_slope(wings[0])?, normal_slope(wings[1])?);
        // J over (e0, e1, wing0, wing1).
        let jump = [(e[0], s1[0] - s0[0]), (e[1], s1[1] - s0[1]), (wings[0], -s0[2]), (wings[1], s1[2])];
        // J of ½ Hᵢⱼ uᵢuⱼ (u from the edge's midpoint; J ignores linear terms), per unit
        // Voigt component of H.
        let midpoint = 0.5 * (p(e[0]) + p(e[1]));
        let mut jump_of_hessian = [0.0; 3];
        for &(v, j) in &jump {
            let u = p(v) - midpoint;
            jump_of_hessian[0] += j * 0.5 * u.x * u.x;
            jump_of_hessian[1] += j * 0.5 * u.y * u.y;
            jump_of_hessian[2] += j * u.x * u.y;
        }
        let mut vertices = patch.vertices.clone();
        let mut stencil: Vec<f64> = patch.weights.iter().map(|w| -(0..3).map(|i| jump_of_hessian[i] * w[i]).sum::<f64>()).collect();
        for &(h, j) in &jump {
            match vertices.iter().position(|&v| v == h) {
                Some(i) => stencil[i] += j,
                None => {
                    vertices.push(h);
                    stencil.push(j);
                }
            }
        }
        let centroid = |wing: u32| (p(e[0]) + p(e[1]) + p(wing)) / 3.0;
        let distance = (centroid(wings[1]) - centroid(wings[0])).dot(normal);
        let area = |wing: u32| 0.5 * along.perp_dot(p(wing) - p(e[0])).abs();
        let weight = 0.5 * (area(wings[0]) + area(wings[1])) / 3.0 / (distance * distance);
        Some(Self { vertices, stencil, normal, weight })
    }

    /// Its stiffness: β B_m A/(2d²).
    fn stiffness(&self, bending: &BendingStiffness) -> f64 {
        HINGE_STABILIZATION * bending.rigidity_at(self.normal.to_angle()) * self.weight
    }
}

/// β, the hinges' share of the full hinge rigidity.
const HINGE_STABILIZATION: f64 = 1.0;

/// Weights c_v (2-vectors) such that Σ_v c_v f_v is the gradient at `midpoint` of the
/// least-squares quadratic through the values f_v at the vertices around `edge`; exact for
/// quadratics. The neighbourhood grows ring by ring until the fit is well posed (near
/// corners one ring lies on two lines, which no quadratic fit can resolve).
fn edge_gradient_stencil(
    mesh: &Mesh,
    vertex_triangles: &[Vec<u32>],
    warp: &[DVec2],
    edge: [u32; 2],
    midpoint: DVec2,
    scale: f64,
    usable: impl Fn(u32) -> bool,
) -> Option<Vec<(u32, DVec2)>> {
    let mut points: Vec<u32> = edge.to_vec();
    for _ring in 0..3 {
        let mut grown = points.clone();
        for &v in &points {
            for &t in &vertex_triangles[v as usize] {
                grown.extend_from_slice(&mesh.triangles[t as usize]);
            }
        }
        grown.retain(|&v| usable(v));
        grown.sort_unstable();
        grown.dedup();
        points = grown;
        if let Some(stencil) = quadratic_gradient_weights(&points, warp, midpoint, scale) {
            return Some(stencil);
        }
    }
    None
}

/// Least-squares fit of f ≈ c0 + c1 u + c2 v + c3 u² + c4 uv + c5 v² with (u, v) the
/// offsets from `midpoint` over `scale`, weighted towards near points; returns the weights
/// of each point's value in (c1, c2)/scale. None if the fit is ill-posed.
fn quadratic_gradient_weights(points: &[u32], warp: &[DVec2], midpoint: DVec2, scale: f64) -> Option<Vec<(u32, DVec2)>> {
    if points.len() < 6 {
        return None;
    }
    let rows: Vec<([f64; 6], f64)> = points
        .iter()
        .map(|&v| {
            let d = (warp[v as usize] - midpoint) / scale;
            // Near points count more, so the fit is as local as the data allow.
            let weight = 1.0 / (1.0 + d.length_squared());
            ([1.0, d.x, d.y, d.x * d.x, d.x * d.y, d.y * d.y], weight)
        })
        .collect();
    let mut normal = [[0.0f64; 6]; 6];
    for (r, w) in &rows {
        for i in 0..6 {
            for j in 0..6 {
                normal[i][j] += w * r[i] * r[j];
            }
        }
    }
    let inverse = invert_spd6(normal)?;
    Some(
        points
            .iter()
            .zip(&rows)
            .map(|(&v, (r, w))| {
                let coefficient = |row: usize| (0..6).map(|j| inverse[row][j] * r[j]).sum::<f64>() * w;
                (v, DVec2::new(coefficient(1), coefficient(2)) / scale)
            })
            .collect(),
    )
}

/// Inverse of a symmetric positive definite 6×6 matrix by Cholesky; None when a pivot is
/// below 1e-4 of the largest diagonal entry. Such a fit is nearly ill-posed (its points lie
/// close to a conic, as happens near corners of irregular meshes): it would still invert,
/// but with weights so large that the bending matrix gained eigenvalues a million times too
/// high (explicit steps 100× too small, stiff Newton systems). The caller then grows the
/// neighbourhood instead.
// Index loops are the plain statement of a 6×6 Cholesky solve.
#[allow(clippy::needless_range_loop)]
fn invert_spd6(a: [[f64; 6]; 6]) -> Option<[[f64; 6]; 6]> {
    let mut l = [[0.0f64; 6]; 6];
    let largest = (0..6).map(|i| a[i][i]).fold(0.0, f64::max);
    for i in 0..6 {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s <= 1e-4 * largest {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut inverse = [[0.0f64; 6]; 6];
    for col in 0..6 {
        // Solve L y = e_col, then Lᵀ x = y.
        let mut y = [0.0f64; 6];
        for i in 0..6 {
            let rhs = if i == col { 1.0 } else { 0.0 };
            y[i] = (rhs - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
        }
        for i in (0..6).rev() {
            inverse[i][col] = (y[i] - (i + 1..6).map(|k| l[k][i] * inverse[k][col]).sum::<f64>()) / l[i][i];
        }
    }
    Some(inverse)
}

/// One triangle's bending stencil: its Hessian x_,ij in Voigt order (xx, yy, xy) is
/// Σ_a weights[a] x_{vertices[a]}.
#[derive(Debug, Clone)]
struct BendingPatch {
    vertices: Vec<u32>,
    weights: Vec<[f64; 3]>,
    /// Rest area, m².
    area: f64,
    /// Whether the triangle has a neighbour across each edge.
    interior: bool,
}

impl BendingPatch {
    fn hessian(&self, x: &[DVec3]) -> [DVec3; 3] {
        let mut h = [DVec3::ZERO; 3];
        for (v, w) in self.vertices.iter().zip(&self.weights) {
            for i in 0..3 {
                h[i] += w[i] * x[*v as usize];
            }
        }
        h
    }
}

/// Linear bending energy density ½ Σ_ij D_ij h_i·h_j of a triangle with Hessian `h`, J/m².
fn linear_bending_density(stiffness: &BendingStiffness, h: &[DVec3; 3]) -> f64 {
    let d = stiffness.voigt();
    let mut e = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            e += d[i][j] * h[i].dot(h[j]);
        }
    }
    0.5 * e
}

/// Each triangle's (slot, value) share of Q, for re-weighting by secant factors.
fn triangle_contributions(q: &ScalarCsr, patches: &[BendingPatch], stiffness: &BendingStiffness) -> Vec<Vec<(u32, f64)>> {
    let d = stiffness.voigt();
    patches
        .iter()
        .map(|p| {
            let mut out = Vec::with_capacity(p.vertices.len() * p.vertices.len());
            for (a, wa) in p.vertices.iter().zip(&p.weights) {
                for (b, wb) in p.vertices.iter().zip(&p.weights) {
                    let mut e = 0.0;
                    for i in 0..3 {
                        for j in 0..3 {
                            e += wa[i] * d[i][j] * wb[j];
                        }
                    }
                    out.push((q.slot(*a, *b) as u32, p.area * e));
                }
            }
            out
        })
        .collect()
}

/// The hinges' part of the bending Hessian, Σ k sᵀs, on the pattern of `q`.
fn hinge_matrix_values(q: &ScalarCsr, hinges: &[Hinge], stiffness: &BendingStiffness) -> Vec<f64> {
    let mut values = vec![0.0; q.values.len()];
    for hinge in hinges {
        let k = hinge.stiffness(stiffness);
        for (a, sa) in hinge.vertices.iter().zip(&hinge.stencil) {
            for (b, sb) in hinge.vertices.iter().zip(&hinge.stencil) {
                values[q.slot(*a, *b)] += k * sa * sb;
            }
        }
    }
    values
}

/// Q = Σ_T A_T Wᵀ 𝔻 W + Σ_hinges k sᵀs, the constant Hessian of the quadratic bending
/// energy, and the hinges' part of its values (unsymmetrised).
fn bending_matrix(n: usize, patches: &[BendingPatch], hinges: &[Hinge], stiffness: &BendingStiffness) -> (ScalarCsr, Vec<f64>) {
    let d = stiffness.voigt();
    let pairs = patches.iter().flat_map(|p| {
        p.vertices.iter().flat_map(move |&a| p.vertices.iter().map(move |&b| (a, b))).collect::<Vec<_>>()
    });
    // The hinges add no entries: a half hinge's points are its triangle's patch and the
    // edge's two wings, which that patch already holds (the shared edge's fit spans a ring
    // around the edge, both wings included).
    let mut q = ScalarCsr::with_pattern(n, pairs);
    for BendingPatch { vertices: vs, weights: ws, area, .. } in patches {
        for (a, wa) in vs.iter().zip(ws) {
            for (b, wb) in vs.iter().zip(ws) {
                let mut e = 0.0;
                for i in 0..3 {
                    for j in 0..3 {
                        e += wa[i] * d[i][j] * wb[j];
                    }
                }
                let slot = q.slot(*a, *b);
                q.values[slot] += area * e;
            }
        }
    }
    let hinge_values = hinge_matrix_values(&q, hinges, stiffness);
    for (value, h) in q.values.iter_mut().zip(&hinge_values) {
        *value += h;
    }
    symmetrize_with_zero_row_sums(&mut q);
    (q, hinge_values)
}

/// Makes `q` exactly symmetric, with rows that sum to exactly zero (the energy ignores
/// translations), so that round-off in the weights cannot leave a net force that drifts the
/// momentum.
fn symmetrize_with_zero_row_sums(q: &mut ScalarCsr) {
    let n = q.vertex_count();
    let entries: Vec<(u32, u32, f64)> = q.entries().collect();
    for &(a, b, v) in &entries {
        if a < b {
            let mean = 0.5 * (v + q.values[q.slot(b, a)]);
            let (ab, ba) = (q.slot(a, b), q.slot(b, a));
            q.values[ab] = mean;
            q.values[ba] = mean;
        }
    }
    for row in 0..n as u32 {
        let off_diagonal: f64 = q.entries_of_row(row).filter(|&(col, _)| col != row).map(|(_, v)| v).sum();
        let diagonal = q.slot(row, row);
        q.values[diagonal] = -off_diagonal;
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sim::curve::PiecewiseLinear;
    use crate::sim::mesh::Pattern;

    pub(crate) fn test_fabric() -> Fabric {
        Fabric {
            areal_density: 0.2,
            thickness: 3e-4,
            tensile_warp: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 10.0], [0.05, 200.0]]).unwrap(),
            tensile_weft: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.02, 12.0], [0.06, 150.0]]).unwrap(),
            shear_modulus: 30.0,
            poisson_warp: 0.2,
            bending_warp: 1.2e-5,
            bending_weft: 0.8e-5,
            bending_bias: None,
            bending_curve: None,
        }
    }

    fn deformed(model: &Model, f: impl Fn(DVec2) -> DVec3) -> Vec<DVec3> {
        model.rest.iter().map(|&p| f(p)).collect()
    }

    #[test]
    fn forces_are_minus_the_energy_gradient() {
        let mut nonlinear = test_fabric();
        // Stiffening, then softening moment–curvature knees (initial slope = bending_warp).
        nonlinear.bending_curve =
            Some(PiecewiseLinear::new_material(&[[0.0, 0.0], [2.0, 2.4e-5], [5.0, 1.2e-4], [9.0, 1.5e-4]]).unwrap());
        for (pattern, fabric) in [(Pattern::Alternating, test_fabric()), (Pattern::Jittered, test_fabric()), (Pattern::Alternating, nonlinear)] {
            let mesh = Mesh::rectangle(0.04, 0.03, 0.01, pattern, 3).unwrap();
            let model = Model::new(&mesh, &fabric, 0.4, PhysicsOptions::default()).unwrap();
            let x = deformed(&model, |p| {
                DVec3::new(p.x * 1.02 + 0.003 * p.y, p.y * 0.99, 0.2 * p.x * p.x + 0.1 * p.x * p.y + 0.001 * (p.y * 300.0).sin())
            });
            let mut f = vec![DVec3::ZERO; x.len()];
            model.forces(&x, &mut f);
            let h = 1e-7;
            for v in [0, 5, 11, x.len() - 1] {
                for c in 0..3 {
                    let mut xp = x.clone();
                    let mut xm = x.clone();
                    xp[v][c] += h;
                    xm[v][c] -= h;
                    let numeric = -(model.potential_energy(&xp) - model.potential_energy(&xm)) / (2.0 * h);
                    let scale = f.iter().map(|q| q.length()).fold(0.0, f64::max);
                    assert!((numeric - f[v][c]).abs() < 1e-5 * scale, "{pattern:?} v{v} c{c}: {numeric} vs {}", f[v][c]);
                }
            }
        }
    }

    /// A compressed and sheared state in which many edges carry compression: the exact
    /// in-plane Hessian must match the forces' derivative there, and the bounded one must
    /// stay positive semi-definite once the allowance is added to its diagonal.
    #[test]
    fn compressed_edges_exact_and_bounded_stiffness() {
        let mesh = Mesh::rectangle(0.03, 0.02, 0.005, Pattern::Regular, 0).unwrap();
        let opts = PhysicsOptions { bending: false, gravity: DVec3::ZERO, ..Default::default() };
        let model = Model::new(&mesh, &test_fabric(), 0.0, opts).unwrap();
        let x = deformed(&model, |p| DVec3::new(0.97 * p.x + 0.05 * p.y, 1.01 * p.y, 0.002 * (80.0 * p.x).sin()));
        let n = x.len();
        let direction: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), (i as f64 * 0.7).cos(), (i as f64 * 1.3).sin())).collect();
        let mut k = model.stiffness_matrix();
        model.assemble_membrane_stiffness_within(&x, &mut k, CompressedEdges::Exact);
        let mut kd = vec![DVec3::ZERO; n];
        k.multiply(&direction, &mut kd);
        let h = 1e-8;
        let xp: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a + h * *d).collect();
        let xm: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a - h * *d).collect();
        let (mut fp, mut fm) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        model.forces(&xp, &mut fp);
        model.forces(&xm, &mut fm);
        for i in 0..n {
            let numeric = -(fp[i] - fm[i]) / (2.0 * h);
            assert!((numeric - kd[i]).length() < 1e-4 * (1.0 + kd[i].length()), "vertex {i}: {numeric} vs {}", kd[i]);
        }
        // The dropped term matters here: without it the product differs.
        let mut dropped = model.stiffness_matrix();
        model.assemble_membrane_stiffness(&x, &mut dropped);
        let mut dd = vec![DVec3::ZERO; n];
        dropped.multiply(&direction, &mut dd);
        let gap: f64 = dd.iter().zip(&kd).map(|(a, b)| (*a - *b).length()).sum();
        assert!(gap > 1e-3 * kd.iter().map(|v| v.length()).sum::<f64>(), "no compressed edges in the test state");
        // Bounded by an allowance far below the compression: dᵀ(K + A)d ≥ 0 for out-of-plane
        // and in-plane directions alike.
        let allowance = vec![1.0; n];
        let mut bounded = model.stiffness_matrix();
        model.assemble_membrane_stiffness_within(&x, &mut bounded, CompressedEdges::Within(&allowance));
        for seed in 0..20 {
            let d: Vec<DVec3> = (0..n)
                .map(|i| {
                    let t = (i * 31 + seed * 17) as f64;
                    DVec3::new((t * 0.37).sin(), (t * 0.91).cos(), (t * 1.7).sin() * 3.0)
                })
                .collect();
            let mut bd = vec![DVec3::ZERO; n];
            bounded.multiply(&d, &mut bd);
            let quadratic: f64 = (0..n).map(|i| d[i].dot(bd[i]) + allowance[i] * d[i].length_squared()).sum();
            assert!(quadratic >= -1e-12, "seed {seed}: {quadratic}");
        }
    }

    #[test]
    fn stiffness_matches_force_derivative_in_tension() {
        let mesh = Mesh::rectangle(0.03, 0.02, 0.01, Pattern::Regular, 0).unwrap();
        let opts = PhysicsOptions { bending: false, gravity: DVec3::ZERO, ..Default::default() };
        let model = Model::new(&mesh, &test_fabric(), 0.0, opts).unwrap();
        // Biaxial stretch along the warp and weft of a right-triangle grid: no edge carries
        // compression, so the projected Hessian equals the exact one.
        let x = deformed(&model, |p| DVec3::new(1.03 * p.x, 1.025 * p.y, 0.0));
        let mut k = model.stiffness_matrix();
        model.assemble_membrane_stiffness(&x, &mut k);
        let direction: Vec<DVec3> = (0..x.len()).map(|i| DVec3::new((i as f64).sin(), (i as f64 * 0.7).cos(), 0.3)).collect();
        let mut kd = vec![DVec3::ZERO; x.len()];
        k.multiply(&direction, &mut kd);
        let h = 1e-8;
        let xp: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a + h * *d).collect();
        let xm: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a - h * *d).collect();
        let (mut fp, mut fm) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
        model.forces(&xp, &mut fp);
        model.forces(&xm, &mut fm);
        for i in 0..x.len() {
            let numeric = -(fp[i] - fm[i]) / (2.0 * h);
            assert!((numeric - kd[i]).length() < 1e-4 * (1.0 + kd[i].length()), "vertex {i}: {numeric} vs {}", kd[i]);
        }
    }

    #[test]
    fn rigid_motion_costs_no_energy() {
        let mesh = Mesh::rectangle(0.05, 0.03, 0.01, Pattern::Equilateral, 0).unwrap();
        let opts = PhysicsOptions { gravity: DVec3::ZERO, ..Default::default() };
        let model = Model::new(&mesh, &test_fabric(), 0.7, opts).unwrap();
        let rotation = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let x = deformed(&model, |p| rotation * DVec3::new(p.x, p.y, 0.0) + DVec3::new(1.0, -2.0, 0.5));
        let (membrane, bending) = model.elastic_energy(&x);
        // Round-off only: a strain of 1e-6 alone would store about 1e-12 J here.
        assert!(membrane.abs() < 1e-13, "{membrane}");
        assert!(bending.abs() < 1e-13, "{bending}");
    }

    /// A cylindrical bend of curvature κ in direction θ stores ½ B_θ κ² per unit area
    /// (eq. 3). The discrete energy must converge to it on every triangulation and warp angle.
    #[test]
    fn cylindrical_bending_energy_converges_to_eq3() {
        let fabric = test_fabric();
        let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
        let kappa = 8.0;
        for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
            for (warp_deg, bend_deg) in [(0.0, 0.0), (30.0, 0.0), (0.0, 90.0), (45.0, 20.0)] {
                let mut errors = Vec::new();
                for h in [0.01, 0.005] {
                    let mesh = Mesh::rectangle(0.1, 0.1, h, pattern, 11).unwrap();
                    let model = Model::new(&mesh, &fabric, f64::to_radians(warp_deg), opts).unwrap();
                    let dir = DVec2::from_angle(f64::to_radians(bend_deg));
                    // Isometric roll: arclength s along `dir` wraps onto a circle of radius 1/κ.
                    let x = deformed(&model, |p| {
                        let s = p.dot(dir);
                        let t = p.dot(dir.perp());
                        let along = dir * ((kappa * s).sin() / kappa) + dir.perp() * t;
                        DVec3::new(along.x, along.y, (1.0 - (kappa * s).cos()) / kappa)
                    });
                    // Free edges carry no moment (m_νν = 0), which a uniform roll violates,
                    // so compare on the triangles that have all three neighbours.
                    let energies = model.triangle_bending_energies(&x);
                    let interior: Vec<usize> = (0..energies.len()).filter(|&t| model.is_interior_triangle(t)).collect();
                    let bending: f64 = interior.iter().map(|&t| energies[t]).sum();
                    let area: f64 = interior.iter().map(|&t| mesh.signed_area(t)).sum();
                    let theta = f64::to_radians(bend_deg - warp_deg);
                    let exact = 0.5 * model.bending_stiffness.rigidity_at(theta) * kappa * kappa * area;
                    errors.push(((bending - exact) / exact).abs());
                }
                assert!(errors[1] < 0.01, "{pattern:?} warp {warp_deg} bend {bend_deg}: errors {errors:?}");
                assert!(errors[1] <= errors[0] + 1e-4, "{pattern:?}: error must not grow on refinement {errors:?}");
            }
        }
    }

    /// The hinges read zero on every quadratic surface (whose curvature each triangle's fitted
    /// Hessian reproduces), on any triangulation and warp angle, so they leave constant
    /// curvatures to the fitted stencils.
    #[test]
    fn hinges_vanish_on_quadratic_surfaces() {
        let f = |p: DVec2| 0.3 + 2.0 * p.x - p.y + 40.0 * p.x * p.x - 25.0 * p.x * p.y + 10.0 * p.y * p.y;
        for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
            let mesh = Mesh::rectangle(0.1, 0.08, 0.01, pattern, 5).unwrap();
            let (_, hinges) = bending_patches(&mesh, 0.4, &vec![false; mesh.rest.len()]).unwrap();
            assert!(hinges.len() > 100, "{pattern:?}: {} hinges", hinges.len());
            // A kink as sharp as this surface's curvature (about 100 /m) over an edge
            // (0.01 m) would read about 1.
            for h in &hinges {
                let reading: f64 = h.vertices.iter().zip(&h.stencil).map(|(&v, s)| s * f(mesh.rest[v as usize])).sum();
                assert!(reading.abs() < 1e-9, "{pattern:?}: hinge reads {reading:e}");
            }
            // And a zigzag does register.
            let zigzag = |v: u32| if (mesh.rest[v as usize].x / 0.01).round() as i64 % 2 == 0 { 0.001 } else { -0.001 };
            let loudest = hinges.iter().map(|h| h.vertices.iter().zip(&h.stencil).map(|(&v, s)| s * zigzag(v)).sum::<f64>().abs()).fold(0.0, f64::max);
            assert!(loudest > 0.05, "{pattern:?}: a 1 mm zigzag reads at most {loudest:e}");
        }
    }

    /// Smallest μ with Q v = μ (L M⁻¹ L) v over deflections that vanish within two rings of
    /// the edge, against c_min: the continuum plate's 2E = ∫ D:∇∇w:∇∇w ≥ c_min ∫(Δw)² for
    /// such w (c_min the smallest eigenvalue of 𝔻 on (w_xx, w_yy, √2 w_xy)), and L M⁻¹ L is
    /// ∫(Δw)² with the cotangent Laplacian L and lumped areas M.
    fn softest_deflection(mesh: &Mesh, model: &Model) -> f64 {
        let n = mesh.rest.len();
        let mut near_edge = vec![false; n];
        let mut owners: HashMap<[u32; 2], u32> = HashMap::new();
        for tri in &mesh.triangles {
            for k in 0..3 {
                *owners.entry(sorted_edge(tri[(k + 1) % 3], tri[(k + 2) % 3])).or_default() += 1;
            }
        }
        for (e, count) in &owners {
            if *count == 1 {
                e.iter().for_each(|&v| near_edge[v as usize] = true);
            }
        }
        for _ring in 0..2 {
            let grown = near_edge.clone();
            for tri in &mesh.triangles {
                if tri.iter().any(|&v| grown[v as usize]) {
                    tri.iter().for_each(|&v| near_edge[v as usize] = true);
                }
            }
        }
        let inner: Vec<usize> = (0..n).filter(|&v| !near_edge[v]).collect();
        let mut index = vec![usize::MAX; n];
        inner.iter().enumerate().for_each(|(i, &v)| index[v] = i);
        let m = inner.len();
        let mut laplacian = faer::Mat::<f64>::zeros(m, m);
        for tri in &mesh.triangles {
            for k in 0..3 {
                let (o, a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize, tri[(k + 2) % 3] as usize);
                let (ea, eb) = (mesh.rest[a] - mesh.rest[o], mesh.rest[b] - mesh.rest[o]);
                let w = 0.5 * ea.dot(eb) / ea.perp_dot(eb).abs();
                for (p, q) in [(a, b), (b, a)] {
                    if index[p] != usize::MAX {
                        laplacian[(index[p], index[p])] += w;
                        if index[q] != usize::MAX {
                            laplacian[(index[p], index[q])] -= w;
                        }
                    }
                }
            }
        }
        use faer::linalg::solvers::DenseSolveCore;
        let inverse = laplacian.llt(faer::Side::Lower).expect("Dirichlet Laplacian").inverse();
        let q = model.bending_newton_matrix(&deformed(model, |p| p.extend(0.0))).unwrap();
        let mut qm = faer::Mat::<f64>::zeros(m, m);
        for (a, b, v) in q.entries() {
            let (i, j) = (index[a as usize], index[b as usize]);
            if i != usize::MAX && j != usize::MAX {
                qm[(i, j)] = v;
            }
        }
        let root_area = faer::Mat::<f64>::from_fn(m, m, |i, j| if i == j { model.vertex_area[inner[i]].sqrt() } else { 0.0 });
        let s = &root_area * &inverse * &qm * &inverse * &root_area;
        let smallest = s.self_adjoint_eigenvalues(faer::Side::Lower).unwrap()[0];
        let d = model.bending_stiffness;
        let c_min = (0.5 * (d.d11 + d.d22) - (0.25 * (d.d11 - d.d22).powi(2) + d.d12 * d.d12).sqrt()).min(2.0 * d.d66);
        smallest / c_min
    }

    /// No deflection is much softer than a plate: the softest one, relative to c_min, is at
    /// least a quarter of the continuum's bound of 1 on every triangulation (a discrete
    /// operator may be softer at the mesh scale; the fitted stencils alone reach 0.04–0.14
    /// there, with the hinges the softest deflection is the smooth one, at 9–12).
    #[test]
    fn no_mesh_scale_deflection_escapes_bending() {
        let fabric = test_fabric();
        let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
        for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
            let mesh = Mesh::rectangle(0.12, 0.1, 0.005, pattern, 11).unwrap();
            let model = Model::new(&mesh, &fabric, 0.3, opts).unwrap();
            let softest = softest_deflection(&mesh, &model);
            assert!(softest > 0.25, "{pattern:?}: the softest deflection has {softest:.3} of the plate's bending energy");
        }
    }

    /// A Gaussian bump w = a·exp(−r²/σ²) four edges wide (σ = 4h) stores within 10 % of the
    /// plate energy ½ ∫ D:∇∇w:∇∇w (computed from the exact Hessian by quadrature), on every
    /// triangulation; the fitted stencils alone store 14 % too little there.
    #[test]
    fn smooth_bumps_bend_as_a_plate() {
        let fabric = test_fabric();
        let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
        let (warp, h, sigma, a) = (0.3f64, 0.005, 0.02, 0.001);
        let centre = DVec2::new(0.1, 0.1);
        for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
            let mesh = Mesh::rectangle(0.2, 0.2, h, pattern, 11).unwrap();
            let model = Model::new(&mesh, &fabric, warp, opts).unwrap();
            let x = deformed(&model, |p| p.extend(a * (-(p - centre).length_squared() / (sigma * sigma)).exp()));
            let d = model.bending_stiffness.voigt();
            let (n, cell) = (400, 0.2 / 400.0);
            let rotation = DMat2::from_angle(-warp);
            let mut plate = 0.0;
            for i in 0..n {
                for j in 0..n {
                    let p = DVec2::new((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell) - centre;
                    let e = a * (-p.length_squared() / (sigma * sigma)).exp() / sigma.powi(4);
                    let hessian = DMat2::from_cols(
                        e * DVec2::new(4.0 * p.x * p.x - 2.0 * sigma * sigma, 4.0 * p.x * p.y),
                        e * DVec2::new(4.0 * p.x * p.y, 4.0 * p.y * p.y - 2.0 * sigma * sigma),
                    );
                    // In the warp frame.
                    let hw = rotation * hessian * rotation.transpose();
                    let k = [hw.x_axis.x, hw.y_axis.y, hw.y_axis.x];
                    plate += 0.5 * (0..3).map(|r| (0..3).map(|c| d[r][c] * k[r] * k[c]).sum::<f64>()).sum::<f64>() * cell * cell;
                }
            }
            let ratio = model.bending_energy(&x) / plate;
            assert!((ratio - 1.0).abs() < 0.1, "{pattern:?}: the bump stores {ratio:.3} of the plate's energy");
        }
    }
}
