//! The simulation worker: a named thread that owns the [`Scene`], takes [`Command`]s from a
//! channel and publishes the newest [`Snapshot`] into a one-slot mailbox.
//!
//! ```text
//!   UI thread ──Command──▶ mpsc channel ──▶ worker thread (owns Scene, steps at fixed dt)
//!   UI thread ◀──Arc<Snapshot>── mailbox (Mutex<Option<Arc>>, newest wins) ◀──┘
//! ```
//!
//! The window never waits on physics: it takes whatever snapshot is newest. Physics never
//! waits on rendering: a snapshot nobody read is simply replaced. The worker steps at the
//! scene's fixed `solver.dt`; when it is faster than real time it sleeps so that simulated
//! time follows wall time, and when it is slower it runs flat out and reports the
//! real-time factor. Nothing here depends on a GUI crate, so tests drive it directly.

use crate::scene::garment::SewingProgress;
use crate::scene::{Measures, Scene, SceneConfig, SettleWatch, Topology, load_scene};
use crate::settings::FabricConfig;
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use glam::DVec3;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, TryRecvError, channel};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};


/// A prop's surface as drawn: positions (m) and triangles.
pub type PropSurface = (Vec<DVec3>, Vec<[u32; 3]>);
/// What the UI asks of the worker. Commands are handled in the order sent.
#[derive(Debug, Clone)]
pub enum Command {
    /// Builds and shows a new scene (paused at t = 0), labelled `name` (a preset name or a
    /// file). A scene that fails to build is reported and the current one kept.
    LoadScene { name: String, config: Box<crate::scene::CheckedScene> },
    /// Settings edited in the window (a pattern's seams): checked, then loaded.
    LoadEdited { name: String, config: Box<SceneConfig> },
    /// Runs the scene, paced to wall time.
    Play,
    /// Stops stepping; the state stays.
    Pause,
    /// Pauses and advances exactly one step.
    Step,
    /// Plays until simulated time `t` (s) and pauses at the first step that reaches it, as a
    /// settled cloth pauses: a script's wait for simulated time holds the scene there for
    /// the steps after it (a screenshot shows that moment, not a later one).
    HoldAt(f64),
    /// Rebuilds the current scene from its configuration at t = 0, keeping play/pause.
    Reset,
    /// Replaces the fabric and restarts the scene from t = 0 (the cloth drapes again with
    /// the new material), keeping play/pause.
    SetFabric(Box<FabricConfig>),
    /// Changes the time step (s) and integrator, keeping the current positions, velocities
    /// and time. The BDF2 history is dropped: its formula assumes the old step.
    SetSolver { dt: f64, integrator: IntegratorKind },
    /// Switches between the exact and the fast solver path and restarts the scene from
    /// t = 0 (the fast path builds its coarser levels), keeping play/pause.
    SetPath(SolverPath),
    /// Recuts a garment's panels on these grains (degrees, one per panel, `grain_deg`) and
    /// restarts the scene from t = 0, keeping play/pause.
    SetGrains(Vec<f64>),
    /// Holds `vertex` at a point moving towards `target` (m) by at most [`DRAG_SPEED`]·dt
    /// and [`DRAG_STEP_EDGES`] of an edge per step, so a fast mouse cannot tear the mesh in
    /// one step. A second
    /// drag of another vertex releases the first. `mesh` is the version of the
    /// [`Topology`] the index was picked on: across a weld the vertex is carried to its
    /// merged vertex; on an unrelated mesh (a finer level, a rebuilt scene) the command is
    /// dropped, since the index names another point of the cloth.
    DragVertex { vertex: u32, mesh: u64, target: DVec3 },
    /// Lets the dragged vertex go with the velocity it had.
    ReleaseDrag,
    /// Loads the bundled laboratory scene `name` with the current fabric and plays it: the
    /// fabric under design is what the test measures.
    RunTest(String),
}

/// Fastest a dragged vertex follows the mouse, m/s.
pub const DRAG_SPEED: f64 = 1.0;

/// Farthest a dragged vertex moves in one step, in mean edges. The held vertex jumps
/// there at the step's start while its neighbours start where they were, so the jump is a
/// strain of about this much on the edges round it: half an edge (50 % strain) took the
/// fast path's 24 ms garment step 100 Newton iterations; a tenth (10 %) takes a few.
pub const DRAG_STEP_EDGES: f64 = 0.1;

/// How often a running worker publishes, at most.
const PUBLISH_INTERVAL: Duration = Duration::from_millis(15);

