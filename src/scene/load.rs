//! Loading a scene: the scene file, its fabric file and the `--set` overrides merged, the
//! sheets converted and everything checked, every refusal traced to the file, the `--set`
//! or the flag that gave the value (`Sources`), in the terms the user wrote it in: a sheet's
//! field rather than the fabric key it became, `--duration` rather than `scene.duration`.

use super::check::CheckedScene;
use crate::settings::read::{PresetKind, apply_override, looks_like_path, parse_override, read_preset};
use crate::settings::{FabricConfig, Origin, Origins, PresetError, SceneConfig};
use crate::fabric::Import;
use crate::io::number::short;
use std::path::Path;

/// What `rosette run` says beside `--set`: the run's duration (`--duration`) and step
/// bound (`--max-steps`). The checks use them and name the flag; `--max-steps` is the
/// scene's `scene.max_steps`, `--duration` the run's length (the scene's own duration still
/// sets what depends on it, such as the arc's roll).
#[derive(Debug, Clone, Copy, Default)]
pub struct RunFlags {
    pub duration: Option<f64>,
    pub max_steps: Option<u64>,
}

/// Where each value of a scene came from, so that an error names the file or the `--set`
/// that gave the bad value.
struct Sources {
    scene_file: String,
    /// The fabric file named by `fabric.preset`, and the keys the scene's own `[fabric]`
    /// table gives (those are the scene file's).
    fabric_file: Option<String>,
    scene_fabric_keys: Vec<String>,
    /// Each `--set` (as `--set KEY=VALUE`) or flag (`--max-steps N`) that set a key, with
    /// the key.
    overrides: Vec<(Vec<String>, String)>,
    /// The flags that set scene keys: their key in messages is replaced by the flag.
    flags: Vec<(&'static str, &'static str)>,
    /// The fabric keys the sheets gave, with their sources.
    import: Import,
    /// The scene and fabric files' values before the overrides, to quote as an example.
    original: toml::Table,
}

