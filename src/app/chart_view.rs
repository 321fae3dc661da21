//! The chart window: `rosette chart`'s tables (accuracy.csv, stability.csv) loaded from a
//! directory and drawn with egui_plot, the same data as the PNGs. Both axes of every plot
//! are logarithmic: points are plotted at log10 of their values and the axes labelled in
//! the values themselves.

use crate::chart::data::{AccuracyRow, StabilityRow, read_accuracy, read_stability};
use crate::chart::{Problem, StabilityMap, Status};
use crate::sim::IntegratorKind;
use egui::Color32;
use egui_plot::{GridMark, Legend, Line, MarkerShape, Plot, PlotPoints, Points};
use std::ops::RangeInclusive;
use std::path::Path;

/// State of the chart window.
pub struct ChartView {
    pub open: bool,
    /// Directory holding the CSV files (`rosette chart --out DIR`).
    pub dir: String,
    accuracy: Vec<AccuracyRow>,
    stability: Vec<StabilityRow>,
    problem: Problem,
    message: Option<String>,
    loaded: bool,
}

impl Default for ChartView {
    fn default() -> Self {
        Self {
            open: false,
            dir: "chart".into(),
            accuracy: Vec::new(),
            stability: Vec::new(),
            problem: Problem::Cantilever,
            message: None,
            loaded: false,
        }
    }
}

fn integrator_colour(kind: IntegratorKind) -> Color32 {
    let c = crate::chart::plot::integrator_colour(kind);
    Color32::from_rgb(c.0, c.1, c.2)
}

fn status_colour(status: Status) -> Color32 {
    let c = crate::chart::plot::status_colour(status);
    Color32::from_rgb(c.0, c.1, c.2)
}

fn integrator_shape(kind: IntegratorKind) -> MarkerShape {
    match kind {
        IntegratorKind::SymplecticEuler => MarkerShape::Circle,
        IntegratorKind::ImplicitEuler => MarkerShape::Square,
        IntegratorKind::Bdf2 => MarkerShape::Up,
    }
}

/// Axis label at a log10 grid mark: the value it stands for.
fn log_axis(mark: GridMark, _: &RangeInclusive<f64>) -> String {
    if (mark.value - mark.value.round()).abs() < 1e-6 { format!("{:.0e}", 10f64.powf(mark.value)) } else { String::new() }
}

fn log_point(x: f64, y: f64) -> Option<[f64; 2]> {
    (x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()).then(|| [x.log10(), y.log10()])
}

impl ChartView {
    /// Reads both tables from `self.dir`; a missing or malformed file is reported in the
    /// window.
    pub fn load(&mut self) {
        let dir = Path::new(&self.dir);
        self.loaded = true;
        match (read_accuracy(&dir.join("accuracy.csv")), read_stability(&dir.join("stability.csv"))) {
            (Ok(accuracy), Ok(stability)) => {
                self.message = None;
                if !accuracy.iter().any(|r| r.problem == self.problem) {
                    self.problem = accuracy.first().map_or(Problem::Cantilever, |r| r.problem);
                }
                self.accuracy = accuracy;
                self.stability = stability;
            }
            (Err(e), _) | (_, Err(e)) => {
                self.message = Some(format!("{e}. Make the files with `rosette chart --out {}`", self.dir));
            }
        }
    }

    pub fn show(&mut self, ctx: &egui::Context) {
        if !self.open {
            return;
        }
        if !self.loaded {
            self.load();
        }
        let mut open = self.open;
        egui::Window::new("Speed against accuracy").open(&mut open).default_size([560.0, 640.0]).show(ctx, |ui| self.contents(ui));
        self.open = open;
    }

