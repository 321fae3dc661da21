//! The window driven as users drive it: scripted sessions (`rosette view SCENE --script`)
//! under Xvfb, on Mesa's software renderer. Every bundled garment and an imported
//! GarmentCode pattern, on both paths, is sewn, settles, is pinned, switched to denim,
//! recut on the other grain, dragged and saved as a picture; a drop scene and a laboratory
//! scene get one session each. Each test asserts on the session's report (the window's own
//! snapshots) and on its screenshot.
//!
//! The window once died on every garment at the first frame after the seams welded (the
//! renderer kept the unwelded mesh's triangles): these sessions are what would have caught
//! it. They run the garments on a coarser mesh than the bundled one (`mesh.edge_length =
//! 0.035`), which keeps CI inside its time; the sewing, the weld and every step of the loop
//! are the same.
//!
//! Needs `xvfb-run` (Debian: xvfb, xauth) and Mesa; `.ci/run` installs them. Where it is
//! missing the tests say they are skipped, except in CI (`CI` set), where they fail.

mod common;

use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The bundled garments' mesh edge in these sessions, m (the bundled ones are 2 cm).
const COARSE_EDGE: &str = "mesh.edge_length=0.035";

/// A saturated red for the cloth: [`cloth_share`] tells the cloth from the grey background,
/// the form and the props by its saturation, and some bundled fabrics' own looks (the
/// cotton's pale blue, the wool's natural) are nearly grey under the light.
const RED_LOOK: &str = "fabric.appearance.colour=#B03A2E";

fn xvfb_available() -> bool {
    Command::new("sh").args(["-c", "command -v xvfb-run"]).stdout(Stdio::null()).status().is_ok_and(|s| s.success())
}

/// A folder of its own for one session's files.
fn folder(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("sessions-{}", std::process::id())).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// What a session left: its exit code, its report, its folder and its standard error.
struct Played {
    code: Option<i32>,
    report: Value,
    dir: PathBuf,
    stderr: String,
}

impl Played {
    /// The report's entry of the `k`-th step (from 0) whose action starts with `action`
    /// (as the report spells it: `Wait { until: Settled`, `Drag`, `Fabric`).
    fn step(&self, action: &str, k: usize) -> &Value {
        let steps = self.report["steps"].as_array().unwrap();
        steps.iter().filter(|s| s["action"].as_str().unwrap().starts_with(action)).nth(k).unwrap_or_else(|| panic!("no step {action} #{k}: {}", self.report))
    }

    fn dc(step: &Value) -> f64 {
        step["measures"]["garment_drape_coefficient"].as_f64().unwrap_or_else(|| panic!("no drape coefficient: {step}"))
    }
}

/// Plays `script` on `scene` (with `args`) under Xvfb; None where no Xvfb is installed.
fn play(name: &str, scene: &str, args: &[&str], script: &str) -> Option<Played> {
    if !xvfb_available() {
        assert!(std::env::var_os("CI").is_none(), "CI must install xvfb and xauth (see .ci/run)");
        writeln!(std::io::stderr(), "SKIPPED session {name}: no xvfb-run (apt-get install xvfb xauth mesa-vulkan-drivers)").ok();
        return None;
    }
    let dir = folder(name);
    let script_path = dir.join("session.toml");
    std::fs::write(&script_path, script).unwrap();
    let report = dir.join("report.json");
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_rosette"), "view", scene])
        .args(args)
        .args(["--script", script_path.to_str().unwrap(), "--report", report.to_str().unwrap(), "--force"])
        .current_dir(&dir)
        .env("XDG_RUNTIME_DIR", common::runtime_dir())
        // Two sessions may run at once on the two cores.
        .env("RAYON_NUM_THREADS", "1")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("xvfb-run starts");
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{name}: the viewer panicked:\n{stderr}");
    let text = std::fs::read_to_string(&report).unwrap_or_else(|e| panic!("{name}: no report ({e}); exit {:?}:\n{stderr}", output.status.code()));
    Some(Played { code: output.status.code(), report: serde_json::from_str(&text).unwrap(), dir, stderr })
}

