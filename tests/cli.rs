//! Validates the `rosette` command line: preset listing, headless runs of every bundled
//! scene with complete metrics, exit codes and messages for bad input (2) and divergence (3),
//! and metrics on standard output.

use rosette::settings::SCENES;
use rosette::scene::{Metrics, Scene, load_scene};
use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::Instant;

fn rosette(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).output().expect("the rosette binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh path for a metrics file, unique to the test.
fn metrics_path(tag: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{tag}-{}.json", std::process::id()));
    let _ = std::fs::remove_file(&path);
    path
}

/// The keys every metrics report carries.
const KEYS: [&str; 11] = [
    "preset",
    "integrator",
    "dt",
    "vertices",
    "triangles",
    "simulated_seconds",
    "steps",
    "wall_seconds",
    "cpu_seconds_per_simulated_second",
    "stable",
    "measures",
];

fn assert_has_keys(metrics: &Value, context: &str) {
    for key in KEYS {
        assert!(metrics.get(key).is_some(), "{context}: metrics lack '{key}': {metrics}");
    }
}

#[test]
fn presets_lists_every_bundled_scene() {
    let out = rosette(&["presets"]);
    assert!(out.status.success(), "exit {:?}: {}", out.status, text(&out.stderr));
    let listed: Vec<String> =
        text(&out.stdout).lines().filter_map(|l| l.split_whitespace().next()).map(str::to_string).collect();
    let bundled: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
    assert_eq!(listed, bundled, "`rosette presets` must list the bundled scenes, in order");
}

// ---------------------------------------------------------------------------------------
// Every bundled preset runs headless to completion
// ---------------------------------------------------------------------------------------

/// Runs `rosette run NAME --metrics FILE` and checks the report against the preset's own
/// input data: its integrator and step, a run to the end of its duration, stable.
fn run_bundled(name: &str) {
    run_bundled_with(name, &[]);
}

/// `run_bundled` with `--set` overrides, checked against the scene they make.
fn run_bundled_with(name: &str, overrides: &[&str]) {
    let owned: Vec<String> = overrides.iter().map(|o| o.to_string()).collect();
    let (config, _) = load_scene(name, &owned).unwrap();
    let scene = Scene::build(config.clone()).unwrap();
    let path = metrics_path(name);
    let started = Instant::now();
    let mut args = vec!["run", name, "--metrics", path.to_str().unwrap()];
    for o in overrides {
        args.extend(["--set", o]);
    }
    let out = rosette(&args);
    let elapsed = started.elapsed().as_secs_f64();
    eprintln!("rosette run {name}: {elapsed:.1} s wall");
    assert_eq!(out.status.code(), Some(0), "{name}: {}", text(&out.stderr));
    let written = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let metrics: Value = serde_json::from_str(&written).unwrap();
    assert_has_keys(&metrics, name);
    // The typed report reads the file back and writes it out again unchanged (what
    // `rosette bench` relies on).
    let typed: Metrics = serde_json::from_str(&written).unwrap_or_else(|e| panic!("{name}: the metrics do not read back: {e}"));
    assert_eq!(serde_json::to_string_pretty(&typed).unwrap() + "\n", written, "{name}: the metrics change when read back and written");
    let dt = config.solver.dt;
    let duration = config.scene.duration;
    assert_eq!(metrics["preset"], name);
    assert_eq!(metrics["integrator"], config.solver.integrator.name());
    assert_eq!(metrics["dt"].as_f64(), Some(dt));
    assert_eq!(metrics["stable"], true, "{name}: {}", metrics["error"]);
    assert!(metrics.get("error").is_none(), "{name}: a stable run reports no error");
    assert_eq!(metrics["vertices"].as_u64(), Some(scene.model.vertex_count() as u64));
    assert_eq!(metrics["triangles"].as_u64(), Some(scene.model.triangle_count() as u64));
    // The run covers the whole duration in whole steps of dt, unless it watched for settling
    // and stopped once the cloth had stayed slow for the settling window.
    let full_steps = (duration / dt - 1e-9).ceil() as u64;
    let steps = metrics["steps"].as_u64().unwrap();
    let simulated = metrics["simulated_seconds"].as_f64().unwrap();
    // Time is a running sum of dt: round-off of order steps·ε relative.
    assert!((simulated - steps as f64 * dt).abs() < 1e-9 * duration, "{name}: simulated {simulated} s");
    match metrics["settled"].as_bool() {
        Some(true) => {
            let settle_time = metrics["settle_time"].as_f64().unwrap();
            assert!(steps <= full_steps && settle_time < simulated, "{name}: settled at {settle_time} s, stopped at {simulated} s");
        }
        _ => {
            assert_eq!(steps, full_steps, "{name}");
            assert!(simulated >= duration - 1e-9 * duration, "{name}: stopped at {simulated} s of {duration} s");
        }
    }
    let wall = metrics["wall_seconds"].as_f64().unwrap();
    assert!(wall > 0.0 && wall <= elapsed, "{name}: wall_seconds {wall} outside (0, {elapsed}]");
    let cpu = metrics["cpu_seconds_per_simulated_second"].as_f64().unwrap();
    assert!(cpu.is_finite() && cpu > 0.0, "{name}: cpu_seconds_per_simulated_second {cpu}");
    let measures = metrics["measures"].as_object().expect("measures is an object");
    assert!(!measures.is_empty(), "{name}: no measurements");
    // Read back as the scene's own rig's measures, not another rig's.
    assert_eq!(std::mem::discriminant(&typed.measures), std::mem::discriminant(&scene.measures()), "{name}: {:?}", typed.measures);
    if !config.props.is_empty() {
        let depth = metrics["max_penetration"].as_f64().expect("scenes with props report max_penetration");
        assert!(depth >= 0.0 && depth < config.contact.thickness, "{name}: max_penetration {depth}");
        assert_eq!(metrics["self_intersections"].as_u64(), Some(0), "{name}");
        assert_eq!(metrics["settled"], true, "{name}: a drape runs until it settles");
        for key in ["drape_coefficient", "nodes", "shadow_area"] {
            assert!(measures.contains_key(key), "{name}: measures lack {key}");
        }
    }
}

/// Every bundled scene has its own test below (so that they run in parallel).
const COVERED: [&str; 16] = [
    "tensile-warp",
    "tensile-weft",
    "tensile-bias",
    "cantilever",
    "arc",
    "euler-buckling",
    "shear-buckling",
    "cusick-drape",
    "cusick-drape-30",
    "tablecloth",
    "sphere-drop",
    "swing",
    "skirt-circle",
    "skirt-gored-straight",
    "skirt-gored-bias",
    "shift-dress",
];

#[test]
fn every_bundled_scene_has_a_run_test() {
    for scene in SCENES {
        assert!(COVERED.contains(&scene.name), "bundled scene '{}' has no run test in tests/cli.rs", scene.name);
    }
}

#[test]
fn runs_tensile_warp() {
    run_bundled("tensile-warp");
}

#[test]
fn runs_tensile_weft() {
    run_bundled("tensile-weft");
}

#[test]
fn runs_tensile_bias() {
    run_bundled("tensile-bias");
}

#[test]
fn runs_cantilever() {
    run_bundled("cantilever");
}

#[test]
fn runs_arc() {
    run_bundled("arc");
}

#[test]
fn runs_euler_buckling() {
    run_bundled("euler-buckling");
}

#[test]
fn runs_cusick_drape() {
    run_bundled("cusick-drape");
}

#[test]
fn runs_cusick_drape_30() {
    run_bundled("cusick-drape-30");
}

#[test]
fn runs_tablecloth() {
    run_bundled("tablecloth");
}

/// The sphere drop on 4 cm edges (1 250 triangles): its own 8 000 triangles take minutes on
/// the exact path (the bench runs it, docs/fast-path.md).
#[test]
fn runs_sphere_drop() {
    run_bundled_with("sphere-drop", &["mesh.edge_length=0.04"]);
}

#[test]
fn runs_swing() {
    run_bundled("swing");
}

/// The garments on 5 cm edges for 1.5 s, past their sewing time (the bundled meshes run in
/// tests/garment.rs and take a minute each). Every bundled garment is sewn (exit 0, its
/// metrics saying so), never deeper into the form than its contact layer and free of
/// self-intersection. A garment whose sewing time ends before its seams can close (springs
/// of 0.01 N/m, 5 000 times weaker than the default, for 0.2 s: its seams still centimetres
/// open; a sewing ramp not shorter than the sewing time is refused before the run, in
/// tests/garment.rs) exits 8 naming garment.sewing_time, its metrics written with `sewn`
/// false.
#[test]
fn runs_garments() {
    // Both paths: the fast one takes the garment step and its contact penalty.
    for (name, path_flag) in ["skirt-gored-straight", "skirt-gored-bias", "skirt-circle", "shift-dress"].into_iter().flat_map(|n| [(n, "--set=solver.path=exact"), (n, "--fast")]) {
        let name_on_path = format!("{name}{path_flag}");
        let path = metrics_path(&name_on_path);
        let out = rosette(&["run", name, path_flag, "--set", "mesh.edge_length=0.05", "--duration", "1.5", "--metrics", path.to_str().unwrap()]);
        let scene = name;
        let name = name_on_path.as_str();
        let written = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: no metrics ({e}): {}", text(&out.stderr)));
        std::fs::remove_file(&path).ok();
        let metrics: Value = serde_json::from_str(&written).unwrap();
        let typed: Metrics = serde_json::from_str(&written).unwrap_or_else(|e| panic!("{name}: the metrics do not read back: {e}"));
        let garment = typed.measures.garment().unwrap_or_else(|| panic!("{name}: no garment measures"));
        let (config, _) = load_scene(scene, &[]).unwrap();
        assert_eq!(metrics["stable"], true, "{name}");
        assert_eq!(out.status.code(), Some(0), "{name}: {}", text(&out.stderr));
        assert!(garment.sewn, "{name}: exit 0 for an unsewn garment");
        assert!(metrics["max_penetration"].as_f64().unwrap() < config.contact.thickness, "{name}: {}", metrics["max_penetration"]);
        assert_eq!(metrics["self_intersections"].as_u64(), Some(0), "{name}");
    }
    let path = metrics_path("unsewn");
    let out = rosette(&["run", "skirt-gored-straight", "--set", "mesh.edge_length=0.05", "--set", "garment.sewing_time=0.2", "--set", "garment.sewing_ramp=0.15", "--set", "garment.sewing_stiffness=0.01", "--duration", "0.3", "--metrics", path.to_str().unwrap()]);
    let written = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("unsewn: no metrics ({e}): {}", text(&out.stderr)));
    std::fs::remove_file(&path).ok();
    assert_eq!(out.status.code(), Some(8), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("garment.sewing_time"), "{}", text(&out.stderr));
    let typed: Metrics = serde_json::from_str(&written).unwrap();
    assert!(!typed.measures.garment().expect("garment measures").sewn);
}

