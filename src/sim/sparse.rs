//! Sparse symmetric matrices over vertices and the preconditioned conjugate gradient.
//!
//! Written by hand rather than taken from a general sparse crate because the structure is
//! fixed for a whole run: the pattern is built once from the mesh, each element keeps the
//! slots it writes to, and re-assembly is a plain pass over a value array. The in-plane
//! part is stored as 3×3 blocks; the bending part is a scalar matrix that acts the same on
//! x, y and z (its energy is ½ Σ Q_ab x_a·x_b), so it is stored once, not three times.

use glam::{DMat3, DVec3};

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
        for_rows(y, |row, out| {
            let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
            let mut acc = DVec3::ZERO;
            for k in s..e {
                acc += self.values[k] * x[self.cols[k] as usize];
            }
            *out = acc;
        });
    }

    pub fn vertex_count(&self) -> usize {
        self.row_start.len() - 1
    }
}

impl ScalarCsr {
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
        for_rows(y, |row, out| {
            let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
            let mut acc = DVec3::ZERO;
            for k in s..e {
                acc += self.values[k] * x[self.cols[k] as usize];
            }
            *out += acc;
        });
    }

    pub fn diagonal(&self, row: u32) -> f64 {
        self.value(row, row)
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
        self.stiffness.multiply(x, y);
        if let Some(q) = self.bending {
            q.multiply_add(x, y);
        }
        for c in self.couplings {
            let along = |j: usize| c.weights[j] * c.normal.dot(x[c.vertices[j] as usize]);
            let total: f64 = (0..4).map(along).sum();
            for j in 0..4 {
                y[c.vertices[j] as usize] += c.stiffness * c.weights[j] * (total - along(j)) * c.normal;
            }
        }
        for i in 0..y.len() {
            y[i] = if self.fixed[i] { DVec3::ZERO } else { y[i] + self.mass_diagonal[i] * x[i] };
        }
    }

    /// The preconditioner: incomplete Cholesky on the in-plane pattern, or block Jacobi if
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
    fn block_jacobi(&self) -> Vec<DMat3> {
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
}

impl Preconditioner {
    fn apply(&self, r: &[DVec3], z: &mut [DVec3]) {
        match self {
            Preconditioner::BlockJacobi(blocks) => {
                for i in 0..r.len() {
                    z[i] = blocks[i] * r[i];
                }
            }
            Preconditioner::IncompleteCholesky(factor) => factor.solve(r, z),
        }
    }
}

/// Incomplete Cholesky factor L (A ≈ L Lᵀ) of the system matrix restricted to the in-plane
/// (one-ring) pattern, as scalars over the 3n unknowns, lower triangle by rows; the
/// diagonal is each row's last entry. The bending matrix's wider entries are left out of
/// the factor (they are still in the matrix CG solves with). Written by hand: the pattern
/// is the mesh's, and no sparse-factorisation crate we could use takes it as it is.
pub struct IncompleteCholesky {
    row_start: Vec<usize>,
    cols: Vec<u32>,
    values: Vec<f64>,
}

impl IncompleteCholesky {
    /// Factors A + shift·diag(A); None if a pivot is not positive (breakdown).
    fn new(a: &SystemMatrix, shift: f64) -> Option<Self> {
        let n = a.fixed.len();
        let k = a.stiffness;
        let mut row_start = Vec::with_capacity(3 * n + 1);
        let mut cols: Vec<u32> = Vec::new();
        let mut values: Vec<f64> = Vec::new();
        row_start.push(0);
        for vertex in 0..n {
            let (s, e) = (k.row_start[vertex] as usize, k.row_start[vertex + 1] as usize);
            for c in 0..3 {
                let row = 3 * vertex + c;
                if a.fixed[vertex] {
                    cols.push(row as u32);
                    values.push(1.0);
                    row_start.push(cols.len());
                    continue;
                }
                for slot in s..e {
                    let other = k.cols[slot] as usize;
                    if a.fixed[other] || other > vertex {
                        continue;
                    }
                    let q = a.bending.map_or(0.0, |q| q.value(vertex as u32, other as u32));
                    let block = k.values[slot];
                    for d in 0..3 {
                        let col = 3 * other + d;
                        if col > row {
                            continue;
                        }
                        let mut v = block.col(d)[c];
                        if d == c {
                            v += q;
                            if other == vertex {
                                v = (v + a.mass_diagonal[vertex]) * (1.0 + shift);
                            }
                        }
                        cols.push(col as u32);
                        values.push(v);
                    }
                }
                row_start.push(cols.len());
            }
        }
        // Rows are built in increasing column order because the block columns are sorted.
        let mut factor = Self { row_start, cols, values };
        for i in 0..3 * n {
            let (s, e) = (factor.row_start[i], factor.row_start[i + 1]);
            for p in s..e {
                let k = factor.cols[p] as usize;
                // Σ_j L_ij L_kj over the columns j < k the two rows share.
                let (ks, ke) = (factor.row_start[k], factor.row_start[k + 1]);
                let (mut x, mut y, mut sum) = (s, ks, 0.0);
                while x < p && y < ke - 1 {
                    let (cx, cy) = (factor.cols[x], factor.cols[y]);
                    if cx == cy {
                        sum += factor.values[x] * factor.values[y];
                        x += 1;
                        y += 1;
                    } else if cx < cy {
                        x += 1;
                    } else {
                        y += 1;
                    }
                }
                if k == i {
                    let pivot = factor.values[p] - sum;
                    if pivot.is_nan() || pivot <= 0.0 {
                        return None;
                    }
                    factor.values[p] = pivot.sqrt();
                } else {
                    factor.values[p] = (factor.values[p] - sum) / factor.values[ke - 1];
                }
            }
        }
        Some(factor)
    }

    /// z = (L Lᵀ)⁻¹ r.
    fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
        let n = 3 * r.len();
        let mut y: Vec<f64> = r.iter().flat_map(|v| v.to_array()).collect();
        for i in 0..n {
            let (s, e) = (self.row_start[i], self.row_start[i + 1]);
            let mut v = y[i];
            for p in s..e - 1 {
                v -= self.values[p] * y[self.cols[p] as usize];
            }
            y[i] = v / self.values[e - 1];
        }
        for i in (0..n).rev() {
            let (s, e) = (self.row_start[i], self.row_start[i + 1]);
            y[i] /= self.values[e - 1];
            let yi = y[i];
            for p in s..e - 1 {
                y[self.cols[p] as usize] -= self.values[p] * yi;
            }
        }
        for (i, zi) in z.iter_mut().enumerate() {
            *zi = DVec3::new(y[3 * i], y[3 * i + 1], y[3 * i + 2]);
        }
    }
}

/// Outcome of a conjugate-gradient solve.
#[derive(Debug, Clone, Copy)]
pub struct CgReport {
    pub iterations: usize,
    pub relative_residual: f64,
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
        return CgReport { iterations: 0, relative_residual: 0.0 };
    }
    let mut z = vec![DVec3::ZERO; n];
    preconditioner.apply(&r, &mut z);
    let mut p = z.clone();
    let mut ap = vec![DVec3::ZERO; n];
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let mut residual = 1.0;
    while iterations < max_iterations {
        a.apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap <= 0.0 || !pap.is_finite() {
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
    CgReport { iterations, relative_residual: residual }
}

#[cfg(test)]
mod tests {
    use super::*;

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
