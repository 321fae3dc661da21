//! The `rosette` command: runs bundled or custom scenes headless and reports metrics.

use anyhow::Context;
use clap::{Parser, Subcommand};
use rosette::app::viewer::ViewerOptions;
use rosette::render;
use rosette::scene::{RunOptions, Scene, StepRecord, load_scene, preset, run_scene};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

/// `rosette card` and `rosette compare`.
mod cli;

#[derive(Parser)]
#[command(
    name = "rosette",
    version,
    about = "Woven-fabric simulator and virtual fabric laboratory",
    after_help = "Exit codes: 0 done; 2 bad input, refused before the run; 3 the simulation diverged; \
                  4 an output could not be rendered or written after the run; 5 the run ended but \
                  some Newton solves did not converge (metrics: converged = false); 6 the run \
                  stopped at --max-steps or --max-wall. Metrics, outline and picture are kept for \
                  3 to 6."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// With no subcommand the viewer opens; exit after drawing N frames (smoke tests).
    #[arg(long, value_name = "N")]
    quit_after_frames: Option<u64>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene headless and report its measurements.
    Run {
        /// A bundled scene name (see `rosette presets`) or the path of a scene file.
        preset: String,
        /// Override a preset value, e.g. --set fabric.areal_density=0.2 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Simulated seconds (default: the scene's scene.duration).
        #[arg(long)]
        duration: Option<f64>,
        /// Write the metrics JSON to FILE, or to standard output with '-'.
        #[arg(long, value_name = "FILE|-")]
        metrics: Option<String>,
        /// Drape scenes: write the final shadow outline as CSV (angle_deg, radius_m).
        #[arg(long, value_name = "FILE.csv")]
        outline: Option<String>,
        /// Write one CSV row per step: its Newton, CG and factorisation counts, Newton's
        /// shift, the cloth's RMS speed, the CPU time so far and the step's time by phase.
        #[arg(long, value_name = "FILE.csv")]
        step_log: Option<std::path::PathBuf>,
        /// Most steps the run may take (default: the scene's scene.max_steps, 1 000 000): a
        /// scene that needs more is refused before it starts.
        #[arg(long, value_name = "N")]
        max_steps: Option<u64>,
        /// Wall-clock seconds after which the run stops, keeping what it has (exit 6).
        #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_MAX_WALL)]
        max_wall: f64,
        /// Take the fast path (solver.path = "fast"): settling scenes settle coarse to fine,
        /// with longer steps and Newton solved to the step's own accuracy (docs/solvers.md).
        #[arg(long)]
        fast: bool,
        /// Write the cloth as glTF 2.0 binary (Blender, three.js): the final state, or with
        /// --export-frames an animation of the run.
        #[arg(long, value_name = "FILE.glb")]
        export: Option<std::path::PathBuf>,
        /// With --export: N frames spread evenly over the run (2 to 1000), played back at
        /// the simulated times.
        #[arg(long, value_name = "N", requires = "export")]
        export_frames: Option<usize>,
        #[command(flatten)]
        screenshot: ScreenshotArgs,
    },
    /// Sweep integrators, time steps and meshes: error against CPU time and stability
    /// maps, as CSV and PNG (accuracy.csv/png, stability.csv/png).
    Chart {
        /// Directory for the CSV and PNG files (created if missing).
        #[arg(long, value_name = "DIR", default_value = "chart")]
        out: std::path::PathBuf,
        /// The small sweep the tests run: fewer and smaller runs, no drape.
        #[arg(long)]
        quick: bool,
    },
    /// The fabric card: the virtual laboratory's tests and the 30 cm Cusick drape on one
    /// fabric, written as DIR/NAME.png (one page) and DIR/NAME.json.
    Card {
        /// A bundled fabric's name (see `rosette fabric list`) or a fabric file.
        fabric: String,
        /// Directory for the page and the JSON (created if missing).
        #[arg(long, value_name = "DIR", default_value = ".")]
        out: std::path::PathBuf,
    },
    /// Drape several fabrics on one scene in parallel and set them side by side: a contact
    /// sheet PNG (same camera for all, DC and nodes under each) with its numbers as JSON and
    /// CSV beside it.
    Compare {
        /// Bundled fabric names or fabric files.
        #[arg(required = true, num_args = 1..)]
        fabrics: Vec<String>,
        /// The drape scene to run them on.
        #[arg(long, default_value = "cusick-drape-30")]
        scene: String,
        /// Override a scene value for every fabric, e.g. --set scene.duration=3 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// The contact sheet; FILE.json and FILE.csv are written beside it.
        #[arg(long, value_name = "FILE.png", default_value = "compare.png")]
        out: std::path::PathBuf,
    },
    /// List the bundled scenes.
    Presets,
    /// Fabrics from measurement sheets (KES-F, FAST, ASTM D1388 / BS 3356 cantilever).
    Fabric {
        #[command(subcommand)]
        action: FabricAction,
    },
    /// Time the paper's Table 1 scenes and the Cusick drape at about 800, 5 000, 20 000
    /// and 80 000 triangles, on 1 and 2 threads; writes bench.csv and bench.json.
    Bench {
        /// Directory for bench.csv and bench.json.
        #[arg(long, default_value = "bench")]
        out: std::path::PathBuf,
        /// Short windows and the two smaller drapes only (about a minute).
        #[arg(long)]
        quick: bool,
        /// Thread counts to run each case with.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
    },
    /// Open the interactive viewer (the default when no subcommand is given).
    View {
        /// A bundled scene name or scene file (default: the Cusick drape, or Euler buckling).
        preset: Option<String>,
        /// Exit after drawing N frames (smoke tests).
        #[arg(long, value_name = "N")]
        quit_after_frames: Option<u64>,
        /// Override a scene value, e.g. --set mesh.edge_length=0.0075 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Take the fast path (solver.path = "fast"): settling scenes settle coarse to fine,
        /// with longer steps and Newton solved to the step's own accuracy (docs/solvers.md).
        #[arg(long)]
        fast: bool,
    },
}

