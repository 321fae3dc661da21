//! A fabric's look (`[appearance]`, src/appearance) where it is drawn and written: a headless
//! screenshot shows denim bluer than wool and the white-dots print lighter than its black
//! ground alone would be; the glTF export carries the look as a PBR material with
//! `KHR_materials_sheen` and `KHR_texture_transform`; and a bad look in a fabric file
//! (a colour that is not one, a missing texture, a repeat of zero) exits 2 naming its key.

mod common;

use common::runtime_dir;
use rosette::appearance::{Look, Pattern};
use rosette::render::{BACKGROUND, Frame, Headless, RenderOptions, Screenshot};
use rosette::scene::{Scene, load_scene};
use serde_json::Value;
use std::path::PathBuf;
use std::process::Command;

const SIZE: [u32; 2] = [240, 180];

fn temp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("appearance-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The 30 cm Cusick specimen in `fabric`, a few steps into its fall.
fn cusick(fabric: &str) -> Scene {
    let (config, _) = load_scene("cusick-drape-30", &[format!("fabric.preset={fabric}")]).unwrap();
    let mut scene = Scene::build(config).unwrap();
    for _ in 0..5 {
        scene.step().unwrap();
    }
    scene
}

/// The mean sRGB colour of the picture's middle, a third of it each way: the cloth seen
/// from above, which covers the pedestal there.
fn cloth_colour(image: &image::RgbaImage) -> [f64; 3] {
    let (w, h) = image.dimensions();
    let (mut sum, mut n) = ([0.0; 3], 0.0);
    for y in h / 3..2 * h / 3 {
        for x in w / 3..2 * w / 3 {
            let p = image.get_pixel(x, y);
            for k in 0..3 {
                sum[k] += f64::from(p[k]);
            }
            n += 1.0;
        }
    }
    let mean = sum.map(|s| s / n);
    let bg = BACKGROUND.map(|c| 255.0 * f64::from(c));
    assert!((0..3).map(|k| (mean[k] - bg[k]).abs()).sum::<f64>() > 30.0, "the middle is background: {mean:?}");
    mean
}

fn screenshot(fabric: &str) -> image::RgbaImage {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: set before any device exists; the test that renders is the only one here.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", runtime_dir()) };
    }
    let mut headless = Headless::new().unwrap_or_else(|e| panic!("{e}"));
    let frame = Frame::from_scene(&cusick(fabric), None);
    let shot = Screenshot { path: PathBuf::new(), size: SIZE, view: Some((-60.0, 60.0, None)), color_map: None, wireframe: false };
    let image = headless.render(&frame, &shot.camera(&frame), &RenderOptions::default(), SIZE).unwrap();
    if let Some(dir) = std::env::var_os("ROSETTE_SCREENSHOT_DIR") {
        std::fs::create_dir_all(&dir).unwrap();
        image.save(PathBuf::from(dir).join(format!("look-{fabric}.png"))).unwrap();
    }
    image
}

/// Indigo denim is blue (blue over red), wool suiting's camel is not, and the dots print's
/// white dots lift its black ground: each drawn in its own look, the same renderer.
#[test]
fn a_headless_screenshot_draws_each_fabric_in_its_own_look() {
    let denim = cloth_colour(&screenshot("denim"));
    let wool = cloth_colour(&screenshot("wool"));
    let dots = cloth_colour(&screenshot("white-dots-on-blk"));
    assert!(denim[2] > denim[0] + 25.0, "denim {denim:?}");
    assert!(wool[0] > wool[2] + 15.0, "wool {wool:?}");
    assert!(denim[2] - denim[0] > wool[2] - wool[0] + 40.0, "denim {denim:?} against wool {wool:?}");
    // Black cloth lit as the others are stays below 45; a tenth of it white lifts it.
    let luma = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    assert!(luma(dots) > 45.0 && luma(dots) < luma(wool), "dots {dots:?}");
}

