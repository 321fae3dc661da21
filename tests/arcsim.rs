//! ARCSim materials (issue 38): the import's factors checked on cases worked by hand from
//! ARCSim's definitions (a uniaxial pull; a uniform bend of a strip, its hinge energy summed
//! over a mesh), and the round trip through both formats: a value both hold survives, and
//! a second pass changes nothing. The ten Wang–O'Brien–Ramamoorthi materials are
//! presets/fabrics/arcsim/*.json; the derivations are in docs/fabric-sheets.md.

use glam::{DVec2, DVec3};
use rosette::fabric::arcsim::export::{export, to_json};
use rosette::fabric::arcsim::material::parse_json;
use rosette::fabric::arcsim::model::{STRAIN_SAMPLE, moment, sample_curvatures};
use rosette::fabric::arcsim::project::{CURVE_TOLERANCE, MAX_POISSON, warp_bending_curve};
use rosette::fabric::arcsim::{ArcsimMaterial, model};
use rosette::fabric::{LoadedFabric, load_fabric, parse_fabric};
use rosette::sim::{BendingStiffness, Fabric, PiecewiseLinear};

const FILES: [&str; 10] = [
    "11oz-black-denim",
    "camel-ponte-roma",
    "gray-interlock",
    "ivory-rib-knit",
    "navy-sparkle-sweat",
    "pink-ribbon-brown",
    "royal-target",
    "tango-red-jet-set",
    "white-dots-on-blk",
    "white-swim-solid",
];
const WOVENS: [&str; 4] = ["11oz-black-denim", "pink-ribbon-brown", "royal-target", "white-dots-on-blk"];

fn file(stem: &str) -> String {
    format!("{}/presets/fabrics/arcsim/{stem}.json", env!("CARGO_MANIFEST_DIR"))
}

fn material(stem: &str) -> ArcsimMaterial {
    rosette::fabric::arcsim::material::read_file(std::path::Path::new(&file(stem))).unwrap()
}

/// A fabric file holding `m` inline, loaded.
fn import(m: &ArcsimMaterial) -> LoadedFabric {
    let rows = |t: &[&[f64]]| format!("[{}]", t.iter().map(|r| format!("[{}]", r.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(", "))).collect::<Vec<_>>().join(", "));
    let s: Vec<&[f64]> = m.stretching.iter().map(|r| r.as_slice()).collect();
    let b: Vec<&[f64]> = m.bending.iter().map(|r| r.as_slice()).collect();
    let text = format!("thickness = 5e-4\n[arcsim]\ndensity = {:e}\nstretching = {}\nbending = {}\n", m.density, rows(&s), rows(&b));
    parse_fabric(&text, "inline").unwrap_or_else(|e| panic!("{e}\n{text}"))
}

fn fabric(f: &LoadedFabric) -> Fabric {
    f.config.to_fabric().unwrap()
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * b.abs().max(1e-300)
}

