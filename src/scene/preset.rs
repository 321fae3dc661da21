//! Scene and fabric presets: TOML files under `presets/`, bundled into the binary, with
//! dotted-key overrides from the command line.
//!
//! A scene file names its fabric with `fabric.preset` (a bundled fabric name or a path
//! relative to the scene file); any other `fabric.*` key in the scene overrides the
//! fabric file. Overrides given with `--set KEY=VALUE` are applied to the scene before the
//! fabric is merged, so they win over both. Unknown keys are errors, so a typo fails loudly.

use crate::io::read::{FileKind, parse_toml, read_text};
use crate::sim::contact::ContactSettings;
use crate::sim::{AdaptiveStep, Fabric, FabricError, FabricPoints, IntegratorKind, NewtonSettings, Pattern};
use serde::de::{DeserializeSeed, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::path::{Path, PathBuf};
use thiserror::Error;

pub use super::load::{RunFlags, load_scene, load_scene_with};

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
    "cusick-drape", "cusick-drape-30", "tablecloth", "sphere-drop",
    "skirt-circle", "skirt-gored-straight", "skirt-gored-bias", "shift-dress", "swing");

/// Bundled fabrics.
pub const FABRICS: &[Bundled] = bundled!("fabrics/"; "wool", "cotton-shirting", "denim", "polyester", "silk", "wool-plain-fast", "wool-worsted", "wool-flannel", "cotton-poplin", "cotton-oxford", "cotton-lawn", "denim-14oz", "11oz-black-denim", "royal-target", "white-dots-on-blk", "pink-ribbon-brown");

/// Why a preset could not be loaded. Every message names the file and, where it can, the key.
#[derive(Debug, Error)]
pub enum PresetError {
    #[error("{key}: {source}")]
    Read { key: &'static str, source: crate::io::read::ReadError },
    #[error("{file}: {message}")]
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
    /// Pattern pieces sewn into a garment on a dress form (`[garment]`, docs/garments.md).
    Garment,
    /// A strip hung from its top edge, released in the hanging chain's first mode; its
    /// period against the chain's (docs/references.md §10).
    Swing,
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

pub(super) fn looks_like_path(spec: &str) -> bool {
    spec.contains('/') || spec.contains('\\') || spec.ends_with(".toml")
}

/// Reads a bundled preset by name or a file by path (relative to `base` where that holds
/// it) through the bounded reader, and parses it; returns the table and the name errors
/// give the file.
pub(super) fn read_table(kind: &'static str, spec: &str, list: &'static [Bundled], base: Option<&Path>) -> Result<(toml::Table, String), PresetError> {
    let bundled = list.iter().find(|b| b.name == spec);
    if let (Some(b), false) = (bundled, looks_like_path(spec)) {
        let dir = if kind == "fabric" { "fabrics/" } else { "" };
        let file = format!("presets/{dir}{}.toml (bundled)", b.name);
        return Ok((parse_table(b.text, &file)?, file));
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
    let file = path.display().to_string();
    if kind == "fabric" && crate::fabric::is_arcsim_file(spec) {
        // An ARCSim material stands for a fabric file whose `[arcsim]` section reads it.
        read_text(&path, FileKind::Arcsim).map_err(|source| PresetError::Read { key: "fabric.preset", source })?;
        return Ok((arcsim_fabric_table(&file), file));
    }
    let (file_kind, key) = if kind == "fabric" { (FileKind::Fabric, "fabric.preset") } else { (FileKind::Scene, "scene") };
    let text = read_text(&path, file_kind).map_err(|source| PresetError::Read { key, source })?;
    let table = parse_toml(&text, Some(&path), file_kind).map_err(|message| PresetError::Syntax { file: file.clone(), message })?;
    if kind == "fabric" {
        refuse_fabric_preset(&table).map_err(|message| PresetError::Invalid { file: file.clone(), message })?;
    }
    Ok((table, file))
}

/// The fabric table an ARCSim material file `file` (`….json`) stands for: named after the
/// file, its `[arcsim]` section reading it.
pub fn arcsim_fabric_table(file: &str) -> toml::Table {
    let stem = Path::new(file).file_stem().map_or_else(|| file.to_string(), |s| s.to_string_lossy().into_owned());
    let mut table = toml::Table::new();
    table.insert("name".into(), toml::Value::String(format!("{stem} (ARCSim material)")));
    table.insert("description".into(), toml::Value::String(format!("ARCSim material {file}, imported by Rosette's projection")));
    let mut section = toml::Table::new();
    section.insert("data".into(), toml::Value::String(file.into()));
    table.insert("arcsim".into(), toml::Value::Table(section));
    table
}

/// A fabric file stands alone: `preset` (a fabric to start from) is read only in a scene's
/// `[fabric]` table, so one in a fabric file would be silently ignored.
pub fn refuse_fabric_preset(table: &toml::Table) -> Result<(), String> {
    match table.get("preset") {
        None => Ok(()),
        Some(preset) => Err(format!(
            "preset = {preset}: a fabric file cannot start from another fabric (only a scene's [fabric] table can); \
             remove the key and give the fabric's values, or name {preset} in the scene's fabric.preset and set the keys that differ under [fabric]"
        )),
    }
}

pub(super) fn parse_table(text: &str, file: &str) -> Result<toml::Table, PresetError> {
    parse_toml(text, None, FileKind::Scene).map_err(|message| PresetError::Syntax { file: file.to_string(), message })
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

pub(super) fn apply_override(table: &mut toml::Table, path: &[String], value: toml::Value) -> Result<(), String> {
    let (last, parents) = path.split_last().expect("non-empty key");
    let mut current = table;
    for part in parents {
        let entry = current.entry(part.clone()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        current = entry.as_table_mut().ok_or_else(|| format!("'{part}' is a value, not a table"))?;
    }
    current.insert(last.clone(), value);
    Ok(())
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
            crate::fabric::expand_sheets(&mut t).unwrap_or_else(|e| panic!("{}: {e}", f.name));
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
