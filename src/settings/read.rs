//! The one reader of "a bundled name or a file" for scenes and fabrics, and the `--set`
//! overrides: every refusal names the file and, where it can, the key.

use super::registry::{Bundled, FABRICS, SCENES};
use crate::io::read::{FileKind, parse_toml, read_text};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a preset could not be loaded. Every message names the file and, where it can, the key.
#[derive(Debug, Error)]
pub enum PresetError {
    #[error("{}{source}", .key.map_or(String::new(), |k| format!("{k}: ")))]
    Read { key: Option<&'static str>, source: crate::io::read::ReadError },
    #[error("{file}: {message}")]
    Syntax { file: String, message: String },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
    #[error("no bundled {kind} named '{name}' and no such file; bundled {kind}s: {available}")]
    Unknown { kind: &'static str, name: String, available: String },
    #[error("--set {text}: {message}")]
    BadOverride { text: String, message: String },
}

/// Whether `spec` reads as a path rather than a bundled name.
pub fn looks_like_path(spec: &str) -> bool {
    spec.contains('/') || spec.contains('\\') || spec.ends_with(".toml")
}

/// Whether `spec` names an ARCSim material file (`….json`) rather than a fabric file.
pub fn is_arcsim_file(spec: &str) -> bool {
    Path::new(spec).extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Whether `spec` names a pattern CAD file (`….dxf`).
pub fn is_dxf_file(spec: &str) -> bool {
    Path::new(spec).extension().is_some_and(|e| e.eq_ignore_ascii_case("dxf"))
}

/// Whether the scene `spec` names a sewing pattern (GarmentCode's `….json`, pattern CAD's
/// `….dxf`), which stands for the scene `rosette pattern import` writes for it.
pub fn is_pattern_spec(spec: &str) -> bool {
    is_arcsim_file(spec) || is_dxf_file(spec)
}

/// The seams file that goes with a pattern file: `NAME.seams.toml` beside `NAME.dxf`.
pub fn seams_beside(pattern: &Path) -> PathBuf {
    let stem = pattern.file_stem().map_or_else(|| "pattern".into(), |s| s.to_string_lossy().into_owned());
    pattern.with_file_name(format!("{stem}.seams.toml"))
}

/// A scene table with the bundled base it names (`base = "garment"`) laid under it: the
/// base's keys, then the scene's over them (tables merged key by key, any other value
/// replaced). Returns the merged table and the base's own table; a scene without `base` is
/// returned as it is.
pub fn with_base(mut table: toml::Table, file: &str) -> Result<(toml::Table, Option<toml::Table>), PresetError> {
    let Some(base) = table.remove("base") else { return Ok((table, None)) };
    let names = || super::registry::BASES.iter().map(|b| format!("\"{}\"", b.name)).collect::<Vec<_>>().join(", ");
    let invalid = |message: String| PresetError::Invalid { file: file.to_string(), message };
    let name = base.as_str().ok_or_else(|| invalid(format!("base must name bundled settings in quotes ({}), got {base}", names())))?;
    let bundled = super::registry::BASES
        .iter()
        .find(|b| b.name == name)
        .ok_or_else(|| invalid(format!("base = \"{name}\": no bundled settings of that name; the bases are {}", names())))?;
    let base = parse_table(bundled.text, &format!("presets/bases/{name}.toml (bundled)"))?;
    let mut merged = base.clone();
    lay_over(&mut merged, table);
    Ok((merged, Some(base)))
}

/// Lays `over`'s keys over `under`: tables merged key by key, other values replaced.
fn lay_over(under: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (under.get_mut(&key), value) {
            (Some(toml::Value::Table(below)), toml::Value::Table(above)) => lay_over(below, above),
            (_, value) => {
                under.insert(key, value);
            }
        }
    }
}

/// What a name or a path stands for: a scene or a fabric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PresetKind {
    Scene,
    Fabric,
}

impl PresetKind {
    fn name(self) -> &'static str {
        match self {
            PresetKind::Scene => "scene",
            PresetKind::Fabric => "fabric",
        }
    }

