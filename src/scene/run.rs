//! Running a scene to its end: the step loop, divergence handling and the metrics report.

use super::{Measures, Scene};
use crate::sim::{StepError, StepReport, StepTimings};
use serde::{Deserialize, Deserializer, Serialize};
use std::time::Instant;

/// What a run reports (written as JSON by `rosette run --metrics`, and read back from it
/// by `rosette bench`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Metrics {
    pub preset: String,
    pub integrator: String,
    /// Time step, s (the first, with adaptive steps: `simulated_seconds / steps` is their mean).
    pub dt: f64,
    pub vertices: usize,
    pub triangles: usize,
    pub simulated_seconds: f64,
    pub steps: u64,
    /// Wall seconds of the steps, from the first (the time to settle in the notes and
    /// tables).
    pub wall_seconds: f64,
    /// Wall seconds `rosette run` took to build the scene before its first step (meshing,
    /// the model, the start checks): with `wall_seconds`, what its user waited.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build_seconds: Option<f64>,
    /// CPU seconds of this process per simulated second.
    pub cpu_seconds_per_simulated_second: f64,
    /// CPU seconds per 10 ms simulated, the unit of the paper's Table 1.
    pub cpu_seconds_per_10ms: f64,
    /// False where a step diverged (`error` says how); the run stopped there.
    pub stable: bool,
    /// Whether every step's Newton solve converged: its last Newton step was within
    /// `UNCONVERGED_FACTOR` times the tolerance it stopped at (`StepReport::converged`).
    /// A run that is stable but not converged has results that the solver's limits, not
    /// the physics, decided.
    pub converged: bool,
    /// Steps that stopped at Newton's iteration limit (or left a contact unresolved after
    /// four solves).
    pub newton_limit_steps: u64,
    /// The largest of the steps' last Newton step (largest vertex move) over the mean edge
    /// length, the measure of `solver.newton.tolerance`; 0 for the explicit integrator.
    pub worst_residual: f64,
    /// Why the run stopped before its end at a bound (`--max-steps`, `--max-wall`), if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped_at_limit: Option<String>,
    /// Whether the run stopped early because the cloth settled (absent when settling is
    /// not watched: `scene.settle_speed` unset).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settled: Option<bool>,
    /// Time at which the cloth settled, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub settle_time: Option<f64>,
    /// Why the run stopped early, if it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Deepest any vertex went inside a prop over the run, m (scenes with contact).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_penetration: Option<f64>,
    /// Edge–triangle crossings of the cloth with itself in the final state (scenes with
    /// contact).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_intersections: Option<usize>,
    /// Steps solved again for a contact the prediction missed, and crossings stopped by
    /// the self-collision fail-safe.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_events: Option<ContactEvents>,
    pub newton_iterations: u64,
    /// Iterations of the quasi-Newton step (`solver.newton.minimizer = "quasi-newton"`).
    #[serde(default)]
    pub quasi_newton_iterations: u64,
    pub cg_iterations: u64,
    /// Preconditioners built for the linear solves (factorisations).
    pub factorizations: u64,
    /// Peak resident memory of the process, bytes (Linux; absent elsewhere).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_bytes: Option<u64>,
    /// Steps the adaptive control took again with a smaller Δt.
    pub rejected_steps: u64,
    /// Seconds of the run spent in each phase of the steps.
    #[serde(deserialize_with = "step_timings")]
    pub step_time: StepTimings,
    pub measures: Measures,
    /// What the run could not measure or did not reach, one sentence each
    /// (`possible::judge`): a measure left out of `measures` is explained here.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Every setting the run plan chose over the scene's value, and every value of the
    /// user's it kept although it would have chosen another, on the scene's own mesh
    /// (`plan::Choice`; `rosette run --plan` prints them per level).
    #[serde(default, skip_serializing_if = "Vec::is_empty", deserialize_with = "plan_choices")]
    pub plan_overrides: Vec<super::plan::Choice>,
}

/// Reads `Metrics::plan_overrides` back as their sentences are not needed by a reader:
/// each entry is kept whole as written.
fn plan_choices<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<super::plan::Choice>, D::Error> {
    let _ = Vec::<serde_json::Value>::deserialize(deserializer)?;
    Ok(Vec::new())
}

