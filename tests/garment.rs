//! Garments: patterns refused with the panel and edge named, seams that close and keep
//! their length, a hanging panel that stretches as eq. 1 predicts for the direction it was
//! cut, and a tube sewn from one rectangle that keeps no membrane strain. The references
//! are worked out here, from the fabric file's numbers (docs/garments.md, Tests).

mod common;

use rosette::scene::{RunOptions, Scene, SceneConfig, load_scene, run_scene};
use rosette::settings as preset;

/// Writes `text` as a scene file and loads it.
fn load_text(name: &str, text: &str) -> Result<SceneConfig, String> {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    load_scene(path.to_str().unwrap(), &[]).map(|(c, _)| c.into_config()).map_err(|e| e.to_string())
}

fn bundled(name: &str) -> String {
    preset::SCENES.iter().find(|b| b.name == name).unwrap().text.to_string()
}

/// Initial slope of a tensile curve [[strain, N/m], ...], N/m.
fn initial_slope(curve: &[[f64; 2]]) -> f64 {
    (curve[1][1] - curve[0][1]) / (curve[1][0] - curve[0][0])
}

#[test]
fn bad_patterns_are_refused_naming_the_panel_and_the_edge() {
    let gored = bundled("skirt-gored-straight");
    // The front gore's right side crosses its left side.
    let crossed = gored.replacen("{ name = \"right\", to = [8.8, 55] }", "{ name = \"right\", to = [-30, 55] }", 1);
    let err = load_text("crossed", &crossed).unwrap_err();
    assert!(err.contains("'front'") && err.contains("crosses itself") && err.contains("'right'"), "{err}");
    // A seam between a 56 cm side and a 17.6 cm waist.
    let uneven = gored.replacen("b = \"right.left\"", "b = \"right.waist\"", 1);
    let err = load_text("uneven", &uneven).unwrap_err();
    assert!(err.contains("front.right") && err.contains("right.waist") && err.contains("seam_ease"), "{err}");
    // A seam naming an edge the panel does not have.
    let missing = gored.replacen("b = \"right.left\"", "b = \"right.side\"", 1);
    let err = load_text("missing", &missing).unwrap_err();
    assert!(err.contains("no edge 'side'") && err.contains("hem, right, waist, left"), "{err}");
    // A grain angle that is not a number.
    let nan = gored.replacen("grain_deg = 90", "grain_deg = nan", 1);
    let err = load_text("nan", &nan).unwrap_err();
    assert!(err.contains("'front'") && err.contains("grain_deg"), "{err}");
    // A panel placed inside the form: refused when the scene is built, before any step.
    let inside = gored.replacen("distance = 17", "distance = 5", 1);
    let config = load_text("inside", &inside).unwrap();
    let err = Scene::new(config).err().expect("a panel inside the form is refused").to_string();
    assert!(err.contains("'front'") && err.contains("inside the form"), "{err}");
    // An anchor typed in the wrong units (a panel placed 30 m to the side), and one at
    // infinity: refused naming the panel and the keys to check.
    for anchor in ["3000", "inf"] {
        let far = gored.replacen("anchor = [0, 54.1131]", &format!("anchor = [{anchor}, 54.1131]"), 1);
        assert_ne!(far, gored);
        let err = load_text("far", &far).expect_err("a panel placed far off is refused");
        assert!(err.contains("'front'") && err.contains("anchor") && err.contains("from the form's axis"), "{err}");
    }
    // Each refused naming its key, before any step: a panel below the floor, lengths in cm
    // read as metres, a seam from an edge to itself, a weld 20 cm wide (it once took a
    // step of minutes), and springs that cannot draw the seams shut by the sewing time.
    let cases = [
        ("height = 104 }", "height = -50 }", &["'front'", "positive distance and height"][..]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nunits = \"m\"\n\n[fabric]\npreset = \"wool\"", &["check garment.units", "m across"]),
        ("b = \"right.left\"", "b = \"front.right\"", &["garment.seams[0] sews edge 'right' of panel 'front' to itself"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nunits = \"cm\"\nclosed_share = 100\n\n[fabric]\npreset = \"wool\"", &["garment.closed_share = 100 is more than 1"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nunits = \"cm\"\nsewing_ramp = 2\n\n[fabric]\npreset = \"wool\"", &["garment.sewing_ramp = 2 s is not shorter than garment.sewing_time"]),
    ];
    for (from, to, words) in cases {
        let err = refusal(&gored, from, to);
        assert!(words.iter().all(|w| err.contains(w)), "{to}: {err}");
    }
}

/// The error reading `text` with its first `from` replaced by `to` (which must change it):
/// refused as the file is read, before any scene is built.
fn refusal(text: &str, from: &str, to: &str) -> String {
    let bad = text.replacen(from, to, 1);
    assert_ne!(bad, text, "{from}");
    load_text("bad", &bad).expect_err(to)
}

/// What a pattern file can get wrong beyond the cases above, each refused before any step
/// (as the file is read, or a missing form mesh as the scene is built) with a message that
/// names the key, the panel or the edge, and says what would fix it.
#[test]
fn malformed_outlines_seams_and_forms_are_refused_naming_their_key() {
    let gored = bundled("skirt-gored-straight");
    let outline = "edges = [\n  { name = \"hem\", to = [20, 0], through = [0, -2.0157] },\n  { name = \"right\", to = [8.8, 55] },\n  { name = \"waist\", to = [-8.8, 55], through = [0, 54.1131] },\n  { name = \"left\", to = [-20, 0] },\n]";
    let clockwise = "edges = [\n  { name = \"left\", to = [-8.8, 55] },\n  { name = \"waist\", to = [8.8, 55], through = [0, 54.1131] },\n  { name = \"right\", to = [20, 0] },\n  { name = \"hem\", to = [-20, 0], through = [0, -2.0157] },\n]";
    let hem = "{ name = \"hem\", to = [20, 0], through = [0, -2.0157] }";
    let last = "{ name = \"left\", to = [-20, 0] },\n]";
    let cases: [(&str, &str, &[&str]); 20] = [
        // Outlines.
        (outline, clockwise, &["'front'", "runs clockwise", "counter-clockwise"]),
        (last, "{ name = \"left\", to = [-20, 1] },\n]", &["'front'", "'left' must end at start"]),
        (last, "{ name = \"left\", to = [-20, 0] },\n  { name = \"extra\", to = [-20, 0] },\n]", &["'front'", "edge 'extra' has no length"]),
        (last, "{ name = \"hem\", to = [-20, 0] },\n]", &["'front'", "two edges are named 'hem'"]),
        (hem, "{ name = \"hem\", to = [20, 0], through = [0, -2], controls = [[6, -2], [-6, -2]] }", &["'front'", "edge 'hem'", "keep one"]),
        (hem, "{ name = \"hem\", to = [20, 0], through = [0, 0] }", &["'front'", "edge 'hem'", "lie on a line"]),
        (hem, "{ name = \"hem\", to = [20, 0], controls = [[nan, -20], [-60, -20]] }", &["'front'", "edge 'hem'", "finite coordinates"]),
        (hem, "{ name = \"hem\", to = [20, 0], controls = [[60, -20], [-60, -20]] }", &["'front'", "crosses itself", "'hem'"]),
        // Panels and their placement.
        ("name = \"right\"\ngrain_deg", "name = \"front\"\ngrain_deg", &["two panels are named 'front'"]),
        ("flare_deg = 14.82", "flare_deg = 200", &["'front'", "flare_deg between 0 and 90"]),
        ("around = \"cone\"", "around = \"sphere\"", &["placement.around", "expected `cone` or `plane`"]),
        // Seams, hem and attachments.
        ("direction = \"opposite\"\n", "direction = \"opposite\"\na_span = [0.8, 0.2]\n", &["garment.seams[0].a_span", "increasing stretch"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nunits = \"cm\"\nhem = [\"front.nothem\"]\n\n[fabric]\npreset = \"wool\"", &["garment.hem", "no edge 'nothem'", "hem, right, waist, left"]),
        ("[fabric]\npreset = \"wool\"", "[fabric]\npreset = \"wool\"\n\n[[garment.attachments]]\nedge = \"front.nowaist\"\npin = true", &["garment.attachments[0].edge", "no edge 'nowaist'"]),
        ("[fabric]\npreset = \"wool\"", "[fabric]\npreset = \"wool\"\n\n[[garment.attachments]]\nedge = \"front.waist\"\nlevel = \"knee\"", &["garment.attachments[0].level", "waist, hip or bust"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nunits = \"cm\"\nseam_ease = -0.5\n\n[fabric]\npreset = \"wool\"", &["garment.seam_ease = -0.5", "between 0 and 0.5"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nsewing_time = -1.0\n\n[fabric]\npreset = \"wool\"", &["garment.sewing_time must be a positive number"]),
        ("[fabric]\npreset = \"wool\"", "[garment]\nsewing_tiem = 1.0\n\n[fabric]\npreset = \"wool\"", &["garment.sewing_tiem", "unknown field"]),
        // The form.
        ("size = \"uk-12\"", "size = \"uk-99\"", &["no size 'uk-99'", "uk-10, uk-12, uk-14"]),
        ("size = \"uk-12\"", "size = \"uk-12\"\nobj = \"assets/cushion.obj\"", &["garment.form", "exactly one of size, measurements or obj"]),
    ];
    for (from, to, words) in cases {
        let err = refusal(&gored, from, to);
        assert!(words.iter().all(|w| err.contains(w)), "{to}: {err}");
    }
    // A form mesh that is not there: refused when the scene is built, before any step.
    let config = load_text("no-form", &gored.replacen("size = \"uk-12\"", "obj = \"no/such/body.obj\"", 1)).unwrap();
    let err = Scene::new(config).err().expect("a missing form mesh is refused").to_string();
    assert!(err.contains("garment.form.obj") && err.contains("no such file"), "{err}");
    // A mesh too fine for memory is refused before meshing, with the edge that fits.
    let err = load_scene("skirt-gored-straight", &["mesh.edge_length=0.00005".into()]).expect_err("too fine").to_string();
    assert!(err.contains("mesh.edge_length = 5e-5 m") && err.contains("use at least"), "{err}");
}

/// The gored skirt on a coarse mesh: every seam closes under the sewing springs to a
/// quarter of the contact layer before the sewing time, is welded, and the welded seam's
/// length stays that of both sides' rest lengths (the skirt hangs at small strain).
#[test]
fn seams_close_within_the_contact_layer_and_keep_their_rest_length() {
    let (config, _) = load_scene("skirt-gored-straight", &["mesh.edge_length=0.05".into(), "scene.duration=1.0".into()]).unwrap();
    let thickness = config.contact.thickness;
    let mut scene = Scene::build(config).unwrap();
    let (metrics, error) = run_scene(&mut scene, "skirt-gored-straight", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    let m = metrics.measures.garment().expect("garment measures");
    assert!(m.sewn, "{m:?}");
    assert!(m.sewn_at.unwrap() < 1.0);
    assert!(m.seam_gap_at_weld.unwrap() <= 0.25 * thickness, "{m:?}");
    assert_eq!(m.open_seam_gap, 0.0);
    for [now, a, b] in &m.seams {
        assert!((a - b).abs() < 1e-9, "the gores' sides are equal: {a} {b}");
        // Hanging under its own weight, wool stretches by ρgL/E ≈ 1e-3 along the seam.
        assert!((now / a - 1.0).abs() < 0.01, "seam {now} m against its rest {a} m");
    }
}

/// Eq. 1 of the paper, written out here: the modulus of a strip cut at θ to the warp,
/// 1/E_θ = c⁴/E_x + s⁴/E_y + (1/G − 2ν_xy/E_x) c²s².
fn modulus_at(theta: f64, e_x: f64, e_y: f64, g: f64, nu_xy: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    1.0 / (c.powi(4) / e_x + s.powi(4) / e_y + (1.0 / g - 2.0 * nu_xy / e_x) * c * c * s * s)
}

const HANGING_STRIP: &str = r#"
[scene]
kind = "garment"
description = "A 4 cm x 60 cm panel hung from its top edge"
duration = 4.0
gravity_ramp = 0.5
settle_speed = 1e-5
settle_window = 0.3
[fabric]
preset = "wool"
poisson_warp = 0.0
[mesh]
edge_length = 0.01
[solver]
integrator = "implicit-euler"
dt = 0.01
damping = 20.0
[garment]
units = "cm"
sewing_time = 0.5
[garment.form]
obj = "assets/cushion.obj"
scale = 0.05
[[garment.panels]]
name = "strip"
grain_deg = GRAIN
start = [-2, 0]
edges = [
  { name = "bottom", to = [2, 0] },
  { name = "right", to = [2, 60] },
  { name = "top", to = [-2, 60] },
  { name = "left", to = [-2, 0] },
]
placement = { around = "plane", angle_deg = 0, distance = 50, height = 150 }
[[garment.attachments]]
edge = "strip.top"
pin = true
"#;

/// A panel hung from its top edge carries its own weight below each level, so it
/// stretches by ∫ ρg(L − y)/E_θ dy = ρgL²/(2E_θ), with E_θ the modulus of eq. 1 along the
/// hanging direction: the warp's for a straight cut, E₄₅ for a bias cut (about seven
/// times softer for this wool, whose shear modulus is small).
#[test]
fn a_hanging_panel_stretches_by_its_weight_over_the_modulus_of_its_cut() {
    let (length, g) = (0.6, rosette::physics::STANDARD_GRAVITY);
    let runs: Vec<(f64, f64)> = std::thread::scope(|s| {
        let handles: Vec<_> = [(90.0, 0.0), (45.0, 45f64.to_radians())]
            .into_iter()
            .map(|(grain, theta)| {
                s.spawn(move || {
                    let config = load_text(&format!("hang-{grain}"), &HANGING_STRIP.replace("GRAIN", &grain.to_string())).unwrap();
                    let f = &config.fabric.properties;
                    let e = modulus_at(theta, initial_slope(&f.tensile_warp), initial_slope(&f.tensile_weft), f.shear_modulus, f.poisson_warp);
                    let predicted = f.areal_density * g * length * length / (2.0 * e);
                    let mut scene = Scene::new(config).unwrap();
                    let (metrics, error) = run_scene(&mut scene, "hang", RunOptions::default());
                    assert!(error.is_none() && metrics.settled == Some(true), "{error:?} {metrics:?}");
                    // The top and bottom edges by their place on the pattern.
                    let rest = &scene.model.rest;
                    let top = rest.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
                    let mean_z = |at: f64| {
                        let v: Vec<usize> = (0..rest.len()).filter(|&i| (rest[i].y - at).abs() < 1e-9).collect();
                        v.iter().map(|&i| scene.state.x[i].z).sum::<f64>() / v.len() as f64
                    };
                    let stretch = mean_z(top) - mean_z(0.0) - length;
                    (stretch, predicted)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (cut, (stretch, predicted)) in ["straight", "bias"].iter().zip(&runs) {
        // The pinned top edge cannot narrow or shear: over about a width below it the strip
        // is stiffer than a free one, which the formula ignores. That band (4 cm of 60)
        // carries 2w/L ≈ 13 % of the stretch, so the strip may come out up to about 10 %
        // short of the formula, never long.
        let ratio = stretch / predicted;
        assert!(ratio > 0.88 && ratio < 1.02, "{cut}: stretched {stretch:.3e} m, eq. 1 predicts {predicted:.3e} m");
    }
    assert!(runs[1].0 > 4.0 * runs[0].0, "the bias hangs longer: {runs:?}");
}

/// The weave follows each panel's grain: in the texture space (the weave the viewer and
/// screenshots draw, an export's texture coordinates) every triangle's edges are its edges
/// in its own warp frame, on the straight cut and on the bias, and the panels do not overlap
/// there.
#[test]
fn the_texture_space_runs_the_weave_along_each_panels_grain() {
    for name in ["skirt-gored-straight", "skirt-gored-bias"] {
        let (config, _) = load_scene(name, &["mesh.edge_length=0.04".into()]).unwrap();
        let scene = Scene::build(config).unwrap();
        let (texture, warp) = scene.model.texture_space();
        assert_eq!(warp, 0.0, "{name}: the texture space is in the warp frame");
        let frames = scene.model.frames.as_ref().expect("a garment's triangles have frames");
        for (t, c) in scene.model.triangles.iter().zip(frames) {
            for k in 1..3 {
                let drawn = texture[t[k] as usize] - texture[t[0] as usize];
                assert!((drawn - (c[k] - c[0])).length() < 1e-9, "{name}: triangle {t:?} drawn {drawn} against its warp frame's {}", c[k] - c[0]);
            }
        }
        let area: f64 = scene.model.triangles.iter().map(|t| {
            let [a, b, c] = t.map(|v| texture[v as usize]);
            0.5 * (b - a).perp_dot(c - a)
        }).sum();
        let (lo, hi) = texture.iter().fold((glam::DVec2::INFINITY, glam::DVec2::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        assert!(area > 0.0 && lo.x >= -1e-9 && lo.y >= -1e-9, "{name}: panels laid from the origin, right side up");
        assert!(hi.x > 4.0 * 0.40 * std::f64::consts::FRAC_1_SQRT_2, "{name}: four gores side by side, not stacked: width {}", hi.x);
    }
}

const TUBE: &str = r#"
[scene]
kind = "garment"
description = "A rectangle sewn into a tube"
duration = 3.0
settle_speed = 1e-4
settle_window = 0.2
[fabric]
preset = "wool"
poisson_warp = 0.0
[physics]
gravity = false
[mesh]
edge_length = 0.02
[solver]
integrator = "implicit-euler"
dt = 0.01
damping = 10.0
[garment]
units = "cm"
sewing_time = 1.0
[garment.form]
obj = "assets/cushion.obj"
scale = 0.05
# 2π · 8 cm around, 20 cm tall, the warp around it; placed on a 10 cm cylinder, so the seam starts 12.6 cm open.
[[garment.panels]]
name = "tube"
grain_deg = 0
start = [0, 0]
edges = [
  { name = "bottom", to = [50.26548, 0] },
  { name = "right", to = [50.26548, 20] },
  { name = "top", to = [0, 20] },
  { name = "left", to = [0, 0] },
]
placement = { around = "cone", angle_deg = 0, distance = 10, height = 100 }
[[garment.seams]]
a = "tube.right"
b = "tube.left"
direction = "opposite"
"#;

/// A rectangle sewn edge to edge into a tube is a cylinder without stretch: with gravity
/// off it closes, welds and keeps no membrane strain, seam included (the seam bends as the
/// cloth around it), at the radius its width gives. The warp runs around the tube: cut
/// off the axes, an orthotropic sheet bent into a cylinder also twists (its bending
/// stiffness couples the two), and a closed tube can only twist by shearing.
#[test]
fn a_tube_sewn_from_one_rectangle_keeps_no_membrane_strain() {
    let config = load_text("tube", TUBE).unwrap();
    let mut scene = Scene::new(config).unwrap();
    let (metrics, error) = run_scene(&mut scene, "tube", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    assert!(metrics.measures.garment().unwrap().sewn);
    let strains = scene.model.triangle_strains(&scene.state.x);
    let worst = strains.iter().flatten().fold(0.0f64, |m, e| m.max(e.abs()));
    // The exact reference is zero; the bound is the one set before the first run. Measured
    // (2 cm mesh, 3 s): 1.5e-3, the tube still creeping slowly (docs/garments.md, open
    // questions). A seam welded folded (sides that overshot each other while sewing)
    // showed 4.8e-3; a seam welded without the panels' rest shapes would strain the tube by
    // the 25 % it was placed open by.
    assert!(worst < 2e-3, "largest membrane strain {worst:.2e}");
    // The tube's radius about its own axis (the mean of its vertices, which stays
    // vertical by symmetry): a 25-gon of the rectangle's 50.27 cm.
    let x = &scene.state.x;
    let centre = x.iter().copied().sum::<glam::DVec3>() / x.len() as f64;
    let radii: Vec<f64> = x.iter().map(|p| (*p - centre).truncate().length()).collect();
    let mean = radii.iter().sum::<f64>() / radii.len() as f64;
    assert!((mean / 0.08 - 1.0).abs() < 0.01, "mean radius {mean}");
    let spread = radii.iter().map(|r| (r - mean).abs()).fold(0.0, f64::max);
    assert!(spread < 0.05 * mean, "radius varies by {spread} about {mean}");
}

/// The bundled garments load, and each builds (meshes, places, welds its pattern).
#[test]
fn every_bundled_garment_builds() {
    for name in ["skirt-circle", "skirt-gored-straight", "skirt-gored-bias", "shift-dress"] {
        let (config, _) = load_scene(name, &["mesh.edge_length=0.04".into()]).unwrap_or_else(|e| panic!("{name}: {e}"));
        let scene = Scene::build(config).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(scene.garment.is_some() && scene.model.triangle_count() > 100, "{name}");
    }
}

/// The tension per unit width down a gore hanging from its waist, integrated over its
/// length: ∫₀ᴸ (∫ₛᴸ w(u) du / w(s)) ds for a width growing linearly from `waist` to `hem`
/// (m) over `length` (m), by the midpoint rule; the stretch is ρg/E times this.
fn gore_load_integral(waist: f64, hem: f64, length: f64, from: f64) -> f64 {
    let n = 2000;
    let width = |s: f64| waist + (hem - waist) * s / length;
    let below = |s: f64| (width(s) + hem) / 2.0 * (length - s);
    let ds = (length - from) / n as f64;
    (0..n).map(|i| from + (i as f64 + 0.5) * ds).map(|s| below(s) / width(s) * ds).sum()
}

/// The gored skirt cut on the bias stretches down its gores more than the straight cut by
/// what the bias's E₄₅ (eq. 1) predicts, where the gores hang free: below the hip line the
/// skirt touches nothing, and each gore's centre line carries the weight of the cloth below
/// it, ρg ∫ w / w per unit width, so it lengthens by ρg I / E_θ with I the integral above
/// (`gore_load_integral`) from the hip line down. Above it the skirt rests on the hips,
/// whose contact carries its weight and stretches it around: no hanging-sheet formula
/// holds there, and the hem's height (the bias about 4.5 mm lower) is set mostly by how far
/// each cut flares out from the hips, not by stretch (docs/garments.md).
///
/// Measured on the preset's 2 cm mesh: the bias gores' free part 0.657 mm longer than at
/// rest (ρgI/E₄₅: 0.672 mm), the straight ones 0.143 mm (ρgI/E₀: 0.099 mm), a difference of
/// 0.514 mm against 0.573 mm; 0.514 mm again on 1.41 cm edges; on 4 cm edges (four to ten
/// elements across a gore) 0.890 mm. The straight cut's own stretch, a seventh of the
/// bias's, is not held to its prediction (it comes out 0.04–0.09 mm longer: the hips' pull
/// reaches below the hip line, and at a tenth of a millimetre the folds' paths count); the
/// bias's free part is held to 15 % of its prediction and the difference between the cuts
/// to 20 %.
#[test]
fn the_bias_cut_gores_stretch_by_what_e45_predicts() {
    let (length, hip) = (0.5613, 0.206);
    // Each gore's free part on the flat pattern: gores 40 cm wide laid 5 cm apart, the
    // hem's lowest point at y = 0 and the waist's at 56.13 cm.
    let free = length - hip;
    let runs: Vec<(f64, f64)> = std::thread::scope(|s| {
        let handles: Vec<_> = ["skirt-gored-straight", "skirt-gored-bias"]
            .into_iter()
            .map(|name| {
                s.spawn(move || {
                    let (config, _) = load_scene(name, &[]).unwrap();
                    let mut scene = Scene::build(config).unwrap();
                    let (metrics, error) = run_scene(&mut scene, name, RunOptions::default());
                    let garment = metrics.measures.garment().unwrap();
                    assert!(error.is_none() && garment.sewn && metrics.settled == Some(true), "{name}: {error:?}");
                    // Triangles at a welded seam have one corner drawn on the other panel's
                    // place on the flat pattern: only those whose drawn shape is their rest
                    // shape are searched (the centre lines lie far from the seams).
                    let corners = scene.model.frames.as_ref().expect("a garment's triangles have frames");
                    let rest = &scene.model.rest;
                    let drawn = |t: &[u32; 3], c: &[glam::DVec2; 3]| (0..3).all(|k| {
                        let (a, b) = (k, (k + 1) % 3);
                        (rest[t[a] as usize].distance(rest[t[b] as usize]) - c[a].distance(c[b])).abs() < 1e-9
                    });
                    let triangles = scene.model.triangles.iter().zip(corners).filter(|(t, c)| drawn(t, c)).map(|(t, _)| *t).collect();
                    let flat = rosette::sim::Mesh { rest: rest.clone(), triangles };
                    // Sampled finely enough that every triangle the line crosses holds a
                    // sample: the path is then the material line's own length.
                    let stretch: f64 = (0..4)
                        .map(|k| {
                            let x = k as f64 * 0.45 + 0.20;
                            let points: Vec<glam::DVec2> = (0..=400).map(|i| glam::DVec2::new(x, free * i as f64 / 400.0)).collect();
                            let along: Vec<glam::DVec3> = flat.embed(&points).iter().map(|e| e.position(&scene.state.x)).collect();
                            along.windows(2).map(|w| w[0].distance(w[1])).sum::<f64>() - free
                        })
                        .sum::<f64>()
                        / 4.0;
                    (stretch, garment.hem_height_mean)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let (config, _) = load_scene("skirt-gored-bias", &[]).unwrap();
    let f = &config.fabric.properties;
    let modulus = |deg: f64| modulus_at(deg.to_radians(), initial_slope(&f.tensile_warp), initial_slope(&f.tensile_weft), f.shear_modulus, f.poisson_warp);
    let (e0, e45) = (modulus(0.0), modulus(45.0));
    let load = f.areal_density * rosette::physics::STANDARD_GRAVITY * gore_load_integral(0.176, 0.40, length, hip);
    let (straight, bias) = (load / e0, load / e45);
    let difference = bias - straight;
    eprintln!(
        "free parts stretched {:.3} mm (straight, eq. 1: {:.3}) and {:.3} mm (bias, eq. 1: {:.3}); hems at {:.4} m and {:.4} m",
        1e3 * runs[0].0, 1e3 * straight, 1e3 * runs[1].0, 1e3 * bias, runs[0].1, runs[1].1
    );
    assert!((runs[1].0 / bias - 1.0).abs() < 0.15, "the bias gores stretched {:.3} mm, eq. 1 predicts {:.3} mm", 1e3 * runs[1].0, 1e3 * bias);
    let measured = runs[1].0 - runs[0].0;
    assert!((measured / difference - 1.0).abs() < 0.2, "bias stretched {:.3} mm more, eq. 1 predicts {:.3} mm", 1e3 * measured, 1e3 * difference);
}

/// A pattern in GarmentCode's specification format (`assets/patterns/aline-skirt_specification.json`,
/// drafted for Rosette's tests: an A-line skirt of two panels, a waist dart in each, the back
/// panel written clockwise as GarmentCode writes back panels) is imported by `rosette pattern
/// import` and sews: every seam and dart closes within a quarter of the contact layer, both
/// sides of each were drafted equal, and the skirt stays out of its form and itself.
#[test]
fn an_imported_garmentcode_pattern_sews_and_stays_clean() {
    let spec = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/patterns/aline-skirt_specification.json");
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("aline-skirt-import.toml");
    let run = |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_rosette")).args(args).output().unwrap();
    let imported = run(&["pattern", "import", spec, "--out", out.to_str().unwrap()]);
    assert!(imported.status.success(), "{}", String::from_utf8_lossy(&imported.stderr));
    let (config, _) = load_scene(out.to_str().unwrap(), &["mesh.edge_length=0.05".into(), "scene.duration=1.6".into()]).unwrap();
    let thickness = config.contact.thickness;
    let mut scene = Scene::build(config).unwrap();
    let (metrics, error) = run_scene(&mut scene, "aline-skirt-import", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    assert!(metrics.converged);
    let m = metrics.measures.garment().expect("garment measures");
    assert!(m.sewn, "{m:?}");
    assert!(m.seam_gap_at_weld.unwrap() <= 0.25 * thickness, "{m:?}");
    assert_eq!(m.seams.len(), 4, "two darts and two side seams");
    for [_, a, b] in &m.seams {
        assert!((a - b).abs() < 1e-9, "the darts' legs and the side seams are drafted equal: {a} {b}");
    }
    assert!(metrics.max_penetration.unwrap() < thickness, "{:?}", metrics.max_penetration);
    assert_eq!(metrics.self_intersections, Some(0));
    // A file that is not a specification is refused before any work, naming the file.
    let not_a_pattern = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("not-a-pattern.json");
    std::fs::write(&not_a_pattern, "{\"panels\": []}").unwrap();
    let refused = run(&["pattern", "import", not_a_pattern.to_str().unwrap()]);
    assert_eq!(refused.status.code(), Some(2));
    let said = String::from_utf8_lossy(&refused.stderr);
    assert!(said.contains("not-a-pattern.json") && said.contains("not a GarmentCode pattern specification"), "{said}");
}

/// A GarmentCode specification given where a scene goes (`rosette run SPEC.json`, the
/// viewer's Open) is the scene `rosette pattern import` writes for it with its defaults, and
/// takes `--set` like any scene; a broken one is refused naming the file, panel and edge.
#[test]
fn a_garmentcode_specification_runs_as_a_scene() {
    let spec = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/patterns/aline-skirt_specification.json");
    let (config, file) = load_scene(spec, &["mesh.edge_length=0.05".into(), "fabric.preset=\"denim\"".into()]).unwrap();
    assert!(file.ends_with("aline-skirt_specification.json"), "{file}");
    let garment = config.garment.as_ref().expect("a garment scene");
    assert_eq!(garment.panels.len(), 2);
    assert_eq!(garment.seams.len(), 4);
    assert_eq!(garment.form.size.as_deref(), Some("uk-14"));
    assert_eq!(config.mesh.edge_length, 0.05);
    assert_eq!(config.fabric.preset.as_deref(), Some("denim"));
    Scene::build(config).unwrap();
    let broken = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("broken_specification.json");
    let text = std::fs::read_to_string(spec).unwrap().replacen(r#"{"endpoints": [1, 2]"#, r#"{"endpoints": [1, 3]"#, 1);
    std::fs::write(&broken, text).unwrap();
    let err = load_scene(broken.to_str().unwrap(), &[]).expect_err("a broken loop is refused").to_string();
    assert!(err.contains("broken_specification.json") && err.contains("panel 'skirt_front'") && err.contains("edge 1"), "{err}");
}
