//! The egui panels and the 3D view's mouse and keyboard handling. Everything the user does
//! becomes an [`Action`]: a worker [`Command`] or a request the window carries out (a file
//! dialog, a screenshot). No window or GPU is needed here, so tests run it on a bare
//! `egui::Context`.

use super::camera::OrbitCamera;
use super::card_view::CardView;
use super::chart_view::ChartView;
use super::pattern_view::PatternView;
use super::pin::Pinned;
use super::colour::ColourMap;
use super::plots::{self, History};
pub use super::action::{Action, FileDialog};
use super::worker::{Command, Snapshot};
use crate::settings::{FABRICS, FabricConfig, SCENES, scene_descriptions};
use crate::scene::{SceneConfig, load_scene};
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use egui::{Color32, Key, PointerButton, Rect, Sense};
use egui_plot::{Legend, Line, MarkerShape, Plot, PlotPoints, Points};
use glam::DVec3;
use std::time::{Duration, Instant};

/// The laboratory tests offered as buttons, in the order of the paper; those missing from
/// the bundled scenes (e.g. a drape scene not yet added) are left out.
pub const TESTS: &[&str] =
    &["tensile-warp", "tensile-weft", "tensile-bias", "cantilever", "arc", "euler-buckling", "shear-buckling", "cusick-drape"];

/// Fabric edits are sent at most this often while a value is being dragged.
const FABRIC_THROTTLE: Duration = Duration::from_millis(250);

/// A cloth point held by the mouse: it moves in the plane through the picked point facing
/// the camera.
#[derive(Debug, Clone, Copy)]
struct MouseDrag {
    vertex: u32,
    /// The version of the mesh `vertex` indexes (`Topology::version`).
    mesh: u64,
    /// The cloth was rebuilt under the drag: the rest of the gesture moves nothing.
    lost: bool,
    /// Where the ray first met the cloth, m.
    hit: DVec3,
    /// The vertex's position then, m.
    start: DVec3,
    /// Normal of the drag plane (towards the camera).
    normal: DVec3,
}

/// State of the panels and the view between frames.
pub struct ViewerUi {
    pub camera: OrbitCamera,
    pub colour_map: ColourMap,
    pub wireframe: bool,
    /// The 3D view's rectangle, in points.
    pub view_rect: Rect,
    pub history: History,
    /// Errors from the window side (files, dialogs), shown until dismissed.
    pub messages: Vec<String>,
    /// The last thing done that has no other feedback (a file saved).
    pub notice: Option<String>,
    framed_scene: Option<String>,
    /// The mesh the view last saw, and whether the user has turned, panned or zoomed the
    /// camera since the scene was framed.
    framed_mesh: Option<u64>,
    camera_moved: bool,
    fabric: Option<FabricConfig>,
    fabric_generation: u64,
    fabric_pending: bool,
    fabric_sent: Option<Instant>,
    /// Point of a tensile curve being dragged: (0 warp / 1 weft, point index).
    curve_drag: Option<(usize, usize)>,
    history_choice: String,
    /// The kind of test `history_choice` was made for.
    history_kind: Option<crate::scene::SceneKind>,
    mouse_drag: Option<MouseDrag>,
    /// The speed/accuracy chart window (`rosette chart`'s tables).
    pub chart: ChartView,
    /// The Fabric card window.
    pub card: CardView,
    /// A fabric's result kept for comparison, shown at the top of the right panel.
    pub pinned: Option<Pinned>,
    /// A garment's grains and flat pattern.
    pub pattern: PatternView,
    /// The fabric's look beside its editor.
    swatch: super::swatch::Swatch,
}

impl Default for ViewerUi {
    fn default() -> Self {
        Self {
            camera: OrbitCamera::default(),
            colour_map: ColourMap::Fabric,
            wireframe: false,
            view_rect: Rect::NOTHING,
            history: History::default(),
            messages: Vec::new(),
            notice: None,
            framed_scene: None,
            framed_mesh: None,
            camera_moved: false,
            fabric: None,
            fabric_generation: 0,
            fabric_pending: false,
            fabric_sent: None,
            curve_drag: None,
            history_choice: String::new(),
            history_kind: None,
            mouse_drag: None,
            chart: ChartView::default(),
            card: CardView::default(),
            pinned: None,
            pattern: PatternView::default(),
            swatch: Default::default(),
        }
    }
}