#[derive(Subcommand)]
enum FabricAction {
    /// Convert a sheet (a TOML file with [kes], [fast] and/or [cantilever] sections, an
    /// ARCSim material .json, or a bundled fabric's name) into a fabric file with every
    /// value's source.
    Import {
        /// The sheet file, an ARCSim material (.json), or a bundled fabric (see `rosette fabric list`).
        sheet: String,
        /// Write the fabric file here (default: standard output).
        #[arg(long, value_name = "FILE.toml")]
        out: Option<std::path::PathBuf>,
    },
    /// Print a sheet to fill in, every field with its unit and meaning.
    Template {
        /// Only this standard's section: kes, fast or cantilever.
        #[arg(long, value_name = "STANDARD")]
        standard: Option<String>,
    },
    /// Run the virtual laboratory tests on a fabric and set their readings beside its
    /// sheet (KES tensile, pure bending, shear, cantilever); exit 7 if any is outside its
    /// tolerance.
    Check {
        /// A bundled fabric's name or a fabric file with sheets.
        fabric: String,
    },
    /// List the bundled fabrics, the sheets they come from, and who measured them.
    List,
    /// Write a fabric (bundled name, fabric file or ARCSim material) as an ARCSim material
    /// file: density, stretching and bending samples (docs/fabric-sheets.md).
    Export {
        /// A bundled fabric's name, a fabric file or an ARCSim material (.json).
        fabric: String,
        /// Write ARCSim's material format (JSON), the one export format.
        #[arg(long, required = true)]
        arcsim: bool,
        /// Write the material here (default: standard output).
        #[arg(long, value_name = "FILE.json")]
        out: Option<std::path::PathBuf>,
    },
}

