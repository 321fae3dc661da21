//! The block incomplete Cholesky factor, the preconditioner of coarse meshes.

use super::storage::merge_rows;
use super::system::SystemMatrix;
use glam::{DMat3, DVec3, Mat3};
use std::sync::atomic::{AtomicBool, Ordering};

/// Block incomplete LDLᵀ factor of the system matrix, A ≈ (D + U) D⁻¹ (D + U)ᵀ with U
/// strictly lower and D block diagonal, both in 3×3 blocks, on one of two patterns
/// ([`FactorPattern`]).
///
/// Triangular solves are sequential, so a large matrix is factored in parts: contiguous
/// ranges of vertices (spatially coherent on our meshes) whose couplings to other parts
/// are dropped, each factored and solved on its own thread (block Jacobi over incomplete
/// factors). The parts depend on the size only, never on the thread count, so results do
/// not change with the machine.
///
/// Written by hand: the pattern is the mesh's, and no sparse-factorisation crate we could
/// use takes 3×3 blocks on a fixed pattern.
pub struct IncompleteCholesky {
    parts: Vec<FactorPart>,
    pub pattern: FactorPattern,
    /// The diagonal shift it was made with, a share of the diagonal (0: none needed).
    pub shift: f64,
    /// Multiply-adds of one conjugate-gradient iteration with it: the matrix product and
    /// the two triangular solves.
    pub iteration_cost: f64,
    /// What building it cost, in conjugate-gradient iterations with it (from counts of
    /// multiply-adds, so the same on every machine).
    pub cost_in_iterations: f64,
}

/// Which blocks an incomplete factor keeps. Neither is cheaper everywhere, so the solver
/// measures both as it goes (`solver::preconditioning::PatternChoice`); docs/performance-log.md
/// has the figures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FactorPattern {
    /// The whole matrix's pattern: the in-plane one-ring and the bending matrix's wider
    /// stencil (each triangle's bending couples the vertices of its three neighbours: about
    /// 45 columns a row on a regular mesh). Where bending sets the slow modes (a drape's
    /// skirt at 4 ms steps) a factor without those entries leaves CG iterations growing like
    /// the bending stiffness h²·B/ℓ⁴ as the mesh is refined: eight times as many on the
    /// 7.5 mm drape.
    Wide,
    /// The in-plane one-ring and the contact couplings only (about 7 columns a row), so a
    /// solve with it reads an eighth of the blocks. Where inertia, membrane and contact
    /// set the slow modes (a cloth landing on a prop at 16 ms steps) CG needs only a few
    /// more iterations with it than with the wide one.
    Ring,
}

/// Vertices per part of a split factor, roughly: below this a factor is one part.
pub(super) const PART_VERTICES: usize = 4096;

/// How many parts a factor over `n` vertices is split into: one below [`PART_VERTICES`],
/// else one per `PART_VERTICES` but at least two. The two-part floor is for the meshes of
/// 4 096–8 191 vertices (a 10k-triangle garment): as one part their triangular solves,
/// half of a step's time, ran on one thread while the other waited. Split in two, a
/// 10 226-triangle circle skirt took 3 % more conjugate-gradient iterations at 21 % less
/// time each on two threads (docs/performance-log.md).
pub(super) fn part_count(n: usize) -> usize {
    if n < PART_VERTICES { 1 } else { (n / PART_VERTICES).max(2) }
}

/// Whether an incomplete factor over `n` vertices is split into parts.
pub fn factor_is_split(n: usize) -> bool {
    part_count(n) > 1
}

/// The factor of the diagonal block of rows `start..start + pivot_inverse.len()`.
struct FactorPart {
    start: usize,
    /// Strictly lower blocks by local rows: global columns ascending, none before `start`.
    row_start: Vec<usize>,
    cols: Vec<u32>,
    /// U_ik, in single precision: the solve is bound by reading these, and a preconditioner
    /// needs no more digits (rounding keeps it symmetric positive definite).
    lower: Vec<Mat3>,
    /// D_i⁻¹.
    pivot_inverse: Vec<DMat3>,
    /// 3×3 block products the factorisation took.
    block_products: usize,
}

impl IncompleteCholesky {
    /// How many independently factored parts the matrix was split into.
    #[cfg(test)]
    pub(super) fn part_count(&self) -> usize {
        self.parts.len()
    }

