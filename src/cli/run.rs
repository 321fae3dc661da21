//! `rosette run`: a scene headless, its outputs checked before the run and written whole
//! after it, and an exit code that says how it ended.

use super::outputs::{self, GLTF, METRICS, OUTLINE, PICTURE, STEP_LOG};
use super::{EXIT_DIVERGED, EXIT_NO_OUTPUT, EXIT_NOT_CONVERGED, EXIT_NOT_SEWN, EXIT_OFF_FORM, EXIT_STOPPED, bad_input, say_error};
use super::args::{DEFAULT_MAX_WALL, ScreenshotArgs};
use rosette::io::guard::Plan;
use rosette::io::number::short;
use rosette::io::write::Output;
use rosette::scene::{RunFlags, load_scene_with};
use rosette::scene::{RunOptions, Scene, SceneConfig, StepRecord, possible, run_scene};
use rosette::{errln, outln, render};
use std::io::{IsTerminal, Write};
use std::path::Path;
use std::sync::Arc;
use std::process::ExitCode;

/// Where `rosette run` writes what it measured (nothing by default).
#[derive(Default)]
pub struct RunOutputs<'a> {
    pub metrics: Option<&'a str>,
    pub outline: Option<&'a str>,
    pub step_log: Option<&'a Path>,
    /// The glTF file, and how many frames of the run it animates (the final state alone
    /// when `None`).
    pub export: Option<&'a Path>,
    pub export_frames: Option<usize>,
    /// Replace existing files that are not Rosette's own output.
    pub force: bool,
}

/// Most frames an animated export may hold: each is a morph target, and the animation's
/// weights grow as the square of their number.
const MAX_EXPORT_FRAMES: usize = 1000;

/// How long `rosette run` may go on.
pub struct RunLimits {
    /// Simulated seconds, the scene's own when `None`.
    pub duration: Option<f64>,
    /// Steps, the scene's `scene.max_steps` when `None`.
    pub max_steps: Option<u64>,
    /// Wall-clock seconds.
    pub max_wall: f64,
}

impl Default for RunLimits {
    fn default() -> Self {
        Self { duration: None, max_steps: None, max_wall: DEFAULT_MAX_WALL }
    }
}

/// The outputs `run` will write, checked against its inputs, each other and the files
/// already there; also the formats their names promise.
fn plan_outputs(config: &SceneConfig, spec: &str, outputs: &RunOutputs, shot: &ScreenshotArgs) -> Result<(), String> {
    if outputs.outline.is_some() && !rosette::scene::kinds::of(config.scene.kind).writes_outline() {
        return Err(format!("--outline: {spec} is not a drape scene; only drape scenes have a shadow outline"));
    }
    if let Some(path) = shot.screenshot.as_deref().filter(|p| !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))) {
        return Err(format!("--screenshot {}: the picture is written as PNG; name the file FILE.png", path.display()));
    }
    if let Some(path) = outputs.export.filter(|p| !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))) {
        return Err(format!("--export {}: the cloth is written as glTF binary; name the file FILE.glb", path.display()));
    }
    if let Some(n) = outputs.export_frames.filter(|n| !(2..=MAX_EXPORT_FRAMES).contains(n)) {
        return Err(format!("--export-frames {n}: an animation needs 2 to {MAX_EXPORT_FRAMES} frames (leave it out for the final state alone)"));
    }
    let mut plan = Plan::new(outputs.force);
    let files = [
        ("--metrics", outputs.metrics.filter(|m| *m != "-").map(Path::new), METRICS),
        ("--outline", outputs.outline.map(Path::new), OUTLINE),
        ("--step-log", outputs.step_log, STEP_LOG),
        ("--screenshot", shot.screenshot.as_deref(), PICTURE),
        ("--export", outputs.export, GLTF),
    ];
    for (flag, path, kind) in files {
        if let Some(path) = path {
            plan.add(flag, path, kind);
        }
    }
    outputs::check(&plan, &[config])?;
    if let (Some(_), Some((_, _, Some(distance)))) = (&shot.screenshot, shot.camera) {
        possible::check_camera(config, distance, shot.size[1], render::Camera::default().fov_y)?;
    }
    Ok(())
}

