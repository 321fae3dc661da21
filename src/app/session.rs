//! A scripted session played in the window: each frame the session looks at the newest
//! snapshot, carries out the next step of its [`Script`] through the code the click it
//! stands for runs (the panels' own methods, the toolbar's actions, pointer events fed to
//! egui for a drag), or waits, and keeps a report of what each step saw.
//!
//! A step that changes the scene (a fabric, a recut, the path) sends its command like the
//! click does; a wait that follows looks only at snapshots that have taken every command
//! sent so far, so it never reads the state from before the click.

use super::script::{Action as Step, Script, WaitFor, Window};
use super::ui::{Action, ViewerUi};
use super::worker::{Command, Snapshot, reached};
use serde_json::{Value, json};
use std::path::PathBuf;
use std::time::Instant;

/// How a session ended badly: the exit code (as `rosette run` uses them) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub code: u8,
    pub line: usize,
    pub message: String,
}

/// Exit codes a session fails with (README, "Exit codes").
pub const EXIT_DIVERGED: u8 = 3;
pub const EXIT_NO_OUTPUT: u8 = 4;
pub const EXIT_TIMED_OUT: u8 = 6;
pub const EXIT_NOT_SEWN: u8 = 8;

/// What the window does after a frame of the session.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    Continue,
    /// The script asked to quit, or ended.
    Quit,
    Fail(Failure),
}

/// The frame the session acts in.
pub struct FrameInput<'a> {
    pub snapshot: &'a Snapshot,
    pub ui: &'a mut ViewerUi,
    /// Input events of this frame, before egui sees them: a drag is fed in here.
    pub events: &'a mut Vec<egui::Event>,
    /// What the frame asks of the window, as clicks do.
    pub actions: &'a mut Vec<Action>,
    /// Commands the window has sent to the worker so far.
    pub commands_sent: u64,
}

/// A drag under way: whether the button is down, the frames it has moved in, whether it
/// has been let go, and whether the cloth was held meanwhile.
#[derive(Debug, Clone, Copy)]
struct DragState {
    pressed: bool,
    moves: u32,
    released: bool,
    held_vertex: bool,
}

/// The fewest frames a drag moves in, whatever its duration: egui tells a drag from a
/// click by the pointer's moves between frames, and a slow window (two sessions on two
/// cores) might otherwise press, move and let go in one frame.
const DRAG_FRAMES: u32 = 8;

/// The session's state between frames.
pub struct Session {
    script: Script,
    started: Instant,
    step: usize,
    /// When the current step began: wall instant, simulated time (once the worker had
    /// every command), and the commands sent before it.
    step_wall: Option<Instant>,
    step_simulated: Option<f64>,
    drag: Option<DragState>,
    /// The screenshot asked for and not yet written.
    screenshot: Option<PathBuf>,
    /// The simulated time of the last screenshot's picture, s.
    picture_time: Option<f64>,
    /// The scene stands still for the session: at t = 0 when the window opens (a script's
    /// window does not start playing by itself) or where a wait for simulated time paused it
    /// (`Command::HoldAt`). The steps that only look see that moment; a wait for simulated
    /// time counts from it; any other step plays the scene again first.
    holding: bool,
    report: Vec<Value>,
    /// Rounds of the script played (a repeating script).
    round: u64,
    /// The cloth the session opened on: its vertices and triangles.
    opened: Option<(usize, usize)>,
}

impl Session {
    pub fn new(script: Script) -> Self {
        Self { script, started: Instant::now(), step: 0, step_wall: None, step_simulated: None, drag: None, screenshot: None, picture_time: None, holding: true, report: Vec::new(), round: 0, opened: None }
    }

    /// Whether the session is feeding the window input (a drag under way): its frames come
    /// as the user's input does, at once, not at the pace of the scene's snapshots.
    pub fn feeding_input(&self) -> bool {
        self.drag.is_some_and(|d| d.pressed && !d.released)
    }

    /// The script's file, as given.
    pub fn script_name(&self) -> String {
        self.script.path.display().to_string()
    }

    /// The line of the step under way (for messages).
    pub fn line(&self) -> usize {
        self.script.steps.get(self.step).map_or(0, |s| s.line)
    }

