//! Generated garment input, bounded: random garment scenes (outlines, seams, forms,
//! placements, attachments, mesh sizes), GarmentCode specifications and ARCSim materials,
//! each put through the binary as a user would, with a time bound. Every case must end in
//! a documented exit code (docs/robustness.md), never a panic or a hang; a refusal (exit 2)
//! names a key; no staged file is left behind; and an imported pattern that is written
//! always loads (`run --plan`), for an import never writes a scene a run refuses.
//!
//! Seeds are fixed, so a failure replays; the case is printed with its seed.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::fmt::Write as _;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Exit codes a run may end with (docs/scenes.md, "Outputs of a run").
const DOCUMENTED: &[i32] = &[0, 2, 3, 4, 5, 6, 8, 9];
/// A case that runs longer than this is hung.
const BOUND: Duration = Duration::from_secs(60);
/// What a refusal's message names: a scene key's section, a flag or a file's field.
const KEY_WORDS: &[&str] = &["garment", "mesh", "scene", "solver", "contact", "fabric", "pattern", "panel", "stretching", "bending", "density", "--"];

fn folder(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("generated-{}", std::process::id())).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

struct Ended {
    code: Option<i32>,
    stderr: String,
    took: Duration,
}

/// Runs the binary in `dir`, killed past [`BOUND`].
fn rosette(args: &[&str], dir: &Path) -> Ended {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let mut pipe = child.stderr.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        pipe.read_to_string(&mut text).ok();
        text
    });
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > BOUND {
            child.kill().ok();
            break child.wait().expect("wait");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Ended { code: status.code(), stderr: reader.join().unwrap_or_default(), took: start.elapsed() }
}

/// The checks every case passes; `allowed` are its exit codes.
fn judge(case: &str, ended: &Ended, allowed: &[i32], dir: &Path) {
    assert!(ended.took < BOUND, "{case}: hung ({:?}):\n{}", ended.took, ended.stderr);
    assert!(!ended.stderr.contains("panicked"), "{case}: panicked:\n{}", ended.stderr);
    let code = ended.code.unwrap_or_else(|| panic!("{case}: ended by a signal:\n{}", ended.stderr));
    assert!(allowed.contains(&code), "{case}: exit {code}, not one of {allowed:?}:\n{}", ended.stderr);
    if code == 2 {
        assert!(KEY_WORDS.iter().any(|k| ended.stderr.contains(k)), "{case}: a refusal names no key:\n{}", ended.stderr);
    }
    let stray: Vec<String> =
        std::fs::read_dir(dir).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect();
    assert!(stray.is_empty(), "{case}: stray files {stray:?}");
}

/// A closed outline around the origin, counter-clockwise, `k` corners at random radii
/// (cm); now and then two corners swapped (an outline that may cross itself) or a corner
/// repeated (an edge of no length).
fn outline(rng: &mut Pcg64Mcg, k: usize) -> Vec<[f64; 2]> {
    let mut points: Vec<[f64; 2]> = (0..k)
        .map(|i| {
            let t = std::f64::consts::TAU * (i as f64 + rng.random_range(0.0..0.8)) / k as f64;
            let r = rng.random_range(8.0..45.0);
            [r * t.cos(), r * t.sin()]
        })
        .collect();
    match rng.random_range(0..10) {
        0 => points.swap(0, k / 2),
        1 => points[1] = points[0],
        _ => {}
    }
    points
}

