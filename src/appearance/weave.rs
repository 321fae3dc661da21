//! Woven textures generated from their interlacing: plain, twill and satin.
//!
//! One repeat of the weave, warp yarns along x (texture u, the fabric's warp) and weft
//! yarns along y (v), [`PITCH`] pixels a yarn, yarns [`YARN_SPACING_M`] apart on the cloth.
//! At each crossing one yarn lies on top; a yarn on top is bright along its crown and dark
//! at its sides, and dips at each end of its float where it goes under. The picture is a
//! multiplier of the fabric's colour (1 at a yarn's crown), so the weave shows its own
//! light and shade in any colour: a twill's diagonal wales, a satin's long smooth floats.
//!
//! ```text
//!   plain (1/1)        twill (3/1, left-hand)   satin (8-end, move 3)
//!   weft j →           weft j →                 weft j →
//!   ■□■□  warp i ↓     ■■■□  warp i ↓           ■■■□■■■■  warp i ↓
//!   □■□■               ■■□■                     ■■■■■■□■
//!   ■□■□               ■□■■                     ■□■■■■■■
//!   □■□■               □■■■                     ■■■■□■■■   ■ warp on top
//! ```

use image::{Rgba, RgbaImage};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, OnceLock};

/// Pixels across one yarn.
pub const PITCH: u32 = 16;

/// Distance between neighbouring yarns on the cloth, m: the 1 mm of Rosette's first weave
/// texture (a medium-weight fabric has 20 to 40 ends per centimetre; 1 mm keeps the weave
/// visible in a close-up, and in a view of a whole garment the mipmaps take it to its mean).
pub const YARN_SPACING_M: f64 = 0.001;

/// A weave, as `appearance.weave` names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Weave {
    /// Each yarn over one, under one: poplin, lawn, crêpe de chine, most shirtings.
    #[default]
    Plain,
    /// 3/1 twill: each warp over three wefts and under one, shifted one weft per warp, so
    /// the floats line up in diagonal wales (denim, gabardine, drill).
    Twill,
    /// 8-end satin, move 3: each warp over seven wefts and under one, the binding points
    /// scattered so that no line shows, the face all long warp floats.
    Satin,
}

impl Weave {
    pub const ALL: [Weave; 3] = [Weave::Plain, Weave::Twill, Weave::Satin];

    /// The name a fabric file writes.
    pub fn name(self) -> &'static str {
        match self {
            Weave::Plain => "plain",
            Weave::Twill => "twill",
            Weave::Satin => "satin",
        }
    }

    /// Yarns each way in one repeat of the texture (plain repeats after two; four give its
    /// yarns their own small differences).
    pub fn yarns(self) -> u32 {
        match self {
            Weave::Plain | Weave::Twill => 4,
            Weave::Satin => 8,
        }
    }

    /// One repeat of the texture on the cloth, along the warp and the weft alike, m.
    pub fn repeat_m(self) -> f64 {
        f64::from(self.yarns()) * YARN_SPACING_M
    }

    /// Whether warp yarn `warp` lies over weft yarn `weft` where they cross.
    pub fn warp_on_top(self, warp: u32, weft: u32) -> bool {
        let n = self.yarns();
        let (i, j) = (warp % n, weft % n);
        match self {
            Weave::Plain => (i + j) % 2 == 0,
            // Under one weft, the one that moves along by one for each warp.
            Weave::Twill => (j + i) % 4 != 3,
            Weave::Satin => j != (3 * i) % 8,
        }
    }

    /// The texture's pixels, sRGB, generated once per weave.
    pub fn texels(self) -> Arc<RgbaImage> {
        static TEXELS: [OnceLock<Arc<RgbaImage>>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        let slot = &TEXELS[Self::ALL.iter().position(|w| *w == self).expect("every weave is in ALL")];
        Arc::clone(slot.get_or_init(|| Arc::new(generate(self))))
    }

    /// The texture as a PNG file's bytes (for glTF).
    pub fn png(self) -> Vec<u8> {
        let image = self.texels();
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new(&mut bytes)
            .write_image(image.as_raw(), image.width(), image.height(), image::ExtendedColorType::Rgba8)
            .expect("a PNG encodes into memory");
        bytes
    }
}

