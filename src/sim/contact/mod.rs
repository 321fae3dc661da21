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
//!   plane are frozen over the step, the tangential slip u = T(y − x̂) pays λ·F(|u|) with
//!   F' = μ_s·|u|/ε below the slip threshold ε = v_ε·h (sticking) and decaying from μ_s to
//!   μ_k beyond it (sliding). Because both are energies, the line search, the energy
//!   checks and the unconditional stability of the implicit step are kept. After the
//!   solve, any path that still enters a prop (a new contact the prediction missed) adds
//!   its plane and the step is solved again: no vertex tunnels through a thin prop at any
//!   step size.
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

pub mod geometry;
pub mod props;

pub use props::{MAX_REACH, Prop, PropError, PropShape, SurfacePoint};

use crate::sim::model::Model;
use crate::sim::sparse::{BlockCsr, Coupling};
use geometry::{SpatialHash, closest_point_triangle, closest_points_segments, edge_edge_ccd, segment_crosses_triangle, vertex_triangle_ccd};
use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};
use std::sync::Mutex;

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
    /// Tangential speed below which friction sticks, m/s. Smoothed (IPC) friction lets a
    /// sticking cloth under a sideways pull F creep at slip_speed·F/(μN): keep it well
    /// below the speeds a scene should resolve, and below its settle speed.
    pub slip_speed: f64,
}

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
        }
    }
}

impl ContactSettings {
    /// The distance kept between cloth layers on a mesh of this mean edge length, m.
    pub fn self_thickness_for(&self, mean_edge_length: f64) -> f64 {
        self.self_thickness.unwrap_or(self.thickness.min(0.2 * mean_edge_length))
    }