    /// Advances the session by one frame.
    pub fn frame(&mut self, input: FrameInput) -> Control {
        let Some(step) = self.script.steps.get(self.step).cloned() else { return Control::Quit };
        self.opened.get_or_insert((input.snapshot.positions.len(), input.snapshot.topology.triangles.len()));
        let simulated_wait = matches!(step.action, Step::Wait { until: WaitFor::Simulated(_), .. });
        if self.holding && self.step_wall.is_none() && !step.action.looks() && !simulated_wait {
            self.holding = false;
            if !matches!(step.action, Step::Pause | Step::Play) {
                // The step starts once the worker plays again.
                input.actions.push(Action::Send(Command::Play));
                return Control::Continue;
            }
        }
        let now = Instant::now();
        let step_wall = *self.step_wall.get_or_insert(now);
        let elapsed = now.duration_since(step_wall).as_secs_f64();
        let snapshot = input.snapshot;
        // Every command sent is in this snapshot, and no fabric edit waits to be sent.
        let synced = snapshot.commands_done >= input.commands_sent && !input.ui.fabric_pending();
        let fail = |code: u8, message: String| Control::Fail(Failure { code, line: step.line, message });
        if synced
            && let Some(error) = &snapshot.error
        {
            return fail(if snapshot.diverged { EXIT_DIVERGED } else { 2 }, format!("the window reports: {error}"));
        }
        let done = match &step.action {
            Step::Wait { until, timeout_s } => {
                if elapsed > *timeout_s {
                    return fail(
                        EXIT_TIMED_OUT,
                        format!("waited {timeout_s} s of wall time for {} (raise timeout_s); t = {:.3} s simulated", until.describe(), snapshot.time),
                    );
                }
                if !synced {
                    false
                } else {
                    let since = match (self.step_simulated, until) {
                        (Some(since), _) => since,
                        (None, WaitFor::Simulated(seconds)) if snapshot.playing || self.holding => {
                            // Held at the step that reaches the time: the steps after the wait
                            // see the cloth as it was then. From a held scene the time counts
                            // from where it is held, so that waits add up exactly.
                            input.actions.push(Action::Send(Command::HoldAt(snapshot.time + seconds)));
                            self.holding = true;
                            self.step_simulated = Some(snapshot.time);
                            return Control::Continue;
                        }
                        (None, _) => *self.step_simulated.insert(snapshot.time),
                    };
                    match self.wait(*until, snapshot, since, elapsed) {
                        Ok(done) => done,
                        Err((code, message)) => return fail(code, message),
                    }
                }
            }
            Step::Drag { from, to, seconds } => self.drag(input.ui, input.events, input.snapshot, *from, *to, elapsed / seconds),
            Step::Screenshot(path) => {
                if self.screenshot.is_none() && self.step_simulated.is_none() {
                    // Asked once; the window writes it after drawing this frame.
                    self.screenshot = Some(path.clone());
                    self.step_simulated = Some(snapshot.time);
                    input.actions.push(Action::SaveScreenshot(path.clone()));
                }
                // Done once the window has written it (`saved`).
                self.screenshot.is_none()
            }
            Step::Quit => {
                self.record(&step, snapshot, elapsed, json!({}));
                return Control::Quit;
            }
            action => {
                if let Err(message) = act(action, input.ui, snapshot, input.actions) {
                    return fail(2, message);
                }
                true
            }
        };
        if done {
            let details = match (&step.action, self.drag) {
                (Step::Drag { .. }, Some(d)) => json!({ "held_a_vertex": d.held_vertex }),
                (Step::Screenshot(_), _) => json!({ "picture_time_s": self.picture_time }),
                _ => json!({}),
            };
            self.record(&step, snapshot, elapsed, details);
            self.step += 1;
            (self.step_wall, self.step_simulated, self.drag) = (None, None, None);
            if self.step == self.script.steps.len() {
                if !self.script.repeat {
                    return Control::Quit;
                }
                self.step = 0;
                self.round += 1;
            }
        }
        Control::Continue
    }

