//! The preconditioned conjugate gradient.

use super::preconditioner::Preconditioner;
use super::system::SystemMatrix;
use glam::DVec3;

/// Outcome of a conjugate-gradient solve.
#[derive(Debug, Clone, Copy)]
pub struct CgReport {
    pub iterations: usize,
    pub relative_residual: f64,
    /// The matrix showed a direction of non-positive curvature (it is not positive
    /// definite); the solve stopped there.
    pub negative_curvature: bool,
}

fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

/// Solves `A x = b` by preconditioned conjugate gradients from `x = 0`, to a residual of
/// `tolerance · |b|`. `A` must be symmetric positive definite on the free vertices.
pub fn pcg(
    a: &SystemMatrix,
    preconditioner: &Preconditioner,
    b: &[DVec3],
    x: &mut [DVec3],
    tolerance: f64,
    max_iterations: usize,
) -> CgReport {
    let n = b.len();
    x.fill(DVec3::ZERO);
    let mut r: Vec<DVec3> = b.iter().zip(a.fixed).map(|(&v, &f)| if f { DVec3::ZERO } else { v }).collect();
    let b_norm = dot(&r, &r).sqrt();
    if b_norm == 0.0 {
        return CgReport { iterations: 0, relative_residual: 0.0, negative_curvature: false };
    }
    let mut z = vec![DVec3::ZERO; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut ap = vec![DVec3::ZERO; n];
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let mut residual = 1.0;
    let mut negative_curvature = false;
    while iterations < max_iterations {
        a.apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 || !pap.is_finite() {
            negative_curvature = true;
            break;
        }
        let alpha = rz / pap;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        iterations += 1;
        residual = dot(&r, &r).sqrt() / b_norm;
        if residual <= tolerance {
            break;
        }
        preconditioner.apply(&r, &mut z);
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
    }
    CgReport { iterations, relative_residual: residual, negative_curvature }
}