    pub fn validate(&self) -> Result<(), String> {
        let positive = |key: &str, v: f64| if v.is_finite() && v > 0.0 { Ok(()) } else { Err(format!("contact.{key} must be positive, got {v}")) };
        positive("thickness", self.thickness)?;
        if let Some(v) = self.self_thickness {
            positive("self_thickness", v)?;
        }
        positive("stiffness", self.stiffness)?;
        positive("slip_speed", self.slip_speed)?;
        for (key, v) in [("friction_static", self.friction_static), ("friction_kinetic", self.friction_kinetic)] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(format!("contact.{key} must be zero or positive, got {v}"));
            }
        }
        if self.friction_kinetic > self.friction_static {
            return Err(format!(
                "contact.friction_kinetic = {} exceeds contact.friction_static = {}: sliding friction is at most sticking friction",
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
    /// Cloth–cloth pairs near enough to meet soon, kept from step to step.
    near: NearPairCache,
}

/// Cloth–cloth pairs closer than `reach` at positions `origin` (by their bounding boxes).
#[derive(Debug, Default)]
struct NearPairs {
    origin: Vec<DVec3>,
    reach: f64,
    /// (vertex, triangle index).
    vertex_triangle: Vec<(u32, u32)>,
    /// (edge, edge) indices, first < second, sharing no vertex.
    edge_edge: Vec<(u32, u32)>,
}

impl NearPairs {
    /// Whether every pair that comes within `margin` while its vertices move at most
    /// `motion` from `start` is listed: in the worst case two vertices have closed by
    /// twice the largest displacement since the list was built and by twice `motion`.
    fn covers(&self, start: &[DVec3], motion: f64, margin: f64) -> bool {
        if self.origin.len() != start.len() {
            return false;
        }
        let moved = start.iter().zip(&self.origin).map(|(a, b)| a.distance_squared(*b)).fold(0.0, f64::max).sqrt();
        2.0 * moved + 2.0 * motion + margin <= self.reach
    }

    fn build(x: &[DVec3], triangles: &[[u32; 3]], edges: &[[u32; 2]], reach: f64) -> Self {
        let parallel = triangles.len() >= PARALLEL_TRIANGLES;
        let cell = mean_edge(x, triangles).max(reach).max(1e-6);
        let points: Vec<_> = x.iter().map(|&p| (p, p)).collect();
        let hash = SpatialHash::new(cell, &points);
        let pad = DVec3::splat(reach);
        // The hash returns an item once per cell it overlaps (and its bucket-mates): each
        // query marks what it has taken with its own number instead of searching a list of
        // them, which took about a quarter of the search's time at 20 000 triangles.
        let vertex_triangle = search_in_chunks(triangles.len(), x.len(), parallel, |t, taken, found| {
            let tri = triangles[t];
            let c = tri.map(|i| x[i as usize]);
            let (lo, hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
            hash.query_box(lo - pad, hi + pad, |v| {
                if taken[v as usize] != t as u32 && !tri.contains(&v) && boxes_overlap((x[v as usize], x[v as usize]), (lo, hi), reach) {
                    taken[v as usize] = t as u32;
                    found.push((v, t as u32));
                }
            });
        });
        let segment = |e: usize| {
            let [a, b] = edges[e].map(|i| x[i as usize]);
            (a.min(b), a.max(b))
        };
        let boxes: Vec<_> = (0..edges.len()).map(segment).collect();
        let hash = SpatialHash::new(cell, &boxes);
        let edge_edge = search_in_chunks(edges.len(), edges.len(), parallel, |e, taken, found| {
            let [a, b] = edges[e];
            hash.query_box(boxes[e].0 - pad, boxes[e].1 + pad, |f| {
                let [c, d] = edges[f as usize];
                if (f as usize) > e && taken[f as usize] != e as u32 && c != a && c != b && d != a && d != b && boxes_overlap(boxes[e], boxes[f as usize], reach) {
                    taken[f as usize] = e as u32;
                    found.push((e as u32, f));
                }
            });
        });
        Self { origin: x.to_vec(), reach, vertex_triangle, edge_edge }
    }
}

/// The near-pair list behind a lock, so that the contact model's searches can renew it
/// through a shared reference; a clone starts without one.
#[derive(Debug, Default)]
struct NearPairCache(Mutex<NearPairs>);

impl Clone for NearPairCache {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// A vertex held outside a prop by a plane over one step.
#[derive(Debug, Clone, Copy)]
struct PlaneContact {
    vertex: u32,
    prop: u32,
    point: DVec3,
    normal: DVec3,
    /// Penalty stiffness, N/m.
    stiffness: f64,
    /// Normal force at the start of the step (lagged for friction), N.
    normal_force: f64,
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
    /// Steps solved again because a path entered a prop the prediction missed.
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
        Ok(Self { props, settings, bounds, near: NearPairCache::default() })
    }

    /// The near-pair list for a search from `start` over paths of at most `motion` for
    /// pairs that come within `margin`, renewed if it does not cover them.
    fn near_pairs(&self, model: &Model, start: &[DVec3], motion: f64, margin: f64) -> std::sync::MutexGuard<'_, NearPairs> {
        // The skin: half an edge lets a draping cloth keep its list for many steps while
        // adding few pairs beyond those in reach.
        let skin = 0.5 * model.mean_edge_length;
        let mut near = self.near.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if !near.covers(start, motion, margin) {
            *near = NearPairs::build(start, &model.triangles, &model.edges, margin + 2.0 * motion + skin);
        }
        near
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
    /// or the BDF2 equivalent), with time step `h` and vertex masses.
    pub fn begin_step(&self, model: &Model, start: &[DVec3], predicted: &[DVec3], h: f64) -> StepContacts {
        let (fixed, mass) = (&model.fixed, &model.mass);
        let parallel = model.triangles.len() >= PARALLEL_TRIANGLES;
        let s = &self.settings;
        let mut contacts = StepContacts {
            planes: Vec::new(),
            pairs: Vec::new(),
            mu_static: s.friction_static,
            mu_kinetic: s.friction_kinetic,
            thickness: s.thickness,
            self_thickness: s.self_thickness_for(model.mean_edge_length),
            slip: s.slip_speed * h,
        };
        let per_vertex = filter_in_order(start, parallel, |v, _| {
            let mut planes = Vec::new();
            if !fixed[v] {
                self.add_planes(v, start[v], predicted[v], mass[v], h, &mut planes, false);
            }
            (!planes.is_empty()).then_some(planes)
        });
        contacts.planes = per_vertex.into_iter().flatten().collect();
        if s.self_collision {
            contacts.pairs = self.self_pairs(model, start, predicted, h);
        }
        contacts
    }

    /// Adds vertex `v`'s planes: props within reach of its path, or entered by it. With
    /// `only_missing`, only props the vertex has no plane with yet. Returns how many.
    #[allow(clippy::too_many_arguments)]
    fn add_planes(&self, v: usize, a: DVec3, b: DVec3, m: f64, h: f64, planes: &mut Vec<PlaneContact>, only_missing: bool) -> usize {
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
                let normal_force = stiffness * (s.thickness - near.distance).max(0.0);
                planes.push(PlaneContact { vertex: v as u32, prop: p as u32, point: sp.point, normal: sp.normal, stiffness, normal_force });
                added += 1;
            }
        }
        added
    }

    /// After a solve from `start` to `end`: adds planes for paths that enter a prop without
    /// one. Returns how many were added (zero: the step stands).
    pub fn add_missed(&self, contacts: &mut StepContacts, model: &Model, start: &[DVec3], end: &[DVec3], h: f64) -> usize {
        let (fixed, mass) = (&model.fixed, &model.mass);
        let parallel = model.triangles.len() >= PARALLEL_TRIANGLES;
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
            added += self.add_planes(v, start[v], end[v], mass[v], h, &mut contacts.planes, true);
        }
        added
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

    /// Vertex–triangle and edge–edge pairs within reach over the step.
    fn self_pairs(&self, model: &Model, start: &[DVec3], predicted: &[DVec3], h: f64) -> Vec<SelfPair> {
        let (fixed, mass, triangles, edges) = (&model.fixed, &model.mass, &model.triangles, &model.edges);
        let parallel = triangles.len() >= PARALLEL_TRIANGLES;
        let delta = self.settings.self_thickness_for(model.mean_edge_length);
        let motion: Vec<f64> = start.iter().zip(predicted).map(|(a, b)| a.distance(*b)).collect();
        let near = self.near_pairs(model, start, motion.iter().copied().fold(0.0, f64::max), delta);
        let stiffness = |m: f64| self.settings.stiffness * m / (h * h);
        let mut pairs = filter_in_order(&near.vertex_triangle, parallel, |_, &(v, t)| {
            let (vi, tri) = (v as usize, triangles[t as usize]);
            let corners = tri.map(|i| i as usize);
            if fixed[vi] && corners.iter().all(|&i| fixed[i]) {
                return None;
            }
            let reach = delta + motion[vi] + corners.iter().map(|&i| motion[i]).fold(0.0, f64::max);
            // The triangle's box at the start: a vertex farther from it than the reach is
            // farther from the triangle too.
            let c = corners.map(|i| start[i]);
            if !boxes_overlap((start[vi], start[vi]), (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2])), reach) {
                return None;
            }
            let (q, _) = closest_point_triangle(start[vi], c[0], c[1], c[2]);
            ((q - start[vi]).length() < reach).then(|| {
                let m = 0.25 * (mass[vi] + corners.iter().map(|&i| mass[i]).sum::<f64>());
                SelfPair { vertices: [v, tri[0], tri[1], tri[2]], edge_edge: false, stiffness: stiffness(m) }
            })
        });
        // Edges can pass through each other with every vertex far from every triangle.
        pairs.extend(filter_in_order(&near.edge_edge, parallel, |_, &(e, f)| {
            let [a, b] = edges[e as usize].map(|i| i as usize);
            let [c, d] = edges[f as usize].map(|i| i as usize);
            if fixed[a] && fixed[b] && fixed[c] && fixed[d] {
                return None;
            }
            let reach = delta + motion[a].max(motion[b]) + motion[c].max(motion[d]);
            let segment_box = |p: usize, q: usize| (start[p].min(start[q]), start[p].max(start[q]));
            if !boxes_overlap(segment_box(a, b), segment_box(c, d), reach) {
                return None;
            }
            let (sa, tb) = closest_points_segments(start[a], start[b], start[c], start[d]);
            let gap = (start[a].lerp(start[b], sa) - start[c].lerp(start[d], tb)).length();
            (gap < reach).then(|| {
                let m = 0.25 * (mass[a] + mass[b] + mass[c] + mass[d]);
                SelfPair { vertices: [a as u32, b as u32, c as u32, d as u32], edge_edge: true, stiffness: stiffness(m) }
            })
        }));
        pairs
    }

    /// The continuous-collision fail-safe: finds vertex–triangle and edge–edge pairs that
    /// cross between `start` and `end`, holds their vertices at `start` and gives each
    /// impact zone its mean velocity. Returns the number of crossings stopped.
    pub fn stop_self_crossings(&self, model: &Model, start: &[DVec3], end: &mut [DVec3], v: &mut [DVec3]) -> u64 {
        let (mass, triangles, edges) = (&model.mass, &model.triangles, &model.edges);
        let n = start.len();
        let eps = 1e-3 * self.settings.self_thickness_for(model.mean_edge_length);
        let mut zone: Vec<u32> = (0..n as u32).collect();
        fn root(zone: &mut [u32], mut i: u32) -> u32 {
            while zone[i as usize] != i {
                zone[i as usize] = zone[zone[i as usize] as usize];
                i = zone[i as usize];
            }
            i
        }
        let mut stopped = 0u64;
        let mut frozen = vec![false; n];
        for _round in 0..50 {
            let motion = start.iter().zip(end.iter()).map(|(a, b)| a.distance_squared(*b)).fold(0.0, f64::max).sqrt();
            let crossings = find_crossings(start, end, triangles, edges, &self.near_pairs(model, start, motion, eps), eps);
            if crossings.is_empty() {
                break;
            }
            stopped += crossings.len() as u64;
            for group in crossings {
                let r0 = root(&mut zone, group[0]);
                for &i in &group {
                    let r = root(&mut zone, i);
                    zone[r as usize] = r0;
                    frozen[i as usize] = true;
                }
            }
            for i in 0..n {
                if frozen[i] {
                    end[i] = start[i];
                }
            }
        }
        if stopped > 0 {
            // Each zone moves on with its mass-weighted mean velocity (momentum kept).
            let mut sums: std::collections::HashMap<u32, (DVec3, f64)> = std::collections::HashMap::new();
            for i in 0..n {
                if frozen[i] {
                    let e = sums.entry(root(&mut zone, i as u32)).or_insert((DVec3::ZERO, 0.0));
                    e.0 += mass[i] * v[i];
                    e.1 += mass[i];
                }
            }
            for i in 0..n {
                if frozen[i] {
                    let (p, m) = sums[&root(&mut zone, i as u32)];
                    v[i] = p / m;
                }
            }
        }
        stopped
    }
}