impl ViewerUi {
    /// Lays out one frame of the UI over `snapshot` and returns what the user asked for.
    pub fn show(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot) -> Vec<Action> {
        let mut actions = Vec::new();
        self.history.record(snapshot);
        self.follow_scene(snapshot);
        self.keys(ui.ctx(), snapshot, &mut actions);
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui, snapshot, &mut actions));
        egui::Panel::left("lab").default_size(340.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.left_panel(ui, snapshot, &mut actions));
        });
        egui::Panel::right("tests").default_size(360.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.right_panel(ui, snapshot, &mut actions));
        });
        egui::CentralPanel::no_frame().show(ui, |ui| self.view(ui, snapshot, &mut actions));
        self.chart.show(ui.ctx());
        self.card.show(ui.ctx(), self.fabric.as_ref());
        self.pattern.show(ui.ctx(), snapshot, &mut actions);
        self.flush_fabric(&mut actions);
        actions
    }

    /// Frames the camera on a new scene and takes the scene's fabric into the editor.
    fn follow_scene(&mut self, snapshot: &Snapshot) {
        // A new scene is framed; a reset, a new fabric or a finer level keeps the user's
        // view. A garment's flat panels start far out round the form: once its seams weld,
        // a view the user has not moved is framed again on the sewn garment.
        let key = snapshot.scene_name.clone();
        if self.framed_scene.as_ref() != Some(&key) {
            self.camera.frame(&snapshot.positions);
            self.framed_scene = Some(key);
            self.camera_moved = false;
        } else if !self.camera_moved && self.framed_mesh.is_some_and(|m| snapshot.topology.merged_from.as_ref().is_some_and(|(from, _)| *from == m)) {
            self.camera.frame(&snapshot.positions);
        }
        self.framed_mesh = Some(snapshot.topology.version);
        if snapshot.scene_generation != self.fabric_generation && !self.fabric_pending {
            self.fabric = Some(snapshot.config.fabric.clone());
            self.fabric_generation = snapshot.scene_generation;
        }
    }

    fn keys(&mut self, ctx: &egui::Context, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        if ctx.egui_wants_keyboard_input() {
            return;
        }
        ctx.input(|i| {
            if i.key_pressed(Key::Space) {
                actions.push(Action::Send(if snapshot.playing { Command::Pause } else { Command::Play }));
            }
            if i.key_pressed(Key::S) {
                actions.push(Action::Send(Command::Step));
            }
            if i.key_pressed(Key::R) {
                actions.push(Action::Send(Command::Reset));
            }
            if i.key_pressed(Key::F12) {
                actions.push(Action::Screenshot);
            }
            if i.key_pressed(Key::F) {
                self.camera.frame(&snapshot.positions);
            }
        });
    }

    fn toolbar(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        ui.horizontal_wrapped(|ui| {
            ui.menu_button("File", |ui| {
                for (label, action) in [
                    ("Open scene…", Action::File(FileDialog::OpenScene)),
                    ("Save scene…", Action::File(FileDialog::SaveScene)),
                    ("Open fabric…", Action::File(FileDialog::OpenFabric)),
                    ("Save fabric…", Action::File(FileDialog::SaveFabric)),
                    ("Export cloth mesh (OBJ)…", Action::File(FileDialog::ExportObj)),
                    ("Export glTF (GLB, Blender, web)…", Action::File(FileDialog::ExportGltf)),
                    ("Export test data (CSV)…", Action::File(FileDialog::ExportCsv)),
                    ("Save screenshot (PNG)  F12", Action::Screenshot),
                ] {
                    if ui.button(label).clicked() {
                        actions.push(action);
                        ui.close();
                    }
                }
            });
            ui.separator();
            let play = if snapshot.playing { "Pause" } else { "Play" };
            if ui.button(play).on_hover_text("Space").clicked() {
                actions.push(Action::Send(if snapshot.playing { Command::Pause } else { Command::Play }));
            }
            if ui.button("Step").on_hover_text("S").clicked() {
                actions.push(Action::Send(Command::Step));
            }
            if ui.button("Reset").on_hover_text("R").clicked() {
                actions.push(Action::Send(Command::Reset));
            }
            ui.separator();
            ui.monospace(format!("t = {:.3} / {} s   step {}", snapshot.time, snapshot.duration, snapshot.steps));
            if let Some((text, colour)) = drape_status(snapshot) {
                ui.colored_label(colour, text);
            }
            match (snapshot.finished, snapshot.settled_at) {
                (true, Some(t)) => {
                    ui.label(format!("(settled at t = {t:.2} s: Play continues)"));
                }
                (true, None) => {
                    ui.label("(end of scene: Play continues)");
                }
                _ => {}
            }
            if snapshot.stats.unconverged_steps > 0 {
                ui.colored_label(Color32::from_rgb(255, 110, 100), format!("Newton did not converge on {} steps", snapshot.stats.unconverged_steps))
                    .on_hover_text(format!(
                        "Their last Newton step reached {:.1e} of an edge, above the tolerance: their results are not trustworthy. \
                         Raise solver.newton.max_iterations or take a smaller time step.",
                        snapshot.stats.worst_residual
                    ));
            }
            if snapshot.playing && snapshot.stats.real_time_factor > 0.0 && snapshot.stats.real_time_factor < 0.95 {
                ui.colored_label(Color32::from_rgb(230, 160, 40), format!("{:.2}× real time", snapshot.stats.real_time_factor));
            }
            ui.separator();
            egui::ComboBox::from_id_salt("colour_map").selected_text(format!("colour: {}", self.colour_map.label())).show_ui(ui, |ui| {
                for map in ColourMap::ALL {
                    ui.selectable_value(&mut self.colour_map, map, map.label());
                }
            });
            ui.checkbox(&mut self.wireframe, "wireframe");
            if ui.button("Frame").on_hover_text("F: fit the cloth in the view").clicked() {
                self.camera.frame(&snapshot.positions);
            }
            if ui.button("Save PNG").on_hover_text("F12").clicked() {
                actions.push(Action::Screenshot);
            }
            ui.separator();
            ui.toggle_value(&mut self.chart.open, "Chart").on_hover_text("speed against accuracy: the tables of `rosette chart`");
            ui.toggle_value(&mut self.card.open, "Fabric card")
                .on_hover_text("the virtual laboratory's tests and the 30 cm drape on the fabric being edited (`rosette card`)");
            if ui
                .button(if self.pinned.is_some() { "Pin again" } else { "Pin fabric" })
                .on_hover_text("keep this fabric's picture and measures beside the live view, to compare while you edit")
                .clicked()
            {
                actions.push(Action::Pin);
            }
        });
        if let Some(error) = &snapshot.error {
            ui.colored_label(Color32::from_rgb(255, 110, 100), format!("Error: {error}"));
        }
        if let Some(notice) = &self.notice {
            ui.colored_label(Color32::from_rgb(130, 210, 130), notice);
        }
        let mut dismiss = None;
        for (i, message) in self.messages.iter().enumerate() {
            ui.horizontal(|ui| {
                ui.colored_label(Color32::from_rgb(255, 110, 100), format!("Error: {message}"));
                if ui.small_button("dismiss").clicked() {
                    dismiss = Some(i);
                }
            });
        }
        if let Some(i) = dismiss {
            self.messages.remove(i);
        }
    }

    fn left_panel(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        ui.heading("Scene");
        let descriptions = scene_descriptions();
        egui::ComboBox::from_id_salt("scene_picker").selected_text(&snapshot.scene_name).width(300.0).show_ui(ui, |ui| {
            for (name, description) in &descriptions {
                if ui.selectable_label(snapshot.scene_name == *name, *name).on_hover_text(description).clicked() {
                    match load_scene(name, &[]) {
                        Ok((config, _)) => {
                            actions.push(Action::Send(Command::LoadScene { name: name.to_string(), config: Box::new(config) }))
                        }
                        Err(e) => self.messages.push(e.to_string()),
                    }
                }
            }
        });
        if let Some((_, description)) = descriptions.iter().find(|(n, _)| *n == snapshot.scene_name) {
            ui.small(description);
        }
        if snapshot.config.garment.is_some() {
            ui.separator();
            self.pattern.panel(ui, snapshot, actions);
        }
        ui.separator();
        self.solver_panel(ui, snapshot, actions);
        ui.separator();
        self.fabric_panel(ui, &snapshot.config);
    }

    fn solver_panel(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        ui.heading("Solver");
        let (mut dt, mut integrator) = (snapshot.config.solver.dt, snapshot.config.solver.integrator);
        egui::Grid::new("solver").num_columns(2).show(ui, |ui| {
            ui.label("integrator");
            egui::ComboBox::from_id_salt("integrator").selected_text(integrator.name()).show_ui(ui, |ui| {
                for kind in IntegratorKind::ALL {
                    ui.selectable_value(&mut integrator, kind, kind.name());
                }
            });
            ui.end_row();
            ui.label("time step dt");
            ui.add(relative_drag(&mut dt).range(1e-6..=0.1).suffix(" s"));
            ui.end_row();
            ui.label("path");
            let mut path = snapshot.config.solver.path;
            ui.horizontal(|ui| {
                ui.selectable_value(&mut path, SolverPath::Exact, "exact")
                    .on_hover_text("The validated reference: the scene's own mesh and time step throughout.");
                ui.selectable_value(&mut path, SolverPath::Fast, "fast").on_hover_text(
                    "Settling scenes settle coarse to fine, with longer steps and Newton solved to the step's own accuracy; \
                     drape coefficients stay within about 0.01 of the exact path's seed scatter (docs/fast-path.md).",
                );
            });
            self.choose_path(path, snapshot, actions);
            ui.end_row();
        });
        if dt != snapshot.config.solver.dt || integrator != snapshot.config.solver.integrator {
            actions.push(Action::Send(Command::SetSolver { dt, integrator }));
        }
        if snapshot.coarse_level {
            ui.small("Fast path: a coarser level of the mesh; the scene's own mesh follows once it settles.");
        }
        let running = snapshot.stats.step_dt;
        if snapshot.config.solver.path == SolverPath::Fast && running > 0.0 && (running - snapshot.config.solver.dt).abs() > 1e-9 * running {
            ui.small(format!("Fast path: steps of {running:.3} s from its plan (rosette run SCENE --fast --plan); dt above is the scene's, which the exact path takes."));
        }
        if integrator.is_explicit() {
            ui.small("Symplectic Euler is stable only below its limit; a diverged step is reported and the last state kept.");
        }
    }

    fn fabric_panel(&mut self, ui: &mut egui::Ui, scene: &SceneConfig) {
        ui.heading("Fabric");
        let Some(fabric) = &self.fabric else { return };
        let mut chosen = None;
        egui::ComboBox::from_id_salt("fabric_preset")
            .selected_text(format!("start from: {}", fabric.preset.as_deref().unwrap_or("(custom)")))
            .show_ui(ui, |ui| {
                for bundled in FABRICS {
                    if ui.selectable_label(false, bundled.name).clicked() {
                        chosen = Some(bundled.name);
                    }
                }
            });
        if let Some(name) = chosen
            && let Err(e) = self.choose_fabric(name, scene)
        {
            self.messages.push(e);
        }
        let Some(fabric) = &mut self.fabric else { return };
        self.swatch.show(ui, fabric, scene.base_dir.as_deref());
        let mut changed = false;
        // Rigidities are shown in µN·m, the size they come in.
        let micro = |v: &mut f64| *v * 1e6;
        let (mut bending_warp, mut bending_weft) = (micro(&mut fabric.properties.bending_warp), micro(&mut fabric.properties.bending_weft));
        let mut bias = fabric.properties.bending_bias.map(|b| b * 1e6);
        egui::Grid::new("fabric").num_columns(2).show(ui, |ui| {
            let mut row = |ui: &mut egui::Ui, label: &str, value: &mut f64, suffix: &str, range: std::ops::RangeInclusive<f64>| {
                ui.label(label);
                changed |= ui.add(relative_drag(value).range(range).suffix(suffix)).changed();
                ui.end_row();
            };
            row(ui, "areal density", &mut fabric.properties.areal_density, " kg/m²", 1e-3..=5.0);
            row(ui, "thickness", &mut fabric.properties.thickness, " m", 1e-5..=0.01);
            row(ui, "shear modulus G", &mut fabric.properties.shear_modulus, " N/m", 1e-3..=1e5);
            row(ui, "bending, warp", &mut bending_warp, " µN·m", 1e-3..=1e4);
            row(ui, "bending, weft", &mut bending_weft, " µN·m", 1e-3..=1e4);
            ui.label("Poisson ν_xy");
            changed |= ui.add(egui::DragValue::new(&mut fabric.properties.poisson_warp).range(0.0..=0.9).speed(0.005)).changed();
            ui.end_row();
            let mut has_bias = bias.is_some();
            if ui.checkbox(&mut has_bias, "bending, bias").on_hover_text("Measured 45° rigidity; off: eq. 3 of the paper").changed() {
                bias = has_bias.then_some(0.35 * (bending_warp + bending_weft));
                changed = true;
            }
            if let Some(b) = &mut bias {
                changed |= ui.add(relative_drag(b).range(1e-3..=1e4).suffix(" µN·m")).changed();
            }
            ui.end_row();
        });
        fabric.properties.bending_warp = bending_warp * 1e-6;
        fabric.properties.bending_weft = bending_weft * 1e-6;
        fabric.properties.bending_bias = bias.map(|b| b * 1e-6);
        if let Some(curve) = &fabric.properties.bending_curve {
            ui.small(format!("Nonlinear bending: a moment–curvature curve of {} points (edit it in the fabric file).", curve.len()));
        }
        ui.label("Tensile curves (drag points; double-click adds, right-click removes)");
        changed |= curve_editor(ui, fabric, &mut self.curve_drag);
        if changed {
            if fabric.preset.is_some() && !fabric.name.ends_with("(edited)") {
                fabric.name = format!("{} (edited)", if fabric.name.is_empty() { "fabric" } else { &fabric.name });
            }
            self.fabric_pending = true;
        }
        if let Err(e) = fabric.to_fabric() {
            ui.colored_label(Color32::from_rgb(255, 110, 100), format!("not applied: {e}"));
        }
    }

    /// Sends a pending fabric edit, at most every FABRIC_THROTTLE, once it is valid.
    fn flush_fabric(&mut self, actions: &mut Vec<Action>) {
        let Some(fabric) = &self.fabric else { return };
        if !self.fabric_pending || self.fabric_sent.is_some_and(|t| t.elapsed() < FABRIC_THROTTLE) {
            return;
        }
        if fabric.to_fabric().is_ok() {
            actions.push(Action::Send(Command::SetFabric(Box::new(fabric.clone()))));
            self.fabric_sent = Some(Instant::now());
        }
        self.fabric_pending = false;
    }

    /// Takes the bundled fabric `name` into the editor as the scene `scene` runs it
    /// (`--set fabric.preset=NAME`: a drape scene's own fabric keys stay) and applies it:
    /// what choosing it in the fabric list does.
    pub fn choose_fabric(&mut self, name: &str, scene: &SceneConfig) -> Result<(), String> {
        let bundled = FABRICS.iter().find(|f| f.name == name).ok_or_else(|| format!("no bundled fabric '{name}'"))?;
        let mut fabric = crate::fabric::parse_fabric(bundled.text, bundled.name).map_err(|e| format!("fabric {name}: {e}"))?.config;
        fabric.preset = Some(bundled.name.to_string());
        let fabric = crate::card::scene_fabric(scene, &fabric).map_err(|e| format!("fabric {name}: {e}"))?;
        self.set_fabric(fabric);
        Ok(())
    }

    /// Whether a fabric edit waits to be sent to the worker.
    pub fn fabric_pending(&self) -> bool {
        self.fabric_pending
    }

    /// The solver path switch.
    pub fn choose_path(&mut self, path: SolverPath, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        if path != snapshot.config.solver.path {
            actions.push(Action::Send(Command::SetPath(path)));
        }
    }

    /// A fabric test's button: the bundled test `name` runs on the fabric being edited.
    pub fn run_test(&mut self, name: &str, actions: &mut Vec<Action>) {
        actions.push(Action::Send(Command::RunTest(name.to_string())));
    }

    /// Turns the camera about the cloth by `yaw` and `pitch` (radians), as an orbiting drag
    /// does.
    pub fn turn_camera(&mut self, yaw: f64, pitch: f64) {
        self.camera.turn(yaw, pitch);
        self.camera_moved = true;
    }

    /// Brings the camera `factor` times closer (below 1: farther), as the wheel does.
    pub fn zoom_camera(&mut self, factor: f64) {
        self.camera.zoom(10.0 * factor.ln());
        self.camera_moved = true;
    }

    /// Replaces the fabric under edit (e.g. from a file) and applies it.
    pub fn set_fabric(&mut self, fabric: FabricConfig) {
        self.fabric = Some(fabric);
        self.fabric_pending = true;
        self.fabric_sent = None;
    }

    fn right_panel(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        if let Some(pinned) = &mut self.pinned {
            if pinned.show(ui, snapshot) {
                self.pinned = None;
            }
            ui.separator();
        }
        ui.heading("Fabric tests");
        ui.small("Each runs the bundled laboratory scene on the fabric being edited.");
        ui.horizontal_wrapped(|ui| {
            for name in TESTS.iter().filter(|n| SCENES.iter().any(|s| s.name == **n)) {
                if ui.button(*name).clicked() {
                    self.run_test(name, actions);
                }
            }
        });
        ui.separator();
        ui.heading("Live measurements");
        plots::test_plot(ui, snapshot);
        if !self.history.names.is_empty() {
            // Each new test opens on the measure it changes; a choice of the user's stays
            // while the scene keeps that measure.
            let kind = snapshot.config.scene.kind;
            if self.history_kind != Some(kind) || !self.history.names.contains(&self.history_choice) {
                let default = crate::scene::kinds::of(kind).plot_series();
                self.history_choice =
                    if self.history.names.iter().any(|n| n == default) { default.to_string() } else { self.history.names[0].clone() };
                self.history_kind = Some(kind);
            }
            egui::ComboBox::from_id_salt("history").selected_text(format!("over time: {}", self.history_choice)).show_ui(ui, |ui| {
                for name in &self.history.names {
                    ui.selectable_value(&mut self.history_choice, name.clone(), name);
                }
            });
            plots::history_plot(ui, &self.history, &self.history_choice);
        }
        if ui.button("Export test data (CSV)…").clicked() {
            actions.push(Action::File(FileDialog::ExportCsv));
        }
        egui::CollapsingHeader::new("All measures (JSON)").show(ui, |ui| {
            let mut text = serde_json::to_string_pretty(&*snapshot.measures).unwrap_or_default();
            ui.add(egui::TextEdit::multiline(&mut text).code_editor().interactive(false).desired_rows(6));
        });
        ui.separator();
        ui.heading("Stats");
        let s = &snapshot.stats;
        egui::Grid::new("stats").num_columns(2).striped(true).show(ui, |ui| {
            let mut row = |label: &str, value: String| {
                ui.label(label);
                ui.monospace(value);
                ui.end_row();
            };
            row("vertices / triangles", format!("{} / {}", s.vertices, s.triangles));
            row("integrator, scene dt", format!("{}, {} s", snapshot.config.solver.integrator, snapshot.config.solver.dt));
            row("steps per second", format!("{:.1}", s.steps_per_second));
            row("step time per 10 ms simulated", format!("{:.3} ms", s.step_ms_per_10ms));
            row("real-time factor", format!("{:.2}", s.real_time_factor));
            row("step, Δt", format!("{}, {} s", s.minimizer, s.step_dt));
            if s.quasi_newton_iterations > 0 {
                row("quasi-Newton iterations", format!("{}", s.quasi_newton_iterations));
            }
            row("Newton / CG iterations", format!("{} / {}", s.newton_iterations, s.cg_iterations));
            let clock = snapshot.drape;
            let waited = match clock.settled {
                Some((_, wall)) => format!("settled {wall:.1} s after the {}", clock.cause.name()),
                None => format!("{:.1} s since the {}, not settled", clock.wall, clock.cause.name()),
            };
            row("drape", waited);
            if let Some(factor) = clock.real_time_factor_since_weld() {
                let from = if snapshot.sewing.is_some() && !clock.from_sewn { "the weld".to_string() } else { format!("the {}", clock.cause.name()) };
                row(&format!("real-time factor from {from}"), format!("{factor:.2}"));
            }
            row("kinetic energy", format!("{:.4e} J", s.kinetic_energy));
            row("membrane energy", format!("{:.4e} J", s.membrane_energy));
            row("bending energy", format!("{:.4e} J", s.bending_energy));
        });
        ui.separator();
        ui.small(
            "Mouse: left-drag the cloth to pull a point, left-drag elsewhere to orbit, right- or middle-drag to pan, \
             wheel to zoom. Keys: Space play/pause, S step, R reset, F frame, F12 screenshot.",
        );
    }

    /// The 3D view: camera and cloth-dragging input, plus the colour legend.
    fn view(&mut self, ui: &mut egui::Ui, snapshot: &Snapshot, actions: &mut Vec<Action>) {
        let rect = ui.available_rect_before_wrap();
        self.view_rect = rect;
        let response = ui.allocate_rect(rect, Sense::click_and_drag());
        let local = |p: egui::Pos2| (f64::from(p.x - rect.min.x), f64::from(p.y - rect.min.y));
        let (w, h) = (f64::from(rect.width()), f64::from(rect.height()));
        if response.drag_started_by(PointerButton::Primary)
            && let Some(pos) = response.interact_pointer_pos()
        {
            let (x, y) = local(pos);
            let ray = self.camera.ray(x, y, w, h);
            if let Some((vertex, hit)) = ray.pick_vertex(&snapshot.positions, &snapshot.topology.triangles)
                && !snapshot.fixed[vertex as usize]
            {
                let start = snapshot.positions[vertex as usize];
                let mesh = snapshot.topology.version;
                self.mouse_drag = Some(MouseDrag { vertex, mesh, lost: false, hit, start, normal: -self.camera.basis().0 });
                actions.push(Action::Send(Command::DragVertex { vertex, mesh, target: start }));
            }
        }
        // The mesh changed under the mouse: a weld carries the held point to its merged
        // vertex; another mesh lets it go (the worker has let go too).
        if let Some(drag) = &mut self.mouse_drag
            && drag.mesh != snapshot.topology.version
        {
            match snapshot.topology.carry_vertex(drag.mesh, drag.vertex) {
                Some(vertex) => (drag.vertex, drag.mesh) = (vertex, snapshot.topology.version),
                None => drag.lost = true,
            }
        }
        if response.dragged_by(PointerButton::Primary) {
            match (self.mouse_drag, response.interact_pointer_pos()) {
                (Some(drag), _) if drag.lost => {}
                (Some(drag), Some(pos)) => {
                    let (x, y) = local(pos);
                    if let Some(point) = self.camera.ray(x, y, w, h).hit_plane(drag.hit, drag.normal) {
                        let target = drag.start + (point - drag.hit);
                        actions.push(Action::Send(Command::DragVertex { vertex: drag.vertex, mesh: drag.mesh, target }));
                    }
                }
                _ => {
                    let d = response.drag_delta();
                    self.camera.orbit(f64::from(d.x), f64::from(d.y));
                    self.camera_moved = true;
                }
            }
        }
        if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
            let d = response.drag_delta();
            self.camera.pan(f64::from(d.x), f64::from(d.y), h);
            self.camera_moved = true;
        }
        if response.drag_stopped() && self.mouse_drag.take().is_some_and(|d| !d.lost) {
            actions.push(Action::Send(Command::ReleaseDrag));
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera.zoom(f64::from(scroll) / 50.0);
                self.camera_moved = true;
            }
        }
    }
}

