//! Scene and fabric presets: TOML files under `presets/`, bundled into the binary, with
//! dotted-key overrides from the command line.
//!
//! A scene file names its fabric with `fabric.preset` (a bundled fabric name or a path
//! relative to the scene file); any other `fabric.*` key in the scene overrides the
//! fabric file. Overrides given with `--set KEY=VALUE` are applied to the scene before the
//! fabric is merged, so they win over both. Unknown keys are errors, so a typo fails loudly.

use crate::sim::contact::ContactSettings;
use crate::sim::{AdaptiveStep, Fabric, FabricError, FabricPoints, IntegratorKind, NewtonSettings, Pattern};
use serde::de::{DeserializeSeed, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
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
    "cusick-drape", "cusick-drape-30", "tablecloth", "sphere-drop");

/// Bundled fabrics.
pub const FABRICS: &[Bundled] = bundled!("fabrics/"; "wool", "cotton-shirting", "denim", "polyester", "silk", "wool-plain-fast", "wool-worsted", "wool-flannel", "cotton-poplin", "cotton-oxford", "cotton-lawn", "denim-14oz", "11oz-black-denim", "royal-target", "white-dots-on-blk", "pink-ribbon-brown");

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
    pub contact: ContactSettings,
    /// Rigid props: `[[props]]` tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub props: Vec<PropConfig>,
    /// Directory of the scene file, for relative asset paths (none for bundled scenes).
    #[serde(skip)]
    pub base_dir: Option<PathBuf>,
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

/// A fabric as a file gives it: the simulator's properties (SI units per unit width, the
/// curves as points) with its name, and in a scene the fabric file it starts from.
#[derive(Debug, Clone)]
pub struct FabricConfig {
    /// Bundled fabric name or path of the fabric file this one starts from.
    pub preset: Option<String>,
    pub name: String,
    pub description: String,
    /// The material's properties, each a key of the fabric table.
    pub properties: FabricPoints,
}

impl FabricConfig {
    /// Validated material for the simulator.
    pub fn to_fabric(&self) -> Result<Fabric, FabricError> {
        self.properties.to_fabric()
    }
}

/// Written as one table: the names beside the properties.
impl Serialize for FabricConfig {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Table<'a> {
            #[serde(skip_serializing_if = "Option::is_none")]
            preset: &'a Option<String>,
            name: &'a str,
            description: &'a str,
            #[serde(flatten)]
            properties: &'a FabricPoints,
        }
        Table { preset: &self.preset, name: &self.name, description: &self.description, properties: &self.properties }.serialize(serializer)
    }
}

/// Read as one table: the three names are taken out as the keys go by and every other key
/// goes to the properties, so that an error there keeps its key's path (serde's `flatten`
/// would buffer the table and lose it, and cannot refuse unknown keys).
impl<'de> Deserialize<'de> for FabricConfig {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Fields;
        impl<'de> Visitor<'de> for Fields {
            type Value = FabricConfig;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a table of fabric properties")
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<FabricConfig, A::Error> {
                let mut names = Names::default();
                let properties = FabricPoints::deserialize(serde::de::value::MapAccessDeserializer::new(WithoutNames { map, names: &mut names }))?;
                Ok(FabricConfig { preset: names.preset, name: names.name.unwrap_or_default(), description: names.description.unwrap_or_default(), properties })
            }
        }
        #[derive(Default)]
        struct Names {
            preset: Option<String>,
            name: Option<String>,
            description: Option<String>,
        }
        struct WithoutNames<'n, A> {
            map: A,
            names: &'n mut Names,
        }
        impl<'de, A: MapAccess<'de>> MapAccess<'de> for WithoutNames<'_, A> {
            type Error = A::Error;
            fn next_key_seed<K: DeserializeSeed<'de>>(&mut self, seed: K) -> Result<Option<K::Value>, A::Error> {
                while let Some(key) = self.map.next_key::<String>()? {
                    match key.as_str() {
                        "preset" => self.names.preset = Some(self.map.next_value()?),
                        "name" => self.names.name = Some(self.map.next_value()?),
                        "description" => self.names.description = Some(self.map.next_value()?),
                        _ => return seed.deserialize(IntoDeserializer::<A::Error>::into_deserializer(key)).map(Some),
                    }
                }
                Ok(None)
            }
            fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
                self.map.next_value_seed(seed)
            }
        }
        deserializer.deserialize_map(Fields)
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
    /// The exact path (the validated reference) or the fast one.
    #[serde(default)]
    pub path: super::levels::SolverPath,
    /// The fast path's settings.
    #[serde(default)]
    pub fast: super::levels::FastSettings,
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

