//! A pinned fabric: the picture and numbers of one fabric's result, kept beside the live
//! view while another fabric is edited and run on the same scene, so that a designer can
//! compare as they go. The window renders the picture (it has the GPU); this keeps it and
//! lays out the comparison.

use super::worker::Snapshot;
use crate::scene::measures::Scalar;
use egui::Color32;

/// What was pinned.
pub struct Pinned {
    /// The fabric's name then.
    pub fabric: String,
    /// The scene it ran on.
    pub scene: String,
    /// Simulated time of the picture, s, and when the cloth had settled, if it had.
    pub time: f64,
    pub settled_at: Option<f64>,
    /// The scene's scalar measures then, by name.
    pub measures: Vec<(&'static str, Scalar)>,
    /// The view as it was drawn.
    pub picture: image::RgbaImage,
    texture: Option<egui::TextureHandle>,
}

impl Pinned {
    /// Pins `snapshot`'s fabric and measures with `picture`, the live view as drawn.
    pub fn new(snapshot: &Snapshot, picture: image::RgbaImage) -> Self {
        let fabric = &snapshot.config.fabric;
        let name = if fabric.name.is_empty() { fabric.preset.clone().unwrap_or_else(|| "fabric".into()) } else { fabric.name.clone() };
        Self {
            fabric: name,
            scene: snapshot.scene_name.clone(),
            time: snapshot.time,
            settled_at: snapshot.settled_at,
            measures: snapshot.measures.scalars(),
            picture,
            texture: None,
        }
    }

    /// The pinned picture and its measures beside the live ones. Returns true when the user
    /// unpins it.
    pub fn show(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot) -> bool {
        let mut unpin = false;
        ui.horizontal(|ui| {
            ui.heading("Pinned");
            unpin = ui.small_button("unpin").clicked();
        });
        ui.label(format!("{} on {}", self.fabric, self.scene));
        let state = match self.settled_at {
            Some(t) => format!("settled at t = {t:.2} s"),
            None => format!("at t = {:.2} s, not settled", self.time),
        };
        ui.small(state);
        let texture = self.texture.get_or_insert_with(|| {
            let size = [self.picture.width() as usize, self.picture.height() as usize];
            let image = egui::ColorImage::from_rgba_unmultiplied(size, self.picture.as_raw());
            ui.ctx().load_texture("pinned fabric", image, egui::TextureOptions::LINEAR)
        });
        let width = ui.available_width().clamp(120.0, 420.0);
        let size = texture.size_vec2();
        ui.image((texture.id(), egui::vec2(width, width * size.y / size.x.max(1.0))));
        if snapshot.scene_name != self.scene {
            ui.colored_label(Color32::from_rgb(230, 160, 40), format!("Pinned on {}; the live scene is {}.", self.scene, snapshot.scene_name));
        }
        let live = snapshot.measures.scalars();
        egui::Grid::new("pinned_measures").num_columns(3).striped(true).show(ui, |ui| {
            ui.strong("measure");
            ui.strong("pinned");
            ui.strong("live");
            ui.end_row();
            for (name, value) in &self.measures {
                let unit = unit(name);
                ui.label(if unit.is_empty() { name.to_string() } else { format!("{name} ({unit})") });
                ui.monospace(short(*value));
                let now = live.iter().find(|(n, _)| n == name).map_or("–".to_string(), |(_, v)| short(*v));
                ui.monospace(now);
                ui.end_row();
            }
        });
        unpin
    }
}

/// A measure to four significant figures (a count as it is).
fn short(value: Scalar) -> String {
    match value {
        Scalar::Count(n) => n.to_string(),
        Scalar::Real(x) if x == 0.0 || (1e-3..1e4).contains(&x.abs()) => format!("{x:.4}"),
        Scalar::Real(x) => format!("{x:.3e}"),
    }
}

/// The unit of a rig's scalar measure (`scene::measures`; SI, angles in degrees).
pub fn unit(name: &str) -> &'static str {
    match name {
        "final_stress" | "critical_load" | "end_force" | "euler_load" => "N/m",
        "bending_length" | "tip_drop" | "tip_reach" | "outline_radius_max" | "outline_radius_min" | "midspan_deflection"
        | "wrinkle_amplitude" | "wrinkle_wavelength" => "m",
        "shadow_area" | "specimen_area" | "support_area" => "m²",
        "curvature" => "1/m",
        "moment" => "N·m/m",
        "rigidity" => "N·m",
        "compression_speed" => "m/s",
        n if n.ends_with("_deg") => "°",
        _ => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::measures::{DrapeMeasures, Measures};

    #[test]
    fn every_scalar_with_a_dimension_has_its_unit() {
        // The dimensionless ones, by the definitions in scene::measures.
        let bare = ["final_strain", "poisson_ratio", "lambda", "end_shortening", "lobes", "out_of_balance", "wrinkle_count", "drape_coefficient", "nodes"];
        let drape = Measures::Drape(DrapeMeasures { outline_radius_min: Some(0.1), ..Default::default() });
        for (name, _) in drape.scalars() {
            assert_eq!(unit(name).is_empty(), bare.contains(&name), "{name}");
        }
        assert_eq!(short(Scalar::Real(0.48212)), "0.4821");
        assert_eq!(short(Scalar::Count(8)), "8");
        assert_eq!(short(Scalar::Real(2.5e-6)), "2.500e-6");
    }

    #[test]
    fn a_pinned_fabric_lays_out_beside_the_live_one() {
        use crate::app::ui::ViewerUi;
        use crate::app::worker::{Command, Worker};
        let (config, _) = crate::scene::load_scene("cusick-drape-30", &[]).unwrap();
        let worker = Worker::spawn("cusick-drape-30", config, None).unwrap();
        worker.send(Command::Step);
        let snapshot = worker.sync(std::time::Duration::from_secs(60));
        let mut ui_state = ViewerUi::default();
        ui_state.pinned = Some(Pinned::new(&snapshot, image::RgbaImage::new(48, 32)));
        ui_state.card.open = true;
        let pinned = ui_state.pinned.as_ref().unwrap();
        assert_eq!(pinned.scene, "cusick-drape-30");
        assert!(pinned.measures.iter().any(|(n, _)| *n == "drape_coefficient"));
        let ctx = egui::Context::default();
        let input = egui::RawInput { screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))), ..Default::default() };
        let mut actions = Vec::new();
        ctx.run_ui(input, |ui| actions = ui_state.show(ui, &snapshot)).drop_without_applying_deltas();
        assert!(actions.is_empty(), "{actions:?}");
        assert!(ui_state.view_rect.width() > 100.0, "the 3D view keeps room beside the pinned panel");
    }
}