use image::ImageEncoder;

/// Brightness across a yarn, `t` in 0..1: a rounded crown with dark gaps at its sides.
fn across(t: f64) -> f64 {
    0.35 + 0.65 * (std::f64::consts::PI * t).sin().powf(0.6)
}

/// Brightness along a float, `t` in 0..1 from where the yarn comes up to where it goes under.
fn along(t: f64) -> f64 {
    0.80 + 0.20 * (std::f64::consts::PI * t).sin().powf(0.5)
}

/// Warp yarns a shade lighter and warmer than weft yarns, so that the warp's direction
/// still shows when the texture is tinted (as in a real cloth, whose warp is the tighter,
/// smoother set).
const WARP: [f64; 3] = [1.00, 0.97, 0.92];
const WEFT: [f64; 3] = [0.86, 0.86, 0.88];

/// Each yarn's own brightness, a few per cent either way: indexed by yarn, so the repeat
/// still tiles.
fn jitter(k: u32, salt: u32) -> f64 {
    let h = (k.wrapping_mul(2_654_435_761) ^ salt.wrapping_mul(40_503)).wrapping_mul(2_246_822_519);
    1.0 + 0.05 * (f64::from(h >> 8) / f64::from(1u32 << 24) * 2.0 - 1.0)
}

/// The float through crossing `at` along a yarn whose crossings `on_top(k)` says it is on
/// top at: where it starts (in crossings, may be negative) and how many crossings it spans.
fn float_extent(at: i64, period: i64, on_top: impl Fn(i64) -> bool) -> (i64, i64) {
    let (mut start, mut end) = (at, at);
    while start - 1 > at - period && on_top(start - 1) {
        start -= 1;
    }
    while end + 1 < at + period && on_top(end + 1) {
        end += 1;
    }
    (start, end - start + 1)
}

