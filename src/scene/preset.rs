//! Scene and fabric presets: TOML files under `presets/`, bundled into the binary, with
//! dotted-key overrides from the command line.
//!
//! A scene file names its fabric with `fabric.preset` (a bundled fabric name or a path
//! relative to the scene file); any other `fabric.*` key in the scene overrides the
//! fabric file. Overrides given with `--set KEY=VALUE` are applied to the scene before the
//! fabric is merged, so they win over both. Unknown keys are errors, so a typo fails loudly.

use crate::sim::{AdaptiveStep, Fabric, FabricError, IntegratorKind, NewtonSettings, Pattern, PiecewiseLinear};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A preset file bundled into the binary.
pub struct Bundled {
    pub name: &'static str,
    pub text: &'static str,
}

macro_rules! bundled {
    ($dir:literal; $($name:literal),* $(,)?) => {
        &[$(Bundled { name: $name, text: include_str!(concat!("../../presets/", $dir, $name, ".toml")) }),*]
    };
}

/// Bundled scenes; their file stems are the names users type.
pub const SCENES: &[Bundled] = bundled!("";
    "tensile-warp", "tensile-weft", "tensile-bias", "cantilever", "arc", "euler-buckling", "shear-buckling",
    "cusick-drape", "cusick-drape-30", "tablecloth");

/// Bundled fabrics.
pub const FABRICS: &[Bundled] = bundled!("fabrics/"; "wool", "cotton-shirting", "denim", "polyester", "silk", "wool-plain-fast", "wool-worsted", "wool-flannel", "cotton-poplin", "cotton-oxford", "cotton-lawn", "denim-14oz");

/// Why a preset could not be loaded. Every message names the file and, where it can, the key.
#[derive(Debug, Error)]
pub enum PresetError {
    #[error("cannot read {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{file}: not valid TOML: {message}")]
    Syntax { file: String, message: String },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("no bundled {kind} named '{name}' and no such file; bundled {kind}s: {available}")]
    Unknown { kind: &'static str, name: String, available: String },
    #[error("--set {text}: {message}")]
    BadOverride { text: String, message: String },
    #[error("{file}: {source}")]
    Fabric { file: String, source: FabricError },
}

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
}

/// A complete scene description, after the fabric file and overrides are merged.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    pub scene: SceneSection,
    pub fabric: FabricConfig,
    pub cloth: ClothSection,
    pub mesh: MeshSection,
    pub solver: SolverSection,
    #[serde(default)]
    pub physics: PhysicsSection,
    #[serde(default)]
    pub test: TestSection,
    /// Contact settings (props, friction, self-collision).
    #[serde(default)]
    pub contact: ContactSection,
    /// Rigid props: `[[props]]` tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub props: Vec<PropConfig>,
    /// Directory of the scene file, for relative asset paths (none for bundled scenes).
    #[serde(skip)]
    pub base_dir: Option<PathBuf>,
}

/// Contact with props and between folds of the cloth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSection {
    /// Distance the cloth keeps from a prop's surface, m.
    pub thickness: f64,
    /// Coulomb friction coefficient while sticking.
    pub friction_static: f64,
    /// Coulomb friction coefficient while sliding (at most the static one).
    pub friction_kinetic: f64,
    /// Cloth–cloth contact in folds. Off where the cloth cannot touch itself.
    pub self_collision: bool,
    /// Distance kept between cloth layers, m; absent: the smaller of the prop thickness
    /// and a fifth of the edge length.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_thickness: Option<f64>,
    /// Contact penalty stiffness as a multiple of m/Δt² per vertex (implicit solvers).
    pub stiffness: f64,
    /// Tangential speed below which friction sticks, m/s. Smoothed (IPC) friction lets a
    /// sticking cloth under a sideways pull F creep at slip_speed·F/(μN): keep it well
    /// below the speeds a scene should resolve, and below its settle speed.
    pub slip_speed: f64,
}

impl Default for ContactSection {
    fn default() -> Self {
        Self {
            thickness: 0.002,
            friction_static: 0.5,
            friction_kinetic: 0.4,
            self_collision: false,
            self_thickness: None,
            stiffness: 100.0,
            slip_speed: 1e-3,
        }
    }
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
}

fn default_settle_window() -> f64 {
    0.2
}

