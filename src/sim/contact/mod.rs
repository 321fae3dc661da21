//! Contact: cloth against rigid props and cloth against itself.
//!
//! How contact keeps the integrators' stability:
//! - Implicit integrators (implicit Euler, BDF2) take contact *inside* the minimisation
//!   of the incremental potential. At the start of a step every vertex near a prop, or
//!   whose predicted path x → x + h·v enters one, gets a contact plane (the prop's closest
//!   point and normal, or the entry point of the path). The plane adds the energy
//!   ½k·max(0, τ − n·(y − p))², τ the contact thickness, with k = c·m/h² scaled by the
//!   vertex mass so that it stiffens the Newton system no more than inertia does (c = 100:
//!   the cloth sinks g·h²/c into its thickness layer under its own weight). Coulomb
//!   friction enters as IPC's lagged dissipative potential: the normal force λ and the
//!   plane are frozen over the step, the tangential slip u = T(y − a) pays λ·F(|u|) with
//!   F' = μ_s·|u|/ε below the slip threshold ε = v_ε·h (sticking) and decaying from μ_s to
//!   μ_k beyond it (sliding). The slip is measured from a = x̂ where the vertex has just
//!   arrived or slid, and from the point it stuck at while it sticks: IPC's a = x̂ at every
//!   step makes sticking viscous, a vertex under a sideways pull F creeping at v_ε·F/(μ_s λ)
//!   for ever (`StepContacts::stuck_after`). Because both are energies, the line search, the energy
//!   checks and the unconditional stability of the implicit step are kept. After the
//!   solve, any path that still enters a prop (a new contact the prediction missed) adds
//!   its plane, and a vertex that slid past its plane's reach into a concave part of a
//!   prop has its plane renewed where it ended (`ContactModel::refresh_planes`); the step
//!   is then solved again: no vertex tunnels through a thin prop at any step size.
//! - The explicit integrator takes contact at the velocity level after its update: a
//!   vertex that ends inside the thickness layer, or whose path entered the prop, is put
//!   back on the layer, loses its inward normal velocity, and its tangential velocity is
//!   reduced by a Coulomb impulse (stopped if μ_s·|Δv_n| suffices). This adds no stiffness,
//!   so the explicit stability limit is the cloth's own.
//! - Cloth–cloth: vertex–triangle pairs closer than the layer thickness δ at the start of
//!   a step (found in a list of near pairs, below) get the repulsion ½k·max(0, δ − d)², d the
//!   point–triangle distance, in the implicit solve. Whatever the solve did, a continuous
//!   collision test of every vertex–triangle and edge–edge pair over the step follows; the
//!   vertices of a pair that would cross are held at their start positions and share
//!   their mean velocity (an inelastic impact zone), repeated until no pair crosses. The
//!   start of the step is free of crossings, so this always ends with none.
//! - Both cloth–cloth searches read a list of vertex–triangle and edge–edge pairs that were
//!   near when it was built (a Verlet list, as molecular dynamics keeps for its neighbours:
//!   found with a spatial hash, out to a reach with a skin to spare). A pair not listed was
//!   at least the reach apart then, and no two vertices have since closed more than twice
//!   the largest displacement, so the list serves until displacements and the step's
//!   motion use up the skin; then it is rebuilt. On a draping cloth it lasts many steps.
//! - On meshes of 4096 triangles or more the searches, the pair filters and the plane
//!   checks run in fixed chunks on rayon's threads and collect what they find in order, so
//!   that contact does the same on any number of threads.

mod cloth;
pub mod geometry;
pub mod props;
mod step;

