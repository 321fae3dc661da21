//! The cloth's light on the CPU: a diffuse base under a sheen, the model glTF's
//! `KHR_materials_sheen` defines, for the swatch beside the fabric editor. The fragment
//! shader `fs_cloth` in `shaders/scene.wgsl` computes the same terms per pixel.
//!
//! The sheen is the "Charlie" microfibre distribution of Estevez and Kulla (*Production
//! Friendly Microfacet Sheen BRDF*, Sony Imageworks 2017), as the glTF extension gives it,
//!
//!   D(h) = (2 + 1/α)·sin(θ_h)^(1/α) / 2π,   α = roughness²,
//!
//! with the visibility term of Neubelt and Pettineo (*Crafting a Next-Gen Material
//! Pipeline for The Order: 1886*, 2013), V = 1 / (4(n·l + n·v − (n·l)(n·v))). Fibres
//! standing out of the surface catch the light at grazing angles: the sheen is strongest
//! where the cloth turns away from the eye, at folds' flanks and silhouettes. The base is
//! dimmed by the light the sheen takes, glTF's albedo scaling, here a constant share
//! [`SHEEN_ALBEDO`] of the sheen's brightest channel rather than the table the extension
//! suggests.

use super::{Look, Sheen, linear_to_srgb};
use glam::Vec3;
use image::{Rgba, RgbaImage};

/// The sheen layer's mean directional albedo at full sheen colour, the share of light it
/// takes from the base: Estevez and Kulla's figures lie from 0.1 (rough, at normal
/// incidence) to about 0.45 (at grazing); a quarter is their middle.
pub const SHEEN_ALBEDO: f32 = 0.25;

/// The least α the distribution is evaluated at: below it sin^(1/α) underflows to a
/// sheen of nothing at all but the silhouette (the clamp Filament applies too).
pub const MIN_ALPHA: f32 = 0.007;

/// Charlie's distribution D at `n_dot_h`, for roughness `roughness` (0..1).
pub fn charlie_distribution(roughness: f32, n_dot_h: f32) -> f32 {
    let alpha = (roughness * roughness).max(MIN_ALPHA);
    let inverse = 1.0 / alpha;
    let sin2 = (1.0 - n_dot_h * n_dot_h).max(0.0);
    (2.0 + inverse) * sin2.powf(0.5 * inverse) / std::f32::consts::TAU
}

/// Neubelt and Pettineo's visibility term.
pub fn sheen_visibility(n_dot_l: f32, n_dot_v: f32) -> f32 {
    1.0 / (4.0 * (n_dot_l + n_dot_v - n_dot_l * n_dot_v)).max(1e-4)
}

/// The sheen's share of the environment's light towards the eye, at `n_dot_v`: a fit of
/// the distribution's directional albedo, low facing the eye and rising to the grazing
/// angle, a little higher for rough sheens.
pub fn sheen_ambient(roughness: f32, n_dot_v: f32) -> f32 {
    let grazing = (1.0 - n_dot_v.clamp(0.0, 1.0)).powf(2.5);
    (0.08 + 0.4 * grazing) * (0.7 + 0.3 * roughness)
}

/// Light leaving cloth of linear colour `base` with `sheen`, normal `n`, towards the eye
/// along `v`, lit by a light from `l` of irradiance `key` (facing it) and an ambient
/// `ambient`: linear RGB.
pub fn cloth(base: [f32; 3], sheen: Option<Sheen>, n: Vec3, v: Vec3, l: Vec3, key: f32, ambient: f32) -> [f32; 3] {
    let n_dot_l = n.dot(l).max(0.0);
    let n_dot_v = n.dot(v).max(1e-3);
    let diffuse = base.map(|c| c * (ambient + key * n_dot_l));
    let Some(s) = sheen else { return diffuse };
    let colour = s.colour.linear();
    let scale = 1.0 - SHEEN_ALBEDO * colour.iter().copied().fold(0.0, f32::max);
    let h = (l + v).normalize_or_zero();
    let lobe = charlie_distribution(s.roughness, n.dot(h).clamp(0.0, 1.0)) * sheen_visibility(n_dot_l, n_dot_v);
    // `key` is the diffuse's π·E: the lobe takes the same light.
    let specular = std::f32::consts::PI * key * n_dot_l * lobe + ambient * sheen_ambient(s.roughness, n_dot_v) * 2.0;
    [0, 1, 2].map(|k| diffuse[k] * scale + colour[k] * specular)
}