/// One repeat of `weave`, [`PITCH`] pixels a yarn.
fn generate(weave: Weave) -> RgbaImage {
    let n = weave.yarns();
    let size = n * PITCH;
    let period = i64::from(n);
    let wrap = |k: i64| k.rem_euclid(period) as u32;
    RgbaImage::from_fn(size, size, |x, y| {
        // Warp yarns run along x, so row y picks the warp yarn; column x the weft yarn.
        let (warp, weft) = (y / PITCH, x / PITCH);
        let at = |p: u32| (f64::from(p % PITCH) + 0.5) / f64::from(PITCH);
        let (warp_t, weft_t) = (at(y), at(x));
        let (shade, colour, across_t) = if weave.warp_on_top(warp, weft) {
            // A warp float runs along x, over consecutive wefts.
            let (start, length) = float_extent(i64::from(weft), period, |k| weave.warp_on_top(warp, wrap(k)));
            let t = (i64::from(weft) - start) as f64 / length as f64 + weft_t / length as f64;
            (across(warp_t) * along(t) * jitter(warp, 1), WARP, weft_t)
        } else {
            let (start, length) = float_extent(i64::from(warp), period, |k| !weave.warp_on_top(wrap(k), weft));
            let t = (i64::from(warp) - start) as f64 / length as f64 + warp_t / length as f64;
            (across(weft_t) * along(t) * jitter(weft, 2), WEFT, warp_t)
        };
        // Fine fibre streaks along each yarn.
        let streak = 1.0 + 0.04 * (std::f64::consts::TAU * 3.0 * across_t + 1.3).sin();
        let [r, g, b] = colour.map(|c| (255.0 * c * shade * streak).round().clamp(0.0, 255.0) as u8);
        Rgba([r, g, b, 255])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean brightness of the pixels of `image` and of its copy shifted by (dx, dy),
    /// correlated: near 1 where the picture repeats along that shift.
    fn correlation(image: &RgbaImage, dx: u32, dy: u32) -> f64 {
        let (w, h) = image.dimensions();
        let luma = |x: u32, y: u32| {
            let p = image.get_pixel(x % w, y % h);
            f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])
        };
        let n = f64::from(w * h);
        let mean = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| luma(x, y)).sum::<f64>() / n;
        let (mut cov, mut var) = (0.0, 0.0);
        for y in 0..h {
            for x in 0..w {
                let (a, b) = (luma(x, y) - mean, luma(x + dx, y + dy) - mean);
                cov += a * b;
                var += a * a;
            }
        }
        cov / var
    }

    #[test]
    fn a_twill_has_diagonal_wales_and_plain_and_satin_have_none() {
        let p = PITCH;
        // A twill repeats along its wales: one yarn over and one yarn back (the floats move
        // one weft per warp), not along the other diagonal, where a step of one yarn each
        // way moves the binding points two wefts on: of a 3/1 twill's four crossings, two
        // then lie float on float and two do not, a correlation near a half.
        let twill = Weave::Twill.texels();
        let (wale, across_wales) = (correlation(&twill, p, 3 * p), correlation(&twill, p, p));
        assert!(wale > 0.8 && across_wales < 0.6, "twill: along its wales {wale:.2}, across {across_wales:.2}");
        // A plain weave's two diagonals are alike; a satin shows no diagonal line.
        let plain = Weave::Plain.texels();
        let (d1, d2) = (correlation(&plain, p, p), correlation(&plain, p, 3 * p));
        assert!((d1 - d2).abs() < 0.1, "plain: {d1:.2} against {d2:.2}");
        let satin = Weave::Satin.texels();
        // Seven crossings in eight are floats, so a shift that moves the binding points off
        // themselves still leaves six in eight float on float (about 0.8): what shows a line
        // is a correlation near the twill's wale, which no short diagonal of the satin has.
        for (dx, dy) in [(1, 1), (1, 7), (1, 2), (2, 1)] {
            let c = correlation(&satin, dx * p, dy * p);
            assert!(c < 0.9 && c < wale - 0.1, "satin along ({dx}, {dy}) yarns: {c:.2}");
        }
    }

    #[test]
    fn each_weave_has_the_interlacing_its_name_says() {
        // Over three, under one for the twill; over seven, under one for the satin, each weft
        // bound once per repeat.
        for warp in 0..8 {
            assert_eq!((0..4).filter(|&j| Weave::Twill.warp_on_top(warp, j)).count(), 3);
            assert_eq!((0..8).filter(|&j| Weave::Satin.warp_on_top(warp, j)).count(), 7);
            assert_eq!((0..8).filter(|&i| !Weave::Satin.warp_on_top(i, warp)).count(), 1);
            assert_eq!((0..4).filter(|&j| Weave::Plain.warp_on_top(warp, j)).count(), 2);
        }
        assert_eq!(Weave::Satin.texels().dimensions(), (8 * PITCH, 8 * PITCH));
        assert_eq!(Weave::Plain.texels().dimensions(), (4 * PITCH, 4 * PITCH));
        let png = Weave::Twill.png();
        assert_eq!(image::load_from_memory(&png).unwrap().to_rgba8(), *Weave::Twill.texels());
    }

    #[test]
    fn a_satin_face_is_smoother_than_a_plain_weave() {
        // Long floats dip less often: the satin's brightness varies less along the warp.
        let variation = |image: &RgbaImage| {
            let (w, h) = image.dimensions();
            let mut sum = 0.0;
            for y in 0..h {
                for x in 0..w {
                    let a = f64::from(image.get_pixel(x, y)[1]);
                    let b = f64::from(image.get_pixel((x + 1) % w, y)[1]);
                    sum += (a - b).abs();
                }
            }
            sum / f64::from(w * h)
        };
        let (satin, plain) = (variation(&Weave::Satin.texels()), variation(&Weave::Plain.texels()));
        assert!(satin < 0.8 * plain, "satin {satin:.2} against plain {plain:.2}");
    }
}