pub use cloth::{NearPairs, count_self_intersections, pairs_within, self_intersections};
pub use props::{MAX_REACH, Prop, PropError, PropShape, SurfacePoint};

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// What contact reads of the cloth: its topology and masses.
#[derive(Debug, Clone, Copy)]
pub struct Cloth<'a> {
    pub triangles: &'a [[u32; 3]],
    /// Undirected edges (a < b).
    pub edges: &'a [[u32; 2]],
    /// Vertices whose positions are prescribed.
    pub fixed: &'a [bool],
    /// Lumped vertex masses, kg.
    pub mass: &'a [f64],
    /// Mean rest edge length, m.
    pub mean_edge_length: f64,
    /// Per vertex, the seams being sewn that it lies near (`Sewing::bands`; empty: none):
    /// self-collision leaves out pairs near a common seam, whose sides must meet.
    pub seam_bands: &'a [u64],
    /// Per vertex, the vertex it becomes once the seams are welded (empty: itself): pairs
    /// that will share a vertex then are neighbours now.
    pub welded: &'a [u32],
}

impl Cloth<'_> {
    /// Whether self-collision leaves out the pair of these two sides (a vertex and a
    /// triangle's corners, or two edges): they will share a vertex once the seams are
    /// welded, or both lie near a seam that is still open.
    pub fn sewn_together(&self, one: &[u32], other: &[u32]) -> bool {
        if !self.welded.is_empty() && one.iter().any(|&a| other.iter().any(|&b| self.welded[a as usize] == self.welded[b as usize])) {
            return true;
        }
        if self.seam_bands.is_empty() {
            return false;
        }
        let bits = |side: &[u32]| side.iter().fold(0u64, |b, &v| b | self.seam_bands[v as usize]);
        bits(one) & bits(other) != 0
    }
}

/// Contact parameters, SI units: the `[contact]` section of a scene file.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSettings {
    /// Distance the cloth keeps from a prop's surface, m.
    pub thickness: f64,
    /// Coulomb friction coefficient while sticking.
    pub friction_static: f64,
    /// Coulomb friction coefficient while sliding (at most the static one).
    pub friction_kinetic: f64,
    /// Cloth–cloth contact in folds. Off where the cloth cannot touch itself.
    pub self_collision: bool,
    /// Distance kept between cloth layers, m; absent: the smaller of the prop thickness
    /// and a fifth of the mean edge length (`self_thickness_for`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_thickness: Option<f64>,
    /// Contact penalty stiffness as a multiple of m/Δt² per vertex (implicit solvers).
    pub stiffness: f64,
    /// Tangential speed below which friction sticks, m/s: a vertex resting on a prop may
    /// slip elastically by up to slip_speed·Δt from where it stuck before it slides (its
    /// friction then a spring of stiffness μ_s·λ/(slip_speed·Δt)).
    pub slip_speed: f64,
    /// Bound how far cloth–cloth pairs can close by their vertices' motion relative to
    /// their common motion, instead of by each vertex's own (additive CCD's centred
    /// displacements, Li et al. 2021). Both bounds are rigorous; the centred one does not
    /// count a falling or settling cloth's common drift, which otherwise lists every
    /// in-plane neighbour as a pair and caps Newton's steps by it (the fast path).
    pub relative_motion: bool,
    /// Hold a vertex that sticks to a prop where it is over the next step (its position
    /// prescribed, as a pinned vertex's), instead of solving its sticking friction as a
    /// stiff spring; released where the force holding it leaves `HOLD_MARGIN` of Coulomb's
    /// cone. Off by default: it trades the settled drape for speed (docs/fast-path.md,
    /// "What was tried and not kept").
    pub hold_sticking: bool,
}

/// The share of Coulomb's cone within which a vertex is held (`ContactSettings::hold_sticking`):
/// a held vertex is rigid, so load its sliding neighbours would share gathers on it; held
/// only well inside the cone, the vertices near slipping keep the smoothed friction.
pub const HOLD_MARGIN: f64 = 0.5;

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            thickness: 0.002,
            friction_static: 0.5,
            friction_kinetic: 0.4,
            self_collision: false,
            self_thickness: None,
            stiffness: 100.0,
            slip_speed: 1e-3,
            relative_motion: false,
            hold_sticking: false,
        }
    }
}