/// A swatch of the fabric, `size` pixels: a strip of it in two soft folds, seen from the
/// front and lit from the upper left, at a scale that shows its weave's yarns or one and a
/// bit repeats of its print (warp across). sRGB.
pub fn swatch(look: &Look, size: [u32; 2]) -> RgbaImage {
    let [width, height] = size.map(|s| s.max(1));
    let texels = look.texels();
    let (tw, th) = texels.dimensions();
    // Cloth shown across the swatch, m.
    let across = (1.25 * look.repeat_m[0]).max(0.024);
    let metres_per_pixel = across / f64::from(width);
    let tint = look.colour.linear();
    // Weaves are a multiplier about their mean, so the cloth keeps its colour on average.
    let normaliser = match look.pattern {
        super::Pattern::Weave(_) => 1.0 / mean_linear(&texels),
        super::Pattern::Image(_) => 1.0,
    };
    let light = Vec3::new(-0.45, 0.55, 0.7).normalize();
    let eye = Vec3::Z;
    // Two folds across: height z = a·sin(2πx/λ), steepest at 65°.
    let wavelength = f64::from(width) / 2.0;
    let slope_peak = 65f64.to_radians().tan();
    let texel = |u: f64, v: f64| {
        let x = (u * f64::from(tw)).rem_euclid(f64::from(tw)) as u32;
        let y = (v * f64::from(th)).rem_euclid(f64::from(th)) as u32;
        let p = texels.get_pixel(x.min(tw - 1), y.min(th - 1));
        [0, 1, 2].map(|k| super::srgb_to_linear(f32::from(p[k]) / 255.0))
    };
    RgbaImage::from_fn(width, height, |px, py| {
        let phase = std::f64::consts::TAU * (f64::from(px) + 0.5) / wavelength;
        let slope = slope_peak * phase.cos();
        let n = Vec3::new(-slope as f32, 0.0, 1.0).normalize();
        // The pixel's texels, four by four, averaged: the swatch shows the weave's mean
        // where its yarns are finer than a pixel.
        let mut sum = [0.0f32; 3];
        for sy in 0..4 {
            for sx in 0..4 {
                let x = (f64::from(px) + (f64::from(sx) + 0.5) / 4.0) * metres_per_pixel;
                let y = (f64::from(py) + (f64::from(sy) + 0.5) / 4.0) * metres_per_pixel;
                let t = texel(x / look.repeat_m[0], y / look.repeat_m[1]);
                for k in 0..3 {
                    sum[k] += t[k] / 16.0;
                }
            }
        }
        let base = [0, 1, 2].map(|k| tint[k] * (sum[k] * normaliser).min(1.0));
        let c = cloth(base, look.sheen, n, eye, light, 0.85, 0.25);
        let [r, g, b] = c.map(|v| (255.0 * linear_to_srgb(v)).round() as u8);
        Rgba([r, g, b, 255])
    })
}

/// The mean of an sRGB texture's channels in linear light.
pub fn mean_linear(image: &RgbaImage) -> f32 {
    let n = (image.width() * image.height()).max(1) as f32;
    let sum: f32 = image.pixels().map(|p| (0..3).map(|k| super::srgb_to_linear(f32::from(p[k]) / 255.0)).sum::<f32>() / 3.0).sum();
    (sum / n).max(1e-3)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::appearance::{Colour, Pattern, Weave};

    fn luma(p: &Rgba<u8>) -> f32 {
        0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
    }

    #[test]
    fn the_sheen_lobe_lies_at_grazing_angles_and_integrates_to_one() {
        // D over the hemisphere, weighted by cos θ_h, integrates to 1 (a distribution).
        for roughness in [0.3f32, 0.6, 1.0] {
            let steps = 20_000;
            let integral: f32 = (0..steps)
                .map(|k| {
                    let theta = (k as f32 + 0.5) / steps as f32 * std::f32::consts::FRAC_PI_2;
                    charlie_distribution(roughness, theta.cos()) * theta.cos() * theta.sin() * std::f32::consts::TAU * std::f32::consts::FRAC_PI_2 / steps as f32
                })
                .sum();
            assert!((integral - 1.0).abs() < 0.01, "roughness {roughness}: {integral}");
            assert!(charlie_distribution(roughness, 0.1) > charlie_distribution(roughness, 0.99));
        }
    }

    #[test]
    fn a_sheen_brightens_the_folds_flanks_more_than_their_crests() {
        let plain = Look { colour: Colour([0x60, 0x20, 0x30]), ..Look::default() };
        let silky = Look { sheen: Some(Sheen { colour: Colour([0xE0, 0xD0, 0xD8]), roughness: 0.35 }), ..plain.clone() };
        let (a, b) = (swatch(&plain, [160, 40]), swatch(&silky, [160, 40]));
        // Column 0 is the steepest flank of a fold; a quarter wavelength on, its crest facing
        // the eye; half a wavelength on, the other flank.
        let column = |image: &RgbaImage, x: u32| (0..40).map(|y| luma(image.get_pixel(x, y))).sum::<f32>() / 40.0;
        let gain_crest = column(&b, 20) / column(&a, 20);
        let gain_flank = (column(&b, 0) / column(&a, 0)).max(column(&b, 40) / column(&a, 40));
        assert!(gain_flank > 1.3 * gain_crest, "flank ×{gain_flank:.2}, crest ×{gain_crest:.2}");
        assert!(matches!(silky.pattern, Pattern::Weave(Weave::Plain)));
    }

    #[test]
    fn a_swatch_keeps_the_fabrics_colour_on_average() {
        let denim = Look { colour: Colour([0x2B, 0x3A, 0x67]), pattern: Pattern::Weave(Weave::Twill), ..Look::default() };
        let image = swatch(&denim, [120, 60]);
        let mean = |k: usize| image.pixels().map(|p| f32::from(p[k])).sum::<f32>() / image.pixels().len() as f32;
        assert!(mean(2) > mean(0) + 20.0 && mean(2) > mean(1) + 15.0, "blue: {} {} {}", mean(0), mean(1), mean(2));
    }
}