/// A pull along u worked by hand from ARCSim's definitions, at a strain half-way to the
/// strain sample: ARCSim blends the zero-strain row and the strained row by
/// w = 6·(λ − 1) = 0.5, doubles the blend, and loads the sheet by S = K·G in Green strain;
/// the tester reads λ·S₀₀ per unit width.
#[test]
fn a_uniaxial_pull_worked_by_hand_is_the_imported_tensile_curve() {
    let text = r#"{"density": 0.2,
        "stretching": [[100, 20, 200, 30], [130, 20, 230, 40], [130, 20, 230, 40], [130, 20, 230, 40], [130, 20, 230, 40], [130, 20, 230, 40]],
        "bending": [[1e-5, 1e-5, 1e-5, 1e-5, 1e-5], [1e-5, 1e-5, 1e-5, 1e-5, 1e-5], [1e-5, 1e-5, 1e-5, 1e-5, 1e-5]]}"#;
    let f = fabric(&import(&parse_json(text, "hand.json").unwrap()));
    // ε = 1/12: λ = 13/12, w = 6·(1/12) = 0.5, blend [115, 20, 215, 35], doubled
    // K = [230, 40, 430, 70]. G₀₀ = (λ² − 1)/2 = 25/288. The free edges give
    // S₁₁ = 40·G₀₀ + 430·G₁₁ = 0, so S₀₀ = (230 − 40²/430)·G₀₀ = 19.6423 N/m, and the
    // load per unit width λ·S₀₀ = 21.2791 N/m.
    let load: f64 = 13.0 / 12.0 * (230.0 - 1600.0 / 430.0) * 25.0 / 288.0;
    assert!((load - 21.2791).abs() < 1e-4, "{load}");
    let read = f.tensile_warp.value(1.0 / 12.0);
    assert!(close(read, load, CURVE_TOLERANCE), "warp at 1/12: {read} vs {load}");
    // Along v the same with the roles of c11 and c22 swapped: (430 − 40²/230)·G₁₁·λ.
    let weft = 13.0 / 12.0 * (430.0 - 1600.0 / 230.0) * 25.0 / 288.0;
    assert!(close(f.tensile_weft.value(1.0 / 12.0), weft, CURVE_TOLERANCE));
    // At zero strain: E_u = 2·100 − (2·20)²/(2·200) = 196 N/m, the first segment exactly;
    // ν = c12/c22 = 0.1; the shear modulus is c33 = 30 N/m (doubled to 60, on the tensor
    // shear γ/2: ½·60·(γ/2)²·2 = ½·30·γ²).
    assert!(close(f.tensile_warp.initial_slope(), 196.0, 1e-12));
    assert!(close(f.tensile_weft.initial_slope(), 400.0 - 1600.0 / 200.0, 1e-12));
    assert!(close(f.poisson_warp, 0.1, 1e-12) && f.shear_modulus == 30.0);
    // From the strain sample on, ARCSim's stiffness is the strained row's: at 30 %,
    // λ·(260 − 40²/460)·G₀₀.
    let g = 0.5 * (1.3f64 * 1.3 - 1.0);
    assert!(close(f.tensile_warp.value(0.3), 1.3 * (260.0 - 1600.0 / 460.0) * g, CURVE_TOLERANCE));
}

/// A mesh of a ring: vertices (i, j) with i around it (periodic, `columns` of them) and j
/// across; `rest` gives a vertex's place on the unrolled strip (i may be `columns`, the
/// first column one circumference on), `place` its position on the ring.
struct Ring<'a> {
    columns: usize,
    triangles: Vec<[(usize, usize); 3]>,
    rest: &'a dyn Fn(usize, usize) -> DVec2,
    place: &'a dyn Fn(usize, usize) -> DVec3,
}

/// ARCSim's hinge energy over a ring's interior edges, by its definitions (physics.cpp
/// `bending_energy`, dde.cpp `bending_stiffness`): ke·l²/(2(A₀+A₁))·θ²/4 with θ the
/// dihedral angle and ke the sample of the edge's direction in material space (folded into
/// 0–90°, linear between the rows at 0°, 45° and 90°) at the hinge curvature θ·l/(A₀+A₁),
/// read every 10 m⁻¹ (`value = curv/2 · 0.2`). Returns the energy over the mesh's area,
/// J/m² (the strip's long edges are hinges of no energy in a bend along it, on the strip's
/// own mesh or not: the edges along the bend that would fold on equilateral triangles are
/// the boundary's few).
fn hinge_energy_density(m: &ArcsimMaterial, ring: &Ring) -> f64 {
    type Corner = (usize, usize);
    type Faces = Vec<(usize, Corner, Corner)>;
    let id = |(i, j): Corner| (i % ring.columns, j);
    let mut faces_of: std::collections::HashMap<(Corner, Corner), Faces> = Default::default();
    for (t, tri) in ring.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = if id(a) < id(b) { (id(a), id(b)) } else { (id(b), id(a)) };
            faces_of.entry(key).or_default().push((t, a, b));
        }
    }
    let area = |t: usize| {
        let [a, b, c] = ring.triangles[t].map(|(i, j)| (ring.rest)(i, j));
        0.5 * (b - a).perp_dot(c - a).abs()
    };
    let normal = |t: usize| {
        let [a, b, c] = ring.triangles[t].map(|(i, j)| (ring.place)(i, j));
        (b - a).cross(c - a).normalize()
    };
    let mut energy = 0.0;
    for faces in faces_of.values() {
        let [(f0, a, b), (f1, _, _)] = faces[..] else { continue };
        let theta = normal(f0).dot(normal(f1)).clamp(-1.0, 1.0).acos();
        let du = (ring.rest)(b.0, b.1) - (ring.rest)(a.0, a.1);
        let l = du.length();
        let areas = area(f0) + area(f1);
        // ARCSim's fold of the edge's angle into [0, 2] (0°, 45°, 90°).
        let mut bias = (du.y.atan2(du.x) * 4.0 / std::f64::consts::PI).abs();
        if bias > 4.0 {
            bias = 8.0 - bias;
        }
        if bias > 2.0 {
            bias = 4.0 - bias;
        }
        let row = (bias.floor() as usize).min(1);
        let f = bias - row as f64;
        let curv = theta * l / areas;
        let ke = (1.0 - f) * model::bending_sample(m, row, curv) + f * model::bending_sample(m, row + 1, curv);
        energy += ke * l * l / (2.0 * areas) * theta * theta / 4.0;
    }
    energy / (0..ring.triangles.len()).map(area).sum::<f64>()
}

