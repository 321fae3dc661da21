//! Garment input that cannot hurt, one test per class of failure (docs/robustness.md,
//! "Garment input"): every file a run reads is known to the output guard; the work before
//! the first step is estimated and refused or bounded; a garment not on its form is said,
//! not measured; inputs that contradict each other are refused; a hem drawn as many short
//! segments is not a fold; exit codes follow the documented order; an interrupted run
//! keeps what a `--max-wall` stop keeps.

use rosette::scene::{Scene, load_scene};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A folder of this test's own.
fn folder(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("garment-input-{}", std::process::id())).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn rosette(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).current_dir(dir).env("RAYON_NUM_THREADS", "1").stdin(Stdio::null()).output().expect("rosette runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A panel 60 cm long and 2·`HW` cm wide hung by its top edge from an OBJ body: a garment
/// scene that builds in a moment. `BOTTOM` is its bottom edge's entry (or entries).
const STRIP: &str = r#"
[scene]
kind = "garment"
duration = 1.0
[fabric]
preset = "wool"
[mesh]
edge_length = 0.01
[solver]
integrator = "implicit-euler"
dt = 0.01
[contact]
self_collision = true
[garment]
units = "cm"
sewing_time = 0.5
[garment.form]
obj = "FORM"
scale = 0.05
[[garment.panels]]
name = "strip"
grain_deg = 90
start = [-HW, 0]
edges = [
  BOTTOM
  { name = "right", to = [HW, 60] },
  { name = "top", to = [-HW, 60] },
  { name = "left", to = [-HW, 0] },
]
placement = { around = "plane", angle_deg = 0, distance = 50, height = 150 }
[[garment.attachments]]
edge = "strip.top"
pin = true
"#;

fn strip(form: &str, bottom: &str, half_width: f64) -> String {
    STRIP.replace("FORM", form).replace("BOTTOM", bottom).replace("HW", &half_width.to_string())
}

const ONE_BOTTOM: &str = r#"{ name = "bottom", to = [2, 0] },"#;

/// Class 1: the garment form's OBJ body is read only when the scene is built, after the
/// output guard's check; the guard knows it all the same, and `--force` does not make it
/// an output.
#[test]
fn the_form_body_is_an_input_the_outputs_may_not_overwrite() {
    let dir = folder("form-body");
    std::fs::copy(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cushion.obj"), dir.join("body.obj")).unwrap();
    std::fs::write(dir.join("strip.toml"), strip("body.obj", ONE_BOTTOM, 2.0)).unwrap();
    let before = std::fs::read(dir.join("body.obj")).unwrap();
    for flag in ["--metrics", "--step-log"] {
        let out = rosette(&["run", "strip.toml", "--duration", "0.02", flag, "body.obj", "--force"], &dir);
        assert_eq!(out.status.code(), Some(2), "{flag}: {}", stderr(&out));
        assert!(stderr(&out).contains("mesh file (OBJ) this command reads"), "{flag}: {}", stderr(&out));
    }
    assert_eq!(std::fs::read(dir.join("body.obj")).unwrap(), before, "the body is untouched");
}

/// Class 6: a path that can only name a folder is refused before the run, not after it.
#[test]
fn an_output_ending_in_a_slash_is_refused_before_the_run() {
    let dir = folder("slash");
    let start = Instant::now();
    let out = rosette(&["run", "skirt-gored-straight", "--metrics", "results/"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--metrics results/") && stderr(&out).contains("names a folder"), "{}", stderr(&out));
    assert!(start.elapsed() < Duration::from_secs(30), "refused only after {:?}", start.elapsed());
}

/// Class 5: a hem drawn as a hundred collinear segments of 4 mm (as pattern tools export a
/// polyline) is the same panel as one straight edge, not a panel folded onto itself.
#[test]
fn a_hem_of_many_collinear_segments_is_not_a_fold() {
    let dir = folder("collinear");
    let bottom: String = (1..=100).map(|i| format!("{{ name = \"b{i}\", to = [{:.4}, 0] }},\n  ", -20.0 + 0.4 * f64::from(i))).collect();
    let path = dir.join("strip.toml");
    std::fs::write(&path, strip("assets/cushion.obj", &bottom, 20.0)).unwrap();
    let (config, _) = load_scene(path.to_str().unwrap(), &[]).unwrap_or_else(|e| panic!("{e}"));
    Scene::build(config).unwrap_or_else(|e| panic!("{e}"));
}

/// Class 2: an outline of hundreds of edges (a curve exported as a polyline) is checked
/// for crossings in linear time: `--plan` answers at once.
#[test]
fn an_outline_of_many_edges_is_checked_at_once() {
    let dir = folder("many-edges");
    // The bottom edge as 400 segments (each sampled into hundreds for the check).
    let bottom: String = (1..=400).map(|i| format!("{{ name = \"b{i}\", to = [{:.4}, 0] }},\n  ", -2.0 + 0.01 * f64::from(i))).collect();
    std::fs::write(dir.join("strip.toml"), strip("assets/cushion.obj", &bottom, 2.0)).unwrap();
    let start = Instant::now();
    let out = rosette(&["run", "strip.toml", "--plan"], &dir);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(start.elapsed() < Duration::from_secs(60), "the checks took {:?}", start.elapsed());
}

/// Class 2: a garment mesh too fine for the vertex cap, or for the memory this run has (4
/// GiB of address space here), is refused before any panel is meshed, naming the edge
/// length that fits.
#[test]
fn a_garment_too_fine_to_build_is_refused_before_it_is_meshed() {
    let dir = folder("fine");
    let out = rosette(&["run", "skirt-gored-straight", "--set", "mesh.edge_length=0.0003"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("mesh.edge_length") && stderr(&out).contains("limit of 2000000"), "{}", stderr(&out));
    let out = Command::new("sh")
        .args(["-c", "ulimit -v 4194304 && exec \"$0\" \"$@\"", env!("CARGO_BIN_EXE_rosette")])
        .args(["run", "skirt-gored-straight", "--set", "mesh.edge_length=0.0015"])
        .current_dir(&dir)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("sh runs");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("mesh.edge_length") && stderr(&out).contains("GB"), "{}", stderr(&out));
}

/// Class 3: a garment that is not on its form (moved below where it is held, or below
/// the floor) is said so, with its drape measures withheld.
#[test]
fn a_garment_off_its_form_is_said_not_measured() {
    let dir = folder("off-form");
    let path = dir.join("strip.toml");
    std::fs::write(&path, strip("assets/cushion.obj", ONE_BOTTOM, 2.0)).unwrap();
    let (config, _) = load_scene(path.to_str().unwrap(), &[]).unwrap();
    let mut scene = Scene::build(config).unwrap();
    assert_eq!(rosette::scene::possible::off_form(&scene), None, "as placed, the strip hangs where it is held");
    for (drop, word) in [(0.5, "slid off"), (3.0, "below the floor")] {
        let mut moved = scene.state.x.clone();
        moved.iter_mut().for_each(|p| p.z -= drop);
        let kept = std::mem::replace(&mut scene.state.x, moved);
        let reason = rosette::scene::possible::off_form(&scene).unwrap_or_else(|| panic!("{drop} m down is off the form"));
        assert!(reason.contains(word), "{drop} m: {reason}");
        scene.state.x = kept;
    }
}

/// Class 6: where an output is lost and the garment is not sewn, the lost output is what
/// the exit code says (4): results the user cannot find outrank results that say they
/// are unfinished. The metrics go to a named pipe nobody reads.
#[test]
fn a_lost_output_outranks_an_unsewn_garment() {
    let dir = folder("lost-unsewn");
    let fifo = dir.join("metrics.json");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs");
    assert!(made.success());
    let out = rosette(&["run", "skirt-gored-straight", "--set", "mesh.edge_length=0.05", "--duration", "0.05", "--metrics", "metrics.json"], &dir);
    let text = stderr(&out);
    assert!(text.contains("--metrics") && text.contains("not sewn"), "{text}");
    assert_eq!(out.status.code(), Some(4), "{text}");
}

/// Class 7: Ctrl-C (or SIGTERM) stops a run at the end of its step; its metrics and step
/// log are kept as a `--max-wall` stop keeps them, the exit code is 128 + the signal, and
/// no staged file is left beside the outputs.
#[test]
fn an_interrupted_run_keeps_its_results_and_leaves_no_stray_file() {
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let dir = folder(&format!("interrupt-{signal}"));
        let child = Command::new(env!("CARGO_BIN_EXE_rosette"))
            .args(["run", "cusick-drape", "--metrics", "m.json", "--step-log", "log.csv"])
            .current_dir(&dir)
            .env("RAYON_NUM_THREADS", "1")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Into the run: the step log's rows are being written.
        let start = Instant::now();
        while std::fs::read_dir(&dir).unwrap().flatten().all(|e| !e.file_name().to_string_lossy().contains("log.csv")) && start.elapsed() < Duration::from_secs(60) {
            std::thread::sleep(Duration::from_millis(50));
        }
        std::thread::sleep(Duration::from_millis(1500));
        // SAFETY: a signal to the child this test started.
        assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
        let output = child.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(code), "{text}");
        let metrics: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("m.json")).unwrap()).unwrap();
        assert!(metrics["stopped_at_limit"].as_str().is_some_and(|s| s.contains("stopped by SIG")), "{metrics}");
        let log = std::fs::read_to_string(dir.join("log.csv")).unwrap();
        assert!(log.lines().count() > 1, "the step log keeps its rows");
        let stray: Vec<String> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect();
        assert!(stray.is_empty(), "stray files: {stray:?}");
    }
}

/// Class 4: a bending rigidity that underflows to nothing is refused, naming the key.
#[test]
fn a_rigidity_below_any_fabric_is_refused() {
    let dir = folder("tiny");
    let out = rosette(&["run", "cantilever", "--set", "fabric.bending_warp=5e-324"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("fabric.bending_warp") && stderr(&out).contains("below any fabric"), "{}", stderr(&out));
}

/// Class 6: a bad value given with `--set` on a list entry is blamed on that `--set`, not
/// on the bundled scene file.
#[test]
fn a_set_on_a_list_entry_is_blamed_on_the_set() {
    let dir = folder("blame");
    let out = rosette(&["run", "skirt-gored-straight", "--set", "garment.panels[0].grain_deg=1000"], &dir);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--set garment.panels[0].grain_deg=1000"), "{}", stderr(&out));
}
