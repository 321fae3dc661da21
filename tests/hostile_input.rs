//! Input a hostile user (or a typo at 2 a.m.) feeds `rosette run`: every outcome is a clean
//! refusal (exit 2, naming the key) or a finite, honest run (exit 0, 3, 5, 6 or 8, metrics
//! without NaN or null); never a panic (101), a signal or a hang.
//!
//! The property test derives every numeric key of every bundled scene (and of its fabric
//! file) from the presets themselves, so that a key added later is covered, and drives each
//! with every value of a fixed hostile list (NaN, ±inf, 0, negative, 1e±300, f32 overflow,
//! text, arrays of the wrong length); the focused tests below it are the repros,
//! named after what broke.

use rosette::settings::{FABRICS, SCENES};
use serde_json::Value;
use std::io::Read;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What one run of the binary did.
struct Outcome {
    /// Exit code; `None` where a signal ended it (or the timeout killed it).
    code: Option<i32>,
    stderr: String,
    timed_out: bool,
}

/// Runs the binary with `args`, killed after `limit` (a hang fails the caller's checks).
fn rosette(args: &[String], limit: Duration) -> Outcome {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the rosette binary runs");
    let mut stderr = child.stderr.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        stderr.read_to_string(&mut text).ok();
        text
    });
    let start = Instant::now();
    let (status, timed_out) = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break (status, false);
        }
        if start.elapsed() > limit {
            child.kill().ok();
            break (child.wait().expect("wait"), true);
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Outcome { code: status.code(), stderr: reader.join().unwrap_or_default(), timed_out }
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

fn temp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("hostile-{}-{name}", std::process::id()))
}

/// The first null (a NaN or infinity serialised) in a metrics report, by its path.
fn find_null(value: &Value, path: &str) -> Option<String> {
    match value {
        Value::Null => Some(path.to_string()),
        Value::Array(items) => items.iter().enumerate().find_map(|(i, v)| find_null(v, &format!("{path}[{i}]"))),
        Value::Object(map) => map.iter().find_map(|(k, v)| find_null(v, &format!("{path}.{k}"))),
        _ => None,
    }
}

/// Every numeric leaf of a TOML table (numbers, and arrays of numbers or of number pairs)
/// by dotted key, with its value. Arrays of tables (`[[props]]`) cannot be reached with
/// `--set KEY=VALUE`'s dotted keys and are left to the focused tests.
fn numeric_keys(table: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (key, value) in table {
        let path = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
        match value {
            toml::Value::Integer(_) | toml::Value::Float(_) => out.push((path, value.clone())),
            toml::Value::Array(items) if items.iter().all(|v| v.is_integer() || v.is_float() || v.is_array()) && !items.is_empty() => {
                out.push((path, value.clone()))
            }
            toml::Value::Table(t) => numeric_keys(t, &path, out),
            _ => {}
        }
    }
}

/// Hostile values for a key whose value in the preset is `original`: scalars as they are,
/// arrays with their first number replaced (and of the wrong length or type).
fn hostile_values(original: &toml::Value) -> Vec<String> {
    const SCALARS: [&str; 13] = ["nan", "inf", "-inf", "0", "-1", "1e300", "-1e300", "1e-300", "\"abc\"", "[1, 2]", "true", "1e39", "-0.3"];
    match original {
        toml::Value::Array(items) => {
            let mut values: Vec<String> = SCALARS[..8]
                .iter()
                .map(|bad| {
                    let mut replaced = items.clone();
                    // The first number of the first element.
                    match &mut replaced[0] {
                        toml::Value::Array(pair) => pair[0] = bad.parse::<toml::Value>().unwrap_or(toml::Value::Float(f64::NAN)),
                        first => *first = format!("v = {bad}").parse::<toml::Table>().map(|mut t| t.remove("v").unwrap()).unwrap(),
                    }
                    toml::Value::Array(replaced).to_string()
                })
                .collect();
            values.extend(["\"abc\"".to_string(), "[1]".to_string(), "7".to_string()]);
            values
        }
        _ => SCALARS.iter().map(|s| s.to_string()).collect(),
    }
}

