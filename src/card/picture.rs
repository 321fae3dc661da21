//! Pictures for the card and the contact sheet: a draped scene rendered headless from above
//! and from the side with the viewer's renderer, and the few raster operations that put
//! rendered pictures and text on one page (text through plotters with egui's bundled font,
//! so that no system font is needed).

use crate::render::{Camera, Frame, Headless, RenderError, RenderOptions};
use crate::scene::Scene;
use glam::DVec3;
use image::{RgbImage, RgbaImage};
use plotters::prelude::*;
use std::path::Path;

/// A view direction: yaw and pitch, degrees (the renderer's orbit camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub yaw_deg: f64,
    pub pitch_deg: f64,
}

/// Straight down (the camera cannot look exactly along its up axis), the warp across.
pub const ABOVE: View = View { yaw_deg: -90.0, pitch_deg: 89.0 };
/// From the side, a little above the pedestal's top so that the folds' depth shows.
pub const SIDE: View = View { yaw_deg: -90.0, pitch_deg: 12.0 };
/// Three-quarter view, the screenshots' default: the folds and their depth at once.
pub const THREE_QUARTER: View = View { yaw_deg: -60.0, pitch_deg: 35.0 };

/// A camera looking along `view` that frames the box `lo`..`hi` in a `size` picture.
pub fn camera_for(lo: DVec3, hi: DVec3, view: View, size: [u32; 2]) -> Camera {
    let mut camera = Camera { yaw: view.yaw_deg.to_radians(), pitch: view.pitch_deg.to_radians(), ..Camera::default() };
    camera.frame_bounds(lo, hi, f64::from(size[0]) / f64::from(size[1].max(1)));
    camera
}

/// The scene as the renderer draws it, the cloth in its fabric look.
pub fn frame(scene: &Scene) -> Frame {
    Frame::from_scene(scene, None)
}

/// What a picture of `frame` frames: the cloth, and below it a fifth of its width of what
/// holds it (the top of a pedestal), so that the cloth fills the picture.
pub fn bounds(frame: &Frame) -> (DVec3, DVec3) {
    let mut points = frame.cloth_positions.iter().filter(|p| p.iter().all(|c| c.is_finite())).map(|p| DVec3::new(p[0].into(), p[1].into(), p[2].into()));
    let Some(first) = points.next() else { return (DVec3::splat(-0.1), DVec3::splat(0.1)) };
    let (mut lo, hi) = points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
    lo.z -= 0.2 * (hi - lo).truncate().max_element();
    (lo, hi)
}

/// Renders `frame` from `view`, framed on `lo`..`hi`.
pub fn render(headless: &mut Headless, frame: &Frame, lo: DVec3, hi: DVec3, view: View, size: [u32; 2]) -> Result<RgbaImage, RenderError> {
    let camera = camera_for(lo, hi, view, size);
    headless.render(frame, &camera, &RenderOptions::default(), size)
}

/// The draped scene from above and from the side, each `size` pixels, on one device.
pub fn drape_views(scene: &Scene, size: [u32; 2]) -> Result<[RgbaImage; 2], RenderError> {
    let mut headless = Headless::new()?;
    let frame = frame(scene);
    let (lo, hi) = bounds(&frame);
    Ok([render(&mut headless, &frame, lo, hi, ABOVE, size)?, render(&mut headless, &frame, lo, hi, SIDE, size)?])
}

/// Copies `picture` into the RGB `buffer` (`width` pixels wide) with its top left corner at
/// `at`, clipped to the buffer.
pub fn blit(buffer: &mut [u8], width: u32, picture: &RgbaImage, at: (u32, u32)) {
    let height = buffer.len() as u32 / (3 * width.max(1));
    for (x, y, pixel) in picture.enumerate_pixels() {
        let (bx, by) = (at.0 + x, at.1 + y);
        if bx < width && by < height {
            let i = 3 * (by * width + bx) as usize;
            buffer[i..i + 3].copy_from_slice(&pixel.0[..3]);
        }
    }
}

/// A grey panel with `message` in it, where a picture could not be rendered.
pub fn placeholder(size: [u32; 2], message: &str) -> RgbaImage {
    let mut buffer = vec![0u8; (size[0] * size[1] * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (size[0], size[1])).into_drawing_area();
        let _ = root.fill(&RGBColor(225, 225, 228));
        let style = TextStyle::from(("sans-serif", 14).into_font()).color(&RGBColor(120, 30, 30));
        for (i, line) in wrap(message, (size[0] as usize / 8).max(10)).iter().enumerate() {
            let _ = root.draw_text(line, &style, (10, 10 + 18 * i as i32));
        }
        let _ = root.present();
    }
    let rgb = RgbImage::from_raw(size[0], size[1], buffer).expect("w × h × 3 bytes");
    image::DynamicImage::ImageRgb8(rgb).to_rgba8()
}

/// Splits `text` into lines of at most `width` characters at spaces.
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// Writes an RGB buffer as a PNG, whole or not at all, compressed as far as the encoder
/// goes (the cards are committed under docs/).
pub fn save_png(path: &Path, buffer: Vec<u8>, size: (u32, u32)) -> Result<(), String> {
    crate::io::write::png_file(path, &buffer, size, 3, crate::io::write::Effort::Smallest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_words_whole_and_lines_short() {
        assert_eq!(wrap("no graphics adapter found here", 12), ["no graphics", "adapter", "found here"]);
        assert!(wrap("", 10).is_empty());
    }

    #[test]
    fn blit_clips_at_the_edges() {
        let mut buffer = vec![0u8; 4 * 3 * 3];
        let picture = RgbaImage::from_pixel(3, 3, image::Rgba([9, 8, 7, 255]));
        blit(&mut buffer, 4, &picture, (2, 1));
        // Row 0 untouched; rows 1 and 2 painted in columns 2 and 3 only.
        assert!(buffer[..12].iter().all(|&b| b == 0));
        assert_eq!(&buffer[12 + 6..12 + 12], &[9, 8, 7, 9, 8, 7]);
        assert_eq!(&buffer[12..12 + 6], &[0; 6]);
    }
}