/// What the drape is doing, in words, for the toolbar: a garment sewing, settling or
/// settled (with the wall time from the click), and its colour.
fn drape_status(snapshot: &Snapshot) -> Option<(String, Color32)> {
    let sewing = snapshot.sewing?;
    let clock = snapshot.drape;
    let (amber, green, red) = (Color32::from_rgb(230, 180, 70), Color32::from_rgb(130, 210, 130), Color32::from_rgb(255, 110, 100));
    Some(match (sewing.sewn_at, clock.settled) {
        (None, _) if sewing.failed => ("not sewn: a seam was still open at the sewing time".into(), red),
        (None, _) => (format!("sewing: seams {:.1} mm apart", 1e3 * sewing.open_gap), amber),
        (Some(_), Some((_, wall))) => (format!("settled in {wall:.1} s after the {}", clock.cause.name()), green),
        (Some(_), None) if clock.from_sewn => (format!("re-draping from the sewn garment ({:.1} s)", clock.wall), amber),
        (Some(at), None) => (format!("settling (sewn at t = {at:.2} s, {:.1} s ago)", clock.wall - clock.sewn.map_or(0.0, |s| s.1)), amber),
    })
}

/// A drag value whose step is half a percent of its size, for quantities spanning decades.
fn relative_drag(value: &mut f64) -> egui::DragValue<'_> {
    let speed = (value.abs() * 0.005).max(1e-9);
    egui::DragValue::new(value).speed(speed).max_decimals(8)
}