    /// Factors A + shift·diag(A) on `pattern`; None if a pivot block is not positive
    /// definite (breakdown).
    pub(super) fn new(a: &SystemMatrix, shift: f64, pattern: FactorPattern) -> Option<Self> {
        use rayon::prelude::*;
        let n = a.fixed.len();
        let count = part_count(n);
        let bounds: Vec<(usize, usize)> = (0..count).map(|p| (p * n / count, (p + 1) * n / count)).collect();
        // The contact couplings' off-diagonal blocks k·c_i c_j·nnᵀ, by row (columns below the
        // row, ascending, summed). Without them the factor sees each coupled vertex held
        // on its own where only the pair's relative motion is, and CG spends an iteration
        // per pair finding that out.
        let mut coupled: Vec<Vec<(u32, DMat3)>> = vec![Vec::new(); n];
        for c in a.couplings {
            let nn = DMat3::from_cols(c.normal * c.normal.x, c.normal * c.normal.y, c.normal * c.normal.z) * c.stiffness;
            for i in 0..4 {
                for j in 0..4 {
                    let (row, col) = (c.vertices[i], c.vertices[j]);
                    if col < row {
                        coupled[row as usize].push((col, nn * (c.weights[i] * c.weights[j])));
                    }
                }
            }
        }
        for row in &mut coupled {
            row.sort_unstable_by_key(|e| e.0);
            row.dedup_by(|later, kept| {
                let same = later.0 == kept.0;
                if same {
                    kept.1 += later.1;
                }
                same
            });
        }
        // Set by the first part to break down, so that the others stop too.
        let broken = AtomicBool::new(false);
        let parts = if count == 1 {
            vec![FactorPart::new(a, &coupled, shift, pattern, 0, n, &broken)?]
        } else {
            bounds.par_iter().map(|&(lo, hi)| FactorPart::new(a, &coupled, shift, pattern, lo, hi, &broken)).collect::<Option<Vec<_>>>()?
        };
        // A block product is 27 multiply-adds; a CG iteration applies every factor block
        // twice and the matrix once (9 per block, 3 per bending entry).
        let products: usize = parts.iter().map(|p| p.block_products).sum();
        let factor_blocks: usize = parts.iter().map(|p| p.lower.len() + p.pivot_inverse.len()).sum();
        let per_iteration = 18 * factor_blocks + 9 * a.stiffness.values.len() + 3 * a.bending.map_or(0, |q| q.values.len());
        let cost_in_iterations = 27.0 * products as f64 / per_iteration.max(1) as f64;
        Some(Self { parts, pattern, shift, iteration_cost: per_iteration as f64, cost_in_iterations })
    }

    /// z = P⁻¹ r, each part on its own.
    pub(super) fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
        use rayon::prelude::*;
        if let [part] = &self.parts[..] {
            return part.solve(r, z);
        }
        let mut pieces = Vec::with_capacity(self.parts.len());
        let mut rest = z;
        for (p, part) in self.parts.iter().enumerate() {
            let len = self.parts.get(p + 1).map_or(rest.len(), |next| next.start - part.start);
            let (piece, tail) = rest.split_at_mut(len);
            pieces.push((part, piece));
            rest = tail;
        }
        pieces.into_par_iter().for_each(|(part, piece)| {
            let len = piece.len();
            part.solve(&r[part.start..part.start + len], piece);
        });
    }
}