/// How far simulated time may fall behind wall time before pacing gives up catching up
/// (the worker then runs flat out and the real-time factor shows the shortfall), s.
const MAX_LAG: f64 = 0.1;

/// A time counts as reached within this share of a step: the sum of many steps misses it
/// by rounding.
const STEP_ROUNDING: f64 = 1e-6;

/// Whether simulated time `time` has reached `target` (s) on steps of `dt`: where play stops
/// at the scene's end and at a hold (`Command::HoldAt`), and where a script's wait for
/// simulated time ends, so that the wait ends where the hold stopped.
pub fn reached(time: f64, target: f64, dt: f64) -> bool {
    time >= target - STEP_ROUNDING * dt
}

/// Window over which the rates in [`Stats`] are measured.
const STATS_WINDOW: Duration = Duration::from_secs(1);

/// Figures for the stats panel.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stats {
    pub vertices: usize,
    pub triangles: usize,
    /// Steps per wall-clock second over the last second of play.
    pub steps_per_second: f64,
    /// Time the steps took per 10 ms simulated, ms (the unit of the paper's Table 1), on
    /// the same wall clock as `real_time_factor`: a step's work runs on rayon's pool as
    /// well as on the worker thread, so the worker's own CPU time would miss most of it.
    /// `real_time_factor · step_ms_per_10ms` is at most 10 ms: the steps fill at most the
    /// window.
    pub step_ms_per_10ms: f64,
    /// Simulated seconds per wall-clock second over the last second of play (1 when paced).
    pub real_time_factor: f64,
    /// Kinetic energy, J.
    pub kinetic_energy: f64,
    /// Membrane (in-plane) elastic energy, J.
    pub membrane_energy: f64,
    /// Bending energy, J.
    pub bending_energy: f64,
    /// Newton iterations of the last step (0 for the explicit integrator).
    pub newton_iterations: usize,
    /// Conjugate-gradient iterations of the last step.
    pub cg_iterations: usize,
    /// Quasi-Newton iterations of the last step (the fast path's step for cloth in motion).
    pub quasi_newton_iterations: usize,
    /// How the running level minimises each step ("newton" or "quasi-newton") and its Δt, s.
    pub minimizer: &'static str,
    pub step_dt: f64,
    /// Steps since the scene started whose Newton solve stopped short of its tolerance (by
    /// more than `UNCONVERGED_FACTOR`), as `rosette run` counts them against exit 5.
    pub unconverged_steps: u64,
    /// The largest of those steps' last Newton step over the mean edge length.
    pub worst_residual: f64,
}

/// What started a drape: the click it answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DrapeCause {
    /// The scene was opened (or a test started).
    #[default]
    Open,
    Reset,
    /// Another fabric.
    Fabric,
    /// Panels recut on other grains.
    Grain,
    /// The other solver path.
    Path,
    /// The mouse pulled a cloth that had come to rest.
    Drag,
}

impl DrapeCause {
    pub fn name(self) -> &'static str {
        match self {
            Self::Open => "open",
            Self::Reset => "reset",
            Self::Fabric => "fabric switch",
            Self::Grain => "recut",
            Self::Path => "path switch",
            Self::Drag => "drag",
        }
    }
}

/// The drape under way, on the wall clock from the click that started it, less the time the
/// scene stood paused: what a designer waits for.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DrapeClock {
    pub cause: DrapeCause,
    /// Wall seconds since the click, while the scene played.
    pub wall: f64,
    /// Simulated time when the drape started, s.
    pub started_at: f64,
    /// The drape went on from a sewn garment (a new fabric or grain on the same pattern)
    /// instead of sewing the panels again.
    pub from_sewn: bool,
    /// When the garment was welded during this drape: (simulated s, wall s since the click).
    pub sewn: Option<(f64, f64)>,
    /// When the cloth was found settled (the end of the settle window, where play
    /// pauses): (simulated s, wall s since the click).
    pub settled: Option<(f64, f64)>,
    /// Simulated time and wall seconds from the weld on (from the start for a drape that
    /// needs no sewing), until settling or now: their ratio is the real-time factor a
    /// designer watches the garment settle at.
    pub since_weld: (f64, f64),
    /// Wall seconds the steps themselves took since the click (the rest went to drawing,
    /// publishing, pacing and pauses).
    pub stepping: f64,
}