impl ContactSettings {
    /// The distance kept between cloth layers on a mesh of this mean edge length, m.
    pub fn self_thickness_for(&self, mean_edge_length: f64) -> f64 {
        self.self_thickness.unwrap_or(self.thickness.min(0.2 * mean_edge_length))
    }

    pub fn validate(&self) -> Result<(), String> {
        let positive = |key: &str, v: f64| if v.is_finite() && v > 0.0 { Ok(()) } else { Err(format!("contact.{key} must be positive, got {v:?}")) };
        positive("thickness", self.thickness)?;
        if let Some(v) = self.self_thickness {
            positive("self_thickness", v)?;
        }
        positive("stiffness", self.stiffness)?;
        positive("slip_speed", self.slip_speed)?;
        for (key, v) in [("friction_static", self.friction_static), ("friction_kinetic", self.friction_kinetic)] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(format!("contact.{key} must be zero or positive, got {v:?}"));
            }
        }
        if self.friction_kinetic > self.friction_static {
            return Err(format!(
                "contact.friction_kinetic = {:?} exceeds contact.friction_static = {:?}: sliding friction is at most sticking friction",
                self.friction_kinetic, self.friction_static
            ));
        }
        Ok(())
    }
}

/// The props and settings of a scene: the fixed part of contact.
#[derive(Debug, Clone)]
pub struct ContactModel {
    pub props: Vec<Prop>,
    pub settings: ContactSettings,
    /// World bounding box of each prop (None: unbounded, the ground).
    bounds: Vec<Option<(DVec3, DVec3)>>,
}

/// A vertex held outside a prop by a plane over one step.
#[derive(Debug, Clone, Copy)]
struct PlaneContact {
    vertex: u32,
    prop: u32,
    point: DVec3,
    normal: DVec3,
    /// Penalty stiffness in the layer, N/m.
    stiffness: f64,
    /// Its stiffness past the surface, N/m: `SURFACE_STIFFENING` times the layer's for a
    /// vertex that starts the step in the layer or whose plane was renewed where it ended
    /// inside the prop (`ContactModel::refresh_planes`), the layer's for one arriving.
    beyond: f64,
    /// Normal force at the start of the step (lagged for friction), N.
    normal_force: f64,
    /// Where friction measures the slip from: the vertex's start of step, or, while it
    /// sticks, the point it stuck at (`stick_point`).
    stick: DVec3,
}

/// How much stiffer the penalty is past a prop's surface than in its contact layer, for a
/// vertex that starts the step in the layer.
///
/// The layer stands in for the cloth's own thickness: a soft penalty there keeps a resting
/// vertex's Newton system well conditioned, and a vertex settles into it by its load over
/// c·m/Δt² (c = `contact.stiffness`), a fraction of the layer for a vertex carrying its own
/// weight. A vertex that carries much more, a shoulder holding up a heavy dress while its
/// seams close, was pushed on through the layer into the form: the denim shift dress went
/// 1.9 mm into its form on the exact path, 0.008 mm with this (docs/performance-log.md,
/// "2026-12-04, late evening"). A vertex arriving from outside the layer keeps the layer's
/// stiffness: its plane, the tangent where it starts, stands for the surface only near
/// there, and one that passes a corner of a mesh prop within the step may lie below that
/// plane yet outside the prop (applied to every plane, the stiffening threw such vertices
/// back and moved the fast path's garments off their path).
const SURFACE_STIFFENING: f64 = 100.0;

/// How deep inside its prop, as a share of the contact layer, a vertex may end a step
/// before its plane is renewed where it is (`ContactModel::refresh_planes`): a fiftieth of
/// the 2 mm layer is 0.04 mm, under any fabric's thickness and far under what a viewer
/// can see.
const REFRESH_DEPTH_SHARE: f64 = 0.02;

