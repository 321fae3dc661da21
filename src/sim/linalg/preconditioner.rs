//! The choice of approximate inverse for the conjugate gradient.
//!
//! Each kind lives in its own module and knows only the system matrix; this enum is the
//! one place that names them all, so the factors never import each other.

use super::direct::DirectFactor;
use super::incomplete::{FactorPattern, IncompleteCholesky, factor_is_split};
use super::multigrid::Multigrid;
use super::system::SystemMatrix;
use glam::{DMat3, DVec3};

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

/// The diagonal shifts, as shares of the diagonal, that an incomplete factorisation tries in
/// turn until one does not break down.
const SHIFTS: [f64; 4] = [0.0, 1e-3, 1e-2, 1e-1];

/// The shifts of a one-ring factor of a split-size matrix (`factor_is_split`): those of
/// [`SHIFTS`], then up to the diagonal itself. On the 10k circle skirt's bounded matrices the
/// one-ring factor broke down at every shift of [`SHIFTS`], so every factor was the whole
/// pattern's, whose blocks (with the matrix's) no longer fit in the cache: a CG iteration read
/// about 13 MB. Made at a shift of the whole diagonal, the one-ring factor reads an eighth
/// of the blocks, and the pattern choice (`solver::preconditioning::PatternChoice`) took it
/// for most factors: a fifth fewer Newton iterations, a third fewer factors and a third less
/// solve time per CG iteration (docs/performance-log.md, "2026-12-05: the one-ring factor at larger shifts").
/// On smaller meshes, whose factors stay in the cache, it was taken too and cost more CG
/// iterations than it saved (the 2 cm circle skirt's exact path: 84 335 against 49 481).
const RING_SPLIT_SHIFTS: [f64; 6] = [0.0, 1e-3, 1e-2, 1e-1, 0.3, 1.0];

/// The shifts a factor on `pattern` of a matrix over `n` vertices tries.
fn shifts(pattern: FactorPattern, n: usize) -> &'static [f64] {
    if pattern == FactorPattern::Ring && factor_is_split(n) { &RING_SPLIT_SHIFTS } else { &SHIFTS }
}

/// Factors between trials of the shift below the one the last factor of a pattern needed.
const SHIFT_PROBE: usize = 4;

/// Where a run's next incomplete factor of each pattern starts on its shifts ([`shifts`]):
/// at the shift the last one needed, and one lower every [`SHIFT_PROBE`] factors (clamped
/// to the pattern's list, which depends on the matrix's size). A matrix that breaks
/// the unshifted factorisation usually breaks it again at the next Newton iteration: on the
/// 10k circle skirt two of every three factorisations started from no shift failed
/// (each costing nearly a whole factorisation, the parts running side by side), and the
/// factors' building was a tenth of the run. Counts, not clocks, decide, so a run takes the
/// same path on every machine.
#[derive(Debug, Clone, Default)]
pub struct ShiftMemory {
    /// Index into the pattern's shifts ([`shifts`]) and factors made, by pattern (`Wide`, `Ring`).
    start: [usize; 2],
    made: [usize; 2],
}

impl SystemMatrix<'_> {
    /// The preconditioner: block incomplete Cholesky on `pattern`, or block Jacobi if that
    /// factorisation breaks down even with a diagonal shift.
    pub fn preconditioner(&self, pattern: FactorPattern) -> Preconditioner {
        self.preconditioner_remembering(pattern, &mut ShiftMemory::default())
    }

    /// As [`SystemMatrix::preconditioner`], its shifts tried from where `memory` says.
    pub fn preconditioner_remembering(&self, pattern: FactorPattern, memory: &mut ShiftMemory) -> Preconditioner {
        let p = usize::from(pattern == FactorPattern::Ring);
        memory.made[p] += 1;
        let shifts = shifts(pattern, self.fixed.len());
        let start = memory.start[p].min(shifts.len() - 1);
        let first = if memory.made[p].is_multiple_of(SHIFT_PROBE) { start.saturating_sub(1) } else { start };
        for (level, &shift) in shifts.iter().enumerate().skip(first) {
            if let Some(factor) = IncompleteCholesky::new(self, shift, pattern) {
                memory.start[p] = level;
                return Preconditioner::IncompleteCholesky(factor);
            }
        }
        memory.start[p] = shifts.len() - 1;
        Preconditioner::BlockJacobi(self.block_jacobi())
    }
}