    /// Whether the wait for `until` is over; an error where it never can be.
    fn wait(&self, until: WaitFor, snapshot: &Snapshot, since: f64, elapsed: f64) -> Result<bool, (u8, String)> {
        let stalled = !snapshot.playing;
        Ok(match until {
            WaitFor::Sewn => match snapshot.sewing {
                Some(s) if s.sewn_at.is_some() => true,
                Some(s) if s.failed => return Err((EXIT_NOT_SEWN, format!("the garment was not sewn in its sewing time (a seam still {:.1} mm open)", 1e3 * s.open_gap))),
                _ if stalled => return Err((EXIT_TIMED_OUT, "the scene is paused before its seams were sewn: add a play step first".into())),
                _ => false,
            },
            WaitFor::Settled if snapshot.settled_at.is_some() => true,
            WaitFor::Settled if stalled && snapshot.finished => {
                return Err((EXIT_TIMED_OUT, format!("the scene reached its end (t = {:.3} s) without settling", snapshot.time)));
            }
            WaitFor::Settled | WaitFor::Finished if stalled && !snapshot.finished => {
                return Err((EXIT_TIMED_OUT, "the scene is paused: add a play step before waiting for it".into()));
            }
            WaitFor::Settled => false,
            WaitFor::Finished => snapshot.finished,
            WaitFor::Simulated(seconds) => {
                if reached(snapshot.time, since + seconds, snapshot.stats.step_dt) {
                    true
                } else if stalled && let Some(settled) = snapshot.settled_at {
                    return Err((
                        EXIT_TIMED_OUT,
                        format!(
                            "the cloth settled at t = {settled:.3} s and play paused there, short of t = {:.3} s: wait = \"settled\" instead, or add a play step before this wait",
                            since + seconds
                        ),
                    ));
                } else if stalled && snapshot.finished {
                    return Err((EXIT_TIMED_OUT, format!("the scene reached its end (t = {:.3} s) short of t = {:.3} s", snapshot.time, since + seconds)));
                } else if stalled {
                    return Err((EXIT_TIMED_OUT, "the scene is paused, so simulated time does not pass: add a play step first".into()));
                } else {
                    false
                }
            }
            WaitFor::Wall(seconds) => elapsed >= seconds,
        })
    }

    /// One frame of a drag across the view from `from` to `to` (fractions of the view), at
    /// `progress` (0..1 and past it once its time is up): pointer events as a mouse makes.
    fn drag(&mut self, ui: &ViewerUi, events: &mut Vec<egui::Event>, snapshot: &Snapshot, from: [f64; 2], to: [f64; 2], progress: f64) -> bool {
        let rect = ui.view_rect;
        if !rect.is_positive() {
            // The view is laid out by the first frame.
            return false;
        }
        let at = |f: [f64; 2]| egui::pos2(rect.min.x + f[0] as f32 * rect.width(), rect.min.y + f[1] as f32 * rect.height());
        let state = self.drag.get_or_insert(DragState { pressed: false, moves: 0, released: false, held_vertex: false });
        let button = |pos, pressed| egui::Event::PointerButton { pos, button: egui::PointerButton::Primary, pressed, modifiers: Default::default() };
        if !state.pressed {
            let start = at(from);
            events.push(egui::Event::PointerMoved(start));
            events.push(button(start, true));
            state.pressed = true;
            return false;
        }
        state.held_vertex |= snapshot.dragged.is_some();
        if state.released {
            return true;
        }
        let t = progress.min(f64::from(state.moves) / f64::from(DRAG_FRAMES)).clamp(0.0, 1.0);
        let now = at([from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]);
        if t >= 1.0 && state.moves > DRAG_FRAMES {
            // Let go in a frame of its own, where the last move left the pointer.
            events.push(button(now, false));
            state.released = true;
        } else {
            events.push(egui::Event::PointerMoved(now));
            state.moves += 1;
        }
        false
    }

    /// The window wrote (or failed to write) the screenshot it was asked for.
    /// `time` is the simulated time of the picture, s.
    pub fn saved(&mut self, path: &std::path::Path, result: Result<(), String>, time: f64) -> Control {
        if self.screenshot.as_deref() != Some(path) {
            return Control::Continue;
        }
        self.screenshot = None;
        self.picture_time = Some(time);
        match result {
            Ok(()) => Control::Continue,
            Err(e) => Control::Fail(Failure { code: EXIT_NO_OUTPUT, line: self.line(), message: format!("screenshot {} not written: {e}", path.display()) }),
        }
    }

    /// Adds what `step` saw to the report.
    fn record(&mut self, step: &super::script::Step, snapshot: &Snapshot, took: f64, details: Value) {
        let clock = snapshot.drape;
        let fabric = &snapshot.config.fabric;
        let mut entry = json!({
            "line": step.line,
            "round": self.round,
            "action": format!("{:?}", step.action),
            "wall_s": self.started.elapsed().as_secs_f64(),
            "took_s": took,
            "time_s": snapshot.time,
            "scene": snapshot.scene_name,
            "path": snapshot.config.solver.path.name(),
            "fabric": if fabric.name.is_empty() { fabric.preset.clone().unwrap_or_default() } else { fabric.name.clone() },
            "vertices": snapshot.positions.len(),
            "triangles": snapshot.topology.triangles.len(),
            "playing": snapshot.playing,
            "settled_at_s": snapshot.settled_at,
            "sewn_at_s": snapshot.sewing.and_then(|s| s.sewn_at),
            "drape": {
                "cause": clock.cause.name(),
                "from_sewn": clock.from_sewn,
                "wall_s": clock.wall,
                "sewn_wall_s": clock.sewn.map(|s| s.1),
                "settled_wall_s": clock.settled.map(|s| s.1),
                "real_time_factor_since_weld": clock.real_time_factor_since_weld(),
                "stepping_s": clock.stepping,
            },
            "real_time_factor": snapshot.stats.real_time_factor,
            "unconverged_steps": snapshot.stats.unconverged_steps,
            "last_step": { "newton_iterations": snapshot.stats.newton_iterations, "cg_iterations": snapshot.stats.cg_iterations, "dt_s": snapshot.stats.step_dt },
            "step_ms_per_10ms": snapshot.stats.step_ms_per_10ms,
            "steps": snapshot.steps,
            "measures": measures(snapshot),
        });
        if let Value::Object(extra) = details {
            entry.as_object_mut().expect("an object").extend(extra);
        }
        self.report.push(entry);
    }

