//! Cloth against itself: the near-pair list (a Verlet list found with a spatial hash),
//! the pairs kept apart in each step's solve, and the continuous-collision fail-safe.

use super::geometry::{SpatialHash, closest_point_triangle, closest_points_segments, edge_edge_ccd, segment_crosses_triangle, vertex_triangle_ccd};
use super::{Cloth, ContactModel, PARALLEL_TRIANGLES, SelfPair, TEAM_ITEMS, boxes_overlap, closing_bound, filter_in_order};
use glam::DVec3;
use std::borrow::Cow;

/// Cloth–cloth pairs closer than `reach` at positions `origin` (by their bounding boxes):
/// contact's changing state, kept from step to step by the integrator that owns it (the
/// props and settings, [`ContactModel`], are fixed).
#[derive(Debug, Clone, Default)]
pub struct NearPairs {
    origin: Vec<DVec3>,
    /// Triangle and edge counts of the cloth it was built for, and a checksum of the
    /// seam bands it left out (`Cloth::seam_bands`).
    topology: (usize, usize),
    bands: u64,
    reach: f64,
    /// (vertex, triangle index).
    vertex_triangle: Vec<(u32, u32)>,
    /// (edge, edge) indices, first < second, sharing no vertex.
    edge_edge: Vec<(u32, u32)>,
    /// The pairs along the last step's paths, where that step searched them
    /// (`NearPairs::swept`): the same step's crossing check takes them again.
    along_paths: Option<Box<PathPairs>>,
}

/// Pairs whose paths from `start` to `end` (less their mean motion) come within `reach`,
/// for one step.
#[derive(Debug, Clone)]
struct PathPairs {
    start: Vec<DVec3>,
    end: Vec<DVec3>,
    reach: f64,
    pairs: NearPairs,
}

impl PathPairs {
    /// Whether every pair whose paths from `start` to `end` come within `margin` is listed:
    /// the same start, and ends that depart from the listed ones, less the mean departure,
    /// by at most half of what the reach leaves over `margin`. Each vertex's box (around its
    /// start and its end less the mean motion) then lies within that departure of its
    /// listed box, and a box around several vertices within the largest of theirs.
    fn covers(&self, cloth: Cloth, start: &[DVec3], end: &[DVec3], margin: f64, relative: bool) -> bool {
        if self.start.len() != start.len() || self.pairs.topology != (cloth.triangles.len(), cloth.edges.len()) || self.pairs.bands != bands_checksum(cloth) || self.start != start {
            return false;
        }
        margin + 2.0 * largest_move(&self.end, end, relative) <= self.reach
    }
}

impl NearPairs {
    /// Whether every pair that comes within `margin` while its vertices move at most
    /// `motion` from `start` is listed: in the worst case two vertices have closed by
    /// twice the largest displacement since the list was built and by twice `motion`
    /// (both measured from the cloth's mean displacement where `relative`).
    fn covers(&self, cloth: Cloth, start: &[DVec3], motion: f64, margin: f64, relative: bool) -> bool {
        if self.origin.len() != start.len() || self.topology != (cloth.triangles.len(), cloth.edges.len()) || self.bands != bands_checksum(cloth) {
            return false;
        }
        let moved = largest_move(&self.origin, start, relative);
        2.0 * moved + 2.0 * motion + margin <= self.reach
    }

    /// The pairs within `reach` of each other at `x`, listed for reuse from there.
    fn build(x: &[DVec3], cloth: Cloth, reach: f64) -> Self {
        let points: Vec<_> = x.iter().map(|&p| (p, p)).collect();
        Self { origin: x.to_vec(), ..Self::search(&points, mean_edge(x, cloth.triangles), cloth, reach) }
    }