fn garment_scene(rng: &mut Pcg64Mcg) -> String {
    let mut s = String::new();
    let duration = rng.random_range(0.5..4.0);
    writeln!(s, "[scene]\nkind = \"garment\"\nduration = {duration}\n[fabric]\npreset = \"{}\"", ["wool", "silk", "denim", "polyester"][rng.random_range(0..4)]).unwrap();
    writeln!(s, "[mesh]\nedge_length = {}", [0.02, 0.03, 0.05, 0.1, 0.015, 1.0][rng.random_range(0..6)]).unwrap();
    writeln!(s, "[solver]\nintegrator = \"implicit-euler\"\ndt = {}", [0.01, 0.02, 0.004][rng.random_range(0..3)]).unwrap();
    writeln!(s, "[contact]\nthickness = {}", [0.002, 0.004, 0.0001][rng.random_range(0..3)]).unwrap();
    writeln!(s, "[garment]\nunits = \"cm\"\nsewing_time = {}", duration * rng.random_range(0.5..1.1)).unwrap();
    match rng.random_range(0..4) {
        0 => {
            let bust = rng.random_range(40.0..160.0);
            writeln!(
                s,
                "[garment.form.measurements]\nbust_girth = {bust}\nwaist_girth = {}\nhip_girth = {}\nbust_height = {}\nwaist_height = {}\nhip_height = {}\ntorso_length = {}\nneck_girth = {}\nshoulder_width = {}",
                bust * rng.random_range(0.6..1.1),
                bust * rng.random_range(0.9..1.2),
                rng.random_range(50.0..200.0),
                rng.random_range(40.0..180.0),
                rng.random_range(20.0..150.0),
                rng.random_range(10.0..80.0),
                rng.random_range(20.0..50.0),
                rng.random_range(20.0..80.0)
            )
            .unwrap();
        }
        _ => writeln!(s, "[garment.form]\nsize = \"{}\"", ["uk-10", "uk-12", "uk-14"][rng.random_range(0..3)]).unwrap(),
    }
    let panels = rng.random_range(1..=4);
    let mut edges: Vec<(String, usize)> = Vec::new();
    for p in 0..panels {
        let k = rng.random_range(3..=9);
        let points = outline(rng, k);
        writeln!(s, "[[garment.panels]]\nname = \"p{p}\"\ngrain_deg = {}\nstart = [{}, {}]\nedges = [", rng.random_range(-400.0..400.0), points[0][0], points[0][1]).unwrap();
        for e in 0..k {
            let to = points[(e + 1) % k];
            writeln!(s, "  {{ name = \"e{e}\", to = [{}, {}] }},", to[0], to[1]).unwrap();
            edges.push((format!("p{p}.e{e}"), p));
        }
        writeln!(
            s,
            "]\nplacement = {{ around = \"{}\", angle_deg = {}, distance = {}, height = {} }}",
            // Mostly the placements the schema has; one in five a name it refuses.
            ["plane", "cone", "plane", "cone", "cylinder"][rng.random_range(0..5)],
            rng.random_range(0.0..360.0),
            rng.random_range(2.0..60.0),
            rng.random_range(30.0..160.0)
        )
        .unwrap();
    }
    for _ in 0..rng.random_range(0..=3) {
        let (a, b) = (&edges[rng.random_range(0..edges.len())].0, &edges[rng.random_range(0..edges.len())].0);
        writeln!(s, "[[garment.seams]]\na = \"{a}\"\nb = \"{b}\"\ndirection = \"{}\"", ["same", "opposite"][rng.random_range(0..2)]).unwrap();
    }
    if rng.random_bool(0.5) {
        let edge = &edges[rng.random_range(0..edges.len())].0;
        writeln!(s, "[[garment.attachments]]\nedge = \"{edge}\"\nlevel = \"{}\"", ["waist", "hip", "bust", "knee"][rng.random_range(0..4)]).unwrap();
    }
    s
}

/// Random garment scenes: checked (`--plan`), and where accepted, run for a moment under a
/// wall bound with its outputs.
#[test]
fn generated_garment_scenes_end_in_a_documented_way() {
    let mut rng = Pcg64Mcg::seed_from_u64(60);
    let dir = folder("scenes");
    let mut accepted = 0;
    for case in 0..40 {
        let text = garment_scene(&mut rng);
        let file = format!("case-{case}.toml");
        std::fs::write(dir.join(&file), &text).unwrap();
        let name = format!("garment scene {case} (seed 60):\n{text}");
        let planned = rosette(&["run", &file, "--plan"], &dir);
        judge(&name, &planned, &[0, 2], &dir);
        // The first few accepted run (each costs a mesh and a model).
        if planned.code == Some(0) && accepted < 6 {
            accepted += 1;
            let metrics = format!("m-{case}.json");
            let ran = rosette(&["run", &file, "--duration", "0.04", "--max-wall", "20", "--metrics", &metrics, "--step-log", "log.csv", "--force"], &dir);
            judge(&name, &ran, DOCUMENTED, &dir);
        }
    }
    eprintln!("{accepted} generated garments ran");
    assert!(accepted > 0, "no generated garment passed its checks and ran: the generator no longer reaches the run");
}