impl DrapeClock {
    /// Simulated seconds per wall second from the weld on (None before the weld, or with
    /// no wall time yet).
    pub fn real_time_factor_since_weld(&self) -> Option<f64> {
        let (simulated, wall) = self.since_weld;
        (wall > 0.0 && simulated > 0.0).then(|| simulated / wall)
    }
}

/// What the worker shows the UI: one consistent picture of the simulation.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// Bumped at each publish.
    pub serial: u64,
    /// Number of commands fully handled when this was taken (see [`Worker::send`]).
    pub commands_done: u64,
    /// Bumped whenever the scene is rebuilt (the mesh may have changed).
    pub scene_generation: u64,
    /// Name of the bundled preset or file the scene came from.
    pub scene_name: String,
    /// The configuration of the running scene (fabric and solver as currently set).
    pub config: Arc<SceneConfig>,
    /// Vertex positions, m, one per vertex of `topology`.
    pub positions: Vec<DVec3>,
    /// The mesh `positions` belong to: triangles, texture coordinates and a version that
    /// changes whenever the mesh does (a weld, a finer level, a rebuilt scene). Whatever
    /// keeps vertex indices between snapshots (a drag, a colour field, a GPU buffer)
    /// compares the version.
    pub topology: Arc<Topology>,
    /// Vertices held by the rig (clamps, grips) or the mouse.
    pub fixed: Vec<bool>,
    /// Surfaces of the scene's props (ground planes excepted): positions (m) and triangles.
    pub props: Arc<Vec<PropSurface>>,
    /// Height of the highest ground prop, m, if any.
    pub ground_z: Option<f64>,
    /// Per-triangle membrane strain `[ε_warp, ε_weft, γ]` (empty with the membrane off).
    pub triangle_strains: Vec<[f32; 3]>,
    /// Per-triangle curvature `[κ_warp, κ_weft, κ_twist]`, 1/m (empty with bending off).
    pub triangle_curvatures: Vec<[f32; 3]>,
    /// Simulated time, s.
    pub time: f64,
    /// Steps taken since the scene started.
    pub steps: u64,
    /// The scene's `scene.duration`, s.
    pub duration: f64,
    pub playing: bool,
    /// The scene has reached its duration or settled (playing further continues past it).
    pub finished: bool,
    /// When the cloth settled (`scene.settle_speed`), if it has: play then paused there, so
    /// that a resting cloth costs no more steps.
    pub settled_at: Option<f64>,
    pub stats: Stats,
    /// The rig's measurements (`Scene::measures`), for live plots.
    pub measures: Arc<Measures>,
    /// The last error (a bad scene or fabric, a diverged step), until the next success.
    pub error: Option<String>,
    /// The error is a step that diverged (the last good state is shown), not a refused edit.
    pub diverged: bool,
    /// The vertex held by the mouse, if any.
    pub dragged: Option<u32>,
    /// A garment's sewing: welded when, or the gap still open (None for other scenes).
    pub sewing: Option<SewingProgress>,
    /// The drape under way: what started it and, in wall time since, when the garment was
    /// sewn and when the cloth settled.
    pub drape: DrapeClock,
    /// The fast path is on one of its coarser levels (the scene's own mesh comes next).
    pub coarse_level: bool,
}

/// The shared one-slot mailbox: the newest snapshot, and a condition variable for callers
/// that want to wait for one.
#[derive(Default)]
struct Mailbox {
    slot: Mutex<Option<Arc<Snapshot>>>,
    published: Condvar,
}

/// Handle to the worker thread. Dropping it stops the thread and joins it.
pub struct Worker {
    commands: Option<Sender<Command>>,
    mailbox: Arc<Mailbox>,
    sent: AtomicU64,
    thread: Option<JoinHandle<()>>,
}

/// Builds a scene the window edited (a fabric, grains, the path, a reset) after the checks
/// a scene file meets, so that an edit the command line would refuse is refused here too,
/// with the same message, and the running scene stays.
fn checked_build(config: SceneConfig) -> Result<Scene, String> {
    Scene::new(config).map_err(|e| e.to_string())
}

impl Worker {
    /// Builds `config` and starts the worker thread on it, paused. `name` labels the scene.
    /// `on_publish` is called (on the worker thread) after each publish, e.g. to wake the UI.
    pub fn spawn(
        name: &str,
        config: crate::scene::CheckedScene,
        on_publish: Option<Box<dyn Fn() + Send>>,
    ) -> Result<Self, crate::scene::SceneError> {
        let scene = Scene::build(config)?;
        let (tx, rx) = channel();
        let mailbox = Arc::new(Mailbox::default());
        let mut state = WorkerState::new(name.to_string(), scene, Arc::clone(&mailbox), on_publish);
        state.publish();
        let thread = std::thread::Builder::new()
            .name("rosette-solver".into())
            .spawn(move || state.run(rx))
            .expect("the OS can start a thread");
        Ok(Self { commands: Some(tx), mailbox, sent: AtomicU64::new(0), thread: Some(thread) })
    }