/// The point at arc length `s` and width `w` of a ring of curvature `kappa`.
fn on_ring(kappa: f64, s: f64, w: f64) -> DVec3 {
    DVec3::new((kappa * s).sin() / kappa, w, (1.0 - (kappa * s).cos()) / kappa)
}

/// A strip cut along `along` (a unit vector in material space) bent into a ring of
/// curvature `kappa` on its own mesh: squares of side h split by a diagonal, the hinges
/// across the strip the square sides at right angles to it.
fn strip_ring(m: &ArcsimMaterial, along: DVec2, kappa: f64) -> f64 {
    let columns = 400;
    let h = 2.0 * std::f64::consts::PI / kappa / columns as f64;
    let rest = |i: usize, j: usize| (i as f64 * h) * along + (j as f64 * h) * along.perp();
    let place = |i: usize, j: usize| on_ring(kappa, i as f64 * h, j as f64 * h);
    let mut triangles = Vec::new();
    for j in 0..3 {
        for i in 0..columns {
            triangles.push([(i, j), (i + 1, j), (i + 1, j + 1)]);
            triangles.push([(i, j), (i + 1, j + 1), (i, j + 1)]);
        }
    }
    hinge_energy_density(m, &Ring { columns, triangles, rest: &rest, place: &place })
}

/// A strip bent uniformly on its own mesh stores ½·(ke/4)·κ² per area, with ke the sample of
/// the hinges across it at the curvature itself: the import's rigidities and the warp's
/// moments are that quarter.
#[test]
fn a_uniform_bend_of_a_strip_stores_a_quarter_of_the_sample() {
    let m = material("11oz-black-denim");
    let f = fabric(&import(&m));
    let curve = f.bending_curve.clone().expect("the denim's warp samples vary");
    let directions = [(DVec2::X, 2, f.bending_warp), (DVec2::Y, 0, f.bending_weft), (DVec2::new(1.0, 1.0).normalize(), 1, f.bending_bias.unwrap())];
    for (along, row, rigidity) in directions {
        for kappa in [1e-3, 10.0, 15.0, 20.0, 30.0] {
            let density = strip_ring(&m, along, kappa);
            let ke = model::bending_sample(&m, row, kappa);
            let expected = 0.5 * (ke / 4.0) * kappa * kappa;
            assert!(close(density, expected, 2e-4), "row {row} at {kappa}/m: {density} vs {expected}");
            // The moment of ARCSim's secant force (ke held): d/dκ of the energy at fixed
            // ke, 2·density/κ.
            let moment_per_width = 2.0 * density / kappa;
            assert!(close(moment(&m, row, kappa), moment_per_width, 2e-4));
            if kappa < 1.0 {
                assert!(close(rigidity, moment_per_width / kappa, 2e-4), "row {row}: {rigidity} vs {}", moment_per_width / kappa);
            } else if row == 2 {
                assert!(close(curve.value(kappa), moment_per_width, CURVE_TOLERANCE), "warp at {kappa}/m: {} vs {moment_per_width}", curve.value(kappa));
            }
        }
    }
}

