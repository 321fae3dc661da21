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
    // The weave's scale: one repeat of the texture (four 1 mm yarns) per 4 mm of cloth, so
    // the 300 mm disc spans 75 repeats along the warp and the weft. The disc's edge is a
    // polygon through the circle's points, so its extent is the diameter.
    assert!(s.uv.iter().all(|t| t[0].is_finite() && t[1].is_finite()));
    for k in 0..2 {
        let span = s.uv.iter().map(|t| t[k]).fold(f32::NEG_INFINITY, f32::max) - s.uv.iter().map(|t| t[k]).fold(f32::INFINITY, f32::min);
        assert!((span - 75.0).abs() < 0.75, "uv span {span} repeats, want 75 (300 mm / 4 mm)");
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
/// side by side: `Model::texture_space`) at the weave's scale, so that a print mapped onto
/// the bias skirt runs along each gore's grain: the exported coordinates are the model's,
/// and within each triangle their edges are the triangle's own edges in its warp frame.
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
    let period = f64::from(rosette::render::RenderOptions::default().weave_period);
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

