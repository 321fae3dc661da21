//! Headless screenshots: every bundled scene, stepped briefly, rendered offscreen at
//! 320 × 240 with the viewer's renderer (Mesa's lavapipe on a machine without a GPU;
//! `.ci/run` installs it). Each picture must be the asked size, not blank, show cloth in
//! its centre and the background at its corners; the colour map draws its legend, the
//! wireframe its edges and the floor shadow darkens the background.
//!
//! `ROSETTE_SCREENSHOT_DIR=dir cargo test --test screenshot` also writes the images there.

mod common;

use common::runtime_dir;
use rosette::render::{self, BACKGROUND, ColorMap, Frame, Headless, RenderOptions, Screenshot};
use rosette::settings::SCENES;
use rosette::scene::{Scene, load_scene};
use std::collections::HashSet;
use std::path::PathBuf;
use std::process::Command;
use std::sync::{Mutex, OnceLock};

const SIZE: [u32; 2] = [320, 240];

/// Steps each scene takes before its picture: enough to move the rigs and start buckling,
/// little enough to keep the test to about a second per scene.
const STEPS: usize = 20;


/// One device for the whole file: opening lavapipe and compiling the shaders is the slow part.
fn headless() -> &'static Mutex<Headless> {
    static HEADLESS: OnceLock<Mutex<Headless>> = OnceLock::new();
    HEADLESS.get_or_init(|| {
        if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // SAFETY: set once, before any device exists.
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", runtime_dir()) };
        }
        let headless = Headless::new().unwrap_or_else(|e| panic!("{e}"));
        eprintln!("adapter: {:?}", headless.adapter_info());
        Mutex::new(headless)
    })
}

