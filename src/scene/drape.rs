//! Drape measurements (BS 5058 / ISO 9073-9, docs/references.md §7): the shadow of the
//! draped cloth on the horizontal plane, its area, its outline in polar form, the drape
//! coefficient and the number of folds (nodes).

use glam::{DVec2, DVec3};

/// The vertical projection of the cloth, rasterised.
pub struct Shadow {
    /// Area of the union of the projected triangles, m².
    pub area: f64,
    /// Outline radius from the centre at each angle: (angle rad, radius m), ascending.
    pub outline: Vec<(f64, f64)>,
}

/// Angular resolution of the outline: half a degree.
const OUTLINE_BINS: usize = 720;

/// Projects the triangles on z = 0 and rasterises their union on a square grid of
/// `resolution` cells a side around `centre`; the outline is the farthest covered cell
/// along each ray from `centre`. Rasterising is used (not polygon clipping) because the
/// union of thousands of overlapping triangles of a folded cloth is what the standard's
/// light box sees, and a grid gives it exactly up to the cell size.
pub fn shadow(x: &[DVec3], triangles: &[[u32; 3]], centre: DVec2, resolution: usize) -> Shadow {
    let reach = x.iter().map(|p| (p.truncate() - centre).abs().max_element()).fold(0.0, f64::max) * 1.001 + 1e-9;
    let cell = 2.0 * reach / resolution as f64;
    let origin = centre - DVec2::splat(reach);
    let mut covered = vec![false; resolution * resolution];
    for t in triangles {
        let p = t.map(|i| (x[i as usize].truncate() - origin) / cell);
        if (p[1] - p[0]).perp_dot(p[2] - p[0]).abs() < 1e-14 {
            continue;
        }
        // Row by row, the cells whose centres lie between the triangle's edges.
        let lo = (p[0].y.min(p[1].y).min(p[2].y) - 0.5).ceil().max(0.0) as usize;
        let hi = (p[0].y.max(p[1].y).max(p[2].y) - 0.5).floor().min(resolution as f64 - 1.0);
        if hi < 0.0 {
            continue;
        }
        for j in lo..=hi as usize {
            let y = j as f64 + 0.5;
            let (mut left, mut right) = (f64::INFINITY, f64::NEG_INFINITY);
            for k in 0..3 {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                if (a.y <= y && y <= b.y) || (b.y <= y && y <= a.y) {
                    let x = if a.y == b.y { a.x.min(b.x) } else { a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x) };
                    let x_other = if a.y == b.y { a.x.max(b.x) } else { x };
                    left = left.min(x);
                    right = right.max(x_other);
                }
            }
            let first = (left - 0.5).ceil().max(0.0);
            let last = (right - 0.5).floor().min(resolution as f64 - 1.0);
            if first <= last {
                covered[j * resolution + first as usize..=j * resolution + last as usize].fill(true);
            }
        }
    }
    let area = covered.iter().filter(|&&c| c).count() as f64 * cell * cell;
    let mut outline = Vec::with_capacity(OUTLINE_BINS);
    let steps = 2 * resolution;
    // A covered cell's centre lies in a triangle, so within the farthest vertex's distance;
    // a ray sample in it is within a cell of that. Samples beyond are skipped (same outline).
    let farthest = x.iter().map(|p| (p.truncate() - centre).length()).fold(0.0, f64::max) + cell;
    let first = ((farthest / (reach * 1.5) * steps as f64).ceil() as usize).min(steps);
    for k in 0..OUTLINE_BINS {
        let angle = 2.0 * std::f64::consts::PI * k as f64 / OUTLINE_BINS as f64;
        let dir = DVec2::from_angle(angle);
        // The farthest covered cell along the ray: marching inwards, the first one met (the
        // ray leaves the square grid once, so the cells outside it are a tail of the ray).
        let mut radius = 0.0;
        for s in (0..first).rev() {
            let r = reach * 1.5 * s as f64 / steps as f64;
            let q = (centre + r * dir - origin) / cell;
            if q.x < 0.0 || q.y < 0.0 || q.x >= resolution as f64 || q.y >= resolution as f64 {
                continue;
            }
            if covered[q.y as usize * resolution + q.x as usize] {
                radius = r;
                break;
            }
        }
        outline.push((angle, radius));
    }
    Shadow { area, outline }
}

/// Drape coefficient DC = (A_shadow − A_support)/(A_specimen − A_support).
pub fn drape_coefficient(shadow_area: f64, specimen_area: f64, support_area: f64) -> f64 {
    (shadow_area - support_area) / (specimen_area - support_area)
}

