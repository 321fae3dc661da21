//! Patterns from pattern CAD: DXF in the AAMA / ASTM D6673 convention, in and out
//! (docs/garments.md, "Patterns from pattern CAD").
//!
//! The files read are exports by two tools that are not Rosette: Valentina 0.7.52 (ASTM and
//! AAMA, R12) and ezdxf 1.4's Gerber AccuMark exporter (ASTM R12, inches), all of one A-line
//! skirt drafted for Rosette (`assets/patterns/src/`). The facts asserted are the draft's:
//! its points (cm, Valentina's y axis down) FWL (15, 0), FWR (53, 0), FHR (59.5, 20),
//! FHemR (68, 60), FHemL (0, 60), FHL (8.5, 20) for the front; BCW (80, 0.5), BSW (99, 0),
//! BSH (105.5, 20), BSHem (114, 60), BCHem (80, 61), BCN (80, 18) for the back half; a
//! 1 cm seam allowance; grain lines up and down; the back cut twice; notches at the hips
//! and at the centre back's zip point. The front's two sides and the back's side are one
//! curve moved or mirrored, so every side seam's sides are equal.

use rosette::garment::dxf::import::{ImportOptions, import};
use rosette::garment::dxf::seams::{SeamsFile, parse as parse_seams};
use rosette::garment::dxf::write::{WriteOptions, write};
use rosette::garment::dxf::{DxfPattern, LengthUnit, Piece, ReadOptions, read};
use rosette::garment::stretch::Outline;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/patterns").join(name)
}

fn read_asset(name: &str, options: &ReadOptions) -> DxfPattern {
    let bytes = std::fs::read(asset(name)).unwrap();
    read(&bytes, name, options).unwrap_or_else(|e| panic!("{e}"))
}

fn piece<'a>(pattern: &'a DxfPattern, name: &str) -> &'a Piece {
    pattern.pieces.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no piece {name}"))
}