/// Random GarmentCode specifications: `pattern import` refuses (2) or writes a scene that a
/// run then loads.
#[test]
fn generated_garmentcode_specifications_import_or_are_refused() {
    let mut rng = Pcg64Mcg::seed_from_u64(61);
    let dir = folder("garmentcode");
    for case in 0..30 {
        let mut panels = Vec::new();
        let count = rng.random_range(1..=3);
        for p in 0..count {
            let k = rng.random_range(3..=7);
            let points = outline(&mut rng, k);
            let vertices: Vec<String> = points.iter().map(|q| format!("[{}, {}]", q[0], q[1])).collect();
            let edges: Vec<String> = (0..k)
                .map(|e| match rng.random_range(0..6) {
                    0 => format!("{{\"endpoints\": [{e}, {}], \"curvature\": [0.5, {}]}}", (e + 1) % k, rng.random_range(-0.5..0.5)),
                    1 => format!("{{\"endpoints\": [{e}, {}], \"curvature\": {{\"type\": \"circle\", \"params\": [{}, 0, 1]}}}}", (e + 1) % k, rng.random_range(1.0..80.0)),
                    _ => format!("{{\"endpoints\": [{e}, {}]}}", (e + 1) % k),
                })
                .collect();
            // Now and then two panels under one name.
            let name = if rng.random_range(0..8) == 0 { "panel0".to_string() } else { format!("panel{p}") };
            panels.push(format!(
                "\"{name}\": {{\"translation\": [{}, {}, {}], \"rotation\": [0, {}, 0], \"vertices\": [{}], \"edges\": [{}]}}",
                rng.random_range(-60.0..60.0),
                rng.random_range(40.0..150.0),
                rng.random_range(-40.0..40.0),
                rng.random_range(-180.0..180.0),
                vertices.join(", "),
                edges.join(", ")
            ));
        }
        let stitches: Vec<String> = (0..rng.random_range(0..3))
            .map(|_| {
                format!(
                    "[{{\"panel\": \"panel{}\", \"edge\": {}}}, {{\"panel\": \"panel{}\", \"edge\": {}}}]",
                    rng.random_range(0..count),
                    rng.random_range(0..8),
                    rng.random_range(0..count),
                    rng.random_range(0..8)
                )
            })
            .collect();
        let spec = format!(
            "{{\"pattern\": {{\"panels\": {{{}}}, \"stitches\": [{}]}}, \"properties\": {{\"curvature_coords\": \"relative\", \"units_in_meter\": 100}}}}",
            panels.join(", "),
            stitches.join(", ")
        );
        let (file, out) = (format!("spec-{case}.json"), format!("scene-{case}.toml"));
        std::fs::write(dir.join(&file), &spec).unwrap();
        let name = format!("GarmentCode specification {case} (seed 61):\n{spec}");
        let imported = rosette(&["pattern", "import", &file, "--out", &out, "--force"], &dir);
        judge(&name, &imported, &[0, 2], &dir);
        if imported.code == Some(0) {
            let planned = rosette(&["run", &out, "--plan"], &dir);
            judge(&name, &planned, &[0], &dir);
        }
    }
}

/// Random ARCSim materials (tables of any sign and size): imported (0) or refused naming
/// the field (2), within the bound.
#[test]
fn generated_arcsim_materials_import_or_are_refused() {
    let mut rng = Pcg64Mcg::seed_from_u64(62);
    let dir = folder("arcsim");
    let number = |rng: &mut Pcg64Mcg| -> String {
        match rng.random_range(0..12) {
            0 => "0".into(),
            1 => "-1.5".into(),
            2 => "1e300".into(),
            3 => "5e-324".into(),
            _ => format!("{:e}", 10f64.powf(rng.random_range(-6.0..4.0))),
        }
    };
    for case in 0..30 {
        let stretching: Vec<String> = (0..6).map(|_| format!("[{}]", (0..4).map(|_| number(&mut rng)).collect::<Vec<_>>().join(", "))).collect();
        let bending: Vec<String> = (0..3).map(|_| format!("[{}]", (0..5).map(|_| format!("{:e}", 10f64.powf(rng.random_range(-8.0..-3.0)))).collect::<Vec<_>>().join(", "))).collect();
        let density = ["0.1", "0.324", "5e-324", "0"][rng.random_range(0..4)];
        let text = format!("{{\"density\": {density}, \"stretching\": [{}], \"bending\": [{}]}}", stretching.join(", "), bending.join(", "));
        let (file, out) = (format!("material-{case}.json"), format!("fabric-{case}.toml"));
        std::fs::write(dir.join(&file), &text).unwrap();
        let ended = rosette(&["fabric", "import", &file, "--out", &out, "--force"], &dir);
        judge(&format!("ARCSim material {case} (seed 62):\n{text}"), &ended, &[0, 2], &dir);
    }
}
