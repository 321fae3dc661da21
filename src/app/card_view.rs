//! The Fabric card window: `rosette card` for the fabric being edited, made on its own
//! thread (`rosette-card`, not the solver's) with a progress bar and a cancel button, then
//! shown as the page (an egui texture) and its key numbers, and saved as PNG and JSON.

use super::job::Job;
use crate::card::Made;
use crate::settings::FabricConfig;
use egui::Color32;
use std::time::Duration;

/// How often the window redraws while a card is being made, so that its bar moves.
const PROGRESS_REPAINT: Duration = Duration::from_millis(100);

/// A card being made, and the fabric's name. Dropping it cancels the card and joins the
/// thread.
struct Making {
    job: Job<Result<Made, String>>,
    fabric: String,
}

impl Making {
    fn start(fabric: FabricConfig) -> Result<Self, String> {
        let name = if fabric.name.is_empty() { "fabric".to_string() } else { fabric.name.clone() };
        let job = Job::start("rosette-card", move |progress| {
            crate::card::make(&fabric, "the viewer's fabric", None, progress).map_err(|e| e.to_string())
        })
        .map_err(|e| format!("cannot start the card's thread: {e}"))?;
        Ok(Self { job, fabric: name })
    }

    fn join(self) -> Result<Made, String> {
        self.job.join().unwrap_or_else(|| Err("the card failed unexpectedly (its thread panicked)".into()))
    }
}

/// State of the Fabric card window.
#[derive(Default)]
pub struct CardView {
    pub open: bool,
    making: Option<Making>,
    /// The last card made, and its page as a texture once uploaded.
    made: Option<Made>,
    texture: Option<egui::TextureHandle>,
    message: Option<String>,
    notice: Option<String>,
}

impl CardView {
    /// Starts a card for `fabric` unless one is being made.
    pub fn start(&mut self, fabric: &FabricConfig) {
        if self.making.is_some() {
            return;
        }
        self.notice = None;
        self.message = None;
        match Making::start(fabric.clone()) {
            Ok(m) => self.making = Some(m),
            Err(e) => self.message = Some(e),
        }
    }

    /// Asks the card being made to stop after the tests in progress.
    pub fn cancel(&self) {
        if let Some(m) = &self.making {
            m.job.progress.cancel();
        }
    }

    pub fn busy(&self) -> bool {
        self.making.is_some()
    }

    /// The last card made.
    pub fn made(&self) -> Option<&Made> {
        self.made.as_ref()
    }

    /// Takes a finished card (or its failure) into the window.
    fn poll(&mut self) {
        if !self.making.as_ref().is_some_and(|m| m.job.finished()) {
            return;
        }
        let making = self.making.take().expect("checked");
        let cancelled = making.job.progress.is_cancelled();
        match making.join() {
            Ok(made) => {
                self.message = made.picture_error.as_ref().map(|e| format!("The drape pictures could not be rendered: {e}"));
                self.made = Some(made);
                self.texture = None;
            }
            Err(e) if cancelled => self.notice = Some(format!("Card cancelled: {e}")),
            Err(e) => self.message = Some(format!("Card failed: {e}")),
        }
    }

    /// Writes the card as `rosette-card-NAME.png` and `.json` in the working directory.
    fn save(&mut self) {
        let Some(made) = &self.made else { return };
        let stem: String = made.card.fabric.name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
        let stem = format!("rosette-card-{}", stem.trim_matches('-'));
        match made.write(std::path::Path::new("."), &stem) {
            Ok(paths) => self.notice = Some(format!("saved {} and {}", paths[1].display(), paths[0].display())),
            Err(e) => self.message = Some(e.to_string()),
        }
    }

