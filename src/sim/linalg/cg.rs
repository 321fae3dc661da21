//! The preconditioned conjugate gradient.

use super::preconditioner::Preconditioner;
use super::storage::{PARALLEL_ROWS, TEAM_ROWS};
use super::system::SystemMatrix;
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::ops::Range;

/// Outcome of a conjugate-gradient solve.
#[derive(Debug, Clone, Copy)]
pub struct CgReport {
    pub iterations: usize,
    pub relative_residual: f64,
    /// The matrix showed a direction of non-positive curvature (it is not positive
    /// definite); the solve stopped there.
    pub negative_curvature: bool,
    /// The residual came under the tolerance (false where the solve stopped at its
    /// iteration limit or at negative curvature).
    pub reached: bool,
}

impl CgReport {
    /// The solve stopped at its iteration limit with the residual above its tolerance.
    pub fn stopped_short(&self) -> bool {
        !self.reached && !self.negative_curvature
    }
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
        return CgReport { iterations: 0, relative_residual: 0.0, negative_curvature: false, reached: true };
    }
    let deflation = recycled.and_then(|recycled| Deflation::new(a, recycled));
    let mut residual = 1.0;
    if let Some(d) = &deflation {
        let c = d.galerkin(&r);
        d.add(&d.w, &c, x, 1.0);
        d.add(&d.aw, &c, &mut r, -1.0);
        residual = dot(&r, &r).sqrt() / b_norm;
        if residual <= tolerance {
            return CgReport { iterations: 0, relative_residual: residual, negative_curvature: false, reached: true };
        }
    }
    let mut z = vec![DVec3::ZERO; n];
    preconditioner.apply(&r, &mut z);
    let mut p = vec![DVec3::ZERO; n];
    let mut rz = next_direction(&r, &z, &mut p, None, deflation.as_ref());
    let mut ap = vec![DVec3::ZERO; n];
    let mut iterations = 0;
    let mut negative_curvature = false;
    while iterations < max_iterations {
        a.apply(&p, &mut ap);
        let pap = in_order(n, |rows| dot(&p[rows.clone()], &ap[rows])).iter().sum::<f64>();
        if pap <= 0.0 || !pap.is_finite() {
            // (A direction deflated to nothing is no curvature: the solve has stalled.)
            negative_curvature = !(pap == 0.0 && dot(&p, &p) == 0.0);
            break;
        }
        let alpha = rz / pap;
        // x += αp and r −= αAp, with |r|² in the same pass.
        let rr = in_order_mut(x, &mut r, |rows, x, r| {
            let mut rr = 0.0;
            for (((x, r), p), ap) in x.iter_mut().zip(r.iter_mut()).zip(&p[rows.clone()]).zip(&ap[rows]) {
                *x += alpha * *p;
                *r -= alpha * *ap;
                rr += r.length_squared();
            }
            rr
        })
        .iter()
        .sum::<f64>();
        iterations += 1;
        residual = rr.sqrt() / b_norm;
        if residual <= tolerance {
            break;
        }
        preconditioner.apply(&r, &mut z);
        rz = next_direction(&r, &z, &mut p, Some(rz), deflation.as_ref());
    }
    CgReport { iterations, relative_residual: residual, negative_curvature, reached: residual <= tolerance }
}