fn stepped(name: &str) -> Scene {
    let (config, _) = load_scene(name, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut scene = Scene::build(config).unwrap_or_else(|e| panic!("{name}: {e}"));
    for _ in 0..STEPS {
        scene.step().unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    scene
}

fn shoot(name: &str, frame: &Frame, options: &RenderOptions, tag: &str) -> image::RgbaImage {
    let camera = Screenshot { path: PathBuf::new(), size: SIZE, view: None, color_map: None, wireframe: false }.camera(frame);
    let image = headless().lock().unwrap().render(frame, &camera, options, SIZE).unwrap_or_else(|e| panic!("{name}: {e}"));
    if let Some(dir) = std::env::var_os("ROSETTE_SCREENSHOT_DIR") {
        std::fs::create_dir_all(&dir).unwrap();
        image.save(PathBuf::from(dir).join(format!("{name}{tag}.png"))).unwrap();
    }
    image
}

fn background() -> [u8; 3] {
    BACKGROUND.map(|c| (c * 255.0).round() as u8)
}

/// The scene's frame with its cloth in the default look, whatever its fabric: these tests
/// find the cloth by its terracotta (each fabric's own look is tests/appearance.rs's).
fn terracotta(scene: &Scene, map: Option<ColorMap>) -> Frame {
    Frame { look: rosette::appearance::Look::default(), ..Frame::from_scene(scene, map) }
}

/// The default look's front and back tints are both clearly red-orange; the background, the
/// shadow and the props are neutral greys.
fn is_cloth(p: &image::Rgba<u8>) -> bool {
    let [r, g, b] = [p[0], p[1], p[2]].map(f32::from);
    r > 40.0 && r > 1.25 * g && r > 1.3 * b
}

fn luminance(p: &image::Rgba<u8>) -> f32 {
    0.3 * f32::from(p[0]) + 0.55 * f32::from(p[1]) + 0.15 * f32::from(p[2])
}

/// Fraction of the pixels in the middle third (both ways) that `keep` holds for.
fn centre_fraction(image: &image::RgbaImage, keep: impl Fn(&image::Rgba<u8>) -> bool) -> f64 {
    let (w, h) = image.dimensions();
    let (mut hits, mut total) = (0, 0);
    for y in h / 3..2 * h / 3 {
        for x in w / 3..2 * w / 3 {
            total += 1;
            hits += usize::from(keep(image.get_pixel(x, y)));
        }
    }
    hits as f64 / total as f64
}

fn check_fabric_picture(name: &str, image: &image::RgbaImage) {
    assert_eq!(image.dimensions(), (SIZE[0], SIZE[1]), "{name}");
    let colours: HashSet<[u8; 3]> = image.pixels().map(|p| [p[0], p[1], p[2]]).collect();
    // A blank frame has one colour. A flat strip still has its weave, its shading and its
    // shadow's penumbra (over a hundred colours at this size); a flat 1 m tablecloth, whose 4 mm weave
    // averages out at 3 mm a pixel, has 38.
    assert!(colours.len() >= 20, "{name}: only {} distinct colours: blank", colours.len());
    let cloth = centre_fraction(image, is_cloth);
    assert!(cloth >= 0.25, "{name}: only {:.1} % of the centre is cloth", 100.0 * cloth);
    let bg = background();
    for (x0, y0) in [(0, 0), (SIZE[0] - 6, 0), (0, SIZE[1] - 6), (SIZE[0] - 6, SIZE[1] - 6)] {
        for y in y0..y0 + 6 {
            for x in x0..x0 + 6 {
                let p = image.get_pixel(x, y);
                let near = (0..3).all(|c| p[c].abs_diff(bg[c]) <= 2);
                assert!(near, "{name}: corner pixel ({x}, {y}) is {p:?}, not the background {bg:?}");
            }
        }
    }
    // The shadow: neutral pixels clearly darker than the background.
    let shadow = image
        .pixels()
        .filter(|p| !is_cloth(p) && luminance(p) < luminance(&image::Rgba([bg[0], bg[1], bg[2], 255])) - 25.0)
        .count();
    assert!(shadow > 200, "{name}: no floor shadow ({shadow} dark pixels)");
    eprintln!("{name}: {} colours, centre {:.0} % cloth, {shadow} shadow pixels", colours.len(), 100.0 * cloth);
}

#[test]
fn every_bundled_scene_renders_cloth_in_the_centre_and_background_at_the_corners() {
    for scene in SCENES {
        let started = std::time::Instant::now();
        let frame = terracotta(&stepped(scene.name), None);
        let image = shoot(scene.name, &frame, &RenderOptions::default(), "");
        check_fabric_picture(scene.name, &image);
        eprintln!("{}: {:.2} s", scene.name, started.elapsed().as_secs_f64());
    }
}

#[test]
fn colour_map_draws_its_scale_and_legend() {
    let scene = stepped("tensile-bias");
    let fabric = shoot("tensile-bias", &terracotta(&scene, None), &RenderOptions::default(), "");
    for map in [ColorMap::Shear, ColorMap::Bending] {
        let image = shoot("tensile-bias", &terracotta(&scene, Some(map)), &RenderOptions::default(), &format!("-{map}"));
        // The cloth takes the map's colours: hardly any fabric red is left in the centre.
        let red = centre_fraction(&image, is_cloth);
        assert!(red < 0.5 * centre_fraction(&fabric, is_cloth), "{map}: {:.1} % still fabric-coloured", 100.0 * red);
        // The legend bar runs from the scale's bottom colour to its top colour.
        let [x0, y0, x1, y1] = render::legend_bar_rect(SIZE[0], SIZE[1]);
        let x = (0.5 * (x0 + x1)) as u32;
        let top = *image.get_pixel(x, y0 as u32 + 2);
        let bottom = *image.get_pixel(x, y1 as u32 - 3);
        let expect = |t: f32| map.color(t).map(|c| (c * 255.0).round() as u8);
        for (pixel, want) in [(top, expect(1.0)), (bottom, expect(0.0))] {
            let close = (0..3).all(|c| pixel[c].abs_diff(want[c]) <= 12);
            assert!(close, "{map}: legend bar shows {pixel:?}, expected about {want:?}");
        }
        // Its labels: dark text on the light panel left of the bar.
        let ink = (0..x0 as u32).flat_map(|x| (y0 as u32..y1 as u32).map(move |y| (x, y))).filter(|&(x, y)| luminance(image.get_pixel(x, y)) < 60.0).count();
        assert!(ink > 20, "{map}: no legend labels ({ink} dark pixels)");
    }
}

#[test]
fn wireframe_draws_the_edges_over_the_cloth() {
    let scene = stepped("cantilever");
    let frame = terracotta(&scene, None);
    let plain = shoot("cantilever", &frame, &RenderOptions::default(), "");
    let wired = shoot("cantilever", &frame, &RenderOptions { wireframe: true, ..RenderOptions::default() }, "-wireframe");
    // Pixels the lines darken; 360 triangles give a few thousand at this size.
    let darkened = plain.pixels().zip(wired.pixels()).filter(|(p, w)| luminance(w) < luminance(p) - 20.0).count();
    assert!(darkened > 1000, "the wireframe darkens only {darkened} pixels");
    eprintln!("wireframe: {darkened} pixels darkened");
    // Nothing but lines changes: the pictures agree away from the cloth.
    let brightened = plain.pixels().zip(wired.pixels()).filter(|(p, w)| luminance(w) > luminance(p) + 2.0).count();
    assert_eq!(brightened, 0);
}

#[test]
fn run_writes_a_png_of_the_asked_size() {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("shot-{}.png", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["run", "tensile-warp", "--duration", "0.04", "--size", "200x150", "--camera", "-30,40", "--colormap", "warp", "--wireframe"])
        .arg("--screenshot")
        .arg(&path)
        .env("XDG_RUNTIME_DIR", runtime_dir())
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let image = image::open(&path).unwrap();
    assert_eq!((image.width(), image.height()), (200, 150));
    std::fs::remove_file(&path).unwrap();

    let bad = Command::new(env!("CARGO_BIN_EXE_rosette")).args(["run", "tensile-warp", "--colormap", "stress", "--screenshot", "x.png"]).output().unwrap();
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("warp, weft, shear, bending"));
}
