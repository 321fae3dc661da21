//! Measurement sheets into fabrics (issue 26, part 1): the exact unit factors of
//! docs/fabric-sheets.md, the tensile curves built from KES and FAST summaries, the stated
//! defaults with their warnings, and bad sheets refused with the field and the fix. No
//! simulation runs here; tests/fabric_lab.rs reads the sheets back with the virtual tests.

use rosette::fabric::{Sheets, derive, expand_sheets, load_fabric, parse_fabric, write};
use rosette::scene::load_scene;
use rosette::settings::FabricConfig;

/// Standard gravity and the gram-force, written out here rather than taken from the
/// library, so that a wrong factor there cannot agree with itself.
const G0: f64 = 9.80665;
const GF: f64 = 9.80665e-3;

fn table(text: &str) -> toml::Table {
    text.parse().unwrap_or_else(|e| panic!("{e}"))
}

/// Expands a fabric file's text and returns its fabric and warnings.
fn expand(text: &str) -> Result<(FabricConfig, Vec<String>), String> {
    let mut t = table(text);
    let warnings = expand_sheets(&mut t).map_err(|e| e.to_string())?.warnings;
    let config: FabricConfig = t.try_into().map_err(|e: toml::de::Error| e.to_string())?;
    config.to_fabric().map_err(|e| e.to_string())?;
    Ok((config, warnings))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// The area under a piecewise-linear curve from the origin to its last point.
fn area(curve: &[[f64; 2]]) -> f64 {
    curve.windows(2).map(|w| 0.5 * (w[0][1] + w[1][1]) * (w[1][0] - w[0][0])).sum()
}

const KES_SHEET: &str = r#"
poisson_warp = 0.15
[kes]
source = "test sheet"
W = 13.7
T = 0.314
EMT_warp = 6.0
LT_warp = 0.62
WT_warp = 9.3
EMT_weft = 7.5
LT_weft = 0.55
B_warp = 0.092
B_weft = 0.071
G_warp = 0.70
G_weft = 0.74
2HB = 0.04
RT = 62
"#;

#[test]
fn kes_sheet_converts_with_the_exact_gram_force_factors() {
    let (f, warnings) = expand(KES_SHEET).unwrap();
    assert!(warnings.is_empty(), "a complete sheet warns of nothing: {warnings:?}");
    assert!(close(f.properties.areal_density, 13.7 * 1e-6 / 1e-4, 1e-15), "1 mg/cm² = 0.01 kg/m²");
    assert!(close(f.properties.thickness, 0.314e-3, 1e-15));
    assert!(close(f.properties.bending_warp, 0.092 * GF * 1e-2, 1e-14), "1 gf·cm²/cm = 9.80665e-5 N·m");
    assert!(close(f.properties.bending_weft, 0.071 * GF * 1e-2, 1e-14));
    // Shear: the mean of the two directions, 1 gf/(cm·deg) = 0.980665·180/π N/m per radian.
    let g = 0.5 * (0.70 + 0.74) * (GF / 1e-2) * 180.0 / std::f64::consts::PI;
    assert!(close(f.properties.shear_modulus, g, 1e-14), "{} vs {g}", f.properties.shear_modulus);
    // Tensile: the curve ends at (EMT, 500 gf/cm) and its area is LT·Fm·EMT/2 (WT).
    let fm = 500.0 * GF / 1e-2;
    for (curve, emt, lt) in [(&f.properties.tensile_warp, 0.06, 0.62), (&f.properties.tensile_weft, 0.075, 0.55)] {
        let end = curve.last().unwrap();
        assert!(close(end[0], emt, 1e-15) && close(end[1], fm, 1e-15), "{curve:?}");
        assert!(close(area(curve), lt * fm * emt / 2.0, 1e-12), "WT = LT·Fm·EMT/2");
    }
    // The sheet's WT (9.3 gf·cm/cm²) agrees with LT·Fm·EMT/2 = 9.3 exactly.
    assert!(close(area(&f.properties.tensile_warp), 9.3 * GF * 1e-2 / 1e-4, 1e-12));
}

#[test]
fn fast_sheet_converts_bending_lengths_extensions_and_bias_extension() {
    let text = r#"
        poisson_warp = 0.15
        thickness = 4e-4
        [fast]
        W = 168
        C_warp = 15.0
        B_weft = 5.02
        E5_warp = 0.67
        E20_warp = 1.87
        E100_warp = 4.60
        E5_weft = 0.40
        E20_weft = 1.87
        E100_weft = 5.87
        EB5 = 4.7
    "#;
    let (f, warnings) = expand(text).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(close(f.properties.areal_density, 0.168, 1e-15));
    // FAST-2: B = W·g·C³ with W in kg/m² and C in m.
    assert!(close(f.properties.bending_warp, 0.168 * G0 * 0.015f64.powi(3), 1e-14), "{}", f.properties.bending_warp);
    assert!(close(f.properties.bending_weft, 5.02e-6, 1e-14));
    // FAST-3: the points (E, load) at 5, 20 and 100 gf/cm.
    let expected: Vec<[f64; 2]> = [(0.0, 0.0), (0.0067, 5.0), (0.0187, 20.0), (0.046, 100.0)]
        .iter()
        .map(|&(e, gf_cm)| [e, gf_cm * GF / 1e-2])
        .collect();
    for (got, want) in f.properties.tensile_warp.iter().zip(&expected) {
        assert!(close(got[0], want[0], 1e-12) && close(got[1], want[1], 1e-12), "{:?} vs {expected:?}", f.properties.tensile_warp);
    }
    assert!(close(f.properties.shear_modulus, 123.0 / 4.7, 1e-14), "G = 123/EB5");
}

#[test]
fn cantilever_overhang_is_twice_the_bending_length() {
    let base = "poisson_warp = 0.15\n[kes]\nEMT = 5\nLT = 0.6\nG = 0.7\nT = 0.4\n[cantilever]\nW = 150\n";
    let (a, _) = expand(&format!("{base}c_warp = 20\nc_weft = 18")).unwrap();
    let (b, _) = expand(&format!("{base}overhang_warp = \"4 cm\"\noverhang_weft = 36")).unwrap();
    assert!(close(a.properties.bending_warp, 0.150 * G0 * 0.020f64.powi(3), 1e-14));
    assert!(close(a.properties.bending_warp, b.properties.bending_warp, 1e-14) && close(a.properties.bending_weft, b.properties.bending_weft, 1e-14));
}

#[test]
fn missing_values_get_stated_defaults_and_a_warning_each() {
    let (f, warnings) = expand("[cantilever]\nW = 120\nc_warp = 19").unwrap();
    let joined = warnings.join("\n");
    for key in ["thickness", "shear_modulus", "tensile_warp", "tensile_weft", "poisson_warp", "bending_weft"] {
        assert!(joined.contains(key), "no warning for the defaulted {key}: {joined}");
    }
    assert!(close(f.properties.thickness, 0.120 / 400.0, 1e-12), "mass per area over 400 kg/m³");
    assert_eq!(f.properties.shear_modulus, 50.0);
    assert_eq!(f.properties.poisson_warp, 0.15);
    assert_eq!(f.properties.bending_weft, f.properties.bending_warp, "the only direction given serves for both");
    let fm = 500.0 * GF / 1e-2;
    assert!(close(area(&f.properties.tensile_warp), 0.65 * fm * 0.05 / 2.0, 1e-12), "EMT 5 %, LT 0.65");
}

#[test]
fn a_key_written_in_the_file_wins_over_the_sheet_and_says_so() {
    let (f, warnings) = expand(&format!("bending_warp = 2e-5\n{KES_SHEET}")).unwrap();
    assert_eq!(f.properties.bending_warp, 2e-5);
    assert!(warnings.iter().any(|w| w.contains("bending_warp") && w.contains("kes.B_warp")), "{warnings:?}");
    // Two sections that disagree: the first (KES) is used and the other named.
    let (f, warnings) = expand(&format!("{KES_SHEET}\n[fast]\nW = 137\nB_warp = 20")).unwrap();
    assert!(close(f.properties.bending_warp, 0.092 * GF * 1e-2, 1e-14));
    assert!(warnings.iter().any(|w| w.contains("fast.B_warp") && w.contains("kes.B_warp")), "{warnings:?}");
}

/// Bad sheets are refused before any work, naming the field and how to fix it.
#[test]
fn bad_sheets_name_the_field_and_the_fix() {
    let cases: [(&str, &[&str]); 10] = [
        ("[kes]\nW = 13\nEMT = 5\nLT = 1.2\nB = 0.1", &["kes.LT_warp", "softens", "ratio"]),
        ("[kes]\nW = 13\nEMT = 5\nLT = 0.6\nWT = 12\nB = 0.1", &["kes.WT_warp", "LT·Fm·EMT/2", "7.500"]),
        ("[kes]\nW = -13\nB = 0.1", &["kes.W", "positive"]),
        ("[kes]\nW = \"13 lb/in2\"\nB = 0.1", &["kes.W", "lb/in2", "mg/cm²"]),
        ("[fast]\nW = 150\nC = 15\nE5 = 2\nE20 = 1\nE100 = 4", &["fast.E5_warp", "fast.E20_warp", "E5 < E20 < E100"]),
        ("[fast]\nW = 150\nC_warp = 15\nB_warp = 9\nC_weft = 15", &["fast.B_warp", "fast.C_warp", "W·g·C³"]),
        ("[kes]\nB = 0.1", &["mass per area", "W"]),
        ("[cantilever]\nW = 150\nc_warp = 15\noverhang_warp = 30", &["cantilever.c_warp", "overhang_warp", "not both"]),
        ("[cantilever]\nW = 150\nc_warp = 20\nc_weft = 20\nc_bias = 8", &["cantilever.c_bias", "shorter than any sheet"]),
        ("[kes]\nW = 13\nBending = 0.1", &["kes.Bending", "B_warp", "rosette fabric template"]),
    ];
    for (text, needles) in cases {
        let err = expand(text).unwrap_err();
        for n in needles {
            assert!(err.contains(n), "sheet {text:?}: the error should mention {n:?}: {err}");
        }
    }
}

#[test]
fn the_imported_file_loads_back_to_the_same_fabric() {
    let loaded = load_fabric("wool-plain-fast").unwrap();
    let table = toml::Table::try_from(&loaded.config).unwrap();
    let text = write::fabric_file(&table, &loaded.sheets, &loaded.import, "wool-plain-fast");
    assert!(text.contains("# C_warp = 15 mm"), "the sheet is quoted: {text}");
    assert!(text.contains("# fast.G = 26.17 N/m\nshear_modulus = 26.17"), "each key's source is given: {text}");
    let again = parse_fabric(&text, "imported").unwrap();
    assert!(again.sheets.is_empty(), "the written file holds fabric keys only");
    let (a, b) = (toml::Table::try_from(&loaded.config).unwrap(), toml::Table::try_from(&again.config).unwrap());
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (k, v) in &a {
        let (x, y) = (numbers(v), numbers(&b[k]));
        assert_eq!(x.len(), y.len(), "{k}");
        for (x, y) in x.iter().zip(&y) {
            assert!(close(*y, *x, 1e-9), "{k}: {x} vs {y}");
        }
    }
}

/// Every number in a TOML value, in order.
fn numbers(v: &toml::Value) -> Vec<f64> {
    match v {
        toml::Value::Float(f) => vec![*f],
        toml::Value::Integer(i) => vec![*i as f64],
        toml::Value::Array(items) => items.iter().flat_map(numbers).collect(),
        _ => Vec::new(),
    }
}

#[test]
fn the_template_imports_as_it_stands() {
    let mut t = table(&write::template(None));
    let sheets = Sheets::take(&mut t).unwrap();
    assert!(sheets.kes.is_some() && sheets.fast.is_some() && sheets.cantilever.is_some());
    let import = derive(&sheets, &t).unwrap();
    assert!(import.get("bending_bias").is_some(), "the template's cantilever section measures the bias");
    for kind in rosette::fabric::SheetKind::ALL {
        let mut t = table(&write::template(Some(kind)));
        expand_sheets(&mut t).unwrap_or_else(|e| panic!("{}: {e}", kind.section()));
    }
}

/// A scene can change one sheet value (`--set fabric.fast.G=20`) and the fabric is
/// converted again with it; a bundled sheet fabric loads into any scene.
#[test]
fn scenes_load_sheet_fabrics_and_override_sheet_fields() {
    let (plain, _) = load_scene("cantilever", &["fabric.preset=wool-plain-fast".into()]).unwrap();
    // The sheet gives both B1 = 5.56 µN·m and C1 = 15 mm (W·g·C³ = 5.5604): B is used.
    assert!(close(plain.fabric.properties.bending_warp, 5.56e-6, 1e-14), "{}", plain.fabric.properties.bending_warp);
    assert!(close(plain.fabric.properties.shear_modulus, 26.17, 1e-14));
    let (changed, _) = load_scene("cantilever", &["fabric.preset=wool-plain-fast".into(), "fabric.fast.G=20".into()]).unwrap();
    assert!(close(changed.fabric.properties.shear_modulus, 20.0, 1e-14), "{}", changed.fabric.properties.shear_modulus);
    let err = load_scene("cantilever", &["fabric.preset=wool-plain-fast".into(), "fabric.fast.E5_warp=9".into()]).unwrap_err();
    assert!(err.to_string().contains("fast.E5_warp"), "{err}");
}
