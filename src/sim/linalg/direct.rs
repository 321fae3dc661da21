//! Sparse Cholesky factor of the Newton matrix (faer's supernodal LLᵀ with a
//! fill-reducing ordering), used as the conjugate gradient's preconditioner.
//!
//! An incomplete factor leaves out the fill that couples distant vertices, which is what
//! the stiff bending modes of a fine mesh need: with it the CG iterations grow in
//! proportion to the vertex count. The complete factor of a recent matrix leaves CG only the change since then
//! and the contact couplings to resolve. Its pattern (in-plane one-ring, bending stencil,
//! fixed vertices) is the model's for the whole run, so the ordering and symbolic analysis
//! are done once and each factorisation is numeric only. faer's symbolic analysis picks
//! the ordering and the supernodes; the numeric factorisation and the triangular solves
//! run on two threads (`supernodal`).

use super::storage::merge_rows;
use super::system::SystemMatrix;
use super::supernodal::SupernodalPlan;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, factorize_symbolic_cholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use glam::DVec3;
use std::sync::Arc;

/// faer factors on one thread. Its supernodes on cloth meshes are small, and on two cores
/// its rayon mode was slower than its sequential one at every drape size measured, factor
/// and solves alike (docs/performance-log.md). Supernodal factors are left to
/// `SupernodalPlan`, which splits the elimination tree instead; faer factors and solves
/// only the simplicial factors it picks for small matrices.
const PARALLELISM: Par = Par::Seq;

/// Where each stored entry of the lower triangle comes from.
#[derive(Debug, Clone, Copy)]
struct Source {
    /// Slot of the in-plane block A_vu (row v, column u ≥ v), or u32::MAX.
    block: u32,
    /// Component (a, b) of that block: entry [a][b].
    a: u8,
    b: u8,
    /// Slot of the bending entry Q_vu for a diagonal component (a = b), or u32::MAX.
    bending: u32,
    /// The vertex whose mass term sits here (diagonal entries), or u32::MAX.
    mass: u32,
}

/// The lower-triangle pattern of the scalar 3n × 3n matrix, its symbolic factor and where
/// each entry comes from.
pub struct DirectPattern {
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    sources: Vec<Source>,
    symbolic: SymbolicCholesky<u32>,
    /// The two-thread factorisation's and triangular solves' plan (None: faer's simplicial
    /// factor, made and solved by faer).
    plan: Option<SupernodalPlan>,
    /// Where each stored entry goes in L's supernodal blocks, for `plan`.
    destinations: Vec<usize>,
    /// The fixed vertices it was built for.
    fixed: Vec<bool>,
}

impl DirectPattern {
    /// The pattern of `a`; None if the symbolic analysis fails.
    pub fn new(a: &SystemMatrix) -> Option<Self> {
        let n = a.fixed.len();
        let k = a.stiffness;
        let mut col_ptr = vec![0u32];
        let mut row_idx = Vec::new();
        let mut sources = Vec::new();
        let mut neighbours: Vec<(u32, usize, usize)> = Vec::new();
        for v in 0..n {
            neighbours.clear();
            if !a.fixed[v] {
                // Columns u ≥ v of row v in either pattern, with their slots.
                let q_row = a.bending.map_or((&[][..], 0), |q| q.row_pattern(v));
                merge_rows(k.row_pattern(v), q_row, |u| u as usize >= v && !a.fixed[u as usize], &mut neighbours);
            }
            for col_c in 0..3u8 {
                let col = 3 * v + col_c as usize;
                if a.fixed[v] {
                    row_idx.push(col as u32);
                    sources.push(Source { block: u32::MAX, a: 0, b: 0, bending: u32::MAX, mass: u32::MAX });
                } else {
                    for &(u, block, bending) in &neighbours {
                        for row_c in 0..3u8 {
                            let row = 3 * u as usize + row_c as usize;
                            if row < col {
                                continue;
                            }
                            // Entry (3u + row_c, 3v + col_c) = A_uv[row_c][col_c] = A_vu[col_c][row_c].
                            let diagonal_component = row_c == col_c;
                            row_idx.push(row as u32);
                            let slot = |s: usize| if s == usize::MAX { u32::MAX } else { s as u32 };
                            sources.push(Source {
                                block: slot(block),
                                a: col_c,
                                b: row_c,
                                bending: if diagonal_component { slot(bending) } else { u32::MAX },
                                mass: if diagonal_component && u as usize == v { v as u32 } else { u32::MAX },
                            });
                        }
                    }
                }
                col_ptr.push(row_idx.len() as u32);
            }
        }
        let size = 3 * n;
        let pattern = SymbolicSparseColMatRef::new_checked(size, size, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), Default::default()).ok()?;
        let plan = SupernodalPlan::new(&symbolic);
        let destinations = plan.as_ref().map_or_else(Vec::new, |p| p.destinations(&col_ptr, &row_idx));
        Some(Self { col_ptr, row_idx, sources, symbolic, plan, destinations, fixed: a.fixed.to_vec() })
    }

    /// Whether this pattern is that of `a` (the same vertices fixed).
    pub fn fits(&self, a: &SystemMatrix) -> bool {
        self.fixed == a.fixed
    }
}