impl FactorPart {
    /// Factors rows and columns `lo..hi` of A + shift·diag(A) on `pattern`, with the
    /// contact couplings' lower blocks `coupled` by row; None if a pivot breaks down here,
    /// setting `broken`, or once another part has set it.
    fn new(a: &SystemMatrix, coupled: &[Vec<(u32, DMat3)>], shift: f64, pattern: FactorPattern, lo: usize, hi: usize, broken: &AtomicBool) -> Option<Self> {
        let k = a.stiffness;
        let rows = hi - lo;
        let mut row_start = Vec::with_capacity(rows + 1);
        let mut cols: Vec<u32> = Vec::new();
        let mut lower: Vec<DMat3> = Vec::new();
        let mut pivot_inverse = vec![DMat3::ZERO; rows];
        // Where column j sits in the row being factored (usize::MAX: not in it), by j − lo.
        let mut position = vec![usize::MAX; rows];
        let mut merged = Vec::new();
        // W_ij = U_ij D_j⁻¹ of the row being factored.
        let mut scaled: Vec<DMat3> = Vec::new();
        let mut block_products = 0;
        row_start.push(0);
        for (row, coupled_row) in (lo..hi).zip(&coupled[lo..hi]) {
            if row % 64 == 0 && broken.load(Ordering::Relaxed) {
                return None;
            }
            let start = cols.len();
            if !a.fixed[row] {
                let q_row = a.bending.map_or((&[][..], 0), |q| q.row_pattern(row));
                // The strictly lower part within this factor's rows, fixed vertices left out.
                let keep = |col: u32| (lo..row).contains(&(col as usize)) && !a.fixed[col as usize];
                merge_rows(k.row_pattern(row), q_row, keep, &mut merged);
                if pattern == FactorPattern::Ring {
                    // Bending entries outside the one-ring are dropped (not lumped onto the
                    // diagonal: that measured no better).
                    merged.retain(|&(_, k_slot, _)| k_slot != usize::MAX);
                }
                let mut push = |col: u32, block: DMat3| {
                    position[col as usize - lo] = cols.len();
                    cols.push(col);
                    lower.push(block);
                };
                // The two sorted lists merged: coupling blocks in and beside the pattern.
                let mut extra = coupled_row.iter().filter(|e| keep(e.0)).peekable();
                for &(col, k_slot, q_slot) in &merged {
                    while let Some(&(c, block)) = extra.next_if(|e| e.0 < col) {
                        push(c, block);
                    }
                    let mut block = if k_slot == usize::MAX { DMat3::ZERO } else { k.values[k_slot] };
                    if q_slot != usize::MAX {
                        block += DMat3::from_diagonal(DVec3::splat(a.bending.expect("merged from it").values[q_slot]));
                    }
                    if let Some(&(_, coupling)) = extra.next_if(|e| e.0 == col) {
                        block += coupling;
                    }
                    push(col, block);
                }
                for &(c, block) in extra {
                    push(c, block);
                }
            }
            let end = cols.len();
            scaled.clear();
            for p in start..end {
                let col = cols[p] as usize - lo;
                // U_ik −= Σ_{j<k} W_ij U_kjᵀ over the j both rows hold.
                let mut sum = DMat3::ZERO;
                for r in row_start[col]..row_start[col + 1] {
                    let at = position[cols[r] as usize - lo];
                    if at != usize::MAX && at < p {
                        sum += scaled[at - start] * lower[r].transpose();
                        block_products += 1;
                    }
                }
                lower[p] -= sum;
                scaled.push(lower[p] * pivot_inverse[col]);
            }
            let local = row - lo;
            if a.fixed[row] {
                pivot_inverse[local] = DMat3::IDENTITY;
            } else {
                let q = a.bending.map_or(0.0, |q| q.diagonal(row as u32));
                let mut pivot = k.values[k.diagonal_slot(row as u32)]
                    + DMat3::from_diagonal(DVec3::splat(a.mass_diagonal[row] + q));
                pivot += DMat3::from_diagonal(DVec3::new(pivot.x_axis.x, pivot.y_axis.y, pivot.z_axis.z) * shift);
                for p in start..end {
                    pivot -= scaled[p - start] * lower[p].transpose();
                }
                block_products += 2 * (end - start) + 1;
                // Symmetrised: round-off would otherwise leave D slightly unsymmetric, and the
                // recursion amplifies that row after row until the preconditioner is no
                // longer symmetric and the conjugate gradient stalls.
                let pivot = 0.5 * (pivot + pivot.transpose());
                if !positive_definite(&pivot) {
                    broken.store(true, Ordering::Relaxed);
                    return None;
                }
                let inverse = pivot.inverse();
                pivot_inverse[local] = 0.5 * (inverse + inverse.transpose());
            }
            for p in start..end {
                position[cols[p] as usize - lo] = usize::MAX;
            }
            row_start.push(end);
        }
        let lower = lower.iter().map(DMat3::as_mat3).collect();
        Some(Self { start: lo, row_start, cols, lower, pivot_inverse, block_products })
    }

    /// z = ((D + U) D⁻¹ (D + U)ᵀ)⁻¹ r over this part's rows (`r` and `z` are its slices).
    fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
        let (n, lo) = (r.len(), self.start);
        // (D + U) w = r, row by row.
        for i in 0..n {
            let (s, e) = (self.row_start[i], self.row_start[i + 1]);
            let v = self.lower[s..e].iter().zip(&self.cols[s..e]).fold(r[i], |v, (u, &c)| v - u.as_dmat3() * z[c as usize - lo]);
            z[i] = self.pivot_inverse[i] * v;
        }
        // (D + U)ᵀ z = D w: z_i = w_i − D_i⁻¹ Σ_{k>i} U_kiᵀ z_k, the sums scattered from
        // each finished row.
        let mut pending = vec![DVec3::ZERO; n];
        for i in (0..n).rev() {
            z[i] -= self.pivot_inverse[i] * pending[i];
            let zi = z[i];
            let (s, e) = (self.row_start[i], self.row_start[i + 1]);
            for (u, &c) in self.lower[s..e].iter().zip(&self.cols[s..e]) {
                pending[c as usize - lo] += DVec3::new(u.x_axis.as_dvec3().dot(zi), u.y_axis.as_dvec3().dot(zi), u.z_axis.as_dvec3().dot(zi));
            }
        }
    }
}

/// Whether a symmetric 3×3 matrix is positive definite (Sylvester's criterion; NaN fails).
fn positive_definite(m: &DMat3) -> bool {
    let (a, b, d) = (m.x_axis.x, m.y_axis.x, m.y_axis.y);
    a > 0.0 && a * d - b * b > 0.0 && m.determinant() > 0.0
}

