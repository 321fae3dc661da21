//! Files a hostile user (or a tired one who keeps the only copy of a sheet in the working
//! directory) hands the command line: outputs that are the command's own inputs under any
//! name, two outputs in one file, files that exist and are not Rosette's, special files
//! (/dev/zero, FIFOs, folders, sockets) for every file key, standard output closed or full,
//! and files whose contents must not be quoted. Every case is refused cleanly (exit 2, the
//! flag or key and the file named, the input intact) or ends as the conventions of
//! command-line tools say; never a panic, a hang or a lost file.
//!
//! The property tests derive their cases from the command's flags and inputs, so that a
//! flag added to the table below is covered against every input.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What one run of the binary did.
struct Outcome {
    code: Option<i32>,
    stderr: String,
    timed_out: bool,
}

/// Runs the binary with `args` and `stdout` as its standard output, killed after `limit`.
fn rosette_with(args: &[String], stdout: Stdio, env: &[(&str, &str)], limit: Duration) -> Outcome {
    let mut command = Command::new(env!("CARGO_BIN_EXE_rosette"));
    command.args(args).env("RAYON_NUM_THREADS", "1").stdout(stdout).stderr(Stdio::piped());
    for (k, v) in env {
        command.env(k, v);
    }
    let mut child = command.spawn().expect("the rosette binary runs");
    let mut err = child.stderr.take().expect("piped");
    let err_reader = std::thread::spawn(move || {
        let mut text = String::new();
        err.read_to_string(&mut text).ok();
        text
    });
    let out_reader = child.stdout.take().map(|mut out| {
        std::thread::spawn(move || {
            let mut text = String::new();
            out.read_to_string(&mut text).ok();
            text
        })
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
    // Standard output is drained so that the command never waits on a full pipe.
    if let Some(reader) = out_reader {
        reader.join().ok();
    }
    Outcome { code: status.code(), stderr: err_reader.join().unwrap_or_default(), timed_out }
}

fn rosette(args: &[String]) -> Outcome {
    rosette_with(args, Stdio::piped(), &[], Duration::from_secs(60))
}

fn strings(args: &[&str]) -> Vec<String> {
    args.iter().map(|s| s.to_string()).collect()
}

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("hostile-files-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bundled(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// A closed tetrahedron, outward faces, 1 cm across.
const TETRAHEDRON: &str = "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0 0 0.01\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

/// Checks a refusal: exit 2, quickly, naming each of `words`, and every file of `intact`
/// as it was.
fn assert_refused_intact(context: &str, out: &Outcome, words: &[&str], intact: &[(&Path, &[u8])]) -> Result<(), String> {
    if out.timed_out {
        return Err(format!("{context}: still running after its limit (a hang)"));
    }
    if out.code != Some(2) {
        return Err(format!("{context}: exit {:?}, expected 2: {}", out.code, out.stderr.trim()));
    }
    for word in words {
        if !out.stderr.contains(word) {
            return Err(format!("{context}: the message should name '{word}': {}", out.stderr.trim()));
        }
    }
    for (path, bytes) in intact {
        if std::fs::read(path).ok().as_deref() != Some(*bytes) {
            return Err(format!("{context}: {} was changed", path.display()));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Outputs against inputs
// ---------------------------------------------------------------------------------------

/// `rosette run`'s output flags and the extension each requires (none: any name).
const RUN_OUTPUTS: [(&str, Option<&str>); 5] =
    [("--metrics", None), ("--outline", None), ("--step-log", None), ("--screenshot", Some("png")), ("--export", Some("glb"))];

/// The files a drape scene can read: the scene, its fabric file and a mesh prop.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Scene,
    Fabric,
    Mesh,
}

/// Writes a scene (a copy of cusick-drape-30), its fabric (a copy of wool) and a mesh prop
/// into `dir`, the file of `role` named `name` and the others by their kind; returns the
/// three paths.
fn scene_files(dir: &Path, role: Role, name: &str) -> [PathBuf; 3] {
    let pick = |r: Role, default: &str| dir.join(if r == role { name } else { default });
    let (scene, fabric, mesh) = (pick(Role::Scene, "scene.toml"), pick(Role::Fabric, "fabric.toml"), pick(Role::Mesh, "prop.obj"));
    std::fs::write(&fabric, bundled("presets/fabrics/wool.toml")).unwrap();
    std::fs::write(&mesh, TETRAHEDRON).unwrap();
    let text = bundled("presets/cusick-drape-30.toml");
    let mut scene_text = String::new();
    for line in text.lines() {
        let line = if line.trim_start().starts_with("preset =") { format!("preset = {:?}", fabric.display().to_string()) } else { line.to_string() };
        scene_text += &line;
        scene_text.push('\n');
    }
    scene_text += &format!("\n[[props]]\nname = \"pebble\"\nshape = \"mesh\"\nfile = {:?}\nposition = [0.5, 0.5, -0.4]\n", mesh.display().to_string());
    std::fs::write(&scene, scene_text).unwrap();
    [scene, fabric, mesh]
}

/// The property: every output flag of `rosette run`, aimed at every file the run reads
/// (directly, through `./`, and through a link), is refused before the run and the file
/// is left as it was.
#[test]
fn every_run_output_aimed_at_every_input_is_refused_and_the_input_survives() {
    let dir = folder("run-inputs");
    let mut failures = Vec::new();
    let mut cases = 0;
    for (flag, required) in RUN_OUTPUTS {
        for role in [Role::Scene, Role::Fabric, Role::Mesh] {
            let natural = match role {
                Role::Mesh => "obj",
                _ => "toml",
            };
            let name = format!("input-{}.{}", flag.trim_start_matches('-'), required.unwrap_or(natural));
            let files = scene_files(&dir, role, &name);
            let target = &files[role as usize];
            let link = dir.join(format!("link-{name}"));
            let _ = std::fs::remove_file(&link);
            #[cfg(unix)]
            std::os::unix::fs::symlink(target, &link).unwrap();
            let dotted = dir.join(".").join(&name);
            let contents: Vec<(PathBuf, Vec<u8>)> = files.iter().map(|f| (f.clone(), std::fs::read(f).unwrap())).collect();
            for output in [target.clone(), dotted, link] {
                if !output.exists() {
                    continue;
                }
                cases += 1;
                let args = strings(&["run", files[0].to_str().unwrap(), "--duration", "0.004", "--max-wall", "20", flag, output.to_str().unwrap()]);
                let out = rosette(&args);
                let intact: Vec<(&Path, &[u8])> = contents.iter().map(|(p, b)| (p.as_path(), b.as_slice())).collect();
                let context = format!("rosette run ({role:?} file as output) {flag} {}", output.display());
                if let Err(e) = assert_refused_intact(&context, &out, &[flag, "reads"], &intact) {
                    failures.push(e);
                }
            }
        }
    }
    // Two outputs in one file, whatever the names they are given by.
    let files = scene_files(&dir, Role::Scene, "scene.toml");
    let shared = dir.join("shared.csv");
    for (i, (a, _)) in RUN_OUTPUTS[..3].iter().enumerate() {
        for (b, _) in &RUN_OUTPUTS[i + 1..3] {
            cases += 1;
            let other = dir.join(".").join("shared.csv");
            let args = strings(&["run", files[0].to_str().unwrap(), "--duration", "0.004", a, shared.to_str().unwrap(), b, other.to_str().unwrap()]);
            let out = rosette(&args);
            if let Err(e) = assert_refused_intact(&format!("{a} and {b} into one file"), &out, &[a, b, "same file"], &[]) {
                failures.push(e);
            }
            if shared.exists() {
                failures.push(format!("{a} and {b}: {} was written", shared.display()));
            }
        }
    }
    assert!(cases >= 45, "{cases} cases");
    assert!(failures.is_empty(), "{} of {cases} cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// The other commands that write files, each aimed at its own input: the sheet an import
/// converts, the fabric a card or a comparison reads.
#[test]
fn card_compare_and_import_never_write_over_their_inputs() {
    let dir = folder("other-inputs");
    let sheet = dir.join("sheet.toml");
    let sheet_text = bundled("presets/fabrics/cotton-poplin.toml");
    std::fs::write(&sheet, &sheet_text).unwrap();
    let mut failures = Vec::new();
    let link = dir.join("link.toml");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&sheet, &link).unwrap();
    for out in [sheet.clone(), dir.join(".").join("sheet.toml"), link] {
        let result = rosette(&strings(&["fabric", "import", sheet.to_str().unwrap(), "--out", out.to_str().unwrap(), "--force"]));
        if let Err(e) = assert_refused_intact("fabric import SHEET --out SHEET", &result, &["--out", "reads"], &[(&sheet, sheet_text.as_bytes())]) {
            failures.push(e);
        }
    }
    // A fabric named d14.json (an ARCSim material, the one kind of fabric file that ends in
    // .json): the card's DIR/d14.json would be that file.
    let fabric = dir.join("d14.json");
    let material_text = bundled("presets/fabrics/arcsim/11oz-black-denim.json");
    std::fs::write(&fabric, &material_text).unwrap();
    for out in [dir.clone(), dir.join(".")] {
        let result = rosette(&strings(&["card", fabric.to_str().unwrap(), "--out", out.to_str().unwrap(), "--force"]));
        if let Err(e) = assert_refused_intact("card d14.json --out .", &result, &["--out", "reads"], &[(&fabric, material_text.as_bytes())]) {
            failures.push(e);
        }
    }
    // compare's FILE.json beside its picture.
    let sheet_png = dir.join("d14.png");
    let result = rosette(&strings(&["compare", fabric.to_str().unwrap(), "silk", "--out", sheet_png.to_str().unwrap(), "--force"]));
    if let Err(e) = assert_refused_intact("compare d14.json --out d14.png", &result, &["--out", "reads"], &[(&fabric, material_text.as_bytes())]) {
        failures.push(e);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// An existing file that is not Rosette's own output of the same kind is replaced only
/// with --force; one Rosette wrote (the metrics of an earlier run, a fabric it imported) is
/// replaced as before.
#[test]
fn an_existing_file_is_replaced_only_when_rosette_wrote_it_or_with_force() {
    let dir = folder("existing");
    let notes = dir.join("notes.json");
    std::fs::write(&notes, "my only notes").unwrap();
    let run = |extra: &[&str]| {
        let mut args = strings(&["run", "cantilever", "--duration", "0.01", "--metrics", notes.to_str().unwrap()]);
        args.extend(strings(extra));
        rosette(&args)
    };
    let out = run(&[]);
    assert_refused_intact("--metrics over notes", &out, &["--metrics", "not a metrics file Rosette wrote", "--force"], &[(&notes, b"my only notes")]).unwrap();
    let out = run(&["--force"]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let first: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&notes).unwrap()).unwrap();
    assert_eq!(first["preset"], "cantilever");
    // Now Rosette's own metrics: replaced without --force.
    let out = run(&[]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    // A hand-written sheet is not replaced by an import; an earlier import is.
    let hand = dir.join("hand.toml");
    std::fs::write(&hand, "# my sheet\n[kes]\nW = 13.7\n").unwrap();
    let out = rosette(&strings(&["fabric", "import", "cotton-poplin", "--out", hand.to_str().unwrap()]));
    assert_refused_intact("import over a hand sheet", &out, &["--out", "--force"], &[(&hand, b"# my sheet\n[kes]\nW = 13.7\n")]).unwrap();
    let imported = dir.join("imported.toml");
    for _ in 0..2 {
        let out = rosette(&strings(&["fabric", "import", "cotton-poplin", "--out", imported.to_str().unwrap()]));
        assert_eq!(out.code, Some(0), "{}", out.stderr);
    }
    // No staging file is left behind.
    let stray: Vec<String> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect();
    assert!(stray.is_empty(), "{stray:?}");
}

/// `chart` and `bench` check their outputs before their sweeps (which take minutes), and
/// name the file.
#[test]
fn long_sweeps_check_their_outputs_before_the_first_run() {
    let dir = folder("sweeps");
    for (command, file) in [("chart", "accuracy.csv"), ("bench", "bench.csv")] {
        let precious = dir.join(file);
        std::fs::write(&precious, "someone's table").unwrap();
        let started = Instant::now();
        let mut args = strings(&[command, "--quick", "--out", dir.to_str().unwrap()]);
        if command == "bench" {
            args.extend(strings(&["--threads", "1"]));
        }
        let out = rosette(&args);
        assert_refused_intact(command, &out, &["--out", file], &[(&precious, b"someone's table")]).unwrap();
        assert!(started.elapsed() < Duration::from_secs(20), "{command}: refused only after {:?}", started.elapsed());
    }
    let out = rosette(&strings(&["bench", "--threads", "0", "--out", dir.to_str().unwrap()]));
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(out.stderr.contains("--threads") && out.stderr.contains("1 to"), "{}", out.stderr);
}

// ---------------------------------------------------------------------------------------
// Special files for every file key
// ---------------------------------------------------------------------------------------

/// Special files of every kind this machine can make, with what the message must say.
fn special_files(dir: &Path) -> Vec<(PathBuf, &'static str)> {
    let mut files = vec![(PathBuf::from("/dev/zero"), "device"), (PathBuf::from("/dev/urandom"), "device"), (dir.to_path_buf(), "folder")];
    let fifo = dir.join("fifo.toml");
    if Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
        files.push((fifo, "FIFO"));
    }
    #[cfg(unix)]
    {
        let socket = dir.join("socket.toml");
        // The listener stays bound while the file exists; the tests only stat it.
        if let Ok(listener) = std::os::unix::net::UnixListener::bind(&socket) {
            std::mem::forget(listener);
            files.push((socket, "socket"));
        }
    }
    files.retain(|(p, _)| p.exists());
    files
}

/// The property: every key that names a file (the scene, `fabric.preset`, a mesh prop's
/// `file`, the card's, the comparison's, the import's and the check's fabric), given every
/// kind of special file, is refused within seconds naming the file; none hangs on a FIFO
/// or reads /dev/zero until memory runs out.
#[test]
fn special_files_for_every_file_key_are_refused_without_reading_them() {
    let dir = folder("special");
    let specials = special_files(&dir);
    assert!(specials.len() >= 4, "{specials:?}");
    let mut failures = Vec::new();
    let mut cases = 0;
    for (file, what) in &specials {
        let f = file.to_str().unwrap();
        let mesh = format!("props=[{{shape='mesh', file='{f}'}}]");
        let preset = format!("fabric.preset={f}");
        let keys: [(&str, Vec<&str>); 7] = [
            ("run SCENE", vec!["run", f, "--duration", "0.01"]),
            ("fabric.preset", vec!["run", "cantilever", "--set", &preset, "--duration", "0.01"]),
            ("props[].file", vec!["run", "cusick-drape-30", "--set", &mesh, "--duration", "0.01"]),
            ("card FABRIC", vec!["card", f, "--out", dir.to_str().unwrap()]),
            ("compare FABRIC", vec!["compare", f, "silk", "--out", "unused.png"]),
            ("fabric import SHEET", vec!["fabric", "import", f]),
            ("fabric check FABRIC", vec!["fabric", "check", f]),
        ];
        for (key, args) in keys {
            cases += 1;
            let started = Instant::now();
            let out = rosette_with(&strings(&args), Stdio::null(), &[], Duration::from_secs(20));
            let context = format!("{key} = {f}");
            if let Err(e) = assert_refused_intact(&context, &out, &[f, what], &[]) {
                failures.push(e);
            } else if started.elapsed() > Duration::from_secs(10) {
                failures.push(format!("{context}: refused only after {:?}", started.elapsed()));
            }
        }
    }
    assert!(failures.is_empty(), "{} of {cases} cases failed:\n{}", failures.len(), failures.join("\n"));
}

// ---------------------------------------------------------------------------------------
// Standard output closed or full
// ---------------------------------------------------------------------------------------

/// The commands that print to standard output and finish in a second or two.
fn printing_commands() -> Vec<Vec<String>> {
    [
        vec!["presets"],
        vec!["fabric", "list"],
        vec!["fabric", "template"],
        vec!["fabric", "import", "cotton-poplin"],
        vec!["run", "cantilever", "--duration", "0.01"],
        vec!["run", "cantilever", "--duration", "0.01", "--metrics", "-"],
    ]
    .iter()
    .map(|a| strings(a))
    .collect()
}

/// A pipe whose reader is gone before the command starts: every write fails with EPIPE.
fn closed_pipe() -> Stdio {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Stdio::from(writer)
}

fn full_device() -> Option<Stdio> {
    std::fs::OpenOptions::new().write(true).open("/dev/full").ok().map(Stdio::from)
}

/// The property: `rosette presets | head -1` and the like end quietly with exit 0 (as
/// other command-line tools do), and `> /dev/full` is exit 4 naming standard output;
/// never a panic.
#[test]
fn every_printing_command_survives_a_closed_or_full_standard_output() {
    let mut failures = Vec::new();
    for args in printing_commands() {
        let context = args.join(" ");
        let out = rosette_with(&args, closed_pipe(), &[], Duration::from_secs(60));
        if out.code != Some(0) || out.stderr.contains("panicked") || out.stderr.contains("error") {
            failures.push(format!("rosette {context} | (closed): exit {:?}: {}", out.code, out.stderr.trim()));
        }
        let Some(full) = full_device() else { continue };
        let out = rosette_with(&args, full, &[], Duration::from_secs(60));
        if out.code != Some(4) || out.stderr.contains("panicked") || !out.stderr.contains("standard output") {
            failures.push(format!("rosette {context} > /dev/full: exit {:?}: {}", out.code, out.stderr.trim()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Standard error full (`2>/dev/full`): the diagnostics are lost, the command is not.
#[test]
fn a_full_standard_error_does_not_panic() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else { return };
    let out = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["run", "cantilever", "--duration", "0.01", "--set", "fabric.areal_density=-1"])
        .stdout(Stdio::null())
        .stderr(Stdio::from(full))
        .status()
        .unwrap();
    assert_eq!(out.code(), Some(2), "the refusal's exit code survives a lost message");
}

/// The commands whose printing comes after minutes of work: the same property as above.
#[test]
#[ignore = "runs `fabric check`, `chart --quick` and `bench --quick` in full (minutes); cargo test --test hostile_files -- --ignored"]
fn long_commands_survive_a_closed_standard_output() {
    let dir = folder("long-closed");
    let chart = dir.join("chart");
    let bench = dir.join("bench");
    for args in [
        strings(&["fabric", "check", "cotton-poplin"]),
        strings(&["chart", "--quick", "--out", chart.to_str().unwrap()]),
        strings(&["bench", "--quick", "--threads", "1", "--out", bench.to_str().unwrap()]),
    ] {
        let out = rosette_with(&args, closed_pipe(), &[], Duration::from_secs(1800));
        assert!(matches!(out.code, Some(0 | 7)) && !out.stderr.contains("panicked"), "{args:?}: exit {:?}: {}", out.code, out.stderr);
    }
}

// ---------------------------------------------------------------------------------------
// Leaks
// ---------------------------------------------------------------------------------------

/// A file named where a fabric, a scene or a mesh is expected is quoted in an error only
/// when it is named as one (FILE.toml, FILE.obj): `fabric.preset=/etc/shadow` must not
/// print the file's first line, `/proc/self/environ` not the environment.
#[test]
fn errors_quote_a_file_only_where_it_is_the_kind_the_key_expects() {
    let dir = folder("leaks");
    let secret = dir.join("shadow");
    std::fs::write(&secret, "root:$6$hunter2hash:19000:0:99999:7:::\n").unwrap();
    let mesh = dir.join("mesh-secret");
    std::fs::write(&mesh, "v hunter2hash 0 0\nf 1 2 3\n").unwrap();
    let s = secret.to_str().unwrap();
    let prop = format!("props=[{{shape='mesh', file='{}'}}]", mesh.display());
    let preset = format!("fabric.preset={s}");
    let environ = "fabric.preset=/proc/self/environ".to_string();
    let cases: Vec<Vec<String>> = vec![
        strings(&["run", "cantilever", "--set", &preset]),
        strings(&["run", s]),
        strings(&["run", "cusick-drape-30", "--set", &prop]),
        strings(&["card", s, "--out", dir.to_str().unwrap()]),
        strings(&["fabric", "import", s]),
        strings(&["fabric", "check", s]),
        strings(&["run", "cantilever", "--set", &environ]),
    ];
    for args in cases {
        let out = rosette_with(&args, Stdio::null(), &[("ROSETTE_TEST_SECRET", "hunter3env")], Duration::from_secs(30));
        assert_eq!(out.code, Some(2), "{args:?}: {}", out.stderr);
        for secret in ["hunter2hash", "hunter3env", "root:"] {
            assert!(!out.stderr.contains(secret), "{args:?} leaks '{secret}': {}", out.stderr);
        }
        assert!(out.stderr.contains("not a") || out.stderr.contains("no such"), "{args:?}: {}", out.stderr);
    }
    // A file named as the kind expected is quoted: the user's own typo is shown.
    let mine = dir.join("mine.toml");
    std::fs::write(&mine, "areal_density = 0.2\nthickness = = 3\n").unwrap();
    let out = rosette(&strings(&["run", "cantilever", "--set", &format!("fabric.preset={}", mine.display())]));
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(out.stderr.contains("thickness = = 3"), "the fabric file's own line is quoted: {}", out.stderr);
}
