//! The fixed part of a simulation: rest geometry, masses, material laws, topology,
//! constraints and loads. Positions and velocities live in [`State`](crate::sim::State).
//!
//! Energies and their gradients (forces) and Hessians are all here, so every integrator
//! sees the same conservative model. Everything that a scene switches off (membrane,
//! bending, gravity) is absent from the model, not multiplied by zero.

mod bending;
mod charts;
mod membrane;
mod motion;
mod sewing;
mod stability;
#[cfg(test)]
pub(crate) mod tests;

pub use bending::curvature_magnitude;
pub use membrane::CompressedEdges;
pub use motion::Motion;
pub use sewing::{PanelSurface, Sewing, seam_bands};

use crate::sim::contact::{Cloth, ContactModel};
use crate::sim::linalg::{BlockCsr, ScalarCsr};
use crate::sim::material::{BendingStiffness, Fabric, FabricError, MembraneLaw};
use crate::sim::mesh::{Mesh, MeshError};
use bending::{BendingPatch, NonlinearBending};
use glam::{DMat3, DVec2, DVec3};
use membrane::{RosetteTriangle, rosette};
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
        Self { membrane: true, bending: true, gravity: DVec3::new(0.0, 0.0, -crate::physics::STANDARD_GRAVITY), damping: 0.0 }
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
    /// Warp direction in the sample plane, radians from the sample's x axis (zero for a
    /// cloth of panels, whose triangles carry their own frames).
    pub warp_angle: f64,
    /// A cloth of panels ([`Model::from_panels`]): each triangle's corners in its own warp
    /// frame (x along the warp), m. None for a flat specimen, whose frame is `rest` turned
    /// by `warp_angle`.
    pub frames: Option<Vec<[DVec2; 3]>>,
    /// Where the weave is drawn, per vertex, m, for a cloth of panels: each panel in its
    /// own warp frame (`PanelSurface::texture`). None: `rest` turned by `warp_angle`.
    pub texture: Option<Vec<DVec2>>,
    /// Rest length of each of `edges` for a cloth of panels, m (None: from `rest`).
    pub edge_rest_lengths: Option<Vec<f64>>,
    /// Zero-length springs that close seams and hold attachments (empty unless sewn).
    pub sewing: Sewing,
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

