//! Scripted sessions (`rosette view SCENE --script FILE.toml`): a timeline of what a person
//! does in the window, read and checked before the window opens. [`super::session`] plays it
//! through the same code the clicks go through.
//!
//! ```toml
//! # Sew a skirt, let it settle, try it in silk, recut it on the bias, keep a picture.
//! [[step]]
//! wait = "settled"          # "sewn", "settled", "finished"; or wait_simulated_s, wait_wall_s
//! timeout_s = 300           # a wait's limit on the wall clock (default 600 s)
//! [[step]]
//! pin = true                # Pin fabric
//! [[step]]
//! fabric = "silk"           # a bundled fabric (or fabric_file = "my-fabric.toml")
//! [[step]]
//! recut = "bias"            # "straight", "bias"; or grain = { panel = "front", deg = 45 }
//! [[step]]
//! screenshot = "silk-bias.png"
//! [[step]]
//! quit = true
//! ```
//!
//! Every step holds one action. A bad script is refused with its line and key, exit 2,
//! before any window opens ([`Script::check`]).

use super::pattern_view::Cut;
use crate::io::read::{FileKind, read_text};
use crate::settings::{FABRICS, FabricConfig, SceneConfig, SolverPath};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The longest a wait may last on the wall clock unless the step says otherwise, s.
pub const DEFAULT_TIMEOUT_S: f64 = 600.0;

/// The longest a script may run a drag or wait for, s: a day.
const LONGEST_S: f64 = 86_400.0;

/// What a wait waits for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WaitFor {
    /// A garment's seams are welded.
    Sewn,
    /// The cloth has settled (play pauses there).
    Settled,
    /// The scene has reached its duration or settled.
    Finished,
    /// This much simulated time from the step's start, s: the scene pauses at the first step
    /// that reaches it and is held there through the steps that only look ([`Action::looks`]).
    Simulated(f64),
    /// This much wall time from the step's start, s.
    Wall(f64),
}

impl WaitFor {
    pub fn describe(self) -> String {
        match self {
            Self::Sewn => "sewn".into(),
            Self::Settled => "settled".into(),
            Self::Finished => "finished".into(),
            Self::Simulated(s) => format!("{s} s simulated"),
            Self::Wall(s) => format!("{s} s of wall time"),
        }
    }
}

/// A window the toolbar opens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    Card,
    Chart,
    Pattern,
}

/// One thing a person does.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    Wait { until: WaitFor, timeout_s: f64 },
    Play,
    Pause,
    Reset,
    /// The solver path switch.
    Path(SolverPath),
    /// A bundled fabric from the fabric editor's list.
    Fabric(String),
    /// A fabric file, read and checked with the script, as File › Open fabric reads it.
    FabricFile { path: PathBuf, fabric: Box<FabricConfig> },
    /// The pattern's straight / bias switch.
    Recut(Cut),
    /// A panel's grain set in the pattern editor, then *Recut*.
    Grain { panel: String, degrees: f64 },
    /// A laboratory test's button: the test runs on the fabric being edited.
    Test(String),
    Pin,
    Unpin,
    /// A left-drag across the 3D view, from and to fractions of its width and height (0 at
    /// the left and top), over this many seconds of wall time.
    Drag { from: [f64; 2], to: [f64; 2], seconds: f64 },
    /// The camera turned about the cloth, degrees: (left–right, up–down).
    Orbit { yaw_deg: f64, pitch_deg: f64 },
    /// The camera moved closer by this factor (below 1: farther).
    Zoom(f64),
    /// Frame the cloth (F).
    Frame,
    Open(Window),
    Close(Window),
    /// Colour the cloth by a field (`fabric`, `warp`, `weft`, `shear`, `bending`).
    Colour(super::colour::ColourMap),
    Screenshot(PathBuf),
    Quit,
}

