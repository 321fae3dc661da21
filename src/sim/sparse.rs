//! Sparse symmetric matrices over vertices and the preconditioned conjugate gradient.
//!
//! Written by hand rather than taken from a general sparse crate because the structure is
//! fixed for a whole run: the pattern is built once from the mesh, each element keeps the
//! slots it writes to, and re-assembly is a plain pass over a value array. The in-plane
//! part is stored as 3×3 blocks; the bending part is a scalar matrix that acts the same on
//! x, y and z (its energy is ½ Σ Q_ab x_a·x_b), so it is stored once, not three times.

use crate::sim::direct::DirectFactor;
use crate::sim::multigrid::Multigrid;
use glam::{DMat3, DVec3, Mat3};

/// Compressed sparse rows of 3×3 blocks with a fixed pattern.
#[derive(Debug, Clone)]
pub struct BlockCsr {
    row_start: Vec<u32>,
    cols: Vec<u32>,
    pub values: Vec<DMat3>,
}

/// Compressed sparse rows of scalars with a fixed pattern.
#[derive(Debug, Clone)]
pub struct ScalarCsr {
    row_start: Vec<u32>,
    cols: Vec<u32>,
    pub values: Vec<f64>,
}

/// Sorted, de-duplicated column lists per row, from (row, col) pairs, symmetric and with diagonals.
fn pattern(n: usize, pairs: impl Iterator<Item = (u32, u32)>) -> (Vec<u32>, Vec<u32>) {
    let mut rows: Vec<Vec<u32>> = (0..n as u32).map(|i| vec![i]).collect();
    for (a, b) in pairs {
        rows[a as usize].push(b);
        rows[b as usize].push(a);
    }
    let mut row_start = Vec::with_capacity(n + 1);
    let mut cols = Vec::new();
    row_start.push(0);
    for mut row in rows {
        row.sort_unstable();
        row.dedup();
        cols.extend_from_slice(&row);
        row_start.push(cols.len() as u32);
    }
    (row_start, cols)
}

/// Below this many rows a product runs on the calling thread: spreading a few thousand
/// rows over threads costs more in scheduling than it saves.
const PARALLEL_ROWS: usize = 4096;

/// Calls `f(row, &mut y[row])` for every row, in chunks over rayon's pool when `y` is long.
fn for_rows(y: &mut [DVec3], f: impl Fn(usize, &mut DVec3) + Sync) {
    use rayon::prelude::*;
    const CHUNK: usize = 1024;
    if y.len() < PARALLEL_ROWS {
        y.iter_mut().enumerate().for_each(|(row, out)| f(row, out));
    } else {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, chunk)| {
            for (i, out) in chunk.iter_mut().enumerate() {
                f(c * CHUNK + i, out);
            }
        });
    }
}

fn find_slot(row_start: &[u32], cols: &[u32], row: u32, col: u32) -> usize {
    let (s, e) = (row_start[row as usize] as usize, row_start[row as usize + 1] as usize);
    s + cols[s..e].binary_search(&col).expect("entry must be in the sparsity pattern")
}

impl BlockCsr {
    /// A zero matrix over `n` vertices whose pattern holds every pair given (and its transpose).
    pub fn with_pattern(n: usize, pairs: impl Iterator<Item = (u32, u32)>) -> Self {
        let (row_start, cols) = pattern(n, pairs);
        let values = vec![DMat3::ZERO; cols.len()];
        Self { row_start, cols, values }
    }

    /// Index into `values` of block (row, col). Build-time only: a binary search.
    pub fn slot(&self, row: u32, col: u32) -> usize {
        find_slot(&self.row_start, &self.cols, row, col)
    }

    pub fn diagonal_slot(&self, row: u32) -> usize {
        self.slot(row, row)
    }

    pub fn clear(&mut self) {
        self.values.fill(DMat3::ZERO);
    }

    /// y = A x (y overwritten); rows in parallel on large meshes.
    pub fn multiply(&self, x: &[DVec3], y: &mut [DVec3]) {
        for_rows(y, |row, out| *out = self.row_product(row, x));
    }

