//! `rosette run --export FILE.glb`: the cloth as glTF 2.0 binary, read back with the `gltf`
//! crate (which validates the document as it loads): counts against the run's metrics,
//! accessor bounds against the data, unit normals, texture coordinates at the weave's scale,
//! the embedded texture, and the animation's frames.

use gltf::animation::util::ReadOutputs;
use std::path::PathBuf;
use std::process::Command;

fn temp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Runs the 30 cm Cusick drape for 0.2 s (50 steps) with `args` and returns its metrics.
fn run(args: &[&str]) -> serde_json::Value {
    let metrics = temp(&format!("metrics-{}.json", args.len()));
    let out = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["run", "cusick-drape-30", "--duration", "0.2", "--metrics", metrics.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(&std::fs::read_to_string(metrics).unwrap()).unwrap()
}

struct Read {
    gltf: gltf::Gltf,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    indices: Vec<u32>,
    /// Morph targets' position offsets.
    targets: Vec<Vec<[f32; 3]>>,
}

fn read(path: &PathBuf) -> Read {
    let bytes = std::fs::read(path).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("{}: not valid glTF: {e:?}", path.display()));
    let blob = gltf.blob.clone().expect("a binary chunk");
    let mesh = gltf.meshes().next().expect("one mesh");
    let primitive = mesh.primitives().next().expect("one primitive");
    assert_eq!(primitive.mode(), gltf::mesh::Mode::Triangles);
    // Every vertex accessor's bounds are those of its data (glTF requires them for positions).
    let reader = primitive.reader(|_| Some(&blob[..]));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let bounds = primitive.get(&gltf::Semantic::Positions).unwrap();
    let (lo, hi) = (bounds.min().unwrap(), bounds.max().unwrap());
    for k in 0..3 {
        let data_lo = positions.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
        let data_hi = positions.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max);
        assert_eq!(lo[k].as_f64().unwrap() as f32, data_lo);
        assert_eq!(hi[k].as_f64().unwrap() as f32, data_hi);
    }
    let normals: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
    let uv: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let targets = reader.read_morph_targets().map(|(p, _, _)| p.expect("positions in every target").collect()).collect();
    Read { gltf, positions, normals, uv, indices, targets }
}

#[test]
fn the_cloth_reads_back_with_its_normals_weave_and_animation() {
    let still = temp("still.glb");
    let metrics = run(&["--export", still.to_str().unwrap()]);
    let s = read(&still);
    let vertices = metrics["vertices"].as_u64().unwrap() as usize;
    assert_eq!(s.positions.len(), vertices);
    assert_eq!(s.indices.len(), 3 * metrics["triangles"].as_u64().unwrap() as usize);
    assert!(s.indices.iter().all(|&i| (i as usize) < vertices));
    assert_eq!(s.normals.len(), vertices);
    for n in &s.normals {
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((length - 1.0).abs() < 1e-5, "normal {n:?}");
    }
    // The weave's scale: texture coordinates in metres of cloth, and the material's texture
    // transform one repeat of the texture (four 1 mm yarns) per 4 mm, so the 300 mm disc
    // spans 75 repeats along the warp and the weft. The disc's edge is a polygon through the
    // circle's points, so its extent is the diameter.
    assert!(s.uv.iter().all(|t| t[0].is_finite() && t[1].is_finite()));
    let scale = s.gltf.materials().next().unwrap().pbr_metallic_roughness().base_color_texture().unwrap().texture_transform().map(|t| t.scale());
    for k in 0..2 {
        let span = s.uv.iter().map(|t| t[k]).fold(f32::NEG_INFINITY, f32::max) - s.uv.iter().map(|t| t[k]).fold(f32::INFINITY, f32::min);
        let repeats = span * scale.map_or(250.0, |s| s[k]);
        assert!((repeats - 75.0).abs() < 0.75, "uv span {span} m, {repeats} repeats, want 75 (300 mm / 4 mm)");
    }
    // glTF is y up: the cloth sits on the pedestal's top, the scene's z = 0 to 2 mm, so its
    // heights are y, and the disc spreads over x and z.
    let extent = |k: usize| s.positions.iter().map(|p| p[k]).fold(f32::NEG_INFINITY, f32::max) - s.positions.iter().map(|p| p[k]).fold(f32::INFINITY, f32::min);
    assert!(extent(0) > 0.25 && extent(2) > 0.25 && extent(1) < 0.05, "extents {} {} {}", extent(0), extent(1), extent(2));
    // The texture is there, on a two-sided material, and is the weave PNG.
    let material = s.gltf.materials().next().unwrap();
    assert!(material.double_sided());
    let texture = material.pbr_metallic_roughness().base_color_texture().expect("a base colour texture").texture();
    let gltf::image::Source::View { view, mime_type } = texture.source().source() else { panic!("the image is embedded") };
    assert_eq!(mime_type, "image/png");
    let blob = s.gltf.blob.as_ref().unwrap();
    let png = &blob[view.offset()..view.offset() + view.length()];
    let image = image::load_from_memory_with_format(png, image::ImageFormat::Png).unwrap();
    assert_eq!((image.width(), image.height()), (64, 64));
    assert_eq!(texture.sampler().wrap_s(), gltf::texture::WrappingMode::Repeat);
    assert_eq!(s.gltf.animations().count(), 0, "the final state alone is a still");

    // The same run animated: 6 frames over 0.2 s, the last of which is the still's state.
    let animated = temp("animated.glb");
    run(&["--export", animated.to_str().unwrap(), "--export-frames", "6"]);
    let a = read(&animated);
    assert_eq!(a.targets.len(), 5, "frames after the first are morph targets");
    let animation = a.gltf.animations().next().expect("an animation");
    let channel = animation.channels().next().unwrap();
    assert_eq!(channel.target().property(), gltf::animation::Property::MorphTargetWeights);
    let blob = a.gltf.blob.clone().unwrap();
    let reader = channel.reader(|_| Some(&blob[..]));
    let times: Vec<f32> = reader.read_inputs().unwrap().collect();
    assert_eq!(times.len(), 6);
    assert!(times.windows(2).all(|w| w[1] > w[0]), "{times:?}");
    assert!((times[5] - 0.2).abs() < 0.01, "the run lasted 0.2 s: {times:?}");
    let Some(ReadOutputs::MorphTargetWeights(weights)) = reader.read_outputs() else { panic!("weights") };
    let weights: Vec<f32> = weights.into_f32().collect();
    assert_eq!(weights.len(), 6 * 5);
    // Frame k shows target k − 1 alone.
    for k in 0..6 {
        for j in 0..5 {
            assert_eq!(weights[5 * k + j], if k == j + 1 { 1.0 } else { 0.0 });
        }
    }
    // The first frame is the flat disc on the pedestal (z = 2 mm, with the 0.2 mm ripple).
    assert!(a.positions.iter().all(|p| (p[1] - 0.002).abs() <= 0.000_25), "the start lies flat");
    // The last frame, base plus its offsets, is the still's final state (the runs are the same).
    let last = &a.targets[4];
    for ((p, d), q) in a.positions.iter().zip(last).zip(&s.positions) {
        for k in 0..3 {
            assert!((p[k] + d[k] - q[k]).abs() < 1e-6, "{p:?} + {d:?} vs {q:?}");
        }
    }
}