/// What the contact handling had to do over a run (`Metrics::contact_events`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ContactEvents {
    /// Crossings stopped by the self-collision fail-safe (impact zones).
    pub impacts: u64,
    /// Steps solved again for a contact the prediction missed.
    pub resolves: u64,
}

/// Reads `Metrics::step_time` back: the solver's `StepTimings` only serialises (the
/// physics has no need to read it), so its fields are named here; a field the metrics
/// lack is an error, not a zero.
fn step_timings<'de, D: Deserializer<'de>>(deserializer: D) -> Result<StepTimings, D::Error> {
    #[derive(Deserialize)]
    struct Phases {
        forces: f64,
        solve: f64,
        contact: f64,
    }
    let Phases { forces, solve, contact } = Phases::deserialize(deserializer)?;
    Ok(StepTimings { forces, solve, contact })
}

/// How to run a scene; `RunOptions::default()` runs it for its own duration, silently.
#[derive(Default)]
pub struct RunOptions<'a> {
    /// Simulated time, s; the scene's own when `None`.
    pub duration: Option<f64>,
    /// Called with the fraction done, now and then.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
    /// Called after every step that stood, with what it cost.
    pub on_step: Option<&'a mut dyn FnMut(&StepRecord)>,
    /// Most steps the run may take; the scene's `scene.max_steps` when `None`.
    pub max_steps: Option<u64>,
    /// Wall-clock seconds after which the run stops; unbounded when `None`.
    pub max_wall_seconds: Option<f64>,
    /// Called after every step that stood, with the scene as it is then (`rosette run
    /// --export-frames` samples the cloth from it).
    pub on_state: Option<&'a mut dyn FnMut(&Scene)>,
}


/// One step of a run: what it cost and how fast the cloth moved (`rosette run --step-log`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepRecord {
    /// Steps taken so far, this one included.
    pub step: u64,
    /// Simulated time at the end of the step, s.
    pub time: f64,
    /// The step's Δt, s.
    pub dt: f64,
    pub newton_iterations: usize,
    pub quasi_newton_iterations: usize,
    pub cg_iterations: usize,
    pub factorizations: usize,
    /// The largest shift Newton's matrix took, as a share of the inertia (0 where none).
    pub shift: f64,
    /// Whether Newton stopped at its iteration limit.
    pub newton_unconverged: bool,
    /// Newton's last step over the mean edge length (see `Metrics::worst_residual`).
    pub newton_residual: f64,
    /// Mass-weighted RMS speed of the cloth after the step, m/s.
    pub rms_speed: f64,
    /// Process CPU seconds since the run began.
    pub cpu_seconds: f64,
    /// Wall seconds of the step by phase.
    pub timings: StepTimings,
}

impl StepRecord {
    /// The CSV header matching `csv_row`.
    pub const CSV_HEADER: &'static str =
        "step,time_s,dt_s,newton,cg,factorizations,shift,newton_unconverged,rms_speed_m_s,cpu_s,forces_s,solve_s,contact_s,newton_residual,quasi_newton";

    pub fn csv_row(&self) -> String {
        let t = &self.timings;
        format!(
            "{},{},{:e},{},{},{},{},{},{:.4e},{:.4},{:.3e},{:.3e},{:.3e},{:.3e},{}",
            self.step,
            self.time,
            self.dt,
            self.newton_iterations,
            self.cg_iterations,
            self.factorizations,
            self.shift,
            self.newton_unconverged as u8,
            self.rms_speed,
            self.cpu_seconds,
            t.forces,
            t.solve,
            t.contact,
            self.newton_residual,
            self.quasi_newton_iterations
        )
    }
}

impl Scene {
    /// The cloth's mass-weighted RMS speed √(2 KE / M), m/s: what settling is judged by.
    pub fn rms_speed(&self) -> f64 {
        let total_mass: f64 = self.model.mass.iter().sum();
        (2.0 * self.state.kinetic_energy(&self.model) / total_mass).sqrt()
    }
}

/// Watches a scene for settling (`scene.settle_speed`): the cloth's mass-weighted RMS
/// speed stays below that speed for `scene.settle_window` seconds, once every prescribed
/// motion and the gravity ramp are done. `rosette run` then stops, and the viewer pauses.
#[derive(Debug, Clone)]
pub struct SettleWatch {
    speed: Option<f64>,
    window: f64,
    gravity_ramp: Option<f64>,
    /// Start of the current run of slow steps.
    slow_since: Option<f64>,
    /// When the cloth settled: the start of the slow run that lasted the window.
    pub settled_at: Option<f64>,
}

