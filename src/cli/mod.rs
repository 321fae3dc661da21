//! `rosette card` and `rosette compare`: the fabric card and the contact sheet from the
//! command line (the work is `rosette::card`'s; here are the checks before it, the progress
//! bar and the exit codes).

mod arcsim;

pub use arcsim::{export_arcsim, same_file};

use super::{EXIT_DIVERGED, EXIT_NO_OUTPUT, bad_input, check_writable};
use std::io::IsTerminal;
use std::process::ExitCode;

/// Shows `progress` on a bar on stderr while `work` runs, where someone watches.
fn with_bar<T>(label: &str, progress: &rosette::card::Progress, work: impl FnOnce() -> T) -> T {
    if !std::io::stderr().is_terminal() {
        return work();
    }
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent}% ({elapsed})").expect("valid template").progress_chars("=> "),
    );
    let done = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                bar.set_position((progress.fraction() * 1000.0) as u64);
                let running = progress.running().join(", ");
                let stage = progress.stage().unwrap_or(running);
                bar.set_message(format!("{label}: {}/{} {stage}", progress.done(), progress.total()));
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            bar.finish_and_clear();
        });
        let result = work();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        result
    })
}

pub fn card(spec: &str, out: &std::path::Path) -> ExitCode {
    use rosette::card::CardError;
    let loaded = match rosette::fabric::load_fabric(spec) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let stem = std::path::Path::new(spec).file_stem().map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned());
    if let Err(e) = std::fs::create_dir_all(out) {
        return bad_input(format!("--out {}: cannot create the directory: {e}", out.display()));
    }
    for ext in ["json", "png"] {
        if let Err(e) = check_writable("--out", &out.join(format!("{stem}.{ext}"))) {
            return bad_input(format!("{e:#}"));
        }
    }
    let progress = rosette::card::Progress::default();
    let made = with_bar(&stem, &progress, || rosette::card::make(&loaded.config, &loaded.file, Some((&loaded.sheets, &loaded.import)), &progress));
    let made = match made {
        Ok(m) => m,
        Err(e @ CardError::BadInput(_)) => return bad_input(e),
        Err(e @ CardError::Output(_)) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_NO_OUTPUT);
        }
        Err(e) => {
            eprintln!("error: {stem}: {e}");
            return ExitCode::from(EXIT_DIVERGED);
        }
    };
    let written = made.write(out, &stem);
    let c = &made.card;
    eprintln!(
        "{stem}: DC {:.3}, {} nodes; bending length warp {:.1} mm, weft {:.1} mm; {:.1} CPU s, {:.1} s wall",
        c.drape.result.drape_coefficient, c.drape.result.nodes, c.cantilever[0].bending_length_mm, c.cantilever[1].bending_length_mm, c.cost.cpu_seconds, c.cost.wall_seconds
    );
    match written {
        Ok(paths) => paths.iter().for_each(|p| eprintln!("wrote {}", p.display())),
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_NO_OUTPUT);
        }
    }
    if let Some(e) = &made.picture_error {
        eprintln!("error: the drape pictures could not be rendered (the page has a note in their place): {e}");
        return ExitCode::from(EXIT_NO_OUTPUT);
    }
    ExitCode::SUCCESS
}

pub fn compare(fabrics: &[String], scene: &str, overrides: &[String], out: &std::path::Path) -> ExitCode {
    use rosette::card::compare;
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return bad_input(format!("--out {}: the contact sheet is written as PNG; name the file FILE.png", out.display()));
    }
    let configs = match compare::configs(fabrics, scene, overrides) {
        Ok(c) => c,
        Err(e) => return bad_input(e),
    };
    let paths = [out.to_path_buf(), out.with_extension("json"), out.with_extension("csv")];
    for path in &paths {
        if let Err(e) = check_writable("--out", path) {
            return bad_input(format!("{e:#}"));
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
            None => eprintln!("{:<20} DC {:.3}  {} nodes", e.fabric, e.result.drape_coefficient, e.result.nodes),
            Some(error) => eprintln!("{:<20} failed: {error}", e.fabric),
        }
    }
    let mut failed_output = false;
    let json = serde_json::to_string_pretty(&comparison).expect("numbers serialise") + "\n";
    for (path, text) in [(&paths[1], json), (&paths[2], comparison.csv())] {
        if let Err(e) = std::fs::write(path, text) {
            eprintln!("error: cannot write {}: {e}", path.display());
            failed_output = true;
        }
    }
    let picture_error = pictures.as_ref().err().cloned();
    let pictures = pictures.unwrap_or_else(|e| comparison.entries.iter().map(|_| rosette::card::picture::placeholder(compare::TILE, &format!("not rendered: {e}"))).collect());
    match compare::contact_sheet(&comparison, &pictures).and_then(|(pixels, size)| rosette::card::picture::save_png(out, pixels, size)) {
        Ok(()) => eprintln!("wrote {}, {} and {} ({:.1} CPU s, {:.1} s wall)", out.display(), paths[1].display(), paths[2].display(), comparison.cpu_seconds, comparison.wall_seconds),
        Err(e) => {
            eprintln!("error: {e}");
            failed_output = true;
        }
    }
    if comparison.entries.iter().any(|e| e.error.is_some()) {
        eprintln!("error: some drapes failed; the sheet says which");
        return ExitCode::from(EXIT_DIVERGED);
    }
    if let Some(e) = picture_error {
        eprintln!("error: the drapes could not be rendered (the sheet has notes in their place): {e}");
        return ExitCode::from(EXIT_NO_OUTPUT);
    }
    if failed_output { ExitCode::from(EXIT_NO_OUTPUT) } else { ExitCode::SUCCESS }
}