    /// The session's report: how it ended, a line per step done with what it saw, and the
    /// pinned fabric's measures where one is pinned.
    pub fn report(&self, ui: &ViewerUi, outcome: &Control) -> Report {
        let pinned = ui.pinned.as_ref().map(|p| {
            let measures: serde_json::Map<String, Value> = p.measures.iter().map(|(n, v)| (n.to_string(), json!(v.value()))).collect();
            json!({ "fabric": p.fabric, "scene": p.scene, "time_s": p.time, "settled_at_s": p.settled_at, "measures": measures })
        });
        let outcome = match outcome {
            Control::Fail(f) => json!({ "ok": false, "exit_code": f.code, "line": f.line, "message": f.message }),
            _ => json!({ "ok": true, "exit_code": 0 }),
        };
        let opened = self.opened.map(|(vertices, triangles)| json!({ "vertices": vertices, "triangles": triangles }));
        Report { session: self.script_name(), outcome, opened, steps: self.report.clone(), pinned }
    }
}

/// What `rosette view --script --report FILE.json` writes; its first key names it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    /// The script's file.
    pub session: String,
    pub outcome: Value,
    /// The cloth the session opened on (vertices, triangles), before any weld.
    pub opened: Option<Value>,
    pub steps: Vec<Value>,
    pub pinned: Option<Value>,
}

impl Report {
    /// The first bytes of a report as written (for the output guard).
    pub const START: &'static str = "{\n  \"session\": ";

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("JSON values serialise")
    }
}

/// A scene's scalar measures by name.
fn measures(snapshot: &Snapshot) -> Value {
    Value::Object(snapshot.measures.scalars().into_iter().map(|(n, v)| (n.to_string(), json!(v.value()))).collect())
}

/// An instantaneous step, done as its click does it.
fn act(action: &Step, ui: &mut ViewerUi, snapshot: &Snapshot, actions: &mut Vec<Action>) -> Result<(), String> {
    match action {
        Step::Play => actions.push(Action::Send(Command::Play)),
        Step::Pause => actions.push(Action::Send(Command::Pause)),
        Step::Reset => actions.push(Action::Send(Command::Reset)),
        Step::Path(path) => ui.choose_path(*path, snapshot, actions),
        Step::Fabric(name) => ui.choose_fabric(name, &snapshot.config)?,
        Step::FabricFile { fabric, .. } => ui.set_fabric((**fabric).clone()),
        Step::Recut(cut) => ui.pattern.choose_cut(*cut, snapshot, actions)?,
        Step::Grain { panel, degrees } => {
            ui.pattern.edit_grain(panel, *degrees, snapshot)?;
            ui.pattern.recut(snapshot, actions);
        }
        Step::Test(name) => ui.run_test(name, actions),
        Step::Pin => actions.push(Action::Pin),
        Step::Unpin => ui.pinned = None,
        Step::Orbit { yaw_deg, pitch_deg } => ui.turn_camera(yaw_deg.to_radians(), pitch_deg.to_radians()),
        Step::Zoom(factor) => ui.zoom_camera(*factor),
        Step::Frame => ui.camera.frame(&snapshot.positions),
        Step::Open(window) | Step::Close(window) => {
            let open = matches!(action, Step::Open(_));
            match window {
                Window::Card => ui.card.open = open,
                Window::Chart => ui.chart.open = open,
                Window::Pattern => ui.pattern.open = open,
            }
        }
        Step::Colour(map) => ui.colour_map = *map,
        Step::Wait { .. } | Step::Drag { .. } | Step::Screenshot(_) | Step::Quit => unreachable!("handled by the session"),
    }
    Ok(())
}
