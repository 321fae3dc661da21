//! The preconditioned conjugate gradient.

use super::preconditioner::Preconditioner;
use super::storage::PARALLEL_ROWS;
use super::system::SystemMatrix;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

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
    pcg_deflated(a, preconditioner, b, x, tolerance, max_iterations, None)
}

/// Earlier solutions of systems like the next one (a run's last Newton directions), kept to
/// deflate the next solves ([`pcg_deflated`]).
#[derive(Debug, Default)]
pub struct Recycled {
    /// Newest last, each scaled to unit length.
    columns: Vec<Vec<DVec3>>,
}

impl Recycled {
    /// Keeps `x` (scaled to unit length) as the newest of at most `keep` columns; columns
    /// of another length (a mesh that changed) are forgotten, and all of them with `keep`
    /// 0.
    pub fn remember(&mut self, x: &[DVec3], keep: usize) {
        // Off (every solve of a scene that does not deflate): nothing to keep, and no pass
        // over `x`.
        if keep == 0 {
            self.columns.clear();
            return;
        }
        self.columns.retain(|c| c.len() == x.len());
        let norm = dot(x, x).sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return;
        }
        // The oldest go (their storage reused for the newest).
        let excess = (self.columns.len() + 1).saturating_sub(keep);
        let mut column = self.columns.drain(..excess).next_back().unwrap_or_default();
        column.clear();
        column.extend(x.iter().map(|d| *d / norm));
        self.columns.push(column);
    }
}