    /// Queues a command and returns its sequence number: a snapshot with
    /// `commands_done >= number` reflects it.
    pub fn send(&self, command: Command) -> u64 {
        let number = self.sent.fetch_add(1, Ordering::SeqCst) + 1;
        if let Some(tx) = &self.commands {
            // The thread only ends when this handle drops, so a failed send means it
            // panicked; the UI keeps showing the last snapshot.
            let _ = tx.send(command);
        }
        number
    }

    /// How many commands have been sent so far: a snapshot whose `commands_done` reaches it
    /// has taken them all.
    pub fn sent(&self) -> u64 {
        self.sent.load(Ordering::SeqCst)
    }

    /// The newest snapshot (never blocks on physics: the lock is held only to swap an Arc).
    pub fn latest(&self) -> Arc<Snapshot> {
        self.mailbox.slot.lock().expect("mailbox lock").clone().expect("published at spawn")
    }

    /// Waits until a snapshot satisfies `ready` or `timeout` passes; returns the newest
    /// snapshot either way (for tests and scripted use, never the render loop).
    pub fn wait_for(&self, timeout: Duration, ready: impl Fn(&Snapshot) -> bool) -> Arc<Snapshot> {
        let deadline = Instant::now() + timeout;
        let mut slot = self.mailbox.slot.lock().expect("mailbox lock");
        loop {
            let snapshot = slot.clone().expect("published at spawn");
            let now = Instant::now();
            if ready(&snapshot) || now >= deadline {
                return snapshot;
            }
            slot = self.mailbox.published.wait_timeout(slot, deadline - now).expect("mailbox lock").0;
        }
    }