/// The property test: for every numeric key of every bundled scene, a sample of hostile
/// values (fixed seed) through `--set`, each run short. Checks the outcome classes above.
#[test]
fn hostile_values_through_set_are_refused_or_run_honestly() {
    let mut cases = Vec::new();
    for scene in SCENES {
        // With the bundled base it names laid under it: the base's keys are the scene's too.
        let (table, _) = rosette::settings::read::with_base(scene.text.parse().unwrap(), scene.name).unwrap();
        let mut keys = Vec::new();
        numeric_keys(&table, "", &mut keys);
        // The fabric file's keys reach the scene as fabric.*.
        if let Some(name) = table.get("fabric").and_then(|f| f.get("preset")).and_then(|p| p.as_str()) {
            let fabric: toml::Table = FABRICS.iter().find(|f| f.name == name).unwrap().text.parse().unwrap();
            let mut fabric_keys = Vec::new();
            numeric_keys(&fabric, "fabric", &mut fabric_keys);
            fabric_keys.retain(|(k, _)| !keys.iter().any(|(s, _)| s == k));
            keys.extend(fabric_keys);
        }
        let dt = table["solver"]["dt"].as_float().unwrap();
        for (key, value) in keys {
            cases.push((scene.name, key, value, dt));
        }
    }
    assert!(cases.len() > 150, "keys found: {}", cases.len());
    // Every hostile value of every key: most are refused in milliseconds, and the runs that
    // pass take two steps, so the whole sweep takes under a minute on two cores.
    let mut runs = Vec::new();
    for (scene, key, original, dt) in &cases {
        for value in hostile_values(original) {
            runs.push((*scene, key.clone(), value, *dt, runs.len()));
        }
    }
    let failures = std::sync::Mutex::new(Vec::new());
    let next = std::sync::atomic::AtomicUsize::new(0);
    let started = Instant::now();
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some((scene, key, value, dt, tag)) = runs.get(i) else { break };
                    if let Err(message) = check_run(scene, key, value, *dt, *tag) {
                        failures.lock().unwrap().push(message);
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    eprintln!("{} runs over {} keys in {:.1} s", runs.len(), cases.len(), started.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "{} of {} runs failed:\n{}", failures.len(), runs.len(), failures.join("\n"));
}

/// One hostile run: its outcome, or what was wrong with it.
fn check_run(scene: &str, key: &str, value: &str, dt: f64, tag: usize) -> Result<(), String> {
    let metrics = temp(&format!("{tag}.json"));
    let set = format!("{key}={value}");
    // Two of the scene's own steps: long enough to solve, short enough for the sweep.
    let duration = format!("{}", 2.0 * dt);
    let args = strings(&["run", scene, "--set", &set, "--duration", &duration, "--max-wall", "30", "--metrics", metrics.to_str().unwrap()]);
    let out = rosette(&args, Duration::from_secs(60));
    let context = format!("rosette run {scene} --set {set} --duration {duration}");
    let result = (|| {
        if out.timed_out {
            return Err(format!("{context}: still running after 60 s (a hang)"));
        }
        match out.code {
            Some(2) => {
                if !out.stderr.contains(key) {
                    return Err(format!("{context}: refused without naming {key}: {}", out.stderr.trim()));
                }
                // Values are quoted to a few figures, never as 1e300's 301 digits.
                let longest = out.stderr.split(|c: char| !c.is_ascii_digit()).map(str::len).max().unwrap_or(0);
                if longest >= 20 {
                    return Err(format!("{context}: a {longest}-digit number in the message: {}", out.stderr.trim()));
                }
                Ok(())
            }
            // Exit 8: a garment whose seams had not closed when the run ended (two steps are
            // far short of its sewing time), reported with its metrics.
            Some(0 | 3 | 5 | 6 | 8) => {
                let text = std::fs::read_to_string(&metrics).map_err(|e| format!("{context}: exit {:?} without metrics: {e}", out.code))?;
                let report: Value = serde_json::from_str(&text).map_err(|e| format!("{context}: metrics are not JSON: {e}"))?;
                if let Some(path) = find_null(&report, "metrics") {
                    return Err(format!("{context}: exit {:?} with a null (NaN or infinity) at {path}", out.code));
                }
                if out.code == Some(0) && !(report["stable"] == true && report["converged"] == true) {
                    return Err(format!("{context}: exit 0 but stable = {}, converged = {}", report["stable"], report["converged"]));
                }
                Ok(())
            }
            code => Err(format!("{context}: exit {code:?}: {}", out.stderr.trim())),
        }
    })();
    std::fs::remove_file(&metrics).ok();
    result
}

// ---------------------------------------------------------------------------------------
// The repros, each named after what broke
// ---------------------------------------------------------------------------------------

const QUICK: Duration = Duration::from_secs(60);

/// Runs `args` and checks it is refused with exit 2, quickly, naming each of `words`.
fn assert_refused(args: &[&str], words: &[&str]) {
    let start = Instant::now();
    let out = rosette(&strings(args), QUICK);
    assert_eq!(out.code, Some(2), "{args:?}: {}", out.stderr);
    for word in words {
        assert!(out.stderr.contains(word), "{args:?}: the message should name '{word}': {}", out.stderr);
    }
    assert!(start.elapsed() < Duration::from_secs(10), "{args:?}: refused only after {:?}", start.elapsed());
}

#[test]
fn non_finite_cloth_position_no_longer_hangs_the_contact_search() {
    assert_refused(&["run", "cusick-drape-30", "--set", "cloth.position=[nan,0,0]", "--duration", "0.02"], &["--set cloth.position", "finite"]);
    assert_refused(&["run", "cusick-drape-30", "--set", "test.perturbation=inf", "--duration", "0.02"], &["test.perturbation"]);
    assert_refused(&["run", "cusick-drape-30", "--set", "test.perturbation=1", "--duration", "0.02"], &["test.perturbation", "mesh.edge_length"]);
}

#[test]
fn a_picosecond_step_is_refused_by_the_step_bound_instead_of_running_for_ever() {
    assert_refused(&["run", "cusick-drape-30", "--set", "solver.dt=1e-12"], &["solver.dt", "scene.max_steps", "--max-steps"]);
    assert_refused(&["run", "cantilever", "--duration", "1e9"], &["--duration", "--max-steps"]);
    // Raised, the bound lets the same run through its check.
    // Named as the user wrote it (the flag, not the scene key it sets).
    assert_refused(&["run", "cantilever", "--max-steps", "0"], &["--max-steps 0", "at least 1"]);
}

#[test]
fn a_negative_or_nan_perturbation_no_longer_panics() {
    for scene in ["euler-buckling", "cantilever"] {
        for value in ["-1", "nan"] {
            assert_refused(&["run", scene, "--set", &format!("test.perturbation={value}"), "--duration", "0.01"], &["test.perturbation"]);
        }
    }
}

#[test]
fn zero_newton_or_cg_iterations_are_refused_instead_of_reported_stable() {
    assert_refused(&["run", "cantilever", "--set", "solver.newton.max_iterations=0"], &["solver.newton.max_iterations"]);
    assert_refused(&["run", "cantilever", "--set", "solver.newton.cg_max_iterations=0"], &["solver.newton.cg_max_iterations"]);
    assert_refused(&["run", "skirt-gored-bias", "--fast", "--set", "solver.fast.cg_max_iterations=0"], &["solver.fast.cg_max_iterations", "at least 1"]);
}

/// Recycled directions cost memory and a product each per solve: a count no solve could
/// repay is refused, naming the key and the limit; a negative one is not a count.
#[test]
fn too_many_recycled_directions_are_refused() {
    assert_refused(&["run", "cantilever", "--set", "solver.newton.recycled_directions=100000"], &["solver.newton.recycled_directions", "at most 32"]);
    assert_refused(&["run", "skirt-circle", "--fast", "--set", "solver.fast.recycled_directions=33"], &["solver.fast.recycled_directions", "at most 32"]);
    assert_refused(&["run", "cantilever", "--set", "solver.newton.recycled_directions=-1"], &["solver.newton.recycled_directions"]);
}

#[test]
fn a_tensile_curve_of_slope_1e300_is_refused_instead_of_giving_nan_measures() {
    assert_refused(&["run", "tensile-warp", "--set", "fabric.tensile_warp=[[0,0],[0.01,1e300]]"], &["fabric.tensile_warp", "slope"]);
}

/// A Newton solve cut short by its iteration limit shows in the metrics and the exit code:
/// one iteration per step cannot reach the tolerance on a sagging cantilever.
#[test]
fn newton_stopping_at_its_limit_is_reported_and_exits_5() {
    let metrics = temp("limit.json");
    let out = rosette(
        &strings(&["run", "cantilever", "--set", "solver.newton.max_iterations=1", "--duration", "0.05", "--metrics", metrics.to_str().unwrap()]),
        QUICK,
    );
    assert_eq!(out.code, Some(5), "{}", out.stderr);
    assert!(out.stderr.contains("did not converge") && out.stderr.contains("solver.newton.max_iterations"), "{}", out.stderr);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&metrics).unwrap()).unwrap();
    std::fs::remove_file(&metrics).ok();
    assert_eq!(report["stable"], true);
    assert_eq!(report["converged"], false);
    assert_eq!(report["newton_limit_steps"], report["steps"], "every step stopped at its one iteration");
    assert!(report["worst_residual"].as_f64().unwrap() > 10.0 * 1e-5, "{}", report["worst_residual"]);
    // The same scene with its default limit converges.
    let out = rosette(&strings(&["run", "cantilever", "--duration", "0.05", "--metrics", metrics.to_str().unwrap()]), QUICK);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&metrics).unwrap()).unwrap();
    std::fs::remove_file(&metrics).ok();
    assert_eq!((report["converged"].clone(), report["newton_limit_steps"].clone()), (Value::Bool(true), Value::from(0)));
    assert!(report["worst_residual"].as_f64().unwrap() <= 1e-5);
}