/// Loads the scene for `run` and checks everything before any work: the flags, the scene,
/// the outputs and the props' start. The scene is built.
/// `rosette run SCENE --plan`: the scene's run plan in words, nothing run or written.
pub fn print_plan(spec: &str, overrides: &[String], duration: Option<f64>) -> ExitCode {
    let flags = RunFlags { duration, max_steps: None };
    match load_scene_with(spec, overrides, &flags) {
        Ok((checked, _)) => {
            outln!("{spec}: {}", checked.plan().describe(&checked).trim_end());
            ExitCode::SUCCESS
        }
        Err(e) => bad_input(e),
    }
}

fn prepare(spec: &str, overrides: &[String], limits: &RunLimits, outputs: &RunOutputs, shot: &ScreenshotArgs) -> Result<Scene, String> {
    if let Some(d) = limits.duration.filter(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(format!("--duration must be a positive number of seconds, got {}", short(d)));
    }
    if !(limits.max_wall.is_finite() && limits.max_wall > 0.0) {
        return Err(format!("--max-wall must be a positive number of seconds, got {}", short(limits.max_wall)));
    }
    let flags = RunFlags { duration: limits.duration, max_steps: limits.max_steps };
    let (config, _) = load_scene_with(spec, overrides, &flags).map_err(|e| e.to_string())?;
    plan_outputs(&config, spec, outputs, shot)?;
    let scene = Scene::build(config).map_err(|e| format!("{spec}: {e}"))?;
    possible::check_start(&scene).map_err(|e| format!("{spec}: {e}"))?;
    Ok(scene)
}

/// Bounds the work before the first step (reading, checking, meshing, building the
/// model) by `--max-wall` and by Ctrl-C: past the bound, or on a signal, the process says
/// so and exits (6, or 128 + the signal) with nothing written, for nothing has been yet.
/// The checks refuse what they can estimate; this bounds what they cannot.
struct Watchdog {
    done: Arc<std::sync::atomic::AtomicBool>,
}

impl Watchdog {
    fn start(limit: f64) -> Watchdog {
        let done = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let flag = Arc::clone(&done);
        let started = std::time::Instant::now();
        std::thread::spawn(move || {
            while !flag.load(std::sync::atomic::Ordering::SeqCst) {
                if let Some(signal) = rosette::io::interrupt::received() {
                    say_error(format!("stopped by {} while preparing the scene; nothing was run or written", rosette::io::interrupt::name(signal)));
                    std::process::exit(128 + signal);
                }
                if started.elapsed().as_secs_f64() > limit {
                    say_error(format!("stopped after {limit} s of wall time preparing the scene, the bound --max-wall (raise it); nothing was run or written"));
                    std::process::exit(i32::from(EXIT_STOPPED));
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
        });
        Watchdog { done }
    }

    fn stop(self) {
        self.done.store(true, std::sync::atomic::Ordering::SeqCst);
    }
}

/// Creates the step log (staged beside its name until the run ends) and writes its header.
fn open_step_log(path: &Path) -> Result<Output, String> {
    let mut out = Output::open(path).map_err(|e| format!("--step-log {}: cannot create it: {e}", path.display()))?;
    writeln!(out, "{}", StepRecord::CSV_HEADER).map_err(|e| format!("--step-log {}: cannot write it: {e}", path.display()))?;
    Ok(out)
}

/// A progress bar, hidden until shown, only where someone watches (stderr a terminal).
fn progress_bar(name: &str) -> Option<indicatif::ProgressBar> {
    std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(1000);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {percent}% ({elapsed}, eta {eta})")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(name.to_string());
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
        bar
    })
}

