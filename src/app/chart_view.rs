//! The chart window: `rosette chart`'s tables (accuracy.csv, stability.csv) drawn with
//! egui_plot, the same data as the PNGs. It opens on the full sweep bundled with the binary
//! (`docs/chart`), can run the quick sweep (`rosette chart --quick`) on a background thread
//! with a progress bar, and can load the tables of any `rosette chart --out DIR`. Both axes
//! of every plot are logarithmic: points are plotted at log10 of their values and the axes
//! labelled in the values themselves.

use crate::chart::data::{AccuracyRow, StabilityRow, parse_accuracy, parse_stability, read_accuracy, read_stability};
use super::job::Job;
use crate::chart::{ChartError, ChartOptions, ChartReport, Plan, Problem, StabilityMap, Status};
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use egui::Color32;
use egui_plot::{GridMark, Legend, Line, MarkerShape, Plot, PlotPoints, Points};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The full sweep's tables as committed in `docs/chart` (`rosette chart --out docs/chart`).
const BUNDLED_ACCURACY: &str = include_str!("../../docs/chart/accuracy.csv");
const BUNDLED_STABILITY: &str = include_str!("../../docs/chart/stability.csv");

/// How often the window redraws while a quick run is in progress, so that its bar moves.
const PROGRESS_REPAINT: Duration = Duration::from_millis(100);

/// Where the tables on show came from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// The full sweep compiled into the binary.
    Bundled,
    /// The quick sweep run from this window, written into this directory.
    QuickRun(PathBuf),
    /// Tables loaded from a directory.
    Directory(PathBuf),
}

impl Source {
    pub fn describe(&self) -> String {
        match self {
            Self::Bundled => "bundled full sweep (docs/chart, made with `rosette chart`)".into(),
            Self::QuickRun(dir) => format!("quick chart run just now (files in {})", dir.display()),
            Self::Directory(dir) => format!("directory {}", dir.display()),
        }
    }
}

/// The quick sweep running on its own thread (`rosette-chart`, which drives the sweep's
/// pool), and where it writes. Dropping it cancels the sweep and joins the thread.
struct QuickRun {
    job: Job<Result<ChartReport, ChartError>>,
    out: PathBuf,
}

impl QuickRun {
    fn start(out: PathBuf) -> Result<Self, String> {
        // One run per core, as `rosette chart`; the solver thread then shares the cores.
        let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
        let options = ChartOptions { out: out.clone(), quick: true, threads };
        let job = Job::start("rosette-chart", move |progress| crate::chart::run_with_progress(&options, progress))
            .map_err(|e| format!("cannot start the chart thread: {e}"))?;
        Ok(Self { job, out })
    }

    /// Waits for the sweep's end (at once when it has finished) and returns its result.
    fn join(self) -> Result<ChartReport, String> {
        match self.job.join() {
            Some(result) => result.map_err(|e| e.to_string()),
            None => Err("the quick chart run failed unexpectedly (its thread panicked)".into()),
        }
    }
}

/// State of the chart window.
pub struct ChartView {
    pub open: bool,
    /// Directory to load the CSV files from (`rosette chart --out DIR`).
    pub dir: String,
    accuracy: Vec<AccuracyRow>,
    stability: Vec<StabilityRow>,
    /// Where `accuracy` and `stability` came from; `None` before the first load.
    source: Option<Source>,
    problem: Problem,
    /// The last failure (a missing directory, a failed run), shown above the tables.
    message: Option<String>,
    /// The last thing done that has no other feedback (a run cancelled).
    notice: Option<String>,
    quick: Option<QuickRun>,
    /// Where the quick run writes its CSVs and PNGs.
    quick_out: PathBuf,
}