#[test]
fn ghost_props_with_nan_or_huge_geometry_are_refused() {
    let cylinder = |extra: &str| format!("props=[{{shape='cylinder', radius=0.09, height=0.3, position=[0,0,-0.15]{extra}}}]");
    assert_refused(&["run", "cusick-drape-30", "--set", &cylinder(", rotation_deg=[nan,0,0]")], &["rotation_deg"]);
    assert_refused(&["run", "cusick-drape-30", "--set", "props=[{shape='cylinder', radius=1e40, height=0.3}]"], &["radius"]);
    assert_refused(&["run", "cusick-drape-30", "--set", "props=[{shape='mesh', file='assets/cushion.obj', scale=1e40}]"], &["scale"]);
    for (tag, coordinate) in [("nan", "nan"), ("inf", "inf"), ("big", "1e39")] {
        let path = temp(&format!("{tag}.obj"));
        std::fs::write(&path, format!("v 0 0 0\nv 1 0 0\nv {coordinate} 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n")).unwrap();
        let prop = format!("props=[{{shape='mesh', file='{}'}}]", path.display());
        assert_refused(&["run", "cusick-drape-30", "--set", &prop], &[&format!("{}:3", path.display()), coordinate]);
        std::fs::remove_file(&path).ok();
    }
}