/// A fabric as written in a preset: SI units per unit width.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FabricConfig {
    /// Bundled fabric name or path of the fabric file this one starts from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    #[serde(default)]
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// Mass per unit area, kg/m².
    pub areal_density: f64,
    /// Thickness, m.
    pub thickness: f64,
    /// Warp tensile curve, [[strain, N/m], ...].
    pub tensile_warp: Vec<[f64; 2]>,
    /// Weft tensile curve, [[strain, N/m], ...].
    pub tensile_weft: Vec<[f64; 2]>,
    /// In-plane shear modulus, N/m.
    pub shear_modulus: f64,
    /// Poisson ratio ν_xy (weft contraction under a warp pull).
    pub poisson_warp: f64,
    /// Bending rigidity along the warp, N·m.
    pub bending_warp: f64,
    /// Bending rigidity along the weft, N·m.
    pub bending_weft: f64,
    /// Rigidity of a 45° strip, N·m; replaces eq. 3's middle term when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_bias: Option<f64>,
    /// Nonlinear bending: warp moment–curvature curve, [[1/m, N·m/m], ...]; its shape scales
    /// the rigidities with curvature. Absent: linear bending.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_curve: Option<Vec<[f64; 2]>>,
}

impl FabricConfig {
    /// Validated material for the simulator.
    pub fn to_fabric(&self) -> Result<Fabric, FabricError> {
        let curve = |key: &'static str, points: &[[f64; 2]]| {
            PiecewiseLinear::new_material(points).map_err(|source| FabricError::Curve { key, source })
        };
        let fabric = Fabric {
            areal_density: self.areal_density,
            thickness: self.thickness,
            tensile_warp: curve("tensile_warp", &self.tensile_warp)?,
            tensile_weft: curve("tensile_weft", &self.tensile_weft)?,
            shear_modulus: self.shear_modulus,
            poisson_warp: self.poisson_warp,
            bending_warp: self.bending_warp,
            bending_weft: self.bending_weft,
            bending_bias: self.bending_bias,
            bending_curve: match &self.bending_curve {
                Some(points) => Some(curve("bending_curve", points)?),
                None => None,
            },
        };
        fabric.validate()?;
        Ok(fabric)
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
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
}

#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsSection {
    pub gravity: bool,
    pub bending: bool,
    pub membrane: bool,
    /// Sub-element buckling: compressive membrane stress along the warp and the weft is
    /// capped at the Euler load of one element, π²B/ℓ² (ℓ the edge length), beyond which
    /// it grows at 1 % of the initial tensile slope. A triangle stands for cloth that would
    /// have buckled within it; without the cap coarse meshes lock in folds. Only where the
    /// tensile curves give no compression points of their own.
    pub compression_buckling: bool,
}

impl Default for PhysicsSection {
    fn default() -> Self {
        Self { gravity: true, bending: true, membrane: true, compression_buckling: false }
    }
}