impl Default for ChartView {
    fn default() -> Self {
        Self {
            open: false,
            dir: "chart".into(),
            accuracy: Vec::new(),
            stability: Vec::new(),
            source: None,
            problem: Problem::Cantilever,
            message: None,
            notice: None,
            quick: None,
            quick_out: std::env::temp_dir().join(format!("rosette-quick-chart-{}", std::process::id())),
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
    /// Shows `accuracy` and `stability`, from `source`.
    fn install(&mut self, accuracy: Vec<AccuracyRow>, stability: Vec<StabilityRow>, source: Source) {
        if !accuracy.iter().any(|r| r.problem == self.problem) {
            self.problem = accuracy.first().map_or(Problem::Cantilever, |r| r.problem);
        }
        self.accuracy = accuracy;
        self.stability = stability;
        self.source = Some(source);
        self.message = None;
    }

    /// Shows the full sweep compiled into the binary.
    pub fn load_bundled(&mut self) {
        let parsed = parse_accuracy(BUNDLED_ACCURACY, Path::new("docs/chart/accuracy.csv (bundled)"))
            .and_then(|a| Ok((a, parse_stability(BUNDLED_STABILITY, Path::new("docs/chart/stability.csv (bundled)"))?)));
        match parsed {
            Ok((accuracy, stability)) => self.install(accuracy, stability, Source::Bundled),
            Err(e) => self.message = Some(e.to_string()),
        }
    }

    /// Reads both tables from `self.dir`; a missing or malformed file is reported in the
    /// window and the tables on show stay.
    pub fn load(&mut self) {
        let dir = PathBuf::from(&self.dir);
        match (read_accuracy(&dir.join("accuracy.csv")), read_stability(&dir.join("stability.csv"))) {
            (Ok(accuracy), Ok(stability)) => self.install(accuracy, stability, Source::Directory(dir)),
            (Err(e), _) | (_, Err(e)) => {
                self.message = Some(format!("{e}. Make the files with `rosette chart --out {}`", self.dir));
            }
        }
    }

    /// Starts the quick sweep on its own thread, unless one is running.
    pub fn start_quick_run(&mut self) {
        if self.quick.is_some() {
            return;
        }
        self.notice = None;
        match QuickRun::start(self.quick_out.clone()) {
            Ok(run) => self.quick = Some(run),
            Err(e) => self.message = Some(e),
        }
    }

    /// Asks the quick run to stop: runs not yet started are skipped, those in progress end.
    pub fn cancel_quick_run(&self) {
        if let Some(run) = &self.quick {
            run.job.progress.cancel();
        }
    }

    /// A quick run is in progress (or cancelled and finishing its runs in progress).
    pub fn quick_running(&self) -> bool {
        self.quick.is_some()
    }

    /// Where the tables on show came from.
    pub fn source(&self) -> Option<&Source> {
        self.source.as_ref()
    }

    /// Takes a finished quick run's tables (or its failure) into the window.
    fn poll_quick_run(&mut self) {
        if !self.quick.as_ref().is_some_and(|run| run.job.finished()) {
            return;
        }
        let run = self.quick.take().expect("checked");
        let (out, cancelled) = (run.out.clone(), run.job.progress.is_cancelled());
        match run.join() {
            Ok(report) => {
                self.dir = out.display().to_string();
                self.install(report.accuracy, report.stability, Source::QuickRun(out));
            }
            Err(e) if cancelled => self.notice = Some(format!("Quick chart cancelled: {e}")),
            Err(e) => self.message = Some(format!("Quick chart failed: {e}")),
        }
    }

    pub fn show(&mut self, ctx: &egui::Context) {
        // A run's result is taken in even while the window is closed.
        self.poll_quick_run();
        if !self.open {
            return;
        }
        if self.source.is_none() && self.message.is_none() {
            self.load_bundled();
        }
        if self.quick.is_some() {
            ctx.request_repaint_after(PROGRESS_REPAINT);
        }
        let mut open = self.open;
        egui::Window::new("Speed against accuracy").open(&mut open).default_size([560.0, 640.0]).show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.contents(ui));
        });
        self.open = open;
    }

    /// The source line, the quick-run controls and progress, and loading from a directory.
    fn controls(&mut self, ui: &mut egui::Ui) {
        if let Some(source) = &self.source {
            ui.horizontal_wrapped(|ui| {
                ui.label("Showing:");
                ui.strong(source.describe());
            });
        }
        match &self.quick {
            None => {
                ui.horizontal(|ui| {
                    let plan = Plan::new(true);
                    let runs = plan.accuracy.len() + plan.stability.len();
                    if ui
                        .button("Run quick chart")
                        .on_hover_text(format!(
                            "The sweep of `rosette chart --quick` ({runs} runs, no drape; tens of seconds), on a background \
                             thread; writes its CSVs and PNGs into {}",
                            self.quick_out.display()
                        ))
                        .clicked()
                    {
                        self.start_quick_run();
                    }
                    if self.source != Some(Source::Bundled) && ui.button("Show bundled full sweep").clicked() {
                        self.load_bundled();
                    }
                });
            }
            Some(run) => {
                let progress = &run.job.progress;
                let (done, total, fraction) = (progress.done(), progress.total(), progress.fraction() as f32);
                let cancelling = progress.is_cancelled();
                ui.horizontal(|ui| {
                    ui.add(
                        egui::ProgressBar::new(fraction)
                            .desired_width(300.0)
                            .text(format!("{done} / {total} runs, {:.0} s", run.job.started.elapsed().as_secs_f64())),
                    );
                    if ui.add_enabled(!cancelling, egui::Button::new("Cancel")).clicked() {
                        progress.cancel();
                    }
                });
                let running = progress.running();
                if cancelling {
                    ui.small(format!("Cancelling: waiting for the {} run(s) in progress to end", running.len()));
                } else if total == 0 {
                    ui.small("Planning the sweep…");
                }
                for label in running {
                    ui.small(format!("running: {label}"));
                }
            }
        }
        egui::CollapsingHeader::new("Load from directory").show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label("directory");
                ui.text_edit_singleline(&mut self.dir);
                if ui.button("Load").on_hover_text("accuracy.csv and stability.csv of `rosette chart --out DIR`").clicked() {
                    self.load();
                }
            });
        });
        if let Some(notice) = &self.notice {
            ui.colored_label(Color32::from_rgb(130, 210, 130), notice);
        }
        if let Some(message) = &self.message {
            ui.colored_label(Color32::from_rgb(255, 110, 100), message);
        }
        ui.separator();
    }

    fn contents(&mut self, ui: &mut egui::Ui) {
        self.controls(ui);
        if self.accuracy.is_empty() && self.stability.is_empty() {
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
                    let exact = |r: &&&AccuracyRow| r.integrator == kind && r.path == SolverPath::Exact;
                    let mut edges: Vec<f64> = rows.iter().filter(exact).map(|r| r.edge_length).collect();
                    edges.sort_by(f64::total_cmp);
                    edges.dedup();
                    for edge in edges {
                        let mut points: Vec<[f64; 2]> = rows
                            .iter()
                            .filter(exact)
                            .filter(|r| r.edge_length == edge)
                            .filter_map(|r| log_point(r.cpu_seconds, r.error?))
                            .collect();
                        points.sort_by(|a, b| a[0].total_cmp(&b[0]));
                        plot.line(Line::new(kind.name(), PlotPoints::from(points.clone())).color(integrator_colour(kind)).width(2.0));
                        plot.points(Points::new(kind.name(), PlotPoints::from(points)).color(integrator_colour(kind)).radius(3.0));
                    }
                }
                // The fast path: one run per mesh, joined from coarse to fine.
                let mut fast: Vec<[f64; 2]> =
                    rows.iter().filter(|r| r.path == SolverPath::Fast).filter_map(|r| log_point(r.cpu_seconds, r.error?)).collect();
                if !fast.is_empty() {
                    fast.sort_by(|a, b| a[0].total_cmp(&b[0]));
                    let c = crate::chart::plot::FAST_PATH_COLOUR;
                    let colour = Color32::from_rgb(c.0, c.1, c.2);
                    plot.line(Line::new("fast path", PlotPoints::from(fast.clone())).color(colour).width(2.0));
                    plot.points(Points::new("fast path", PlotPoints::from(fast)).color(colour).shape(MarkerShape::Up).radius(5.0));
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
            ui.small("green bounded, orange inaccurate, red diverged; circles symplectic Euler, squares implicit Euler, triangles BDF2; line: explicit limit 2/ω_max");
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
    use std::time::Instant;

    fn frame(ctx: &egui::Context, view: &mut ChartView) {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1280.0, 800.0))),
            ..Default::default()
        };
        ctx.run_ui(input, |ui| view.show(ui.ctx())).drop_without_applying_deltas();
    }

    #[test]
    fn chart_window_opens_on_the_bundled_full_sweep() {
        let ctx = egui::Context::default();
        let mut view = ChartView { open: true, ..Default::default() };
        frame(&ctx, &mut view);
        assert_eq!(view.message, None);
        assert_eq!(view.source(), Some(&Source::Bundled));
        // One row per data line of the committed files.
        assert_eq!(view.accuracy.len(), BUNDLED_ACCURACY.lines().count() - 1);
        assert_eq!(view.stability.len(), BUNDLED_STABILITY.lines().count() - 1);
        // The full sweep has every problem, the drape included, and both stability maps.
        for problem in Problem::ALL {
            assert!(view.accuracy.iter().any(|r| r.problem == problem), "{}", problem.name());
        }
        for map in StabilityMap::ALL {
            assert!(view.stability.iter().any(|r| r.map == map), "{}", map.name());
        }
    }

    #[test]
    fn quick_run_works_in_the_background_and_a_cancel_keeps_the_tables_on_show() {
        let ctx = egui::Context::default();
        let out = std::env::temp_dir().join(format!("rosette-chart-view-cancel-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let mut view = ChartView { open: true, quick_out: out.clone(), ..Default::default() };
        frame(&ctx, &mut view);
        view.start_quick_run();
        frame(&ctx, &mut view);
        // The frame came back while the sweep runs: the UI thread does not wait for it.
        assert!(view.quick_running());
        view.cancel_quick_run();
        let deadline = Instant::now() + Duration::from_secs(300);
        while view.quick_running() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(20));
            frame(&ctx, &mut view);
        }
        assert!(!view.quick_running(), "the cancelled sweep ended");
        assert!(view.notice.as_deref().is_some_and(|n| n.contains("cancelled")), "{:?} {:?}", view.notice, view.message);
        assert_eq!(view.message, None);
        assert_eq!(view.source(), Some(&Source::Bundled), "a cancelled run leaves the tables on show");
        assert!(!out.join("accuracy.csv").exists(), "a cancelled sweep writes nothing");
        std::fs::remove_dir_all(&out).ok();
    }

    #[test]
    fn chart_window_loads_the_tables_and_says_when_they_are_missing() {
        let dir = std::env::temp_dir().join(format!("rosette-chart-view-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ctx = egui::Context::default();
        let mut view = ChartView { open: true, dir: dir.join("missing").display().to_string(), ..Default::default() };
        frame(&ctx, &mut view);
        view.load();
        frame(&ctx, &mut view);
        assert!(view.message.as_deref().is_some_and(|m| m.contains("rosette chart")), "{:?}", view.message);
        assert_eq!(view.source(), Some(&Source::Bundled), "a failed load keeps the tables on show");

        let mut accuracy: Vec<AccuracyRow> = [(0.1, 0.02), (0.5, 0.01)]
            .into_iter()
            .map(|(cpu, error)| AccuracyRow {
                problem: Problem::Tensile,
                integrator: IntegratorKind::Bdf2,
                path: SolverPath::Exact,
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
        assert_eq!(view.source(), Some(&Source::Directory(dir.clone())));
        assert_eq!(view.problem, Problem::Tensile, "the window shows a problem that has rows");
    }
}