/// Rendering the final state offscreen (`rosette run ... --screenshot`).
#[derive(clap::Args)]
struct ScreenshotArgs {
    /// Render the final state to this PNG file (offscreen, no display needed).
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<std::path::PathBuf>,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "1280x800", value_parser = render::Screenshot::parse_size)]
    size: [u32; 2],
    /// View direction, yaw and pitch in degrees, and optionally the distance in metres
    /// (default -60,30, framing the scene).
    #[arg(long, value_name = "YAW,PITCH[,DISTANCE]", value_parser = render::Screenshot::parse_view, allow_hyphen_values = true)]
    camera: Option<(f64, f64, Option<f64>)>,
    /// Colour the cloth by a field: warp, weft, shear or bending.
    #[arg(long, value_name = "MAP")]
    colormap: Option<render::ColorMap>,
    /// Draw the mesh edges over the cloth.
    #[arg(long)]
    wireframe: bool,
}

/// Exit codes (also in `--help` and the README): 0 done, 2 bad input (refused before the
/// run), 3 the simulation diverged, 4 an output could not be rendered or written after the
/// run, 5 the run ended but some Newton solves did not converge, 6 the run stopped at its
/// step or wall-time bound, 7 a fabric's virtual tests disagree with its sheet.
const EXIT_BAD_INPUT: u8 = 2;
const EXIT_DIVERGED: u8 = 3;
const EXIT_NO_OUTPUT: u8 = 4;
const EXIT_NOT_CONVERGED: u8 = 5;
const EXIT_STOPPED: u8 = 6;
/// `rosette fabric check`: a virtual test read a sheet value outside its tolerance.
const EXIT_READBACK: u8 = 7;

/// What `--fast` adds to a scene's overrides.
const FAST_PATH: &str = "solver.path=fast";

/// A day: longer than any bundled scene takes, short enough that a runaway run ends.
const DEFAULT_MAX_WALL: f64 = 86_400.0;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        None if !rosette::app::viewer::display_available() => {
            // The main job where no window can open: the default drape, headless, with a
            // picture of it.
            eprintln!("no display (DISPLAY and WAYLAND_DISPLAY unset): running cusick-drape headless instead of the viewer");
            let shot = ScreenshotArgs {
                screenshot: Some("cusick-drape.png".into()),
                size: [1280, 800],
                camera: None,
                colormap: None,
                wireframe: false,
            };
            let code = run("cusick-drape", &[], &RunLimits::default(), &RunOutputs::default(), &shot);
            eprintln!("wrote cusick-drape.png; `rosette run PRESET --screenshot FILE.png` for other scenes");
            code
        }
        None => view(ViewerOptions { preset: None, quit_after_frames: cli.quit_after_frames, overrides: Vec::new() }),
        Some(Command::View { preset, quit_after_frames, mut overrides, fast }) => {
            if fast {
                overrides.push(FAST_PATH.to_string());
            }
            view(ViewerOptions { preset, quit_after_frames, overrides })
        }
        Some(Command::Presets) => {
            for (name, description) in preset::scene_descriptions() {
                println!("{name:<16} {description}");
            }
            ExitCode::SUCCESS
        }
        Some(Command::Bench { out, quick, threads }) => match rosette::bench::run(&out, quick, &threads) {
            Ok(_) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e:#}");
                ExitCode::from(EXIT_BAD_INPUT)
            }
        },
        Some(Command::Chart { out, quick }) => chart(out, quick),
        Some(Command::Card { fabric, out }) => cli::card(&fabric, &out),
        Some(Command::Compare { fabrics, scene, overrides, out }) => cli::compare(&fabrics, &scene, &overrides, &out),
        Some(Command::Fabric { action }) => fabric(action),
        Some(Command::Run { preset, mut overrides, duration, metrics, outline, step_log, max_steps, max_wall, fast, export, export_frames, screenshot }) => {
            if fast {
                overrides.push(FAST_PATH.to_string());
            }
            let outputs = RunOutputs {
                metrics: metrics.as_deref(),
                outline: outline.as_deref(),
                step_log: step_log.as_deref(),
                export: export.as_deref(),
                export_frames,
            };
            run(&preset, &overrides, &RunLimits { duration, max_steps, max_wall }, &outputs, &screenshot)
        }
    }
}

