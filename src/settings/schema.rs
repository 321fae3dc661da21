//! The scene schema: what a scene file may say, section by section, as serde reads it.
//! Unknown keys are refused (`deny_unknown_fields`), so a typo fails loudly; the values are
//! checked in `scene::check`.

use super::fabric::FabricConfig;
use crate::sim::contact::ContactSettings;
use crate::sim::{AdaptiveStep, Fabric, FabricError, IntegratorKind, NewtonSettings, Pattern};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// What kind of laboratory test or demo a scene runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SceneKind {
    /// Instron-style strip pull at constant speed (paper Figs. 4–5).
    Tensile,
    /// Heavy cantilever, Peirce / ASTM D1388.
    Cantilever,
    /// Strip under a constant end moment.
    Arc,
    /// Compression between pinned ends (paper Figs. 7–8).
    EulerBuckling,
    /// One edge clamped, the opposite edge moved along the warp (paper Figs. 9–10).
    ShearBuckling,
    /// A cloth falling or resting on props until it settles: the Cusick drape test
    /// (paper Fig. 6, BS 5058), a tablecloth.
    Drape,
    /// Pattern pieces sewn into a garment on a dress form (`[garment]`, docs/garments.md).
    Garment,
    /// A strip hung from its top edge, released in the hanging chain's first mode; its
    /// period against the chain's (docs/references.md §10).
    Swing,
}

impl SceneKind {
    /// Every kind, in the order above (what each does: `scene::kinds`).
    pub const ALL: [SceneKind; 8] =
        [Self::Tensile, Self::Cantilever, Self::Arc, Self::EulerBuckling, Self::ShearBuckling, Self::Drape, Self::Garment, Self::Swing];
}

/// A complete scene description, after the fabric file and overrides are merged.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    pub scene: SceneSection,
    pub fabric: FabricConfig,
    /// The specimen (every kind but garments, whose cloth is their `[garment]` pattern).
    #[serde(default)]
    pub cloth: ClothSection,
    pub mesh: MeshSection,
    pub solver: SolverSection,
    #[serde(default)]
    pub physics: PhysicsSection,
    #[serde(default)]
    pub test: TestSection,
    /// Contact settings (props, friction, self-collision).
    #[serde(default)]
    pub contact: ContactSettings,
    /// Rigid props: `[[props]]` tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub props: Vec<PropConfig>,
    /// Garment scenes: the pattern, its seams and the form.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub garment: Option<crate::garment::GarmentConfig>,
    /// Directory of the scene file, for relative asset paths (none for bundled scenes).
    #[serde(skip)]
    pub base_dir: Option<PathBuf>,
    /// Where each value came from (`scene::load`): the plan keeps what the user set.
    #[serde(skip)]
    pub origins: super::Origins,
    /// The scene's own `[fabric]` keys (and `--set fabric.KEY`), laid over the fabric file:
    /// what stays when another fabric is chosen for the scene (`card::scene_fabric`).
    #[serde(skip)]
    pub own_fabric_keys: toml::Table,
}

/// The kinds of prop a scene can place.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PropKind {
    Ground,
    Box,
    Cylinder,
    Sphere,
    Mesh,
}

/// One `[[props]]` table. Which size keys are needed depends on `shape`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropConfig {
    pub shape: PropKind,
    #[serde(default)]
    pub name: Option<String>,
    /// Centre of the prop (a point of the ground plane), m.
    #[serde(default)]
    pub position: [f64; 3],
    /// Rotation about x, then y, then z, degrees.
    #[serde(default)]
    pub rotation_deg: [f64; 3],
    /// Cylinder and sphere radius, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Cylinder height, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// Box size along x, y, z, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    /// Mesh: OBJ file, a bundled asset name (e.g. `assets/bowl.obj`) or a path relative to
    /// the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Mesh: uniform scale applied to the file's coordinates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    pub kind: SceneKind,
    /// One line for menus and `rosette presets`.
    #[serde(default)]
    pub description: String,
    /// Simulated time, s.
    pub duration: f64,
    /// Seed of the random perturbation.
    #[serde(default)]
    pub seed: u64,
    /// Stop early once the cloth has settled: the RMS vertex speed stays below this, m/s,
    /// for `settle_window` seconds after every prescribed motion has finished. Absent: run
    /// the whole duration.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_speed: Option<f64>,
    /// How long the cloth must stay slow to count as settled, s.
    #[serde(default = "default_settle_window")]
    pub settle_window: f64,
    /// Gravity grows linearly from zero to full over this time, s: the cloth then sinks
    /// through a sequence of near-equilibria instead of falling, as a specimen lowered onto
    /// its support does. Absent: full gravity from the start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_ramp: Option<f64>,
    /// Most steps a run may take (`rosette run --max-steps`): a scene that needs more is
    /// refused before it starts, and a run with adaptive steps stops there.
    #[serde(default = "default_max_steps")]
    pub max_steps: u64,
}