/// As [`pcg`], deflated by the span W of `recycled`'s columns (Saad, Yeung, Erhel and
/// Guyomarc'h, "A deflated version of the conjugate gradient algorithm", 2000): the solve
/// starts from the Galerkin solution in W, and every search direction is kept
/// A-orthogonal to W, so that the slow modes W holds are solved for once, exactly, and
/// never return. A cloth coming to rest repeats its slow motion from step to step, and
/// that motion is what an incomplete factor resolves worst.
pub fn pcg_deflated(
    a: &SystemMatrix,
    preconditioner: &Preconditioner,
    b: &[DVec3],
    x: &mut [DVec3],
    tolerance: f64,
    max_iterations: usize,
    recycled: Option<&Recycled>,
) -> CgReport {
    let n = b.len();
    x.fill(DVec3::ZERO);
    let mut r: Vec<DVec3> = b.iter().zip(a.fixed).map(|(&v, &f)| if f { DVec3::ZERO } else { v }).collect();
    let b_norm = dot(&r, &r).sqrt();
    if b_norm == 0.0 {
        return CgReport { iterations: 0, relative_residual: 0.0, negative_curvature: false };
    }
    let deflation = recycled.and_then(|recycled| Deflation::new(a, recycled));
    let mut residual = 1.0;
    if let Some(d) = &deflation {
        let c = d.galerkin(&d.w, &r);
        d.add(&d.w, &c, x, 1.0);
        d.add(&d.aw, &c, &mut r, -1.0);
        residual = dot(&r, &r).sqrt() / b_norm;
        if residual <= tolerance {
            return CgReport { iterations: 0, relative_residual: residual, negative_curvature: false };
        }
    }
    let mut z = vec![DVec3::ZERO; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    if let Some(d) = &deflation {
        d.remove(&z, &mut p);
    }
    let mut ap = vec![DVec3::ZERO; n];
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let mut negative_curvature = false;
    while iterations < max_iterations {
        a.apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 || !pap.is_finite() {
            // (A direction deflated to nothing is no curvature: the solve has stalled.)
            negative_curvature = !(pap == 0.0 && dot(&p, &p) == 0.0);
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
        if let Some(d) = &deflation {
            d.remove(&z, &mut p);
        }
    }
    CgReport { iterations, relative_residual: residual, negative_curvature }
}

/// The deflation space of one solve: W and AW, their k columns side by side (`w[i * k + j]`
/// is vertex i of column j: a pass over all k reads memory in order), and the Cholesky
/// factor of WᵀAW.
///
/// Written by hand: k is at most a handful, and the passes are fused over the mesh's
/// vertices, which no dense-algebra crate's k×k routines would do for us.
struct Deflation {
    k: usize,
    w: Vec<DVec3>,
    aw: Vec<DVec3>,
    /// W and AW in single precision, for the passes of every iteration (bound by reading
    /// them; the projection needs no more digits than the incomplete factor keeps).
    w32: Vec<Vec3>,
    aw32: Vec<Vec3>,
    /// L of WᵀAW = LLᵀ by rows (k×k); a column whose pivot is not clearly positive (A not
    /// positive along it, or it nearly lies in the span of the columns before it) is left
    /// out: its row and column of L are zero and it gets no weight.
    factor: Vec<f64>,
}

impl Deflation {
    fn new(a: &SystemMatrix, recycled: &Recycled) -> Option<Self> {
        let n = a.fixed.len();
        let columns: Vec<&Vec<DVec3>> = recycled.columns.iter().filter(|c| c.len() == n).collect();
        let k = columns.len();
        if k == 0 {
            return None;
        }
        let mut w = vec![DVec3::ZERO; n * k];
        for (i, row) in w.chunks_mut(k).enumerate() {
            if !a.fixed[i] {
                for (out, column) in row.iter_mut().zip(&columns) {
                    *out = column[i];
                }
            }
        }
        let mut aw = vec![DVec3::ZERO; n * k];
        a.apply_many(k, &w, &mut aw);
        // G = WᵀAW, symmetrised.
        let mut g = vec![0.0; k * k];
        for (wr, ar) in w.chunks(k).zip(aw.chunks(k)) {
            for p in 0..k {
                for q in 0..=p {
                    g[p * k + q] += wr[p].dot(ar[q]) + wr[q].dot(ar[p]);
                }
            }
        }
        let mut factor = vec![0.0_f64; k * k];
        let mut kept = 0;
        for j in 0..k {
            let diagonal = 0.5 * g[j * k + j];
            let pivot = diagonal - (0..j).map(|l| factor[j * k + l].powi(2)).sum::<f64>();
            if !(diagonal > 0.0 && pivot > 1e-8 * diagonal && pivot.is_finite()) {
                continue;
            }
            let root = pivot.sqrt();
            factor[j * k + j] = root;
            for i in j + 1..k {
                let gij = 0.5 * g[i * k + j];
                factor[i * k + j] = (gij - (0..j).map(|l| factor[i * k + l] * factor[j * k + l]).sum::<f64>()) / root;
            }
            kept += 1;
        }
        let w32 = w.iter().map(|v| v.as_vec3()).collect();
        let aw32 = aw.iter().map(|v| v.as_vec3()).collect();
        (kept > 0).then_some(Self { k, w, aw, w32, aw32, factor })
    }

    /// (WᵀAW)⁻¹ Mᵀv for M = W or AW: the k products in one pass over v, then the two
    /// triangular solves with L, columns left out getting zero.
    fn galerkin<T: Column>(&self, m: &[T], v: &[DVec3]) -> Vec<f64> {
        let k = self.k;
        // Partial sums by fixed chunks of vertices, added in order: the same result on any
        // number of threads.
        let partial = |(mc, vc): (&[T], &[DVec3])| {
            let mut c = vec![0.0; k];
            for (mr, vi) in mc.chunks(k).zip(vc) {
                for (cj, mj) in c.iter_mut().zip(mr) {
                    *cj += mj.wide().dot(*vi);
                }
            }
            c
        };
        let partials: Vec<Vec<f64>> = if v.len() < PARALLEL_ROWS {
            m.chunks(k * CHUNK).zip(v.chunks(CHUNK)).map(partial).collect()
        } else {
            m.par_chunks(k * CHUNK).zip(v.par_chunks(CHUNK)).map(partial).collect()
        };
        let mut c = vec![0.0; k];
        for part in &partials {
            for (cj, pj) in c.iter_mut().zip(part) {
                *cj += pj;
            }
        }
        let l = |i: usize, j: usize| self.factor[i * k + j];
        for i in 0..k {
            c[i] = if l(i, i) > 0.0 { (c[i] - (0..i).map(|j| l(i, j) * c[j]).sum::<f64>()) / l(i, i) } else { 0.0 };
        }
        for i in (0..k).rev() {
            c[i] = if l(i, i) > 0.0 { (c[i] - (i + 1..k).map(|j| l(j, i) * c[j]).sum::<f64>()) / l(i, i) } else { 0.0 };
        }
        c
    }

    /// v += sign · M c.
    fn add<T: Column>(&self, m: &[T], c: &[f64], v: &mut [DVec3], sign: f64) {
        let k = self.k;
        let pass = |(vc, mc): (&mut [DVec3], &[T])| {
            for (vi, mr) in vc.iter_mut().zip(mc.chunks(k)) {
                *vi += sign * mr.iter().zip(c).fold(DVec3::ZERO, |acc, (mj, &cj)| acc + cj * mj.wide());
            }
        };
        if v.len() < PARALLEL_ROWS {
            v.chunks_mut(CHUNK).zip(m.chunks(k * CHUNK)).for_each(pass);
        } else {
            v.par_chunks_mut(CHUNK).zip(m.par_chunks(k * CHUNK)).for_each(pass);
        }
    }

    /// p −= W (WᵀAW)⁻¹ (AW)ᵀ z: the part of z that is not A-orthogonal to W taken out of
    /// the search direction p built from it.
    fn remove(&self, z: &[DVec3], p: &mut [DVec3]) {
        let c = self.galerkin(&self.aw32, z);
        self.add(&self.w32, &c, p, -1.0);
    }
}

/// Vertices per chunk of the deflation's passes.
const CHUNK: usize = 512;

/// A column entry in double or single precision.
trait Column: Sync {
    fn wide(&self) -> DVec3;
}

impl Column for DVec3 {
    #[inline]
    fn wide(&self) -> DVec3 {
        *self
    }
}

impl Column for Vec3 {
    #[inline]
    fn wide(&self) -> DVec3 {
        self.as_dvec3()
    }
}