    /// The pairs whose paths from `a` to `b`, less the motion `centre` that all share, come
    /// within `reach` (each vertex's box around both ends): for one step's motion only (it
    /// is not kept for reuse). Along straight paths no other pair can come that close,
    /// whatever their relative motion, where a list around the start must reach as far as
    /// the fastest vertex moves from the slowest: a landing cloth, half stopped and half
    /// still falling a tenth of a metre a step, listed millions of pairs that way
    /// (docs/fast-path.md). Taking a common motion out changes no pair's distance at any
    /// point of the step, but keeps it out of the boxes: a resting drape's predicted path
    /// includes the step's whole fall under gravity (h²g, 4 cm at 64 ms), and with it the
    /// boxes of its sloping skirt met 1.8 million pairs at 20 000 triangles, 0.45 s a
    /// search, where the same step's search along its actual paths met 30 000.
    pub(super) fn swept(a: &[DVec3], b: &[DVec3], centre: DVec3, cloth: Cloth, reach: f64) -> Self {
        let boxes: Vec<_> = a.iter().zip(b).map(|(&p, &q)| path_box(p, q, centre)).collect();
        Self::search(&boxes, mean_edge(a, cloth.triangles), cloth, reach)
    }

    /// Vertex–triangle and edge–edge pairs whose boxes (vertex v's `points[v]`, a triangle's
    /// or an edge's the union of its corners') come within `reach`, less those near a
    /// common seam still being sewn.
    fn search(points: &[(DVec3, DVec3)], edge_length: f64, cloth: Cloth, reach: f64) -> Self {
        let (triangles, edges) = (cloth.triangles, cloth.edges);
        let parallel = triangles.len() >= PARALLEL_TRIANGLES;
        let cell = edge_length.max(reach).max(1e-6);
        let hash = SpatialHash::new(cell, points);
        let pad = DVec3::splat(reach);
        let union = |corners: &[u32]| {
            corners.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| (lo.min(points[i as usize].0), hi.max(points[i as usize].1)))
        };
        // The hash returns an item once per cell it overlaps (and its bucket-mates): each
        // query marks what it has taken with its own number instead of searching a list of
        // them, which costs a search per item found.
        // Each item's finds are sorted, so that the list's order, and with it the order in
        // which contact forces are summed, does not depend on the hash's cells: every search
        // that lists the pairs in reach gives a step the same contacts to the last bit.
        let vertex_triangle = search_in_chunks(triangles.len(), points.len(), parallel, |t, taken, found| {
            let tri = triangles[t];
            let (lo, hi) = union(&tri);
            let first = found.len();
            hash.query_box(lo - pad, hi + pad, |v| {
                if taken[v as usize] != t as u32 && !tri.contains(&v) && boxes_overlap(points[v as usize], (lo, hi), reach) && !cloth.sewn_together(&[v], &tri) {
                    taken[v as usize] = t as u32;
                    found.push((v, t as u32));
                }
            });
            found[first..].sort_unstable();
        });
        let boxes: Vec<_> = edges.iter().map(|e| union(e)).collect();
        let hash = SpatialHash::new(cell, &boxes);
        let edge_edge = search_in_chunks(edges.len(), edges.len(), parallel, |e, taken, found| {
            let [a, b] = edges[e];
            let first = found.len();
            hash.query_box(boxes[e].0 - pad, boxes[e].1 + pad, |f| {
                let [c, d] = edges[f as usize];
                if (f as usize) > e
                    && taken[f as usize] != e as u32
                    && c != a
                    && c != b
                    && d != a
                    && d != b
                    && boxes_overlap(boxes[e], boxes[f as usize], reach)
                    && !cloth.sewn_together(&[a, b], &[c, d])
                {
                    taken[f as usize] = e as u32;
                    found.push((e as u32, f));
                }
            });
            found[first..].sort_unstable();
        });
        Self { origin: Vec::new(), topology: (triangles.len(), edges.len()), bands: bands_checksum(cloth), reach, vertex_triangle, edge_edge, along_paths: None }
    }
}

/// A checksum of the cloth's seam bands: a list built with other bands left out other pairs.
fn bands_checksum(cloth: Cloth) -> u64 {
    cloth.seam_bands.iter().enumerate().fold(0u64, |sum, (v, &bits)| sum.wrapping_mul(31).wrapping_add(bits ^ v as u64))
}