fn curve_mut(fabric: &mut FabricConfig, k: usize) -> &mut Vec<[f64; 2]> {
    if k == 0 { &mut fabric.properties.tensile_warp } else { &mut fabric.properties.tensile_weft }
}

/// The warp and weft stress–strain curves as draggable points. Returns whether a curve
/// changed. A point stays between its neighbours' strains; the first point stays at zero
/// strain.
fn curve_editor(ui: &mut egui::Ui, fabric: &mut FabricConfig, dragging: &mut Option<(usize, usize)>) -> bool {
    const PICK_RADIUS: f32 = 10.0;
    const COLOURS: [Color32; 2] = [Color32::from_rgb(90, 160, 255), Color32::from_rgb(255, 120, 90)];
    let mut changed = false;
    let curves = [fabric.properties.tensile_warp.clone(), fabric.properties.tensile_weft.clone()];
    let plot = Plot::new("fabric_curves")
        .height(200.0)
        .legend(Legend::default())
        .x_axis_label("strain")
        .y_axis_label("stress (N/m)")
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .allow_double_click_reset(false)
        .include_x(0.0)
        .include_y(0.0);
    let response = plot.show(ui, |plot| {
        for (k, (curve, name)) in curves.iter().zip(["warp", "weft"]).enumerate() {
            plot.line(Line::new(name, PlotPoints::from(curve.clone())).color(COLOURS[k]).width(2.0));
            plot.points(Points::new(name, PlotPoints::from(curve.clone())).color(COLOURS[k]).radius(4.0).shape(MarkerShape::Circle));
        }
    });
    let transform = response.transform;
    let nearest = |pos: egui::Pos2| -> Option<(usize, usize, f32)> {
        let mut best: Option<(usize, usize, f32)> = None;
        for (k, curve) in curves.iter().enumerate() {
            for (i, p) in curve.iter().enumerate() {
                let screen = transform.position_from_point(&egui_plot::PlotPoint::new(p[0], p[1]));
                let d = screen.distance(pos);
                if best.is_none_or(|b| d < b.2) {
                    best = Some((k, i, d));
                }
            }
        }
        best
    };
    let r = &response.response;
    if r.drag_started_by(PointerButton::Primary)
        && let Some(pos) = r.interact_pointer_pos()
    {
        *dragging = nearest(pos).filter(|b| b.2 < PICK_RADIUS).map(|b| (b.0, b.1));
    }
    if let (Some((k, i)), true, Some(pos)) = (*dragging, r.dragged(), r.interact_pointer_pos()) {
        let value = transform.value_from_position(pos);
        let curve = curve_mut(fabric, k);
        let lo = if i > 0 { curve[i - 1][0] + 1e-5 } else { 0.0 };
        let hi = curve.get(i + 1).map_or(f64::INFINITY, |p| p[0] - 1e-5);
        let strain = if i == 0 { curve[0][0] } else { value.x.clamp(lo, hi) };
        curve[i] = [strain, value.y.max(0.0)];
        changed = true;
    }
    if r.drag_stopped() {
        *dragging = None;
    }
    if r.double_clicked()
        && let Some(pos) = r.interact_pointer_pos()
    {
        let value = transform.value_from_position(pos);
        let k = nearest(pos).map_or(0, |b| b.0);
        let curve = curve_mut(fabric, k);
        if value.x > 0.0 && !curve.iter().any(|p| (p[0] - value.x).abs() < 1e-5) {
            curve.push([value.x, value.y.max(0.0)]);
            curve.sort_by(|a, b| a[0].total_cmp(&b[0]));
            changed = true;
        }
    }
    if r.secondary_clicked()
        && let Some(pos) = r.interact_pointer_pos()
        && let Some((k, i, d)) = nearest(pos)
    {
        let curve = curve_mut(fabric, k);
        if d < PICK_RADIUS && i > 0 && curve.len() > 2 {
            curve.remove(i);
            changed = true;
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::worker::Worker;
    use std::time::Duration;

    fn frame(ctx: &egui::Context, ui_state: &mut ViewerUi, snapshot: &Snapshot, events: Vec<egui::Event>) -> Vec<Action> {
        let input = egui::RawInput {
            screen_rect: Some(Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))),
            events,
            ..Default::default()
        };
        let mut actions = Vec::new();
        ctx.run_ui(input, |ui| actions = ui_state.show(ui, snapshot)).drop_without_applying_deltas();
        actions
    }

    #[test]
    fn every_scene_lays_out_and_keys_become_commands() {
        let ctx = egui::Context::default();
        let mut ui_state = ViewerUi::default();
        for scene in SCENES {
            let (config, _) = load_scene(scene.name, &[]).unwrap();
            let worker = Worker::spawn(scene.name, config, None).unwrap();
            worker.send(Command::Step);
            let snapshot = worker.sync(Duration::from_secs(60));
            for map in ColourMap::ALL {
                ui_state.colour_map = map;
                let actions = frame(&ctx, &mut ui_state, &snapshot, Vec::new());
                assert!(actions.is_empty(), "{}: a frame without input asks for nothing: {actions:?}", scene.name);
            }
            assert!(ui_state.view_rect.width() > 100.0, "the 3D view keeps room beside the panels");
        }
        let worker = Worker::spawn("cantilever", load_scene("cantilever", &[]).unwrap().0, None).unwrap();
        let snapshot = worker.latest();
        let press = |key| egui::Event::Key { key, physical_key: None, pressed: true, repeat: false, modifiers: Default::default() };
        let actions = frame(&ctx, &mut ui_state, &snapshot, vec![press(Key::Space), press(Key::S), press(Key::R), press(Key::F12)]);
        let names: Vec<String> = actions.iter().map(|a| format!("{a:?}")).collect();
        assert_eq!(names, ["Send(Play)", "Send(Step)", "Send(Reset)", "Screenshot"]);
    }
}
