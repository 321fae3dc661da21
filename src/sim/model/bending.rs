//! Bending (paper eq. 3): per-triangle curvature stencils from shared edge gradients, the
//! hinges that stiffen what the fits miss, the constant bending matrix Q, and nonlinear
//! bending by a measured moment–curvature curve.

use super::charts::{PanelCharts, Placement};
use super::{Model, ModelError, PARALLEL_TRIANGLES, TEAM_TRIANGLES, sorted_edge, sum_of, to_warp_frame};
use crate::sim::curve::PiecewiseLinear;
use crate::sim::linalg::ScalarCsr;
use crate::sim::material::BendingStiffness;
use crate::sim::mesh::{Mesh, MeshError};
use glam::{DMat2, DVec2, DVec3};
use std::collections::HashMap;

/// Nonlinear bending data: the warp moment–curvature curve and each triangle's
/// (slot, value) share of Q, re-weighted by secant factors into Newton's matrix.
#[derive(Debug, Clone)]
pub(super) struct NonlinearBending {
    curve: PiecewiseLinear,
    contributions: Vec<Vec<(u32, f64)>>,
    /// The hinges' part of Q (see [`Hinge`]), which stays linear.
    hinges: Option<ScalarCsr>,
}

impl NonlinearBending {
    /// The curve alone; `Model::build_bending` fills in the rest.
    pub(super) fn new(curve: PiecewiseLinear) -> Self {
        Self { curve, contributions: Vec::new(), hinges: None }
    }
}