/// On meshes of at least this many triangles the searches run on rayon's threads. On
/// smaller ones a search takes tens of microseconds, about what handing it out costs (on the
/// paper's drape, 875 triangles, the pair filters on rayon's threads took half again as
/// long as on one).
const PARALLEL_TRIANGLES: usize = 4096;

/// Runs `search(i, marks, found)` for every i < `count` and returns what it found, in the
/// order of i whatever the number of threads (if `parallel`, fixed chunks on rayon's
/// threads). `marks` holds `marks_len` entries, u32::MAX at first, for the search
/// to mark what item i has taken with i: each thread keeps one array for its chunks, which
/// is sound because no two items share a number.
fn search_in_chunks<T: Send>(count: usize, marks_len: usize, parallel: bool, search: impl Fn(usize, &mut [u32], &mut Vec<T>) + Sync) -> Vec<T> {
    use rayon::prelude::*;
    const CHUNK: usize = 1024;
    let run = |first: usize, marks: &mut [u32], found: &mut Vec<T>| {
        let end = if parallel { (first + CHUNK).min(count) } else { count };
        for i in first..end {
            search(i, marks, found);
        }
    };
    if !parallel {
        let (mut marks, mut found) = (vec![u32::MAX; marks_len], Vec::new());
        run(0, &mut marks, &mut found);
        return found;
    }
    let parts: Vec<Vec<T>> = (0..count.div_ceil(CHUNK))
        .into_par_iter()
        .map_init(
            || vec![u32::MAX; marks_len],
            |marks, c| {
                let mut found = Vec::new();
                run(c * CHUNK, marks, &mut found);
                found
            },
        )
        .collect();
    parts.into_iter().flatten().collect()
}