pub fn run(spec: &str, overrides: &[String], limits: &RunLimits, outputs: &RunOutputs, shot: &ScreenshotArgs) -> ExitCode {
    let building = std::time::Instant::now();
    rosette::io::interrupt::catch();
    let watch = Watchdog::start(limits.max_wall);
    let prepared = prepare(spec, overrides, limits, outputs, shot);
    watch.stop();
    let mut scene = match prepared {
        Ok(scene) => scene,
        Err(e) => return bad_input(e),
    };
    // The step log is written as the run goes (beside its name), so that a run stopped
    // early keeps its rows, and put in place when the run ends.
    let mut step_log = match outputs.step_log.map(open_step_log).transpose() {
        Ok(log) => log,
        Err(e) => return bad_input(e),
    };
    let name = Path::new(spec).file_stem().map_or(spec.to_string(), |s| s.to_string_lossy().into_owned());
    let bar = progress_bar(&name);
    // Shown only if the run lasts.
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
        r.observe(scene.state.time, scene.topology(), &scene.state.x);
        r
    });
    let mut on_state = |s: &Scene| {
        if let Some(r) = recorder.as_mut() {
            r.observe(s.state.time, s.topology(), &s.state.x);
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
    let build_seconds = building.elapsed().as_secs_f64();
    let (mut metrics, error) = run_scene(&mut scene, &name, options);
    metrics.build_seconds = Some(build_seconds);
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    // Every output is attempted, whatever failed before it: the run's results are kept.
    let mut output_failed = false;
    let mut fail = |e: String| {
        say_error(&e);
        output_failed = true;
    };
    if let Err(e) = write_metrics(&metrics, outputs.metrics) {
        fail(e);
    }
    if let Some(Err(e)) = outputs.outline.map(|path| write_outline(&scene, path)) {
        fail(e);
    }
    // Put in place once the run's metrics are saved: a log that fails mid-run (a full
    // disk) does not cost the run's results.
    if let (Some(log), Some(path)) = (step_log, outputs.step_log)
        && let Some(e) = log_error.map(Err).unwrap_or_else(|| log.finish()).err()
    {
        fail(format!("--step-log {}: cannot write the step log: {e}", path.display()));
    }
    for note in &metrics.notes {
        errln!("note: {name}: {note}");
    }
    if outputs.metrics.is_none() {
        errln!(
            "{name}: {} steps of {} s with {}, {:.3} s simulated in {:.2} s wall ({:.4} CPU s per 10 ms simulated), after {:.2} s building the scene",
            metrics.steps,
            short(metrics.dt),
            metrics.integrator,
            metrics.simulated_seconds,
            metrics.wall_seconds,
            metrics.cpu_seconds_per_10ms,
            build_seconds
        );
        outln!("{}", serde_json::to_string_pretty(&metrics.measures).expect("JSON values serialise"));
    }
    if let Some(path) = outputs.export {
        // The last good state (and the run up to it), also after a divergence.
        let frames = match recorder {
            Some(r) => r.finish(scene.state.time, scene.topology(), &scene.state.x),
            None => vec![rosette::export::ClothFrame { time: scene.state.time, topology: Arc::clone(scene.topology()), positions: scene.state.x.clone() }],
        };
        let look = rosette::appearance::Look::or_default(&scene.config.fabric.appearance, scene.config.base_dir.as_deref());
        match rosette::export::write_glb(path, &name, &frames, &look) {
            Ok(()) => errln!("wrote {} ({} frame{})", path.display(), frames.len(), if frames.len() == 1 { "" } else { "s" }),
            Err(e) => fail(format!("--export: {e}")),
        }
    }
    if let Some(path) = &shot.screenshot {
        // The last good state, also after a divergence.
        let options = render::Screenshot { path: path.clone(), size: shot.size, view: shot.camera, color_map: shot.colormap, wireframe: shot.wireframe };
        if let Err(e) = render::save_screenshot(&scene, &options) {
            fail(format!("--screenshot: {e}"));
        }
    }
    outcome(&name, &scene, &metrics, error, output_failed)
}

/// The exit code and its message: the run's own outcome first (a diverged, cut-short or
/// unconverged run is what the caller most needs to know), then a lost output, then what
/// the garment came to (not sewn): results the user cannot find outrank results that are
/// there and say they are unfinished.
fn outcome(name: &str, scene: &Scene, metrics: &rosette::scene::Metrics, error: Option<rosette::sim::StepError>, output_failed: bool) -> ExitCode {
    if let Some(e) = error {
        say_error(&e);
        return ExitCode::from(EXIT_DIVERGED);
    }
    if let Some(reason) = &metrics.stopped_at_limit {
        say_error(format!("{name}: {reason}; the results cover {:.4} s", metrics.simulated_seconds));
        let signal = rosette::io::interrupt::received().and_then(|s| u8::try_from(128 + s).ok());
        return ExitCode::from(signal.unwrap_or(EXIT_STOPPED));
    }
    if !metrics.converged {
        errln!(
            "error: {name}: Newton did not converge on {} steps (its last step reached {:.2e} of an edge, the tolerance is {:.0e}): \
             the results are not trustworthy; {}",
            metrics.newton_limit_steps,
            metrics.worst_residual,
            scene.integrator.newton.tolerance,
            unconverged_advice(scene)
        );
        return ExitCode::from(EXIT_NOT_CONVERGED);
    }
    let lost = ExitCode::from(EXIT_NO_OUTPUT);
    if let Some(garment) = metrics.measures.garment().filter(|g| !g.sewn) {
        let sewing_time = scene.config.garment.as_ref().map_or(f64::INFINITY, |g| g.sewing_time);
        let ended = scene.state.time;
        // A run cut short before the sewing time is unfinished, not a garment that cannot
        // be sewn: say which.
        let message = if ended + 1e-9 < sewing_time {
            format!(
                "{name}: the garment is not sewn yet: the run ended at {ended:.3} s, before garment.sewing_time = {sewing_time} s, with a seam still {:.1} mm open, \
                 and what was drawn is unfinished; run at least until the sewing time (--duration)",
                1e3 * garment.open_seam_gap
            )
        } else {
            format!(
                "{name}: the garment was not sewn: a seam was still {:.1} mm open at garment.sewing_time, and what was drawn is unfinished; \
                 give the seams more time (garment.sewing_time) or stiffer springs (garment.sewing_stiffness), or place the panels nearer their seams",
                1e3 * garment.open_seam_gap
            )
        };
        say_error(message);
        return if output_failed { lost } else { ExitCode::from(EXIT_NOT_SEWN) };
    }
    if let Some(reason) = metrics.measures.garment().and_then(|g| g.off_form.as_ref()) {
        say_error(format!("{name}: {reason}"));
        return if output_failed { lost } else { ExitCode::from(EXIT_OFF_FORM) };
    }
    if output_failed { lost } else { ExitCode::SUCCESS }
}

/// What to change when Newton stops short: the limits the scene or its run plan lowered
/// below their defaults first, then more iterations, then a shorter step (never what the
/// run already has).
fn unconverged_advice(scene: &Scene) -> String {
    let config = &scene.config;
    let n = &config.solver.newton;
    let defaults = rosette::sim::NewtonSettings::default();
    let mut advice = Vec::new();
    if n.cg_max_iterations < defaults.cg_max_iterations {
        advice.push(format!(
            "raise solver.newton.cg_max_iterations (now {}, default {}): the linear solves stop short",
            n.cg_max_iterations, defaults.cg_max_iterations
        ));
    }
    // The run plan's own, lower limit (a garment's on the fast path), as the plan recorded it.
    if let Some(choice) = scene.plan_choices().iter().find(|c| c.key == "solver.newton.cg_max_iterations" && !c.kept) {
        advice.push(format!("raise solver.fast.cg_max_iterations (now {}): the run plan stops this scene's linear solves there on the fast path", choice.value));
    }
    if n.cg_tolerance > defaults.cg_tolerance {
        advice.push(format!("lower solver.newton.cg_tolerance (now {}, default {})", short(n.cg_tolerance), short(defaults.cg_tolerance)));
    }
    advice.push(format!("raise solver.newton.max_iterations (now {})", n.max_iterations));
    advice.push(format!("or use a smaller solver.dt (now {} s)", short(config.solver.dt)));
    advice.join("; ")
}

fn write_outline(scene: &Scene, path: &str) -> Result<(), String> {
    let outline = scene
        .rig
        .outline(&scene.model, &scene.state)
        .ok_or_else(|| format!("--outline: {} is not a drape scene; only drape scenes have a shadow outline", scene.config.scene.description))?;
    let mut text = String::from("angle_deg,radius_m\n");
    for (angle, radius) in outline {
        text += &format!("{:.2},{radius:.6}\n", angle.to_degrees());
    }
    rosette::io::write::whole(Path::new(path), text.as_bytes()).map_err(|e| format!("--outline {path}: cannot write the outline: {e}"))
}

fn write_metrics(metrics: &rosette::scene::Metrics, out: Option<&str>) -> Result<(), String> {
    let Some(out) = out else { return Ok(()) };
    let text = serde_json::to_string_pretty(metrics).map_err(|e| e.to_string())? + "\n";
    if out == "-" {
        // A failure here is standard output's, reported once at the end (exit 4).
        rosette::io::stdout::write(&text);
        return Ok(());
    }
    rosette::io::write::whole(Path::new(out), text.as_bytes()).map_err(|e| format!("--metrics {out}: cannot write the metrics: {e}"))
}
