//! Geometry helpers shared by the strip rigs: vertex columns, the centre line, circle fits.

use glam::{DVec2, DVec3};

/// Vertices grouped into columns by rest x (bins of half the grid spacing, so that the
/// shifted rows of the equilateral pattern and the jittered grid both fall into place).
pub struct Columns {
    /// Rest x of each column's bin centre, m, increasing.
    pub rest_x: Vec<f64>,
    pub vertices: Vec<Vec<u32>>,
}

impl Columns {
    pub fn new(rest: &[DVec2], length: f64, edge_length: f64) -> Self {
        let cells = ((length / edge_length).round()).max(1.0);
        let bin = length / cells / 2.0;
        let mut map: std::collections::BTreeMap<i64, Vec<u32>> = Default::default();
        for (i, p) in rest.iter().enumerate() {
            map.entry((p.x / bin).round() as i64).or_default().push(i as u32);
        }
        let (rest_x, vertices) = map.into_iter().map(|(k, v)| (k as f64 * bin, v)).unzip();
        Self { rest_x, vertices }
    }

    /// The column whose rest x is nearest `x`.
    pub fn nearest(&self, x: f64) -> usize {
        let mut best = 0;
        for (i, &cx) in self.rest_x.iter().enumerate() {
            if (cx - x).abs() < (self.rest_x[best] - x).abs() {
                best = i;
            }
        }
        best
    }

    /// Mean current position of each column: the strip's centre line.
    pub fn centre_line(&self, x: &[DVec3]) -> Vec<DVec3> {
        self.vertices
            .iter()
            .map(|col| col.iter().map(|&v| x[v as usize]).sum::<DVec3>() / col.len() as f64)
            .collect()
    }
}

/// Vertices whose rest position satisfies `keep`.
pub fn vertices_where(rest: &[DVec2], keep: impl Fn(DVec2) -> bool) -> Vec<u32> {
    rest.iter().enumerate().filter(|(_, p)| keep(**p)).map(|(i, _)| i as u32).collect()
}

/// Total force the cloth exerts on a group of vertices (their internal + gravity force), N.
/// A clamp holding them supplies the opposite.
pub fn group_force(forces: &[DVec3], group: &[u32]) -> DVec3 {
    group.iter().map(|&v| forces[v as usize]).sum()
}

/// Least-squares circle through points (u, w) (Kåsa's algebraic fit). Returns the radius.
pub fn fit_circle_radius(points: &[(f64, f64)]) -> Option<f64> {
    if points.len() < 3 {
        return None;
    }
    // Centre the data for conditioning, then solve for u² + w² + D u + E w + F = 0.
    let n = points.len() as f64;
    let (mu, mw) = points.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0 / n, a.1 + p.1 / n));
    let mut ata = [[0.0f64; 3]; 3];
    let mut atb = [0.0f64; 3];
    for &(u, w) in points {
        let (u, w) = (u - mu, w - mw);
        let row = [u, w, 1.0];
        let rhs = -(u * u + w * w);
        for i in 0..3 {
            for j in 0..3 {
                ata[i][j] += row[i] * row[j];
            }
            atb[i] += row[i] * rhs;
        }
    }
    let m = glam::DMat3::from_cols_array_2d(&ata);
    if m.determinant().abs() < 1e-300 {
        return None;
    }
    let sol = m.inverse() * DVec3::from_array(atb);
    let (d, e, f) = (sol.x, sol.y, sol.z);
    let r2 = 0.25 * (d * d + e * e) - f;
    (r2 > 0.0).then(|| r2.sqrt())
}

/// Counts half-waves of a sampled signal: runs of one sign whose peak exceeds `fraction`
/// of the largest magnitude (smaller wiggles are noise and join their neighbours).
pub fn count_half_waves(values: &[f64], fraction: f64) -> usize {
    let peak = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if peak == 0.0 {
        return 0;
    }
    let threshold = fraction * peak;
    let mut count = 0;
    let mut last_sign = 0.0;
    for &v in values {
        if v.abs() >= threshold {
            let sign = v.signum();
            if sign != last_sign {
                count += 1;
                last_sign = sign;
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_fit_recovers_radius() {
        let pts: Vec<(f64, f64)> = (0..20).map(|i| {
            let a = 0.1 + 0.05 * i as f64;
            (0.3 + 0.05 * a.cos(), -0.2 + 0.05 * a.sin())
        }).collect();
        assert!((fit_circle_radius(&pts).unwrap() - 0.05).abs() < 1e-12);
    }

    #[test]
    fn half_waves_of_sines() {
        for n in 1..5 {
            let v: Vec<f64> = (0..=200).map(|i| (n as f64 * std::f64::consts::PI * i as f64 / 200.0).sin()).collect();
            assert_eq!(count_half_waves(&v, 0.2), n);
        }
        let noisy: Vec<f64> = (0..=200)
            .map(|i| (std::f64::consts::PI * i as f64 / 200.0).sin() + 0.01 * ((i * 37 % 11) as f64 - 5.0))
            .collect();
        assert_eq!(count_half_waves(&noisy, 0.2), 1);
    }
}