    fn contents(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label("directory");
            ui.text_edit_singleline(&mut self.dir);
            if ui.button("Load").clicked() {
                self.load();
            }
        });
        if let Some(message) = &self.message {
            ui.colored_label(Color32::from_rgb(255, 110, 100), message);
            return;
        }
        ui.horizontal(|ui| {
            for problem in Problem::ALL.into_iter().filter(|p| self.accuracy.iter().any(|r| r.problem == *p)) {
                ui.selectable_value(&mut self.problem, problem, problem.name());
            }
        });
        ui.label(format!("Error ({}) against CPU seconds per run; Pareto front ringed", self.problem.error_label()));
        let rows: Vec<&AccuracyRow> = self.accuracy.iter().filter(|r| r.problem == self.problem).collect();
        Plot::new("chart_accuracy")
            .height(240.0)
            .legend(Legend::default())
            .x_axis_label("CPU s")
            .y_axis_label("error")
            .x_axis_formatter(log_axis)
            .y_axis_formatter(log_axis)
            .show(ui, |plot| {
                for kind in IntegratorKind::ALL {
                    let mut edges: Vec<f64> = rows.iter().filter(|r| r.integrator == kind).map(|r| r.edge_length).collect();
                    edges.sort_by(f64::total_cmp);
                    edges.dedup();
                    for edge in edges {
                        let mut points: Vec<[f64; 2]> = rows
                            .iter()
                            .filter(|r| r.integrator == kind && r.edge_length == edge)
                            .filter_map(|r| log_point(r.cpu_seconds, r.error?))
                            .collect();
                        points.sort_by(|a, b| a[0].total_cmp(&b[0]));
                        plot.line(Line::new(kind.name(), PlotPoints::from(points.clone())).color(integrator_colour(kind)).width(2.0));
                        plot.points(Points::new(kind.name(), PlotPoints::from(points)).color(integrator_colour(kind)).radius(3.0));
                    }
                }
                let mut front: Vec<[f64; 2]> = rows.iter().filter(|r| r.pareto).filter_map(|r| log_point(r.cpu_seconds, r.error?)).collect();
                front.sort_by(|a, b| a[0].total_cmp(&b[0]));
                plot.line(Line::new("Pareto front", PlotPoints::from(front.clone())).color(Color32::WHITE).width(1.0));
                plot.points(Points::new("Pareto front", PlotPoints::from(front)).color(Color32::WHITE).filled(false).radius(6.0));
            });
        for map in StabilityMap::ALL {
            let rows: Vec<&StabilityRow> = self.stability.iter().filter(|r| r.map == map).collect();
            if rows.is_empty() {
                continue;
            }
            ui.label(match map {
                StabilityMap::Tensile => "dt against tensile stiffness (N/m), tensile pull",
                StabilityMap::Bending => "dt against bending rigidity (N·m), cantilever",
            });
            ui.small("green bounded, orange inaccurate, red diverged; ● symplectic Euler, ■ implicit Euler, ▲ BDF2; line: explicit limit 2/ω_max");
            Plot::new(("chart_stability", map.name()))
                .height(200.0)
                .x_axis_formatter(log_axis)
                .y_axis_formatter(log_axis)
                .y_axis_label("dt (s)")
                .show(ui, |plot| {
                    let mut limit: Vec<[f64; 2]> = rows.iter().filter_map(|r| log_point(r.stiffness(), r.explicit_limit)).collect();
                    limit.sort_by(|a, b| a[0].total_cmp(&b[0]));
                    limit.dedup_by(|a, b| a[0] == b[0]);
                    plot.line(Line::new("explicit limit", PlotPoints::from(limit)).color(Color32::WHITE).width(2.0));
                    for r in &rows {
                        let offset = match r.integrator {
                            IntegratorKind::SymplecticEuler => 0.85,
                            IntegratorKind::ImplicitEuler => 1.0,
                            IntegratorKind::Bdf2 => 1.0 / 0.85,
                        };
                        if let Some(p) = log_point(r.stiffness() * offset, r.dt) {
                            plot.points(
                                Points::new(r.integrator.name(), PlotPoints::from(vec![p]))
                                    .shape(integrator_shape(r.integrator))
                                    .color(status_colour(r.status))
                                    .radius(4.0),
                            );
                        }
                    }
                });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chart::data::{mark_pareto, write_accuracy, write_stability};

    fn frame(ctx: &egui::Context, view: &mut ChartView) {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))),
            ..Default::default()
        };
        ctx.run_ui(input, |ui| view.show(ui.ctx())).drop_without_applying_deltas();
    }

    #[test]
    fn chart_window_loads_the_tables_and_says_when_they_are_missing() {
        let dir = std::env::temp_dir().join(format!("rosette-chart-view-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ctx = egui::Context::default();
        let mut view = ChartView { open: true, dir: dir.join("missing").display().to_string(), ..Default::default() };
        frame(&ctx, &mut view);
        assert!(view.message.as_deref().is_some_and(|m| m.contains("rosette chart")), "{:?}", view.message);

        let mut accuracy: Vec<AccuracyRow> = [(0.1, 0.02), (0.5, 0.01)]
            .into_iter()
            .map(|(cpu, error)| AccuracyRow {
                problem: Problem::Tensile,
                integrator: IntegratorKind::Bdf2,
                dt: 0.01,
                dt_over_limit: 300.0,
                edge_length: 0.01,
                triangles: 100,
                cpu_seconds: cpu,
                error: Some(error),
                status: "ok".into(),
                pareto: false,
            })
            .collect();
        mark_pareto(&mut accuracy);
        let stability = vec![StabilityRow {
            map: StabilityMap::Tensile,
            problem: Problem::Tensile,
            integrator: IntegratorKind::SymplecticEuler,
            dt: 3e-5,
            explicit_limit: 2e-5,
            tensile_scale: 1.0,
            bending_scale: 1.0,
            tensile_stiffness: 1000.0,
            bending_stiffness: 9e-6,
            triangles: 100,
            cpu_seconds: 0.01,
            error: None,
            status: Status::Diverged,
        }];
        write_accuracy(&dir.join("accuracy.csv"), &accuracy).unwrap();
        write_stability(&dir.join("stability.csv"), &stability).unwrap();
        view.dir = dir.display().to_string();
        view.load();
        frame(&ctx, &mut view);
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(view.message, None);
        assert_eq!((view.accuracy.len(), view.stability.len()), (2, 1));
        assert_eq!(view.problem, Problem::Tensile, "the window shows a problem that has rows");
    }
}