/// The share of the 3D view's pixels (between the side panels) coloured like cloth rather
/// than the grey background, form, props and shadow: saturated pixels.
fn cloth_share(picture: &Path) -> f64 {
    let image = image::open(picture).unwrap_or_else(|e| panic!("{}: {e}", picture.display())).to_rgb8();
    let (w, h) = image.dimensions();
    // The view lies between the left panel (about 340 points) and the right one (360).
    let (x0, x1, y0) = (w * 27 / 100, w * 72 / 100, h / 10);
    let mut coloured = 0u64;
    for y in y0..h {
        for x in x0..x1 {
            let p = image.get_pixel(x, y).0.map(i32::from);
            let spread = p.iter().max().unwrap() - p.iter().min().unwrap();
            coloured += u64::from(spread > 60);
        }
    }
    coloured as f64 / (f64::from(x1 - x0) * f64::from(h - y0))
}

/// The designer's loop on one garment: sewn, settled, pinned, switched to denim (stiffer
/// than every bundled garment's fabric, so its hem stands out farther: a higher drape
/// coefficient), recut on the other grain, dragged, saved.
fn garment_loop(name: &str, scene: &str, path: &str, recut: &str) {
    let script = format!(
        "[[step]]\nwait = \"sewn\"\ntimeout_s = 600\n\
         [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
         [[step]]\nscreenshot = \"settled.png\"\n\
         [[step]]\npin = true\n\
         [[step]]\nfabric = \"denim\"\n\
         [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
         [[step]]\nrecut = \"{recut}\"\n\
         [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
         [[step]]\nframe = true\n\
         [[step]]\ndrag = {{ from = [0.5, 0.62], to = [0.56, 0.72], seconds = 0.6 }}\n\
         [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
         [[step]]\nscreenshot = \"recut.png\"\n\
         [[step]]\nquit = true\n"
    );
    // The drag lasts 0.6 s of wall time, as many steps as the frames allow, so where it
    // leaves the cloth depends on the machine's load: beside the suite's other tests it
    // held the straight skirt from 7.51 to 8.90 s and the skirt had not settled again when
    // the garment's 6 s from the drag ran out at 13.51 s; run alone, held to 8.81 s, it
    // settled at 10.46 s. The session asks whether each change settles, not how fast: 15 s
    // (docs/performance-log.md, "2026-12-08: the second core").
    let args = ["--set", COARSE_EDGE, "--set", RED_LOOK, "--set", "scene.duration=15", path];
    let Some(played) = play(name, scene, &args, &script) else { return };
    let report = &played.report;
    assert_eq!(played.code, Some(0), "{name}: {}\n{}", report["outcome"], played.stderr);
    let opened = report["opened"]["vertices"].as_u64().unwrap();
    let settled = |k| played.step("Wait { until: Settled", k);
    let sewn = played.step("Wait { until: Sewn", 0);
    assert!(sewn["sewn_at_s"].as_f64().is_some(), "{name}: {sewn}");
    assert!(sewn["vertices"].as_u64().unwrap() < opened, "{name}: the weld merges the seams' vertices: {opened} → {}", sewn["vertices"]);
    assert_eq!(sewn["path"], if path == "--fast" { "fast" } else { "exact" }, "{name}");
    let wool = settled(0);
    assert!(wool["settled_at_s"].as_f64().is_some(), "{name}: {wool}");
    let denim = settled(1);
    assert_eq!(denim["drape"]["cause"], "fabric switch", "{name}");
    assert_eq!(denim["drape"]["from_sewn"], true, "{name}: a new fabric re-drapes the sewn garment: {denim}");
    assert!(denim["settled_at_s"].as_f64().is_some(), "{name}: {denim}");
    let pinned = &report["pinned"];
    assert_ne!(pinned["fabric"], denim["fabric"], "{name}");
    let pinned_dc = pinned["measures"]["garment_drape_coefficient"].as_f64().unwrap();
    assert_eq!(pinned_dc, Played::dc(wool), "{name}: the pin keeps the drape it was taken on");
    assert!(
        Played::dc(denim) > pinned_dc,
        "{name}: denim, several times stiffer in bending, stands out farther: DC {} against the pinned {} ({})",
        Played::dc(denim),
        pinned_dc,
        pinned["fabric"]
    );
    let recut_step = settled(2);
    assert_eq!(recut_step["drape"]["cause"], "recut", "{name}");
    assert_eq!(recut_step["drape"]["from_sewn"], true, "{name}: the same pattern on another grain re-drapes where it hangs");
    assert!(recut_step["settled_at_s"].as_f64().is_some(), "{name}: {recut_step}");
    assert_eq!(played.step("Drag", 0)["held_a_vertex"], true, "{name}: the drag picked the cloth");
    assert!(settled(3)["settled_at_s"].as_f64().is_some(), "{name}: settled again after the drag");
    for picture in ["settled.png", "recut.png"] {
        let share = cloth_share(&played.dir.join(picture));
        assert!(share > 0.03, "{name}: {picture} shows cloth in {:.1} % of the view", 100.0 * share);
    }
}

#[test]
fn the_bias_skirt_on_the_fast_path() {
    garment_loop("bias-fast", "skirt-gored-bias", "--fast", "straight");
}

#[test]
fn the_bias_skirt_on_the_exact_path() {
    garment_loop("bias-exact", "skirt-gored-bias", "--exact", "straight");
}

#[test]
fn the_straight_skirt_on_the_fast_path() {
    garment_loop("straight-fast", "skirt-gored-straight", "--fast", "bias");
}

#[test]
fn the_straight_skirt_on_the_exact_path() {
    garment_loop("straight-exact", "skirt-gored-straight", "--exact", "bias");
}

#[test]
fn the_circle_skirt_on_the_fast_path() {
    garment_loop("circle-fast", "skirt-circle", "--fast", "bias");
}

#[test]
fn the_circle_skirt_on_the_exact_path() {
    garment_loop("circle-exact", "skirt-circle", "--exact", "bias");
}

#[test]
fn the_dress_on_the_fast_path() {
    garment_loop("dress-fast", "shift-dress", "--fast", "bias");
}

#[test]
fn the_dress_on_the_exact_path() {
    garment_loop("dress-exact", "shift-dress", "--exact", "bias");
}

fn pattern() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/patterns/aline-skirt_specification.json").display().to_string()
}