/// Number of folds: peaks of the outline radius around the circle, after smoothing over
/// `smoothing` radians, that stand out from the troughs on both sides by more than
/// `prominence` metres.
pub fn count_nodes(outline: &[(f64, f64)], smoothing: f64, prominence: f64) -> usize {
    let n = outline.len();
    if n < 8 {
        return 0;
    }
    let half = ((smoothing / (2.0 * std::f64::consts::PI) * n as f64) / 2.0).round() as isize;
    let r: Vec<f64> = (0..n as isize)
        .map(|i| {
            let sum: f64 = (-half..=half).map(|k| outline[(i + k).rem_euclid(n as isize) as usize].1).sum();
            sum / (2 * half + 1) as f64
        })
        .collect();
    // Walk around from the global minimum; a peak counts when the radius has risen more
    // than `prominence` above the last trough and later falls that much below it.
    let start = (0..n).min_by(|&a, &b| r[a].total_cmp(&r[b])).unwrap_or(0);
    let mut peaks = 0;
    let mut trough = r[start];
    let mut crest = f64::NEG_INFINITY;
    let mut rising = true;
    for k in 1..=n {
        let v = r[(start + k) % n];
        if rising {
            crest = crest.max(v);
            if crest - v > prominence && crest - trough > prominence {
                peaks += 1;
                rising = false;
                trough = v;
            }
        } else {
            trough = trough.min(v);
            if v - trough > prominence {
                rising = true;
                crest = v;
            }
        }
    }
    peaks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat star-shaped polygon fan around the origin with radius r(θ).
    fn fan(radius: impl Fn(f64) -> f64, segments: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut x = vec![DVec3::ZERO];
        let mut t = Vec::new();
        for k in 0..segments {
            let a = 2.0 * std::f64::consts::PI * k as f64 / segments as f64;
            x.push(DVec3::new(radius(a) * a.cos(), radius(a) * a.sin(), 0.0));
            t.push([0, k as u32 + 1, ((k + 1) % segments) as u32 + 1]);
        }
        (x, t)
    }

    #[test]
    fn disc_shadow_area_and_outline() {
        let (x, t) = fan(|_| 0.18, 720);
        let s = shadow(&x, &t, DVec2::ZERO, 1024);
        let exact = std::f64::consts::PI * 0.18f64.powi(2);
        assert!((s.area / exact - 1.0).abs() < 2e-3, "{} vs {exact}", s.area);
        assert!(s.outline.iter().all(|(_, r)| (r - 0.18).abs() < 1e-3));
        assert_eq!(count_nodes(&s.outline, 0.1, 0.005), 0);
    }

    #[test]
    fn nodes_of_a_wavy_outline() {
        for nodes in [4usize, 6, 9] {
            let (x, t) = fan(|a| 0.14 + 0.02 * (nodes as f64 * a + 0.3).cos(), 1440);
            let s = shadow(&x, &t, DVec2::ZERO, 1024);
            assert_eq!(count_nodes(&s.outline, 0.1, 0.005), nodes);
        }
        // Overlapping layers count once.
        let (mut x, mut t) = fan(|_| 0.1, 360);
        let (x2, t2) = fan(|_| 0.1, 360);
        let offset = x.len() as u32;
        x.extend(x2);
        t.extend(t2.iter().map(|tri| tri.map(|i| i + offset)));
        let s = shadow(&x, &t, DVec2::ZERO, 1024);
        assert!((s.area / (std::f64::consts::PI * 0.01) - 1.0).abs() < 3e-3);
    }

    #[test]
    fn scanline_shadow_covers_the_cells_whose_centres_are_inside() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let resolution = 64;
        for _ in 0..200 {
            // One random triangle and the square's corners, which fix the grid to [-1, 1]².
            let mut x: Vec<DVec3> = (0..3).map(|_| DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 0.0)).collect();
            x.extend([DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, 0.0)]);
            let s = shadow(&x, &[[0, 1, 2]], DVec2::ZERO, resolution);
            let reach = 1.001 + 1e-9;
            let cell = 2.0 * reach / resolution as f64;
            // Count the cell centres inside by the sign of the three edge functions.
            let p = [0, 1, 2].map(|i| x[i].truncate());
            let inside = |c: DVec2| {
                let w = [0, 1, 2].map(|k| (p[(k + 1) % 3] - c).perp_dot(p[(k + 2) % 3] - c));
                w.iter().all(|&w| w >= 0.0) || w.iter().all(|&w| w <= 0.0)
            };
            let count = (0..resolution * resolution)
                .filter(|k| inside(DVec2::splat(-reach) + cell * DVec2::new((k % resolution) as f64 + 0.5, (k / resolution) as f64 + 0.5)))
                .count();
            assert_eq!((s.area / (cell * cell)).round() as usize, count, "triangle {p:?}");
        }
    }

    #[test]
    fn drape_coefficient_bounds() {
        assert_eq!(drape_coefficient(1.0, 1.0, 0.25), 1.0);
        assert_eq!(drape_coefficient(0.25, 1.0, 0.25), 0.0);
    }
}