/// What `keep(i, &items[i])` returns, in the order of i (if `parallel`, fixed chunks on
/// rayon's threads). Both paths run the same loop over a chunk, which `keep` is inlined
/// into: with an iterator adapter on each path it was not, and the paper's drape spent a
/// fifth longer in these filters.
fn filter_in_order<T: Sync, U: Send>(items: &[T], parallel: bool, keep: impl Fn(usize, &T) -> Option<U> + Sync) -> Vec<U> {
    use rayon::prelude::*;
    const CHUNK: usize = 4096;
    let filter = |first: usize, out: &mut Vec<U>| {
        let end = if parallel { (first + CHUNK).min(items.len()) } else { items.len() };
        for (i, item) in items[first..end].iter().enumerate() {
            if let Some(u) = keep(first + i, item) {
                out.push(u);
            }
        }
    };
    let mut found = Vec::new();
    if !parallel {
        filter(0, &mut found);
        return found;
    }
    let parts: Vec<Vec<U>> = (0..items.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut out = Vec::new();
            filter(c * CHUNK, &mut out);
            out
        })
        .collect();
    parts.into_iter().flatten().collect()
}

/// Whether two boxes come within `margin` of each other.
fn boxes_overlap(a: (DVec3, DVec3), b: (DVec3, DVec3), margin: f64) -> bool {
    (a.0 - DVec3::splat(margin)).cmple(b.1).all() && (a.1 + DVec3::splat(margin)).cmpge(b.0).all()
}