/// The next search direction p = z + β p − W (WᵀAW)⁻¹ (AW)ᵀ z = z + β p − V (AV)ᵀ z, with
/// β = 0 for the first and r·z over `rz_before` (the last r·z) after it, V empty without
/// deflation; returns r·z. Two passes over the vectors: one for r·z and (AV)ᵀz together,
/// one for p.
///
/// Fused by hand: apart, the dot product, the direction and the deflation's projection read
/// z three times and p twice, the first two on one thread. On the 10k bias skirt the
/// passes besides the product and the factor's solves took 0.18 ms an iteration apart and
/// 0.14 ms fused (docs/performance-log.md, "2026-12-06").
fn next_direction(r: &[DVec3], z: &[DVec3], p: &mut [DVec3], rz_before: Option<f64>, deflation: Option<&Deflation>) -> f64 {
    let m = deflation.map_or(0, |d| d.m);
    // Entry 0: r·z; entries 1..=m: (AV)ᵀz, the weights of V's columns in p (VᵀAV = I).
    let partials = in_order(r.len(), |rows| {
        let mut sums = vec![0.0; 1 + m];
        sums[0] = dot(&r[rows.clone()], &z[rows.clone()]);
        if let Some(d) = deflation {
            for (mr, zi) in d.av32[rows.start * m..rows.end * m].chunks(m).zip(&z[rows]) {
                for (s, mj) in sums[1..].iter_mut().zip(mr) {
                    *s += mj.as_dvec3().dot(*zi);
                }
            }
        }
        sums
    });
    let sums = add_up(1 + m, partials);
    let (rz, c) = (sums[0], &sums[1..]);
    let beta = rz_before.map_or(0.0, |before| rz / before);
    in_order_mut(p, &mut [], |rows, p, _| {
        let zs = &z[rows.clone()];
        match deflation {
            Some(d) => {
                for ((p, z), vr) in p.iter_mut().zip(zs).zip(d.v32[rows.start * m..rows.end * m].chunks(m)) {
                    let projected = vr.iter().zip(c).fold(DVec3::ZERO, |acc, (vj, &cj)| acc + cj * vj.as_dvec3());
                    *p = *z + beta * *p - projected;
                }
            }
            None => {
                for (p, z) in p.iter_mut().zip(zs) {
                    *p = *z + beta * *p;
                }
            }
        }
    });
    rz
}

/// The least pivot of WᵀAW's Cholesky factor, as a share of its diagonal entry, for which a
/// recycled column is kept. Near rest a run's last Newton directions nearly repeat: on the
/// 10k straight skirt the pivots fell to 1e-8 of the diagonal, and every such solve (10 in
/// the run) ran to CG's limit of 3 000 iterations, its residual growing to 10⁴ times the
/// right-hand side's, 35 % of the run's iterations (docs/performance-log.md, "2026-12-06").
/// Deflated CG in this form is known to be unstable under an inexact projection, and a
/// space that nearly repeats makes it inexact in any precision: in double precision
/// throughout, a test space with pivots of 1e-7 (`deflated_cg_converges_with_nearly_
/// repeated_directions`) still diverged. A column that adds under a hundredth of its
/// A-norm to the span is worth little to deflate by.
const LEAST_PIVOT: f64 = 1e-4;

/// Rows per chunk of the solve's passes: as for the products, small enough that two threads
/// share a 10k garment's rows evenly.
const CHUNK: usize = 256;

/// `f(rows)` for the chunks of [`CHUNK`] rows of `0..n`, the results in chunk order: partial
/// sums added in that order are the same on any number of threads. The chunks go in two
/// halves to the team ([`crate::sim::team`]) from [`TEAM_ROWS`] rows, over rayon's pool from
/// [`PARALLEL_ROWS`].
fn in_order<T: Send>(n: usize, f: impl Fn(Range<usize>) -> T + Sync) -> Vec<T> {
    let rows = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(n);
    let chunks = n.div_ceil(CHUNK);
    if n < TEAM_ROWS {
        (0..chunks).map(|c| f(rows(c))).collect()
    } else if n < PARALLEL_ROWS {
        let mid = chunks.div_ceil(2);
        let run = |range: Range<usize>| range.map(|c| f(rows(c))).collect::<Vec<T>>();
        crate::sim::team::join_in_order(|| run(0..mid), || run(mid..chunks))
    } else {
        (0..chunks).into_par_iter().map(|c| f(rows(c))).collect()
    }
}

