//! Sparse symmetric matrices over vertices, with a pattern fixed for a whole run.
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
pub(super) const PARALLEL_ROWS: usize = 4096;

/// Rows per chunk of a parallel pass over rows: small enough that the threads share the rows
/// evenly (in chunks of 1 024 the 5 247 rows of a 10k garment went 3 072 to one thread and
/// 2 175 to the other).
const CHUNK: usize = 256;

/// From this many rows up to [`PARALLEL_ROWS`] a pass is split in two halves, one on the
/// calling thread and one on the team's, whose hand-off costs far less than rayon's.
pub(super) use crate::sim::team::LEAST_ITEMS as TEAM_ROWS;

/// Calls `f(row, &mut y[row])` for every row: in two halves on the team from [`TEAM_ROWS`]
/// rows, in chunks of [`CHUNK`] rows over rayon's pool from [`PARALLEL_ROWS`]. Each row is
/// computed alone, so the result does not depend on the split.
pub(super) fn for_rows(y: &mut [DVec3], f: impl Fn(usize, &mut DVec3) + Sync) {
    use rayon::prelude::*;
    let serial = |first: usize, y: &mut [DVec3]| y.iter_mut().enumerate().for_each(|(row, out)| f(first + row, out));
    if y.len() < TEAM_ROWS {
        serial(0, y);
    } else if y.len() < PARALLEL_ROWS {
        let mid = y.len() / 2;
        let (low, high) = y.split_at_mut(mid);
        crate::sim::team::join(|| serial(0, low), || serial(mid, high));
    } else {
        y.par_chunks_mut(CHUNK).enumerate().for_each(|(c, chunk)| serial(c * CHUNK, chunk));
    }
}

/// As [`for_rows`] for `k` vectors stored side by side (`y[row * k + j]` is row `row` of
/// the `j`-th): calls `f(row, &mut y[row * k..row * k + k])` for every row.
pub(super) fn for_row_groups(y: &mut [DVec3], k: usize, f: impl Fn(usize, &mut [DVec3]) + Sync) {
    use rayon::prelude::*;
    let rows = y.len() / k;
    let serial = |first: usize, y: &mut [DVec3]| y.chunks_mut(k).enumerate().for_each(|(row, out)| f(first + row, out));
    if rows < TEAM_ROWS {
        serial(0, y);
    } else if rows < PARALLEL_ROWS {
        let mid = rows / 2;
        let (low, high) = y.split_at_mut(mid * k);
        crate::sim::team::join(|| serial(0, low), || serial(mid, high));
    } else {
        y.par_chunks_mut(CHUNK * k).enumerate().for_each(|(c, chunk)| serial(c * CHUNK, chunk));
    }
}

/// One row's entries (`values` at columns `cols`) times the `out.len()` vectors of `x`
/// stored side by side, added to `out`. The vectors go four at a time, each four summed in
/// registers over the whole row: on the 10k bias skirt, eight vectors took 2.4 ms (seven
/// single products) with `out` read and written at every entry of the row, and 1.7 ms so
/// (docs/performance-log.md, "2026-12-06").
#[inline(always)]
fn add_many<T>(values: &[T], cols: &[u32], x: &[DVec3], out: &mut [DVec3], times: impl Fn(&T, DVec3) -> DVec3) {
    let k = out.len();
    let (groups, rest) = out.as_chunks_mut::<4>();
    for (g, o) in groups.iter_mut().enumerate() {
        let mut sum = *o;
        for (m, &c) in values.iter().zip(cols) {
            let at = c as usize * k + 4 * g;
            let v: &[DVec3; 4] = x[at..at + 4].try_into().expect("four vectors");
            for j in 0..4 {
                sum[j] += times(m, v[j]);
            }
        }
        *o = sum;
    }
    let done = 4 * groups.len();
    for (j, o) in rest.iter_mut().enumerate() {
        *o += values.iter().zip(cols).fold(DVec3::ZERO, |acc, (m, &c)| acc + times(m, x[c as usize * k + done + j]));
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
    pub(super) fn row_product(&self, row: usize, x: &[DVec3]) -> DVec3 {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        self.values[s..e].iter().zip(&self.cols[s..e]).fold(DVec3::ZERO, |acc, (m, &c)| acc + *m * x[c as usize])
    }

    /// Row `row` of A X added to `out`, for the `out.len()` vectors of `x` stored side by
    /// side (`x[col * k + j]`): the row's blocks read once for all of them.
    #[inline]
    pub(super) fn row_product_add_many(&self, row: usize, x: &[DVec3], out: &mut [DVec3]) {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        add_many(&self.values[s..e], &self.cols[s..e], x, out, |m, v| *m * v);
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

    /// The slot of (row, col), or None where the pattern has no such entry.
    pub fn find(&self, row: u32, col: u32) -> Option<usize> {
        let (s, e) = (self.row_start[row as usize] as usize, self.row_start[row as usize + 1] as usize);
        self.cols[s..e].binary_search(&col).ok().map(|k| s + k)
    }

    /// y += A x, the scalar matrix acting on each coordinate; rows in parallel on large meshes.
    pub fn multiply_add(&self, x: &[DVec3], y: &mut [DVec3]) {
        for_rows(y, |row, out| *out += self.row_product(row, x));
    }

    /// Row `row` of (A ⊗ I₃) x.
    #[inline]
    pub(crate) fn row_product(&self, row: usize, x: &[DVec3]) -> DVec3 {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        self.values[s..e].iter().zip(&self.cols[s..e]).fold(DVec3::ZERO, |acc, (&v, &c)| acc + v * x[c as usize])
    }

    /// As [`BlockCsr::row_product_add_many`].
    #[inline]
    pub(super) fn row_product_add_many(&self, row: usize, x: &[DVec3], out: &mut [DVec3]) {
        let (s, e) = (self.row_start[row] as usize, self.row_start[row + 1] as usize);
        add_many(&self.values[s..e], &self.cols[s..e], x, out, |&q, v| q * v);
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