    /// Waits until every command sent so far has been handled.
    pub fn sync(&self, timeout: Duration) -> Arc<Snapshot> {
        let sent = self.sent.load(Ordering::SeqCst);
        self.wait_for(timeout, |s| s.commands_done >= sent)
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Closing the channel ends the thread's loop after its current step.
        self.commands.take();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// A vertex held by the mouse.
struct Drag {
    vertex: u32,
    target: DVec3,
    /// Where the vertex is held now, m.
    held_at: DVec3,
}

/// One step's timing, for the rates in [`Stats`].
struct StepTiming {
    start: Instant,
    end: Instant,
    simulated: f64,
}

/// Everything the worker thread owns.
struct WorkerState {
    scene: Scene,
    scene_name: String,
    config: Arc<SceneConfig>,
    props: Arc<Vec<PropSurface>>,
    ground_z: Option<f64>,
    mailbox: Arc<Mailbox>,
    on_publish: Option<Box<dyn Fn() + Send>>,
    playing: bool,
    /// Play has paused at the scene's end; further play runs past it.
    finished: bool,
    /// Play has paused where the cloth settled; further play runs on to the end.
    paused_settled: bool,
    /// The user paused (Pause or Step): an edit that rebuilds the scene does not start it.
    user_paused: bool,
    /// Play pauses at the first step that reaches this simulated time, s (`Command::HoldAt`).
    hold_at: Option<f64>,
    /// The drape under way: its cause, when it started (wall), and when it was sewn and
    /// settled (simulated s, wall s since the start).
    drape: (DrapeClock, Instant),
    settle: SettleWatch,
    error: Option<String>,
    /// The error came from a step that diverged.
    diverged: bool,
    drag: Option<Drag>,
    serial: u64,
    commands_done: u64,
    generation: u64,
    /// Pacing anchor: wall time and simulated time when play (re)started.
    pace: (Instant, f64),
    timings: VecDeque<StepTiming>,
    last_report: crate::sim::StepReport,
    /// Unconverged steps since the scene started, and the worst residual among them.
    unconverged: (u64, f64),
    last_publish: Instant,
    /// Something changed since the last publish.
    dirty: bool,
}

impl WorkerState {
    fn new(scene_name: String, scene: Scene, mailbox: Arc<Mailbox>, on_publish: Option<Box<dyn Fn() + Send>>) -> Self {
        let settle = SettleWatch::new(&scene);
        let mut state = Self {
            config: Arc::new(scene.config.clone()),
            props: Arc::default(),
            ground_z: None,
            scene,
            scene_name,
            mailbox,
            on_publish,
            playing: false,
            finished: false,
            paused_settled: false,
            user_paused: false,
            hold_at: None,
            drape: (DrapeClock::default(), Instant::now()),
            settle,
            error: None,
            diverged: false,
            drag: None,
            serial: 0,
            commands_done: 0,
            generation: 0,
            pace: (Instant::now(), 0.0),
            timings: VecDeque::new(),
            last_report: Default::default(),
            unconverged: (0, 0.0),
            last_publish: Instant::now(),
            dirty: true,
        };
        state.install_scene_data();
        state
    }

    fn run(mut self, commands: Receiver<Command>) {
        loop {
            // Wait for a command: indefinitely while paused, until the next step is due
            // while playing.
            let first = if !self.playing {
                let paused = Instant::now();
                let command = match commands.recv() {
                    Ok(c) => Some(c),
                    Err(_) => return,
                };
                // The drape's clock stands while the scene does (a pause, a script's hold).
                self.drape.1 += paused.elapsed();
                command
            } else {
                let ahead = self.seconds_ahead();
                if ahead > 0.0 {
                    match commands.recv_timeout(Duration::from_secs_f64(ahead)) {
                        Ok(c) => Some(c),
                        Err(RecvTimeoutError::Timeout) => None,
                        Err(RecvTimeoutError::Disconnected) => return,
                    }
                } else {
                    match commands.try_recv() {
                        Ok(c) => Some(c),
                        Err(TryRecvError::Empty) => None,
                        Err(TryRecvError::Disconnected) => return,
                    }
                }
            };
            if let Some(command) = first {
                self.handle(command);
                loop {
                    match commands.try_recv() {
                        Ok(c) => self.handle(c),
                        Err(TryRecvError::Empty) => break,
                        Err(TryRecvError::Disconnected) => return,
                    }
                }
                // Command results are shown at once, even while playing.
                self.publish();
            }
            if self.playing && self.seconds_ahead() <= 0.0 {
                self.step_once();
                // A drape that went on from a sewn garment has the scene's duration from
                // where it started.
                let end = self.reached(self.drape.0.started_at + self.scene.config.scene.duration);
                // A settled cloth pauses, as `rosette run` stops: it would only rest at the
                // cost of a solve per step. Not while the mouse holds it, and only once:
                // Play after the pause runs on to the scene's end.
                let settled = self.drag.is_none() && {
                    let rms = self.scene.rms_speed();
                    self.settle.observe(&self.scene, rms).is_some()
                };
                if self.drag.is_some() {
                    self.settle.interrupt();
                }
                // Not while the mouse holds the cloth: the drag goes on past the end.
                if end && !self.finished && self.drag.is_none() {
                    self.finished = true;
                    self.playing = false;
                }
                if self.hold_at.is_some_and(|t| self.reached(t)) {
                    self.playing = false;
                    self.hold_at = None;
                }
                if settled && !self.paused_settled {
                    self.paused_settled = true;
                    self.playing = false;
                    let wall = self.drape.1.elapsed().as_secs_f64();
                    self.drape.0.settled.get_or_insert((self.scene.state.time, wall));
                }
            }
            if self.dirty && (!self.playing || self.last_publish.elapsed() >= PUBLISH_INTERVAL) {
                self.publish();
            }
        }
    }

    /// Whether the scene's time has reached `t` (s) ([`reached`]).
    fn reached(&self, t: f64) -> bool {
        reached(self.scene.state.time, t, self.scene.integrator.dt)
    }

    /// How far simulated time is ahead of wall time since play started, s (negative: behind).
    /// A lag beyond [`MAX_LAG`] moves the anchor, so a slow solver is not asked to catch up.
    fn seconds_ahead(&mut self) -> f64 {
        let (wall, sim) = self.pace;
        let ahead = (self.scene.state.time - sim) - wall.elapsed().as_secs_f64();
        if ahead < -MAX_LAG {
            self.pace = (Instant::now(), self.scene.state.time);
            return 0.0;
        }
        ahead
    }

    fn handle(&mut self, command: Command) {
        self.commands_done += 1;
        self.dirty = true;
        self.diverged = false;
        match command {
            Command::LoadScene { name, config } => self.load(Scene::build(*config).map_err(|e| e.to_string()), Some(name), false),
            Command::LoadEdited { name, config } => self.load(checked_build(*config), Some(name), false),
            Command::Play => {
                self.playing = true;
                self.user_paused = false;
                self.hold_at = None;
                self.pace = (Instant::now(), self.scene.state.time);
            }
            Command::Pause => {
                self.playing = false;
                self.user_paused = true;
                self.hold_at = None;
            }
            Command::HoldAt(t) => {
                self.user_paused = false;
                (self.playing, self.hold_at) = if self.reached(t) { (false, None) } else { (true, Some(t)) };
                self.pace = (Instant::now(), self.scene.state.time);
            }
            Command::Step => {
                self.playing = false;
                self.user_paused = true;
                self.hold_at = None;
                self.step_once();
            }
            Command::Reset => {
                let config = self.scene.config.clone();
                let playing = self.playing;
                self.load(checked_build(config), None, playing);
                self.drape.0.cause = DrapeCause::Reset;
            }
            Command::SetFabric(fabric) => {
                let mut config = self.scene.config.clone();
                config.fabric = *fabric;
                self.redrape(config, DrapeCause::Fabric).unwrap_or_else(|e| self.error = Some(format!("fabric not applied: {e}")));
            }
            Command::SetSolver { dt, integrator } => self.set_solver(dt, integrator),
            Command::SetPath(path) => {
                let mut config = self.scene.config.clone();
                config.solver.path = path;
                self.redrape(config, DrapeCause::Path).unwrap_or_else(|e| self.error = Some(format!("solver path not applied: {e}")));
            }
            Command::SetGrains(grains) => {
                let mut config = self.scene.config.clone();
                if let Some(garment) = config.garment.as_mut() {
                    for (panel, grain) in garment.panels.iter_mut().zip(grains) {
                        panel.grain_deg = grain;
                    }
                }
                self.redrape(config, DrapeCause::Grain).unwrap_or_else(|e| self.error = Some(format!("grains not applied: {e}")));
            }
            Command::DragVertex { vertex, mesh, target } => self.drag(vertex, mesh, target),
            Command::ReleaseDrag => self.release_drag(),
            Command::RunTest(name) => match load_scene(&name, &[]) {
                Ok((checked, _)) => {
                    let mut config = checked.into_config();
                    config.fabric = self.scene.config.fabric.clone();
                    self.load(checked_build(config), Some(name), true);
                }
                Err(e) => self.error = Some(e.to_string()),
            },
        }
    }

    /// Makes `built` the running scene, labelled `name` (the old label when `None`). A
    /// scene that failed to build leaves the current one running and its message shown.
    fn load(&mut self, built: Result<Scene, String>, name: Option<String>, play: bool) {
        let scene = match built {
            Ok(scene) => scene,
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        self.scene = scene;
        if let Some(name) = name {
            self.scene_name = name;
        }
        self.install_scene_data();
        self.playing = play;
        self.pace = (Instant::now(), 0.0);
    }

    /// Rebuilds the scene for an edit (a fabric, grains, the path) and drapes it again: a
    /// sewn garment whose pattern the edit keeps goes on from where it hangs, anything else
    /// starts from t = 0. The drape plays unless the user had paused.
    fn redrape(&mut self, config: SceneConfig, cause: DrapeCause) -> Result<(), String> {
        let mut scene = checked_build(config)?;
        let from_sewn = scene.continue_sewn(&self.scene);
        let started_at = scene.state.time;
        self.scene = scene;
        self.install_scene_data();
        self.drape.0 = DrapeClock { cause, started_at, from_sewn, ..DrapeClock::default() };
        self.playing = !self.user_paused;
        self.pace = (Instant::now(), started_at);
        Ok(())
    }

    /// Refreshes what snapshots share with the new scene and clears per-scene state.
    fn install_scene_data(&mut self) {
        self.config = Arc::new(self.scene.config.clone());
        let (grounds, solids): (Vec<_>, Vec<_>) =
            self.scene.props.iter().partition(|p| matches!(p.shape, crate::sim::contact::PropShape::Ground));
        self.ground_z = grounds.iter().map(|p| p.position.z).reduce(f64::max);
        self.props = Arc::new(solids.iter().map(|p| p.surface_mesh(0.0)).collect());
        self.generation += 1;
        self.finished = false;
        self.paused_settled = false;
        self.hold_at = None;
        self.drape = (DrapeClock { started_at: self.scene.state.time, ..DrapeClock::default() }, Instant::now());
        self.settle = SettleWatch::new(&self.scene);
        self.error = None;
        self.drag = None;
        self.timings.clear();
        self.last_report = Default::default();
        self.unconverged = (0, 0.0);
    }

    fn set_solver(&mut self, dt: f64, integrator: IntegratorKind) {
        if let Err(e) = self.scene.set_solver(dt, integrator) {
            self.error = Some(e.to_string());
            return;
        }
        self.config = Arc::new(self.scene.config.clone());
        self.pace = (Instant::now(), self.scene.state.time);
        self.timings.clear();
        self.error = None;
    }

    fn drag(&mut self, vertex: u32, mesh: u64, target: DVec3) {
        let topology = self.scene.topology();
        if !topology.follows(mesh) {
            // Picked on a mesh the cloth no longer has: the mouse lets go.
            self.release_drag();
            return;
        }
        let Some(vertex) = topology.carry_vertex(mesh, vertex).filter(|_| target.is_finite()) else {
            self.error = Some(format!("cannot drag vertex {vertex}: no such vertex or a non-finite target"));
            return;
        };
        let v = vertex as usize;
        if self.drag.as_ref().is_some_and(|d| d.vertex == vertex) {
            self.drag.as_mut().expect("checked").target = target;
            return;
        }
        self.release_drag();
        if self.scene.model.fixed[v] {
            // Clamped and driven vertices follow their rig; the mouse does not override it.
            return;
        }
        let held_at = self.scene.state.x[v];
        self.scene.model.pin(vertex, held_at);
        self.drag = Some(Drag { vertex, target, held_at });
        // A cloth that paused where it settled (or ended) moves again under the mouse, and
        // settles again once let go; one the user paused stays paused.
        if !self.playing && !self.user_paused {
            self.playing = true;
            (self.paused_settled, self.finished) = (false, false);
            self.settle = SettleWatch::new(&self.scene);
            self.pace = (Instant::now(), self.scene.state.time);
            // A new drape, from the drag: the scene's duration counts from here.
            let from_sewn = self.scene.garment.as_ref().is_some_and(|g| g.is_sewn());
            self.drape = (DrapeClock { cause: DrapeCause::Drag, started_at: self.scene.state.time, from_sewn, ..DrapeClock::default() }, Instant::now());
        }
    }

    /// The mesh changed under a drag (`from` is the old mesh's version): a weld carries the
    /// held vertex to its merged vertex, which the mouse goes on holding; a finer level or
    /// a rebuilt mesh lets it go.
    fn carry_drag(&mut self, from: u64) {
        let Some(drag) = self.drag.take() else { return };
        match self.scene.topology().carry_vertex(from, drag.vertex) {
            Some(vertex) if !self.scene.model.fixed[vertex as usize] => {
                self.scene.model.pin(vertex, drag.held_at);
                self.drag = Some(Drag { vertex, ..drag });
            }
            _ => {}
        }
    }

    fn release_drag(&mut self) {
        if let Some(drag) = self.drag.take() {
            self.scene.model.fixed[drag.vertex as usize] = false;
        }
    }

    /// Moves the held point of a drag towards its target, at most DRAG_SPEED·dt and
    /// DRAG_STEP_EDGES of an edge per step.
    fn advance_drag(&mut self) {
        let Some(drag) = &mut self.drag else { return };
        let limit = (DRAG_SPEED * self.scene.integrator.dt).min(DRAG_STEP_EDGES * self.scene.model.mean_edge_length);
        let to_target = drag.target - drag.held_at;
        let length = to_target.length();
        drag.held_at += if length > limit { to_target * (limit / length) } else { to_target };
        self.scene.model.pin(drag.vertex, drag.held_at);
    }

    fn step_once(&mut self) {
        self.advance_drag();
        let mesh_before = self.scene.topology().version;
        let start = Instant::now();
        let result = self.scene.step();
        self.dirty = true;
        match result {
            Ok(report) => {
                self.last_report = report;
                if !report.converged() {
                    self.unconverged = (self.unconverged.0 + 1, self.unconverged.1.max(report.newton_residual));
                }
                self.error = None;
                if self.scene.topology().version != mesh_before {
                    self.carry_drag(mesh_before);
                }
                let clock = &mut self.drape.0;
                if clock.settled.is_none() {
                    clock.stepping += start.elapsed().as_secs_f64();
                }
                if clock.sewn.is_none() && !clock.from_sewn && self.scene.garment.as_ref().is_some_and(|g| g.is_sewn()) {
                    clock.sewn = Some((self.scene.state.time, self.drape.1.elapsed().as_secs_f64()));
                }
                let end = Instant::now();
                self.timings.push_back(StepTiming { start, end, simulated: report.dt });
                while self.timings.front().is_some_and(|t| end.duration_since(t.start) > STATS_WINDOW) && self.timings.len() > 1 {
                    self.timings.pop_front();
                }
            }
            Err(e) => {
                // The integrator left the state as it was: keep it and stop.
                self.error = Some(e.to_string());
                self.diverged = true;
                self.playing = false;
            }
        }
    }

    fn stats(&self) -> Stats {
        let model = &self.scene.model;
        let x = &self.scene.state.x;
        let (membrane_energy, bending_energy) = model.elastic_energy(x);
        let mut stats = Stats {
            vertices: model.vertex_count(),
            triangles: model.triangle_count(),
            kinetic_energy: self.scene.state.kinetic_energy(model),
            membrane_energy,
            bending_energy,
            newton_iterations: self.last_report.newton_iterations,
            cg_iterations: self.last_report.cg_iterations,
            quasi_newton_iterations: self.last_report.quasi_newton_iterations,
            minimizer: match self.scene.integrator.newton.minimizer {
                crate::sim::Minimizer::QuasiNewton => "quasi-newton",
                _ => "newton",
            },
            step_dt: self.scene.integrator.dt,
            unconverged_steps: self.unconverged.0,
            worst_residual: self.unconverged.1,
            ..Default::default()
        };
        if let (Some(first), Some(last)) = (self.timings.front(), self.timings.back()) {
            let wall = last.end.duration_since(first.start).as_secs_f64();
            let simulated: f64 = self.timings.iter().map(|t| t.simulated).sum();
            let busy: f64 = self.timings.iter().map(|t| t.end.duration_since(t.start).as_secs_f64()).sum();
            if wall > 0.0 && simulated > 0.0 {
                stats.steps_per_second = self.timings.len() as f64 / wall;
                stats.real_time_factor = simulated / wall;
                // Step seconds per simulated second, times 10 ms, in ms.
                stats.step_ms_per_10ms = busy / simulated * 10.0;
            }
        }
        stats
    }

    /// The drape's clock now: from the weld (or from the start, for a drape that sews
    /// nothing) until it settled or until now.
    fn drape_clock(&self) -> DrapeClock {
        let (clock, started) = self.drape;
        let wall = started.elapsed().as_secs_f64();
        let needs_sewing = self.scene.garment.is_some() && !clock.from_sewn;
        let from = if needs_sewing { clock.sewn } else { Some((clock.started_at, 0.0)) };
        let until = clock.settled.unwrap_or((self.scene.state.time, wall));
        let since_weld = from.map_or((0.0, 0.0), |(t, w)| ((until.0 - t).max(0.0), (until.1 - w).max(0.0)));
        DrapeClock { wall, since_weld, ..clock }
    }

    fn publish(&mut self) {
        self.serial += 1;
        let model = &self.scene.model;
        let x = &self.scene.state.x;
        let to_f32 = |v: [f64; 3]| v.map(|c| c as f32);
        let snapshot = Snapshot {
            serial: self.serial,
            commands_done: self.commands_done,
            scene_generation: self.generation,
            scene_name: self.scene_name.clone(),
            config: Arc::clone(&self.config),
            positions: x.clone(),
            topology: Arc::clone(self.scene.topology()),
            fixed: model.fixed.clone(),
            props: Arc::clone(&self.props),
            ground_z: self.ground_z,
            triangle_strains: model.triangle_strains(x).into_iter().map(to_f32).collect(),
            triangle_curvatures: model.triangle_curvatures(x).into_iter().map(to_f32).collect(),
            time: self.scene.state.time,
            steps: self.scene.state.steps,
            duration: self.scene.config.scene.duration,
            playing: self.playing,
            finished: self.finished || self.paused_settled,
            settled_at: self.settle.settled_at,
            stats: self.stats(),
            measures: Arc::new(self.scene.measures()),
            error: self.error.clone(),
            diverged: self.diverged && self.error.is_some(),
            dragged: self.drag.as_ref().map(|d| d.vertex),
            sewing: self.scene.sewing_progress(),
            drape: self.drape_clock(),
            coarse_level: !self.scene.at_final_level(),
        };
        *self.mailbox.slot.lock().expect("mailbox lock") = Some(Arc::new(snapshot));
        self.mailbox.published.notify_all();
        self.last_publish = Instant::now();
        self.dirty = false;
        if let Some(wake) = &self.on_publish {
            wake();
        }
    }
}
