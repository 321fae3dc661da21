//! `rosette fabric`: template, import, list and check from the command line, with exit 2
//! and the field's name for a bad sheet, warnings for defaults on stderr.

use std::path::PathBuf;
use std::process::{Command, Output};

fn rosette(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).output().expect("the rosette binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A file in the test's own temporary directory.
fn temp(name: &str, contents: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("fabric-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

#[test]
fn template_imports_into_a_fabric_file_that_scenes_load() {
    let out = rosette(&["fabric", "template", "--standard", "kes"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let sheet = temp("template-kes.toml", &text(&out.stdout));
    let fabric = sheet.with_file_name("template-kes-fabric.toml");
    let out = rosette(&["fabric", "import", sheet.to_str().unwrap(), "--out", fabric.to_str().unwrap()]);
    assert!(out.status.success(), "exit {:?}: {}", out.status, text(&out.stderr));
    let written = std::fs::read_to_string(&fabric).unwrap();
    assert!(written.contains("# kes.B_warp = 0.057 gf·cm²/cm\nbending_warp = 5.58979"), "{written}");
    // The written file is a fabric like any other.
    let out = rosette(&["run", "cantilever", "--set", &format!("fabric.preset={}", fabric.display()), "--duration", "0.02"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = rosette(&["fabric", "template", "--standard", "astm"]);
    assert_eq!(out.status.code(), Some(2), "an unknown standard is bad input");
    assert!(text(&out.stderr).contains("kes, fast or cantilever"));
}

#[test]
fn bad_sheet_exits_2_naming_the_field() {
    let cases = [
        ("unit.toml", "[kes]\nW = \"13 stone/acre\"\nB = 0.1", "kes.W"),
        ("negative.toml", "[fast]\nW = 150\nC = -15", "fast.C = -15 mm: must be a positive number"),
        ("lt.toml", "[kes]\nW = 13\nB = 0.1\nEMT = 5\nLT = 1.3", "kes.LT_warp"),
    ];
    for (name, contents, needle) in cases {
        let path = temp(name, contents);
        let out = rosette(&["fabric", "import", path.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", text(&out.stderr));
        assert!(text(&out.stderr).contains(needle), "{name}: {}", text(&out.stderr));
        assert!(out.stdout.is_empty(), "{name}: nothing is written for a bad sheet");
    }
    let out = rosette(&["fabric", "import", "wool"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("no [kes], [fast] or [cantilever]"), "{}", text(&out.stderr));
    let out = rosette(&["fabric", "import", "no-such-fabric"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("wool-plain-fast"), "lists what exists: {}", text(&out.stderr));
}

#[test]
fn defaults_are_warned_on_stderr() {
    let path = temp("cantilever-only.toml", "[cantilever]\nW = 120\nc_warp = 19\nc_weft = 17");
    let out = rosette(&["fabric", "import", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stderr = text(&out.stderr);
    for key in ["shear_modulus", "tensile_warp", "thickness", "poisson_warp"] {
        assert!(stderr.contains(&format!("warning: {key}")), "{key}: {stderr}");
    }
    assert!(text(&out.stdout).contains("# DEFAULT, not measured"), "the file marks its defaults");
}

#[test]
fn list_names_every_bundled_fabric_and_its_sheet() {
    let out = rosette(&["fabric", "list"]);
    assert!(out.status.success());
    let listed = text(&out.stdout);
    for b in rosette::settings::FABRICS {
        assert!(listed.lines().any(|l| l.starts_with(b.name)), "{}: {listed}", b.name);
    }
    assert!(listed.lines().any(|l| l.starts_with("wool-plain-fast") && l.contains("fast")), "{listed}");
}

/// A KES sheet checked end to end: every line within tolerance, exit 0; a fabric without a
/// sheet has nothing to check against (exit 2).
#[test]
fn check_reads_a_kes_sheet_back() {
    let out = rosette(&["fabric", "check", "wool-worsted"]);
    assert!(out.status.success(), "exit {:?}: {}{}", out.status, text(&out.stdout), text(&out.stderr));
    let table = text(&out.stdout);
    for field in ["kes.EMT_warp", "kes.LT_weft", "kes.WT_warp", "kes.B_weft", "kes.G"] {
        assert!(table.contains(field), "{field}: {table}");
    }
    assert!(!table.contains("OUTSIDE"), "{table}");
    let out = rosette(&["fabric", "check", "wool"]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
}