fn fabric(action: FabricAction) -> ExitCode {
    use rosette::fabric::{SheetKind, load_fabric, write};
    let bad = |e: &dyn std::fmt::Display| {
        eprintln!("error: {e}");
        ExitCode::from(EXIT_BAD_INPUT)
    };
    match action {
        FabricAction::Template { standard } => {
            let kind = match standard.as_deref() {
                None => None,
                Some(s) => match SheetKind::ALL.into_iter().find(|k| k.section() == s) {
                    Some(k) => Some(k),
                    None => return bad(&format!("--standard {s}: use kes, fast or cantilever")),
                },
            };
            print!("{}", write::template(kind));
            ExitCode::SUCCESS
        }
        FabricAction::List => {
            for b in rosette::scene::preset::FABRICS {
                match rosette::fabric::parse_fabric(b.text, b.name) {
                    Ok(f) => {
                        let mut sheets: Vec<&str> = f.sheets.sections().map(|s| s.kind.section()).collect();
                        sheets.extend(f.sheets.arcsim.as_ref().map(|_| "arcsim"));
                        let from = if sheets.is_empty() { "keys".to_string() } else { sheets.join("+") };
                        let who = match f.sheets.measured_by() {
                            Some(who) => format!("measured by {who}"),
                            None if sheets.is_empty() => "representative values".into(),
                            None => "typical of its class".into(),
                        };
                        println!("{:<24} {:<16} {:<52} {}", b.name, from, who, f.config.description);
                    }
                    Err(e) => println!("{:<20} error: {e}", b.name),
                }
            }
            ExitCode::SUCCESS
        }
        FabricAction::Import { sheet, out } => {
            if let Some(path) = out.as_deref().filter(|p| cli::same_file(&sheet, p)) {
                return bad(&format!("--out {}: is the file being imported; write the fabric to another file", path.display()));
            }
            let loaded = match load_fabric(&sheet) {
                Ok(f) => f,
                Err(e) => return bad(&e),
            };
            if loaded.sheets.is_empty() {
                return bad(&format!(
                    "{sheet}: no [kes], [fast] or [cantilever] section (nor an [arcsim] material) to import; `rosette fabric template` prints a sheet to fill in"
                ));
            }
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            let table = match toml::Table::try_from(&loaded.config) {
                Ok(t) => t,
                Err(e) => return bad(&e),
            };
            let text = write::fabric_file(&table, &loaded.sheets, &loaded.import, &sheet);
            match out {
                Some(path) => match std::fs::write(&path, text) {
                    Ok(()) => {
                        eprintln!("wrote {}", path.display());
                        ExitCode::SUCCESS
                    }
                    Err(e) => bad(&format!("cannot write {}: {e}", path.display())),
                },
                None => {
                    print!("{text}");
                    ExitCode::SUCCESS
                }
            }
        }
        FabricAction::Export { fabric, arcsim: _, out } => cli::export_arcsim(&fabric, out.as_deref()),
        FabricAction::Check { fabric } => {
            let loaded = match load_fabric(&fabric) {
                Ok(f) => f,
                Err(e) => return bad(&e),
            };
            if loaded.sheets.is_empty() {
                return bad(&format!("{fabric}: no measurement sheet to check against (its keys are written directly)"));
            }
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            match rosette::lab::readback(&loaded.sheets, &loaded.import, &loaded.config) {
                Ok(r) => {
                    print!("{}", r.table());
                    if r.all_pass() { ExitCode::SUCCESS } else { ExitCode::from(EXIT_READBACK) }
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(EXIT_DIVERGED)
                }
            }
        }
    }
}