#[test]
fn an_imported_pattern_on_the_fast_path() {
    garment_loop("pattern-fast", &pattern(), "--fast", "bias");
}

#[test]
fn an_imported_pattern_on_the_exact_path() {
    garment_loop("pattern-exact", &pattern(), "--exact", "bias");
}

/// A cloth dropped on a table: a picture as it lands, held at the time the script waited
/// for; it settles, a drag lifts a corner, it settles again, and the picture shows it.
#[test]
fn a_tablecloth_lands_is_dragged_and_settles() {
    let script = "[[step]]\nwait_simulated_s = 0.2\n\
                  [[step]]\nscreenshot = \"landing.png\"\n\
                  [[step]]\norbit_deg = [20, 0]\n\
                  [[step]]\nscreenshot = \"landing-turned.png\"\n\
                  [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
                  [[step]]\nframe = true\n\
                  [[step]]\ndrag = { from = [0.5, 0.5], to = [0.5, 0.35], seconds = 0.6 }\n\
                  [[step]]\nwait = \"settled\"\ntimeout_s = 900\n\
                  [[step]]\nscreenshot = \"tablecloth.png\"\n\
                  [[step]]\nquit = true\n";
    // The drag restarts the scene's clock, so the bundled 5 s are what the cloth has to settle
    // again after it. That took 2.8–3.5 s from the drag's end in three runs (the drag held
    // the cloth for 0.4–0.5 s of simulated time, as many steps as the frames' pace allowed)
    // and once more than 4.6 s: a longer scene, so that the test asks whether it settles, not
    // how fast (docs/performance-log.md, "2026-12-07, late").
    let Some(played) = play("tablecloth", "tablecloth", &["--fast", "--set", RED_LOOK, "--set", "scene.duration=15"], script) else { return };
    assert_eq!(played.code, Some(0), "{}\n{}", played.report["outcome"], played.stderr);
    // The wait stands the scene at the first step that reaches 0.2 s until a step that needs
    // it running: both pictures show that moment.
    let landing = played.step("Screenshot", 0);
    let (at, dt) = (landing["picture_time_s"].as_f64().unwrap(), landing["last_step"]["dt_s"].as_f64().unwrap());
    assert!(at >= 0.2 - 1e-9 && at < 0.2 + dt, "{landing}");
    assert_eq!(played.step("Screenshot", 1)["picture_time_s"].as_f64(), Some(at));
    let first = played.step("Wait { until: Settled", 0);
    let dc = first["measures"]["drape_coefficient"].as_f64().unwrap();
    // A 1 m square over a 0.6 m square table: its shadow lies between the table's and the
    // cloth's own area, so the coefficient lies strictly between 0 and 1.
    assert!(dc > 0.0 && dc < 1.0, "{first}");
    assert_eq!(played.step("Drag", 0)["held_a_vertex"], true);
    assert!(played.step("Wait { until: Settled", 1)["settled_at_s"].as_f64().is_some());
    assert!(cloth_share(&played.dir.join("tablecloth.png")) > 0.03);
}

