//! The physics: meshes, fabric laws, the model's energies and the time integrators.
//! No rendering, UI or file input/output here.
pub mod contact;
pub mod curve;
pub mod linalg;
pub mod material;
pub mod mesh;
pub mod model;
pub mod solver;
pub(crate) mod team;

/// Revision of the model's physics: raised by every change that alters simulated results,
/// so that results cached from an older model (the chart's drape reference) are recomputed.
/// 2: hinges against mesh-scale oscillation in the bending energy.
pub const MODEL_REVISION: u32 = 2;

pub use curve::PiecewiseLinear;
pub use solver::{AdaptiveStep, Integrator, IntegratorKind, Minimizer, NewtonSettings, PreconditionerChoice, State, StepError, StepReport, StepTimings};
pub use material::{BendingStiffness, Fabric, FabricError, FabricPoints, MembraneLaw};
pub use mesh::{Mesh, MeshError, Pattern};
pub use model::{Model, ModelError, Motion, PhysicsOptions};