fn default_settle_window() -> f64 {
    0.2
}

/// A million steps: any bundled scene at its step, or an explicit run at 10 µs for 10 s.
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000;

fn default_max_steps() -> u64 {
    DEFAULT_MAX_STEPS
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClothSection {
    /// Sample length along its x axis, m (the gauge length of a tensile test, the overhang
    /// of a cantilever, the distance between the ends in Euler buckling).
    #[serde(default)]
    pub length: f64,
    /// Sample width, m.
    #[serde(default)]
    pub width: f64,
    /// Disc diameter, m (drape scenes).
    #[serde(default)]
    pub diameter: f64,
    /// Angle of the warp from the sample's x axis, degrees.
    #[serde(default)]
    pub warp_angle_deg: f64,
    /// Drape: where the cloth's centre starts, [x, y, z] m (it starts flat and level).
    #[serde(default)]
    pub position: [f64; 3],
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSection {
    /// Mean edge length, m.
    pub edge_length: f64,
    #[serde(default)]
    pub pattern: Pattern,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSection {
    pub integrator: IntegratorKind,
    /// Time step, s.
    pub dt: f64,
    /// Air damping rate ζ, 1/s (drag −ζ·m·v).
    #[serde(default)]
    pub damping: f64,
    #[serde(default)]
    pub newton: NewtonSettings,
    /// Adaptive time steps (implicit integrators), starting from `dt`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub adaptive: Option<AdaptiveStep>,
    /// The exact path (the validated reference) or the fast one.
    #[serde(default)]
    pub path: SolverPath,
    /// The fast path's settings.
    #[serde(default)]
    pub fast: FastSettings,
}

impl SolverSection {
    /// The integrator these settings describe: the one place a scene's integrator is made.
    pub fn integrator(&self) -> crate::sim::Integrator {
        let mut integrator = crate::sim::Integrator::new(self.integrator, self.dt);
        integrator.newton = self.newton;
        integrator.adaptive = self.adaptive;
        integrator
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsSection {
    pub gravity: bool,
    pub bending: bool,
    pub membrane: bool,
    /// Sub-element buckling: compressive membrane stress along the warp and the weft is
    /// capped at the Euler load of one element (`Fabric::with_compression_buckling`). Only
    /// where the tensile curves give no compression points of their own.
    pub compression_buckling: bool,
}

impl Default for PhysicsSection {
    fn default() -> Self {
        Self { gravity: true, bending: true, membrane: true, compression_buckling: false }
    }
}

/// Settings of the test rigs; each scene kind reads the ones it needs.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TestSection {
    /// Tensile: clamp strain reached at the end of the pull.
    pub max_strain: Option<f64>,
    /// Euler buckling: end approach as a fraction of the length.
    pub end_shortening: Option<f64>,
    /// Shear buckling: final shear angle, degrees.
    pub shear_angle_deg: Option<f64>,
    /// Clamp speed, m/s (Euler buckling: the speed at which the ends approach each other).
    pub speed: Option<f64>,
    /// Arc: curvature the grips roll the strip to, 1/m.
    pub curvature: Option<f64>,
    /// Largest random normal displacement added at the start, m.
    pub perturbation: Option<f64>,
    /// Cantilever and arc: length of the clamped band (and the arc's grip), m.
    pub clamp_length: Option<f64>,
    /// Shear buckling: how the moving grip travels (default `trellis`).
    pub shear_kinematics: Option<ShearKinematics>,
    /// Drape: radius of the clamped centre of the specimen, m (Cusick: the 18 cm discs
    /// that sandwich it; absent: nothing is clamped).
    pub clamp_radius: Option<f64>,
    /// Drape: diameter of the support disc for the drape coefficient, m.
    pub support_diameter: Option<f64>,
    /// Drape: size of a rectangular support (a table top), [x, y] m, for the drape coefficient.
    pub support_size: Option<[f64; 2]>,
    /// Swing: the free edge's sideways displacement at the start, m (the strip starts in the
    /// hanging chain's first mode).
    pub swing_amplitude: Option<f64>,
}

/// How the shear rig's moving grip travels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShearKinematics {
    /// Swings on the cross yarns, which keep their length (picture-frame shear): pure shear
    /// of the sheet, principal tension at 45° − γ/2 to the clamped edge.
    #[default]
    Trellis,
    /// Slides along the warp with the gap held: the cross yarns stretch by 1/cos γ − 1,
    /// which with stiff yarns removes the compression (and the wrinkles) past γ ≈ 2G/E.
    Simple,
}

impl SceneConfig {
    /// The scene's material: its fabric, with the sub-element buckling branch for its mesh
    /// where `physics.compression_buckling` asks for it.
    pub fn material(&self) -> Result<Fabric, FabricError> {
        let fabric = self.fabric.to_fabric()?;
        if self.physics.compression_buckling { fabric.with_compression_buckling(self.mesh.edge_length) } else { Ok(fabric) }
    }
}

/// Which step design a scene runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum SolverPath {
    /// The validated reference: the scene's own mesh and time step from start to end.
    #[default]
    Exact,
    /// Model no more of the path than the result needs: drapes settle coarse to fine at the
    /// fast path's time step (see the module documentation).
    Fast,
}

impl SolverPath {
    pub const ALL: [SolverPath; 2] = [SolverPath::Exact, SolverPath::Fast];

    /// The name as typed in scene files and CSV tables.
    pub fn name(self) -> &'static str {
        match self {
            SolverPath::Exact => "exact",
            SolverPath::Fast => "fast",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The `--set` override that selects this path (`solver.path=fast`, what `--fast` adds).
    pub fn setting(self) -> String {
        format!("solver.path={}", self.name())
    }
}

/// Settings of the fast path (`[solver.fast]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FastSettings {
    /// Time step of the levels that resolve the folds of a slowly loaded cloth, s.
    pub dt: f64,
    /// Time step of a cloth dropped onto props, s: shorter than `dt`, since long steps damp
    /// and change the fall's path, and with it the folds it lands in (docs/fast-path.md).
    pub drop_dt: f64,
    /// Time step of a garment, s: the longest at which every measured garment settled with
    /// its hem and drape coefficient as at the drop's step (docs/fast-path.md).
    pub garment_dt: f64,
    /// Largest edge of the coarsest level as a share of the fabric's bending length
    /// (B/w)^(1/3): coarse enough to be cheap, fine enough that folds, whose width scales
    /// with the bending length, span several elements.
    pub coarsest_edge_share: f64,
    /// Newton stops at a step under this share of the step's own integration error
    /// (`solver.newton.error_share`; the exact path's tolerance still holds at rest).
    pub error_share: f64,
    /// The same share for cloth in motion (drops not watched for settling, the swing),
    /// where it halves Newton's iterations (docs/fast-path.md, item 6).
    pub motion_error_share: f64,
    /// How many of the last Newton directions deflate a garment's CG solves where its
    /// incomplete factor is split (`solver.newton.recycled_directions`; docs/fast-path.md).
    pub recycled_directions: usize,
    /// The most CG iterations a garment's linear solve takes (`solver.newton.cg_max_iterations`,
    /// where that is lower it holds); docs/fast-path.md says why.
    pub cg_max_iterations: usize,
}

impl Default for FastSettings {
    fn default() -> Self {
        Self { dt: 0.064, drop_dt: 0.016, garment_dt: 0.024, coarsest_edge_share: 0.5, error_share: 0.1, motion_error_share: 0.3, recycled_directions: 8, cg_max_iterations: 400 }
    }
}

