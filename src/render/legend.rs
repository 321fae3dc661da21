//! The colour legend drawn into the image: a vertical bar of the map's scale with its top,
//! middle and bottom values and the map's title, on a light panel at the right edge.
//! Built as 2D triangles for the overlay pipeline (`shaders/overlay.wgsl`).

use super::colormap::{ColorMap, ScalarField};
use super::font;
use bytemuck::{Pod, Zeroable};

/// What an overlay vertex's fragment shows.
pub const SOLID: f32 = 0.0;
/// The gradient texture at `uv`.
pub const GRADIENT: f32 = 1.0;
/// The font atlas texel at `uv` (in texels) as coverage of `color`.
pub const GLYPH: f32 = 2.0;

/// One vertex of the overlay: clip-space position, texture coordinate, sRGB colour with
/// alpha, and the fragment mode.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct OverlayVertex {
    pub position: [f32; 2],
    pub uv: [f32; 2],
    pub color: [f32; 4],
    pub mode: f32,
}

/// Rows of the gradient texture: one per colour map, in `ColorMap::ALL` order.
pub const GRADIENT_ROWS: u32 = ColorMap::ALL.len() as u32;

const PANEL: [f32; 4] = [0.97, 0.97, 0.98, 0.85];
const INK: [f32; 4] = [0.08, 0.08, 0.10, 1.0];

struct Builder {
    width: f32,
    height: f32,
    vertices: Vec<OverlayVertex>,
}

impl Builder {
    /// A rectangle in pixels (x right, y down from the top-left corner) with texture
    /// coordinates at its corners: top-left, top-right, bottom-right, bottom-left.
    fn quad(&mut self, [x0, y0, x1, y1]: [f32; 4], uv: [[f32; 2]; 4], color: [f32; 4], mode: f32) {
        let ndc = |x: f32, y: f32| [2.0 * x / self.width - 1.0, 1.0 - 2.0 * y / self.height];
        let corner = |x: f32, y: f32, uv: [f32; 2]| OverlayVertex { position: ndc(x, y), uv, color, mode };
        let (a, b, c, d) = (corner(x0, y0, uv[0]), corner(x1, y0, uv[1]), corner(x1, y1, uv[2]), corner(x0, y1, uv[3]));
        self.vertices.extend_from_slice(&[a, b, c, a, c, d]);
    }

    /// A rectangle with u running left to right and v top to bottom over `[u0, v0, u1, v1]`.
    fn rect(&mut self, rect: [f32; 4], [u0, v0, u1, v1]: [f32; 4], color: [f32; 4], mode: f32) {
        self.quad(rect, [[u0, v0], [u1, v0], [u1, v1], [u0, v1]], color, mode);
    }

    fn solid(&mut self, rect: [f32; 4], color: [f32; 4]) {
        self.rect(rect, [0.0; 4], color, SOLID);
    }

    /// Text with its top-left corner at (x, y), glyphs `scale` pixels per font texel.
    fn text(&mut self, text: &str, x: f32, y: f32, scale: f32) {
        for (i, c) in text.chars().enumerate() {
            let cell = font::cell(c) as f32;
            let (cw, ch) = (font::CELL_W as f32, font::CELL_H as f32);
            let left = x + i as f32 * cw * scale;
            self.rect([left, y, left + cw * scale, y + ch * scale], [cell * cw, 0.0, (cell + 1.0) * cw, ch], INK, GLYPH);
        }
    }
}

/// Pixels per font texel: one up to 300 px tall images, then whole multiples.
fn text_scale(height: u32) -> f32 {
    (height as f32 / 300.0).floor().max(1.0)
}

/// The legend's colour bar in a `width` × `height` image: [left, top, right, bottom]
/// pixels from the top-left corner; the scale's top value is at the top.
pub fn bar_rect(width: u32, height: u32) -> [f32; 4] {
    let (w, h) = (width as f32, height as f32);
    let s = text_scale(height);
    let bar_h = (0.45 * h).round();
    let bar_x1 = w - 8.0 * s;
    let bar_y0 = (0.5 * (h - bar_h)).round() + 6.0 * s;
    [bar_x1 - 8.0 * s, bar_y0, bar_x1, bar_y0 + bar_h]
}

/// Width at the right edge of an image `height` pixels tall that the legend may cover (its
/// panel is at most this wide), pixels.
pub fn reserved_width(height: u32) -> f32 {
    let s = text_scale(height);
    let longest = ColorMap::ALL.iter().map(|m| m.title().len()).max().unwrap_or(0).max(8 + 2) as f32;
    (longest * font::CELL_W as f32 + 12.0) * s
}

/// Width of `text` in pixels at `scale`.
fn text_width(text: &str, scale: f32) -> f32 {
    text.chars().count() as f32 * font::CELL_W as f32 * scale
}