/// The quarter does not hang on the strip's mesh where the samples are the same in every
/// direction: on equilateral triangles every edge direction bends (the edges along the
/// bend fold the other way), and the sum is again ½·(ke/4)·κ² per area.
#[test]
fn an_isotropic_sample_gives_a_quarter_on_equilateral_triangles_too() {
    let ke = 3e-5;
    let m = ArcsimMaterial { density: 0.2, stretching: [[100.0, 10.0, 100.0, 40.0]; 6], bending: [[ke; 5]; 3] };
    let kappa = 5.0;
    let columns = 300;
    let h = 2.0 * std::f64::consts::PI / kappa / columns as f64;
    let height = 0.5 * 3f64.sqrt() * h;
    for turn in [0.0f64, 0.3] {
        let along = DVec2::from_angle(turn);
        let s_of = |i: usize, j: usize| (i as f64 + 0.5 * (j % 2) as f64) * h;
        let rest = |i: usize, j: usize| s_of(i, j) * along + (j as f64 * height) * along.perp();
        let place = |i: usize, j: usize| on_ring(kappa, s_of(i, j), j as f64 * height);
        let mut triangles = Vec::new();
        for j in 0..120 {
            for i in 0..columns {
                if j % 2 == 0 {
                    triangles.push([(i, j), (i + 1, j), (i, j + 1)]);
                    triangles.push([(i + 1, j), (i + 1, j + 1), (i, j + 1)]);
                } else {
                    triangles.push([(i, j), (i + 1, j), (i + 1, j + 1)]);
                    triangles.push([(i, j), (i + 1, j + 1), (i, j + 1)]);
                }
            }
        }
        let density = hinge_energy_density(&m, &Ring { columns, triangles, rest: &rest, place: &place });
        let expected = 0.5 * (ke / 4.0) * kappa * kappa;
        assert!(close(density, expected, 5e-3), "turned {turn} rad: {density} vs {expected}");
    }
}

/// Through the text a file is written as (ten significant figures).
fn written(m: &ArcsimMaterial) -> ArcsimMaterial {
    parse_json(&to_json(m, &["a comment, as ARCSim's files have".into()]), "written.json").unwrap()
}

fn same_material(a: &ArcsimMaterial, b: &ArcsimMaterial, held_from: f64, what: &str) {
    let rounding = 2e-9;
    assert!(close(a.density, b.density, rounding), "{what}: density");
    for (i, (ra, rb)) in a.stretching.iter().zip(&b.stretching).enumerate() {
        for k in 0..4 {
            assert!((ra[k] - rb[k]).abs() <= rounding * ra[k].abs().max(rb[k].abs()) + 1e-12, "{what}: stretching[{i}][{k}] {} vs {}", ra[k], rb[k]);
        }
    }
    for (i, (ra, rb)) in a.bending.iter().zip(&b.bending).enumerate() {
        // Rosette reads its one curve at the warp curvature of the same linear energy,
        // κ·√(B/B_x): a row is shared up to where that reaches the held range.
        let scale = (ra[0] / a.bending[2][0]).sqrt();
        for j in (0..5).filter(|&j| sample_curvatures()[j] * scale <= held_from) {
            assert!(close(ra[j], rb[j], rounding), "{what}: bending[{i}][{j}] {} vs {}", ra[j], rb[j]);
        }
    }
}

/// The values a Rosette fabric and an ARCSim material both hold (docs/fabric-sheets.md):
/// mass, shear modulus, Poisson ratio, the tensile curves' first slopes and their values
/// at the strain sample, the three rigidities (the bias by eq. 3 where not given) and the
/// warp's moments at the sampled curvatures.
fn same_shared_values(a: &Fabric, b: &Fabric, held_from: f64, what: &str) {
    let tolerance = 1e-8;
    let pairs = [
        ("areal_density", a.areal_density, b.areal_density),
        ("shear_modulus", a.shear_modulus, b.shear_modulus),
        ("poisson_warp", a.poisson_warp, b.poisson_warp),
        ("warp first slope", a.tensile_warp.initial_slope(), b.tensile_warp.initial_slope()),
        ("weft first slope", a.tensile_weft.initial_slope(), b.tensile_weft.initial_slope()),
        ("warp at 1/6", a.tensile_warp.value(STRAIN_SAMPLE), b.tensile_warp.value(STRAIN_SAMPLE)),
        ("weft at 1/6", a.tensile_weft.value(STRAIN_SAMPLE), b.tensile_weft.value(STRAIN_SAMPLE)),
        ("bending_warp", a.bending_warp, b.bending_warp),
        ("bending_weft", a.bending_weft, b.bending_weft),
        ("bending at 45°", bias(a), bias(b)),
    ];
    for (name, x, y) in pairs {
        assert!(close(y, x, tolerance), "{what}: {name} {x} became {y}");
    }
    for kappa in sample_curvatures().into_iter().skip(1).filter(|&k| k <= held_from) {
        let m = |f: &Fabric| f.bending_curve.as_ref().map_or(f.bending_warp * kappa, |c: &PiecewiseLinear| c.value(kappa));
        assert!(close(m(b), m(a), tolerance), "{what}: warp moment at {kappa}/m {} became {}", m(a), m(b));
    }
}