    fn bundled(self) -> &'static [Bundled] {
        match self {
            PresetKind::Scene => SCENES,
            PresetKind::Fabric => FABRICS,
        }
    }

    fn file_kind(self) -> FileKind {
        match self {
            PresetKind::Scene => FileKind::Scene,
            PresetKind::Fabric => FileKind::Fabric,
        }
    }
}

/// Reads a bundled preset by name or a file by path (relative to `base` where that holds
/// it) through the bounded reader, and parses it; returns the table and the name errors
/// give the file. `key` is the key that named the file, for a read error (`fabric.preset`).
/// A fabric may be an ARCSim material file, which stands for a fabric table whose
/// `[arcsim]` section reads it.
pub fn read_preset(kind: PresetKind, spec: &str, base: Option<&Path>, key: Option<&'static str>) -> Result<(toml::Table, String), PresetError> {
    let list = kind.bundled();
    let bundled = list.iter().find(|b| b.name == spec);
    if let (Some(b), false) = (bundled, looks_like_path(spec)) {
        let dir = if kind == PresetKind::Fabric { "fabrics/" } else { "" };
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
    let json = is_arcsim_file(spec);
    let arcsim = kind == PresetKind::Fabric && json;
    if !path.exists() && !looks_like_path(spec) && !json && !is_dxf_file(spec) {
        let available = list.iter().map(|b| b.name).collect::<Vec<_>>().join(", ");
        return Err(PresetError::Unknown { kind: kind.name(), name: spec.to_string(), available });
    }
    let file = path.display().to_string();
    if arcsim {
        read_text(&path, FileKind::Arcsim).map_err(|source| PresetError::Read { key, source })?;
        return Ok((arcsim_fabric_table(&file), file));
    }
    if kind == PresetKind::Scene && json {
        return garment_pattern_table(&path, &file, key).map(|table| (table, file));
    }
    if kind == PresetKind::Scene && is_dxf_file(spec) {
        return dxf_pattern_table(&path, &file, key).map(|table| (table, file));
    }
    let text = read_text(&path, kind.file_kind()).map_err(|source| PresetError::Read { key, source })?;
    let mut table = parse_toml(&text, Some(&path), kind.file_kind()).map_err(|message| PresetError::Syntax { file: file.clone(), message })?;
    if kind == PresetKind::Fabric {
        refuse_fabric_preset(&table).map_err(|message| PresetError::Invalid { file: file.clone(), message })?;
        // A texture beside the fabric file is found from wherever the fabric is used.
        if let Some(dir) = path.parent() {
            crate::appearance::resolve_in_table(&mut table, dir);
        }
    }
    Ok((table, file))
}

/// The scene table a GarmentCode pattern specification (`….json`) stands for: the scene
/// `rosette pattern import` would write for it with its defaults (docs/garments.md).
fn garment_pattern_table(path: &Path, file: &str, key: Option<&'static str>) -> Result<toml::Table, PresetError> {
    use crate::garment::garmentcode::{ImportOptions, ORIGIN, import};
    let text = read_text(path, FileKind::Pattern).map_err(|source| PresetError::Read { key, source })?;
    let imported = import(&text, file, &ImportOptions::default()).map_err(|e| pattern_invalid(file, e))?;
    imported_table(&imported, &ORIGIN, path, file)
}

/// The scene table a pattern CAD file (`….dxf`) stands for: the scene `rosette pattern
/// import` would write for it with its defaults, sewn by the seams file beside it
/// (`NAME.seams.toml`) where there is one.
fn dxf_pattern_table(path: &Path, file: &str, key: Option<&'static str>) -> Result<toml::Table, PresetError> {
    use crate::garment::dxf::import::{ImportOptions, ORIGIN, import};
    let bytes = crate::io::read::read_bytes(path, FileKind::Dxf).map_err(|source| PresetError::Read { key, source })?;
    let seams_path = seams_beside(path);
    let seams = if seams_path.is_file() {
        let shown = seams_path.display().to_string();
        let text = read_text(&seams_path, FileKind::Seams).map_err(|source| PresetError::Read { key, source })?;
        let parsed = crate::garment::dxf::seams::parse(&text, &shown).map_err(|e| pattern_invalid(&shown, e))?;
        Some((parsed, shown))
    } else {
        None
    };
    let imported = import(&bytes, file, &ImportOptions::default(), seams.as_ref().map(|(f, s)| (f, s.as_str()))).map_err(|e| pattern_invalid(file, e))?;
    imported_table(&imported, &ORIGIN, path, file)
}

/// A reader's message as a refusal of `file`: the reader starts it with the file's name,
/// which `Invalid` gives.
fn pattern_invalid(file: &str, e: crate::garment::GarmentError) -> PresetError {
    let message = e.message.strip_prefix(&format!("{file}: ")).map_or(e.message.clone(), str::to_string);
    PresetError::Invalid { file: file.to_string(), message }
}

/// The scene table of an imported pattern, in the default fabric.
fn imported_table(imported: &crate::garment::import::Imported, origin: &crate::garment::import::Origin, path: &Path, file: &str) -> Result<toml::Table, PresetError> {
    let name = path.file_stem().map_or_else(|| "pattern".into(), |s| s.to_string_lossy().into_owned());
    let scene = crate::garment::import::scene_text(imported, origin, file, &name, crate::garment::import::DEFAULT_FABRIC).map_err(|e| pattern_invalid(file, e))?;
    parse_table(&scene, file)
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

pub fn parse_table(text: &str, file: &str) -> Result<toml::Table, PresetError> {
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

/// Sets `value` at the dotted `path` in `table`, creating tables on the way. A part written
/// `name[i]` reaches entry i of the list `name` (`garment.panels[1].grain_deg=45`: the
/// second `[[garment.panels]]`), which must exist.
pub fn apply_override(table: &mut toml::Table, path: &[String], value: toml::Value) -> Result<(), String> {
    let (last, parents) = path.split_last().expect("non-empty key");
    let mut current = table;
    for part in parents {
        current = match indexed(part)? {
            Some((name, i)) => entry_at(current, name, i)?.as_table_mut().ok_or_else(|| format!("'{part}' is a value, not a table"))?,
            None => {
                let entry = current.entry(part.clone()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
                entry.as_table_mut().ok_or_else(|| format!("'{part}' is a value, not a table"))?
            }
        };
    }
    match indexed(last)? {
        Some((name, i)) => *entry_at(current, name, i)? = value,
        None => {
            current.insert(last.clone(), value);
        }
    }
    Ok(())
}

/// `name[i]` as (name, i); None for a plain key.
fn indexed(part: &str) -> Result<Option<(&str, usize)>, String> {
    let Some((name, rest)) = part.split_once('[') else { return Ok(None) };
    let index = rest.strip_suffix(']').and_then(|i| i.trim().parse().ok()).filter(|_| !name.is_empty());
    index.map(|i| Some((name, i))).ok_or_else(|| format!("'{part}': write a list's entry as name[index], counting from 0, e.g. panels[1]"))
}

/// Entry `i` of the list `name` in `table`.
fn entry_at<'a>(table: &'a mut toml::Table, name: &str, i: usize) -> Result<&'a mut toml::Value, String> {
    let list = table.get_mut(name).and_then(toml::Value::as_array_mut).ok_or_else(|| format!("'{name}' is not a list here, so '{name}[{i}]' names nothing"))?;
    let count = list.len();
    list.get_mut(i).ok_or_else(|| format!("'{name}' has {count} entries (0 to {}), no [{i}]", count.saturating_sub(1)))
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
