//! A garment's pattern in the viewer: each panel's grain, editable, a straight / bias
//! switch that recuts every panel at once, and the flat pattern drawn in its own window
//! with the grain lines and the seams' pairs (`garment::flat`). The pattern drawn follows
//! the grains being edited before the garment is recut.

use super::action::Action;
use super::worker::{Command, Snapshot};
use crate::garment::flat::FlatPattern;
use crate::garment::GarmentConfig;
use egui::{Color32, Pos2, Shape, Stroke, pos2, vec2};
use glam::DVec2;

/// The grain of a panel drawn upright that runs the warp down it, degrees.
pub const STRAIGHT_GRAIN: f64 = 90.0;
/// The bias: the warp at 45° to the panel's centre line, degrees.
pub const BIAS_GRAIN: f64 = 45.0;

/// The cut every panel shares, if one does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cut {
    Straight,
    Bias,
    Mixed,
}

/// Which cut `grains` (degrees) are: a grain and its opposite are one line.
pub fn cut_of(grains: &[f64]) -> Cut {
    let line = |g: f64| g.rem_euclid(180.0);
    if grains.iter().all(|&g| (line(g) - STRAIGHT_GRAIN).abs() < 1e-9) {
        Cut::Straight
    } else if grains.iter().all(|&g| [BIAS_GRAIN, 180.0 - BIAS_GRAIN].iter().any(|b| (line(g) - b).abs() < 1e-9)) {
        Cut::Bias
    } else {
        Cut::Mixed
    }
}

/// State of the pattern section and window between frames.
#[derive(Default)]
pub struct PatternView {
    /// The flat pattern window is shown.
    pub open: bool,
    /// Grains being edited, degrees, one per panel: the scene's whenever it is rebuilt.
    grains: Vec<f64>,
    generation: Option<u64>,
    /// The flat pattern for `grains` (or why it could not be drawn).
    flat: Option<Result<FlatPattern, String>>,
}

impl PatternView {
    /// The left panel's section for a garment scene: a grain per panel, the straight / bias
    /// switch (applied at once) and *Recut* for edited grains. Nothing for other scenes.
    pub fn panel(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        let Some(garment) = &snapshot.config.garment else { return };
        self.follow(garment, snapshot.scene_generation);
        let scene_grains: Vec<f64> = garment.panels.iter().map(|p| p.grain_deg).collect();
        ui.heading("Pattern");
        ui.horizontal(|ui| {
            ui.label("cut");
            let cut = cut_of(&self.grains);
            for (label, target, hover) in [
                ("straight", Cut::Straight, "every panel's warp down its centre line (grain 90°)"),
                ("bias", Cut::Bias, "every panel's warp at 45° to its centre line: soft in tension and shear, it hangs closer"),
            ] {
                if ui.selectable_label(cut == target, label).on_hover_text(hover).clicked() && cut != target {
                    self.cut(target, garment, actions);
                }
            }
            if cut == Cut::Mixed {
                ui.label("(mixed)");
            }
        });
        let mut edited = self.grains.clone();
        egui::Grid::new("grains").num_columns(2).show(ui, |ui| {
            for (panel, grain) in garment.panels.iter().zip(&mut edited) {
                ui.label(&panel.name);
                ui.add(egui::DragValue::new(grain).range(-360.0..=360.0).speed(1.0).suffix("° grain"))
                    .on_hover_text("the warp's angle from the panel's x axis: 90 straight, 45 or 135 bias");
                ui.end_row();
            }
        });
        if edited != self.grains {
            self.set_grains(edited, garment);
        }
        ui.horizontal(|ui| {
            let changed = self.grains != scene_grains;
            if ui
                .add_enabled(changed, egui::Button::new("Recut"))
                .on_hover_text("cut the panels again on these grains: a sewn garment re-drapes where it hangs")
                .clicked()
            {
                self.recut(snapshot, actions);
            }
            ui.toggle_value(&mut self.open, "Flat pattern").on_hover_text("the panels as cut, their grain lines and seams");
        });
    }

    /// The straight / bias switch: every panel recut on `cut` at once.
    fn cut(&mut self, cut: Cut, garment: &GarmentConfig, actions: &mut Vec<Action>) {
        let grain = match cut {
            Cut::Straight => STRAIGHT_GRAIN,
            Cut::Bias => BIAS_GRAIN,
            Cut::Mixed => return,
        };
        self.set_grains(vec![grain; self.grains.len()], garment);
        actions.push(Action::Send(Command::SetGrains(self.grains.clone())));
    }

