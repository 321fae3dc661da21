//! The choice of approximate inverse for the conjugate gradient.
//!
//! Each kind lives in its own module and knows only the system matrix; this enum is the
//! one place that names them all, so the factors never import each other.

use super::direct::DirectFactor;
use super::incomplete::{FactorPattern, IncompleteCholesky};
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

impl SystemMatrix<'_> {
    /// The preconditioner: block incomplete Cholesky on `pattern`, or block Jacobi if that
    /// factorisation breaks down even with a diagonal shift.
    pub fn preconditioner(&self, pattern: FactorPattern) -> Preconditioner {
        for shift in [0.0, 1e-3, 1e-2, 1e-1] {
            if let Some(factor) = IncompleteCholesky::new(self, shift, pattern) {
                return Preconditioner::IncompleteCholesky(factor);
            }
        }
        Preconditioner::BlockJacobi(self.block_jacobi())
    }
}
