//! The swatch beside the fabric editor: a strip of the fabric in its look (colour, weave or
//! print, sheen), drawn on the CPU by `appearance::shade::swatch`, with the look in words,
//! or what is wrong with the fabric's `[appearance]`.

use crate::appearance::{Look, shade};
use crate::settings::FabricConfig;
use std::path::Path;

/// The swatch's size, pixels.
const SIZE: [u32; 2] = [280, 84];

/// The swatch shown, and the look it was drawn for (drawn again when that changes).
#[derive(Default)]
pub struct Swatch {
    drawn: Option<(String, egui::TextureHandle)>,
}

impl Swatch {
    /// Shows `fabric`'s look; a relative texture path is taken against `base_dir`.
    pub fn show(&mut self, ui: &mut egui::Ui, fabric: &FabricConfig, base_dir: Option<&Path>) {
        let look = match Look::check(&fabric.appearance, base_dir) {
            Ok(look) => look,
            Err(e) => {
                ui.colored_label(egui::Color32::from_rgb(190, 30, 30), format!("fabric.{}: {}", e.key, e.message));
                return;
            }
        };
        let summary = look.summary();
        if self.drawn.as_ref().is_none_or(|(s, _)| *s != summary) {
            let image = shade::swatch(&look, SIZE);
            let pixels = egui::ColorImage::from_rgba_unmultiplied([SIZE[0] as usize, SIZE[1] as usize], image.as_raw());
            self.drawn = Some((summary.clone(), ui.ctx().load_texture("fabric swatch", pixels, egui::TextureOptions::LINEAR)));
        }
        if let Some((_, texture)) = &self.drawn {
            let width = ui.available_width().clamp(120.0, SIZE[0] as f32);
            ui.image((texture.id(), egui::vec2(width, width * SIZE[1] as f32 / SIZE[0] as f32)))
                .on_hover_text("the fabric's [appearance]: a strip in two folds, lit from the upper left, warp across");
        }
        ui.small(summary);
    }
}