impl SettleWatch {
    pub fn new(scene: &Scene) -> Self {
        let s = &scene.config.scene;
        Self {
            speed: s.settle_speed,
            window: s.settle_window,
            gravity_ramp: s.gravity_ramp,
            slow_since: None,
            settled_at: None,
        }
    }

    /// Whether the scene asks for settling to be watched.
    pub fn watched(&self) -> bool {
        self.speed.is_some()
    }

    /// Takes the state after a step, whose RMS speed is `rms`; the time the cloth settled
    /// once it has. On the fast path only the scene's own mesh counts (its coarser levels
    /// settle on their way to it).
    pub fn observe(&mut self, scene: &Scene, rms: f64) -> Option<f64> {
        if !scene.at_final_level() {
            self.slow_since = None;
            return None;
        }
        self.observe_level(scene, rms)
    }

    /// Restarts the count of slow steps (something outside the scene, such as the mouse,
    /// holds the cloth).
    pub fn interrupt(&mut self) {
        self.slow_since = None;
    }

    /// As `observe`, on whatever level the scene is.
    pub(super) fn observe_level(&mut self, scene: &Scene, rms: f64) -> Option<f64> {
        let limit = self.speed?;
        if self.settled_at.is_some() {
            return self.settled_at;
        }
        let t = scene.state.time;
        let loads_done = self.gravity_ramp.is_none_or(|ramp| t >= ramp);
        if rms < limit && scene.model.motions_finished(t) && loads_done {
            let since = *self.slow_since.get_or_insert(t);
            if t - since >= self.window {
                self.settled_at = Some(since);
            }
        } else {
            self.slow_since = None;
        }
        self.settled_at
    }
}

