//! Blow-up checks and the explicit integrator's stability limit.

use super::Model;
use glam::DVec3;

impl Model {

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


    /// Largest stretch ratio l/L over all edges (a blow-up shows as a huge value).
    pub fn max_stretch(&self, x: &[DVec3]) -> f64 {
        self.edges
            .iter()
            .enumerate()
            .map(|(i, &[a, b])| {
                let rest = match &self.edge_rest_lengths {
                    Some(lengths) => lengths[i],
                    None => (self.rest[a as usize] - self.rest[b as usize]).length(),
                };
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