fn chart(out: std::path::PathBuf, quick: bool) -> ExitCode {
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    match rosette::chart::run(&rosette::chart::ChartOptions { out, quick, threads }) {
        Ok(report) => {
            for line in &report.summary {
                println!("{line}");
            }
            for file in &report.files {
                eprintln!("wrote {}", file.display());
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

fn view(options: ViewerOptions) -> ExitCode {
    match rosette::app::viewer::run(options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

/// Where `rosette run` writes what it measured (nothing by default).
#[derive(Default)]
struct RunOutputs<'a> {
    metrics: Option<&'a str>,
    outline: Option<&'a str>,
    step_log: Option<&'a std::path::Path>,
    /// The glTF file, and how many frames of the run it animates (the final state alone
    /// when `None`).
    export: Option<&'a std::path::Path>,
    export_frames: Option<usize>,
}

/// Most frames an animated export may hold: each is a morph target, and the animation's
/// weights grow as the square of their number.
const MAX_EXPORT_FRAMES: usize = 1000;

/// How long `rosette run` may go on.
struct RunLimits {
    /// Simulated seconds, the scene's own when `None`.
    duration: Option<f64>,
    /// Steps, the scene's `scene.max_steps` when `None`.
    max_steps: Option<u64>,
    /// Wall-clock seconds.
    max_wall: f64,
}

impl Default for RunLimits {
    fn default() -> Self {
        Self { duration: None, max_steps: None, max_wall: DEFAULT_MAX_WALL }
    }
}

fn bad_input(message: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {message}");
    ExitCode::from(EXIT_BAD_INPUT)
}

fn run(spec: &str, overrides: &[String], limits: &RunLimits, outputs: &RunOutputs, shot: &ScreenshotArgs) -> ExitCode {
    let (metrics_out, outline_out) = (outputs.metrics, outputs.outline);
    // `--max-steps N` is `--set scene.max_steps=N`, so that the scene's checks see it.
    let mut overrides = overrides.to_vec();
    if let Some(n) = limits.max_steps {
        overrides.push(format!("scene.max_steps={n}"));
    }
    let config = match load_scene(spec, &overrides) {
        Ok((config, _)) => config,
        Err(e) => return bad_input(e),
    };
    if let Some(d) = limits.duration {
        if !(d.is_finite() && d > 0.0) {
            return bad_input(format!("--duration must be a positive number of seconds, got {d}"));
        }
        if let Err(e) = rosette::scene::validate::check_step_count("--duration", d, config.solver.dt, config.scene.max_steps) {
            return bad_input(e.message);
        }
    }
    if !(limits.max_wall.is_finite() && limits.max_wall > 0.0) {
        return bad_input(format!("--max-wall must be a positive number of seconds, got {}", limits.max_wall));
    }
    // Everything the run will write is checked before it starts, so that a typo in a path
    // does not cost the run (or turn its divergence into bad input).
    if outline_out.is_some() && config.scene.kind != rosette::scene::SceneKind::Drape {
        return bad_input(format!("--outline: {spec} is not a drape scene; only drape scenes have a shadow outline"));
    }
    let paths = [
        ("--metrics", metrics_out.filter(|m| *m != "-").map(std::path::Path::new)),
        ("--outline", outline_out.map(std::path::Path::new)),
        ("--screenshot", shot.screenshot.as_deref()),
        ("--export", outputs.export),
    ];
    for (option, path) in paths {
        if let Some(Err(e)) = path.map(|p| check_writable(option, p)) {
            return bad_input(format!("{e:#}"));
        }
    }
    if let Some(path) = shot.screenshot.as_deref().filter(|p| !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))) {
        return bad_input(format!("--screenshot {}: the picture is written as PNG; name the file FILE.png", path.display()));
    }
    if let Some(path) = outputs.export.filter(|p| !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))) {
        return bad_input(format!("--export {}: the cloth is written as glTF binary; name the file FILE.glb", path.display()));
    }
    if let Some(n) = outputs.export_frames.filter(|n| !(2..=MAX_EXPORT_FRAMES).contains(n)) {
        return bad_input(format!("--export-frames {n}: an animation needs 2 to {MAX_EXPORT_FRAMES} frames (leave it out for the final state alone)"));
    }
    // The step log is opened before the run, so that a bad path fails at once, and
    // written as the run goes, so that a run stopped early keeps its rows.
    let mut step_log = match outputs.step_log.map(open_step_log).transpose() {
        Ok(log) => log,
        Err(e) => return bad_input(format!("{e:#}")),
    };
    let mut scene = match Scene::build(config) {
        Ok(s) => s,
        Err(e) => return bad_input(format!("{spec}: {e}")),
    };
    let name = std::path::Path::new(spec).file_stem().map_or(spec.to_string(), |s| s.to_string_lossy().into_owned());
    // A progress bar only where someone watches, and only if the run lasts.
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(1000);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% ({elapsed}, eta {eta})")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(name.clone());
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        bar
    });
    let started = std::time::Instant::now();
    let mut on_progress = |fraction: f64| {
        if let Some(bar) = &bar {
            if bar.is_hidden() && started.elapsed().as_secs_f64() > 1.0 {
                bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
            }
            bar.set_position((fraction * 1000.0) as u64);
        }
    };
    let mut log_error: Option<std::io::Error> = None;
    let mut on_step = |record: &StepRecord| {
        if let (Some(out), None) = (step_log.as_mut(), &log_error) {
            log_error = writeln!(out, "{}", record.csv_row()).err();
        }
    };
    let mut recorder = outputs.export_frames.map(|n| {
        let mut r = rosette::export::Recorder::new(n, scene.state.time, limits.duration.unwrap_or(scene.config.scene.duration));
        r.observe(scene.state.time, &scene.state.x);
        r
    });
    let mut on_state = |s: &Scene| {
        if let Some(r) = recorder.as_mut() {
            r.observe(s.state.time, &s.state.x);
        }
    };
    let options = RunOptions {
        duration: limits.duration,
        progress: Some(&mut on_progress),
        on_step: Some(&mut on_step),
        max_steps: None,
        max_wall_seconds: Some(limits.max_wall),
        on_state: Some(&mut on_state),
    };
    let (metrics, error) = run_scene(&mut scene, &name, options);
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    // Every output is attempted, whatever failed before it: the run's results are kept.
    let mut output_failed = false;
    let mut fail = |e: anyhow::Error| {
        eprintln!("error: {e:#}");
        output_failed = true;
    };
    if let Err(e) = write_metrics(&metrics, metrics_out) {
        fail(e);
    }
    if let Some(Err(e)) = outline_out.map(|path| write_outline(&scene, path)) {
        fail(e);
    }
    // Checked once the run's metrics are saved: a log that fails mid-run (a full disk)
    // does not cost the run's results.
    if let Some(e) = log_error.or_else(|| step_log.as_mut().and_then(|out| out.flush().err())) {
        let path = outputs.step_log.expect("a log was written").display();
        fail(anyhow::anyhow!("cannot write the step log to {path}: {e}"));
    }
    if metrics_out.is_none() {
        eprintln!(
            "{name}: {} steps of {} s with {}, {:.3} s simulated in {:.2} s wall ({:.4} CPU s per 10 ms simulated)",
            metrics.steps, metrics.dt, metrics.integrator, metrics.simulated_seconds, metrics.wall_seconds, metrics.cpu_seconds_per_10ms
        );
        println!("{}", serde_json::to_string_pretty(&metrics.measures).expect("JSON values serialise"));
    }
    if let Some(path) = outputs.export {
        // The last good state (and the run up to it), also after a divergence.
        let frames = match recorder {
            Some(r) => r.finish(scene.state.time, &scene.state.x),
            None => vec![(scene.state.time, scene.state.x.clone())],
        };
        let cloth = rosette::export::Cloth { triangles: &scene.model.triangles, rest: &scene.model.rest, warp_angle: scene.model.warp_angle, name: &name };
        match rosette::export::write_glb(path, &cloth, &frames) {
            Ok(()) => eprintln!("wrote {} ({} frame{})", path.display(), frames.len(), if frames.len() == 1 { "" } else { "s" }),
            Err(e) => fail(anyhow::anyhow!("--export: {e}")),
        }
    }
    if let Some(path) = &shot.screenshot {
        // The last good state, also after a divergence.
        let options = render::Screenshot { path: path.clone(), size: shot.size, view: shot.camera, color_map: shot.colormap, wireframe: shot.wireframe };
        if let Err(e) = render::save_screenshot(&scene, &options) {
            fail(anyhow::anyhow!("screenshot: {e}"));
        }
    }
    // The run's own outcome first: a diverged, cut-short or unconverged run is what the
    // caller most needs to know; an output that failed is said above.
    if let Some(e) = error {
        eprintln!("error: {e}");
        return ExitCode::from(EXIT_DIVERGED);
    }
    if let Some(reason) = &metrics.stopped_at_limit {
        eprintln!("error: {name}: {reason}; the results cover {:.4} s", metrics.simulated_seconds);
        return ExitCode::from(EXIT_STOPPED);
    }
    if !metrics.converged {
        eprintln!(
            "error: {name}: Newton did not converge on {} steps (its last step reached {:.2e} of an edge, the tolerance is {:.0e}): \
             the results are not trustworthy; raise solver.newton.max_iterations or use a smaller solver.dt",
            metrics.newton_limit_steps, metrics.worst_residual, scene.integrator.newton.tolerance
        );
        return ExitCode::from(EXIT_NOT_CONVERGED);
    }
    if output_failed {
        return ExitCode::from(EXIT_NO_OUTPUT);
    }
    ExitCode::SUCCESS
}