#[test]
fn unwritable_outputs_and_options_the_scene_cannot_honour_are_refused_before_the_run() {
    let missing = temp("no-such-dir").join("out");
    let missing = missing.to_str().unwrap();
    // A run that diverges: it must not even start.
    let diverging = ["run", "cantilever", "--set", "solver.integrator=symplectic-euler", "--set", "solver.dt=0.001", "--duration", "0.05"];
    for (option, path) in [("--metrics", format!("{missing}.json")), ("--outline", format!("{missing}.csv")), ("--screenshot", format!("{missing}.png"))] {
        let mut args = diverging.to_vec();
        args.extend([option, path.as_str()]);
        let args: Vec<&str> = if option == "--outline" { args.iter().map(|a| if *a == "cantilever" { "cusick-drape-30" } else { a }).collect() } else { args };
        assert_refused(&args, &[option, "no-such-dir"]);
    }
    assert_refused(&["run", "cantilever", "--duration", "0.05", "--outline", "x.csv"], &["--outline", "not a drape scene"]);
    assert_refused(&["run", "cantilever", "--duration", "0.05", "--screenshot", "x.jpg"], &["--screenshot", "PNG"]);
    // With its outputs in order the same divergence exits 3 and keeps its metrics.
    let metrics = temp("diverged.json");
    let mut args = diverging.to_vec();
    args.extend(["--metrics", metrics.to_str().unwrap()]);
    let out = rosette(&strings(&args), QUICK);
    assert_eq!(out.code, Some(3), "{}", out.stderr);
    assert!(metrics.exists());
    std::fs::remove_file(&metrics).ok();
}

#[test]
fn messages_name_the_key_the_source_and_the_fix() {
    assert_refused(&["run", "cantilever", "--set", "fabric.areal_density=abc"], &["--set fabric.areal_density=abc", "fabric.areal_density must be a number", "0.137"]);
    assert_refused(&["run", "cantilever", "--set", "cloth.position=[1,2]"], &["--set cloth.position", "cloth.position", "2 values"]);
    assert_refused(&["run", "cantilever", "--set", "solver.newton.max_iterations=-1"], &["solver.newton.max_iterations must be a whole number"]);
    assert_refused(&["run", "cusick-drape", "--set", "cloth.diameter=-0.3"], &["cloth.diameter", "-0.3"]);
    assert_refused(&["run", "cantilever", "--set", "mesh.edge_length=10"], &["mesh.edge_length", "2 elements"]);
    assert_refused(&["run", "cantilever", "--set", "test.max_strain=0.1"], &["test.max_strain", "no effect"]);
    // A value in the bundled file itself is blamed on that file.
    let scene = temp("scene.toml");
    let text = SCENES.iter().find(|s| s.name == "cantilever").unwrap().text.replace("duration = 3.0", "duration = -3.0");
    std::fs::write(&scene, text).unwrap();
    assert_refused(&["run", scene.to_str().unwrap()], &[scene.to_str().unwrap(), "scene.duration", "-3"]);
    std::fs::remove_file(&scene).ok();
}