impl PlaneContact {
    /// The penalty's energy, force along the normal and stiffness for vertex position `y`
    /// against a layer `thickness` thick: ½k·g² for a gap g = thickness − n·(y − point) into
    /// the layer, and past the surface (g > thickness) the stiffness `beyond` on the depth
    /// beyond it, so that the energy's gradient is continuous.
    fn penalty(&self, y: DVec3, thickness: f64) -> (f64, f64, f64) {
        penalty(thickness - self.normal.dot(y - self.point), thickness, self.stiffness, self.beyond)
    }

    /// The vertex's slip at position `y`: its displacement from the stick point, tangent
    /// to the plane.
    fn slip(&self, y: DVec3) -> DVec3 {
        let u = y - self.stick;
        u - u.dot(self.normal) * self.normal
    }
}

/// The penalty of stiffness `k` in a layer `thickness` thick and `beyond` past it (N/m)
/// at a gap `gap` (m) into the layer: energy, force and stiffness (`PlaneContact::penalty`).
fn penalty(gap: f64, thickness: f64, k: f64, beyond: f64) -> (f64, f64, f64) {
    if gap <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let depth = gap - thickness;
    if depth <= 0.0 {
        return (0.5 * k * gap * gap, k * gap, k);
    }
    let extra = beyond - k;
    (0.5 * k * gap * gap + 0.5 * extra * depth * depth, k * gap + extra * depth, beyond)
}

/// Where friction measures vertex `v`'s slip from: the point it stuck at, if it sticks
/// (`stuck`, by vertex), else its start of step.
fn stick_point(stuck: &[Option<DVec3>], v: usize, start: &[DVec3]) -> DVec3 {
    stuck.get(v).copied().flatten().unwrap_or(start[v])
}

/// Two parts of the cloth kept apart over one step: a vertex and a triangle, or two edges.
#[derive(Debug, Clone, Copy)]
struct SelfPair {
    /// Vertex then triangle corners, or the first edge's ends then the second's.
    vertices: [u32; 4],
    edge_edge: bool,
    stiffness: f64,
}

/// Counters of what contact did, accumulated over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactStats {
    /// Deepest any vertex has been inside a prop at the end of a step, m.
    pub max_penetration: f64,
    /// Steps solved again because a path entered a prop the prediction missed, or a
    /// vertex ended inside a prop it had a plane with.
    pub resolves: u64,
    /// Vertex–triangle or edge–edge crossings stopped by impact zones.
    pub impacts: u64,
}

/// The contacts active over one step.
pub struct StepContacts {
    planes: Vec<PlaneContact>,
    pairs: Vec<SelfPair>,
    mu_static: f64,
    mu_kinetic: f64,
    thickness: f64,
    self_thickness: f64,
    /// Slip threshold over the step, m.
    slip: f64,
    /// Step limits by centred displacements (`ContactSettings::relative_motion`).
    relative_motion: bool,
}

impl ContactModel {
    pub fn new(props: Vec<Prop>, settings: ContactSettings) -> Result<Self, String> {
        settings.validate()?;
        let bounds = props
            .iter()
            .map(|p| {
                if matches!(p.shape, PropShape::Ground) {
                    return None;
                }
                let (vertices, _) = p.surface_mesh(0.0);
                let lo = vertices.iter().fold(DVec3::INFINITY, |a, v| a.min(*v));
                let hi = vertices.iter().fold(DVec3::NEG_INFINITY, |a, v| a.max(*v));
                Some((lo, hi))
            })
            .collect();
        Ok(Self { props, settings, bounds })
    }


    fn near_bounds(&self, prop: usize, a: DVec3, b: DVec3, margin: f64) -> bool {
        match self.bounds[prop] {
            None => true,
            Some((lo, hi)) => {
                let (pl, ph) = (a.min(b) - DVec3::splat(margin), a.max(b) + DVec3::splat(margin));
                pl.cmple(hi).all() && ph.cmpge(lo).all()
            }
        }
    }