    /// Row `row` of A x.
    #[inline]
    fn row_product(&self, row: usize, x: &[DVec3]) -> DVec3 {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        self.values[s..e].iter().zip(&self.cols[s..e]).fold(DVec3::ZERO, |acc, (m, &c)| acc + *m * x[c as usize])
    }

    pub fn vertex_count(&self) -> usize {
        self.row_start.len() - 1
    }

    /// Columns of one row and the slot of its first entry.
    pub fn row_pattern(&self, row: usize) -> (&[u32], usize) {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        (&self.cols[s..e], s)
    }
}

impl ScalarCsr {
    pub fn vertex_count(&self) -> usize {
        self.row_start.len() - 1
    }

    pub fn with_pattern(n: usize, pairs: impl Iterator<Item = (u32, u32)>) -> Self {
        let (row_start, cols) = pattern(n, pairs);
        let values = vec![0.0; cols.len()];
        Self { row_start, cols, values }
    }

    pub fn slot(&self, row: u32, col: u32) -> usize {
        find_slot(&self.row_start, &self.cols, row, col)
    }

    /// y += A x, the scalar matrix acting on each coordinate; rows in parallel on large meshes.
    pub fn multiply_add(&self, x: &[DVec3], y: &mut [DVec3]) {
        for_rows(y, |row, out| *out += self.row_product(row, x));
    }

    /// Row `row` of (A ⊗ I₃) x.
    #[inline]
    fn row_product(&self, row: usize, x: &[DVec3]) -> DVec3 {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        self.values[s..e].iter().zip(&self.cols[s..e]).fold(DVec3::ZERO, |acc, (&v, &c)| acc + v * x[c as usize])
    }

    pub fn diagonal(&self, row: u32) -> f64 {
        self.value(row, row)
    }

    /// Columns of one row and the slot of its first entry.
    pub fn row_pattern(&self, row: usize) -> (&[u32], usize) {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        (&self.cols[s..e], s)
    }

    /// Entry (row, col), zero where the pattern has none.
    pub fn value(&self, row: u32, col: u32) -> f64 {
        let (s, e) = (self.row_start[row as usize] as usize, self.row_start[row as usize + 1] as usize);
        self.cols[s..e].binary_search(&col).map_or(0.0, |k| self.values[s + k])
    }

    /// The stored entries of one row as (col, value).
    pub fn entries_of_row(&self, row: u32) -> impl Iterator<Item = (u32, f64)> + '_ {
        let (s, e) = (self.row_start[row as usize] as usize, self.row_start[row as usize + 1] as usize);
        (s..e).map(move |k| (self.cols[k], self.values[k]))
    }

    /// Iterates the stored entries as (row, col, value).
    pub fn entries(&self) -> impl Iterator<Item = (u32, u32, f64)> + '_ {
        (0..self.row_start.len() - 1).flat_map(move |row| {
            (self.row_start[row] as usize..self.row_start[row + 1] as usize)
                .map(move |k| (row as u32, self.cols[k], self.values[k]))
        })
    }
}

/// The Newton system matrix `A = diag(mass_diagonal) + K + Q ⊗ I₃`, with fixed vertices removed.
pub struct SystemMatrix<'a> {
    pub mass_diagonal: &'a [f64],
    pub stiffness: &'a BlockCsr,
    pub bending: Option<&'a ScalarCsr>,
    /// `true` for vertices whose positions are prescribed (their rows and columns are dropped).
    pub fixed: &'a [bool],
    /// Rank-one couplings k·g gᵀ between a few vertices (cloth–cloth contact), whose
    /// diagonal blocks are already in `stiffness`: only their off-diagonal part is applied.
    pub couplings: &'a [Coupling],
}

/// A rank-one term k·g gᵀ of the system matrix with g = (c₀n, c₁n, c₂n, c₃n) on four
/// vertices: the Gauss–Newton Hessian of a penalty on one distance.
#[derive(Debug, Clone, Copy)]
pub struct Coupling {
    pub vertices: [u32; 4],
    pub weights: [f64; 4],
    pub normal: DVec3,
    pub stiffness: f64,
}

