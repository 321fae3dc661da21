//! `rosette card` and `rosette compare`: the fabric card and the contact sheet from the
//! command line (the work is `rosette::card`'s; here are the checks before it, the progress
//! bar, the outputs and the exit codes).

use super::outputs::{self, CARD_JSON, COMPARE_CSV, COMPARE_JSON, PICTURE};
use super::{EXIT_DIVERGED, EXIT_NO_OUTPUT, bad_input, lost_output, say_error, with_bar};
use rosette::errln;
use rosette::io::guard::Plan;
use std::path::Path;
use std::process::ExitCode;

pub fn card(spec: &str, out: &Path, force: bool) -> ExitCode {
    use rosette::card::CardError;
    let loaded = match rosette::fabric::load_fabric(spec) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    for w in &loaded.warnings {
        errln!("warning: {w}");
    }
    let stem = Path::new(spec).file_stem().map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned());
    if let Err(e) = outputs::folder("--out", out) {
        return bad_input(e);
    }
    let mut plan = Plan::new(force);
    plan.add("--out", &out.join(format!("{stem}.json")), CARD_JSON);
    plan.add("--out", &out.join(format!("{stem}.png")), PICTURE);
    if let Err(e) = outputs::check(&plan, &[]) {
        return bad_input(e);
    }
    let progress = rosette::card::Progress::default();
    let made = with_bar(&stem, &progress, || rosette::card::make(&loaded.config, &loaded.file, Some((&loaded.sheets, &loaded.import)), &progress));
    let made = match made {
        Ok(m) => m,
        Err(e @ CardError::BadInput(_)) => return bad_input(e),
        Err(e @ CardError::Output(_)) => return lost_output(e),
        Err(e) => {
            say_error(format!("{stem}: {e}"));
            return ExitCode::from(EXIT_DIVERGED);
        }
    };
    let written = made.write(out, &stem);
    let c = &made.card;
    errln!(
        "{stem}: DC {}, {} nodes; bending length warp {:.1} mm, weft {:.1} mm; {:.1} CPU s, {:.1} s wall",
        rosette::card::dc_text(c.drape.result.drape_coefficient),
        c.drape.result.nodes,
        c.cantilever[0].bending_length_mm,
        c.cantilever[1].bending_length_mm,
        c.cost.cpu_seconds,
        c.cost.wall_seconds
    );
    match written {
        Ok(paths) => paths.iter().for_each(|p| errln!("wrote {}", p.display())),
        Err(e) => return lost_output(e),
    }
    if let Some(e) = &made.picture_error {
        return lost_output(format!("the drape pictures could not be rendered (the page has a note in their place): {e}"));
    }
    ExitCode::SUCCESS
}

/// `--set` keys that would contradict the fabrics `compare` names: the fabric itself.
fn contradicts_the_fabrics(overrides: &[String], fabrics: &[String]) -> Result<(), String> {
    for o in overrides {
        let key = o.split_once('=').map_or(o.as_str(), |(k, _)| k).trim();
        if key == "fabric" || key == "fabric.preset" {
            return Err(format!(
                "--set {o}: compare drapes the fabrics it names ({}), each as fabric.preset; a --set of the fabric would \
                 replace or contradict them all. Name that fabric among the others instead",
                fabrics.join(", ")
            ));
        }
    }
    Ok(())
}

pub fn compare(fabrics: &[String], scene: &str, overrides: &[String], out: &Path, force: bool) -> ExitCode {
    use rosette::card::compare;
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return bad_input(format!("--out {}: the contact sheet is written as PNG; name the file FILE.png", out.display()));
    }
    if let Err(e) = contradicts_the_fabrics(overrides, fabrics) {
        return bad_input(e);
    }
    let configs = match compare::configs(fabrics, scene, overrides) {
        Ok(c) => c,
        Err(e) => return bad_input(e),
    };
    let paths = [out.to_path_buf(), out.with_extension("json"), out.with_extension("csv")];
    let mut plan = Plan::new(force);
    for (path, kind) in paths.iter().zip([PICTURE, COMPARE_JSON, COMPARE_CSV]) {
        plan.add("--out", path, kind);
    }
    if let Err(e) = outputs::check(&plan, &configs.iter().map(|c| &**c).collect::<Vec<_>>()) {
        return bad_input(e);
    }
    // The props start clear of the cloth: every fabric is draped on the same geometry.
    if let Some(config) = configs.first() {
        match rosette::scene::Scene::build(config.clone()) {
            Ok(built) => {
                if let Err(e) = rosette::scene::possible::check_start(&built) {
                    return bad_input(format!("--scene {scene}: {e}"));
                }
            }
            Err(e) => return bad_input(format!("--scene {scene}: {e}")),
        }
    }
    let (wall, cpu) = (std::time::Instant::now(), cpu_time::ProcessTime::now());
    let progress = rosette::card::Progress::default();
    let results = with_bar("compare", &progress, || compare::run(fabrics, configs, &progress));
    let scenes: Vec<Option<&rosette::scene::Scene>> = results.iter().map(|(_, s)| s.as_ref()).collect();
    let pictures = compare::pictures(&scenes);
    let (yaw, pitch) = compare::camera_angles();
    let comparison = compare::Comparison {
        scene: scene.to_string(),
        overrides: overrides.to_vec(),
        camera_yaw_deg: yaw,
        camera_pitch_deg: pitch,
        entries: results.iter().map(|(e, _)| e.clone()).collect(),
        cpu_seconds: cpu.elapsed().as_secs_f64(),
        wall_seconds: wall.elapsed().as_secs_f64(),
    };
    for e in &comparison.entries {
        match &e.error {
            None => errln!("{:<20} DC {}  {} nodes", e.fabric, rosette::card::dc_text(e.result.drape_coefficient), e.result.nodes),
            Some(error) => errln!("{:<20} failed: {error}", e.fabric),
        }
    }
    let mut failed_output = false;
    let json = serde_json::to_string_pretty(&comparison).expect("numbers serialise") + "\n";
    for (path, text) in [(&paths[1], json), (&paths[2], comparison.csv())] {
        if let Err(e) = rosette::io::write::whole(path, text.as_bytes()) {
            say_error(format!("cannot write {}: {e}", path.display()));
            failed_output = true;
        }
    }
    let picture_error = pictures.as_ref().err().cloned();
    let pictures = pictures.unwrap_or_else(|e| comparison.entries.iter().map(|_| rosette::card::picture::placeholder(compare::TILE, &format!("not rendered: {e}"))).collect());
    match compare::contact_sheet(&comparison, &pictures).and_then(|(pixels, size)| rosette::card::picture::save_png(out, pixels, size)) {
        Ok(()) => errln!("wrote {}, {} and {} ({:.1} CPU s, {:.1} s wall)", out.display(), paths[1].display(), paths[2].display(), comparison.cpu_seconds, comparison.wall_seconds),
        Err(e) => {
            say_error(&e);
            failed_output = true;
        }
    }
    if comparison.entries.iter().any(|e| e.error.is_some()) {
        say_error("some drapes failed; the sheet says which");
        return ExitCode::from(EXIT_DIVERGED);
    }
    if let Some(e) = picture_error {
        return lost_output(format!("the drapes could not be rendered (the sheet has notes in their place): {e}"));
    }
    if failed_output { ExitCode::from(EXIT_NO_OUTPUT) } else { ExitCode::SUCCESS }
}