    /// The window, for `fabric` (the one being edited; `None` before a scene is loaded).
    pub fn show(&mut self, ctx: &egui::Context, fabric: Option<&FabricConfig>) {
        self.poll();
        if !self.open {
            return;
        }
        if self.making.is_some() {
            ctx.request_repaint_after(PROGRESS_REPAINT);
        }
        let mut open = self.open;
        egui::Window::new("Fabric card").open(&mut open).default_size([760.0, 640.0]).show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.contents(ui, fabric));
        });
        self.open = open;
    }

    fn contents(&mut self, ui: &mut egui::Ui, fabric: Option<&FabricConfig>) {
        ui.small(
            "The virtual laboratory on the fabric being edited: KES tensile (warp, weft) and a bias pull, pure bending and \
             the ASTM D1388 cantilever (warp, weft, bias), KES shear and the 30 cm Cusick drape, as `rosette card` makes it. \
             About 10 to 30 CPU seconds, on threads of its own.",
        );
        match (&self.making, fabric) {
            (None, Some(fabric)) => {
                let name = if fabric.name.is_empty() { "this fabric" } else { &fabric.name };
                let valid = fabric.to_fabric();
                if ui.add_enabled(valid.is_ok(), egui::Button::new(format!("Make the card of {name}"))).clicked() {
                    self.start(fabric);
                }
                if let Err(e) = valid {
                    ui.colored_label(Color32::from_rgb(255, 110, 100), format!("not a valid fabric: {e}"));
                }
            }
            (None, None) => {
                ui.label("No fabric yet.");
            }
            (Some(m), _) => {
                let progress = &m.job.progress;
                let cancelling = progress.is_cancelled();
                ui.horizontal(|ui| {
                    let seconds = m.job.started.elapsed().as_secs_f64();
                    let text = format!("{}: {} / {} tests, {seconds:.0} s", m.fabric, progress.done(), progress.total());
                    ui.add(egui::ProgressBar::new(progress.fraction() as f32).desired_width(320.0).text(text));
                    if ui.add_enabled(!cancelling, egui::Button::new("Cancel")).clicked() {
                        progress.cancel();
                    }
                });
                if cancelling {
                    ui.small(format!("Cancelling: waiting for the {} test(s) in progress to end", progress.running().len()));
                } else if let Some(stage) = progress.stage() {
                    ui.small(stage);
                } else {
                    for label in progress.running() {
                        ui.small(format!("running: {label}"));
                    }
                }
            }
        }
        if let Some(notice) = &self.notice {
            ui.colored_label(Color32::from_rgb(130, 210, 130), notice);
        }
        if let Some(message) = &self.message {
            ui.colored_label(Color32::from_rgb(255, 110, 100), message);
        }
        let Some(made) = &self.made else { return };
        ui.separator();
        let c = &made.card;
        ui.strong(&c.fabric.name);
        egui::Grid::new("card_numbers").num_columns(4).striped(true).show(ui, |ui| {
            ui.label("drape coefficient");
            ui.monospace(crate::card::dc_text(c.drape.result.drape_coefficient));
            ui.label("nodes");
            ui.monospace(c.drape.result.nodes.to_string());
            ui.end_row();
            for (t, b) in c.cantilever.iter().zip(&c.pure_bending) {
                ui.label(format!("bending length, {}", t.direction));
                ui.monospace(format!("{:.1} mm", t.bending_length_mm));
                ui.label(format!("B, {}", b.direction));
                ui.monospace(format!("{:.3} µN·m", b.rigidity_un_m));
                ui.end_row();
            }
            for t in c.tensile.iter().filter(|t| t.emt_percent.is_some()) {
                ui.label(format!("EMT, {}", t.direction));
                ui.monospace(format!("{:.2} %", t.emt_percent.unwrap_or_default()));
                ui.label(format!("LT, {}", t.direction));
                ui.monospace(format!("{:.3}", t.lt.unwrap_or_default()));
                ui.end_row();
            }
            ui.label("shear G");
            ui.monospace(format!("{:.2} N/m", c.shear.modulus_n_per_m));
            // Wall time: the process's CPU time here includes the window and the solver.
            ui.label("made in");
            ui.monospace(format!("{:.1} s", c.cost.wall_seconds));
            ui.end_row();
        });
        if ui.button("Save card (PNG and JSON)").on_hover_text("rosette-card-NAME.png and .json in the working directory").clicked() {
            self.save();
        }
        let Some(made) = &self.made else { return };
        let texture = self.texture.get_or_insert_with(|| {
            let (w, h) = crate::card::page::SIZE;
            let image = egui::ColorImage::from_rgb([w as usize, h as usize], &made.page);
            ui.ctx().load_texture("fabric card", image, egui::TextureOptions::LINEAR)
        });
        let width = ui.available_width().max(200.0);
        let size = texture.size_vec2();
        ui.image((texture.id(), egui::vec2(width, width * size.y / size.x)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    fn frame(ctx: &egui::Context, view: &mut CardView, fabric: &FabricConfig) {
        let input = egui::RawInput { screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))), ..Default::default() };
        ctx.run_ui(input, |ui| view.show(ui.ctx(), Some(fabric))).drop_without_applying_deltas();
    }

    #[test]
    fn a_card_is_made_off_the_ui_thread_and_a_cancel_stops_it() {
        let fabric = crate::fabric::load_fabric("wool").unwrap().config;
        let ctx = egui::Context::default();
        let mut view = CardView { open: true, ..CardView::default() };
        view.start(&fabric);
        assert!(view.busy());
        frame(&ctx, &mut view, &fabric);
        view.cancel();
        let started = Instant::now();
        while view.busy() && started.elapsed() < Duration::from_secs(300) {
            std::thread::sleep(Duration::from_millis(50));
            frame(&ctx, &mut view, &fabric);
        }
        assert!(!view.busy(), "a cancelled card ends");
        assert!(view.made().is_none());
        assert!(view.notice.as_deref().is_some_and(|n| n.starts_with("Card cancelled")), "{:?} {:?}", view.notice, view.message);
    }
}