/// From this relative motion in a step, in mean edges (twice the largest centred move),
/// the fast path searches along the vertices' paths instead of renewing the list around
/// the start: a list renewed there, its reach widened by that motion, would be renewed
/// again within two steps of the same motion (its skin is half an edge), where the search
/// along one step's paths lists far fewer pairs (in a 10k circle skirt's fall, 1.4 million
/// around the start at 40 mm reach against 0.2–0.4 million along the paths). Searching along paths
/// from 2, 1, 0.5 and 0.25 edges, with the same counts to the iteration (the list only
/// narrows what the step's filter examines), contact took 2.92, 2.05, 1.90 and 1.81 s on
/// the 20k drape; 2.24, 1.81, 1.79 and 1.65 s on the tablecloth; on the sphere drop's first
/// 0.4 s (one thread) 1.98, 1.72, 1.66 and 1.62 s; on the 10k circle skirt's first 2 s 7.04
/// s at 2 and 5.27 s at 0.25 (docs/performance-log.md, "2026-12-06: cloth–cloth pairs along the paths from a quarter edge").
/// At rest the list, which lasts many steps, is renewed instead.
const SWEPT_FROM_EDGES: f64 = 0.25;

/// The near-pair list's skin: half an edge lets a draping cloth keep its list for many
/// steps while adding few pairs beyond those in reach.
fn skin(cloth: Cloth) -> f64 {
    0.5 * cloth.mean_edge_length
}

/// The displacement from `from` to `to` that bounds and path boxes are measured from:
/// their mean displacement where `relative`, else none.
fn common_motion(from: &[DVec3], to: &[DVec3], relative: bool) -> DVec3 {
    if relative && !from.is_empty() {
        from.iter().zip(to).map(|(a, b)| *b - *a).sum::<DVec3>() / from.len() as f64
    } else {
        DVec3::ZERO
    }
}

/// The largest displacement from `from` to `to`, measured from their mean displacement
/// where `relative` (two vertices close by at most twice it either way).
fn largest_move(from: &[DVec3], to: &[DVec3], relative: bool) -> f64 {
    let centre = common_motion(from, to, relative);
    from.iter().zip(to).map(|(a, b)| ((*b - *a) - centre).length_squared()).fold(0.0, f64::max).sqrt()
}

/// The box around a vertex's straight path from `a` to `b`, less the common motion `centre`.
fn path_box(a: DVec3, b: DVec3, centre: DVec3) -> (DVec3, DVec3) {
    (a.min(b - centre), a.max(b - centre))
}

impl ContactModel {