/// The rest geometry a model is built from: per-vertex sample-plane positions (for a cloth
/// of panels, the pattern coordinates drawn and exported), triangles, their rest areas and
/// the mean rest edge length.
struct RestGeometry<'a> {
    rest: &'a [DVec2],
    triangles: &'a [[u32; 3]],
    areas: &'a [f64],
    mean_edge_length: f64,
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
        let areas: Vec<f64> = (0..mesh.triangles.len()).map(|t| mesh.signed_area(t)).collect();
        let corners = |t: usize| mesh.triangles[t].map(|v| to_warp_frame(mesh.rest[v as usize], warp_angle));
        let geometry = RestGeometry { rest: &mesh.rest, triangles: &mesh.triangles, areas: &areas, mean_edge_length: mesh.mean_edge_length() };
        Self::build(geometry, corners, None, &[], fabric, warp_angle, options)
    }

    /// Builds a model of a cloth of flat panels (a garment): each triangle keeps its own
    /// rest shape and warp frame (`surface.corners`), so that panels cut on different grains
    /// and joined along seams are one surface. `seam_pairs` are the vertex pairs sewing
    /// springs may join (their stiffness starts at zero; see [`Sewing`]).
    pub fn from_panels(surface: &PanelSurface, seam_pairs: &[[u32; 2]], fabric: &Fabric, options: PhysicsOptions) -> Result<Self, ModelError> {
        surface.validate()?;
        let areas: Vec<f64> = surface.corners.iter().map(|c| 0.5 * (c[1] - c[0]).perp_dot(c[2] - c[0])).collect();
        let geometry = RestGeometry { rest: &surface.pattern, triangles: &surface.triangles, areas: &areas, mean_edge_length: surface.mean_edge_length() };
        let mut model = Self::build(geometry, |t| surface.corners[t], Some(surface.corners.clone()), seam_pairs, fabric, 0.0, options)?;
        model.edge_rest_lengths = Some(surface.edge_rest_lengths(&model.edges));
        model.texture = Some(surface.texture.clone());
        model.sewing.pairs = seam_pairs.to_vec();
        Ok(model)
    }

    fn build(
        geometry: RestGeometry,
        corners: impl Fn(usize) -> [DVec2; 3],
        frames: Option<Vec<[DVec2; 3]>>,
        extra_pairs: &[[u32; 2]],
        fabric: &Fabric,
        warp_angle: f64,
        options: PhysicsOptions,
    ) -> Result<Self, ModelError> {
        fabric.validate()?;
        if !(options.damping >= 0.0 && options.damping.is_finite()) {
            return Err(ModelError::BadDamping(options.damping));
        }
        let RestGeometry { rest, triangles, areas, mean_edge_length } = geometry;
        let n = rest.len();
        let mut vertex_area = vec![0.0; n];
        for (tri, &a) in triangles.iter().zip(areas) {
            for &v in tri {
                vertex_area[v as usize] += a / 3.0;
            }
        }
        let mass = vertex_area.iter().map(|a| a * fabric.areal_density).collect();
        let mut edge_set: Vec<[u32; 2]> =
            triangles.iter().flat_map(|t| (0..3).map(move |k| sorted_edge(t[(k + 1) % 3], t[(k + 2) % 3]))).collect();
        edge_set.sort_unstable();
        edge_set.dedup();

        let stiffness_pattern = BlockCsr::with_pattern(n, edge_set.iter().chain(extra_pairs).map(|e| (e[0], e[1])));
        let membrane_law = if options.membrane { Some(MembraneLaw::new(fabric)?) } else { None };
        let rosettes = if options.membrane {
            triangles.iter().enumerate().map(|(t, tri)| rosette(corners(t), areas[t], *tri, &stiffness_pattern)).collect()
        } else {
            Vec::new()
        };
        let bending_stiffness = BendingStiffness::new(fabric)?;
        // Filled in by `build_bending` below when bending is on.
        let bending_curve = fabric
            .bending_curve
            .clone()
            .filter(|_| options.bending)
            .map(NonlinearBending::new);
        let mut model = Self {
            options,
            rest: rest.to_vec(),
            triangles: triangles.to_vec(),
            mass,
            vertex_area,
            warp_angle,
            texture: None,
            frames,
            edge_rest_lengths: None,
            sewing: Sewing::default(),
            mean_edge_length,
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

    /// What contact reads of the cloth.
    pub fn cloth(&self) -> Cloth<'_> {
        Cloth { triangles: &self.triangles, edges: &self.edges, fixed: &self.fixed, mass: &self.mass, mean_edge_length: self.mean_edge_length, seam_bands: &self.sewing.bands, welded: &self.sewing.welded }
    }

    /// The texture space: per-vertex coordinates and the warp's angle from their x axis
    /// (radians), the weave drawn along the warp; what screenshots and exports use.
    pub fn texture_space(&self) -> (&[DVec2], f64) {
        match &self.texture {
            Some(texture) => (texture, 0.0),
            None => (&self.rest, self.warp_angle),
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Declares the vertices of a clamp: a region held rigidly (its vertices must also be
    /// pinned or driven together). Bending stencils are rebuilt so that they do not fit
    /// across the clamp line (see `bending_patches`).
    pub fn set_clamped_region(&mut self, rigid: &[bool]) -> Result<(), ModelError> {
        if self.options.bending { self.build_bending(rigid) } else { Ok(()) }
    }

    /// Total potential energy (elastic + gravity), J.
    pub fn potential_energy(&self, x: &[DVec3]) -> f64 {
        let mut energy = self.membrane_energy(x);
        energy += self.bending_energy(x);
        if self.sewing.is_active() {
            energy += self.sewing.energy(x);
        }
        if self.options.gravity != DVec3::ZERO {
            let g = self.options.gravity;
            energy -= sum_of(x.len(), |i| self.mass[i] * g.dot(x[i]));
        }
        energy
    }

    /// Elastic energy only (membrane, bending), J.
    pub fn elastic_energy(&self, x: &[DVec3]) -> (f64, f64) {
        (self.membrane_energy(x), self.bending_energy(x))
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
        self.add_bending_forces(x, f);
        if self.sewing.is_active() {
            self.sewing.add_forces(x, f);
        }
    }

    /// Total conservative force −∇E into `f` (overwritten) and the potential energy E, J, from
    /// one pass over the elements: the same quantities as [`Model::forces`] and
    /// [`Model::potential_energy`], for the quasi-Newton step, which needs both at every trial.
    pub fn energy_and_forces(&self, x: &[DVec3], f: &mut [DVec3]) -> f64 {
        f.fill(DVec3::ZERO);
        let mut energy = 0.0;
        if self.options.gravity != DVec3::ZERO {
            let g = self.options.gravity;
            for ((fi, m), xi) in f.iter_mut().zip(&self.mass).zip(x) {
                *fi += *m * g;
                energy -= *m * g.dot(*xi);
            }
        }
        energy += self.add_membrane_energy_and_forces(x, f);
        energy += self.add_bending_energy_and_forces(x, f);
        if self.sewing.is_active() {
            self.sewing.add_forces(x, f);
            energy += self.sewing.energy(x);
        }
        energy
    }

    /// A zero matrix with the in-plane stiffness pattern.
    pub fn stiffness_matrix(&self) -> BlockCsr {
        self.stiffness_pattern.clone()
    }

    pub fn has_membrane(&self) -> bool {
        self.membrane_law.is_some()
    }

    /// The constant parts of the quasi-Newton step's matrices, scalar matrices acting alike
    /// on x, y and z on the mesh's one-ring pattern (the in-plane stiffness pattern's):
    /// the membrane's isotropic rest stiffness, and the bending matrix Q restricted to the
    /// one-ring, each entry dropped from Q added as |q| to both its diagonals. That
    /// restriction is at least Q (the difference is a sum of |q|(e_i ∓ e_j)(e_i ∓ e_j)ᵀ), so
    /// it is positive semi-definite and never softer than the bending it stands for, and its
    /// factor has a tenth of the fill of Q's two-ring stencil's (68 798 against 701 151
    /// entries on the 7 938-triangle sphere drop).
    pub fn quasi_newton_matrices(&self) -> (ScalarCsr, ScalarCsr) {
        let n = self.vertex_count();
        let mut membrane = ScalarCsr::with_pattern(n, self.edges.iter().map(|e| (e[0], e[1])));
        let mut bending = membrane.clone();
        self.add_isotropic_rest_stiffness(&mut membrane);
        if let Some(q) = &self.bending {
            for (r, c, v) in q.entries() {
                if r == c {
                    let slot = bending.slot(r, r);
                    bending.values[slot] += v;
                } else if let Some(slot) = bending.find(r, c) {
                    bending.values[slot] += v;
                } else {
                    let slot = bending.slot(r, r);
                    bending.values[slot] += v.abs();
                }
            }
        }
        (membrane, bending)
    }
}

/// Above this many triangles (or vertices) the per-element loops of forces, energies and
/// stiffness run on rayon's threads. Below it a loop takes tens of microseconds, about what
/// handing it to another thread costs.
const PARALLEL_TRIANGLES: usize = 4096;

/// From this many triangles (or vertices) up to [`PARALLEL_TRIANGLES`] a per-element map is
/// split in two halves, one on the team's thread, whose hand-off costs far less than
/// rayon's: on the tablecloth (3 200 triangles) a pass takes about a millisecond.
use crate::sim::team::LEAST_ITEMS as TEAM_TRIANGLES;

/// `f` of every item, in order, as two runs of results (the second empty where the pool
/// took them all): in two halves on the team below [`PARALLEL_TRIANGLES`] items, over
/// rayon's pool from there. The caller adds them up in order, so that its sums do not
/// depend on who computed what.
fn map_in_order<I: Sync, T: Send>(items: &[I], f: impl Fn(&I) -> T + Sync) -> [Vec<T>; 2] {
    use rayon::prelude::*;
    if items.len() >= PARALLEL_TRIANGLES {
        return [items.par_iter().map(&f).collect(), Vec::new()];
    }
    let (low, high) = items.split_at(items.len() / 2);
    let (low, high) = crate::sim::team::join(|| low.iter().map(&f).collect(), || high.iter().map(&f).collect());
    [low, high]
}

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

fn sorted_edge(a: u32, b: u32) -> [u32; 2] {
    if a < b { [a, b] } else { [b, a] }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