/// The legend of `field` for a `width` × `height` pixel image.
pub fn legend(field: &ScalarField, width: u32, height: u32) -> Vec<OverlayVertex> {
    let (w, h) = (width as f32, height as f32);
    let mut b = Builder { width: w, height: h, vertices: Vec::new() };
    let s = text_scale(height);
    let pad = 4.0 * s;
    let [bar_x0, bar_y0, bar_x1, bar_y1] = bar_rect(width, height);
    let mid = 0.5 * (field.min + field.max);
    let labels = [(field.max, bar_y0), (mid, 0.5 * (bar_y0 + bar_y1)), (field.min, bar_y1)];
    let extent = field.min.abs().max(field.max.abs());
    let texts: Vec<String> = labels.iter().map(|(v, _)| format_value(*v, extent, field.map.signed())).collect();
    let widest = texts.iter().map(|t| text_width(t, s)).fold(0.0f32, f32::max);
    let title = field.map.title();
    let label_x1 = bar_x0 - 2.0 * s - 3.0 * s;
    let title_y = bar_y0 - (font::CELL_H as f32 + 6.0) * s;
    let left = (label_x1 - widest).min(bar_x1 - text_width(title, s)) - pad;
    b.solid([left, title_y - pad, w - pad, bar_y1 + font::CELL_H as f32 * 0.5 * s + pad], PANEL);
    b.text(title, bar_x1 - text_width(title, s), title_y, s);
    // The bar: t = 1 at the top.
    let v = (field.map.row() as f32 + 0.5) / GRADIENT_ROWS as f32;
    b.quad([bar_x0, bar_y0, bar_x1, bar_y1], [[1.0, v], [1.0, v], [0.0, v], [0.0, v]], [1.0; 4], GRADIENT);
    let frame = s.max(1.0);
    b.solid([bar_x0 - frame, bar_y0 - frame, bar_x1 + frame, bar_y0], INK);
    b.solid([bar_x0 - frame, bar_y1, bar_x1 + frame, bar_y1 + frame], INK);
    b.solid([bar_x0 - frame, bar_y0, bar_x0, bar_y1], INK);
    b.solid([bar_x1, bar_y0, bar_x1 + frame, bar_y1], INK);
    for ((_, y), text) in labels.iter().zip(&texts) {
        b.solid([bar_x0 - 3.0 * s, y - 0.5 * s, bar_x0, y + 0.5 * s], INK);
        let glyph_half = 0.5 * font::GLYPH_H as f32 * s;
        b.text(text, label_x1 - text_width(text, s), (y - glyph_half).round(), s);
    }
    b.vertices
}

/// `value` on a scale reaching `extent` (its largest magnitude): three significant digits
/// of `extent`, the same decimals for every label; signed scales with an explicit '+'.
pub fn format_value(value: f32, extent: f32, signed: bool) -> String {
    let extent = extent.abs();
    let text = if value == 0.0 || !value.is_finite() {
        "0".to_string()
    } else if (1e-3..1e4).contains(&extent) {
        let decimals = (2 - extent.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{value:.decimals$}")
    } else {
        format!("{value:.2e}").to_uppercase()
    };
    if signed && value > 0.0 { format!("+{text}") } else { text }
}

/// The gradient texture: `GRADIENT_TEXELS` × `GRADIENT_ROWS` sRGB texels, RGBA8.
pub fn gradient_texels() -> Vec<u8> {
    let mut texels = Vec::with_capacity((GRADIENT_TEXELS * GRADIENT_ROWS * 4) as usize);
    for map in ColorMap::ALL {
        for i in 0..GRADIENT_TEXELS {
            let c = map.color(i as f32 / (GRADIENT_TEXELS - 1) as f32);
            texels.extend(c.iter().map(|v| (v * 255.0).round() as u8));
            texels.push(255);
        }
    }
    texels
}

/// Texels along each gradient row.
pub const GRADIENT_TEXELS: u32 = 256;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_share_the_decimals_of_the_scale() {
        assert_eq!(format_value(0.0123, 0.0123, true), "+0.0123");
        assert_eq!(format_value(-0.0123, 0.0123, true), "-0.0123");
        assert_eq!(format_value(0.0005, 0.001, false), "0.00050");
        assert_eq!(format_value(6.17, 12.34, false), "6.2");
        assert_eq!(format_value(12.34, 12.34, false), "12.3");
        assert_eq!(format_value(0.0, 0.02, true), "0");
        assert_eq!(format_value(2.5e-5, 5e-5, false), "2.50E-5");
    }

    #[test]
    fn legend_stays_inside_the_image() {
        let field = ScalarField { map: ColorMap::Bending, values: vec![], min: 0.0, max: 12.5 };
        for (w, h) in [(320, 240), (1280, 800)] {
            let vertices = legend(&field, w, h);
            assert!(!vertices.is_empty());
            let reserved_left = 2.0 * (w as f32 - reserved_width(h)) / w as f32 - 1.0;
            for v in vertices {
                assert!(v.position.iter().all(|c| (-1.0..=1.0).contains(c)), "{v:?} in {w}x{h}");
                assert!(v.position[0] >= reserved_left - 1e-6, "{v:?} left of the reserved strip in {w}x{h}");
            }
        }
    }
}