    /// The contacts for a step from `start` (positions x_n) towards `predicted` (x_n + h v_n
    /// or the BDF2 equivalent), with time step `h` and vertex masses; friction measures each
    /// vertex's slip from where it stuck (`stuck`, by vertex, from
    /// [`StepContacts::stuck_after`] of the step before), else from its start.
    /// The near-pair list `near` is renewed where it no longer covers the step.
    pub fn begin_step(&self, cloth: Cloth, near: &mut NearPairs, start: &[DVec3], stuck: &[Option<DVec3>], predicted: &[DVec3], h: f64) -> StepContacts {
        let (fixed, mass) = (cloth.fixed, cloth.mass);
        let parallel = cloth.triangles.len() >= PARALLEL_TRIANGLES;
        let s = &self.settings;
        let mut contacts = StepContacts {
            planes: Vec::new(),
            pairs: Vec::new(),
            mu_static: s.friction_static,
            mu_kinetic: s.friction_kinetic,
            thickness: s.thickness,
            self_thickness: s.self_thickness_for(cloth.mean_edge_length),
            slip: s.slip_speed * h,
            relative_motion: s.relative_motion,
        };
        let per_vertex = filter_in_order(start, parallel, |v, _| {
            let mut planes = Vec::new();
            if !fixed[v] {
                self.add_planes(v, start[v], predicted[v], stick_point(stuck, v, start), mass[v], h, &mut planes, false);
            }
            (!planes.is_empty()).then_some(planes)
        });
        contacts.planes = per_vertex.into_iter().flatten().collect();
        if s.self_collision {
            contacts.pairs = self.self_pairs(cloth, near, start, predicted, h);
        }
        contacts
    }


    /// Adds vertex `v`'s planes: props within reach of its path from `a` to `b`, or entered
    /// by it, friction measuring its slip from `stick`. With `only_missing`, only props the
    /// vertex has no plane with yet. Returns how many.
    #[allow(clippy::too_many_arguments)]
    fn add_planes(&self, v: usize, a: DVec3, b: DVec3, stick: DVec3, m: f64, h: f64, planes: &mut Vec<PlaneContact>, only_missing: bool) -> usize {
        let s = &self.settings;
        let reach = s.thickness + (b - a).length();
        let mut added = 0;
        for (p, prop) in self.props.iter().enumerate() {
            if !self.near_bounds(p, a, b, reach + s.thickness) {
                continue;
            }
            if only_missing && planes.iter().any(|c| c.vertex == v as u32 && c.prop == p as u32) {
                continue;
            }
            let stiffness = s.stiffness * m / (h * h);
            let near = prop.surface_point(a);
            let plane = if near.distance < reach + s.thickness {
                Some(near)
            } else {
                prop.segment_entry(a, b)
            };
            if let Some(sp) = plane {
                // The lagged normal force: what the penalty pushes with at the step's start.
                // The plane is the surface's tangent at the step's start: past it is inside
                // the prop for a vertex resting there, which may slide little in a step; a
                // vertex arriving from outside the layer may go round a corner of the
                // prop within the step, and keeps the layer's stiffness throughout.
                let beyond = if near.distance < s.thickness { SURFACE_STIFFENING * stiffness } else { stiffness };
                let normal_force = penalty(s.thickness - near.distance, s.thickness, stiffness, beyond).1;
                planes.push(PlaneContact { vertex: v as u32, prop: p as u32, point: sp.point, normal: sp.normal, stiffness, beyond, normal_force, stick });
                added += 1;
            }
        }
        added
    }


