//! A garment's pattern in the viewer: each panel's grain, editable, a straight / bias
//! switch that recuts every panel at once, and the flat pattern drawn in its own window
//! with the grain lines and the seams' pairs (`garment::flat`). The pattern drawn follows
//! the grains being edited before the garment is recut.
//!
//! Sewing by clicks: with *Sew by clicks* on, two clicks on one panel's outline pick a
//! stretch (from the first point to the second, the shorter way round; a click near a
//! corner or a notch takes it exactly), two on another's pick the stretch sewn to it,
//! first point to first point. The seam appears at once in its colour, with both
//! stretches' lengths and their difference; a stretch that turns a corner is cut there
//! into seams of one edge each (`garment::stretch`), and a seam the pattern cannot take
//! (sides differing beyond `garment.seam_ease`, a stretch already sewn) is refused with the
//! reason. *Sew* hands the pattern with its new seams to the running scene, which is built
//! again and sewn from flat panels; *File → Save scene* then writes the scene with them.

use super::action::Action;
use super::worker::{Command, Snapshot};
use crate::garment::flat::{FlatPattern, along};
use crate::garment::seams::SeamConfig;
use crate::garment::stretch::{Outline, Stretch};
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
    /// The flat pattern for `grains` and the seams added by clicks (or why it could not be
    /// drawn).
    flat: Option<Result<FlatPattern, String>>,
    /// Clicks on the outlines become seams.
    pub sewing: bool,
    /// Points clicked towards the next seam: (panel, distance along its outline in the
    /// garment's units), two on one panel, then two on another.
    clicks: Vec<(usize, f64)>,
    /// Seams added by clicks, not yet handed to the scene, each click's seams together.
    added: Vec<Vec<SeamConfig>>,
    /// What the last click gave: the seam's lengths, or why it was refused.
    pub note: Option<String>,
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

    /// Takes the scene's grains when the scene is rebuilt, and drops the clicks and the
    /// seams added on the pattern before.
    fn follow(&mut self, garment: &GarmentConfig, generation: u64) {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            self.clicks.clear();
            self.added.clear();
            self.set_grains(garment.panels.iter().map(|p| p.grain_deg).collect(), garment);
        }
    }

    fn set_grains(&mut self, grains: Vec<f64>, garment: &GarmentConfig) {
        self.grains = grains;
        self.refresh(garment);
    }

    /// The scene's garment with the grains being edited and the seams added by clicks.
    fn edited(&self, garment: &GarmentConfig) -> GarmentConfig {
        let mut edited = garment.clone();
        for (panel, grain) in edited.panels.iter_mut().zip(&self.grains) {
            panel.grain_deg = *grain;
        }
        edited.seams.extend(self.added.iter().flatten().cloned());
        edited
    }

    fn refresh(&mut self, garment: &GarmentConfig) {
        self.flat = Some(FlatPattern::new(&self.edited(garment), None).map_err(|e| e.to_string()));
    }

    /// A click at `at` (m, in the flat pattern's laid-out plane) while sewing: the nearest
    /// outline point within `reach` (m), a named point there within `reach` taken exactly.
    /// The fourth click makes the seam, or says why it cannot be.
    pub fn click(&mut self, at: DVec2, reach: f64, snapshot: &Snapshot) -> Result<(), String> {
        let garment = snapshot.config.garment.as_ref().ok_or("the scene is not a garment: it has no outlines to sew")?;
        self.follow(garment, snapshot.scene_generation);
        let Some(Ok(flat)) = &self.flat else { return Err("the flat pattern cannot be drawn, so it cannot be sewn".into()) };
        let mut best: Option<(usize, f64, f64)> = None;
        for (p, panel) in flat.panels.iter().enumerate() {
            let n = panel.outline.len();
            for k in 0..n {
                let (a, b) = (panel.outline[k], panel.outline[(k + 1) % n]);
                let ab = b - a;
                let t = if ab.length_squared() > 0.0 { ((at - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
                let d = at.distance(a + t * ab);
                if best.is_none_or(|x| d < x.2) {
                    best = Some((p, panel.arc[k] + t * (panel.arc[k + 1] - panel.arc[k]), d));
                }
            }
        }
        let Some((panel, mut position, distance)) = best.filter(|b| b.2 <= reach) else {
            return Err("click on a panel's outline".into());
        };
        if let Some((_, point_at, _)) = flat.panels[panel].points.iter().filter(|(_, _, q)| q.distance(at) <= reach).min_by(|x, y| x.2.distance(at).total_cmp(&y.2.distance(at))) {
            position = *point_at;
        }
        let _ = distance;
        // Two clicks on one panel make a stretch; a second click on another panel starts
        // the stretch again there.
        if self.clicks.len() % 2 == 1 && self.clicks.last().is_some_and(|c| c.0 != panel) {
            self.clicks.pop();
        }
        self.clicks.push((panel, position));
        self.note = None;
        if self.clicks.len() < 4 {
            return Ok(());
        }
        let clicks = std::mem::take(&mut self.clicks);
        let edited = self.edited(garment);
        let outlines: Vec<Outline> = edited.panels.iter().map(Outline::new).collect::<Result<_, _>>().map_err(|e| e.to_string())?;
        let stretch = |(p, from): (usize, f64), (_, to): (usize, f64)| Stretch::shorter(p, from, to, outlines[p].perimeter);
        let (a, b) = (stretch(clicks[0], clicks[1]), stretch(clicks[2], clicks[3]));
        let seams = crate::garment::stretch::seams(&edited.panels, &outlines, a, b).map_err(|e| e.to_string())?;
        // The pattern with the new seams must still be one a run takes: sides within the
        // ease, no stretch sewn twice.
        let mut trial = edited.clone();
        trial.seams.extend(seams.iter().cloned());
        let measurements = trial.form.measurements(trial.units).map_err(|e| e.to_string())?;
        let levels = |level: &str| measurements.and_then(|m| m.level(level));
        if let Err(e) = crate::garment::build(&trial, COARSE_EDGE, glam::DVec2::ZERO, &levels) {
            let message = format!("not sewn: {e}");
            self.note = Some(message.clone());
            return Err(message);
        }
        let (la, lb) = (a.length(outlines[a.panel].perimeter), b.length(outlines[b.panel].perimeter));
        let unit = edited.units.name();
        self.note = Some(format!(
            "seam {}: {} {la:.1} {unit} to {} {lb:.1} {unit}, difference {:.1} {unit} ({:.1} %){}",
            edited.seams.len() + 1,
            edited.panels[a.panel].name,
            edited.panels[b.panel].name,
            (la - lb).abs(),
            100.0 * (la - lb).abs() / la.max(lb),
            if seams.len() > 1 { format!(", cut at the corners into {} seams", seams.len()) } else { String::new() }
        ));
        self.added.push(seams);
        self.refresh(garment);
        Ok(())
    }

    /// The seams added by clicks and not yet handed to the scene.
    pub fn added(&self) -> usize {
        self.added.iter().map(Vec::len).sum()
    }

    /// *Sew*: the pattern with its new seams (and the grains being edited) goes to the
    /// running scene, which is built again and sewn from flat panels.
    pub fn sew(&mut self, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        let Some(garment) = &snapshot.config.garment else { return };
        if self.added.is_empty() {
            return;
        }
        let mut config = (*snapshot.config).clone();
        config.garment = Some(self.edited(garment));
        actions.push(Action::Send(Command::LoadEdited { name: snapshot.scene_name.clone(), config: Box::new(config) }));
        actions.push(Action::Send(Command::Play));
    }

    /// The flat pattern window, for a garment scene.
    pub fn show(&mut self, ctx: &egui::Context, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        let Some(garment) = snapshot.config.garment.clone() else { return };
        self.follow(&garment, snapshot.scene_generation);
        let mut open = self.open;
        let mut clicked = None;
        egui::Window::new("Flat pattern").open(&mut open).default_size([520.0, 380.0]).show(ctx, |ui| {
            ui.horizontal(|ui| {
                ui.toggle_value(&mut self.sewing, "Sew by clicks")
                    .on_hover_text("click two points on one outline, then two on another: the stretches between them are sewn, first point to first point");
                let added = self.added();
                if ui.add_enabled(added > 0, egui::Button::new(format!("Sew {added} new seam(s)"))).on_hover_text("build the garment again with them and sew it; File → Save scene keeps them").clicked() {
                    self.sew(snapshot, actions);
                }
                if ui.add_enabled(!self.added.is_empty() || !self.clicks.is_empty(), egui::Button::new("Undo")).clicked() {
                    if self.clicks.is_empty() {
                        self.added.pop();
                    }
                    self.clicks.clear();
                    self.note = None;
                    self.refresh(&garment);
                }
            });
            if let Some(note) = &self.note {
                ui.small(note);
            }
            match &self.flat {
                Some(Ok(flat)) => {
                    ui.small("Panels as cut (right side up). Lines with arrows: the grain (warp). Coloured edges: seams, numbered in pairs, their lengths below; a dot marks the ends sewn together. Ticks: corners and notches.");
                    let size = (ui.available_size() - vec2(0.0, 18.0 * flat.seams.len().min(8) as f32)).max(vec2(200.0, 140.0));
                    let sense = if self.sewing { egui::Sense::click() } else { egui::Sense::hover() };
                    let (response, painter) = ui.allocate_painter(size, sense);
                    let view = View::fit(response.rect, flat);
                    draw(&painter, &view, flat, &self.clicks);
                    if response.clicked()
                        && let Some(pos) = response.interact_pointer_pos()
                    {
                        clicked = Some((view.to_pattern(pos), CLICK_REACH / view.scale));
                    }
                    egui::Grid::new("seam lengths").num_columns(2).show(ui, |ui| {
                        for (i, seam) in flat.seams.iter().enumerate() {
                            ui.colored_label(SEAM_COLOURS[i % SEAM_COLOURS.len()], format!("{}", i + 1));
                            let [la, lb] = seam.lengths;
                            let unit = flat.units.name();
                            ui.small(format!("{la:.1} and {lb:.1} {unit}, difference {:.1} {unit}", (la - lb).abs()));
                            ui.end_row();
                        }
                    });
                }
                Some(Err(e)) => {
                    ui.colored_label(Color32::from_rgb(255, 110, 100), e);
                }
                None => {}
            }
        });
        if let Some((at, reach)) = clicked
            && let Err(e) = self.click(at, reach, snapshot)
        {
            self.note = Some(e);
        }
        self.open = open;
    }
}

/// How near the outline a click must fall, pixels.
const CLICK_REACH: f64 = 10.0;

/// The mesh edge at which a pattern with a new seam is checked, m: coarse, since only the
/// seams' lengths and stretches are checked, not the cloth.
const COARSE_EDGE: f64 = 0.05;

/// The flat pattern fitted into a rectangle of the window, y up.
struct View {
    centre: DVec2,
    /// Pixels per metre.
    scale: f64,
    middle: Pos2,
}

impl View {
    fn fit(rect: egui::Rect, flat: &FlatPattern) -> Self {
        let (lo, hi) = flat.bounds();
        let margin = 18.0;
        let span = (hi - lo).max(DVec2::splat(1e-6));
        let scale = ((rect.width() - 2.0 * margin) as f64 / span.x).min((rect.height() - 2.0 * margin) as f64 / span.y).max(1e-9);
        Self { centre: 0.5 * (lo + hi), scale, middle: rect.center() }
    }

    fn to_screen(&self, p: DVec2) -> Pos2 {
        let d = (p - self.centre) * self.scale;
        pos2(self.middle.x + d.x as f32, self.middle.y - d.y as f32)
    }

    fn to_pattern(&self, p: Pos2) -> DVec2 {
        self.centre + DVec2::new((p.x - self.middle.x) as f64, (self.middle.y - p.y) as f64) / self.scale
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

/// Draws `flat` as `view` fits it, with the points clicked towards the next seam.
fn draw(painter: &egui::Painter, view: &View, flat: &FlatPattern, clicks: &[(usize, f64)]) {
    let to_screen = |p: DVec2| view.to_screen(p);
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
    // Corners and notches: a tick into the panel, named.
    let mark = Color32::from_gray(160);
    for panel in &flat.panels {
        for (name, at, position) in &panel.points {
            let p = to_screen(*position);
            let ahead = to_screen(along(&panel.outline, &panel.arc, at + 1e-3 * panel.arc.last().unwrap_or(&1.0)));
            let inwards = (ahead - p).normalized().rot90() * -6.0;
            painter.line_segment([p, p + inwards], Stroke::new(1.5, mark));
            painter.text(p + inwards * 1.6, egui::Align2::CENTER_CENTER, name, egui::FontId::proportional(9.0), mark);
        }
    }
    // The clicks towards the next seam, and the stretch the first two pick.
    let white = Stroke::new(3.0, Color32::WHITE);
    for pair in clicks.chunks(2) {
        let panel = &flat.panels[pair[0].0];
        if let [(_, from), (_, to)] = pair {
            let perimeter = *panel.arc.last().unwrap_or(&0.0);
            let stretch = Stretch::shorter(pair[0].0, *from, *to, perimeter);
            let length = stretch.length(perimeter);
            let sign = if stretch.counter_clockwise { 1.0 } else { -1.0 };
            let points: Vec<Pos2> = (0..=48).map(|k| to_screen(along(&panel.outline, &panel.arc, from + sign * length * k as f64 / 48.0))).collect();
            painter.add(Shape::line(points, white));
        }
        for (_, at) in pair {
            painter.circle_filled(to_screen(along(&panel.outline, &panel.arc, *at)), 4.0, Color32::WHITE);
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
                view.show(ui.ctx(), snapshot, &mut actions);
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

    /// Sewing by clicks on a DXF pattern imported without seams: the front's side from its
    /// waist corner to its hem corner, then the back's, makes one seam of two sides drafted
    /// equal (62.0 cm), which *Sew* hands to the running scene and *Save scene* writes; the
    /// same stretches clicked again are refused, being sewn already.
    #[test]
    fn clicks_on_two_outlines_sew_them_into_the_scene() {
        use crate::app::worker::Worker;
        use std::time::Duration;
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/patterns/aline-skirt-aama.dxf");
        let (config, _) = crate::scene::load_scene(path, &["mesh.edge_length=0.05".into()]).unwrap();
        assert!(config.garment.as_ref().unwrap().seams.is_empty());
        let worker = Worker::spawn("aline-skirt-aama", config, None).unwrap();
        let snapshot = worker.sync(Duration::from_secs(120));
        let mut view = PatternView { open: true, sewing: true, ..PatternView::default() };
        view.follow(snapshot.config.garment.as_ref().unwrap(), snapshot.scene_generation);
        let Some(Ok(flat)) = view.flat.clone() else { panic!("no flat pattern: {:?}", view.flat) };
        let point = |panel: &str, name: &str| {
            let p = flat.panels.iter().find(|p| p.name == panel).unwrap();
            p.points.iter().find(|q| q.0 == name).unwrap().2
        };
        let clicks = [("front", "c3"), ("front", "c2"), ("back-left", "c3"), ("back-left", "c2")];
        for (panel, name) in clicks {
            view.click(point(panel, name), 1e-3, &snapshot).unwrap();
        }
        assert_eq!(view.added(), 1);
        let note = view.note.clone().unwrap();
        assert!(note.contains("front 62.0 cm to back-left 62.0 cm, difference 0.0 cm"), "{note}");
        for (k, (panel, name)) in clicks.into_iter().enumerate() {
            let result = view.click(point(panel, name), 1e-3, &snapshot);
            assert_eq!(result.is_err(), k == 3, "{result:?}");
        }
        assert_eq!(view.added(), 1);
        let mut actions = Vec::new();
        view.sew(&snapshot, &mut actions);
        let Some(Action::Send(command)) = actions.into_iter().next() else { panic!("no command") };
        worker.send(command);
        let after = worker.sync(Duration::from_secs(120));
        assert!(after.scene_generation > snapshot.scene_generation && after.error.is_none(), "{:?}", after.error);
        let seams = &after.config.garment.as_ref().unwrap().seams;
        assert_eq!((seams.len(), seams[0].a.as_str(), seams[0].b.as_str()), (1, "front.e2", "back-left.e3"));
        let saved = crate::app::files::scene_toml(&after.config).unwrap();
        assert!(saved.contains("front.e2") && saved.contains("back-left.e3"), "{saved}");
    }
}