impl FabricConfig {
    /// The tensile curves with the sub-element buckling branch in compression for elements
    /// of edge length `edge`, m (see [`PhysicsSection::compression_buckling`]).
    pub fn with_compression_buckling(&self, edge: f64) -> FabricConfig {
        let mut f = self.clone();
        let branch = |curve: &mut Vec<[f64; 2]>, rigidity: f64| {
            if curve.first().is_none_or(|p| p[0] < 0.0) || curve.len() < 2 || curve[1][0] <= 0.0 {
                return;
            }
            let slope = curve[1][1] / curve[1][0];
            let critical = std::f64::consts::PI.powi(2) * rigidity / (edge * edge);
            let knee = critical / slope;
            // Far enough that no cloth gets there: half its length.
            let far = 0.5f64.max(2.0 * knee);
            curve.insert(0, [-knee, -critical]);
            curve.insert(0, [-far, -critical - 0.01 * slope * (far - knee)]);
        };
        branch(&mut f.tensile_warp, self.bending_warp);
        branch(&mut f.tensile_weft, self.bending_weft);
        f
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

fn looks_like_path(spec: &str) -> bool {
    spec.contains('/') || spec.contains('\\') || spec.ends_with(".toml")
}

fn read_preset(kind: &'static str, spec: &str, list: &'static [Bundled], base: Option<&Path>) -> Result<(String, String), PresetError> {
    let bundled = list.iter().find(|b| b.name == spec);
    if let (Some(b), false) = (bundled, looks_like_path(spec)) {
        let dir = if kind == "fabric" { "fabrics/" } else { "" };
        return Ok((b.text.to_string(), format!("presets/{dir}{}.toml (bundled)", b.name)));
    }
    let mut path = PathBuf::from(spec);
    if let (true, Some(base)) = (path.is_relative(), base) {
        let candidate = base.join(&path);
        if candidate.exists() {
            path = candidate;
        }
    }
    if !path.exists() && !looks_like_path(spec) {
        let available = list.iter().map(|b| b.name).collect::<Vec<_>>().join(", ");
        return Err(PresetError::Unknown { kind, name: spec.to_string(), available });
    }
    let text = std::fs::read_to_string(&path).map_err(|source| PresetError::Io { path: path.display().to_string(), source })?;
    Ok((text, path.display().to_string()))
}

fn parse_table(text: &str, file: &str) -> Result<toml::Table, PresetError> {
    text.parse::<toml::Table>().map_err(|e| PresetError::Syntax { file: file.to_string(), message: e.to_string() })
}

/// Parses `KEY=VALUE`; VALUE is read as a TOML value (number, array, boolean, quoted
/// string) and otherwise taken as a bare string.
pub fn parse_override(text: &str) -> Result<(Vec<String>, toml::Value), PresetError> {
    let bad = |message: &str| PresetError::BadOverride { text: text.to_string(), message: message.to_string() };
    let (key, value) = text.split_once('=').ok_or_else(|| bad("expected KEY=VALUE, e.g. solver.dt=0.001"))?;
    let path: Vec<String> = key.trim().split('.').map(|s| s.trim().to_string()).collect();
    if path.iter().any(|p| p.is_empty()) {
        return Err(bad("the key has an empty part; write dotted keys like fabric.areal_density"));
    }
    let value = value.trim();
    let parsed = format!("v = {value}")
        .parse::<toml::Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(value.to_string()));
    Ok((path, parsed))
}

fn apply_override(table: &mut toml::Table, path: &[String], value: toml::Value) -> Result<(), String> {
    let (last, parents) = path.split_last().expect("non-empty key");
    let mut current = table;
    for part in parents {
        let entry = current.entry(part.clone()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        current = entry.as_table_mut().ok_or_else(|| format!("'{part}' is a value, not a table"))?;
    }
    current.insert(last.clone(), value);
    Ok(())
}

/// Loads a scene by bundled name or path, applies `overrides` (`KEY=VALUE`), merges its
/// fabric and checks everything.
pub fn load_scene(spec: &str, overrides: &[String]) -> Result<(SceneConfig, String), PresetError> {
    let (text, file) = read_preset("scene", spec, SCENES, None)?;
    let base = if looks_like_path(spec) || Path::new(spec).exists() { Path::new(spec).parent().map(Path::to_path_buf) } else { None };
    let mut table = parse_table(&text, &file)?;
    for o in overrides {
        let (path, value) = parse_override(o)?;
        apply_override(&mut table, &path, value).map_err(|m| PresetError::BadOverride { text: o.clone(), message: m })?;
    }
    let mut scene_fabric = table.remove("fabric").and_then(|v| v.as_table().cloned()).unwrap_or_default();
    let mut fabric = match scene_fabric.get("preset").and_then(|v| v.as_str()).map(str::to_string) {
        Some(name) => {
            let (fabric_text, fabric_file) = read_preset("fabric", &name, FABRICS, base.as_deref())?;
            let mut t = parse_table(&fabric_text, &fabric_file)?;
            crate::fabric::merge_scene_sheets(&mut t, &mut scene_fabric);
            expand_sheets(&mut t, &fabric_file)?;
            // The fabric file's own fields are checked here so errors name that file.
            t.clone()
                .try_into::<FabricConfig>()
                .map_err(|e| PresetError::Invalid { file: fabric_file.clone(), message: describe(&e) })?;
            t.insert("preset".into(), toml::Value::String(name));
            t
        }
        None => toml::Table::new(),
    };
    for (k, v) in scene_fabric {
        fabric.insert(k, v);
    }
    // A scene without a fabric file may carry its own sheets.
    expand_sheets(&mut fabric, &file)?;
    table.insert("fabric".into(), toml::Value::Table(fabric));
    let mut config: SceneConfig =
        table.try_into().map_err(|e: toml::de::Error| PresetError::Invalid { file: file.clone(), message: describe(&e) })?;
    config.base_dir = base;
    let fabric = if config.physics.compression_buckling {
        config.fabric.with_compression_buckling(config.mesh.edge_length)
    } else {
        config.fabric.clone()
    };
    fabric.to_fabric().map_err(|source| PresetError::Fabric { file: file.clone(), source })?;
    check_scene(&config).map_err(|message| PresetError::Invalid { file: file.clone(), message })?;
    Ok((config, file))
}

/// Turns a fabric table's measurement sheets (`[kes]`, `[fast]`, `[cantilever]`) into
/// fabric keys (crate::fabric); the defaults it had to use are reported on stderr.
fn expand_sheets(table: &mut toml::Table, file: &str) -> Result<(), PresetError> {
    let warnings =
        crate::fabric::expand_sheets(table).map_err(|e| PresetError::Invalid { file: file.to_string(), message: e.to_string() })?;
    for w in warnings {
        eprintln!("warning: {file}: {w}");
    }
    Ok(())
}

/// A toml error as one line, with the key path that failed.
fn describe(e: &toml::de::Error) -> String {
    e.message().trim().to_string()
}

fn check_scene(c: &SceneConfig) -> Result<(), String> {
    let positive = |key: &str, v: f64| {
        if v.is_finite() && v > 0.0 { Ok(()) } else { Err(format!("{key} must be a positive number, got {v}")) }
    };
    positive("scene.duration", c.scene.duration)?;
    positive("scene.settle_window", c.scene.settle_window)?;
    if let Some(v) = c.scene.settle_speed {
        positive("scene.settle_speed", v)?;
    }
    if let Some(v) = c.scene.gravity_ramp {
        positive("scene.gravity_ramp", v)?;
    }
    positive("solver.dt", c.solver.dt)?;
    positive("mesh.edge_length", c.mesh.edge_length)?;
    if !(c.solver.damping >= 0.0 && c.solver.damping.is_finite()) {
        return Err(format!("solver.damping must be zero or positive (1/s), got {}", c.solver.damping));
    }
    if let Some(a) = c.solver.adaptive.filter(|a| a.enabled) {
        positive("solver.adaptive.tolerance", a.tolerance)?;
        positive("solver.adaptive.dt_min", a.dt_min)?;
        if !(a.dt_min <= c.solver.dt && c.solver.dt <= a.dt_max) {
            return Err(format!(
                "solver.dt = {} s must lie between solver.adaptive.dt_min = {} s and dt_max = {} s",
                c.solver.dt, a.dt_min, a.dt_max
            ));
        }
        if c.solver.integrator.is_explicit() {
            return Err(format!(
                "solver.adaptive works with the implicit integrators; {} is stable only below a fixed \
                 limit: set solver.adaptive.enabled = false or solver.integrator = \"implicit-euler\"",
                c.solver.integrator
            ));
        }
    }
    if c.solver.dt > c.scene.duration {
        return Err(format!("solver.dt = {} s is longer than scene.duration = {} s", c.solver.dt, c.scene.duration));
    }
    if !c.cloth.warp_angle_deg.is_finite() {
        return Err("cloth.warp_angle_deg must be a finite angle in degrees".into());
    }
    let need = |key: &str, v: Option<f64>| -> Result<f64, String> {
        let v = v.ok_or_else(|| format!("{key} is required for a {:?} scene", c.scene.kind))?;
        positive(key, v)?;
        Ok(v)
    };
    match c.scene.kind {
        SceneKind::Tensile => {
            need("test.max_strain", c.test.max_strain)?;
            need("test.speed", c.test.speed)?;
        }
        SceneKind::EulerBuckling => {
            let s = need("test.end_shortening", c.test.end_shortening)?;
            if s >= 0.9 {
                return Err(format!("test.end_shortening = {s} leaves almost no strip; use a fraction below 0.9"));
            }
            need("test.speed", c.test.speed)?;
        }
        SceneKind::ShearBuckling => {
            let a = need("test.shear_angle_deg", c.test.shear_angle_deg)?;
            if a >= 60.0 {
                return Err(format!("test.shear_angle_deg = {a} is beyond any fabric's locking angle; use less than 60"));
            }
            need("test.speed", c.test.speed)?;
        }
        SceneKind::Arc => {
            need("test.curvature", c.test.curvature)?;
        }
        SceneKind::Cantilever => {}
        SceneKind::Drape => {
            if c.props.is_empty() {
                return Err("a drape scene needs at least one [[props]] table to drape over".into());
            }
            if c.test.support_diameter.is_none() && c.test.support_size.is_none() {
                return Err("a drape scene needs test.support_diameter (a pedestal) or test.support_size (a table top), m".into());
            }
            if let Some(r) = c.test.clamp_radius {
                positive("test.clamp_radius", r)?;
            }
        }
    }
    if c.contact.friction_kinetic > c.contact.friction_static || c.contact.friction_kinetic < 0.0 {
        return Err(format!(
            "contact.friction_kinetic = {} must lie between 0 and contact.friction_static = {}",
            c.contact.friction_kinetic, c.contact.friction_static
        ));
    }
    positive("contact.thickness", c.contact.thickness)?;
    if c.scene.kind == SceneKind::Drape && c.cloth.diameter > 0.0 {
        return positive("cloth.diameter", c.cloth.diameter);
    }
    // Every other scene is a rectangular cloth.
    positive("cloth.length", c.cloth.length)?;
    positive("cloth.width", c.cloth.width)?;
    Ok(())
}

/// The description line of every bundled scene, for `rosette presets`.
pub fn scene_descriptions() -> Vec<(&'static str, String)> {
    SCENES
        .iter()
        .map(|b| {
            let description = parse_table(b.text, b.name)
                .ok()
                .and_then(|t| t.get("scene")?.get("description")?.as_str().map(str::to_string))
                .unwrap_or_default();
            (b.name, description)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bundled_scene_and_fabric_loads() {
        for s in SCENES {
            load_scene(s.name, &[]).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        }
        for f in FABRICS {
            let mut t = parse_table(f.text, f.name).unwrap();
            expand_sheets(&mut t, f.name).unwrap_or_else(|e| panic!("{}: {e}", f.name));
            let c: FabricConfig = t.try_into().unwrap_or_else(|e| panic!("{}: {e}", f.name));
            c.to_fabric().unwrap_or_else(|e| panic!("{}: {e}", f.name));
        }
    }

    #[test]
    fn overrides_parse_numbers_arrays_and_bare_strings() {
        let (config, _) = load_scene(
            "tensile-warp",
            &[
                "fabric.areal_density=0.2".into(),
                "solver.integrator=bdf2".into(),
                "fabric.tensile_warp=[[0,0],[0.01,12.5]]".into(),
                "fabric.preset=denim".into(),
            ],
        )
        .unwrap();
        assert_eq!(config.fabric.areal_density, 0.2);
        assert_eq!(config.solver.integrator, IntegratorKind::Bdf2);
        assert_eq!(config.fabric.tensile_warp, vec![[0.0, 0.0], [0.01, 12.5]]);
        assert_eq!(config.fabric.preset.as_deref(), Some("denim"));
        assert!(config.fabric.bending_warp > 5e-5, "denim's rigidity came with the preset switch");
    }

    #[test]
    fn bad_input_names_the_key_and_the_fix() {
        let err = load_scene("tensile-warp", &["fabric.areal_density=-1".into()]).unwrap_err().to_string();
        assert!(err.contains("fabric.areal_density") && err.contains("positive"), "{err}");
        let err = load_scene("tensile-warp", &["fabric.densty=1".into()]).unwrap_err().to_string();
        assert!(err.contains("densty"), "{err}");
        let err = load_scene("tensile-warp", &["fabric.tensile_warp=[[0,0],[0.02,5],[0.01,9]]".into()]).unwrap_err().to_string();
        assert!(err.contains("tensile_warp") && err.contains("sort"), "{err}");
        let err = load_scene("tensile-warp", &["solver.integrator=rk4".into()]).unwrap_err().to_string();
        assert!(err.contains("rk4") && err.contains("implicit-euler"), "{err}");
        let err = load_scene("no-such-scene", &[]).unwrap_err().to_string();
        assert!(err.contains("tensile-warp"), "lists what exists: {err}");
        let err = load_scene("tensile-warp", &["solver.dt".into()]).unwrap_err().to_string();
        assert!(err.contains("KEY=VALUE"), "{err}");
    }
}