/// Checks before a run that `path` can be written: a file can be created there (and is
/// removed again if it was not there before), or the file that is there can be opened for
/// writing, without truncating it.
fn check_writable(option: &str, path: &std::path::Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("{option} {}: is a folder; give a file name", path.display());
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("{option} {}: cannot write there", path.display()))?;
    if !existed {
        std::fs::remove_file(path).ok();
    }
    Ok(())
}

/// Creates the step log and writes its header.
fn open_step_log(path: &std::path::Path) -> anyhow::Result<std::io::BufWriter<std::fs::File>> {
    let file = std::fs::File::create(path).with_context(|| format!("cannot create the step log {}", path.display()))?;
    let mut out = std::io::BufWriter::new(file);
    writeln!(out, "{}", StepRecord::CSV_HEADER).with_context(|| format!("cannot write the step log {}", path.display()))?;
    Ok(out)
}

fn write_outline(scene: &Scene, path: &str) -> anyhow::Result<()> {
    let outline = scene
        .rig
        .outline(&scene.model, &scene.state)
        .with_context(|| format!("--outline: {} is not a drape scene; only drape scenes have a shadow outline", scene.config.scene.description))?;
    let mut text = String::from("angle_deg,radius_m\n");
    for (angle, radius) in outline {
        text += &format!("{:.2},{radius:.6}\n", angle.to_degrees());
    }
    std::fs::write(path, text).with_context(|| format!("cannot write the outline to {path}"))
}

fn write_metrics(metrics: &rosette::scene::Metrics, out: Option<&str>) -> anyhow::Result<()> {
    let Some(out) = out else { return Ok(()) };
    let text = serde_json::to_string_pretty(metrics)?;
    if out == "-" {
        let mut stdout = std::io::stdout().lock();
        writeln!(stdout, "{text}")?;
    } else {
        std::fs::write(out, text + "\n").with_context(|| format!("cannot write metrics to {out}"))?;
    }
    Ok(())
}