    /// The near-pair list for a search from `start` over paths of at most `motion` for
    /// pairs that come within `margin`, renewed if it does not cover them.
    fn near_pairs<'n>(&self, cloth: Cloth, near: &'n mut NearPairs, start: &[DVec3], motion: f64, margin: f64) -> &'n NearPairs {
        if !near.covers(cloth, start, motion, margin, self.settings.relative_motion) {
            *near = NearPairs::build(start, cloth, margin + 2.0 * motion + skin(cloth));
        }
        near
    }

    /// Candidates for the pairs that come within `margin` on the way from `start` to
    /// `end`: the kept list where it covers them, or where renewing it stays cheap. With
    /// centred bounds (the fast path's long steps) a cloth whose parts move apart by more
    /// than `SWEPT_FROM_EDGES` edges in a step, as a landing cloth does (half stopped, half
    /// falling a tenth of a metre a step), would need a list as wide as that around every
    /// vertex: millions of pairs, sifted every step. It takes the pairs whose paths' boxes
    /// come within `margin + allowance` instead, made for this step alone.
    ///
    /// Pairs searched along paths are kept with the list for the rest of the step: the
    /// crossing check after the solve takes them again wherever the solved paths stay close
    /// enough to the predicted ones (`PathPairs::covers`) instead of searching its own.
    fn candidates<'n>(&self, cloth: Cloth, near: &'n mut NearPairs, start: &[DVec3], end: &[DVec3], margin: f64, allowance: f64) -> Cow<'n, NearPairs> {
        let relative = self.settings.relative_motion;
        if near.along_paths.as_deref().is_some_and(|kept| kept.covers(cloth, start, end, margin, relative)) {
            return Cow::Borrowed(&near.along_paths.as_deref().expect("checked above").pairs);
        }
        let motion = largest_move(start, end, relative);
        if relative && 2.0 * motion > SWEPT_FROM_EDGES * cloth.mean_edge_length && !near.covers(cloth, start, motion, margin, relative) {
            let centre = common_motion(start, end, relative);
            let pairs = NearPairs::swept(start, end, centre, cloth, margin + allowance);
            let kept = near.along_paths.insert(Box::new(PathPairs { start: start.to_vec(), end: end.to_vec(), reach: margin + allowance, pairs }));
            return Cow::Borrowed(&kept.pairs);
        }
        Cow::Borrowed(self.near_pairs(cloth, near, start, motion, margin))
    }

    /// Vertex–triangle and edge–edge pairs within reach over the step.
    pub(super) fn self_pairs(&self, cloth: Cloth, near: &mut NearPairs, start: &[DVec3], predicted: &[DVec3], h: f64) -> Vec<SelfPair> {
        let (fixed, mass, triangles, edges) = (cloth.fixed, cloth.mass, cloth.triangles, cloth.edges);
        let parallel = triangles.len() >= PARALLEL_TRIANGLES;
        let delta = self.settings.self_thickness_for(cloth.mean_edge_length);
        let relative = self.settings.relative_motion;
        let motion: Vec<DVec3> = start.iter().zip(predicted).map(|(a, b)| *b - *a).collect();
        // With centred bounds a pair is also kept only where its predicted paths' boxes
        // (less the cloth's mean motion, as the bounds are) come within reach, with the
        // skin's half edge as allowance for the solve's departure from them: the centred
        // bound takes no account of direction, and lists a landed vertex with a falling one
        // beside it that cannot meet it.
        let allowance = skin(cloth);
        let centre = common_motion(start, predicted, relative);
        let path = |i: usize| path_box(start[i], predicted[i], centre);
        let paths = |vertices: &[usize]| vertices.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| (lo.min(path(i).0), hi.max(path(i).1)));
        let paths_meet = |one: &[usize], other: &[usize]| !relative || boxes_overlap(paths(one), paths(other), delta + allowance);
        let near = self.candidates(cloth, near, start, predicted, delta, allowance);
        let stiffness = |m: f64| self.settings.stiffness * m / (h * h);
        let mut pairs = filter_in_order(&near.vertex_triangle, parallel, |_, &(v, t)| {
            let (vi, tri) = (v as usize, triangles[t as usize]);
            let corners = tri.map(|i| i as usize);
            if fixed[vi] && corners.iter().all(|&i| fixed[i]) {
                return None;
            }
            let reach = delta + closing_bound([vi, corners[0], corners[1], corners[2]].map(|i| motion[i]), false, relative);
            // The triangle's box at the start: a vertex farther from it than the reach is
            // farther from the triangle too.
            let c = corners.map(|i| start[i]);
            if !boxes_overlap((start[vi], start[vi]), (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2])), reach) || !paths_meet(&[vi], &corners) {
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
            let reach = delta + closing_bound([a, b, c, d].map(|i| motion[i]), true, relative);
            let segment_box = |p: usize, q: usize| (start[p].min(start[q]), start[p].max(start[q]));
            if !boxes_overlap(segment_box(a, b), segment_box(c, d), reach) || !paths_meet(&[a, b], &[c, d]) {
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
    pub fn stop_self_crossings(&self, cloth: Cloth, near: &mut NearPairs, start: &[DVec3], end: &mut [DVec3], v: &mut [DVec3]) -> u64 {
        let (mass, triangles, edges) = (cloth.mass, cloth.triangles, cloth.edges);
        let n = start.len();
        let eps = 1e-3 * self.settings.self_thickness_for(cloth.mean_edge_length);
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
            let crossings = find_crossings(start, end, triangles, edges, &self.candidates(cloth, near, start, end, eps, 0.0), eps);
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

/// Runs `search(i, marks, found)` for every i < `count` and returns what it found, in the
/// order of i whatever the number of threads (if `parallel`, fixed chunks on rayon's
/// threads; else, from [`TEAM_ITEMS`] items, two halves, one on the team's). `marks` holds
/// `marks_len` entries, u32::MAX at first, for the search to mark what item i has taken
/// with i: each thread keeps one array for its chunks, which is sound because no two items
/// share a number.
fn search_in_chunks<T: Send>(count: usize, marks_len: usize, parallel: bool, search: impl Fn(usize, &mut [u32], &mut Vec<T>) + Sync) -> Vec<T> {
    use rayon::prelude::*;
    const CHUNK: usize = 1024;
    let run = |range: std::ops::Range<usize>, marks: &mut [u32]| {
        let mut found = Vec::new();
        for i in range {
            search(i, marks, &mut found);
        }
        found
    };
    let fresh = || vec![u32::MAX; marks_len];
    if parallel {
        let parts: Vec<Vec<T>> = (0..count.div_ceil(CHUNK)).into_par_iter().map_init(fresh, |marks, c| run(c * CHUNK..((c + 1) * CHUNK).min(count), marks)).collect();
        parts.into_iter().flatten().collect()
    } else if count >= TEAM_ITEMS {
        crate::sim::team::join_in_order(|| run(0..count / 2, &mut fresh()), || run(count / 2..count, &mut fresh()))
    } else {
        run(0..count, &mut fresh())
    }
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

/// The vertex–triangle pairs closer than `reach` at `x` that self-collision takes in (the
/// triangle not holding the vertex, the two not near a common open seam nor neighbours once
/// welded), as (vertex, triangle, distance).
pub fn pairs_within(x: &[DVec3], cloth: Cloth, reach: f64) -> Vec<(u32, u32, f64)> {
    let near = NearPairs::build(x, cloth, reach);
    near.vertex_triangle
        .iter()
        .filter_map(|&(v, t)| {
            let c = cloth.triangles[t as usize].map(|i| x[i as usize]);
            let gap = (closest_point_triangle(x[v as usize], c[0], c[1], c[2]).0 - x[v as usize]).length();
            (gap < reach).then_some((v, t, gap))
        })
        .collect()
}

/// Edge–triangle crossings in a mesh (edges that share no vertex with the triangle).
pub fn count_self_intersections(x: &[DVec3], triangles: &[[u32; 3]], edges: &[[u32; 2]]) -> usize {
    self_intersections(x, triangles, edges).len()
}

/// The edge–triangle crossings in a mesh, as (edge, triangle) indices.
pub fn self_intersections(x: &[DVec3], triangles: &[[u32; 3]], edges: &[[u32; 2]]) -> Vec<(usize, usize)> {
    let cell = mean_edge(x, triangles).max(1e-6);
    let boxes: Vec<_> = triangles
        .iter()
        .map(|tri| {
            let c = tri.map(|i| x[i as usize]);
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
        })
        .collect();
    let hash = SpatialHash::new(cell, &boxes);
    let mut found = Vec::new();
    let mut seen = Vec::new();
    for (e, [a, b]) in edges.iter().enumerate() {
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
                found.push((e, t as usize));
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::contact::ContactSettings;
    use crate::sim::mesh::{Mesh, Pattern};
    use crate::sim::model::{Model, PhysicsOptions, tests::test_fabric};
    use glam::DVec2;
    use std::collections::BTreeSet;

    /// Every pair the step's search must find, by testing all of them: those whose gap at
    /// the start is under δ plus how far the pair can close, each side's largest move
    /// (measured from the pair's mean move where `relative`, and then only where the boxes
    /// around the two sides' predicted paths, less the cloth's mean motion, come within δ
    /// and half an edge).
    fn all_pairs(model: &Model, start: &[DVec3], predicted: &[DVec3], delta: f64, relative: bool) -> BTreeSet<([u32; 4], bool)> {
        let moves = |ids: [usize; 4]| {
            let d = ids.map(|i| predicted[i] - start[i]);
            let centre = if relative { (d[0] + d[1] + d[2] + d[3]) / 4.0 } else { DVec3::ZERO };
            d.map(|di| (di - centre).length())
        };
        // The paths less the cloth's mean motion.
        let centre = common_motion(start, predicted, relative);
        let paths_meet = |one: &[usize], other: &[usize]| {
            let span = |ids: &[usize], k: usize| {
                let ends = ids.iter().flat_map(|&i| [start[i][k], predicted[i][k] - centre[k]]);
                ends.clone().fold(f64::INFINITY, f64::min)..=ends.fold(f64::NEG_INFINITY, f64::max)
            };
            let margin = delta + 0.5 * model.mean_edge_length;
            !relative || (0..3).all(|k| span(one, k).start() - margin <= *span(other, k).end() && span(other, k).start() - margin <= *span(one, k).end())
        };
        let mut found = BTreeSet::new();
        for (v, &p) in start.iter().enumerate() {
            for tri in &model.triangles {
                if tri.contains(&(v as u32)) {
                    continue;
                }
                let c = tri.map(|i| i as usize);
                let m = moves([v, c[0], c[1], c[2]]);
                let reach = delta + m[0] + m[1].max(m[2]).max(m[3]);
                let (q, _) = closest_point_triangle(p, start[c[0]], start[c[1]], start[c[2]]);
                if (q - p).length() < reach && paths_meet(&[v], &c) {
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
                let m = moves([a, b, c, d]);
                let reach = delta + m[0].max(m[1]) + m[2].max(m[3]);
                let (s, t) = closest_points_segments(start[a], start[b], start[c], start[d]);
                if (start[a].lerp(start[b], s) - start[c].lerp(start[d], t)).length() < reach && paths_meet(&[a, b], &[c, d]) {
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
        let total = folded_strip_pairs(0.004, 12, false, 0.0);
        assert!(total > 100, "the fold should bring many pairs within reach: {total}");
    }

    /// The same with the bound on how far a pair can close taken from the pair's own motion
    /// relative to its mean (the fast path), while the whole strip also falls: the list,
    /// kept over steps by the cloth's motion about its mean, still misses no pair, and the
    /// common fall no longer brings every in-plane neighbour into it.
    #[test]
    fn centred_motion_misses_no_pair_and_ignores_the_common_fall() {
        let relative = folded_strip_pairs(0.004, 12, true, 0.003);
        let absolute = folded_strip_pairs(0.004, 12, false, 0.003);
        assert!(relative > 100, "the fold should still bring many pairs within reach: {relative}");
        assert!(relative < absolute, "centred: {relative} pairs, each vertex's own move: {absolute}");
    }

    /// A strip folded over itself whose lower half lies still while the upper half falls
    /// onto it, a centimetre a step (five edges): parts of the cloth move apart by far more
    /// than the list's skin, as a landing cloth's do, and the pairs are taken along the
    /// vertices' paths. They must still be exactly those an exhaustive search gives.
    #[test]
    fn a_landing_cloth_misses_no_pair_along_its_paths() {
        let (model, contact) = strip(0.002, true);
        let at = |p: DVec2, t: f64| if p.x <= 0.02 { DVec3::new(p.x, p.y, 0.0) } else { DVec3::new(0.04 - p.x, p.y, 0.035 - 0.01 * t) };
        let total = pairs_over_steps(&model, &contact, 5, true, at);
        assert!(total > 100, "the falling layer should come within reach of the lower one: {total}");
    }

    /// The crossing check after a step's solve takes the pairs the step searched along its
    /// predicted paths, where the solved ends depart from the predicted ones by less than
    /// half the allowance: it must stop exactly the crossings a search of its own stops.
    /// An upper layer 3 mm above a lower one is predicted 6 mm down through it (three
    /// edges, so the pairs are searched along the paths), and solved to ends that depart
    /// from that by up to 0.4 mm; then by 4 mm, past what the kept pairs cover.
    #[test]
    fn the_crossing_check_takes_the_steps_pairs_along_paths_and_stops_the_same_crossings() {
        let (model, contact) = strip(0.002, true);
        let cloth = model.cloth();
        let upper = |p: DVec2| p.x > 0.02;
        let start: Vec<DVec3> = model.rest.iter().map(|&p| if upper(p) { DVec3::new(0.04 - p.x, p.y, 0.003) } else { DVec3::new(p.x, p.y, 0.0) }).collect();
        let predicted: Vec<DVec3> = start.iter().zip(&model.rest).map(|(&x, &p)| if upper(p) { x - DVec3::Z * 0.006 } else { x }).collect();
        for (departure, kept) in [(0.0004, true), (0.004, false)] {
            let end: Vec<DVec3> = predicted.iter().enumerate().map(|(i, &x)| x + DVec3::new((i as f64).sin(), (1.7 * i as f64).cos(), 0.5) * (departure / 1.5)).collect();
            let mut near = NearPairs::default();
            contact.begin_step(cloth, &mut near, &start, &[], &predicted, 0.004);
            let listed = near.along_paths.as_ref().map(|k| k.pairs.vertex_triangle.len() + k.pairs.edge_edge.len()).expect("the step searched along its paths");
            let eps = 1e-3 * contact.settings.self_thickness_for(cloth.mean_edge_length);
            let taken = contact.candidates(cloth, &mut near, &start, &end, eps, 0.0).into_owned();
            assert_eq!(taken.vertex_triangle.len() + taken.edge_edge.len() == listed, kept, "departure {departure}: {listed} pairs kept");
            let (mut end_kept, mut v_kept) = (end.clone(), vec![DVec3::X; end.len()]);
            let (mut end_own, mut v_own) = (end.clone(), vec![DVec3::X; end.len()]);
            let stopped = contact.stop_self_crossings(cloth, &mut near, &start, &mut end_kept, &mut v_kept);
            let own = contact.stop_self_crossings(cloth, &mut NearPairs::default(), &start, &mut end_own, &mut v_own);
            assert!(stopped > 10, "the upper layer crosses the lower one: {stopped} crossings stopped");
            assert_eq!((stopped, &end_kept, &v_kept), (own, &end_own, &v_own), "departure {departure}");
        }
    }

    /// A sheet hanging still, as a drape's skirt nearly does, whose predicted path is a
    /// step's fall under gravity (4 cm, twenty edges) that all its vertices share, and one
    /// vertex of which also moves three edges: the pairs are taken along the paths, and
    /// must be exactly those an exhaustive search gives, found without listing the fall:
    /// along the whole 4 cm every vertex's path box meets some twenty rows of the sheet
    /// below it (101 838 candidates for 6 213 pairs; 16 339 with the fall taken out).
    #[test]
    fn a_motion_the_whole_cloth_shares_lists_no_extra_pairs() {
        let (model, contact) = strip(0.002, true);
        let fall = DVec3::new(0.0, 0.0, -0.04);
        let start: Vec<DVec3> = model.rest.iter().map(|p| DVec3::new(p.y, 0.0, -p.x)).collect();
        let mut predicted: Vec<DVec3> = start.iter().map(|&p| p + fall).collect();
        let mover = model.rest.iter().position(|p| (p.x - 0.02).abs() < 1e-9 && (p.y - 0.01).abs() < 1e-9).unwrap();
        predicted[mover] += DVec3::new(0.0, 0.006, 0.0);
        let mut near = NearPairs::default();
        let candidates = contact.candidates(model.cloth(), &mut near, &start, &predicted, 0.002, skin(model.cloth())).into_owned();
        let found = candidates.vertex_triangle.len() + candidates.edge_edge.len();
        let contacts = contact.begin_step(model.cloth(), &mut near, &start, &[], &predicted, 0.004);
        let listed: BTreeSet<_> = contacts.pairs.iter().map(|p| (p.vertices, p.edge_edge)).collect();
        assert_eq!(listed, all_pairs(&model, &start, &predicted, 0.002, true));
        assert!(!listed.is_empty() && found <= 3 * listed.len(), "{found} candidates for {} pairs", listed.len());
    }

    /// Two layers in contact, 1 mm apart within a 2 mm layer: the upper one sliding 5 mm
    /// along them may take the whole step (it crosses nothing), where the bound on how
    /// fast each pair can close would hold it to 0.9 · 1/5 of it; moving 5 mm down through
    /// the lower one it stops at nine tenths of the way to the crossing, a fifth of the step.
    #[test]
    fn a_sliding_layer_takes_its_whole_step_and_a_crossing_one_stops_short() {
        let (model, contact) = strip(0.004, true);
        let upper = |p: DVec2| p.x > 0.02;
        let start: Vec<DVec3> = model.rest.iter().map(|&p| if upper(p) { DVec3::new(0.04 - p.x, p.y, 0.001) } else { DVec3::new(p.x, p.y, 0.0) }).collect();
        for (motion, expected) in [(DVec3::new(0.0, 0.005, 0.0), 1.0), (DVec3::new(0.0, 0.0, -0.005), 0.9 * 0.2)] {
            let d: Vec<DVec3> = model.rest.iter().map(|&p| if upper(p) { motion } else { DVec3::ZERO }).collect();
            let predicted: Vec<DVec3> = start.iter().zip(&d).map(|(x, d)| *x + *d).collect();
            let contacts = contact.begin_step(model.cloth(), &mut NearPairs::default(), &start, &[], &predicted, 0.004);
            assert!(contacts.pair_count() > 100, "the layers are in contact: {} pairs", contacts.pair_count());
            let limit = contacts.max_step(&start, &d);
            assert!((limit - expected).abs() < 1e-6, "moving by {motion}: step limited to {limit}, expected {expected}");
        }
    }

    /// The same on a mesh of over `PARALLEL_TRIANGLES` triangles, whose searches run in
    /// chunks on rayon's threads.
    #[test]
    fn searches_in_parallel_find_every_pair_too() {
        let total = folded_strip_pairs(0.00058, 2, false, 0.0);
        assert!(total > 1000, "the fold should bring many pairs within reach: {total}");
    }

    /// Pairs over `steps` steps of the folded strip meshed at `edge` and falling `fall` m a
    /// step, with the closing bound centred where `relative`, checked against the exhaustive
    /// search; returns how many there were.
    fn folded_strip_pairs(edge: f64, steps: usize, relative: bool, fall: f64) -> usize {
        let (model, contact) = strip(edge, relative);
        assert_eq!(model.triangles.len() >= PARALLEL_TRIANGLES, edge < 0.001, "{} triangles", model.triangles.len());
        let folded = |p: DVec2, drift: DVec3| {
            // The layers drift apart in opposite directions, as closing pairs would.
            if p.x <= 0.02 { DVec3::new(p.x, p.y, 0.0) - drift * (0.02 - p.x) / 0.02 } else { DVec3::new(0.04 - p.x, p.y, 0.0015) + drift * (p.x - 0.02) / 0.02 }
        };
        // Both layers also fall together, `fall` m a step.
        let drift = |t: f64| DVec3::new(0.0015 * t, 0.001 * (0.7 * t).sin(), -0.0001 * t);
        pairs_over_steps(&model, &contact, steps, relative, |p, t| folded(p, drift(t)) - DVec3::Z * (fall * t))
    }

    /// A 4 × 2 cm strip meshed at `edge` with self-collision in a 2 mm layer, bounds on the
    /// pairs' closing centred where `relative`.
    fn strip(edge: f64, relative: bool) -> (Model, ContactModel) {
        let mesh = Mesh::rectangle(0.04, 0.02, edge, Pattern::Regular, 0).unwrap();
        let model = Model::new(&mesh, &test_fabric(), 0.0, PhysicsOptions::default()).unwrap();
        let settings = ContactSettings { self_collision: true, self_thickness: Some(0.002), relative_motion: relative, ..Default::default() };
        (model, ContactModel::new(Vec::new(), settings).unwrap())
    }

    /// Pairs over `steps` steps of the cloth at `at(rest position, step)`, each step's list
    /// (the near-pair list kept across them) checked against the exhaustive search.
    fn pairs_over_steps(model: &Model, contact: &ContactModel, steps: usize, relative: bool, at: impl Fn(DVec2, f64) -> DVec3) -> usize {
        let (mut near, mut total) = (NearPairs::default(), 0);
        for step in 0..steps {
            let t = step as f64;
            let start: Vec<DVec3> = model.rest.iter().map(|&p| at(p, t)).collect();
            let predicted: Vec<DVec3> = model.rest.iter().map(|&p| at(p, t + 1.0)).collect();
            let contacts = contact.begin_step(model.cloth(), &mut near, &start, &[], &predicted, 0.004);
            let listed: BTreeSet<_> = contacts.pairs.iter().map(|p| (p.vertices, p.edge_edge)).collect();
            assert_eq!(listed.len(), contacts.pairs.len(), "step {step}: a pair listed twice");
            assert_eq!(listed, all_pairs(model, &start, &predicted, 0.002, relative), "step {step}");
            total += listed.len();
        }
        total
    }
}