/// As [`in_order`], with the chunks of `a` and of `b` (of `a`'s length, or empty for none)
/// to write: `f(rows, &mut a[rows], &mut b[rows])`.
fn in_order_mut<T: Send>(a: &mut [DVec3], b: &mut [DVec3], f: impl Fn(Range<usize>, &mut [DVec3], &mut [DVec3]) -> T + Sync) -> Vec<T> {
    let n = a.len();
    let rows = |c: usize| c * CHUNK..((c + 1) * CHUNK).min(n);
    // The chunks from `first` of the slices given, which start at chunk `first`.
    let serial = |first: usize, a: &mut [DVec3], b: &mut [DVec3]| -> Vec<T> {
        if b.is_empty() {
            a.chunks_mut(CHUNK).enumerate().map(|(c, a)| f(rows(first + c), a, &mut [])).collect()
        } else {
            a.chunks_mut(CHUNK).zip(b.chunks_mut(CHUNK)).enumerate().map(|(c, (a, b))| f(rows(first + c), a, b)).collect()
        }
    };
    if n < TEAM_ROWS {
        serial(0, a, b)
    } else if n < PARALLEL_ROWS {
        let mid = n.div_ceil(CHUNK).div_ceil(2);
        let (a_low, a_high) = a.split_at_mut(mid * CHUNK);
        let (b_low, b_high) = if b.is_empty() { (&mut [][..], &mut [][..]) } else { b.split_at_mut(mid * CHUNK) };
        crate::sim::team::join_in_order(|| serial(0, a_low, b_low), || serial(mid, a_high, b_high))
    } else if b.is_empty() {
        a.par_chunks_mut(CHUNK).enumerate().map(|(c, a)| f(rows(c), a, &mut [])).collect()
    } else {
        a.par_chunks_mut(CHUNK).zip(b.par_chunks_mut(CHUNK)).enumerate().map(|(c, (a, b))| f(rows(c), a, b)).collect()
    }
}