impl Sources {
    /// The file or `--set` a bad value at `key` (dotted, array indices dropped) came from.
    fn blame(&self, key: &[String]) -> String {
        // `--set garment.panels[1].grain_deg=…` is a path with an index; the key has none.
        let unindexed = |part: &String| part.split('[').next().unwrap_or(part).to_string();
        let overlaps = |path: &[String]| path.iter().zip(key).all(|(a, b)| unindexed(a) == *b);
        if let Some((_, text)) = self.overrides.iter().rev().find(|(path, _)| overlaps(path)) {
            return text.clone();
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
        PresetError::Invalid { file: self.blame(key), message: self.in_flags(message) }
    }

    /// `message` with the keys a flag set named by the flag (`scene.max_steps = 3` becomes
    /// `--max-steps 3`).
    fn in_flags(&self, message: String) -> String {
        self.flags.iter().fold(message, |m, (key, flag)| m.replace(&format!("{key} = "), &format!("{flag} ")).replace(key, flag))
    }

    /// A fabric check that failed on `key` (`fabric.poisson_warp`): in the sheet's terms
    /// where sheet values lie behind it, blamed on the `--set` or file that gave them.
    fn fabric_invalid(&self, key: &str, message: String) -> PresetError {
        let field = key.trim_start_matches("fabric.");
        match crate::fabric::explain::explain(&self.import, field, &message) {
            Some((text, fields)) => PresetError::Invalid { file: self.blame_fields(&fields).unwrap_or_else(|| self.blame(&key_parts(key))), message: text },
            None => self.invalid(&key_parts(key), message),
        }
    }

    /// A sheet that failed to convert, blamed on the `--set` that changed a field it names
    /// where one did.
    fn sheet_invalid(&self, file: &str, error: &crate::fabric::SheetError) -> PresetError {
        let message = error.to_string();
        let named = crate::fabric::explain::field_names(&crate::fabric::explain::quoted_fields(&message));
        PresetError::Invalid { file: self.blame_fields(&named).unwrap_or_else(|| file.to_string()), message }
    }

    /// Where sheet fields (`kes.LT_warp`) came from: the first `--set` among them, else the
    /// first's file.
    fn blame_fields(&self, fields: &[String]) -> Option<String> {
        let blamed: Vec<String> = fields.iter().map(|f| self.blame(&key_parts(&format!("fabric.{f}")))).collect();
        blamed.iter().find(|b| b.starts_with("--")).or(blamed.first()).cloned()
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
    let message = crate::io::number::shorten_in(message.trim());
    let message = message.as_str();
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
pub fn load_scene(spec: &str, overrides: &[String]) -> Result<(CheckedScene, String), PresetError> {
    load_scene_with(spec, overrides, &RunFlags::default())
}

/// [`load_scene`] for a run with `flags` (`rosette run --duration`, `--max-steps`).
pub fn load_scene_with(spec: &str, overrides: &[String], flags: &RunFlags) -> Result<(CheckedScene, String), PresetError> {
    let (own, file) = read_preset(PresetKind::Scene, spec, None, Some("scene"))?;
    let (mut table, base_table) = crate::settings::read::with_base(own.clone(), &file)?;
    let base = if looks_like_path(spec) || Path::new(spec).exists() { Path::new(spec).parent().map(Path::to_path_buf) } else { None };
    let scene_fabric_keys = table.get("fabric").and_then(|v| v.as_table()).map(|t| t.keys().cloned().collect()).unwrap_or_default();
    let mut sources = Sources {
        scene_file: file.clone(),
        fabric_file: None,
        scene_fabric_keys,
        overrides: Vec::new(),
        flags: Vec::new(),
        import: Import::default(),
        original: toml::Table::new(),
    };
    // A bundled scene, or the scene a pattern import writes, is the project's; any other
    // file is the user's. Each `--set` and flag is the user's.
    let scene_origin = if file.ends_with("(bundled)") || crate::settings::read::is_pattern_spec(spec) { Origin::Bundled } else { Origin::User };
    let mut origins = Origins::default();
    if let Some(base) = &base_table {
        origins.record_table("", base, Origin::Bundled);
    }
    // The base's keys are laid under the scene's: what the scene file gives is its own.
    origins.record_table("", &own, scene_origin);
    let mut fabric_table = None;
    // The fabric file named in the scene file, for the original values.
    if let Some(name) = table.get("fabric").and_then(|f| f.get("preset")).and_then(|v| v.as_str()) {
        let (fabric, fabric_file) = read_preset(PresetKind::Fabric, name, base.as_deref(), Some("fabric.preset"))?;
        fabric_table = Some((name.to_string(), fabric, fabric_file));
    }
    sources.original = merge_fabric(table.clone(), fabric_table.as_ref().map(|f| f.1.clone()));
    for o in overrides {
        let (path, value) = parse_override(o)?;
        apply_override(&mut table, &path, value).map_err(|m| PresetError::BadOverride { text: o.clone(), message: m })?;
        origins.record(&path.join("."), Origin::User);
        sources.overrides.push((path, format!("--set {o}")));
    }
    if let Some(n) = flags.max_steps {
        let path = key_parts("scene.max_steps");
        apply_override(&mut table, &path, toml::Value::Integer(i64::try_from(n).unwrap_or(i64::MAX))).expect("[scene] is a table");
        origins.record("scene.max_steps", Origin::User);
        sources.overrides.push((path, format!("--max-steps {n}")));
        sources.flags.push(("scene.max_steps", "--max-steps"));
    }
    if flags.duration.is_some() {
        sources.flags.push(("--duration = ", "--duration "));
    }
    let own_fabric_keys = table.get("fabric").and_then(|v| v.as_table()).cloned().unwrap_or_default();
    let preset = table.get("fabric").and_then(|f| f.get("preset"));
    if let Some(preset) = preset {
        let name = preset.as_str().ok_or_else(|| sources.invalid(&key_parts("fabric.preset"), format!("fabric.preset must be a fabric name or file in quotes, got {preset}")))?;
        if fabric_table.as_ref().is_none_or(|f| f.0 != name) {
            let (fabric, fabric_file) =
                read_preset(PresetKind::Fabric, name, base.as_deref(), Some("fabric.preset")).map_err(|e| {
                    let message = match e {
                        PresetError::Read { source, .. } => source.to_string(),
                        e => e.to_string(),
                    };
                    sources.invalid(&key_parts("fabric.preset"), message)
                })?;
            fabric_table = Some((name.to_string(), fabric, fabric_file));
        }
    } else {
        fabric_table = None;
    }
    if let Some((_, t, fabric_file)) = &mut fabric_table {
        // Sheet fields the scene or a `--set` changes are converted with the file's sheet.
        if let Some(scene_fabric) = table.get_mut("fabric").and_then(|v| v.as_table_mut()) {
            crate::fabric::merge_scene_sheets(t, scene_fabric);
        }
        sources.fabric_file = Some(fabric_file.clone());
        sources.import = expand_sheets_noting(t, fabric_file).map_err(|e| sources.sheet_invalid(fabric_file, &e))?;
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
        let import = expand_sheets_noting(fabric, &file).map_err(|e| sources.sheet_invalid(&file, &e))?;
        if !import.derived.is_empty() {
            sources.import = import;
        }
    }
    let mut config: SceneConfig = deserialize_named(table).map_err(|(parts, key, message)| {
        let example = sources.original(&parts);
        sources.invalid(&parts, type_error(&key, &message, example))
    })?;
    config.base_dir = base;
    config.origins = origins;
    config.own_fabric_keys = own_fabric_keys;
    let checked = super::check::checked_for(config, flags.duration).map_err(|e| match (e.key.as_str(), flags.duration) {
        ("--duration", Some(d)) => PresetError::Invalid { file: format!("--duration {}", short(d)), message: sources.in_flags(e.message) },
        (key, _) if key.starts_with("fabric.") => sources.fabric_invalid(key, e.message),
        (key, _) => {
            // Traced to a `--set` of any key the value was weighed against, if there is one.
            let set = std::iter::once(key).chain(e.also.iter().map(String::as_str)).map(key_parts).find(|k| sources.blame(k).starts_with("--"));
            sources.invalid(&set.unwrap_or_else(|| key_parts(key)), e.message)
        }
    })?;
    Ok((checked, file))
}

/// Turns a fabric table's measurement sheets into fabric keys ([`crate::fabric::expand_sheets`])
/// and reports its warnings on stderr, naming `file`. Returns what the sheets gave, with
/// their sources.
fn expand_sheets_noting(table: &mut toml::Table, file: &str) -> Result<Import, crate::fabric::SheetError> {
    let expanded = crate::fabric::expand_sheets(table)?;
    for w in &expanded.warnings {
        crate::errln!("warning: {file}: {w}");
    }
    Ok(expanded.import)
}

/// The scene's table with its `[fabric]` keys laid over the fabric file's.
fn merge_fabric(mut table: toml::Table, fabric_file: Option<toml::Table>) -> toml::Table {
    let scene_fabric = table.remove("fabric").and_then(|v| v.as_table().cloned()).unwrap_or_default();
    let mut fabric = fabric_file.unwrap_or_default();
    let preset = scene_fabric.get("preset").cloned();
    for (k, v) in scene_fabric {
        crate::settings::fabric::lay_over(&mut fabric, k, v);
    }
    if let Some(p) = preset {
        fabric.insert("preset".into(), p);
    }
    table.insert("fabric".into(), toml::Value::Table(fabric));
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::read::parse_table;
    use crate::settings::{FABRICS, SCENES};
    use crate::sim::IntegratorKind;

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

    /// `--set` reaches one entry of a list: the bias skirt's second gore cut on the straight
    /// grain, the others left alone; an entry past the list's end is refused with its count.
    #[test]
    fn an_override_reaches_one_entry_of_a_list() {
        let (config, _) = load_scene("skirt-gored-bias", &["garment.panels[1].grain_deg=90".into()]).unwrap();
        let (bundled, _) = load_scene("skirt-gored-bias", &[]).unwrap();
        let grains = |c: &SceneConfig| c.garment.as_ref().unwrap().panels.iter().map(|p| p.grain_deg).collect::<Vec<_>>();
        let (set, before) = (grains(&config), grains(&bundled));
        assert_eq!(set[1], 90.0);
        assert_ne!(before[1], 90.0);
        assert_eq!((set[0], set[2], set[3]), (before[0], before[2], before[3]));
        let e = load_scene("skirt-gored-bias", &["garment.panels[4].grain_deg=0".into()]).unwrap_err().to_string();
        assert!(e.contains("has 4 entries") && e.contains("no [4]"), "{e}");
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
        let err = load_scene("sphere-drop", &["solver.fast.motion_error_share=1".into()]).unwrap_err().to_string();
        assert!(err.contains("solver.fast.motion_error_share") && err.contains("[0, 1)"), "{err}");
    }

    /// The simulator's tests use the wool suiting written out (`sim::model::tests`); it is
    /// the bundled file's.
    #[test]
    fn the_simulators_wool_is_the_bundled_wool() {
        let bundled = crate::fabric::load_fabric("wool").unwrap().config.to_fabric().unwrap();
        assert_eq!(format!("{bundled:?}"), format!("{:?}", crate::sim::model::tests::wool_suiting()));
    }
}
