//! The round trip of issue 26, part 2: a fabric imported from a measurement sheet, run
//! through the virtual laboratory (src/lab), reads its sheet back. The references are the
//! sheet's own numbers and the standards' formulas (docs/references.md §8): EMT, LT and WT
//! of a KES pull to 500 gf/cm within 3 %, B of pure bending between 0.5 and 1.5 cm⁻¹
//! within 2 %, G of the shear slope from 0.5° to 5° within 5 %, the FAST extensions within
//! 3 % and the warp, weft and bias bending lengths of the standard's 25 mm strip within 3 %.

use rosette::fabric::{LoadedFabric, load_fabric, parse_fabric};
use rosette::lab::{ReadBack, readback};
use rosette::settings::FABRICS;

/// Reads every sheet value of `fabric` back and prints the table.
fn check(name: &str, fabric: &LoadedFabric) -> ReadBack {
    let r = readback(&fabric.sheets, &fabric.import, &fabric.config).unwrap_or_else(|e| panic!("{name}: {e}"));
    println!("{name}:\n{}", r.table());
    r
}

/// Runs `work` on every item, two at a time (the machine's two cores).
fn on_two_cores<T: Sync, R: Send>(items: &[T], work: impl Fn(&T) -> R + Sync) -> Vec<R> {
    std::thread::scope(|s| {
        let halves = items.split_at(items.len().div_ceil(2));
        let work = &work;
        let a = s.spawn(move || halves.0.iter().map(work).collect::<Vec<_>>());
        let b: Vec<R> = halves.1.iter().map(work).collect();
        let mut out = a.join().unwrap();
        out.extend(b);
        out
    })
}

fn assert_read_back(name: &str, r: &ReadBack) {
    assert!(!r.properties.is_empty(), "{name}: nothing was read back");
    for p in &r.properties {
        assert!(
            p.passes(),
            "{name}: {} = {} {} on the sheet, {} read by the {} test ({:+.2} %, tolerance {} %)",
            p.field,
            p.sheet,
            p.unit,
            p.measured,
            p.test,
            100.0 * p.error(),
            100.0 * p.tolerance
        );
    }
}

/// Every bundled fabric that comes from a sheet (KES, FAST, cantilever) reads it back
/// (the ARCSim materials have their own round trip, tests/arcsim_lab.rs).
#[test]
fn bundled_sheets_read_back_within_the_issue_tolerances() {
    let sheet_fabrics: Vec<(&str, LoadedFabric)> = FABRICS
        .iter()
        .map(|b| (b.name, load_fabric(b.name).unwrap()))
        .filter(|(_, f)| !f.sheets.is_empty() && f.sheets.arcsim.is_none())
        .collect();
    assert!(sheet_fabrics.len() >= 7, "the library's sheet fabrics: {}", sheet_fabrics.len());
    let results = on_two_cores(&sheet_fabrics, |(name, fabric)| check(name, fabric));
    for ((name, _), r) in sheet_fabrics.iter().zip(&results) {
        assert_read_back(name, r);
    }
}

/// Cantilever sheets with a bias bending length: the bias strip, like the warp and weft
/// ones, reads its measured bending length back on the standard's 25 mm strip. The two
/// sheets are a light and a heavy fabric written for this test: a bias bending length 0.87
/// and 0.80 of the warp's (plate B₄₅ 0.52 to 0.66 of the warp/weft mean, docs/fabric-sheets.md).
#[test]
fn bias_bending_lengths_read_back_on_the_standard_strip() {
    let sheets = [
        (
            "light wool, cantilever sheet",
            "poisson_warp = 0.15\n[kes]\nT = 0.3\nEMT = 5\nLT = 0.65\nG = 0.7\n\
             [cantilever]\nW = 137\nc_warp = 18.8\nc_weft = 17.3\nc_bias = 16.4",
        ),
        (
            "denim, cantilever sheet",
            "poisson_warp = 0.2\n[kes]\nT = 0.9\nEMT_warp = 3.5\nEMT_weft = 5\nLT = 0.7\nG = 4.0\n\
             [cantilever]\nW = 420\nc_warp = 30\nc_weft = 25\nc_bias = 24",
        ),
    ];
    let loaded: Vec<(&str, LoadedFabric)> = sheets.iter().map(|(n, t)| (*n, parse_fabric(t, n).unwrap())).collect();
    for (name, f) in &loaded {
        assert!(f.warnings.is_empty(), "{name}: {:?}", f.warnings);
        let plate = f.config.properties.areal_density * rosette::physics::STANDARD_GRAVITY * f.sheets.cantilever.as_ref().unwrap().si("c_bias").unwrap().powi(3);
        let b45 = f.config.properties.bending_bias.unwrap();
        println!("{name}: bending_bias {b45:.4e} N·m, {:.1} % above the plate reading W·g·c³ = {plate:.4e}", 100.0 * (b45 / plate - 1.0));
    }
    let results = on_two_cores(&loaded, |(name, fabric)| check(name, fabric));
    for ((name, _), r) in loaded.iter().zip(&results) {
        assert!(r.properties.iter().any(|p| p.field == "cantilever.c_bias"), "{name}: the bias was not read back");
        assert_read_back(name, r);
    }
}