/// Where each value of a scene came from, so that an error names the file or the `--set`
/// that gave the bad value.
struct Sources {
    scene_file: String,
    /// The fabric file named by `fabric.preset`, and the keys the scene's own `[fabric]`
    /// table gives (those are the scene file's).
    fabric_file: Option<String>,
    scene_fabric_keys: Vec<String>,
    /// Each `--set` as typed, with its key.
    overrides: Vec<(Vec<String>, String)>,
    /// The scene and fabric files' values before the overrides, to quote as an example.
    original: toml::Table,
}

impl Sources {
    /// The file or `--set` a bad value at `key` (dotted, array indices dropped) came from.
    fn blame(&self, key: &[String]) -> String {
        let overlaps = |path: &[String]| path.iter().zip(key).all(|(a, b)| a == b);
        if let Some((_, text)) = self.overrides.iter().rev().find(|(path, _)| overlaps(path)) {
            return format!("--set {text}");
        }
        match (&self.fabric_file, key) {
            (Some(fabric_file), [section, field, ..]) if section == "fabric" && !self.scene_fabric_keys.contains(field) => fabric_file.clone(),
            _ => self.scene_file.clone(),
        }
    }

    /// The value the files give at `key`, as TOML, if they give one.
    fn original(&self, key: &[String]) -> Option<String> {
        let (last, parents) = key.split_last()?;
        let mut table = &self.original;
        for part in parents {
            table = table.get(part)?.as_table()?;
        }
        table.get(last).map(|v| v.to_string())
    }

    fn invalid(&self, key: &[String], message: String) -> PresetError {
        PresetError::Invalid { file: self.blame(key), message }
    }
}

/// A dotted key split into its parts, array indices (`props[0]`) dropped.
fn key_parts(key: &str) -> Vec<String> {
    key.split('.').map(|part| part.split('[').next().unwrap_or("").to_string()).filter(|part| !part.is_empty()).collect()
}

/// serde's message for a value of the wrong type or length, in the words of a scene file,
/// led by the key.
fn type_error(key: &str, message: &str, example: Option<String>) -> String {
    let words = |s: &str| {
        s.replace("f64", "a number")
            .replace("floating point", "the number")
            .replace("u64", "a whole number")
            .replace("usize", "a whole number")
            .replace("integer", "the whole number")
            .replace("string", "the text")
            .replace("sequence", "an array")
    };
    let message = message.trim();
    // serde's "invalid type: X, expected Y" (and value, length) read as "must be Y, got X".
    let reworded = ["invalid type: ", "invalid value: ", "invalid length "].iter().find_map(|lead| {
        let (got, expected) = message.strip_prefix(lead)?.split_once(", expected ")?;
        let got = if *lead == "invalid length " { format!("{got} values") } else { words(got) };
        Some(format!("must be {}, got {got}", words(expected)))
    });
    let text = match (reworded, key.is_empty()) {
        (Some(text), false) => format!("{key} {text}"),
        (None, false) => format!("{key}: {message}"),
        (Some(text), true) => text,
        (None, true) => message.to_string(),
    };
    match example {
        Some(example) if !key.is_empty() => format!("{text}; the file has {key} = {example}"),
        _ => text,
    }
}

/// Deserialises `table` as a `T`, an error naming the key that failed (by its path, which
/// plain serde leaves out).
fn deserialize_named<T: serde::de::DeserializeOwned>(table: toml::Table) -> Result<T, (Vec<String>, String, String)> {
    serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
        let path = e.path().to_string();
        let key = if path == "." { String::new() } else { path };
        (key_parts(&key), key, e.into_inner().message().to_string())
    })
}