/// A garment exports its texture space (each panel turned into its warp frame, the panels
/// side by side: `Model::texture_space`) in metres, the material's texture transform
/// scaling it to the pattern's repeat, so that a print mapped onto the bias skirt runs
/// along each gore's grain: the exported coordinates are the model's, and within each
/// triangle their edges are the triangle's own edges in its warp frame.
#[test]
fn a_garment_exports_each_panel_in_its_warp_frame() {
    let path = temp("skirt-bias.glb");
    let overrides = ["--set", "mesh.edge_length=0.05", "--duration", "0.02"];
    let out = Command::new(env!("CARGO_BIN_EXE_rosette")).args(["run", "skirt-gored-bias"]).args(overrides).args(["--export", path.to_str().unwrap()]).output().unwrap();
    // A run ended before the sewing time is reported unfinished (exit 8), its outputs kept.
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(8), "{stderr}");
    assert!(stderr.contains("before garment.sewing_time") && stderr.contains("--duration"), "{stderr}");
    let r = read(&path);
    let (config, _) = rosette::scene::load_scene("skirt-gored-bias", &["mesh.edge_length=0.05".into()]).unwrap();
    let scene = rosette::scene::Scene::build(config).unwrap();
    // Texture coordinates in metres of the cloth at rest.
    let period = 1.0;
    let frames = scene.model.frames.as_ref().unwrap();
    assert_eq!(r.uv.len(), scene.model.vertex_count());
    for (t, c) in scene.model.triangles.iter().zip(frames) {
        for k in 1..3 {
            let (a, b) = (r.uv[t[0] as usize], r.uv[t[k] as usize]);
            let exported = glam::DVec2::new(f64::from(b[0] - a[0]), f64::from(b[1] - a[1])) * period;
            assert!((exported - (c[k] - c[0])).length() < 1e-5, "triangle {t:?}: exported edge {exported} against {} in its warp frame", c[k] - c[0]);
        }
    }
}


/// The positions of `primitive` at morph weights `weights`: its base plus each target's
/// offsets scaled by its weight.
fn morphed(primitive: &gltf::Primitive, blob: &[u8], weights: &[f32]) -> Vec<[f32; 3]> {
    let reader = primitive.reader(|_| Some(blob));
    let mut positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    for (target, &w) in reader.read_morph_targets().zip(weights) {
        for (p, d) in positions.iter_mut().zip(target.0.expect("positions in every target")) {
            for k in 0..3 {
                p[k] += w * d[k];
            }
        }
    }
    positions
}