fn mean_edge(x: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let sum: f64 = triangles.iter().take(64).map(|t| (x[t[1] as usize] - x[t[0] as usize]).length()).sum();
    sum / triangles.len().clamp(1, 64) as f64
}

/// Groups of vertices of pairs that cross over the step, among the `near` pairs (which must
/// cover the step's paths).
fn find_crossings(start: &[DVec3], end: &[DVec3], triangles: &[[u32; 3]], edges: &[[u32; 2]], near: &NearPairs, eps: f64) -> Vec<Vec<u32>> {
    let swept = |i: usize| (start[i].min(end[i]), start[i].max(end[i]));
    let moving = |i: usize| start[i] != end[i];
    let path = |i: usize| [start[i], end[i]];
    let parallel = triangles.len() >= PARALLEL_TRIANGLES;
    let mut found = filter_in_order(&near.vertex_triangle, parallel, |_, &(v, t)| {
        let (p, tri) = (v as usize, triangles[t as usize]);
        let c = tri.map(|i| i as usize);
        if !moving(p) && c.iter().all(|&i| !moving(i)) {
            return None;
        }
        let lo = c.iter().fold(DVec3::INFINITY, |a, &i| a.min(swept(i).0));
        let hi = c.iter().fold(DVec3::NEG_INFINITY, |a, &i| a.max(swept(i).1));
        if !boxes_overlap(swept(p), (lo, hi), eps) {
            return None;
        }
        vertex_triangle_ccd(path(p), path(c[0]), path(c[1]), path(c[2]), eps).map(|_| vec![v, tri[0], tri[1], tri[2]])
    });
    found.extend(filter_in_order(&near.edge_edge, parallel, |_, &(e, f)| {
        let [a, b] = edges[e as usize].map(|i| i as usize);
        let [c, d] = edges[f as usize].map(|i| i as usize);
        if !moving(a) && !moving(b) && !moving(c) && !moving(d) {
            return None;
        }
        let one = (swept(a).0.min(swept(b).0), swept(a).1.max(swept(b).1));
        let other = (swept(c).0.min(swept(d).0), swept(c).1.max(swept(d).1));
        if !boxes_overlap(one, other, eps) {
            return None;
        }
        edge_edge_ccd(path(a), path(b), path(c), path(d), eps).map(|_| vec![a as u32, b as u32, c as u32, d as u32])
    }));
    found
}

/// Edge–triangle crossings in a mesh (edges that share no vertex with the triangle).
pub fn count_self_intersections(x: &[DVec3], triangles: &[[u32; 3]], edges: &[[u32; 2]]) -> usize {
    let cell = mean_edge(x, triangles).max(1e-6);
    let boxes: Vec<_> = triangles
        .iter()
        .map(|tri| {
            let c = tri.map(|i| x[i as usize]);
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
        })
        .collect();
    let hash = SpatialHash::new(cell, &boxes);
    let mut count = 0;
    let mut seen = Vec::new();
    for [a, b] in edges {
        let (p, q) = (x[*a as usize], x[*b as usize]);
        seen.clear();
        hash.query_box(p.min(q), p.max(q), |t| {
            if !seen.contains(&t) {
                seen.push(t);
            }
        });
        for &t in &seen {
            let tri = triangles[t as usize];
            if tri.contains(a) || tri.contains(b) {
                continue;
            }
            let c = tri.map(|i| x[i as usize]);
            if segment_crosses_triangle(p, q, c[0], c[1], c[2]) {
                count += 1;
            }
        }
    }
    count
}