    /// The straight / bias switch, clicked for `snapshot`'s garment; nothing where the
    /// garment is already cut so.
    pub fn choose_cut(&mut self, cut: Cut, snapshot: &Snapshot, actions: &mut Vec<Action>) -> Result<(), String> {
        let garment = snapshot.config.garment.as_ref().ok_or("the scene is not a garment: it has no pattern to recut")?;
        self.follow(garment, snapshot.scene_generation);
        if cut_of(&self.grains) != cut {
            self.cut(cut, garment, actions);
        }
        Ok(())
    }

    /// A panel's grain typed into the editor, degrees (not yet recut).
    pub fn edit_grain(&mut self, panel: &str, degrees: f64, snapshot: &Snapshot) -> Result<(), String> {
        let garment = snapshot.config.garment.as_ref().ok_or("the scene is not a garment: it has no panels")?;
        self.follow(garment, snapshot.scene_generation);
        let index = garment.panels.iter().position(|p| p.name == panel).ok_or_else(|| format!("no panel '{panel}'"))?;
        let mut grains = self.grains.clone();
        grains[index] = degrees;
        self.set_grains(grains, garment);
        Ok(())
    }

    /// *Recut*: the grains being edited go to the worker, where they differ from the scene's.
    pub fn recut(&mut self, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        let Some(garment) = &snapshot.config.garment else { return };
        if garment.panels.iter().map(|p| p.grain_deg).ne(self.grains.iter().copied()) {
            actions.push(Action::Send(Command::SetGrains(self.grains.clone())));
        }
    }

    /// Takes the scene's grains when the scene is rebuilt.
    fn follow(&mut self, garment: &GarmentConfig, generation: u64) {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            self.set_grains(garment.panels.iter().map(|p| p.grain_deg).collect(), garment);
        }
    }

    fn set_grains(&mut self, grains: Vec<f64>, garment: &GarmentConfig) {
        self.flat = Some(FlatPattern::new(garment, Some(&grains)).map_err(|e| e.to_string()));
        self.grains = grains;
    }

    /// The flat pattern window, for a garment scene.
    pub fn show(&mut self, ctx: &egui::Context, snapshot: &Snapshot) {
        let Some(garment) = &snapshot.config.garment else { return };
        self.follow(garment, snapshot.scene_generation);
        let mut open = self.open;
        egui::Window::new("Flat pattern").open(&mut open).default_size([460.0, 320.0]).show(ctx, |ui| match &self.flat {
            Some(Ok(flat)) => {
                ui.small("Panels as cut (right side up). Lines with arrows: the grain (warp). Coloured edges: seams, numbered in pairs; a dot marks the ends sewn together.");
                let size = ui.available_size().max(vec2(200.0, 140.0));
                let (response, painter) = ui.allocate_painter(size, egui::Sense::hover());
                draw(&painter, response.rect, flat);
            }
            Some(Err(e)) => {
                ui.colored_label(Color32::from_rgb(255, 110, 100), e);
            }
            None => {}
        });
        self.open = open;
    }
}

/// Colours told apart on the dark background, one per seam (repeating past eight).
const SEAM_COLOURS: [Color32; 8] = [
    Color32::from_rgb(240, 120, 90),
    Color32::from_rgb(110, 190, 250),
    Color32::from_rgb(130, 220, 120),
    Color32::from_rgb(240, 200, 80),
    Color32::from_rgb(200, 130, 240),
    Color32::from_rgb(90, 220, 210),
    Color32::from_rgb(250, 150, 200),
    Color32::from_rgb(180, 180, 120),
];

