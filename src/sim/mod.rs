//! The physics: meshes, fabric laws, the model's energies and the time integrators.
//! No rendering, UI or file input/output here.
pub mod contact;
pub mod curve;
pub mod direct;
pub mod integrate;
pub mod material;
pub mod mesh;
pub mod model;
pub mod sparse;

pub use curve::PiecewiseLinear;
pub use integrate::{AdaptiveStep, Integrator, IntegratorKind, NewtonSettings, PreconditionerChoice, State, StepError, StepReport, StepTimings};
pub use material::{BendingStiffness, Fabric, FabricError, MembraneLaw};
pub use mesh::{Mesh, MeshError, Pattern};
pub use model::{Model, ModelError, Motion, PhysicsOptions};