impl StepContacts {
    pub fn is_empty(&self) -> bool {
        self.planes.is_empty() && self.pairs.is_empty()
    }

    pub fn plane_count(&self) -> usize {
        self.planes.len()
    }

    pub fn pair_count(&self) -> usize {
        self.pairs.len()
    }

    /// Friction dissipation function F(s) and F'(s) of the tangential slip s over the step.
    fn friction(&self, s: f64) -> (f64, f64) {
        let (e, ms, mk) = (self.slip, self.mu_static, self.mu_kinetic);
        if s <= e {
            (ms * s * s / (2.0 * e), ms * s / e)
        } else {
            let decay = (-(s - e) / e).exp();
            (ms * e / 2.0 + mk * (s - e) + (ms - mk) * e * (1.0 - decay), mk + (ms - mk) * decay)
        }
    }

    /// Distance of a pair at `y`, the unit direction from the second part to the first, and
    /// the weights c with d = n·Σ c_j y_j (to first order).
    fn self_distance(&self, pair: &SelfPair, y: &[DVec3]) -> (f64, DVec3, [f64; 4]) {
        let p = pair.vertices.map(|i| y[i as usize]);
        let (offset, weights) = if pair.edge_edge {
            let (s, t) = closest_points_segments(p[0], p[1], p[2], p[3]);
            (p[0].lerp(p[1], s) - p[2].lerp(p[3], t), [1.0 - s, s, t - 1.0, -t])
        } else {
            let (q, w) = closest_point_triangle(p[0], p[1], p[2], p[3]);
            (p[0] - q, [1.0, -w[0], -w[1], -w[2]])
        };
        let d = offset.length();
        (d, if d > 1e-15 { offset / d } else { DVec3::Z }, weights)
    }

    /// Contact energy plus friction dissipation at positions `y`; `anchor` is x̂ (the
    /// position the step's velocity is measured from).
    pub fn energy(&self, y: &[DVec3], anchor: &[DVec3]) -> f64 {
        let mut e = 0.0;
        for c in &self.planes {
            let i = c.vertex as usize;
            let gap = self.thickness - c.normal.dot(y[i] - c.point);
            if gap > 0.0 {
                e += 0.5 * c.stiffness * gap * gap;
            }
            if c.normal_force > 0.0 {
                let u = y[i] - anchor[i];
                let slip = (u - u.dot(c.normal) * c.normal).length();
                e += c.normal_force * self.friction(slip).0;
            }
        }
        for p in &self.pairs {
            let (d, _, _) = self.self_distance(p, y);
            if d < self.self_thickness {
                e += 0.5 * p.stiffness * (self.self_thickness - d).powi(2);
            }
        }
        e
    }

    /// Adds ∇(energy) to `g`.
    pub fn add_gradient(&self, y: &[DVec3], anchor: &[DVec3], g: &mut [DVec3], fixed: &[bool]) {
        for c in &self.planes {
            let i = c.vertex as usize;
            let gap = self.thickness - c.normal.dot(y[i] - c.point);
            if gap > 0.0 {
                g[i] -= c.stiffness * gap * c.normal;
            }
            if c.normal_force > 0.0 {
                let u = y[i] - anchor[i];
                let t = u - u.dot(c.normal) * c.normal;
                let slip = t.length();
                if slip > 0.0 {
                    g[i] += c.normal_force * self.friction(slip).1 * t / slip;
                }
            }
        }
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                let f = p.stiffness * (self.self_thickness - d);
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    if !fixed[j as usize] {
                        g[j as usize] -= f * weight * n;
                    }
                }
            }
        }
    }

    /// Adds a positive semi-definite approximation of the energy's Hessian to the diagonal
    /// blocks of `k`; the cloth–cloth pairs' off-diagonal parts come from
    /// [`StepContacts::couplings`]. Both are Gauss–Newton (the normal's rotation is left
    /// out), which keeps the system positive definite.
    pub fn add_hessian(&self, y: &[DVec3], anchor: &[DVec3], k: &mut BlockCsr) {
        for c in &self.planes {
            let i = c.vertex as usize;
            let mut block = DMat3::ZERO;
            if self.thickness - c.normal.dot(y[i] - c.point) > 0.0 {
                block += c.stiffness * outer(c.normal, c.normal);
            }
            if c.normal_force > 0.0 {
                // λF(s) of the slip s = |u_T|: curvature λF'(s)/s across the slip and λF''(s)
                // along it. Sticking (s ≤ ε), F is quadratic and both are μ_s/ε. Sliding,
                // F'' < 0 as μ decays to μ_k; 0 is used there. λF'(s)/s along the slip would
                // be up to μ_s/ε·λ: twenty times a resting vertex's inertia at the drape's slip
                // threshold, and with it Newton creeps along a sliding vertex's path at 0.3 µm
                // an iteration.
                let u = y[i] - anchor[i];
                let t = u - u.dot(c.normal) * c.normal;
                let slip = t.length();
                let tangent = DMat3::IDENTITY - outer(c.normal, c.normal);
                let (_, dfriction) = self.friction(slip.max(self.slip));
                block += tangent * (c.normal_force * dfriction / slip.max(self.slip));
                if slip > self.slip {
                    let along = t / slip;
                    block -= outer(along, along) * (c.normal_force * dfriction / slip);
                }
            }
            let slot = k.diagonal_slot(i as u32);
            k.values[slot] += block;
        }
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                let nn = outer(n, n) * p.stiffness;
                for (&j, &weight) in p.vertices.iter().zip(&w) {
                    let slot = k.diagonal_slot(j);
                    k.values[slot] += nn * (weight * weight);
                }
            }
        }
    }
}