/// Draws `flat` fitted into `rect`, y up.
fn draw(painter: &egui::Painter, rect: egui::Rect, flat: &FlatPattern) {
    let (lo, hi) = flat.bounds();
    let margin = 18.0;
    let span = (hi - lo).max(DVec2::splat(1e-6));
    let scale = ((rect.width() - 2.0 * margin) as f64 / span.x).min((rect.height() - 2.0 * margin) as f64 / span.y).max(1e-9);
    let centre = 0.5 * (lo + hi);
    let to_screen = |p: DVec2| -> Pos2 {
        let d = (p - centre) * scale;
        pos2(rect.center().x + d.x as f32, rect.center().y - d.y as f32)
    };
    let text = Color32::from_gray(220);
    for panel in &flat.panels {
        let outline: Vec<Pos2> = panel.outline.iter().map(|&p| to_screen(p)).collect();
        painter.add(Shape::closed_line(outline, Stroke::new(1.2, Color32::from_gray(200))));
        let top = to_screen(DVec2::new(panel.centre.x, panel.centre.y + 0.5 * panel.size.y));
        painter.text(top + vec2(0.0, -4.0), egui::Align2::CENTER_BOTTOM, &panel.name, egui::FontId::proportional(12.0), text);
        let half = 0.3 * panel.size.min_element();
        let d = DVec2::from_angle(panel.grain) * half;
        let (a, b) = (to_screen(panel.centre - d), to_screen(panel.centre + d));
        let stroke = Stroke::new(1.5, Color32::from_rgb(250, 230, 160));
        painter.line_segment([a, b], stroke);
        for (tip, from) in [(b, a), (a, b)] {
            let along = (tip - from).normalized() * 8.0;
            let across = vec2(-along.y, along.x) * 0.5;
            painter.line_segment([tip, tip - along + across], stroke);
            painter.line_segment([tip, tip - along - across], stroke);
        }
    }
    for (i, seam) in flat.seams.iter().enumerate() {
        let colour = SEAM_COLOURS[i % SEAM_COLOURS.len()];
        for side in [&seam.a, &seam.b] {
            let points: Vec<Pos2> = side.iter().map(|&p| to_screen(p)).collect();
            painter.add(Shape::line(points.clone(), Stroke::new(3.0, colour)));
            painter.circle_filled(points[0], 3.5, colour);
            let middle = points[points.len() / 2];
            painter.text(middle + vec2(6.0, 0.0), egui::Align2::LEFT_CENTER, format!("{}", i + 1), egui::FontId::proportional(12.0), colour);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cut_is_named_by_its_grain_line() {
        assert_eq!(cut_of(&[90.0, -90.0, 270.0]), Cut::Straight);
        assert_eq!(cut_of(&[45.0, 45.0]), Cut::Bias);
        assert_eq!(cut_of(&[135.0, -45.0]), Cut::Bias);
        assert_eq!(cut_of(&[45.0, 90.0]), Cut::Mixed);
        assert_eq!(cut_of(&[45.0, 135.0]), Cut::Bias, "gores mirrored on the bias");
        assert_eq!(cut_of(&[0.0, 0.0]), Cut::Mixed);
    }

    /// The designer's loop on the bundled straight-cut skirt: the section and the window
    /// lay out without asking for anything, a recut on the bias reaches the worker, and the
    /// rebuilt scene's grains come back into the editor.
    #[test]
    fn a_straight_skirt_is_recut_on_the_bias() {
        use crate::app::worker::Worker;
        use std::time::Duration;
        let (config, _) = crate::scene::load_scene("skirt-gored-straight", &[]).unwrap();
        let worker = Worker::spawn("skirt-gored-straight", config, None).unwrap();
        let ctx = egui::Context::default();
        let mut view = PatternView { open: true, ..PatternView::default() };
        let frame = |snapshot: &Snapshot, view: &mut PatternView| {
            let input = egui::RawInput { screen_rect: Some(egui::Rect::from_min_size(Pos2::ZERO, vec2(1280.0, 800.0))), ..Default::default() };
            let mut actions = Vec::new();
            ctx.run_ui(input, |ui| {
                egui::Panel::left("pattern").show(ui, |ui| view.panel(ui, snapshot, &mut actions));
                view.show(ui.ctx(), snapshot);
            })
            .drop_without_applying_deltas();
            actions
        };
        let before = worker.sync(Duration::from_secs(120));
        assert!(frame(&before, &mut view).is_empty());
        assert_eq!(cut_of(&view.grains), Cut::Straight);
        assert!(matches!(view.flat, Some(Ok(_))));
        worker.send(Command::SetGrains(vec![BIAS_GRAIN; view.grains.len()]));
        let after = worker.sync(Duration::from_secs(120));
        assert!(after.scene_generation > before.scene_generation, "the garment was recut");
        assert!(after.error.is_none(), "{:?}", after.error);
        assert!(frame(&after, &mut view).is_empty());
        assert_eq!(cut_of(&view.grains), Cut::Bias);
        let grains: Vec<f64> = after.config.garment.as_ref().unwrap().panels.iter().map(|p| p.grain_deg).collect();
        assert_eq!(grains, view.grains);
    }
}