    /// After a solve from `start` to `end`: adds planes for paths that enter a prop without
    /// one. Returns how many were added (zero: the step stands).
    pub fn add_missed(&self, contacts: &mut StepContacts, cloth: Cloth, start: &[DVec3], stuck: &[Option<DVec3>], end: &[DVec3], h: f64) -> usize {
        let (fixed, mass) = (cloth.fixed, cloth.mass);
        let parallel = cloth.triangles.len() >= PARALLEL_TRIANGLES;
        let props = self.props.len();
        // Which (vertex, prop) have a plane: looked up, not searched for in the list.
        let mut has_plane = vec![false; start.len() * props];
        for c in &contacts.planes {
            has_plane[c.vertex as usize * props + c.prop as usize] = true;
        }
        let missing = filter_in_order(start, parallel, |v, _| {
            let misses = |(p, prop): (usize, &Prop)| {
                if has_plane[v * props + p] || !self.near_bounds(p, start[v], end[v], self.settings.thickness) {
                    return false;
                }
                let inside_layer = prop.surface_point(end[v]).distance < 0.5 * self.settings.thickness;
                inside_layer || prop.segment_entry(start[v], end[v]).is_some()
            };
            (!fixed[v] && self.props.iter().enumerate().any(misses)).then_some(v)
        });
        let mut added = 0;
        for v in missing {
            added += self.add_planes(v, start[v], end[v], stick_point(stuck, v, start), mass[v], h, &mut contacts.planes, true);
        }
        added
    }


    /// After a solve ending at `end`: renews the plane of each vertex that ended more than
    /// `REFRESH_DEPTH_SHARE` of the layer inside its prop, to the surface's tangent at its
    /// closest point there, held with the stiffness past the surface of a resting vertex.
    /// Returns how many were renewed (zero: the step stands).
    ///
    /// A plane is the surface's tangent where the vertex started the step. Over a convex
    /// part of a prop the prop lies behind that plane, but a vertex sliding within a step
    /// into a concave part (a valley, or across an inward fold between a mesh prop's
    /// facets) can pass the surface while still in front of its plane: the shift dress at
    /// 24 ms steps went 0.12 mm into its form that way, a strip sliding through a valley
    /// 11 mm (`tests/contact.rs`; docs/performance-log.md, "2026-12-04, night"). The solve
    /// is repeated from where it stopped with the plane taken where the vertex is: a
    /// sequential linearisation of the prop's surface.
    pub fn refresh_planes(&self, contacts: &mut StepContacts, cloth: Cloth, end: &[DVec3]) -> usize {
        let parallel = cloth.triangles.len() >= PARALLEL_TRIANGLES;
        let limit = REFRESH_DEPTH_SHARE * self.settings.thickness;
        let renewed = filter_in_order(&contacts.planes, parallel, |i, c| {
            let y = end[c.vertex as usize];
            let prop = c.prop as usize;
            if !self.near_bounds(prop, y, y, 0.0) {
                return None;
            }
            let sp = self.props[prop].surface_point(y);
            (sp.distance < -limit).then_some((i, sp))
        });
        for &(i, sp) in &renewed {
            let c = &mut contacts.planes[i];
            c.point = sp.point;
            c.normal = sp.normal;
            c.beyond = SURFACE_STIFFENING * c.stiffness;
        }
        renewed.len()
    }

    /// Deepest penetration of any vertex into any prop, m (zero when all are outside).
    pub fn penetration(&self, x: &[DVec3], fixed: &[bool]) -> f64 {
        let mut deepest = 0.0f64;
        for (v, p) in x.iter().enumerate() {
            if fixed[v] {
                continue;
            }
            for (i, prop) in self.props.iter().enumerate() {
                if self.near_bounds(i, *p, *p, self.settings.thickness) {
                    deepest = deepest.max(-prop.surface_point(*p).distance);
                }
            }
        }
        deepest
    }