/// The laboratory: a tensile test runs to its end, then the cantilever runs from the fabric
/// tests' button on the same fabric.
#[test]
fn a_laboratory_session_runs_a_test_and_then_another() {
    let script = "[[step]]\nwait = \"finished\"\ntimeout_s = 600\n\
                  [[step]]\ntest = \"cantilever\"\n\
                  [[step]]\nwait = \"finished\"\ntimeout_s = 600\n\
                  [[step]]\ncolour = \"bending\"\n\
                  [[step]]\nscreenshot = \"cantilever.png\"\n\
                  [[step]]\nquit = true\n";
    let Some(played) = play("laboratory", "tensile-warp", &[], script) else { return };
    assert_eq!(played.code, Some(0), "{}\n{}", played.report["outcome"], played.stderr);
    let tensile = played.step("Wait { until: Finished", 0);
    assert_eq!(tensile["scene"], "tensile-warp");
    let strain = tensile["measures"]["final_strain"].as_f64().unwrap();
    // The bundled test pulls to 6 % strain.
    assert!((strain - 0.06).abs() < 0.003, "{tensile}");
    let cantilever = played.step("Wait { until: Finished", 1);
    assert_eq!(cantilever["scene"], "cantilever");
    assert!(cantilever["measures"]["tip_drop"].as_f64().unwrap() > 0.0, "{cantilever}");
    assert!(cloth_share(&played.dir.join("cantilever.png")) > 0.01);
}

/// A bad script is refused before any window opens: its line and key named, exit 2.
#[test]
fn a_bad_script_is_refused_before_the_window_opens() {
    let dir = folder("bad");
    for (text, words) in [
        ("[[step]]\nwait = \"sewn\"\n[[step]]\nfabirc = \"silk\"\n", &["line 4", "fabirc"][..]),
        ("[[step]]\nrecut = \"bias\"\n", &["line 1", "garment"][..]),
        ("[[step]]\nscreenshot = \"session.toml\"\n", &["PNG"][..]),
    ] {
        let script = dir.join("session.toml");
        std::fs::write(&script, text).unwrap();
        // No display at all: the script is checked before the viewer looks for one.
        let output = Command::new(env!("CARGO_BIN_EXE_rosette"))
            .args(["view", "euler-buckling", "--script", script.to_str().unwrap()])
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{text}: {stderr}");
        for word in words {
            assert!(stderr.contains(word), "{text}: {stderr} lacks {word}");
        }
        assert!(!stderr.contains("no display"), "{stderr}");
    }
    // A screenshot over the script itself: the output guard refuses it.
    let script = dir.join("guarded.toml");
    std::fs::write(&script, "[[step]]\nscreenshot = \"guarded.png\"\n").unwrap();
    std::fs::write(dir.join("guarded.png"), b"not rosette's").unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["view", "euler-buckling", "--script", script.to_str().unwrap()])
        .current_dir(&dir)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("guarded.png") && stderr.contains("--force"), "{stderr}");
}