/// `--outline` writes the shadow outline of a drape: one row per half degree, radii between
/// the pedestal's and the specimen's; other scenes have none and say so.
#[test]
fn outline_csv_of_a_drape() {
    let path = metrics_path("outline").with_extension("csv");
    let out = rosette(&["run", "cusick-drape-30", "--duration", "0.2", "--outline", path.to_str().unwrap(), "--metrics", "-"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let csv = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("angle_deg,radius_m"));
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let (a, r) = l.split_once(',').unwrap();
            (a.parse().unwrap(), r.parse().unwrap())
        })
        .collect();
    assert_eq!(rows.len(), 720);
    assert!(rows.windows(2).all(|w| w[1].0 > w[0].0) && rows[0].0 == 0.0 && rows[719].0 < 360.0);
    assert!(rows.iter().all(|&(_, r)| r > 0.09 && r <= 0.15 + 1e-3), "radii between the pedestal and the specimen");
    let out = rosette(&["run", "tensile-warp", "--duration", "0.04", "--outline", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("not a drape scene"), "{}", text(&out.stderr));
}

/// `--step-log` writes one row per step, whose Newton and CG counts add up to the run's
/// totals and whose times follow the steps; a path that cannot be created is bad input.
#[test]
fn step_log_has_a_row_per_step() {
    let path = metrics_path("steps").with_extension("csv");
    let out = rosette(&["run", "cantilever", "--duration", "0.1", "--step-log", path.to_str().unwrap(), "--metrics", "-"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let metrics: Value = serde_json::from_str(&text(&out.stdout)).unwrap();
    let csv = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len() as u64, metrics["steps"].as_u64().unwrap());
    assert!(rows.iter().all(|r| r.len() == header.len()));
    let sum = |name: &str| rows.iter().map(|r| r[column(name)]).sum::<f64>();
    assert_eq!(sum("newton"), metrics["newton_iterations"].as_f64().unwrap());
    assert_eq!(sum("cg"), metrics["cg_iterations"].as_f64().unwrap());
    let (time, step) = (column("time_s"), column("step"));
    assert!(rows.windows(2).all(|w| w[1][time] > w[0][time] && w[1][step] == w[0][step] + 1.0));
    let simulated = metrics["simulated_seconds"].as_f64().unwrap();
    assert!((rows.last().unwrap()[time] - simulated).abs() < 1e-9);
    let missing = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("no-such-dir").join("steps.csv");
    assert_bad_input(&["run", "cantilever", "--duration", "0.01", "--step-log", missing.to_str().unwrap()], &["--step-log", "no-such-dir"]);
}

#[test]
fn runs_shear_buckling() {
    run_bundled("shear-buckling");
}

// ---------------------------------------------------------------------------------------
// Bad input: exit 2 and a message that names the culprit
// ---------------------------------------------------------------------------------------

fn assert_bad_input(args: &[&str], must_name: &[&str]) {
    let out = rosette(args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: expected exit 2, stderr: {stderr}");
    for word in must_name {
        assert!(stderr.contains(word), "{args:?}: the message should name '{word}': {stderr}");
    }
}

#[test]
fn negative_areal_density_is_bad_input() {
    assert_bad_input(&["run", "tensile-warp", "--set", "fabric.areal_density=-1"], &["fabric.areal_density", "-1"]);
}

#[test]
fn unknown_key_is_bad_input() {
    assert_bad_input(&["run", "tensile-warp", "--set", "fabric.densty=1"], &["densty"]);
}

#[test]
fn unsorted_curve_is_bad_input() {
    assert_bad_input(&["run", "tensile-warp", "--set", "fabric.tensile_warp=[[0,0],[0.02,5],[0.01,9]]"], &["tensile_warp", "sort"]);
}

#[test]
fn unknown_preset_is_bad_input() {
    // The message names what was asked for and lists what exists.
    assert_bad_input(&["run", "no-such-scene"], &["no-such-scene", "tensile-warp"]);
}

#[test]
fn unknown_integrator_is_bad_input() {
    assert_bad_input(&["run", "tensile-warp", "--set", "solver.integrator=rk4"], &["rk4", "implicit-euler"]);
}

#[test]
fn missing_scene_file_is_bad_input() {
    let missing = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("no-such-dir").join("scene.toml");
    let missing = missing.to_str().unwrap();
    assert_bad_input(&["run", missing], &[missing]);
}

// ---------------------------------------------------------------------------------------
// Divergence: exit 3, metrics still written
// ---------------------------------------------------------------------------------------

#[test]
fn divergence_exits_3_and_still_writes_metrics() {
    // 1 ms is about 70 times the explicit limit of this mesh (5 mm edges, c ≈ 340 m/s on the
    // wool's stiffest segment: h/c ≈ 15 µs).
    let path = metrics_path("diverged");
    let out = rosette(&[
        "run",
        "tensile-warp",
        "--set",
        "solver.integrator=symplectic-euler",
        "--set",
        "solver.dt=0.001",
        "--metrics",
        path.to_str().unwrap(),
    ]);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "stderr: {stderr}");
    assert!(stderr.contains("symplectic-euler"), "the message names the integrator: {stderr}");
    assert!(stderr.contains("dt = 1e-3") || stderr.contains("dt = 0.001"), "the message names the step: {stderr}");
    let metrics: Value = serde_json::from_str(&std::fs::read_to_string(&path).expect("metrics written")).unwrap();
    std::fs::remove_file(&path).ok();
    assert_has_keys(&metrics, "diverged run");
    assert_eq!(metrics["stable"], false);
    assert_eq!(metrics["integrator"], "symplectic-euler");
    assert_eq!(metrics["dt"].as_f64(), Some(0.001));
    assert!(metrics["error"].as_str().is_some_and(|e| e.contains("diverged")), "{}", metrics["error"]);
    let (config, _) = load_scene("tensile-warp", &[]).unwrap();
    let full = (config.scene.duration / 0.001).ceil() as u64;
    assert!(metrics["steps"].as_u64().unwrap() < full, "the run stopped early");
}

// ---------------------------------------------------------------------------------------
// Metrics on standard output
// ---------------------------------------------------------------------------------------

#[test]
fn metrics_dash_writes_json_to_stdout() {
    let out = rosette(&["run", "tensile-warp", "--metrics", "-"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let metrics: Value = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("stdout is not one JSON document ({e}): {stdout}"));
    assert_has_keys(&metrics, "--metrics -");
    assert_eq!(metrics["preset"], "tensile-warp");
    assert_eq!(metrics["stable"], true);
}

/// `rosette bench --quick` times the Table 1 scenes and two drape sizes in child runs and
/// writes one CSV row per case and thread count, with the step time split into shares that
/// add up, and the child's own peak memory.
#[test]
fn bench_quick_writes_one_row_per_case() {
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let output = rosette(&["bench", "--quick", "--threads", "1", "--out", out.to_str().unwrap()]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for key in ["case", "threads", "triangles", "cpu_seconds_per_simulated_second", "forces_share", "solve_share", "contact_share", "solver_speedup_bound", "peak_memory_mb"] {
        assert!(header.contains(&key), "bench.csv lacks {key}: {header:?}");
    }
    // The case name is quoted (it may hold commas); the columns after it are numbers.
    let rows: Vec<Vec<&str>> = lines.map(|l| l[l.rfind("\",").expect("a quoted case") + 2..].split(',').collect()).collect();
    assert_eq!(rows.len(), 11, "three Table 1 scenes, the drape to settling on both solver paths, two drape sizes with two solvers each and the swing on both paths:\n{csv}");
    let column = |row: &Vec<&str>, key: &str| -> f64 {
        let i = header.iter().position(|h| *h == key).unwrap();
        row[i - 1].parse().unwrap_or(f64::NAN)
    };
    for row in &rows {
        assert!(column(row, "cpu_seconds_per_simulated_second") > 0.0, "{row:?}");
        let shares = column(row, "forces_share") + column(row, "solve_share") + column(row, "contact_share");
        assert!((shares - 1.0).abs() < 1e-9, "shares add to {shares}: {row:?}");
        assert!(column(row, "peak_memory_mb") > 1.0, "{row:?}");
        // Amdahl's bound on any faster solver: the time outside the solve stays.
        let bound = column(row, "solver_speedup_bound");
        let outside = column(row, "forces_share") + column(row, "contact_share");
        assert!(bound >= 1.0 && (bound * outside - 1.0).abs() < 1e-9, "bound {bound} with {outside} of the time outside the solve: {row:?}");
    }
    let stdout = text(&output.stdout);
    assert!(stdout.contains("no solver can make this run more than"), "no solver bound printed:\n{stdout}");
    // The drapes (the two whole runs, then the last four rows: each size with the complete
    // factor, then with multigrid) are the only cases with contact; a size's two rows are
    // the same mesh, and the larger size has more triangles.
    assert!(column(&rows[5], "contact_share") > 0.0 && column(&rows[0], "contact_share") == 0.0);
    assert_eq!(column(&rows[5], "triangles"), column(&rows[6], "triangles"));
    assert!(column(&rows[7], "triangles") > 4.0 * column(&rows[5], "triangles"));
    let names: Vec<&str> = csv.lines().skip(1).map(|l| &l[1..l.rfind("\",").unwrap()]).collect();
    assert!(names[5].ends_with("cholesky") && names[6].ends_with("multigrid"), "{names:?}");
    // The whole drape on both paths: the same mesh, both settled on a coefficient.
    assert!(names[3].ends_with(", exact") && names[4].ends_with(", fast"), "{names:?}");
    assert_eq!(column(&rows[3], "triangles"), column(&rows[4], "triangles"));
    for row in &rows[3..5] {
        assert_eq!(row[header.iter().position(|h| *h == "settled").unwrap() - 1], "true", "settled: {row:?}");
        let dc = column(row, "drape_coefficient");
        assert!(dc > 0.0 && dc < 1.0, "{row:?}");
    }
    // The swing on both paths, the fast one at its longer step for cloth in motion.
    assert!(names[9].starts_with("swing, exact") && names[10].starts_with("swing, fast"), "{names:?}");
    assert!(column(&rows[10], "dt") > column(&rows[9], "dt"), "{:?}", &rows[9..]);
    for row in &rows[9..] {
        assert!(column(row, "period_error").abs() < 0.01, "the swing's period against the hanging chain's: {row:?}");
    }
}

/// The run plan never replaces a value of the user's in silence: `--plan` says which
/// values it chose over the scene's and which of the user's it kept, and a run's metrics
/// list both (`plan_overrides`); the user's value is the one the run takes.
#[test]
fn the_plan_says_what_it_chose_and_keeps_what_the_user_set() {
    let plan = rosette(&["run", "tablecloth", "--fast", "--set", "solver.newton.max_iterations=2", "--plan"]);
    assert!(plan.status.success(), "{}", text(&plan.stderr));
    let described = text(&plan.stdout);
    assert!(described.contains("at most 2 iterations"), "{described}");
    assert!(described.contains("kept: solver.newton.max_iterations = 2 (yours; the plan would take 80"), "{described}");
    assert!(described.contains("chosen: solver.dt = 0.016 (replaces the bundled scene's 0.004"), "{described}");
    // A short run of the same: the metrics list the choices, and Newton stopped at 2.
    let path = metrics_path("plan-overrides");
    let run = rosette(&[
        "run", "tablecloth", "--fast", "--set", "solver.newton.max_iterations=2", "--duration", "0.128", "--metrics", path.to_str().unwrap(),
    ]);
    assert!(matches!(run.status.code(), Some(0 | 5)), "{}", text(&run.stderr));
    let metrics: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let overrides = metrics["plan_overrides"].as_array().expect("plan_overrides in the metrics");
    let entry = |key: &str| overrides.iter().find(|o| o["key"] == key).unwrap_or_else(|| panic!("{key} missing: {overrides:?}"));
    assert_eq!(entry("solver.newton.max_iterations")["kept"], true);
    assert_eq!(entry("solver.newton.max_iterations")["value"], "2");
    assert_eq!(entry("solver.dt")["kept"], false);
    assert_eq!(entry("solver.dt")["scene_value"], "0.004");
    assert!(metrics["newton_iterations"].as_u64().unwrap() <= 2 * metrics["steps"].as_u64().unwrap(), "{metrics}");
}