impl StepContacts {
    /// Makes prop contact inelastic: a vertex still inside its contact layer at the end of
    /// the step keeps no velocity away from the prop. The penalty is a spring, and BDF2,
    /// which hardly damps, would otherwise give back its energy as a bounce (a dropped
    /// cloth jumped back to 90 % of its height); cloth does not bounce.
    /// Returns the vertices whose velocity changed.
    pub fn absorb_rebound(&self, y: &[DVec3], v: &mut [DVec3]) -> Vec<u32> {
        let mut changed = Vec::new();
        for c in &self.planes {
            let i = c.vertex as usize;
            let outward = v[i].dot(c.normal);
            if outward > 0.0 && self.thickness - c.normal.dot(y[i] - c.point) > 0.0 {
                v[i] -= outward * c.normal;
                changed.push(c.vertex);
            }
        }
        changed
    }

    /// Largest fraction of the Newton direction `d` from `y` along which no cloth–cloth
    /// pair can meet (additive CCD, Li et al. 2021): a pair at distance g whose vertices move
    /// at most |d_p| + max|d_j| cannot close that gap over a step shorter than g divided by it.
    /// Capping each line search there keeps every Newton iterate free of crossings, so the
    /// solve cannot carry a vertex around a triangle's edge to the far side.
    pub fn max_step(&self, y: &[DVec3], d: &[DVec3]) -> f64 {
        self.step_limit(y, d).min(1.0)
    }

    /// The multiple of `d` (any size) from `y` up to which no cloth–cloth pair can meet; see
    /// [`Self::max_step`].
    pub fn step_limit(&self, y: &[DVec3], d: &[DVec3]) -> f64 {
        let mut alpha = f64::INFINITY;
        for p in &self.pairs {
            let v = p.vertices.map(|i| d[i as usize].length());
            let bound = if p.edge_edge { v[0].max(v[1]) + v[2].max(v[3]) } else { v[0] + v[1].max(v[2]).max(v[3]) };
            if bound > 0.0 {
                let (gap, _, _) = self.self_distance(p, y);
                alpha = alpha.min(0.9 * gap / bound);
            }
        }
        alpha.max(0.0)
    }