/// The curvature up to which the warp's moments are shared: all of them, unless ARCSim's
/// warp moment falls, where the import holds it rising, which no samples interpolated
/// linearly in ke reproduce; then up to the last sample before the fall
/// (docs/fabric-sheets.md).
fn shared_curvature(m: &ArcsimMaterial) -> f64 {
    let step = model::CURVATURE_STEP;
    warp_bending_curve(m).and_then(|(_, held)| held).map_or(f64::INFINITY, |h| step * (h.0 / step).floor())
}

fn bias(f: &Fabric) -> f64 {
    BendingStiffness::new(f).unwrap().rigidity_at(std::f64::consts::FRAC_PI_4)
}

/// ARCSim → Rosette → ARCSim → Rosette for the ten materials: the second import is the first
/// on every shared value, and exporting it again writes the same file to rounding.
#[test]
fn every_material_survives_the_round_trip_through_both_formats() {
    for stem in FILES {
        let original = material(stem);
        let held_from = shared_curvature(&original);
        let first = fabric(&import(&original));
        let exported = written(&export(&first).unwrap());
        let second = fabric(&import(&exported));
        same_shared_values(&first, &second, held_from, stem);
        same_material(&exported, &written(&export(&second).unwrap()), held_from, stem);
        // What the file and the export share: the mass, the zero-strain row where Rosette can
        // hold it (c12 ≥ 0, ν below 0.49), the first bending samples, and ARCSim's own pull at
        // the strain sample along u and v.
        assert!(close(exported.density, original.density, 1e-9), "{stem}");
        let nu = original.stretching[0][1] / original.stretching[0][2];
        if original.stretching[0][1] >= 0.0 && nu <= MAX_POISSON {
            for k in 0..4 {
                assert!(close(exported.stretching[0][k], original.stretching[0][k], 1e-8), "{stem}: stretching[0][{k}]");
            }
        }
        for row in 0..3 {
            assert!(close(exported.bending[row][0], original.bending[row][0], 1e-9), "{stem}: bending[{row}][0]");
        }
        for angle in [0.0, std::f64::consts::FRAC_PI_2] {
            let (a, b) = (model::uniaxial(&original, angle, STRAIN_SAMPLE), model::uniaxial(&exported, angle, STRAIN_SAMPLE));
            assert!(close(b, a, 1e-3), "{stem}: pull at {angle} rad: {a} vs {b}");
        }
    }
}

/// Rosette → ARCSim → Rosette for every bundled fabric: each shared value comes back, and a
/// second export writes the same file.
#[test]
fn every_bundled_fabric_survives_the_round_trip_through_both_formats() {
    for b in rosette::settings::FABRICS {
        let f = fabric(&load_fabric(b.name).unwrap());
        let exported = written(&export(&f).unwrap());
        let back = fabric(&import(&exported));
        let held_from = shared_curvature(&exported);
        same_shared_values(&f, &back, held_from, b.name);
        same_material(&exported, &written(&export(&back).unwrap()), held_from, b.name);
    }
}

/// The knits import as examples, each marked outside a woven model's scope; the wovens
/// import without that mark.
#[test]
fn knits_are_marked_outside_the_woven_model_and_wovens_are_not() {
    for stem in FILES {
        let loaded = load_fabric(&file(stem)).unwrap();
        let marked = loaded.warnings.iter().any(|w| w.contains("outside the scope of Rosette's woven model"));
        assert_eq!(marked, !WOVENS.contains(&stem), "{stem}: {:?}", loaded.warnings);
    }
}

// ---- The command line: import, export, bad files. ----

fn rosette_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).output().expect("the rosette binary runs")
}

