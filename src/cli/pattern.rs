//! `rosette pattern import`, `seams` and `export`: patterns from GarmentCode's
//! specification and pattern CAD's DXF as garment scene files, seams suggested for a DXF
//! pattern, and a garment's panels written back as DXF.

use super::args::PatternArgs;
use super::outputs::{self, DXF_PATTERN, PATTERN_SCENE, SEAMS_FILE};
use super::bad_input;
use rosette::garment::dxf::import::{self as dxf_import, ImportOptions as DxfOptions};
use rosette::garment::dxf::panels::{Arrangement, Top};
use rosette::garment::dxf::{LengthUnit, ReadOptions, seams as dxf_seams, write as dxf_write};
use rosette::garment::form::FormConfig;
use rosette::garment::garmentcode::{self, ImportOptions};
use rosette::garment::import::{Imported, Origin, scene_text};
use rosette::io::guard::{Kind, Plan};
use rosette::io::read::{FileKind, read_bytes, read_text};
use rosette::settings::read::{is_dxf_file, seams_beside};
use rosette::errln;
use std::path::Path;
use std::process::ExitCode;

/// The form of `--form`, with its measurements checked.
fn form(size: &str) -> Result<FormConfig, String> {
    let form = FormConfig { size: Some(size.to_string()), ..FormConfig::default() };
    form.measurements(rosette::garment::pattern::Units::Cm).map_err(|e| format!("--form: {e}"))?;
    Ok(form)
}

/// The DXF options of `args`, checked.
fn dxf_options(args: &PatternArgs) -> Result<DxfOptions, String> {
    let units = match &args.units {
        None => None,
        Some(u) => Some(LengthUnit::parse(u).ok_or_else(|| format!("--units {u}: give mm, cm or in"))?),
    };
    let top = match args.top.as_deref() {
        None => None,
        Some("waist") => Some(Top::Waist),
        Some("shoulder") => Some(Top::Shoulder),
        Some(other) => return Err(format!("--top {other}: give waist (skirts, trousers) or shoulder (tops, dresses)")),
    };
    if let Some(g) = args.grain_deg
        && !(g.is_finite() && g.abs() <= 360.0)
    {
        return Err(format!("--grain-deg {g}: give an angle in degrees between -360 and 360"));
    }
    Ok(DxfOptions {
        read: ReadOptions { units, grain_deg: args.grain_deg },
        arrangement: Arrangement { front: args.front.clone(), back: args.back.clone(), sleeves: args.sleeve.clone(), top },
        form: form(&args.form)?,
    })
}

/// Checks the output `path` (`--out`) of `kind` against the files read, before any work.
fn check_out(path: Option<&Path>, kind: Kind, force: bool) -> Result<(), String> {
    if let Some(path) = path {
        let mut plan = Plan::new(force);
        plan.add("--out", path, kind);
        outputs::check(&plan, &[])?;
    }
    Ok(())
}

/// Writes `text` to `out`, or prints it; `then` follows "wrote PATH", its `{}` the path.
fn emit(out: Option<&Path>, text: &str, what: &str, then: &str) -> ExitCode {
    let hint = out.map_or_else(String::new, |path| then.replace("{}", &path.display().to_string()));
    outputs::write_or_print(out, text, &format!("the {what}"), &hint)
}

/// The seams file of a DXF import: `--seams`, else the one beside the pattern; read and parsed.
fn seams_file(pattern: &Path, given: Option<&Path>) -> Result<Option<(dxf_seams::SeamsFile, String)>, String> {
    let beside = seams_beside(pattern);
    let path = match given {
        Some(p) => p.to_path_buf(),
        None if beside.is_file() => beside,
        None => return Ok(None),
    };
    let text = read_text(&path, FileKind::Seams).map_err(|e| format!("--seams: {e}"))?;
    let shown = path.display().to_string();
    let file = dxf_seams::parse(&text, &shown).map_err(|e| e.to_string())?;
    Ok(Some((file, shown)))
}