/// Loads a scene by bundled name or path, applies `overrides` (`KEY=VALUE`), merges its
/// fabric and checks everything: a value out of range is refused here, with the file or
/// the `--set` that gave it, its key and how to fix it.
pub fn load_scene(spec: &str, overrides: &[String]) -> Result<(SceneConfig, String), PresetError> {
    let (text, file) = read_preset("scene", spec, SCENES, None)?;
    let base = if looks_like_path(spec) || Path::new(spec).exists() { Path::new(spec).parent().map(Path::to_path_buf) } else { None };
    let mut table = parse_table(&text, &file)?;
    let scene_fabric_keys = table.get("fabric").and_then(|v| v.as_table()).map(|t| t.keys().cloned().collect()).unwrap_or_default();
    let mut sources = Sources { scene_file: file.clone(), fabric_file: None, scene_fabric_keys, overrides: Vec::new(), original: toml::Table::new() };
    let mut fabric_table = None;
    // The fabric file named in the scene file, for the original values.
    if let Some(name) = table.get("fabric").and_then(|f| f.get("preset")).and_then(|v| v.as_str()) {
        let (fabric_text, fabric_file) = read_preset("fabric", name, FABRICS, base.as_deref())?;
        fabric_table = Some((name.to_string(), parse_table(&fabric_text, &fabric_file)?, fabric_file));
    }
    sources.original = merge_fabric(table.clone(), fabric_table.as_ref().map(|f| f.1.clone()));
    for o in overrides {
        let (path, value) = parse_override(o)?;
        apply_override(&mut table, &path, value).map_err(|m| PresetError::BadOverride { text: o.clone(), message: m })?;
        sources.overrides.push((path, o.clone()));
    }
    let preset = table.get("fabric").and_then(|f| f.get("preset"));
    if let Some(preset) = preset {
        let name = preset.as_str().ok_or_else(|| sources.invalid(&key_parts("fabric.preset"), format!("fabric.preset must be a fabric name or file in quotes, got {preset}")))?;
        if fabric_table.as_ref().is_none_or(|f| f.0 != name) {
            let (fabric_text, fabric_file) = read_preset("fabric", name, FABRICS, base.as_deref())?;
            fabric_table = Some((name.to_string(), parse_table(&fabric_text, &fabric_file)?, fabric_file));
        }
    } else {
        fabric_table = None;
    }
    if let Some((_, t, fabric_file)) = &mut fabric_table {
        // Sheet fields the scene or a `--set` changes are converted with the file's sheet.
        if let Some(scene_fabric) = table.get_mut("fabric").and_then(|v| v.as_table_mut()) {
            crate::fabric::merge_scene_sheets(t, scene_fabric);
        }
        expand_sheets(t, fabric_file)?;
        // The fabric file's own fields are checked here so errors name that file.
        deserialize_named::<FabricConfig>(t.clone()).map_err(|(_, key, message)| {
            let key = if key.is_empty() { key } else { format!("fabric.{key}") };
            PresetError::Invalid { file: fabric_file.clone(), message: type_error(&key, &message, None) }
        })?;
        sources.fabric_file = Some(fabric_file.clone());
    }
    let mut table = merge_fabric(table, fabric_table.map(|f| f.1));
    // A scene without a fabric file may carry its own sheets.
    if let Some(fabric) = table.get_mut("fabric").and_then(|v| v.as_table_mut()) {
        expand_sheets(fabric, &file)?;
    }
    let mut config: SceneConfig = deserialize_named(table).map_err(|(parts, key, message)| {
        let example = sources.original(&parts);
        sources.invalid(&parts, type_error(&key, &message, example))
    })?;
    config.base_dir = base;
    super::validate::check_scene(&config).map_err(|e| sources.invalid(&key_parts(&e.key), e.message))?;
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

/// The scene's table with its `[fabric]` keys laid over the fabric file's.
fn merge_fabric(mut table: toml::Table, fabric_file: Option<toml::Table>) -> toml::Table {
    let scene_fabric = table.remove("fabric").and_then(|v| v.as_table().cloned()).unwrap_or_default();
    let mut fabric = fabric_file.unwrap_or_default();
    let preset = scene_fabric.get("preset").cloned();
    for (k, v) in scene_fabric {
        fabric.insert(k, v);
    }
    if let Some(p) = preset {
        fabric.insert("preset".into(), p);
    }
    table.insert("fabric".into(), toml::Value::Table(fabric));
    table
}

impl SceneConfig {
    /// The scene's material: its fabric, with the sub-element buckling branch for its mesh
    /// where `physics.compression_buckling` asks for it.
    pub fn material(&self) -> Result<Fabric, FabricError> {
        let fabric = self.fabric.to_fabric()?;
        if self.physics.compression_buckling { fabric.with_compression_buckling(self.mesh.edge_length) } else { Ok(fabric) }
    }
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
        assert_eq!(config.fabric.properties.areal_density, 0.2);
        assert_eq!(config.solver.integrator, IntegratorKind::Bdf2);
        assert_eq!(config.fabric.properties.tensile_warp, vec![[0.0, 0.0], [0.01, 12.5]]);
        assert_eq!(config.fabric.preset.as_deref(), Some("denim"));
        assert!(config.fabric.properties.bending_warp > 5e-5, "denim's rigidity came with the preset switch");
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