/// A factorisation's time over what its multiply-add count says in CG iterations: its
/// multiply-adds work on dense supernodal blocks, a solve's read the factor once each, so
/// a factorisation costs far fewer iterations' time than its count says (the ratio was
/// timed on a fine drape; docs/performance-log.md). It keeps the cost a count (the same
/// choice on every machine) but in the right units; without it the rent-or-buy rule keeps
/// factors several times too long.
const FACTOR_SPEED_RATIO: f64 = 0.2;

/// The Cholesky factor of one Newton matrix.
pub struct DirectFactor {
    pattern: Arc<DirectPattern>,
    /// L's entries in single precision: the triangular solves are bound by reading them and
    /// the factorisation by the arithmetic on them, and a preconditioner needs no more
    /// digits (as for the incomplete factor's blocks).
    values: Vec<f32>,
    /// Estimated cost of the factorisation in solves with it: a column of c entries costs
    /// about c² multiply-adds to factor and 4c to solve with, and the factorisation's run
    /// `1/FACTOR_SPEED_RATIO` times as fast.
    pub cost_in_iterations: f64,
}

impl DirectFactor {
    /// Factors `a` (without its contact couplings) on `pattern`; None if it is not
    /// positive definite.
    pub fn new(pattern: Arc<DirectPattern>, a: &SystemMatrix) -> Option<Self> {
        use rayon::prelude::*;
        let k = a.stiffness;
        let values: Vec<f32> = pattern
            .sources
            .par_iter()
            .with_min_len(1 << 14)
            .map(|s| {
                if s.block == u32::MAX && s.bending == u32::MAX && s.mass == u32::MAX {
                    return if s.a == s.b { 1.0 } else { 0.0 };
                }
                // Summed in double precision, stored in single.
                let mut value = 0.0;
                if s.block != u32::MAX {
                    value += k.values[s.block as usize].col(s.b as usize)[s.a as usize];
                }
                if s.bending != u32::MAX {
                    value += a.bending.expect("the pattern came from it").values[s.bending as usize];
                }
                if s.mass != u32::MAX {
                    value += a.mass_diagonal[s.mass as usize];
                }
                value as f32
            })
            .collect();
        let size = 3 * a.fixed.len();
        let symbolic = &pattern.symbolic;
        let mut factor = vec![0.0f32; symbolic.len_val()];
        let column = symbolic.len_val() as f64 / size.max(1) as f64;
        let cost_in_iterations = column / 4.0 * FACTOR_SPEED_RATIO;
        if let Some(plan) = &pattern.plan {
            let positive = plan.factor(&values, &pattern.destinations, &mut factor);
            return positive.then(|| Self { pattern: pattern.clone(), values: factor, cost_in_iterations });
        }
        let matrix = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(size, size, &pattern.col_ptr, None, &pattern.row_idx),
            &values,
        );
        let par = PARALLELISM;
        let mut buffer = MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f32>(par, Default::default()));
        symbolic
            .factorize_numeric_llt::<f32>(
                &mut factor,
                matrix,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .ok()?;
        Some(Self { pattern, values: factor, cost_in_iterations })
    }

    /// z = (LLᵀ)⁻¹ r.
    pub fn solve(&self, r: &[DVec3], z: &mut [DVec3]) {
        if let Some(plan) = &self.pattern.plan {
            plan.solve(&self.values, |i| r[i / 3][i % 3] as f32, |i, v| z[i / 3][i % 3] = v as f64);
            return;
        }
        let symbolic = &self.pattern.symbolic;
        let mut flat: Vec<f32> = r.iter().flat_map(|v| v.to_array().map(|c| c as f32)).collect();
        let size = flat.len();
        let par = PARALLELISM;
        let mut buffer = MemBuffer::new(symbolic.solve_in_place_scratch::<f32>(1, par));
        LltRef::<'_, u32, f32>::new(symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut flat, size, 1),
            par,
            MemStack::new(&mut buffer),
        );
        for (i, zi) in z.iter_mut().enumerate() {
            *zi = DVec3::new(flat[3 * i] as f64, flat[3 * i + 1] as f64, flat[3 * i + 2] as f64);
        }
    }
}