/// The glb's JSON chunk.
fn glb_json(bytes: &[u8]) -> Value {
    assert_eq!(&bytes[0..4], b"glTF");
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

fn close(value: &Value, expected: &[f32]) -> bool {
    let got: Vec<f64> = value.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    got.len() == expected.len() && got.iter().zip(expected).all(|(a, b)| (a - f64::from(*b)).abs() < 1e-5)
}

/// Silk exports its colour as the base colour (linear, as glTF has it), its sheen as
/// `KHR_materials_sheen`, and its weave repeated per 4 mm along warp and weft; the print
/// embeds its own PNG at its 10 mm repeat. The file still reads as glTF.
#[test]
fn the_glb_carries_the_look_with_sheen_and_the_grain_s_texture_transform() {
    for fabric in ["silk", "white-dots-on-blk"] {
        let path = temp(&format!("{fabric}.glb"));
        let out = Command::new(env!("CARGO_BIN_EXE_rosette"))
            .args(["run", "cusick-drape-30", "--set", &format!("fabric.preset={fabric}"), "--duration", "0.01", "--export", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let bytes = std::fs::read(&path).unwrap();
        gltf::Gltf::from_slice(&bytes).unwrap_or_else(|e| panic!("{fabric}: not valid glTF: {e:?}"));
        let json = glb_json(&bytes);
        let used: Vec<&str> = json["extensionsUsed"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
        assert!(used.contains(&"KHR_materials_sheen") && used.contains(&"KHR_texture_transform"), "{used:?}");
        let (config, _) = load_scene("cusick-drape-30", &[format!("fabric.preset={fabric}")]).unwrap();
        let look = Look::check(&config.fabric.appearance, None).unwrap();
        let material = &json["materials"][0];
        let [r, g, b] = look.colour.linear();
        assert!(close(&material["pbrMetallicRoughness"]["baseColorFactor"], &[r, g, b, 1.0]), "{fabric}: {material}");
        let transform = &material["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"];
        let scale = look.repeat_m.map(|m| (1.0 / m) as f32);
        assert!(close(&transform["scale"], &scale), "{fabric}: {transform}");
        let sheen = &material["extensions"]["KHR_materials_sheen"];
        let expected = look.sheen.map_or([0.0; 3], |s| s.colour.linear());
        assert!(close(&sheen["sheenColorFactor"], &expected), "{fabric}: {sheen}");
        match &look.pattern {
            Pattern::Weave(_) => {
                assert!(expected[0] > 0.5, "silk has a sheen: {sheen}");
                assert!((sheen["sheenRoughnessFactor"].as_f64().unwrap() - 0.35).abs() < 1e-6, "{sheen}");
                assert!(close(&transform["scale"], &[250.0, 250.0]), "plain weave, 4 mm: {transform}");
            }
            Pattern::Image(t) => {
                assert_eq!(json["images"][0]["mimeType"], "image/png");
                let view = &json["bufferViews"][json["images"][0]["bufferView"].as_u64().unwrap() as usize];
                assert_eq!(view["byteLength"].as_u64().unwrap() as usize, t.encoded.len());
                assert!(close(&transform["scale"], &[100.0, 100.0]), "10 mm: {transform}");
            }
        }
    }
}

/// A fabric file whose `[appearance]` is wrong is refused before any work, exit 2, with the
/// key named: by `run` (through a scene) and by `fabric check`.
#[test]
fn a_bad_look_exits_2_naming_its_key() {
    let wool: String = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/presets/fabrics/wool.toml"))
        .unwrap()
        .split("\n[appearance]")
        .next()
        .unwrap()
        .to_string();
    let cases = [
        ("colour", "colour = \"navy\"", "fabric.appearance.colour"),
        ("texture", "texture = { file = \"no-such-print.png\", size_mm = [10, 10] }", "fabric.appearance.texture.file"),
        ("repeat", "texture = { file = \"assets/prints/white-dots-on-black.png\", size_mm = [10, 0] }", "fabric.appearance.texture.size_mm"),
    ];
    for (name, line, key) in cases {
        let path = temp(&format!("bad-{name}.toml"));
        std::fs::write(&path, format!("{wool}\n[appearance]\n{line}\n")).unwrap();
        let run = Command::new(env!("CARGO_BIN_EXE_rosette"))
            .args(["run", "cusick-drape-30", "--set", &format!("fabric.preset={}", path.display()), "--duration", "0.01"])
            .output()
            .unwrap();
        let check = Command::new(env!("CARGO_BIN_EXE_rosette")).args(["fabric", "check", path.to_str().unwrap()]).output().unwrap();
        for (command, out) in [("run", run), ("fabric check", check)] {
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{name}, {command}: {stderr}");
            assert!(stderr.contains(key), "{name}, {command}: {stderr}");
        }
    }
}