fn temp(name: &str, contents: &str) -> std::path::PathBuf {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("arcsim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    path
}

#[test]
fn export_writes_a_material_that_imports_back() {
    let out_path = temp("wool.json", "");
    let out = rosette_cli(&["fabric", "export", "--arcsim", "wool", "--out", out_path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&out_path).unwrap();
    assert!(text.starts_with("// ARCSim material of"), "{text}");
    let out = rosette_cli(&["fabric", "import", out_path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("bending_warp = "));
    // Without --arcsim there is no format to write; the input is not an output.
    let out = rosette_cli(&["fabric", "export", "wool"]);
    assert_eq!(out.status.code(), Some(2));
    let out = rosette_cli(&["fabric", "export", "--arcsim", out_path.to_str().unwrap(), "--out", out_path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("this command reads"), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn bad_material_files_exit_2_naming_the_field() {
    let denim = std::fs::read_to_string(file("11oz-black-denim")).unwrap();
    let cases = [
        ("short-row.json", denim.replace("[225.767487, 40.917892, 1051.55712, 71.810631]", "[225.767487, 40.917892]"), "stretching[5]"),
        ("kg-m3.json", denim.replace("0.324", "1500"), "density"),
        ("negative.json", denim.replace("96.951576e-6", "-96.951576e-6"), "bending[2][0]"),
        ("huge.json", denim.replace("205.352005", "1e400"), "not valid JSON"),
        ("text.json", denim.replace("53.387184", "\"53\""), "stretching[0][3]"),
        ("rows.json", denim.replace("\"bending\": [", "\"bending\": [[1e-5, 1e-5, 1e-5, 1e-5, 1e-5],"), "has 4 rows"),
    ];
    for (name, text, field) in cases {
        let path = temp(name, &text);
        let out = rosette_cli(&["fabric", "import", path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(stderr.contains(field), "{name}: {stderr}");
    }
    // The import's output never overwrites the material it reads.
    let material_copy = temp("copy.json", &denim);
    let out = rosette_cli(&["fabric", "import", material_copy.to_str().unwrap(), "--out", material_copy.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&material_copy).unwrap(), denim);
    // Only regular files of a material's size are read.
    let dir = temp("a-folder.json", "");
    std::fs::remove_file(&dir).unwrap();
    std::fs::create_dir_all(&dir).unwrap();
    let out = rosette_cli(&["fabric", "import", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is a folder"), "{}", String::from_utf8_lossy(&out.stderr));
    let big = temp("big.json", &" ".repeat(2 << 20));
    let out = rosette_cli(&["fabric", "import", big.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("MB, more than"), "{}", String::from_utf8_lossy(&out.stderr));
    // A fabric file's section: a typo, and a file combined with inline samples.
    let path = temp("section.toml", "[arcsim]\ndata = \"x.json\"\ndensity = 0.2");
    let out = rosette_cli(&["fabric", "import", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("arcsim.data"));
    let path = temp("typo.toml", "[arcsim]\nbendng = 1");
    let out = rosette_cli(&["fabric", "import", path.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("arcsim.bendng"), "{}", String::from_utf8_lossy(&out.stderr));
}

/// A fabric file's `[arcsim]` section names the material file or holds it inline, with
/// ARCSim's configuration multipliers: `thicken` multiplies the mass, stretching and bending
/// alike (conf.cpp), the others one each.
#[test]
fn a_fabric_file_names_its_material_or_holds_it_inline_with_the_multipliers() {
    let by_file = parse_fabric(&format!("thickness = 5e-4\n[arcsim]\ndata = \"{}\"", file("royal-target")), "by-file").unwrap();
    let inline = import(&material("royal-target"));
    assert_eq!(by_file.config.properties.tensile_warp, inline.config.properties.tensile_warp);
    assert_eq!(by_file.config.properties.bending_warp, inline.config.properties.bending_warp);
    let scaled = parse_fabric(&format!("thickness = 5e-4\n[arcsim]\ndata = \"{}\"\nthicken = 2\nbending_mult = 1.5", file("royal-target")), "scaled").unwrap();
    let (a, b) = (&inline.config.properties, &scaled.config.properties);
    assert!(close(b.areal_density, 2.0 * a.areal_density, 1e-15));
    assert!(close(b.bending_warp, 3.0 * a.bending_warp, 1e-15));
    assert!(close(b.tensile_warp[1][1] / b.tensile_warp[1][0], 2.0 * a.tensile_warp[1][1] / a.tensile_warp[1][0], 1e-12));
    assert!(close(b.shear_modulus, 2.0 * a.shear_modulus, 1e-15));
    let err = parse_fabric("[arcsim]\ndata = \"no-such-material.json\"", "missing").unwrap_err().to_string();
    assert!(err.contains("no-such-material.json"), "{err}");
    let err = parse_fabric(&format!("[arcsim]\ndata = \"{}\"\nthicken = -1", file("royal-target")), "negative").unwrap_err().to_string();
    assert!(err.contains("arcsim.thicken"), "{err}");
    let err = parse_fabric(&format!("[kes]\nW = 13\n[arcsim]\ndata = \"{}\"", file("royal-target")), "both").unwrap_err().to_string();
    assert!(err.contains("[arcsim] and [kes]"), "{err}");
}