/// Steps `scene` to the end of its duration. A divergence stops the run with the last good
/// state kept; it is reported in the metrics (`stable: false`) and returned.
pub fn run_scene(scene: &mut Scene, name: &str, options: RunOptions) -> (Metrics, Option<StepError>) {
    let duration = options.duration.unwrap_or(scene.config.scene.duration);
    let dt = scene.integrator.dt;
    let end_time = scene.state.time + duration;
    let mut progress = options.progress;
    let mut on_step = options.on_step;
    let mut on_state = options.on_state;
    let wall = Instant::now();
    let cpu = cpu_time::ProcessTime::now();
    let start_time = scene.state.time;
    let mut tally = Tally::default();
    let mut error = None;
    let mut settle = SettleWatch::new(scene);
    let mut k = 0u64;
    let mut stopped_at_limit = None;
    let max_steps = options.max_steps.unwrap_or(scene.config.scene.max_steps);
    // The bound holds within a step too: past it Newton starts no further iteration.
    let before = scene.deadline;
    scene.deadline = options.max_wall_seconds.and_then(|limit| std::time::Duration::try_from_secs_f64(limit).ok()).and_then(|limit| wall.checked_add(limit));
    // Steps until the end time is reached (a fixed Δt that does not divide the duration
    // ends past it).
    while scene.state.time < end_time - 1e-6 * scene.integrator.dt {
        if k >= max_steps {
            stopped_at_limit = Some(format!("stopped after {k} steps, the bound scene.max_steps (raise it with --max-steps)"));
            break;
        }
        if let Some(limit) = options.max_wall_seconds.filter(|&limit| wall.elapsed().as_secs_f64() > limit) {
            stopped_at_limit = Some(format!("stopped after {limit} s of wall time, the bound --max-wall (raise it)"));
            break;
        }
        if let Some(signal) = crate::io::interrupt::received() {
            stopped_at_limit = Some(format!("stopped by {} after {k} steps", crate::io::interrupt::name(signal)));
            break;
        }
        k += 1;
        let report = match scene.step() {
            Ok(report) => report,
            Err(e) => {
                error = Some(e);
                break;
            }
        };
        tally.add(&report);
        let rms = scene.rms_speed();
        if let Some(f) = on_step.as_deref_mut() {
            f(&StepRecord::new(scene, &report, rms, cpu.elapsed().as_secs_f64()));
        }
        if let Some(f) = on_state.as_deref_mut() {
            f(scene);
        }
        if settle.observe(scene, rms).is_some() {
            break;
        }
        if let (Some(p), true) = (progress.as_deref_mut(), k.is_multiple_of(16)) {
            p(((scene.state.time - start_time) / duration).min(1.0));
        }
    }
    scene.deadline = before;
    let cpu_seconds = cpu.elapsed().as_secs_f64();
    let simulated = scene.state.time - start_time;
    let per_second = if simulated > 0.0 { cpu_seconds / simulated } else { 0.0 };
    let mut metrics = Metrics {
        preset: name.to_string(),
        integrator: scene.integrator.kind.name().to_string(),
        dt,
        vertices: scene.model.vertex_count(),
        triangles: scene.model.triangle_count(),
        simulated_seconds: simulated,
        steps: scene.state.steps,
        wall_seconds: wall.elapsed().as_secs_f64(),
        build_seconds: None,
        cpu_seconds_per_simulated_second: per_second,
        cpu_seconds_per_10ms: per_second * 0.01,
        stable: error.is_none(),
        converged: tally.unconverged == 0,
        newton_limit_steps: tally.limit_steps,
        worst_residual: tally.worst_residual,
        stopped_at_limit,
        settled: settle.watched().then_some(settle.settled_at.is_some()),
        settle_time: settle.settled_at,
        error: error.as_ref().map(|e| e.to_string()),
        max_penetration: scene.model.contact.as_ref().map(|_| scene.integrator.contact_stats.max_penetration),
        self_intersections: scene
            .model
            .contact
            .as_ref()
            .map(|_| crate::sim::contact::count_self_intersections(&scene.state.x, &scene.model.triangles, &scene.model.edges)),
        contact_events: scene.model.contact.as_ref().map(|_| {
            let s = scene.integrator.contact_stats;
            ContactEvents { impacts: s.impacts, resolves: s.resolves }
        }),
        newton_iterations: tally.newton,
        quasi_newton_iterations: tally.quasi_newton,
        cg_iterations: tally.cg,
        factorizations: tally.factorizations,
        rejected_steps: tally.rejected,
        peak_memory_bytes: peak_memory_bytes(),
        step_time: tally.step_time,
        measures: scene.measures(),
        notes: Vec::new(),
        plan_overrides: scene.plan_choices().to_vec(),
    };
    super::possible::judge(scene, &mut metrics, duration);
    (metrics, error)
}

/// The counts a run sums over its steps.
#[derive(Default)]
struct Tally {
    newton: u64,
    quasi_newton: u64,
    cg: u64,
    factorizations: u64,
    step_time: StepTimings,
    rejected: u64,
    /// Steps whose Newton stopped at its iteration limit.
    limit_steps: u64,
    worst_residual: f64,
    /// Steps that did not converge to their tolerance.
    unconverged: u64,
}

impl Tally {
    fn add(&mut self, report: &StepReport) {
        self.newton += report.newton_iterations as u64;
        self.quasi_newton += report.quasi_newton_iterations as u64;
        self.cg += report.cg_iterations as u64;
        self.factorizations += report.factorizations as u64;
        self.step_time += report.timings;
        self.rejected += report.rejected as u64;
        self.limit_steps += u64::from(report.newton_unconverged);
        self.worst_residual = self.worst_residual.max(report.newton_residual);
        self.unconverged += u64::from(!report.converged());
    }
}

impl StepRecord {
    /// The record of the step `report` just took `scene` through.
    fn new(scene: &Scene, report: &StepReport, rms_speed: f64, cpu_seconds: f64) -> Self {
        StepRecord {
            step: scene.state.steps,
            time: scene.state.time,
            dt: report.dt,
            newton_iterations: report.newton_iterations,
            quasi_newton_iterations: report.quasi_newton_iterations,
            cg_iterations: report.cg_iterations,
            factorizations: report.factorizations,
            shift: report.shift,
            newton_unconverged: report.newton_unconverged,
            newton_residual: report.newton_residual,
            rms_speed,
            cpu_seconds,
            timings: report.timings,
        }
    }
}

/// The process's peak resident set (VmHWM in /proc/self/status), bytes.
fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
