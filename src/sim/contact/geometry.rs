//! Cloth–cloth geometry: closest points, continuous collision tests and a uniform spatial
//! hash. Written by hand because they run on the cloth's own f64 positions every step and
//! parry3d's versions work on f32 shapes built per query.

use glam::DVec3;

/// Closest point of triangle (a, b, c) to p, with its barycentric weights (Ericson,
/// Real-Time Collision Detection, §5.1.5).
pub fn closest_point_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, [f64; 3]) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

/// Closest points of segments p1q1 and p2q2: parameters (s, t) along each.
pub fn closest_points_segments(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> (f64, f64) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let eps = 1e-20;
    if a <= eps && e <= eps {
        return (0.0, 0.0);
    }
    if a <= eps {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(r);
    if e <= eps {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > eps * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
    let mut t = (b * s + f) / e;
    if t < 0.0 {
        t = 0.0;
        s = (-c / a).clamp(0.0, 1.0);
    } else if t > 1.0 {
        t = 1.0;
        s = ((b - c) / a).clamp(0.0, 1.0);
    }
    (s, t)
}

/// Whether segment pq crosses triangle (a, b, c) (Möller–Trumbore on the segment).
pub fn segment_crosses_triangle(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    let dir = q - p;
    let e1 = b - a;
    let e2 = c - a;
    let h = dir.cross(e2);
    let det = e1.dot(h);
    let scale = e1.length() * e2.length() * dir.length();
    if det.abs() <= 1e-12 * scale {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = inv * s.dot(h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(e1);
    let v = inv * dir.dot(qv);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = inv * e2.dot(qv);
    (0.0..=1.0).contains(&t)
}

/// Roots in [0, 1] of the cubic through f(0), f(1/3), f(2/3), f(1), ascending.
fn cubic_roots_unit(f: impl Fn(f64) -> f64) -> Vec<f64> {
    let (f0, f1, f2, f3) = (f(0.0), f(1.0 / 3.0), f(2.0 / 3.0), f(1.0));
    // Coefficients of c0 + c1 t + c2 t² + c3 t³ from the four samples.
    let c0 = f0;
    let c3 = 4.5 * (f3 - 3.0 * f2 + 3.0 * f1 - f0);
    // f(1/3) = c0 + c1/3 + c2/9 + c3/27 and f(1) = c0 + c1 + c2 + c3, so
    // 3 f(1/3) − f(1) = 2 c0 − (2/3) c2 − (8/9) c3.
    let c2 = (2.0 * c0 - (8.0 / 9.0) * c3 - (3.0 * f1 - f3)) * 1.5;
    let c1 = f3 - c0 - c2 - c3;
    let poly = |t: f64| ((c3 * t + c2) * t + c1) * t + c0;
    // Split [0, 1] at the critical points, then bisect each monotone piece with a sign change.
    let mut knots = vec![0.0];
    let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, c1);
    if qa.abs() > 1e-300 {
        let disc = qb * qb - 4.0 * qa * qc;
        if disc >= 0.0 {
            let s = disc.sqrt();
            let mut r = [(-qb - s) / (2.0 * qa), (-qb + s) / (2.0 * qa)];
            r.sort_by(f64::total_cmp);
            knots.extend(r.into_iter().filter(|t| *t > 0.0 && *t < 1.0));
        }
    } else if qb.abs() > 1e-300 {
        let t = -qc / qb;
        if t > 0.0 && t < 1.0 {
            knots.push(t);
        }
    }
    knots.push(1.0);
    let mut roots = Vec::new();
    for w in knots.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let (flo, fhi) = (poly(lo), poly(hi));
        if flo == 0.0 {
            roots.push(lo);
            continue;
        }
        if flo.signum() == fhi.signum() {
            continue;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if poly(mid).signum() == flo.signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        roots.push(0.5 * (lo + hi));
    }
    if poly(1.0) == 0.0 {
        roots.push(1.0);
    }
    roots
}

/// Earliest time in [0, 1] at which point p meets triangle (a, b, c), all moving linearly
/// from their `0` to their `1` positions, within a distance `eps`.
pub fn vertex_triangle_ccd(p: [DVec3; 2], a: [DVec3; 2], b: [DVec3; 2], c: [DVec3; 2], eps: f64) -> Option<f64> {
    let at = |x: [DVec3; 2], t: f64| x[0] + (x[1] - x[0]) * t;
    let coplanar = |t: f64| {
        let (pa, pb, pc, pp) = (at(a, t), at(b, t), at(c, t), at(p, t));
        (pb - pa).cross(pc - pa).dot(pp - pa)
    };
    let mut candidates = cubic_roots_unit(coplanar);
    candidates.push(1.0);
    candidates.into_iter().find(|&t| {
        let (pp, pa, pb, pc) = (at(p, t), at(a, t), at(b, t), at(c, t));
        let (q, _) = closest_point_triangle(pp, pa, pb, pc);
        (q - pp).length() <= eps
    })
}

/// Earliest time in [0, 1] at which edges (p1, q1) and (p2, q2), moving linearly, meet
/// within a distance `eps`.
pub fn edge_edge_ccd(p1: [DVec3; 2], q1: [DVec3; 2], p2: [DVec3; 2], q2: [DVec3; 2], eps: f64) -> Option<f64> {
    let at = |x: [DVec3; 2], t: f64| x[0] + (x[1] - x[0]) * t;
    let coplanar = |t: f64| {
        let (a, b, c, d) = (at(p1, t), at(q1, t), at(p2, t), at(q2, t));
        (b - a).cross(d - c).dot(c - a)
    };
    let mut candidates = cubic_roots_unit(coplanar);
    candidates.push(1.0);
    candidates.into_iter().find(|&t| {
        let (a, b, c, d) = (at(p1, t), at(q1, t), at(p2, t), at(q2, t));
        let (s, u) = closest_points_segments(a, b, c, d);
        ((a + (b - a) * s) - (c + (d - c) * u)).length() <= eps
    })
}

/// A uniform grid over boxes, rebuilt each step. The cloth's vertices are spread evenly at
/// about one edge length, so a grid of that size keeps every query to a handful of cells.
///
/// Written by hand as a counting-sorted hash table (Teschner et al., "Optimized Spatial
/// Hashing for Collision Detection of Deformable Objects", 2003): cells hash into a table
/// about twice the items' count, and each bucket's items lie contiguously. Building it
/// allocates two arrays, where the map of cells to vectors it replaces allocated a vector
/// per cell. Cells that share a bucket return each other's items, and an item may repeat:
/// callers test boxes anyway.
pub struct SpatialHash {
    cell: f64,
    mask: u32,
    /// Bucket b's items are `items[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl SpatialHash {
    /// The grid of cell size `cell` over `boxes` (lo, hi); item i is box i.
    pub fn new(cell: f64, boxes: &[(DVec3, DVec3)]) -> Self {
        let buckets = (2 * boxes.len()).next_power_of_two().max(16);
        let mut hash = Self { cell, mask: buckets as u32 - 1, start: vec![0; buckets + 1], items: Vec::new() };
        let mut count = vec![0u32; buckets];
        for &(lo, hi) in boxes {
            hash.for_buckets(lo, hi, |b| count[b] += 1);
        }
        for (b, &c) in count.iter().enumerate() {
            hash.start[b + 1] = hash.start[b] + c;
        }
        let mut items = vec![0; hash.start[buckets] as usize];
        // Each bucket fills from its end down.
        for (i, &(lo, hi)) in boxes.iter().enumerate() {
            hash.for_buckets(lo, hi, |b| {
                count[b] -= 1;
                items[(hash.start[b] + count[b]) as usize] = i as u32;
            });
        }
        hash.items = items;
        hash
    }

    /// Calls `f` with the bucket of every cell the box [lo, hi] touches.
    fn for_buckets(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(usize)) {
        let key = |p: DVec3| (p / self.cell).floor().as_ivec3();
        let (a, b) = (key(lo), key(hi));
        // A box over more cells than the table has buckets (a cloth blown far apart, or a
        // coordinate that is not finite and saturates the cell index) touches every bucket
        // at most once: a bounded loop instead of one over up to 2⁹⁶ cells.
        let cells = |lo: i32, hi: i32| (i64::from(hi) - i64::from(lo) + 1).max(0) as u128;
        if cells(a.x, b.x) * cells(a.y, b.y) * cells(a.z, b.z) > u128::from(self.mask) + 1 {
            (0..=self.mask as usize).for_each(f);
            return;
        }
        for x in a.x..=b.x {
            for y in a.y..=b.y {
                for z in a.z..=b.z {
                    // Large odd multipliers spread neighbouring cells over the table.
                    let h = (x as u32).wrapping_mul(0x9E37_79B1) ^ (y as u32).wrapping_mul(0x85EB_CA77) ^ (z as u32).wrapping_mul(0xC2B2_AE3D);
                    f(((h ^ (h >> 15)) & self.mask) as usize);
                }
            }
        }
    }

    /// Calls `f` for every item in the cells the box [lo, hi] touches, and possibly for
    /// others (an item may repeat).
    pub fn query_box(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u32)) {
        self.for_buckets(lo, hi, |b| {
            self.items[self.start[b] as usize..self.start[b + 1] as usize].iter().for_each(|&i| f(i));
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let (q, w) = closest_point_triangle(DVec3::new(0.2, 0.2, 1.0), a, b, c);
        assert!((q - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-12);
        assert!((w[0] - 0.6).abs() < 1e-12 && (w[1] - 0.2).abs() < 1e-12);
        let (q, _) = closest_point_triangle(DVec3::new(2.0, -1.0, 0.0), a, b, c);
        assert!((q - b).length() < 1e-12);
        let (q, _) = closest_point_triangle(DVec3::new(0.5, -1.0, 0.0), a, b, c);
        assert!((q - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn ccd_finds_a_point_passing_through_a_triangle() {
        let tri = |v: DVec3| [v, v];
        let (a, b, c) = (tri(DVec3::ZERO), tri(DVec3::X), tri(DVec3::Y));
        let p = [DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, -1.0)];
        let t = vertex_triangle_ccd(p, a, b, c, 1e-9).unwrap();
        assert!((t - 0.5).abs() < 1e-9);
        // Passing beside the triangle is no collision.
        let p = [DVec3::new(0.8, 0.8, 1.0), DVec3::new(0.8, 0.8, -1.0)];
        assert!(vertex_triangle_ccd(p, a, b, c, 1e-9).is_none());
        // A rotating triangle sweeping over a still point: the cubic's middle root.
        let p = [DVec3::new(0.25, 0.25, 0.1), DVec3::new(0.25, 0.25, 0.1)];
        let c = [DVec3::new(0.0, 1.0, -0.5), DVec3::new(0.0, 1.0, 1.5)];
        let b = [DVec3::new(1.0, 0.0, -0.5), DVec3::new(1.0, 0.0, 1.5)];
        let t = vertex_triangle_ccd(p, [DVec3::ZERO; 2], b, c, 1e-9).unwrap();
        assert!(t > 0.0 && t < 1.0);
    }

    #[test]
    fn ccd_finds_crossing_edges() {
        let e1 = ([DVec3::new(-1.0, 0.0, 1.0), DVec3::new(-1.0, 0.0, -1.0)], [DVec3::new(1.0, 0.0, 1.0), DVec3::new(1.0, 0.0, -1.0)]);
        let e2 = ([DVec3::new(0.0, -1.0, 0.0); 2], [DVec3::new(0.0, 1.0, 0.0); 2]);
        let t = edge_edge_ccd(e1.0, e1.1, e2.0, e2.1, 1e-9).unwrap();
        assert!((t - 0.5).abs() < 1e-9);
        let e3 = ([DVec3::new(2.0, -1.0, 0.0); 2], [DVec3::new(2.0, 1.0, 0.0); 2]);
        assert!(edge_edge_ccd(e1.0, e1.1, e3.0, e3.1, 1e-9).is_none());
    }

    #[test]
    fn segment_triangle_crossing() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert!(segment_crosses_triangle(DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, -1.0), a, b, c));
        assert!(!segment_crosses_triangle(DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, 0.5), a, b, c));
        assert!(!segment_crosses_triangle(DVec3::new(0.9, 0.9, 1.0), DVec3::new(0.9, 0.9, -1.0), a, b, c));
    }
}
