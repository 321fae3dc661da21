//! The Cholesky factor of a scalar matrix that acts alike on x, y and z, (S ⊗ I₃): the
//! quasi-Newton step's matrix, solved with at every iteration.
//!
//! A 3n × 3n factor of the same matrix would store every 3×3 block whole, nine times the
//! entries of S's factor. Here S alone is factored (faer's symbolic analysis with its
//! fill-reducing ordering, then its simplicial numeric factorisation, made anew only when
//! S's values change), and the three coordinates are solved together, each entry of L read
//! once per sweep for all three. The solve is written by hand because faer's solves take
//! the right-hand sides as dense column blocks: with three columns its supernodal solve
//! spent most of its time packing blocks for its matrix kernels (perf, sphere drop), and
//! its simplicial one sweeps L once per column.

use super::storage::ScalarCsr;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, factorize_symbolic_cholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Side};
use glam::DVec3;

/// The lower-triangle pattern of S over a mesh (fixed vertices' rows and columns replaced
/// by the identity), its symbolic factor and where each entry's value comes from.
pub struct ScalarPattern {
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    /// For each stored entry: the slot of `k` it takes, and whether it is a diagonal one
    /// (which also takes the vertex's `diagonal`); `u32::MAX` for a fixed vertex's 1.
    sources: Vec<(u32, bool)>,
    symbolic: SymbolicCholesky<u32>,
    /// The fill-reducing ordering: position i of the factor is vertex `order[i]`.
    order: Vec<u32>,
    fixed: Vec<bool>,
}

impl ScalarPattern {
    /// The pattern of diag + `k` with `fixed` vertices eliminated; None if the analysis fails.
    pub fn new(k: &ScalarCsr, fixed: &[bool]) -> Option<Self> {
        let n = fixed.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        let mut sources = Vec::new();
        col_ptr.push(0u32);
        for v in 0..n {
            if fixed[v] {
                row_idx.push(v as u32);
                sources.push((u32::MAX, true));
            } else {
                let (cols, start) = k.row_pattern(v);
                for (offset, &u) in cols.iter().enumerate() {
                    if u as usize >= v && !fixed[u as usize] {
                        row_idx.push(u);
                        sources.push(((start + offset) as u32, u as usize == v));
                    }
                }
            }
            col_ptr.push(row_idx.len() as u32);
        }
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL, ..Default::default() };
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), params).ok()?;
        let order = match symbolic.perm() {
            Some(perm) => perm.arrays().0.to_vec(),
            None => (0..n as u32).collect(),
        };
        Some(Self { col_ptr, row_idx, sources, symbolic, order, fixed: fixed.to_vec() })
    }

    /// Entries of the factor L.
    pub fn factor_entries(&self) -> usize {
        self.symbolic.len_val()
    }
}

/// The numeric factor S = LLᵀ (in the pattern's ordering).
pub struct ScalarFactor {
    values: Vec<f64>,
}

impl ScalarFactor {
    /// Factors diag(`diagonal`) + `k` on `pattern`; None if it is not positive definite.
    pub fn new(pattern: &ScalarPattern, diagonal: &[f64], k: &ScalarCsr) -> Option<Self> {
        let values: Vec<f64> = pattern
            .sources
            .iter()
            .zip(&pattern.row_idx)
            .map(|(&(slot, diagonal_entry), &row)| {
                if slot == u32::MAX {
                    return 1.0;
                }
                k.values[slot as usize] + if diagonal_entry { diagonal[row as usize] } else { 0.0 }
            })
            .collect();
        let n = diagonal.len();
        let matrix = SparseColMatRef::new(SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx), &values);
        let symbolic = &pattern.symbolic;
        let mut factor = vec![0.0f64; symbolic.len_val()];
        let mut buffer = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
        symbolic
            .factorize_numeric_llt::<f64>(&mut factor, matrix, Side::Lower, Default::default(), Par::Seq, MemStack::new(&mut buffer), Default::default())
            .ok()?;
        Some(Self { values: factor })
    }

    /// z = (S ⊗ I₃)⁻¹ r, zero on fixed vertices.
    pub fn solve(&self, pattern: &ScalarPattern, r: &[DVec3], z: &mut [DVec3]) {
        self.solve_any(pattern, r, z);
    }

    /// z = S⁻¹ r for one scalar right-hand side, zero on fixed vertices.
    pub fn solve_scalar(&self, pattern: &ScalarPattern, r: &[f64], z: &mut [f64]) {
        self.solve_any(pattern, r, z);
    }

    fn solve_any<T>(&self, pattern: &ScalarPattern, r: &[T], z: &mut [T])
    where
        T: Copy + Default + std::ops::SubAssign + std::ops::Mul<f64, Output = T> + std::ops::Div<f64, Output = T>,
    {
        let SymbolicCholeskyRaw::Simplicial(l) = pattern.symbolic.raw() else {
            unreachable!("the pattern's analysis is forced simplicial")
        };
        let (col_ptr, row_idx) = (l.col_ptr(), l.row_idx());
        let n = r.len();
        let order = &pattern.order;
        let mut w: Vec<T> = order.iter().map(|&v| if pattern.fixed[v as usize] { T::default() } else { r[v as usize] }).collect();
        // L w' = w, column by column; each column's first entry is its diagonal.
        for j in 0..n {
            let (s, e) = (col_ptr[j] as usize, col_ptr[j + 1] as usize);
            let wj = w[j] / self.values[s];
            w[j] = wj;
            for k in s + 1..e {
                w[row_idx[k] as usize] -= wj * self.values[k];
            }
        }
        // Lᵀ z' = w'.
        for j in (0..n).rev() {
            let (s, e) = (col_ptr[j] as usize, col_ptr[j + 1] as usize);
            let mut wj = w[j];
            for k in s + 1..e {
                wj -= w[row_idx[k] as usize] * self.values[k];
            }
            w[j] = wj / self.values[s];
        }
        for (i, &v) in order.iter().enumerate() {
            z[v as usize] = if pattern.fixed[v as usize] { T::default() } else { w[i] };
        }
    }
}