impl SystemMatrix<'_> {
    fn apply(&self, x: &[DVec3], y: &mut [DVec3]) {
        // One pass over the rows for the three terms: separate passes read and write y
        // three times, which cost the drape's solves a sixth more time.
        for_rows(y, |row, out| {
            *out = if self.fixed[row] {
                DVec3::ZERO
            } else {
                let bending = self.bending.map_or(DVec3::ZERO, |q| q.row_product(row, x));
                self.stiffness.row_product(row, x) + bending + self.mass_diagonal[row] * x[row]
            };
        });
        for c in self.couplings {
            let along = |j: usize| c.weights[j] * c.normal.dot(x[c.vertices[j] as usize]);
            let total: f64 = (0..4).map(along).sum();
            for j in 0..4 {
                let v = c.vertices[j] as usize;
                if !self.fixed[v] {
                    y[v] += c.stiffness * c.weights[j] * (total - along(j)) * c.normal;
                }
            }
        }
    }

    /// The preconditioner: block incomplete Cholesky on the matrix's pattern, or block Jacobi if
    /// that factorisation breaks down even with a diagonal shift.
    pub fn preconditioner(&self) -> Preconditioner {
        for shift in [0.0, 1e-3, 1e-2, 1e-1] {
            if let Some(factor) = IncompleteCholesky::new(self, shift) {
                return Preconditioner::IncompleteCholesky(factor);
            }
        }
        Preconditioner::BlockJacobi(self.block_jacobi())
    }

    /// Inverse 3×3 diagonal blocks: the block-Jacobi preconditioner.
    pub(crate) fn block_jacobi(&self) -> Vec<DMat3> {
        (0..self.fixed.len())
            .map(|i| {
                if self.fixed[i] {
                    return DMat3::ZERO;
                }
                let q = self.bending.map_or(0.0, |q| q.diagonal(i as u32));
                let block = self.stiffness.values[self.stiffness.diagonal_slot(i as u32)]
                    + DMat3::from_diagonal(DVec3::splat(self.mass_diagonal[i] + q));
                block.inverse()
            })
            .collect()
    }
}

/// An approximate inverse of a [`SystemMatrix`] for [`pcg`]; any symmetric positive
/// definite one works, so one built for a nearby matrix (an earlier Newton iteration of the
/// same step) can be reused.
pub enum Preconditioner {
    BlockJacobi(Vec<DMat3>),
    IncompleteCholesky(IncompleteCholesky),
    Cholesky(DirectFactor),
    Multigrid(Multigrid),
}

impl Preconditioner {
    /// What building it cost, in conjugate-gradient iterations with it.
    pub fn cost_in_iterations(&self) -> f64 {
        match self {
            Preconditioner::BlockJacobi(_) => 0.0,
            Preconditioner::IncompleteCholesky(factor) => factor.cost_in_iterations,
            Preconditioner::Cholesky(factor) => factor.cost_in_iterations,
            Preconditioner::Multigrid(hierarchy) => hierarchy.cost_in_iterations,
        }
    }

    pub(crate) fn apply(&self, r: &[DVec3], z: &mut [DVec3]) {
        match self {
            Preconditioner::BlockJacobi(blocks) => {
                for i in 0..r.len() {
                    z[i] = blocks[i] * r[i];
                }
            }
            Preconditioner::IncompleteCholesky(factor) => factor.solve(r, z),
            Preconditioner::Cholesky(factor) => factor.solve(r, z),
            Preconditioner::Multigrid(hierarchy) => hierarchy.solve(r, z),
        }
    }
}

/// Block incomplete LDLᵀ factor of the system matrix, A ≈ (D + U) D⁻¹ (D + U)ᵀ with U
/// strictly lower and D block diagonal, both in 3×3 blocks, on the pattern of the whole
/// matrix: the in-plane one-ring and the bending matrix's wider stencil. Leaving the
/// bending entries out (as a factor on the in-plane pattern does) costs little on coarse
/// meshes but makes the conjugate gradient's iterations grow like the bending stiffness,
/// h²·B/ℓ⁴, as the mesh is refined: seven times as many at 5 000 triangles.
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
    /// What building it cost, in conjugate-gradient iterations with it (from counts of
    /// multiply-adds, so the same on every machine).
    pub cost_in_iterations: f64,
}