    /// The rank-one Gauss–Newton terms of the active cloth–cloth pairs at `y`.
    pub fn couplings(&self, y: &[DVec3], out: &mut Vec<Coupling>) {
        for p in &self.pairs {
            let (d, n, w) = self.self_distance(p, y);
            if d < self.self_thickness {
                out.push(Coupling {
                    vertices: p.vertices,
                    weights: w,
                    normal: n,
                    stiffness: p.stiffness,
                });
            }
        }
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::mesh::{Mesh, Pattern};
    use crate::sim::model::{PhysicsOptions, tests::test_fabric};
    use glam::DVec2;
    use std::collections::BTreeSet;

    /// Every pair the step's search must find, by testing all of them.
    fn all_pairs(model: &Model, start: &[DVec3], predicted: &[DVec3], delta: f64) -> BTreeSet<([u32; 4], bool)> {
        let motion = |i: usize| start[i].distance(predicted[i]);
        let mut found = BTreeSet::new();
        for (v, &p) in start.iter().enumerate() {
            for tri in &model.triangles {
                if tri.contains(&(v as u32)) {
                    continue;
                }
                let c = tri.map(|i| i as usize);
                let reach = delta + motion(v) + c.iter().map(|&i| motion(i)).fold(0.0, f64::max);
                let (q, _) = closest_point_triangle(p, start[c[0]], start[c[1]], start[c[2]]);
                if (q - p).length() < reach {
                    found.insert(([v as u32, tri[0], tri[1], tri[2]], false));
                }
            }
        }
        for (e, &[a, b]) in model.edges.iter().enumerate() {
            for &[c, d] in &model.edges[e + 1..] {
                if c == a || c == b || d == a || d == b {
                    continue;
                }
                let [a, b, c, d] = [a, b, c, d].map(|i| i as usize);
                let reach = delta + motion(a).max(motion(b)) + motion(c).max(motion(d));
                let (s, t) = closest_points_segments(start[a], start[b], start[c], start[d]);
                if (start[a].lerp(start[b], s) - start[c].lerp(start[d], t)).length() < reach {
                    found.insert(([a, b, c, d].map(|i| i as u32), true));
                }
            }
        }
        found
    }

    /// A strip folded over itself, its layers sliding past each other: the near-pair
    /// list, kept or renewed, must give exactly the pairs an exhaustive search gives.
    #[test]
    fn near_pair_list_finds_every_pair_an_exhaustive_search_finds() {
        let total = folded_strip_pairs(0.004, 12);
        assert!(total > 100, "the fold should bring many pairs within reach: {total}");
    }

    /// The same on a mesh of over `PARALLEL_TRIANGLES` triangles, whose searches run in
    /// chunks on rayon's threads.
    #[test]
    fn searches_in_parallel_find_every_pair_too() {
        let total = folded_strip_pairs(0.00058, 2);
        assert!(total > 1000, "the fold should bring many pairs within reach: {total}");
    }

    /// Pairs over `steps` steps of the folded strip meshed at `edge`, checked against the
    /// exhaustive search; returns how many there were.
    fn folded_strip_pairs(edge: f64, steps: usize) -> usize {
        let mesh = Mesh::rectangle(0.04, 0.02, edge, Pattern::Regular, 0).unwrap();
        let model = Model::new(&mesh, &test_fabric(), 0.0, PhysicsOptions::default()).unwrap();
        assert_eq!(model.triangles.len() >= PARALLEL_TRIANGLES, edge < 0.001, "{} triangles", model.triangles.len());
        let settings = ContactSettings { self_collision: true, self_thickness: Some(0.002), ..Default::default() };
        let contact = ContactModel::new(Vec::new(), settings).unwrap();
        let folded = |p: DVec2, drift: DVec3| {
            // The layers drift apart in opposite directions, as closing pairs would.
            if p.x <= 0.02 { DVec3::new(p.x, p.y, 0.0) - drift * (0.02 - p.x) / 0.02 } else { DVec3::new(0.04 - p.x, p.y, 0.0015) + drift * (p.x - 0.02) / 0.02 }
        };
        let mut total = 0;
        for step in 0..steps {
            let t = step as f64;
            let drift = |t: f64| DVec3::new(0.0015 * t, 0.001 * (0.7 * t).sin(), -0.0001 * t);
            let start: Vec<DVec3> = model.rest.iter().map(|&p| folded(p, drift(t))).collect();
            let predicted: Vec<DVec3> = model.rest.iter().map(|&p| folded(p, drift(t + 1.0))).collect();
            let contacts = contact.begin_step(&model, &start, &predicted, 0.004);
            let listed: BTreeSet<_> = contacts.pairs.iter().map(|p| (p.vertices, p.edge_edge)).collect();
            assert_eq!(listed.len(), contacts.pairs.len(), "step {step}: a pair listed twice");
            assert_eq!(listed, all_pairs(&model, &start, &predicted, 0.002), "step {step}");
            total += listed.len();
        }
        total
    }
}