pub fn import(spec: &Path, out: Option<&Path>, args: &PatternArgs, fabric: &str, seams: Option<&Path>, force: bool) -> ExitCode {
    let source = spec.display().to_string();
    let dxf = is_dxf_file(&source);
    if !dxf {
        for (flag, given) in [("--units", args.units.is_some()), ("--front", !args.front.is_empty()), ("--back", !args.back.is_empty()), ("--sleeve", !args.sleeve.is_empty()), ("--top", args.top.is_some()), ("--seams", seams.is_some())] {
            if given {
                return bad_input(format!("{flag}: only a DXF pattern takes it; GarmentCode's specification places and sews its own panels"));
            }
        }
    }
    if !rosette::settings::FABRICS.iter().any(|b| b.name == fabric) {
        let names: Vec<&str> = rosette::settings::FABRICS.iter().map(|b| b.name).collect();
        return bad_input(format!("--fabric {fabric}: no such bundled fabric; use one of {}", names.join(", ")));
    }
    let imported: Result<(Imported, Origin), String> = if dxf {
        (|| {
            let options = dxf_options(args)?;
            let bytes = read_bytes(spec, FileKind::Dxf).map_err(|e| e.to_string())?;
            let seams = seams_file(spec, seams)?;
            check_out(out, PATTERN_SCENE, force)?;
            let imported = dxf_import::import(&bytes, &source, &options, seams.as_ref().map(|(f, s)| (f, s.as_str()))).map_err(|e| e.to_string())?;
            Ok((imported, dxf_import::ORIGIN))
        })()
    } else {
        (|| {
            let grain_deg = args.grain_deg.unwrap_or(90.0);
            if !grain_deg.is_finite() {
                return Err(format!("--grain-deg {grain_deg}: give a finite angle in degrees (90: the straight grain up and down each panel)"));
            }
            let form = form(&args.form)?;
            let text = read_text(spec, FileKind::Pattern).map_err(|e| e.to_string())?;
            check_out(out, PATTERN_SCENE, force)?;
            let imported = garmentcode::import(&text, &source, &ImportOptions { form, grain_deg }).map_err(|e| e.to_string())?;
            Ok((imported, garmentcode::ORIGIN))
        })()
    };
    let (imported, origin) = match imported {
        Ok(i) => i,
        Err(e) => return bad_input(e),
    };
    // The pattern is meshed here as a run would mesh it, so that an outline that crosses
    // itself or a seam whose sides differ beyond the ease is refused now, naming the panel
    // and the edge, not when the scene is first run.
    let measurements = match imported.garment.form.measurements(rosette::garment::pattern::Units::Cm) {
        Ok(Some(m)) => m,
        Ok(None) => unreachable!("a size gives measurements"),
        Err(e) => return bad_input(format!("--form: {e}")),
    };
    if let Err(e) = rosette::garment::build(&imported.garment, 0.02, glam::DVec2::ZERO, &|level| measurements.level(level)) {
        return bad_input(format!("{source}: {e}"));
    }
    for note in &imported.notes {
        errln!("note: {note}");
    }
    let name = spec.file_stem().map_or_else(|| "pattern".into(), |s| s.to_string_lossy().into_owned());
    let text = match scene_text(&imported, &origin, &source, &name, fabric) {
        Ok(t) => t,
        Err(e) => return bad_input(e),
    };
    if let Err(e) = loads_as_written(&text, &name) {
        return bad_input(format!("{source}: the scene it imports to is refused: {e}"));
    }
    emit(out, &text, "scene file", "; run it with `rosette run {}`")
}

/// Loads the scene text an import is about to write as `rosette run` will load it (every
/// check, the fabric, the form, the plan), so that an import never writes a scene that a
/// run then refuses. The text goes through a file of its own in the temporary folder,
/// removed after.
fn loads_as_written(text: &str, name: &str) -> Result<(), String> {
    let path = std::env::temp_dir().join(format!("rosette-import-{}-{name}.toml", std::process::id()));
    std::fs::write(&path, text).map_err(|e| format!("cannot check it in {}: {e}", path.display()))?;
    let loaded = rosette::scene::load_scene(&path.to_string_lossy(), &[]);
    std::fs::remove_file(&path).ok();
    loaded.map(drop).map_err(|e| e.to_string().replace(&path.display().to_string(), "the imported scene"))
}

pub fn seams(pattern: &Path, out: Option<&Path>, args: &PatternArgs, force: bool) -> ExitCode {
    let source = pattern.display().to_string();
    if !is_dxf_file(&source) {
        return bad_input(format!("{source}: seams are suggested for a DXF pattern (NAME.dxf); GarmentCode's specification carries its own stitches"));
    }
    let result = (|| -> Result<String, String> {
        let options = dxf_options(args)?;
        let bytes = read_bytes(pattern, FileKind::Dxf).map_err(|e| e.to_string())?;
        // A seams file beside the pattern gives its placement, which the suggestions follow.
        let existing = seams_file(pattern, None)?;
        check_out(out, SEAMS_FILE, force)?;
        let (_, panels, top) = dxf_import::placed(&bytes, &source, &options, existing.as_ref().map(|(f, _)| f)).map_err(|e| e.to_string())?;
        let suggestions = dxf_seams::suggest(&panels, top).map_err(|e| e.to_string())?;
        Ok(dxf_seams::suggestions_text(&source, &panels, &suggestions))
    })();
    match result {
        Ok(text) => emit(out, &text, "seams file", "; check it, then keep it as NAME.seams.toml beside the pattern or give it with --seams"),
        Err(e) => bad_input(e),
    }
}

pub fn export(scene: &str, out: &Path, overrides: &[String], units: &str, aama: bool, force: bool) -> ExitCode {
    let result = (|| -> Result<String, String> {
        let units = match LengthUnit::parse(units) {
            Some(u @ (LengthUnit::Mm | LengthUnit::In)) => u,
            _ => return Err(format!("--units {units}: a pattern file is written in mm (METRIC) or in (ENGLISH)")),
        };
        let (config, _) = rosette::scene::load_scene(scene, overrides).map_err(|e| e.to_string())?;
        let garment = config.garment.as_ref().ok_or_else(|| format!("{scene} is not a garment scene: it has no panels to export"))?;
        let mut plan = Plan::new(force);
        plan.add("--out", out, DXF_PATTERN);
        outputs::check(&plan, &[&config])?;
        let name = Path::new(scene).file_stem().map_or_else(|| scene.to_string(), |s| s.to_string_lossy().into_owned());
        let options = dxf_write::WriteOptions { units, style: name, aama_notches: aama };
        dxf_write::write(garment, &options).map_err(|e| e.to_string())
    })();
    match result {
        Ok(text) => emit(Some(out), &text, "pattern", "; pattern CAD reads it as AAMA / ASTM DXF, `rosette pattern import {}` as a garment"),
        Err(e) => bad_input(e),
    }
}