impl Action {
    /// Whether the step only looks at the scene (the camera, the windows, the colours, a
    /// picture, the pin) and so leaves it held where a wait for simulated time stopped it.
    pub fn looks(&self) -> bool {
        matches!(
            self,
            Self::Pin | Self::Unpin | Self::Orbit { .. } | Self::Zoom(_) | Self::Frame | Self::Open(_) | Self::Close(_) | Self::Colour(_) | Self::Screenshot(_) | Self::Quit
        )
    }
}

/// A step: its action and the line of the script it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    pub line: usize,
    pub action: Action,
}

/// A checked script.
#[derive(Debug, Clone, PartialEq)]
pub struct Script {
    /// The file, as given.
    pub path: PathBuf,
    pub steps: Vec<Step>,
    /// Play the steps again from the first once the last is done (a demo left running).
    pub repeat: bool,
}

/// A bad script: the file, the line, what is wrong and how to put it right.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}{}: {message}", line.map(|l| format!(", line {l}")).unwrap_or_default())]
pub struct ScriptError {
    pub file: String,
    pub line: Option<usize>,
    pub message: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScript {
    #[serde(default)]
    repeat: bool,
    #[serde(default)]
    step: Vec<toml::Spanned<RawStep>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawStep {
    wait: Option<String>,
    wait_simulated_s: Option<f64>,
    wait_wall_s: Option<f64>,
    timeout_s: Option<f64>,
    play: Option<bool>,
    pause: Option<bool>,
    reset: Option<bool>,
    path: Option<String>,
    fabric: Option<String>,
    fabric_file: Option<String>,
    recut: Option<String>,
    grain: Option<RawGrain>,
    test: Option<String>,
    pin: Option<bool>,
    unpin: Option<bool>,
    drag: Option<RawDrag>,
    orbit_deg: Option<[f64; 2]>,
    zoom: Option<f64>,
    frame: Option<bool>,
    open: Option<String>,
    close: Option<String>,
    colour: Option<String>,
    screenshot: Option<String>,
    quit: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrain {
    panel: String,
    deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDrag {
    from: [f64; 2],
    to: [f64; 2],
    #[serde(default = "default_drag_seconds")]
    seconds: f64,
}

fn default_drag_seconds() -> f64 {
    0.5
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..text.floor_char_boundary(offset.min(text.len()))].matches('\n').count() + 1
}

/// Every action key a step may hold, for the message when it holds none or several.
const ACTION_KEYS: &str = "wait, wait_simulated_s, wait_wall_s, play, pause, reset, path, fabric, fabric_file, recut, grain, test, \
                           pin, unpin, drag, orbit_deg, zoom, frame, open, close, colour, screenshot, quit";

impl Script {
    /// Reads and checks the script at `path` against `scene`, the scene it will run on. Every
    /// file it names is read now; every output it names is returned for the output guard.
    pub fn load(path: &Path, scene: &SceneConfig) -> Result<Self, ScriptError> {
        let file = path.display().to_string();
        let fail = |line: Option<usize>, message: String| ScriptError { file: file.clone(), line, message };
        let text = read_text(path, FileKind::Script).map_err(|e| fail(None, e.to_string()))?;
        let raw: RawScript = toml::from_str(&text).map_err(|e| {
            let line = e.span().map(|s| line_of(&text, s.start));
            fail(line, format!("{}; a script is a list of [[step]] tables, each with one action ({ACTION_KEYS})", e.message().trim()))
        })?;
        if raw.step.is_empty() {
            return Err(fail(None, "no [[step]]: a script lists what to do, e.g. [[step]] wait = \"settled\"".into()));
        }
        let base = path.parent().filter(|p| !p.as_os_str().is_empty()).map(Path::to_path_buf);
        let mut steps = Vec::with_capacity(raw.step.len());
        for spanned in &raw.step {
            let line = line_of(&text, spanned.span().start);
            let action = step_action(spanned.get_ref(), scene, base.as_deref()).map_err(|m| fail(Some(line), m))?;
            steps.push(Step { line, action });
        }
        let quits = steps.iter().any(|s| s.action == Action::Quit);
        if raw.repeat && quits {
            return Err(fail(None, "repeat = true plays the steps forever, so a quit step would never be reached: drop one or the other".into()));
        }
        if let Some(step) = steps.iter().position(|s| s.action == Action::Quit).filter(|&i| i + 1 < steps.len()) {
            return Err(fail(Some(steps[step + 1].line), "a step after quit would never run: end the script with quit".into()));
        }
        Ok(Self { path: path.to_path_buf(), steps, repeat: raw.repeat })
    }

    /// The files the script writes (its screenshots), in order.
    pub fn outputs(&self) -> impl Iterator<Item = (usize, &Path)> {
        self.steps.iter().filter_map(|s| match &s.action {
            Action::Screenshot(p) => Some((s.line, p.as_path())),
            _ => None,
        })
    }
}

/// The one action a step holds, by its key.
fn action_key(raw: &RawStep) -> Result<&'static str, String> {
    let set: Vec<&str> = [
        ("wait", raw.wait.is_some()),
        ("wait_simulated_s", raw.wait_simulated_s.is_some()),
        ("wait_wall_s", raw.wait_wall_s.is_some()),
        ("play", raw.play.is_some()),
        ("pause", raw.pause.is_some()),
        ("reset", raw.reset.is_some()),
        ("path", raw.path.is_some()),
        ("fabric", raw.fabric.is_some()),
        ("fabric_file", raw.fabric_file.is_some()),
        ("recut", raw.recut.is_some()),
        ("grain", raw.grain.is_some()),
        ("test", raw.test.is_some()),
        ("pin", raw.pin.is_some()),
        ("unpin", raw.unpin.is_some()),
        ("drag", raw.drag.is_some()),
        ("orbit_deg", raw.orbit_deg.is_some()),
        ("zoom", raw.zoom.is_some()),
        ("frame", raw.frame.is_some()),
        ("open", raw.open.is_some()),
        ("close", raw.close.is_some()),
        ("colour", raw.colour.is_some()),
        ("screenshot", raw.screenshot.is_some()),
        ("quit", raw.quit.is_some()),
    ]
    .into_iter()
    .filter_map(|(key, given)| given.then_some(key))
    .collect();
    match set.as_slice() {
        [key] => Ok(*key),
        [] => Err(format!("this step does nothing: give it one action ({ACTION_KEYS})")),
        several => Err(format!("this step holds {}: give each action its own [[step]]", several.join(" and "))),
    }
}

/// The action of one step, checked against the scene.
fn step_action(raw: &RawStep, scene: &SceneConfig, base: Option<&Path>) -> Result<Action, String> {
    let key = action_key(raw)?;
    let is_wait = key.starts_with("wait");
    if raw.timeout_s.is_some() && !is_wait {
        return Err(format!("timeout_s bounds a wait, not {key}: move it to a wait step or drop it"));
    }
    let timeout_s = raw.timeout_s.unwrap_or(DEFAULT_TIMEOUT_S);
    if !(timeout_s.is_finite() && timeout_s > 0.0 && timeout_s <= LONGEST_S) {
        return Err(format!("timeout_s = {timeout_s} must be a number of seconds above 0 and at most {LONGEST_S}"));
    }
    let garment = scene.garment.as_ref();
    let no_garment = |what: &str| format!("{what} needs a garment scene, and this scene is a {} test", crate::scene::kinds::of(scene.scene.kind).name());
    let flag = |value: Option<bool>| -> Result<(), String> {
        match value {
            Some(true) => Ok(()),
            _ => Err(format!("{key} = true is the only value it takes (leave the step out otherwise)")),
        }
    };
    let seconds = |name: &str, value: f64| -> Result<f64, String> {
        if (0.0..=LONGEST_S).contains(&value) {
            Ok(value)
        } else {
            Err(format!("{name} = {value} must be a number of seconds from 0 to {LONGEST_S}"))
        }
    };
    Ok(match key {
        "wait" => {
            let until = match raw.wait.as_deref().unwrap_or_default() {
                "sewn" if garment.is_some() => WaitFor::Sewn,
                "sewn" => return Err(no_garment("wait = \"sewn\"")),
                "settled" if scene.scene.settle_speed.is_some() => WaitFor::Settled,
                "settled" => {
                    return Err("wait = \"settled\": this scene does not watch for settling (its scene.settle_speed is not set): \
                                wait = \"finished\", wait_simulated_s or wait_wall_s instead"
                        .to_string())
                }
                "finished" => WaitFor::Finished,
                other => return Err(format!("wait = \"{other}\": wait for \"sewn\", \"settled\" or \"finished\" (or use wait_simulated_s, wait_wall_s)")),
            };
            Action::Wait { until, timeout_s }
        }
        "wait_simulated_s" => Action::Wait { until: WaitFor::Simulated(seconds(key, raw.wait_simulated_s.unwrap_or_default())?), timeout_s },
        "wait_wall_s" => Action::Wait { until: WaitFor::Wall(seconds(key, raw.wait_wall_s.unwrap_or_default())?), timeout_s },
        "play" => flag(raw.play).map(|()| Action::Play)?,
        "pause" => flag(raw.pause).map(|()| Action::Pause)?,
        "reset" => flag(raw.reset).map(|()| Action::Reset)?,
        "pin" => flag(raw.pin).map(|()| Action::Pin)?,
        "unpin" => flag(raw.unpin).map(|()| Action::Unpin)?,
        "frame" => flag(raw.frame).map(|()| Action::Frame)?,
        "quit" => flag(raw.quit).map(|()| Action::Quit)?,
        "path" => match raw.path.as_deref().unwrap_or_default() {
            "fast" => Action::Path(SolverPath::Fast),
            "exact" => Action::Path(SolverPath::Exact),
            other => return Err(format!("path = \"{other}\": the solver path is \"exact\" or \"fast\"")),
        },
        "fabric" => {
            let name = raw.fabric.clone().unwrap_or_default();
            if !FABRICS.iter().any(|f| f.name == name) {
                let names: Vec<&str> = FABRICS.iter().map(|f| f.name).collect();
                return Err(format!("fabric = \"{name}\" is not a bundled fabric; one of {} (or fabric_file = \"FILE.toml\")", names.join(", ")));
            }
            Action::Fabric(name)
        }
        "fabric_file" => {
            let given = PathBuf::from(raw.fabric_file.as_deref().unwrap_or_default());
            let path = match base {
                Some(dir) if given.is_relative() => dir.join(&given),
                _ => given,
            };
            let fabric = super::files::read_fabric(&path).map_err(|e| format!("fabric_file = \"{}\": {e}", path.display()))?;
            Action::FabricFile { path, fabric: Box::new(fabric) }
        }
        "recut" => {
            if garment.is_none() {
                return Err(no_garment("recut"));
            }
            match raw.recut.as_deref().unwrap_or_default() {
                "straight" => Action::Recut(Cut::Straight),
                "bias" => Action::Recut(Cut::Bias),
                other => return Err(format!("recut = \"{other}\": recut \"straight\" or \"bias\" (or set one panel with grain = {{ panel, deg }})")),
            }
        }
        "grain" => {
            let Some(garment) = garment else { return Err(no_garment("grain")) };
            let grain = raw.grain.as_ref().expect("the key is set");
            if !garment.panels.iter().any(|p| p.name == grain.panel) {
                let names: Vec<&str> = garment.panels.iter().map(|p| p.name.as_str()).collect();
                return Err(format!("grain: no panel '{}' in this garment; its panels are {}", grain.panel, names.join(", ")));
            }
            if !(grain.deg.is_finite() && grain.deg.abs() <= 360.0) {
                return Err(format!("grain: deg = {} must be an angle in degrees from -360 to 360", grain.deg));
            }
            Action::Grain { panel: grain.panel.clone(), degrees: grain.deg }
        }
        "test" => {
            let name = raw.test.clone().unwrap_or_default();
            if !super::ui::TESTS.contains(&name.as_str()) {
                return Err(format!("test = \"{name}\": the fabric tests are {}", super::ui::TESTS.join(", ")));
            }
            Action::Test(name)
        }
        _ => view_action(key, raw, garment.is_some(), &no_garment)?,
    })
}

/// A step that acts on the view (drag, orbit, zoom, windows, colour map, screenshot);
/// `garment`: whether the scene is a garment's, `no_garment` the refusal where it is not.
fn view_action(key: &str, raw: &RawStep, garment: bool, no_garment: &dyn Fn(&str) -> String) -> Result<Action, String> {
    Ok(match key {
        "drag" => {
            let drag = raw.drag.as_ref().expect("the key is set");
            let inside = |p: [f64; 2]| p.iter().all(|c| (0.0..=1.0).contains(c));
            if !inside(drag.from) || !inside(drag.to) {
                return Err(format!(
                    "drag: from = {:?} and to = {:?} are places in the 3D view as fractions of its width and height, each from 0 to 1",
                    drag.from, drag.to
                ));
            }
            if !(drag.seconds.is_finite() && drag.seconds > 0.0 && drag.seconds <= 60.0) {
                return Err(format!("drag: seconds = {} must be above 0 and at most 60", drag.seconds));
            }
            Action::Drag { from: drag.from, to: drag.to, seconds: drag.seconds }
        }
        "orbit_deg" => {
            let [yaw_deg, pitch_deg] = raw.orbit_deg.expect("the key is set");
            if !(yaw_deg.is_finite() && pitch_deg.is_finite() && yaw_deg.abs() <= 360.0 && pitch_deg.abs() <= 180.0) {
                return Err(format!("orbit_deg = [{yaw_deg}, {pitch_deg}]: [left–right, up–down] in degrees, within ±360 and ±180"));
            }
            Action::Orbit { yaw_deg, pitch_deg }
        }
        "zoom" => {
            let factor = raw.zoom.expect("the key is set");
            if !(factor.is_finite() && (0.05..=20.0).contains(&factor)) {
                return Err(format!("zoom = {factor}: a factor from 0.05 to 20 (2 comes twice as close, 0.5 goes twice as far)"));
            }
            Action::Zoom(factor)
        }
        "open" | "close" => {
            let name = if key == "open" { raw.open.as_deref() } else { raw.close.as_deref() }.unwrap_or_default();
            let window = match name {
                "card" => Window::Card,
                "chart" => Window::Chart,
                "pattern" if garment => Window::Pattern,
                "pattern" => return Err(no_garment("the flat pattern")),
                other => return Err(format!("{key} = \"{other}\": the windows are \"card\", \"chart\" and \"pattern\"")),
            };
            if key == "open" { Action::Open(window) } else { Action::Close(window) }
        }
        "colour" => {
            let name = raw.colour.as_deref().unwrap_or_default();
            match super::colour::ColourMap::ALL.into_iter().find(|m| m.key() == name) {
                Some(map) => Action::Colour(map),
                None => {
                    let names: Vec<&str> = super::colour::ColourMap::ALL.iter().map(|m| m.key()).collect();
                    return Err(format!("colour = \"{name}\": one of {}", names.join(", ")));
                }
            }
        }
        "screenshot" => {
            let path = PathBuf::from(raw.screenshot.as_deref().unwrap_or_default());
            if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
                return Err(format!("screenshot = \"{}\": a screenshot is a PNG; name it FILE.png", path.display()));
            }
            Action::Screenshot(path)
        }
        _ => unreachable!("every key of the list is handled"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(name: &str) -> SceneConfig {
        crate::scene::load_scene(name, &[]).unwrap().0.into_config()
    }

    fn write(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rosette-script-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn a_garment_session_reads_with_its_lines() {
        let path = write(
            "ok.toml",
            "# a session\n[[step]]\nwait = \"sewn\"\ntimeout_s = 90\n\n[[step]]\nfabric = \"silk\"\n[[step]]\nrecut = \"bias\"\n[[step]]\n\
             grain = { panel = \"front\", deg = 90 }\n[[step]]\ndrag = { from = [0.5, 0.5], to = [0.5, 0.7] }\n[[step]]\nscreenshot = \"a.png\"\n[[step]]\nquit = true\n",
        );
        let script = Script::load(&path, &scene("skirt-gored-bias")).unwrap();
        assert_eq!(script.steps[0], Step { line: 2, action: Action::Wait { until: WaitFor::Sewn, timeout_s: 90.0 } });
        assert_eq!(script.steps[1].line, 6);
        assert_eq!(script.steps[2].action, Action::Recut(Cut::Bias));
        assert_eq!(script.steps[4].action, Action::Drag { from: [0.5, 0.5], to: [0.5, 0.7], seconds: 0.5 });
        assert_eq!(script.outputs().map(|(_, p)| p.to_path_buf()).collect::<Vec<_>>(), [PathBuf::from("a.png")]);
        assert_eq!(script.steps.last().unwrap().action, Action::Quit);
    }

    #[test]
    fn the_bundled_sessions_read_on_every_garment() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/sessions");
        let mut read = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            for garment in ["skirt-circle", "skirt-gored-bias", "skirt-gored-straight"] {
                Script::load(&path, &scene(garment)).unwrap_or_else(|e| panic!("{garment}: {e}"));
            }
            read += 1;
        }
        assert!(read >= 2, "{read} sessions in {}", dir.display());
    }

    #[test]
    fn bad_steps_are_refused_with_their_line_and_key() {
        let garment = scene("skirt-gored-bias");
        let lab = scene("euler-buckling");
        for (text, on, line, words) in [
            ("[[step]]\nwait = \"sewn\"\n[[step]]\nfabirc = \"silk\"\n", &garment, Some(4), &["fabirc", "unknown"][..]),
            ("[[step]]\nfabric = \"silk\"\nrecut = \"bias\"\n", &garment, Some(1), &["fabric and recut", "own [[step]]"][..]),
            ("[[step]]\n", &garment, Some(1), &["does nothing"][..]),
            ("[[step]]\nfabric = \"velvet\"\n", &garment, Some(1), &["velvet", "not a bundled fabric", "silk"][..]),
            ("[[step]]\nwait = \"sewn\"\n", &lab, Some(1), &["garment scene"][..]),
            ("[[step]]\nwait = \"settled\"\n", &lab, Some(1), &["settle_speed", "finished"][..]),
            ("[[step]]\ngrain = { panel = \"sleeve\", deg = 45 }\n", &garment, Some(1), &["sleeve", "front, right, back, left"][..]),
            ("[[step]]\ndrag = { from = [0.5, 1.5], to = [0.5, 0.5] }\n", &garment, Some(1), &["fractions"][..]),
            ("[[step]]\nwait_wall_s = -1\n", &garment, Some(1), &["wait_wall_s = -1"][..]),
            ("[[step]]\nwait_wall_s = nan\n", &garment, Some(1), &["wait_wall_s = NaN"][..]),
            ("[[step]]\npin = true\ntimeout_s = 5\n", &garment, Some(1), &["timeout_s", "not pin"][..]),
            ("[[step]]\nscreenshot = \"a.jpg\"\n", &garment, Some(1), &["PNG"][..]),
            ("[[step]]\nquit = true\n[[step]]\npin = true\n", &garment, Some(3), &["after quit"][..]),
            ("repeat = true\n[[step]]\nquit = true\n", &garment, None, &["repeat", "quit"][..]),
            ("[[step]]\nfabric_file = \"no-such.toml\"\n", &garment, Some(1), &["no-such.toml", "no such file"][..]),
            ("[[step]\nwait = 1\n", &garment, Some(1), &["[[step]]"][..]),
            ("", &garment, None, &["no [[step]]"][..]),
        ] {
            let path = write("bad.toml", text);
            let err = Script::load(&path, on).unwrap_err();
            let shown = err.to_string();
            assert_eq!(err.line, line, "{text:?}: {shown}");
            for word in words {
                assert!(shown.contains(word), "{text:?}: {shown} lacks {word}");
            }
        }
    }
}