#[test]
fn measures_outside_their_meaning_are_refused_up_front() {
    // A support larger than the specimen gives a drape coefficient above 1; NaN, none.
    assert_refused(&["run", "cusick-drape", "--set", "test.support_diameter=0.5"], &["test.support_diameter", "exceed 1"]);
    assert_refused(&["run", "cusick-drape", "--set", "test.support_diameter=nan"], &["test.support_diameter"]);
    assert_refused(&["run", "tablecloth", "--set", "test.support_size=[1.2, 0.5]"], &["test.support_size"]);
    assert_refused(&["run", "cusick-drape", "--set", "test.clamp_radius=0.2"], &["test.clamp_radius"]);
}

#[test]
fn a_run_past_its_wall_time_bound_stops_with_exit_6_and_keeps_its_metrics() {
    let metrics = temp("wall.json");
    let out = rosette(&strings(&["run", "euler-buckling", "--max-wall", "0.2", "--metrics", metrics.to_str().unwrap()]), QUICK);
    assert_eq!(out.code, Some(6), "{}", out.stderr);
    assert!(out.stderr.contains("--max-wall"), "{}", out.stderr);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&metrics).unwrap()).unwrap();
    std::fs::remove_file(&metrics).ok();
    assert!(report["stopped_at_limit"].as_str().is_some_and(|s| s.contains("--max-wall")));
    assert!(report["simulated_seconds"].as_f64().unwrap() < 8.0);
    assert_refused(&["run", "cantilever", "--max-wall", "nan"], &["--max-wall"]);
}

/// A mesh far above what the run may hold is refused before it is built, with the estimate
/// and an edge length that fits. The run is given 4 GiB of address space (`ulimit -v`), so
/// that the test asserts the same on every machine, whatever its free memory: the refusal
/// must quote at most that figure as available, which shows the limit was read (a machine
/// where no figure is known would refuse nothing and fail here). The estimate for this mesh
/// is about 40 GB.
#[test]
fn a_mesh_too_large_for_memory_is_refused_before_it_is_built() {
    let (vertices, edge) = (1_500_000usize, 2.6e-4);
    let need = rosette::scene::memory::estimate_bytes(vertices, rosette::sim::PreconditionerChoice::Auto);
    assert!(need > 8.0 * 4.0 * f64::from(1u32 << 30), "the estimate {need:e} is far above the limit");
    let out = Command::new("sh")
        .args(["-c", "ulimit -v 4194304 && exec \"$0\" \"$@\"", env!("CARGO_BIN_EXE_rosette")])
        .args(["run", "cusick-drape", "--set", &format!("mesh.edge_length={edge}")])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("sh runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    for word in ["mesh.edge_length", "GB", "available"] {
        assert!(stderr.contains(word), "the message should name '{word}': {stderr}");
    }
    let quoted: f64 = stderr
        .split(" GB available")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|figure| figure.parse().ok())
        .unwrap_or_else(|| panic!("the message should quote the memory available: {stderr}"));
    assert!(quoted <= 4.3, "the 4 GiB limit should bound the {quoted} GB quoted as available: {stderr}");
}

#[test]
fn the_spatial_hash_stays_bounded_for_boxes_without_finite_bounds() {
    // The library's own guard behind the entry checks: a box reaching infinity touches
    // every bucket once instead of looping over 2⁹⁶ cells.
    use glam::DVec3;
    use rosette::sim::contact::geometry::SpatialHash;
    let boxes = [(DVec3::ZERO, DVec3::ONE), (DVec3::splat(f64::NEG_INFINITY), DVec3::splat(f64::INFINITY)), (DVec3::splat(f64::NAN), DVec3::ONE)];
    let hash = SpatialHash::new(0.1, &boxes);
    let mut found = Vec::new();
    hash.query_box(DVec3::splat(-1e300), DVec3::splat(1e300), |i| found.push(i));
    found.sort_unstable();
    found.dedup();
    assert_eq!(found, [0, 1, 2]);
}
