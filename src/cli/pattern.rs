//! `rosette pattern import`: a GarmentCode pattern specification as a garment scene file.

use super::outputs::{self, PATTERN_SCENE};
use super::bad_input;
use rosette::garment::form::FormConfig;
use rosette::garment::garmentcode::{ImportOptions, import as import_spec, scene_text};
use rosette::io::guard::Plan;
use rosette::io::read::{FileKind, read_text};
use rosette::errln;
use std::path::Path;
use std::process::ExitCode;

pub fn import(spec: &Path, out: Option<&Path>, form: &str, fabric: &str, grain_deg: f64, force: bool) -> ExitCode {
    if !grain_deg.is_finite() {
        return bad_input(format!("--grain-deg {grain_deg}: give a finite angle in degrees (90: the straight grain up and down each panel)"));
    }
    let text = match read_text(spec, FileKind::Pattern) {
        Ok(t) => t,
        Err(e) => return bad_input(e),
    };
    if !rosette::settings::FABRICS.iter().any(|b| b.name == fabric) {
        let names: Vec<&str> = rosette::settings::FABRICS.iter().map(|b| b.name).collect();
        return bad_input(format!("--fabric {fabric}: no such bundled fabric; use one of {}", names.join(", ")));
    }
    let form = FormConfig { size: Some(form.to_string()), ..FormConfig::default() };
    let measurements = match form.measurements(rosette::garment::pattern::Units::Cm) {
        Ok(Some(m)) => m,
        Ok(None) => unreachable!("a size gives measurements"),
        Err(e) => return bad_input(format!("--form: {e}")),
    };
    if let Some(path) = out {
        let mut plan = Plan::new(force);
        plan.add("--out", path, PATTERN_SCENE);
        if let Err(e) = outputs::check(&plan, &[]) {
            return bad_input(e);
        }
    }
    let source = spec.display().to_string();
    let imported = match import_spec(&text, &source, &ImportOptions { form, grain_deg }) {
        Ok(i) => i,
        Err(e) => return bad_input(e),
    };
    // The pattern is meshed here as a run would mesh it, so that an outline that crosses
    // itself or a seam whose sides differ beyond the ease is refused now, naming the panel
    // and the edge, not when the scene is first run.
    if let Err(e) = rosette::garment::build(&imported.garment, 0.02, glam::DVec2::ZERO, &|level| measurements.level(level)) {
        return bad_input(format!("{source}: {e}"));
    }
    for note in &imported.notes {
        errln!("note: {note}");
    }
    let name = spec.file_stem().map_or_else(|| "pattern".into(), |s| s.to_string_lossy().into_owned());
    let text = match scene_text(&imported, &source, &name, fabric) {
        Ok(t) => t,
        Err(e) => return bad_input(e),
    };
    if let Err(e) = loads_as_written(&text, &name) {
        return bad_input(format!("{source}: the scene it imports to is refused: {e}"));
    }
    outputs::write_or_print(out, &text, "the scene file", &format!("; run it with `rosette run {}`", out.map_or_else(String::new, |p| p.display().to_string())))
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
