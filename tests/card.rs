//! `rosette card` and `rosette compare` from the command line: the card's JSON against the
//! sheet it came from, the lab's own read-back (`rosette fabric check`) and the drape as
//! `rosette run` gives it; the page's size; the contact sheet's size and numbers; bad input
//! refused with exit 2 before any run.

mod common;

use common::runtime_dir;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};


fn rosette(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).env("XDG_RUNTIME_DIR", runtime_dir()).output().expect("the rosette binary runs")
}

fn dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("card-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))).unwrap()
}

/// `rosette fabric check`'s virtual reading of `field`.
fn checked(table: &str, field: &str) -> f64 {
    let line = table.lines().find(|l| l.split_whitespace().next() == Some(field)).unwrap_or_else(|| panic!("no {field} in\n{table}"));
    line.split_whitespace().nth(2).unwrap().parse().unwrap()
}

fn by_direction<'a>(list: &'a Value, direction: &str) -> &'a Value {
    list.as_array().unwrap().iter().find(|v| v["direction"] == direction).unwrap_or_else(|| panic!("no {direction} in {list}"))
}

/// The poplin's KES sheet (presets/fabrics/cotton-poplin.toml): EMT 3.5 / 5.5 %, B 0.085 /
/// 0.065 gf·cm²/cm, G 1.10 gf/(cm·deg), W 12 mg/cm².
#[test]
fn a_card_reads_back_its_sheet_as_the_lab_does_and_drapes_as_run_does() {
    let out_dir = dir("poplin");
    let out = rosette(&["card", "cotton-poplin", "--out", out_dir.to_str().unwrap()]);
    assert!(out.status.success(), "exit {:?}: {}", out.status, text(&out.stderr));
    let card = json(&out_dir.join("cotton-poplin.json"));
    let page = image::open(out_dir.join("cotton-poplin.png")).unwrap();
    assert_eq!((page.width(), page.height()), (1400, 920));

    // Against the sheet, within the read-back's tolerances (tensile 3 %, bending 2 %, shear 5 %).
    let warp = by_direction(&card["tensile"], "warp");
    let weft = by_direction(&card["tensile"], "weft");
    assert!((warp["emt_percent"].as_f64().unwrap() / 3.5 - 1.0).abs() < 0.03, "{warp}");
    assert!((weft["emt_percent"].as_f64().unwrap() / 5.5 - 1.0).abs() < 0.03, "{weft}");
    let b_warp = by_direction(&card["pure_bending"], "warp")["rigidity_gf_cm2_per_cm"].as_f64().unwrap();
    assert!((b_warp / 0.085 - 1.0).abs() < 0.02, "B warp {b_warp}");
    let g = card["shear"]["g_gf_per_cm_deg"].as_f64().unwrap();
    assert!((g / 1.10 - 1.0).abs() < 0.05, "G {g}");
    assert_eq!(card["fabric"]["areal_density_g_per_m2"].as_f64().unwrap(), 120.0);
    // The standard's relation B = w·c³ (docs/references.md §8; the elastica gives 41.5° at
    // λ = 8): the bending lengths of the warp and weft strips follow the input rigidity.
    for d in ["warp", "weft"] {
        let c = by_direction(&card["cantilever"], d);
        let (measured, formula) = (c["bending_length_mm"].as_f64().unwrap(), c["formula_bending_length_mm"].as_f64().unwrap());
        assert!((measured / formula - 1.0).abs() < 0.03, "{d}: c {measured} mm, (B/w)^⅓ {formula} mm");
    }
    // Every curve starts at the origin and carries its units.
    for t in card["tensile"].as_array().unwrap() {
        assert_eq!(t["measured"]["x"], "strain (%)");
        assert_eq!(t["measured"]["y"], "stress (N/m)");
        assert_eq!(t["measured"]["points"][0], serde_json::json!([0.0, 0.0]), "{}", t["direction"]);
        assert!(t["input"]["points"].as_array().unwrap().len() >= 2);
    }
    assert_eq!(card["cantilever"].as_array().unwrap().len(), 3);
    assert_eq!(card["pure_bending"].as_array().unwrap().len(), 3);

    // The same numbers as the lab's own read-back, which runs the tests itself.
    let check = rosette(&["fabric", "check", "cotton-poplin"]);
    assert!(check.status.success(), "{}", text(&check.stderr));
    let table = text(&check.stdout);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs().max(1.0);
    assert!(close(warp["emt_percent"].as_f64().unwrap(), checked(&table, "kes.EMT_warp")));
    assert!(close(warp["lt"].as_f64().unwrap(), checked(&table, "kes.LT_warp")));
    assert!(close(b_warp, checked(&table, "kes.B_warp")));
    assert!(close(g, checked(&table, "kes.G")));
    let readback = card["sheet_readback"].as_array().unwrap();
    assert_eq!(readback.len(), table.lines().count() - 1, "one row per sheet value");
    for row in readback {
        let field = row["field"].as_str().unwrap();
        assert!(close(row["measured"].as_f64().unwrap(), checked(&table, field)), "{field}");
        assert_eq!(row["passes"], true, "{field}");
    }

    // The drape is the 30 cm Cusick scene's, as `rosette run` drapes this fabric.
    let metrics = out_dir.join("run.json");
    let run = rosette(&["run", "cusick-drape-30", "--set", "fabric.preset=cotton-poplin", "--metrics", metrics.to_str().unwrap()]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let measures = &json(&metrics)["measures"];
    assert_eq!(card["drape"]["drape_coefficient"], measures["drape_coefficient"]);
    assert_eq!(card["drape"]["nodes"], measures["nodes"]);
    assert_eq!(card["drape"]["settled"], true);
}

#[test]
fn bad_fabrics_and_outputs_are_refused_before_any_run() {
    let out_dir = dir("bad");
    let out = rosette(&["card", "no-such-fabric", "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("no bundled fabric named 'no-such-fabric'"), "{}", text(&out.stderr));
    // A fabric file with a bad value names its key.
    let bad = out_dir.join("thin.toml");
    std::fs::write(&bad, std::fs::read_to_string("presets/fabrics/wool.toml").unwrap().replace("thickness = 3.14e-4", "thickness = -1")).unwrap();
    let out = rosette(&["card", bad.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("thickness"), "{}", text(&out.stderr));
    // An output directory that is a file.
    let file = out_dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    let out = rosette(&["card", "wool", "--out", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("--out"), "{}", text(&out.stderr));

    // compare: the bad name among good ones is named, and nothing is written.
    let sheet = out_dir.join("sheet.png");
    let out = rosette(&["compare", "silk", "sik", "denim", "--out", sheet.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("fabric 'sik'"), "{}", text(&out.stderr));
    assert!(!sheet.exists() && !sheet.with_extension("json").exists());
    let out = rosette(&["compare", "silk", "--scene", "cantilever", "--out", sheet.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(text(&out.stderr).contains("not a drape or garment scene"), "{}", text(&out.stderr));
}

#[test]
fn compare_sets_two_drapes_side_by_side_with_the_numbers_run_gives() {
    let out_dir = dir("compare");
    let sheet = out_dir.join("pair.png");
    // A short drape (0.3 s, before settling) keeps the test cheap; the numbers must still be
    // those of the same run by `rosette run`.
    let out = rosette(&["compare", "silk", "denim", "--set", "scene.duration=0.3", "--out", sheet.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let picture = image::open(&sheet).unwrap();
    // Two 420 × 300 pictures side by side, a 44 px title above and 58 px captions below.
    assert_eq!((picture.width(), picture.height()), (840, 402));
    let numbers = json(&sheet.with_extension("json"));
    let entries = numbers["entries"].as_array().unwrap();
    assert_eq!(entries.len(), 2);
    let csv = std::fs::read_to_string(sheet.with_extension("csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    for (entry, fabric) in entries.iter().zip(["silk", "denim"]) {
        assert_eq!(entry["fabric"], fabric);
        let metrics = out_dir.join(format!("{fabric}.json"));
        let preset = format!("fabric.preset={fabric}");
        let run = rosette(&["run", "cusick-drape-30", "--set", "scene.duration=0.3", "--set", &preset, "--metrics", metrics.to_str().unwrap()]);
        assert!(run.status.success(), "{}", text(&run.stderr));
        let measures = &json(&metrics)["measures"];
        assert_eq!(entry["drape_coefficient"], measures["drape_coefficient"], "{fabric}");
        assert_eq!(entry["nodes"], measures["nodes"], "{fabric}");
        assert!(csv.contains(&format!("\"{fabric}\",")), "{csv}");
    }
}