/// A garment's seams weld during its run, and its vertex count drops: the animation holds
/// one mesh before the weld and one after, each shown by its node's scale from its first
/// frame to the next mesh's, and every frame reads back whole (the viewer once died at that
/// weld, and this export failed with exit 4). The last frame is the still export's state.
#[test]
fn a_welded_garment_animates_across_its_weld() {
    let (animated, still) = (temp("dress-animated.glb"), temp("dress-still.glb"));
    let run = |path: &PathBuf, frames: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_rosette"))
            .args(["run", "shift-dress", "--fast", "--set", "mesh.edge_length=0.035", "--export", path.to_str().unwrap()])
            .args(frames)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    run(&animated, &["--export-frames", "12"]);
    run(&still, &[]);
    let bytes = std::fs::read(&animated).unwrap();
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("not valid glTF: {e:?}"));
    let blob = gltf.blob.clone().unwrap();
    let nodes: Vec<gltf::Node> = gltf.nodes().collect();
    assert_eq!(nodes.len(), 2, "one mesh before the weld, one after");
    let counts: Vec<usize> = nodes.iter().map(|n| n.mesh().unwrap().primitives().next().unwrap().get(&gltf::Semantic::Positions).unwrap().count()).collect();
    assert!(counts[1] < counts[0], "the weld merges vertices: {counts:?}");
    for node in &nodes {
        let primitive = node.mesh().unwrap().primitives().next().unwrap();
        let n = primitive.get(&gltf::Semantic::Positions).unwrap().count() as u32;
        let indices: Vec<u32> = primitive.reader(|_| Some(&blob[..])).read_indices().unwrap().into_u32().collect();
        assert!(indices.iter().all(|&i| i < n), "node {}: an index past its vertices", node.index());
    }
    // Each node's animated scale (step) and weights (linear), sampled at every key time.
    let animation = gltf.animations().next().expect("an animation");
    let mut scales: Vec<Vec<(f32, [f32; 3])>> = vec![Vec::new(); 2];
    let mut weights: Vec<Vec<(f32, Vec<f32>)>> = vec![Vec::new(); 2];
    for channel in animation.channels() {
        let node = channel.target().node().index();
        let reader = channel.reader(|_| Some(&blob[..]));
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        match reader.read_outputs().unwrap() {
            ReadOutputs::Scales(s) => {
                assert_eq!(channel.sampler().interpolation(), gltf::animation::Interpolation::Step);
                scales[node] = times.into_iter().zip(s).collect();
            }
            ReadOutputs::MorphTargetWeights(w) => {
                let w: Vec<f32> = w.into_f32().collect();
                let per = w.len() / times.len();
                weights[node] = times.into_iter().enumerate().map(|(k, t)| (t, w[k * per..(k + 1) * per].to_vec())).collect();
            }
            other => panic!("an unexpected channel: {:?}", std::mem::discriminant(&other)),
        }
    }
    let scale_at = |node: usize, t: f32| scales[node].iter().rev().find(|(k, _)| *k <= t).map_or(scales[node][0].1, |k| k.1);
    let mut frame_times: Vec<f32> = weights.iter().flatten().map(|w| w.0).chain(scales.iter().flatten().map(|s| s.0)).collect();
    frame_times.sort_by(f32::total_cmp);
    frame_times.dedup();
    assert!(frame_times.len() >= 6, "{frame_times:?}");
    let mut last = Vec::new();
    for &t in &frame_times {
        let shown: Vec<usize> = (0..2).filter(|&n| scale_at(n, t) == [1.0; 3]).collect();
        assert_eq!(shown.len(), 1, "at t = {t} s exactly one mesh shows: {shown:?}");
        assert!((0..2).all(|n| matches!(scale_at(n, t), [1.0, 1.0, 1.0] | [0.0, 0.0, 0.0])));
        let node = shown[0];
        let primitive = nodes[node].mesh().unwrap().primitives().next().unwrap();
        let frame_weights = weights[node].iter().find(|w| w.0 == t).map(|w| w.1.clone()).unwrap_or_default();
        let positions = morphed(&primitive, &blob, &frame_weights);
        // On or around the form: finite, above the floor, within a metre of its axis.
        assert!(positions.iter().all(|p| p.iter().all(|c| c.is_finite()) && p[1] > 0.0 && p[0].abs() < 1.0 && p[2].abs() < 1.0), "t = {t}");
        last = positions;
    }
    let s = read(&still);
    assert_eq!(last.len(), s.positions.len(), "the last frame is on the welded mesh");
    for (p, q) in last.iter().zip(&s.positions) {
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-5, "{p:?} against the still's {q:?}");
        }
    }
}