/// Width and height of an outline's bounding box, mm.
fn extent(points: &[glam::DVec2]) -> glam::DVec2 {
    let (lo, hi) = points.iter().fold((glam::DVec2::INFINITY, glam::DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    hi - lo
}

/// The point `at` (mm) along a closed outline from its first point.
fn point_at(points: &[glam::DVec2], at: f64) -> glam::DVec2 {
    let mut left = at;
    for i in 0..points.len() {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        let l = a.distance(b);
        if left <= l {
            return a.lerp(b, left / l.max(1e-12));
        }
        left -= l;
    }
    points[0]
}

fn perimeter(points: &[glam::DVec2]) -> f64 {
    (0..points.len()).map(|i| points[i].distance(points[(i + 1) % points.len()])).sum()
}

fn seams_file() -> (SeamsFile, String) {
    let path = asset("aline-skirt.seams.toml");
    let source = path.display().to_string();
    (parse_seams(&std::fs::read_to_string(&path).unwrap(), &source).unwrap(), source)
}

fn rosette(args: &[&str]) -> (Option<i32>, String, String, Duration) {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned(), start.elapsed())
}

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// Valentina's ASTM export (R12: sew line on layer 14, notches as POINTs with their depth in
/// z) reads as the skirt drafted: the sew lines' extents are the draft's points, the seam
/// allowance its 1 cm, the grain up and down, the back cut twice, a notch at each hip and
/// the centre back's 43 cm above the hem, in millimetres from `Units: METRIC`.
#[test]
fn valentina_astm_export_reads_as_the_drafted_skirt() {
    let pattern = read_asset("aline-skirt.dxf", &ReadOptions::default());
    assert_eq!(pattern.units, LengthUnit::Mm);
    assert_eq!(pattern.style.as_deref(), Some("RosetteAlineSkirt"));
    assert_eq!(pattern.pieces.len(), 2);
    let (front, back) = (piece(&pattern, "Front"), piece(&pattern, "Back"));
    assert_eq!((front.quantity, back.quantity), (1, 2));
    assert_eq!(front.size.as_deref(), Some("UK 14"));
    for p in [front, back] {
        assert!(p.sew_line && p.grain_given);
        assert!((p.grain_deg - 90.0).abs() < 1e-6, "{}: {}", p.name, p.grain_deg);
        let [lo, mean, hi] = p.seam_allowance.unwrap();
        // Valentina's allowance is 10 mm; the cut line's curves are flattened apart from
        // the sew line's, so a sew line point lies up to their chords' sag (a few tenths of
        // a millimetre) nearer, and at a corner the cut line is cut off square, further.
        assert!(lo > 9.5 && (mean - 10.0).abs() < 0.2 && hi < 15.0, "{}: {lo} {mean} {hi}", p.name);
        assert_eq!(p.notches.len(), 2, "{}", p.name);
    }
    // Front: x from FHemL (0) to FHemR (68 cm); back: BCW (80) to BSHem (114).
    assert!((extent(&front.outline).x - 680.0).abs() < 0.01, "{}", extent(&front.outline));
    assert!((extent(&back.outline).x - 340.0).abs() < 0.01, "{}", extent(&back.outline));
    // The centre back notch, BCN, lies on the straight centre back (x = 80 cm, the back's
    // leftmost), 43 cm above its hem corner BCHem.
    let x_min = back.outline.iter().map(|q| q.x).fold(f64::INFINITY, f64::min);
    let hem_corner = back.outline.iter().filter(|q| (q.x - x_min).abs() < 1e-6).map(|q| q.y).fold(f64::INFINITY, f64::min);
    let on_centre_back: Vec<glam::DVec2> = back.notches.iter().map(|n| point_at(&back.outline, n.at)).filter(|q| (q.x - x_min).abs() < 0.01).collect();
    assert_eq!(on_centre_back.len(), 1, "{:?}", back.notches);
    assert!((on_centre_back[0].y - hem_corner - 430.0).abs() < 0.05, "the centre back notch is {} mm above the hem", on_centre_back[0].y - hem_corner);
}

/// The same skirt exported by Valentina as AAMA (the sew line on layer 8, notches as short
/// LINEs) and by ezdxf's Gerber exporter (inches, `Units: ENGLISH`, net pieces with no sew
/// line) reads to the same outlines and notches as the ASTM export, to the curves' sampling.
#[test]
fn aama_and_gerber_exports_agree_with_the_astm_one() {
    let astm = read_asset("aline-skirt.dxf", &ReadOptions::default());
    let aama = read_asset("aline-skirt-aama.dxf", &ReadOptions::default());
    let gerber = read_asset("aline-skirt-gerber.dxf", &ReadOptions::default());
    assert_eq!(gerber.units, LengthUnit::In);
    for name in ["Front", "Back"] {
        let reference = piece(&astm, name);
        for (tool, other, sampling) in [("AAMA", piece(&aama, name), 0.01), ("Gerber", piece(&gerber, name), 0.5)] {
            assert_eq!(other.quantity, reference.quantity, "{tool} {name}");
            assert!((other.grain_deg - 90.0).abs() < 1e-6, "{tool} {name}: grain {}", other.grain_deg);
            let (a, b) = (extent(&other.outline), extent(&reference.outline));
            assert!((a - b).abs().max_element() < sampling, "{tool} {name}: {a} against {b}");
            // Curves sampled by another tool are shorter by their chords' sag, no more.
            let (pa, pb) = (perimeter(&other.outline), perimeter(&reference.outline));
            assert!((pa - pb).abs() < 2.0 * sampling + 0.5, "{tool} {name}: perimeter {pa} against {pb}");
            assert_eq!(other.notches.len(), reference.notches.len(), "{tool} {name}");
        }
        assert!(piece(&aama, name).sew_line && !piece(&gerber, name).sew_line);
    }
}

/// The seams file sews the skirt notch to notch: each side seam in two parts that meet at
/// the hip notches, the centre back whole; the sides of every seam were drafted equal, and
/// the garment's side lengths agree to the import's rounding (a micrometre).
#[test]
fn the_seams_file_sews_the_skirt_notch_to_notch() {
    let bytes = std::fs::read(asset("aline-skirt.dxf")).unwrap();
    let (file, source) = seams_file();
    let imported = import(&bytes, "aline-skirt.dxf", &ImportOptions::default(), Some((&file, &source))).unwrap();
    let garment = &imported.garment;
    let names: Vec<&str> = garment.panels.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["back-right", "back-left", "front"]);
    assert_eq!(garment.seams.len(), 5);
    let outlines: Vec<Outline> = garment.panels.iter().map(|p| Outline::new(p).unwrap()).collect();
    let length = |key: &str, span: Option<[f64; 2]>| {
        let (panel, edge) = key.split_once('.').unwrap();
        let p = garment.panels.iter().position(|x| x.name == panel).unwrap();
        let e = outlines[p].edges.iter().find(|x| x.0 == edge).unwrap();
        span.map_or(e.2, |[a, b]| b - a)
    };
    for s in &garment.seams {
        let (a, b) = (length(&s.a, s.a_span), length(&s.b, s.b_span));
        assert!((a - b).abs() < 1e-3, "{s:?}: {a} cm against {b} cm");
    }
    // The centre back: BCHem (80, 61) to BCW (80, 0.5), 60.5 cm.
    let centre_back = garment.seams.iter().find(|s| s.a.starts_with("back-right") && s.b.starts_with("back-left")).unwrap();
    assert!((length(&centre_back.a, centre_back.a_span) - 60.5).abs() < 1e-3);
    // Each side seam's parts meet at the hip notch of both pieces.
    for (panel, notch) in [("front", "n1"), ("back-left", "n1")] {
        let p = garment.panels.iter().find(|x| x.name == panel).unwrap();
        let n = p.notches.iter().find(|x| x.name == notch).unwrap();
        let key = format!("{panel}.{}", n.edge);
        let ends: Vec<f64> = garment.seams.iter().flat_map(|s| [(&s.a, s.a_span), (&s.b, s.b_span)]).filter(|(k, _)| **k == key).flat_map(|(_, span)| span.unwrap()).collect();
        assert!(ends.iter().filter(|&&x| (x - n.at).abs() < 1e-3).count() == 2, "{panel} {notch} at {}: {ends:?}", n.at);
    }
    // The hem is the three bottom edges, none sewn.
    assert_eq!(garment.hem.len(), 3, "{:?}", garment.hem);
    // Placement: the front faces the front (270°), the back halves the back (90°), the
    // drawn one on the wearer's right (towards 180°).
    let angle = |name: &str| garment.panels.iter().find(|p| p.name == name).unwrap().placement.angle_deg;
    assert!((angle("front") - 270.0).abs() < 1.0);
    assert!(angle("back-right") > 90.0 && angle("back-right") < 180.0 && angle("back-left") > 0.0 && angle("back-left") < 90.0);
}