/// Vertices per part of a split factor: below twice this a factor is one part.
const PART_VERTICES: usize = 4096;

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

/// The union of two rows' sorted column lists (`(columns, slot of the first)` each), as
/// (column, slot in the first or `usize::MAX`, slot in the second or `usize::MAX`), keeping
/// the columns `keep` accepts.
pub(crate) fn merge_rows(a: (&[u32], usize), b: (&[u32], usize), keep: impl Fn(u32) -> bool, out: &mut Vec<(u32, usize, usize)>) {
    out.clear();
    let ((ac, a0), (bc, b0)) = (a, b);
    let (mut i, mut j) = (0, 0);
    while i < ac.len() || j < bc.len() {
        let col = match (ac.get(i), bc.get(j)) {
            (Some(&x), Some(&y)) => x.min(y),
            (Some(&x), None) => x,
            (None, Some(&y)) => y,
            (None, None) => unreachable!("the loop runs while either has columns"),
        };
        let mut entry = (col, usize::MAX, usize::MAX);
        if ac.get(i) == Some(&col) {
            entry.1 = a0 + i;
            i += 1;
        }
        if bc.get(j) == Some(&col) {
            entry.2 = b0 + j;
            j += 1;
        }
        if keep(col) {
            out.push(entry);
        }
    }
}

impl IncompleteCholesky {
    /// Factors A + shift·diag(A); None if a pivot block is not positive definite (breakdown).
    fn new(a: &SystemMatrix, shift: f64) -> Option<Self> {
        use rayon::prelude::*;
        let n = a.fixed.len();
        let count = if n < 2 * PART_VERTICES { 1 } else { n / PART_VERTICES };
        let bounds: Vec<(usize, usize)> = (0..count).map(|p| (p * n / count, (p + 1) * n / count)).collect();
        // The contact couplings' off-diagonal blocks k·c_i c_j·nnᵀ, by row (columns below the
        // row, ascending, summed). Without them the factor saw each coupled vertex held
        // on its own where only the pair's relative motion is: a CG iteration per pair was
        // spent finding that out (17 per Newton iteration on the tablecloth against 7
        // without self-collision).
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
        let parts = if count == 1 {
            vec![FactorPart::new(a, &coupled, shift, 0, n)?]
        } else {
            bounds.par_iter().map(|&(lo, hi)| FactorPart::new(a, &coupled, shift, lo, hi)).collect::<Option<Vec<_>>>()?
        };
        // A block product is 27 multiply-adds; a CG iteration applies every factor block
        // twice and the matrix once (9 per block, 3 per bending entry).
        let products: usize = parts.iter().map(|p| p.block_products).sum();
        let factor_blocks: usize = parts.iter().map(|p| p.lower.len() + p.pivot_inverse.len()).sum();
        let per_iteration = 18 * factor_blocks + 9 * a.stiffness.values.len() + 3 * a.bending.map_or(0, |q| q.values.len());
        let cost_in_iterations = 27.0 * products as f64 / per_iteration.max(1) as f64;
        Some(Self { parts, cost_in_iterations })
    }

