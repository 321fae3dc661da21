//! The settings layer: what a scene or fabric file may say and whether it is possible,
//! below both `scene/` (which runs scenes) and `fabric/` (which converts measurement
//! sheets), so that neither reaches into the other.
//!
//! - [`schema`]: the scene file's sections, as serde reads them, and [`fabric`] the fabric
//!   table;
//! - [`registry`]: the scenes, fabrics, prop meshes and textures bundled into the binary;
//! - [`read`]: the one reader of "a bundled name or a file", and `--set` overrides;
//! - [`rule`]: a refused value ([`rule::Invalid`]) and the ranges most keys follow.
//!
//! The checks a scene passes before it is built live above this layer, in `scene::check`,
//! beside the scene kinds they ask.
//!
//! Merging a scene with its fabric file and its overrides (`scene::load`) sits above this
//! layer, since the fabric's measurement sheets are converted on the way.

pub mod fabric;
pub mod origin;
pub mod read;
pub mod registry;
pub mod rule;
pub mod schema;

pub use fabric::FabricConfig;
pub use origin::{Origin, Origins};
pub use read::{PresetError, PresetKind, parse_override, read_preset, scene_descriptions};
pub use registry::{ASSETS, Asset, BASES, Bundled, FABRICS, SCENES};
pub use schema::{
    ClothSection, DEFAULT_MAX_STEPS, FastSettings, MeshSection, PhysicsSection, PropConfig, PropKind, SceneConfig, SceneKind, SceneSection,
    ShearKinematics, SolverPath, SolverSection, TestSection,
};