    /// Velocity-level contact for explicit integrators: positions `x` and velocities `v`
    /// after an unconstrained update from `start`.
    pub fn project_explicit(&self, start: &[DVec3], x: &mut [DVec3], v: &mut [DVec3], fixed: &[bool]) {
        let s = &self.settings;
        for i in 0..x.len() {
            if fixed[i] {
                continue;
            }
            for (p, prop) in self.props.iter().enumerate() {
                if !self.near_bounds(p, start[i], x[i], 2.0 * s.thickness) {
                    continue;
                }
                let near = prop.surface_point(x[i]);
                let (point, normal) = if let Some(entry) = prop.segment_entry(start[i], x[i]) {
                    (entry.point, entry.normal)
                } else if near.distance < s.thickness {
                    (near.point, near.normal)
                } else {
                    continue;
                };
                let depth = s.thickness - normal.dot(x[i] - point);
                if depth <= 0.0 {
                    continue;
                }
                x[i] += depth * normal;
                let vn = v[i].dot(normal);
                if vn < 0.0 {
                    let dv = -vn;
                    v[i] += dv * normal;
                    let vt = v[i] - v[i].dot(normal) * normal;
                    let speed = vt.length();
                    if speed <= s.friction_static * dv {
                        v[i] -= vt;
                    } else {
                        v[i] -= vt * (s.friction_kinetic * dv / speed);
                    }
                }
            }
        }
    }
}

/// On meshes of at least this many triangles the searches run on rayon's threads. On
/// smaller ones a search takes tens of microseconds, about what handing it out costs, and
/// the threads would make it slower.
const PARALLEL_TRIANGLES: usize = 4096;

/// Below [`PARALLEL_TRIANGLES`], searches over at least this many items are split in two
/// halves, one on the team's thread, whose hand-off costs far less than rayon's.
use crate::sim::team::LEAST_ITEMS as TEAM_ITEMS;

/// What `keep(i, &items[i])` returns, in the order of i (if `parallel`, fixed chunks on
/// rayon's threads; else, from [`TEAM_ITEMS`] items, two halves, one on the team's). Every
/// path runs the same loop over a range, which `keep` is inlined into: with an iterator
/// adapter on each path it is not, and the filters, run on every pair every step, are
/// slower. The chunks are small enough for the threads to share the items evenly (in
/// chunks of 4 096 a 10k garment's 5 247 vertices went 4 096 to one thread and 1 151 to the
/// other); what is kept, and its order, do not depend on them.
fn filter_in_order<T: Sync, U: Send>(items: &[T], parallel: bool, keep: impl Fn(usize, &T) -> Option<U> + Sync) -> Vec<U> {
    use rayon::prelude::*;
    const CHUNK: usize = 1024;
    let filter = |range: std::ops::Range<usize>| {
        let mut out = Vec::new();
        for (i, item) in items[range.clone()].iter().enumerate() {
            if let Some(u) = keep(range.start + i, item) {
                out.push(u);
            }
        }
        out
    };
    let n = items.len();
    if parallel {
        let parts: Vec<Vec<U>> = (0..n.div_ceil(CHUNK)).into_par_iter().map(|c| filter(c * CHUNK..((c + 1) * CHUNK).min(n))).collect();
        parts.into_iter().flatten().collect()
    } else if n >= TEAM_ITEMS {
        crate::sim::team::join_in_order(|| filter(0..n / 2), || filter(n / 2..n))
    } else {
        filter(0..n)
    }
}

/// How far a pair's gap can close when its four vertices move by `d` (vertex then triangle
/// corners, or one edge's ends then the other's): each side's largest move, measured from
/// `centre` (the triangle inequality holds for any centre; zero gives each vertex's own
/// move, the pair's mean leaves out their common motion).
fn closing_bound(d: [DVec3; 4], edge_edge: bool, relative: bool) -> f64 {
    let centre = if relative { 0.25 * (d[0] + d[1] + d[2] + d[3]) } else { DVec3::ZERO };
    let v = d.map(|di| (di - centre).length());
    if edge_edge { v[0].max(v[1]) + v[2].max(v[3]) } else { v[0] + v[1].max(v[2]).max(v[3]) }
}

/// Whether two boxes come within `margin` of each other.
fn boxes_overlap(a: (DVec3, DVec3), b: (DVec3, DVec3), margin: f64) -> bool {
    (a.0 - DVec3::splat(margin)).cmple(b.1).all() && (a.1 + DVec3::splat(margin)).cmpge(b.0).all()
}