    /// z = P⁻¹ r, each part on its own.
    fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
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
    /// Factors rows and columns `lo..hi` of A + shift·diag(A), with the contact couplings'
    /// lower blocks `coupled` by row.
    fn new(a: &SystemMatrix, coupled: &[Vec<(u32, DMat3)>], shift: f64, lo: usize, hi: usize) -> Option<Self> {
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
            let start = cols.len();
            if !a.fixed[row] {
                let q_row = a.bending.map_or((&[][..], 0), |q| q.row_pattern(row));
                // The strictly lower part within this factor's rows, fixed vertices left out.
                let keep = |col: u32| (lo..row).contains(&(col as usize)) && !a.fixed[col as usize];
                merge_rows(k.row_pattern(row), q_row, keep, &mut merged);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::direct::DirectPattern;
    use std::sync::Arc;

    /// A chain of `n` vertices: springs between neighbours (anisotropic 3×3 blocks) and a
    /// scalar second-difference "bending" matrix coupling vertices two apart.
    fn banded_chain(n: usize) -> (BlockCsr, ScalarCsr, Vec<f64>) {
        let mut k = BlockCsr::with_pattern(n, (0..n as u32 - 1).map(|i| (i, i + 1)));
        let spring = DMat3::from_cols(DVec3::new(3.0, 0.5, 0.0), DVec3::new(0.5, 1.0, 0.2), DVec3::new(0.0, 0.2, 0.7));
        for a in 0..n as u32 - 1 {
            let b = a + 1;
            let (aa, bb, ab, ba) = (k.slot(a, a), k.slot(b, b), k.slot(a, b), k.slot(b, a));
            k.values[aa] += spring;
            k.values[bb] += spring;
            k.values[ab] -= spring;
            k.values[ba] -= spring;
        }
        let pairs = (0..n as u32 - 2).flat_map(|i| [(i, i + 1), (i + 1, i + 2), (i, i + 2)]);
        let mut q = ScalarCsr::with_pattern(n, pairs);
        for i in 0..n as u32 - 2 {
            // ½ (x_i − 2x_{i+1} + x_{i+2})² · 5
            let w = [1.0, -2.0, 1.0];
            for a in 0..3 {
                for b in 0..3 {
                    let slot = q.slot(i + a, i + b);
                    q.values[slot] += 5.0 * w[a as usize] * w[b as usize];
                }
            }
        }
        let mass = (0..n).map(|i| 1.0 + (i % 7) as f64 * 0.1).collect();
        (k, q, mass)
    }

    /// Vertices coupled only by contact (disjoint groups of four, stiffer than their mass,
    /// each along its own normal): with the couplings in its pattern the incomplete factor
    /// has no fill to drop and is exact up to its single-precision storage, so CG converges
    /// at once; a factor that saw only the couplings' diagonal blocks took 356 iterations.
    #[test]
    fn incomplete_factor_takes_the_contact_couplings_in() {
        let groups = 25;
        let n = 4 * groups;
        let mut k = BlockCsr::with_pattern(n, std::iter::empty());
        let mass = vec![1.0; n];
        let couplings: Vec<Coupling> = (0..groups)
            .map(|g| {
                let t = g as f64;
                Coupling {
                    vertices: [g, g + groups, g + 2 * groups, g + 3 * groups].map(|v| v as u32),
                    weights: [1.0, -0.2 - 0.01 * t, -0.3, -0.5 + 0.01 * t],
                    normal: DVec3::new(t.sin(), t.cos(), 0.5).normalize(),
                    stiffness: 10f64.powf(1.0 + t / 8.0),
                }
            })
            .collect();
        for c in &couplings {
            let nn = DMat3::from_cols(c.normal * c.normal.x, c.normal * c.normal.y, c.normal * c.normal.z);
            for (&v, &w) in c.vertices.iter().zip(&c.weights) {
                let slot = k.diagonal_slot(v);
                k.values[slot] += nn * (c.stiffness * w * w);
            }
        }
        let fixed = vec![false; n];
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: None, fixed: &fixed, couplings: &couplings };
        let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), 1.0, (i % 3) as f64)).collect();
        let mut x = vec![DVec3::ZERO; n];
        let preconditioner = a.preconditioner();
        assert!(matches!(preconditioner, Preconditioner::IncompleteCholesky(_)), "the factorisation broke down");
        let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 500);
        let mut ax = vec![DVec3::ZERO; n];
        a.apply(&x, &mut ax);
        let error = ax.iter().zip(&b).map(|(p, q)| (*p - *q).length()).fold(0.0, f64::max);
        assert!(error < 1e-8, "residual {error} after {} iterations", report.iterations);
        assert!(report.iterations <= 3, "{} iterations", report.iterations);
    }

    #[test]
    fn block_factor_of_a_banded_matrix_is_exact_and_parts_still_converge() {
        for n in [50, 1000, 3 * PART_VERTICES] {
            let (k, q, mass) = banded_chain(n);
            let fixed = vec![false; n];
            let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &[] };
            let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), 1.0, (i % 3) as f64)).collect();
            let mut x = vec![DVec3::ZERO; n];
            let preconditioner = a.preconditioner();
            let Preconditioner::IncompleteCholesky(factor) = &preconditioner else { panic!("the factorisation broke down") };
            let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 500);
            let mut ax = vec![DVec3::ZERO; n];
            a.apply(&x, &mut ax);
            let error = ax.iter().zip(&b).map(|(p, q)| (*p - *q).length()).fold(0.0, f64::max);
            assert!(error < 1e-8, "n = {n}: residual {error} after {} iterations", report.iterations);
            if factor.parts.len() == 1 {
                // No fill falls outside a band: the incomplete factor is the exact one (up to
                // its single-precision storage). This also catches an unsymmetric factor,
                // with which the conjugate gradient stalls.
                assert!(report.iterations <= 3, "n = {n}: {} iterations", report.iterations);
            } else {
                assert_eq!(factor.parts.len(), 3);
                assert!(report.iterations < 100, "n = {n}: {} iterations", report.iterations);
            }
        }
    }

    #[test]
    fn complete_factor_solves_in_one_iteration_and_respects_fixed_vertices() {
        let n = 300;
        let (k, q, mass) = banded_chain(n);
        let mut fixed = vec![false; n];
        fixed[0] = true;
        fixed[150] = true;
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &[] };
        let pattern = Arc::new(DirectPattern::new(&a).expect("symbolic analysis"));
        assert!(pattern.fits(&a));
        let preconditioner = Preconditioner::Cholesky(DirectFactor::new(pattern, &a).expect("the factorisation failed"));
        let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).cos(), -1.0, (i % 4) as f64)).collect();
        let mut x = vec![DVec3::ZERO; n];
        let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 50);
        assert!(report.iterations <= 2, "{} iterations with the exact factor", report.iterations);
        let mut ax = vec![DVec3::ZERO; n];
        a.apply(&x, &mut ax);
        for i in 0..n {
            let expected = if fixed[i] { DVec3::ZERO } else { b[i] };
            assert!((ax[i] - expected).length() < 1e-8, "row {i}: {:?} against {:?}", ax[i], expected);
        }
        assert_eq!(x[0], DVec3::ZERO);
        assert_eq!(x[150], DVec3::ZERO);
    }

    #[test]
    fn pcg_solves_a_small_spd_system() {
        // A chain of three vertices coupled by springs along x plus a mass term.
        let mut k = BlockCsr::with_pattern(3, [(0, 1), (1, 2)].into_iter());
        let spring = DMat3::from_diagonal(DVec3::new(2.0, 1.0, 0.5));
        for (a, b) in [(0u32, 1u32), (1, 2)] {
            let (aa, bb, ab, ba) = (k.slot(a, a), k.slot(b, b), k.slot(a, b), k.slot(b, a));
            k.values[aa] += spring;
            k.values[bb] += spring;
            k.values[ab] -= spring;
            k.values[ba] -= spring;
        }
        let mass = [1.0, 2.0, 3.0];
        let fixed = [false; 3];
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: None, fixed: &fixed, couplings: &[] };
        let b = vec![DVec3::new(1.0, 0.0, 2.0), DVec3::new(-1.0, 3.0, 0.0), DVec3::new(0.5, 0.5, 0.5)];
        let mut x = vec![DVec3::ZERO; 3];
        let report = pcg(&a, &a.preconditioner(), &b, &mut x, 1e-12, 100);
        assert!(report.relative_residual < 1e-12);
        let mut ax = vec![DVec3::ZERO; 3];
        a.apply(&x, &mut ax);
        for i in 0..3 {
            assert!((ax[i] - b[i]).length() < 1e-10);
        }
    }
}
