//! Scalar compressed sparse rows for the hierarchy: products, transposes and the scalar
//! copy of the system matrix.

use super::{CHUNK_ROWS, PARALLEL_ROWS};
use crate::sim::linalg::storage::merge_rows;
use crate::sim::linalg::system::SystemMatrix;
use rayon::prelude::*;

/// Scalar compressed sparse rows.
#[derive(Debug, Clone, Default)]
pub(super) struct Csr {
    pub(super) rows: usize,
    pub(super) columns: usize,
    pub(super) row_start: Vec<u32>,
    pub(super) cols: Vec<u32>,
    pub(super) values: Vec<f64>,
}

impl Csr {
    pub(super) fn row(&self, i: usize) -> (&[u32], &[f64]) {
        let (s, e) = (self.row_start[i] as usize, self.row_start[i + 1] as usize);
        (&self.cols[s..e], &self.values[s..e])
    }

    pub(super) fn entries(&self) -> usize {
        self.values.len()
    }

    /// y = A x.
    pub(super) fn multiply(&self, x: &[f64], y: &mut [f64]) {
        let row = |i: usize| {
            let (c, v) = self.row(i);
            c.iter().zip(v).map(|(&j, &a)| a * x[j as usize]).sum::<f64>()
        };
        if self.rows < PARALLEL_ROWS {
            y.iter_mut().enumerate().for_each(|(i, out)| *out = row(i));
        } else {
            y.par_chunks_mut(CHUNK_ROWS).enumerate().for_each(|(c, chunk)| {
                for (k, out) in chunk.iter_mut().enumerate() {
                    *out = row(c * CHUNK_ROWS + k);
                }
            });
        }
    }

    pub(super) fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|i| {
                let (c, v) = self.row(i);
                c.binary_search(&(i as u32)).map_or(0.0, |k| v[k])
            })
            .collect()
    }

    pub(super) fn transpose(&self) -> Csr {
        let mut counts = vec![0u32; self.columns + 1];
        for &c in &self.cols {
            counts[c as usize + 1] += 1;
        }
        for i in 0..self.columns {
            counts[i + 1] += counts[i];
        }
        let row_start = counts.clone();
        let mut next = counts;
        let mut cols = vec![0u32; self.entries()];
        let mut values = vec![0.0; self.entries()];
        for i in 0..self.rows {
            let (c, v) = self.row(i);
            for (&j, &a) in c.iter().zip(v) {
                let slot = next[j as usize] as usize;
                next[j as usize] += 1;
                cols[slot] = i as u32;
                values[slot] = a;
            }
        }
        Csr { rows: self.columns, columns: self.rows, row_start, cols, values }
    }

    /// The product A B (Gustavson's row-by-row product with a dense accumulator), and its
    /// multiply-add count. Rows are computed in fixed chunks, so the result does not
    /// depend on the thread count.
    pub(super) fn product(&self, b: &Csr) -> (Csr, f64) {
        assert_eq!(self.columns, b.rows, "product of mismatched matrices");
        let width = b.columns;
        let chunk_rows = |range: std::ops::Range<usize>, marker: &mut Vec<u32>, sum: &mut Vec<f64>| {
            let mut lengths = Vec::with_capacity(range.len());
            let mut cols = Vec::new();
            let mut values = Vec::new();
            let mut flops = 0.0;
            for i in range {
                let start = cols.len();
                let (ac, av) = self.row(i);
                for (&k, &a) in ac.iter().zip(av) {
                    let (bc, bv) = b.row(k as usize);
                    flops += bc.len() as f64;
                    for (&j, &bkj) in bc.iter().zip(bv) {
                        let j = j as usize;
                        if marker[j] != i as u32 {
                            marker[j] = i as u32;
                            cols.push(j as u32);
                            sum[j] = a * bkj;
                        } else {
                            sum[j] += a * bkj;
                        }
                    }
                }
                cols[start..].sort_unstable();
                values.extend(cols[start..].iter().map(|&j| sum[j as usize]));
                lengths.push((cols.len() - start) as u32);
            }
            (lengths, cols, values, flops)
        };
        let scratch = || (vec![u32::MAX; width], vec![0.0; width]);
        let parts: Vec<_> = if self.rows < PARALLEL_ROWS {
            let (mut marker, mut sum) = scratch();
            vec![chunk_rows(0..self.rows, &mut marker, &mut sum)]
        } else {
            let chunks = self.rows.div_ceil(CHUNK_ROWS);
            (0..chunks)
                .into_par_iter()
                .map_init(scratch, |(marker, sum), c| chunk_rows(c * CHUNK_ROWS..((c + 1) * CHUNK_ROWS).min(self.rows), marker, sum))
                .collect()
        };
        let mut out = Csr { rows: self.rows, columns: width, row_start: Vec::with_capacity(self.rows + 1), ..Csr::default() };
        out.row_start.push(0);
        let mut flops = 0.0;
        for (lengths, cols, values, f) in parts {
            for l in lengths {
                let last = *out.row_start.last().expect("starts with 0");
                out.row_start.push(last + l);
            }
            out.cols.extend(cols);
            out.values.extend(values);
            flops += f;
        }
        (out, flops)
    }
}

/// The scalar 3n × 3n matrix of `a` (without its contact couplings, as for the factors):
/// rows and columns of fixed vertices replaced by the identity. Without `bending`, its
/// in-plane part and inertia only: the bending matrix lumped into its diagonal, which is
/// dropping it, as it annihilates translations (its rows sum to zero).
pub(super) fn scalar_matrix(a: &SystemMatrix, bending: bool) -> Csr {
    let n = a.fixed.len();
    let k = a.stiffness;
    let q = a.bending.filter(|_| bending);
    let mut out = Csr { rows: 3 * n, columns: 3 * n, row_start: vec![0], ..Csr::default() };
    let mut neighbours = Vec::new();
    for v in 0..n {
        if a.fixed[v] {
            for c in 0..3 {
                out.cols.push((3 * v + c) as u32);
                out.values.push(1.0);
                out.row_start.push(out.cols.len() as u32);
            }
            continue;
        }
        let q_row = q.map_or((&[][..], 0), |q| q.row_pattern(v));
        merge_rows(k.row_pattern(v), q_row, |u| !a.fixed[u as usize], &mut neighbours);
        for row_c in 0..3 {
            for &(u, block, bending) in &neighbours {
                for col_c in 0..3 {
                    // Entry (3v + row_c, 3u + col_c) = A_vu[row_c][col_c].
                    let mut value = if block == usize::MAX { 0.0 } else { k.values[block].col(col_c)[row_c] };
                    if row_c == col_c {
                        if let Some(q) = q.filter(|_| bending != usize::MAX) {
                            value += q.values[bending];
                        }
                        if u as usize == v {
                            value += a.mass_diagonal[v];
                        }
                    }
                    out.cols.push(3 * u + col_c as u32);
                    out.values.push(value);
                }
            }
            out.row_start.push(out.cols.len() as u32);
        }
    }
    out
}