/// The deflation space of one solve: W and AW, their k columns side by side (`w[i * k + j]`
/// is vertex i of column j: a pass over all k reads memory in order), the Cholesky factor of
/// WᵀAW, and an A-orthonormal basis of the same span for the passes of every iteration.
///
/// Written by hand: k is at most a handful, and the passes are fused over the mesh's
/// vertices, which no dense-algebra crate's k×k routines would do for us.
struct Deflation {
    k: usize,
    w: Vec<DVec3>,
    aw: Vec<DVec3>,
    /// L of WᵀAW = LLᵀ by rows (k×k). A column whose pivot is under [`LEAST_PIVOT`] of its
    /// diagonal entry (A not positive along it, or it nearly lies in the span of the
    /// columns before it) is left out: its row and column of L are zero and it gets no
    /// weight.
    factor: Vec<f64>,
    /// The columns kept, m.
    m: usize,
    /// V = W L⁻ᵀ over the kept columns (VᵀAV = I) and AV, m side by side, in single
    /// precision: the passes of every iteration are bound by reading them, and the
    /// projection needs no more digits than the incomplete factor keeps. Orthonormal, so
    /// that the projection's weights are (AV)ᵀz themselves, not rounding errors multiplied
    /// by (WᵀAW)⁻¹.
    v32: Vec<Vec3>,
    av32: Vec<Vec3>,
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
        w.par_chunks_mut(k * CHUNK).enumerate().for_each(|(c, rows)| {
            for (i, row) in (c * CHUNK..).zip(rows.chunks_mut(k)) {
                if !a.fixed[i] {
                    for (out, column) in row.iter_mut().zip(&columns) {
                        *out = column[i];
                    }
                }
            }
        });
        let mut aw = vec![DVec3::ZERO; n * k];
        a.apply_many(k, &w, &mut aw);
        // G = WᵀAW, symmetrised.
        let g = add_up(
            k * k,
            in_order(n, |rows| {
                let mut g = vec![0.0; k * k];
                for (wr, ar) in w[rows.start * k..rows.end * k].chunks(k).zip(aw[rows.start * k..rows.end * k].chunks(k)) {
                    for (p, wp) in wr.iter().enumerate() {
                        for (q, aq) in ar.iter().enumerate() {
                            g[p * k + q] += wp.dot(*aq);
                        }
                    }
                }
                g
            }),
        );
        let gram = |i: usize, j: usize| 0.5 * (g[i * k + j] + g[j * k + i]);
        let mut factor = vec![0.0_f64; k * k];
        for j in 0..k {
            let diagonal = gram(j, j);
            let pivot = diagonal - (0..j).map(|l| factor[j * k + l].powi(2)).sum::<f64>();
            if !(diagonal > 0.0 && pivot > LEAST_PIVOT * diagonal && pivot.is_finite()) {
                continue;
            }
            let root = pivot.sqrt();
            factor[j * k + j] = root;
            for i in j + 1..k {
                factor[i * k + j] = (gram(i, j) - (0..j).map(|l| factor[i * k + l] * factor[j * k + l]).sum::<f64>()) / root;
            }
        }
        let basis: Vec<usize> = (0..k).filter(|&j| factor[j * k + j] > 0.0).collect();
        let m = basis.len();
        if m == 0 {
            return None;
        }
        // L⁻¹ over the kept columns (m×m, lower, by rows), by forward substitution: V's
        // column q is Σ_{p≤q} L⁻¹[q][p] W's kept column p.
        let l = |a: usize, b: usize| factor[basis[a] * k + basis[b]];
        let mut inverse = vec![0.0; m * m];
        for q in 0..m {
            inverse[q * m + q] = 1.0 / l(q, q);
            for p in 0..q {
                inverse[q * m + p] = -(p..q).map(|s| l(q, s) * inverse[s * m + p]).sum::<f64>() / l(q, q);
            }
        }
        let orthonormal = |from: &[DVec3]| -> Vec<Vec3> {
            let mut to = vec![Vec3::ZERO; n * m];
            to.par_chunks_mut(m * CHUNK).zip(from.par_chunks(k * CHUNK)).for_each(|(to, from)| {
                for (to, from) in to.chunks_mut(m).zip(from.chunks(k)) {
                    for (q, out) in to.iter_mut().enumerate() {
                        *out = (0..=q).fold(DVec3::ZERO, |acc, p| acc + inverse[q * m + p] * from[basis[p]]).as_vec3();
                    }
                }
            });
            to
        };
        let (v32, av32) = (orthonormal(&w), orthonormal(&aw));
        Some(Self { k, w, aw, factor, m, v32, av32 })
    }

    /// (WᵀAW)⁻¹ Wᵀv: the k products in one pass over v, then [`Self::solve_gram`].
    fn galerkin(&self, v: &[DVec3]) -> Vec<f64> {
        let k = self.k;
        let partials = in_order(v.len(), |rows| {
            let mut c = vec![0.0; k];
            for (wr, vi) in self.w[rows.start * k..rows.end * k].chunks(k).zip(&v[rows]) {
                for (cj, wj) in c.iter_mut().zip(wr) {
                    *cj += wj.dot(*vi);
                }
            }
            c
        });
        self.solve_gram(add_up(k, partials))
    }

    /// (WᵀAW)⁻¹ c by the two triangular solves with L, columns left out getting zero.
    fn solve_gram(&self, mut c: Vec<f64>) -> Vec<f64> {
        let k = self.k;
        let l = |i: usize, j: usize| self.factor[i * k + j];
        for i in 0..k {
            c[i] = if l(i, i) > 0.0 { (c[i] - (0..i).map(|j| l(i, j) * c[j]).sum::<f64>()) / l(i, i) } else { 0.0 };
        }
        for i in (0..k).rev() {
            c[i] = if l(i, i) > 0.0 { (c[i] - (i + 1..k).map(|j| l(j, i) * c[j]).sum::<f64>()) / l(i, i) } else { 0.0 };
        }
        c
    }

    /// v += sign · M c for M = W or AW (in double precision).
    fn add(&self, m: &[DVec3], c: &[f64], v: &mut [DVec3], sign: f64) {
        let k = self.k;
        in_order_mut(v, &mut [], |rows, v, _| {
            for (vi, mr) in v.iter_mut().zip(m[rows.start * k..rows.end * k].chunks(k)) {
                *vi += sign * mr.iter().zip(c).fold(DVec3::ZERO, |acc, (mj, &cj)| acc + cj * *mj);
            }
        });
    }
}

/// The sum, entry by entry, of `width`-long partial sums, in their order.
fn add_up(width: usize, partials: Vec<Vec<f64>>) -> Vec<f64> {
    let mut sums = vec![0.0; width];
    for part in &partials {
        for (s, q) in sums.iter_mut().zip(part) {
            *s += q;
        }
    }
    sums
}