/// Suggestions pair the centre back and the two side seams (equal lengths, matching
/// notches), not the waist halves, and are only printed: an import without a seams file
/// sews nothing.
#[test]
fn suggested_seams_are_printed_never_applied() {
    let pattern = asset("aline-skirt-aama.dxf");
    let (code, out, err, _) = rosette(&["pattern", "seams", pattern.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let file = parse_seams(&out, "suggested").unwrap();
    assert_eq!(file.seams.len(), 3, "{out}");
    let mut pairs: Vec<[String; 2]> = file.seams.iter().map(|s| [s.a.piece.clone(), s.b.piece.clone()]).collect();
    for pair in &mut pairs {
        pair.sort();
    }
    pairs.sort();
    assert_eq!(pairs, [["back-left", "back-right"], ["back-left", "front"], ["back-right", "front"]].map(|p| p.map(String::from)));
    let bytes = std::fs::read(&pattern).unwrap();
    let imported = import(&bytes, "aline-skirt-aama.dxf", &ImportOptions::default(), None).unwrap();
    assert!(imported.garment.seams.is_empty());
    assert!(imported.notes.iter().any(|n| n.contains("not sewn")), "{:?}", imported.notes);
}

/// Export then import: the sew lines come back to a hundredth of a millimetre, the grain
/// and the notches where they were, the cut line 1 cm out; a recut on the bias goes out as
/// a grain line at 45°.
#[test]
fn export_round_trip_keeps_outline_grain_notches_and_allowance() {
    let bytes = std::fs::read(asset("aline-skirt.dxf")).unwrap();
    let mut garment = import(&bytes, "aline-skirt.dxf", &ImportOptions::default(), None).unwrap().garment;
    garment.panels[2].grain_deg = 45.0;
    for units in [LengthUnit::Mm, LengthUnit::In] {
        let text = write(&garment, &WriteOptions { units, style: "round trip".into(), aama_notches: false }).unwrap();
        let again = read(text.as_bytes(), "round-trip.dxf", &ReadOptions::default()).unwrap();
        assert_eq!(again.units, units);
        assert_eq!(again.pieces.len(), garment.panels.len());
        for (panel, p) in garment.panels.iter().zip(&again.pieces) {
            assert_eq!(p.name, panel.name);
            // Coordinates are written to a micrometre (a millionth of an inch): the grain
            // line's direction to a ten-thousandth of a degree.
            assert!((p.grain_deg - panel.grain_deg).abs() < 1e-4, "{}: {} against {}", p.name, p.grain_deg, panel.grain_deg);
            let [lo, _, _] = p.seam_allowance.unwrap();
            assert!((lo - 10.0 * panel.seam_allowance.unwrap()).abs() < 0.01, "{}: {lo}", p.name);
            let before = Outline::new(panel).unwrap();
            assert!((perimeter(&p.outline) - 10.0 * before.perimeter).abs() < 0.05, "{}", p.name);
            let notches_before: Vec<f64> = before.point_names(panel).into_iter().filter(|(n, _)| n.starts_with('n')).map(|(_, at)| 10.0 * at).collect();
            assert_eq!(p.notches.len(), notches_before.len(), "{}", p.name);
            for (n, at) in p.notches.iter().zip(&notches_before) {
                assert!((n.at - at).abs() < 0.05, "{}: notch at {} mm, was {at}", p.name, n.at);
            }
        }
    }
}

/// Our export read by the `dxf` crate, a reader written to the DXF reference, not ours:
/// version R12, one block per panel inserted once, each with a closed cut line on layer 1
/// and sew line on 14, a grain LINE on 7, notches as POINTs on 4 with a depth in z, a
/// `Piece Name:` text; `Units: METRIC` in the entities.
#[test]
fn our_export_reads_in_the_dxf_crate_as_the_convention_says() {
    use dxf::entities::EntityType;
    let bytes = std::fs::read(asset("aline-skirt.dxf")).unwrap();
    let garment = import(&bytes, "aline-skirt.dxf", &ImportOptions::default(), None).unwrap().garment;
    let text = write(&garment, &WriteOptions { units: LengthUnit::Mm, style: "skirt".into(), aama_notches: false }).unwrap();
    assert!(text.is_ascii());
    let drawing = dxf::Drawing::load(&mut text.as_bytes()).unwrap();
    assert_eq!(drawing.header.version, dxf::enums::AcadVersion::R12);
    let blocks: Vec<&dxf::Block> = drawing.blocks().collect();
    assert_eq!(blocks.len(), 3);
    let inserts: Vec<String> = drawing.entities().filter_map(|e| if let EntityType::Insert(i) = &e.specific { Some(i.name.clone()) } else { None }).collect();
    assert_eq!(inserts, ["BACK-RIGHT", "BACK-LEFT", "FRONT"]);
    for block in blocks {
        fn on<'a>(block: &'a dxf::Block, layer: &'a str) -> impl Iterator<Item = &'a dxf::entities::Entity> + 'a {
            block.entities.iter().filter(move |e| e.common.layer == layer)
        }
        let on = |layer: &'static str| on(block, layer);
        let closed: Vec<bool> = on("1").chain(on("14")).filter_map(|e| if let EntityType::Polyline(p) = &e.specific { Some(p.is_closed()) } else { None }).collect();
        assert_eq!(closed, [true, true], "{}", block.name);
        assert_eq!(on("7").filter(|e| matches!(e.specific, EntityType::Line(_))).count(), 1, "{}", block.name);
        let notches: Vec<f64> = on("4").filter_map(|e| if let EntityType::ModelPoint(p) = &e.specific { Some(p.location.z) } else { None }).collect();
        assert_eq!(notches, [5.0, 5.0], "{}", block.name);
        assert!(block.entities.iter().any(|e| matches!(&e.specific, EntityType::Text(t) if t.value.starts_with("Piece Name: "))), "{}", block.name);
    }
    assert!(drawing.entities().any(|e| matches!(&e.specific, EntityType::Text(t) if t.value == "Units: METRIC")));
}

/// Our export read by ezdxf (Python), the library behind the Gerber AccuMark exporter, with
/// its auditor: no errors, the blocks and their entities as written. Skipped, saying so,
/// where no Python with ezdxf is found (`ROSETTE_EZDXF_PYTHON`, else `python3`).
#[test]
fn our_export_passes_ezdxf_audit() {
    let python = std::env::var("ROSETTE_EZDXF_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_ezdxf = Command::new(&python).args(["-c", "import ezdxf"]).output().is_ok_and(|o| o.status.success());
    if !has_ezdxf {
        eprintln!("skipped: no ezdxf for {python} (pip install ezdxf; set ROSETTE_EZDXF_PYTHON)");
        return;
    }
    let bytes = std::fs::read(asset("aline-skirt.dxf")).unwrap();
    let garment = import(&bytes, "aline-skirt.dxf", &ImportOptions::default(), None).unwrap().garment;
    for aama in [false, true] {
        let text = write(&garment, &WriteOptions { units: LengthUnit::Mm, style: "skirt".into(), aama_notches: aama }).unwrap();
        let path = tmp(&format!("ezdxf-check-{aama}.dxf"));
        std::fs::write(&path, text).unwrap();
        let script = r#"
import sys, ezdxf
doc = ezdxf.readfile(sys.argv[1])
auditor = doc.audit()
print("errors", len(auditor.errors))
print("version", doc.dxfversion)
for block in doc.blocks:
    if block.name.startswith("*") or block.name.startswith("$"):
        continue
    kinds = sorted(f"{e.dxftype()}@{e.dxf.layer}" for e in block)
    closed = [e.is_closed for e in block if e.dxftype() == "POLYLINE"]
    print("block", block.name, " ".join(kinds), "closed" if all(closed) else "open")
"#;
        let out = Command::new(&python).args(["-c", script, path.to_str().unwrap()]).output().unwrap();
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(said.contains("errors 0") && said.contains("version AC1009"), "{said}");
        let blocks: Vec<&str> = said.lines().filter(|l| l.starts_with("block ")).collect();
        assert_eq!(blocks.len(), 3, "{said}");
        let notch = if aama { "LINE@4" } else { "POINT@4" };
        for b in blocks {
            assert!(b.contains("POLYLINE@1") && b.contains("POLYLINE@14") && b.contains("LINE@7") && b.contains(notch) && b.ends_with("closed"), "{b}");
        }
    }
}

/// A small R12 pattern file: each piece (block name, piece name, its cut line, whether it
/// closes, a grain line) inserted once, `Units: METRIC`.
/// A piece of [`pattern_text`]: block name, piece name, cut line, closed, with a grain line.
type PieceSpec<'a> = (&'a str, &'a str, Vec<[f64; 2]>, bool, bool);

fn pattern_text(pieces: &[PieceSpec], extra_lines: usize) -> String {
    let mut t = String::from("0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n0\nENDSEC\n0\nSECTION\n2\nBLOCKS\n");
    for (block, name, outline, closed, grain) in pieces {
        t += &format!("0\nBLOCK\n8\n1\n2\n{block}\n70\n0\n10\n0\n20\n0\n30\n0\n3\n{block}\n");
        t += &format!("0\nPOLYLINE\n8\n1\n66\n1\n70\n{}\n", u8::from(*closed));
        for p in outline {
            t += &format!("0\nVERTEX\n8\n1\n10\n{}\n20\n{}\n", p[0], p[1]);
        }
        t += "0\nSEQEND\n8\n1\n";
        if *grain {
            t += "0\nLINE\n8\n7\n10\n100\n20\n50\n11\n100\n21\n350\n";
        }
        for k in 0..extra_lines {
            t += &format!("0\nLINE\n8\n8\n10\n{k}\n20\n10\n11\n{k}\n21\n20\n");
        }
        t += &format!("0\nTEXT\n8\n1\n10\n50\n20\n200\n40\n3\n1\nPiece Name: {name}\n0\nENDBLK\n8\n1\n");
    }
    t += "0\nENDSEC\n0\nSECTION\n2\nENTITIES\n";
    for (block, ..) in pieces {
        t += &format!("0\nINSERT\n8\n1\n2\n{block}\n10\n0\n20\n0\n");
    }
    t + "0\nTEXT\n8\n1\n10\n0\n20\n-20\n40\n3\n1\nUnits: METRIC\n0\nENDSEC\n0\nEOF\n"
}

fn rect(w: f64, h: f64) -> Vec<[f64; 2]> {
    vec![[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
}

/// Each bad input is refused with exit 2, within seconds, with a message that names the
/// piece (where there is one) and says what to fix.
#[test]
fn bad_pattern_files_are_refused_naming_the_piece() {
    let open = vec![[0.0, 0.0], [200.0, 0.0], [200.0, 400.0], [0.0, 400.0], [0.0, 30.0]];
    // Name, file bytes, flags, words the refusal must hold.
    type Case<'a> = (&'a str, Vec<u8>, Vec<&'a str>, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        ("binary", [rosette::garment::dxf::BINARY_SENTINEL, &[0u8; 64][..]].concat(), vec![], vec!["binary DXF", "ASCII"]),
        ("unclosed", pattern_text(&[("YOKE", "Yoke", open, false, true)], 0).into_bytes(), vec![], vec!["piece 'Yoke'", "does not close", "30.0 mm"]),
        ("no-grain", pattern_text(&[("CUFF", "Cuff", rect(200.0, 100.0), true, false)], 0).into_bytes(), vec![], vec!["piece 'Cuff'", "no grain line", "--grain-deg"]),
        (
            "duplicate",
            pattern_text(&[("FRONT_A", "Front", rect(300.0, 500.0), true, true), ("FRONT_B", "Front", rect(300.0, 500.0), true, true)], 0).into_bytes(),
            vec![],
            vec!["two pieces are named 'Front'", "FRONT_A", "FRONT_B"],
        ),
        ("many", pattern_text(&[("NEST", "Nest", rect(300.0, 500.0), true, true)], 20_000).into_bytes(), vec![], vec!["piece 'NEST'", "entities", "marker"]),
        // Millimetres read as inches: the 68 cm front becomes 17 m wide.
        ("mm-as-inches", std::fs::read(asset("aline-skirt.dxf")).unwrap(), vec!["--units", "in"], vec!["piece 'Back'", "larger than any pattern piece", "--units"]),
        // Inches read as millimetres: the front becomes 27 mm wide.
        ("inches-as-mm", std::fs::read(asset("aline-skirt-gerber.dxf")).unwrap(), vec!["--units", "mm"], vec!["'Front'", "26.8 mm across", "--units"]),
    ];
    for (name, bytes, flags, expected) in cases {
        let path = tmp(&format!("bad-{name}.dxf"));
        std::fs::write(&path, bytes).unwrap();
        let mut args = vec!["pattern", "import", path.to_str().unwrap()];
        args.extend(flags);
        let (code, _, err, took) = rosette(&args);
        assert_eq!(code, Some(2), "{name}: {err}");
        for e in expected {
            assert!(err.contains(e), "{name}: '{e}' not in: {err}");
        }
        assert!(took < Duration::from_secs(20), "{name} took {took:?}");
        // The same file where a scene goes is refused alike, naming the file.
        if name == "no-grain" {
            let (code, _, err, _) = rosette(&["run", path.to_str().unwrap(), "--max-steps", "1"]);
            assert_eq!(code, Some(2), "{err}");
            assert!(err.contains("bad-no-grain.dxf") && err.contains("piece 'Cuff'"), "{err}");
        }
    }
}

/// `rosette run FILE.dxf` takes the pattern and its seams file beside it as a scene, in any
/// fabric: the skirt is sewn and stays out of its form.
#[test]
fn a_dxf_pattern_runs_as_a_scene_and_sews() {
    use rosette::scene::{RunOptions, Scene, load_scene, run_scene};
    let path = asset("aline-skirt.dxf");
    let (config, _) = load_scene(path.to_str().unwrap(), &["mesh.edge_length=0.05".into(), "scene.duration=1.6".into(), "fabric.preset=\"denim\"".into()]).unwrap();
    assert_eq!(config.garment.as_ref().unwrap().seams.len(), 5);
    let thickness = config.contact.thickness;
    let mut scene = Scene::build(config).unwrap();
    let (metrics, error) = run_scene(&mut scene, "aline-skirt-dxf", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    let m = metrics.measures.garment().expect("garment measures");
    assert!(m.sewn, "{m:?}");
    assert!(m.seam_gap_at_weld.unwrap() <= 0.25 * thickness, "{m:?}");
    assert!(metrics.max_penetration.unwrap() < thickness, "{:?}", metrics.max_penetration);
}

/// `rosette pattern export` writes a scene's panels, here the bundled straight skirt's
/// (drafted in Rosette, no seam allowance), and reading the file back gives its panels'
/// perimeters.
#[test]
fn a_bundled_garment_exports_as_dxf() {
    let out = tmp("skirt-gored-straight.dxf");
    let _ = std::fs::remove_file(&out);
    let (code, _, err, _) = rosette(&["pattern", "export", "skirt-gored-straight", "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let (config, _) = rosette::scene::load_scene("skirt-gored-straight", &[]).unwrap();
    let garment = config.into_config().garment.unwrap();
    let again = read(&std::fs::read(&out).unwrap(), "skirt.dxf", &ReadOptions::default()).unwrap();
    assert_eq!(again.pieces.len(), garment.panels.len());
    let metres_to_mm = 1000.0 * garment.units.metres();
    for (panel, p) in garment.panels.iter().zip(&again.pieces) {
        let before = Outline::new(panel).unwrap().perimeter * metres_to_mm;
        assert!(!p.sew_line);
        // Curved edges are sampled afresh by each side: within a millimetre in a metre.
        assert!((perimeter(&p.outline) - before).abs() < 0.5 + 1e-3 * before, "{}: {} mm against {before}", p.name, perimeter(&p.outline));
    }
    // Rosette's own export is replaced when written again; a DXF it did not write is not
    // overwritten without --force.
    let (code, _, err, _) = rosette(&["pattern", "export", "skirt-gored-straight", "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    let other = tmp("not-an-export.dxf");
    std::fs::write(&other, "0\nEOF\n").unwrap();
    let (code, _, err, _) = rosette(&["pattern", "export", "skirt-gored-straight", "--out", other.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
}

/// Every DXF file at hand, the bundled ones and any in the folder `ROSETTE_DXF_DIR` names
/// (files that are not given here: other tools' exports, other versions), either imports,
/// its export reading back to the same pieces, or is refused with exit 2 and a message,
/// within seconds; never a crash.
#[test]
fn any_dxf_file_imports_or_is_refused_cleanly() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(asset("")).unwrap().map(|e| e.unwrap().path()).collect();
    if let Ok(dir) = std::env::var("ROSETTE_DXF_DIR") {
        files.extend(std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()));
    }
    files.retain(|f| f.extension().is_some_and(|e| e.eq_ignore_ascii_case("dxf")));
    files.sort();
    for file in files {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let out = tmp(&format!("any-{name}.toml"));
        let (code, _, err, took) = rosette(&["pattern", "import", file.to_str().unwrap(), "--grain-deg", "90", "--out", out.to_str().unwrap(), "--force"]);
        assert!(took < Duration::from_secs(30), "{name} took {took:?}");
        match code {
            Some(0) => {
                let dxf = tmp(&format!("any-{name}"));
                let (code, _, err, _) = rosette(&["pattern", "export", out.to_str().unwrap(), "--out", dxf.to_str().unwrap(), "--force"]);
                assert_eq!(code, Some(0), "{name}: {err}");
                let (config, _) = rosette::scene::load_scene(out.to_str().unwrap(), &[]).unwrap();
                let again = read(&std::fs::read(&dxf).unwrap(), &name, &ReadOptions::default()).unwrap();
                assert_eq!(again.pieces.len(), config.garment.as_ref().unwrap().panels.len(), "{name}");
                eprintln!("{name}: imported, exported, read back");
            }
            Some(2) => {
                assert!(err.contains(&name) && err.lines().count() >= 1, "{name}: {err}");
                eprintln!("{name}: refused: {}", err.lines().next().unwrap_or(""));
            }
            other => panic!("{name}: exit {other:?}: {err}"),
        }
    }
}
