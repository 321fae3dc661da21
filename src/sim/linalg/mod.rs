//! Linear algebra for Newton's systems: sparse storage on the mesh's fixed pattern, the
//! system matrix, the conjugate gradient and its preconditioners.
//!
//! Dependencies point one way: `storage` ← `system` ← the factors (`incomplete`, `direct`
//! with `supernodal`, `multigrid`) ← `preconditioner` (the one enum naming them all) ←
//! `cg`.

mod cg;
pub mod direct;
mod incomplete;
pub mod multigrid;
mod preconditioner;
mod scalar_factor;
mod storage;
pub mod supernodal;
mod system;
#[cfg(test)]
mod tests;

pub use cg::{CgReport, Recycled, pcg, pcg_deflated};
pub use direct::{DirectFactor, DirectPattern};
pub use incomplete::{FactorPattern, IncompleteCholesky, factor_is_split};
pub use multigrid::Multigrid;
pub use preconditioner::{Preconditioner, ShiftMemory};
pub use scalar_factor::{ScalarFactor, ScalarPattern};
pub use storage::{BlockCsr, ScalarCsr};
pub use system::{Coupling, SystemMatrix};