impl Model {
    /// Adds the bending forces −∇E_b to `f`.
    pub(super) fn add_bending_forces(&self, x: &[DVec3], f: &mut [DVec3]) {
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


    /// Adds the bending forces to `f` and returns the bending energy, J (one pass over Q
    /// for linear bending).
    pub(super) fn add_bending_energy_and_forces(&self, x: &[DVec3], f: &mut [DVec3]) -> f64 {
        match (&self.bending, &self.bending_curve) {
            (Some(q), None) => subtract_quadratic_force_with_energy(q, x, f),
            _ => {
                self.add_bending_forces(x, f);
                self.bending_energy(x)
            }
        }
    }


    /// Builds the bending stencils, Q and (for nonlinear bending) each triangle's share of
    /// Q, with `rigid` marking clamped vertices.
    pub(super) fn build_bending(&mut self, rigid: &[bool]) -> Result<(), ModelError> {
        let (patches, hinges) = match &self.frames {
            None => {
                let mesh = Mesh { rest: self.rest.clone(), triangles: self.triangles.clone() };
                bending_patches(&mesh, self.warp_angle, rigid)?
            }
            Some(corners) => {
                let areas: Vec<f64> = corners.iter().map(|c| 0.5 * (c[1] - c[0]).perp_dot(c[2] - c[0])).collect();
                let rest = RestFrames::Panels { corners };
                stencils(&self.triangles, self.rest.len(), &areas, &rest, self.mean_edge_length, rigid)?
            }
        };
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


    /// Bending energy, J: ½ xᵀQx, or with a moment–curvature curve Σ_T A_T B_x Φ̂(κ_eq),
    /// where κ_eq = √(2ψ_lin/B_x) is the warp curvature that stores the triangle's linear
    /// energy density ψ_lin and Φ̂ is the curve's energy over its initial slope (so that a
    /// bend along the warp follows the measured moments exactly).
    pub(super) fn bending_energy(&self, x: &[DVec3]) -> f64 {
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
}

/// Curvature magnitude √(κ_xx² + κ_yy² + 2κ_xy²), 1/m, of a triangle's `[κ_xx, κ_yy, κ_xy]`
/// ([`Model::triangle_curvatures`]). κ_xy is the tensor's off-diagonal entry (half the
/// engineering twist), which the tensor holds twice, so this is the tensor's Frobenius norm
/// √(κ₁² + κ₂²): the same in every in-plane frame, warp or not.
pub fn curvature_magnitude(k: [f64; 3]) -> f64 {
    (k[0] * k[0] + k[1] * k[1] + 2.0 * k[2] * k[2]).sqrt()
}

/// ½ Σ Q_ab x_a·x_b, J.
fn quadratic_energy(q: &ScalarCsr, x: &[DVec3]) -> f64 {
    if x.len() < PARALLEL_TRIANGLES {
        return 0.5 * (0..x.len()).map(|a| x[a].dot(q.row_product(a, x))).sum::<f64>();
    }
    0.5 * sum_of(x.len(), |a| x[a].dot(q.row_product(a, x)))
}

/// f −= Q x and the energy ½ xᵀQx = −¼ Σ_ab Q_ab |x_b − x_a|² (Q's rows sum to zero), both
/// from the differences x_b − x_a of one pass over Q's rows.
fn subtract_quadratic_force_with_energy(q: &ScalarCsr, x: &[DVec3], f: &mut [DVec3]) -> f64 {
    let row = |a: usize| {
        let xa = x[a];
        q.entries_of_row(a as u32).fold((DVec3::ZERO, 0.0), |(force, energy), (b, v)| {
            let d = x[b as usize] - xa;
            (force + v * d, energy + v * d.length_squared())
        })
    };
    let mut energy = 0.0;
    for (a, fa) in f.iter_mut().enumerate() {
        let (force, e) = row(a);
        *fa -= force;
        energy -= 0.25 * e;
    }
    energy
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
    if f.len() < TEAM_TRIANGLES {
        f.iter_mut().enumerate().for_each(row);
    } else if f.len() < PARALLEL_TRIANGLES {
        let mid = f.len() / 2;
        let (low, high) = f.split_at_mut(mid);
        crate::sim::team::join(|| low.iter_mut().enumerate().for_each(row), || high.iter_mut().enumerate().for_each(|(a, fa)| row((mid + a, fa))));
    } else {
        f.par_iter_mut().enumerate().for_each(row);
    }
}

/// An edge's gradient stencil (vertex, weight) in the frame of its first triangle, and
/// the second triangle's placement in that frame (panels only).
type EdgeStencil = (Vec<(u32, DVec2)>, Option<Placement>);

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
pub(super) fn bending_patches(mesh: &Mesh, warp_angle: f64, rigid: &[bool]) -> Result<(Vec<BendingPatch>, Vec<Hinge>), ModelError> {
    let areas: Vec<f64> = (0..mesh.triangles.len()).map(|t| mesh.signed_area(t)).collect();
    let warp: Vec<DVec2> = mesh.rest.iter().map(|&p| to_warp_frame(p, warp_angle)).collect();
    stencils(&mesh.triangles, mesh.rest.len(), &areas, &RestFrames::Flat(warp), mesh.mean_edge_length(), rigid)
}

/// Where the stencils read rest positions.
enum RestFrames<'a> {
    /// One plane: every vertex's position in the warp frame.
    Flat(Vec<DVec2>),
    /// A cloth of panels: each triangle's corners in its own warp frame (see `charts`).
    Panels { corners: &'a [[DVec2; 3]] },
}

/// The rest points an edge's fit and hinges read: the plane, or the edge's chart.
enum EdgeFrame<'a> {
    Flat(&'a [DVec2]),
    Chart(super::charts::EdgeChart),
}

impl EdgeFrame<'_> {
    fn point(&self, v: u32) -> Option<DVec2> {
        match self {
            EdgeFrame::Flat(warp) => Some(warp[v as usize]),
            EdgeFrame::Chart(chart) => chart.points.get(&v).copied(),
        }
    }
}

/// [`bending_patches`] for any rest frames: `areas` are the triangles' rest areas (m²) and
/// `scale` the mean rest edge length (m).
fn stencils(triangles: &[[u32; 3]], n: usize, areas: &[f64], rest: &RestFrames, scale: f64, rigid: &[bool]) -> Result<(Vec<BendingPatch>, Vec<Hinge>), ModelError> {
    let mut edge_owner: HashMap<[u32; 2], Vec<(usize, usize)>> = HashMap::new();
    let mut vertex_triangles: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (t, tri) in triangles.iter().enumerate() {
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
    let charts = match rest {
        RestFrames::Panels { corners } => Some(PanelCharts { triangles, corners, edge_owner: &edge_owner, reach: 4.5 * scale }),
        RestFrames::Flat(_) => None,
    };
    let frame_of = |edge: [u32; 2], first: usize| match (rest, &charts) {
        (RestFrames::Flat(warp), _) => EdgeFrame::Flat(warp),
        (_, Some(charts)) => EdgeFrame::Chart(charts.unfold(first, edge)),
        (RestFrames::Panels { .. }, None) => unreachable!("panels have charts"),
    };
    let (gradient_of_edge, hinge_points) = edge_fits(&edge_owner, &frame_of, triangles, &vertex_triangles, rigid, scale)?;
    let mut patches = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        let area = areas[t];
        let mut weights: Vec<(u32, [f64; 3])> = Vec::new();
        let mut interior = true;
        for k in 0..3 {
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let key = sorted_edge(a, b);
            interior &= edge_owner[&key].len() == 2;
            let edge = match rest {
                RestFrames::Flat(warp) => warp[b as usize] - warp[a as usize],
                RestFrames::Panels { corners } => corners[t][(k + 2) % 3] - corners[t][(k + 1) % 3],
            };
            // Outward normal times edge length, for a counter-clockwise triangle.
            let ln = DVec2::new(edge.y, -edge.x);
            let (stencil, second) = &gradient_of_edge[&key];
            // The edge's second triangle reads the shared gradient in its own frame.
            let turn = second.filter(|_| edge_owner[&key][0].0 != t);
            for &(v, c) in stencil {
                let c = turn.map_or(c, |p| p.in_own_frame(c));
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
            let wings = [triangles[t0][k0], triangles[t1][k1]];
            if edge.iter().chain(&wings).any(|&v| rigid[v as usize]) {
                continue;
            }
            for t in [t0, t1] {
                let hinge = match rest {
                    RestFrames::Flat(warp) => Hinge::new(&patches[t], &|v| warp[v as usize], edge, wings),
                    RestFrames::Panels { .. } => {
                        let quad = &hinge_points[&edge];
                        let turn = gradient_of_edge[&edge].1.filter(|_| t == t1);
                        let at = |v: u32| {
                            let p = quad.iter().find(|(u, _)| *u == v).expect("a hinge reads its quad").1;
                            turn.map_or(p, |placement| placement.point_to_own(p))
                        };
                        Hinge::new(&patches[t], &at, edge, wings)
                    }
                };
                hinges.extend(hinge);
            }
        }
    }
    Ok((patches, hinges))
}

/// Each edge's gradient stencil, with (on panels) the second triangle's placement in the
/// edge's chart, and the rest points of the edge's hinge quad where it has a chart.
#[allow(clippy::type_complexity)]
fn edge_fits<'r>(
    edge_owner: &HashMap<[u32; 2], Vec<(usize, usize)>>,
    frame_of: &(dyn Fn([u32; 2], usize) -> EdgeFrame<'r> + Sync),
    triangles: &[[u32; 3]],
    vertex_triangles: &[Vec<u32>],
    rigid: &[bool],
    scale: f64,
) -> Result<(HashMap<[u32; 2], EdgeStencil>, HashMap<[u32; 2], Vec<(u32, DVec2)>>), ModelError> {
    let n = vertex_triangles.len();
    // A clamped region moves rigidly: its curvature is zero while the cloth beside it bends,
    // so a fit across the clamp line would smear that jump and make the root too soft.
    // Edges inside the clamp (both ends rigid) fit rigid vertices only, which gives the
    // clamp's exact slope; other edges fit free vertices plus the clamp line itself.
    let on_clamp_line: Vec<bool> =
        (0..n).map(|v| rigid[v] && vertex_triangles[v].iter().any(|&t| triangles[t as usize].iter().any(|&u| !rigid[u as usize]))).collect();
    // One gradient stencil per edge, shared by its triangles (for panels, in the frame of
    // the edge's first triangle, with the second triangle's placement in it), and the
    // rest points of the edge's hinge quad. Each edge's fit (and, on panels, its unfolded
    // chart) is its own: they run in parallel, each giving the same result on any number
    // of threads. On a 10k-triangle garment they were 2 s of the 3 s it took to build, on
    // one thread.
    let fit = |(&edge, owners): (&[u32; 2], &Vec<(usize, usize)>)| -> Result<_, ModelError> {
        let frame = frame_of(edge, owners[0].0);
        let at = |v: u32| frame.point(v);
        let midpoint = 0.5 * (at(edge[0]).expect("laid") + at(edge[1]).expect("laid"));
        let inside_clamp = rigid[edge[0] as usize] && rigid[edge[1] as usize];
        let usable = |v: u32| at(v).is_some() && if inside_clamp { rigid[v as usize] } else { !rigid[v as usize] || on_clamp_line[v as usize] };
        let stencil = edge_gradient_stencil(triangles, vertex_triangles, &|v| at(v).expect("usable"), edge, midpoint, scale, usable)
            .ok_or(ModelError::SingularBendingStencil { triangle: owners[0].0 })?;
        let second = match (&frame, owners.get(1)) {
            (EdgeFrame::Chart(chart), Some(&(t1, _))) => Some(chart.placements[&t1]),
            _ => None,
        };
        let quad = match (&frame, &owners[..]) {
            (EdgeFrame::Chart(_), [(t0, k0), (t1, k1)]) => {
                let quad = [edge[0], edge[1], triangles[*t0][*k0], triangles[*t1][*k1]];
                Some(quad.iter().map(|&v| (v, at(v).expect("the edge's triangles are laid"))).collect::<Vec<_>>())
            }
            _ => None,
        };
        Ok((edge, (stencil, second), quad))
    };
    let fits: Vec<_> = if triangles.len() >= PARALLEL_TRIANGLES {
        use rayon::prelude::*;
        edge_owner.par_iter().map(fit).collect::<Result<_, _>>()?
    } else {
        edge_owner.iter().map(fit).collect::<Result<_, _>>()?
    };
    let mut gradient_of_edge: HashMap<[u32; 2], EdgeStencil> = HashMap::with_capacity(fits.len());
    let mut hinge_points: HashMap<[u32; 2], Vec<(u32, DVec2)>> = HashMap::new();
    for (edge, stencil, quad) in fits {
        if let Some(quad) = quad {
            hinge_points.insert(edge, quad);
        }
        gradient_of_edge.insert(edge, stencil);
    }
    Ok((gradient_of_edge, hinge_points))
}

/// A stabilisation of the fitted bending stencils against mesh-scale oscillation.
///
/// The fits that give the edge gradients average over a ring or more, so a deflection that
/// zigzags from vertex to vertex can have nearly flat fits everywhere and almost no bending
/// energy: on an irregular mesh a share of the bending operator's modes are such
/// oscillations, each with a small fraction of the continuum's stiffness B k⁴ at its
/// wavenumber, and on square grids a zigzag along the grid is as soft. A compressed sheet
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
pub(super) struct Hinge {
    /// The patch's vertices and each one's weight in J − J_T.
    pub(super) vertices: Vec<u32>,
    pub(super) stencil: Vec<f64>,
    /// Unit normal of the edge in the warp frame, towards wing d.
    normal: DVec2,
    /// A/(2d²), the half hinge's energy per unit rigidity and squared J − J_T.
    weight: f64,
}

impl Hinge {
    /// The half hinge of edge `e` between the triangles (e, wings[0]) and (e, wings[1]) on
    /// `patch`, the fitted Hessian of one of them; None if either triangle is degenerate.
    fn new(patch: &BendingPatch, p: &dyn Fn(u32) -> DVec2, e: [u32; 2], wings: [u32; 2]) -> Option<Self> {
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
    triangles: &[[u32; 3]],
    vertex_triangles: &[Vec<u32>],
    warp: &dyn Fn(u32) -> DVec2,
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
                grown.extend_from_slice(&triangles[t as usize]);
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
fn quadratic_gradient_weights(points: &[u32], warp: &dyn Fn(u32) -> DVec2, midpoint: DVec2, scale: f64) -> Option<Vec<(u32, DVec2)>> {
    if points.len() < 6 {
        return None;
    }
    let rows: Vec<([f64; 6], f64)> = points
        .iter()
        .map(|&v| {
            let d = (warp(v) - midpoint) / scale;
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
/// but with weights so large that the bending matrix gains eigenvalues orders of magnitude
/// too high (explicit steps far too small, stiff Newton systems). The caller then grows
/// the neighbourhood instead.
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
pub(super) struct BendingPatch {
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
