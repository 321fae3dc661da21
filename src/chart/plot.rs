//! The PNG charts, drawn with plotters into an RGB buffer and saved with `image`. Text is
//! set in egui's bundled Ubuntu Light through plotters' ab_glyph backend, so no system font
//! is needed.

use super::data::{AccuracyRow, StabilityRow};
use super::sweep::{Problem, Status};
use super::StabilityMap;
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Size of one chart panel, pixels.
pub const PANEL: (u32, u32) = (560, 420);

pub(crate) fn register_font() {
    static FONT: Once = Once::new();
    FONT.call_once(|| {
        // The bundled font is a valid TTF; failing that, text would be missing, not wrong.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

/// The fast solver path's runs in the accuracy panels.
pub const FAST_PATH_COLOUR: RGBColor = RGBColor(230, 120, 0);

pub fn integrator_colour(kind: IntegratorKind) -> RGBColor {
    match kind {
        IntegratorKind::SymplecticEuler => RGBColor(214, 39, 40),
        IntegratorKind::ImplicitEuler => RGBColor(31, 119, 180),
        IntegratorKind::Bdf2 => RGBColor(44, 160, 44),
    }
}

pub fn status_colour(status: Status) -> RGBColor {
    match status {
        Status::Bounded => RGBColor(44, 160, 44),
        Status::Inaccurate => RGBColor(255, 150, 0),
        Status::Diverged => RGBColor(214, 39, 40),
    }
}

/// A log axis range covering `values` with a margin, at least a decade wide.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.filter(|v| v.is_finite() && *v > 0.0).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return 1e-3..1.0;
    }
    let (lo, hi) = (lo / 1.6, hi * 1.6);
    if hi / lo < 10.0 {
        let centre = (lo * hi).sqrt();
        return centre / 10f64.sqrt()..centre * 10f64.sqrt();
    }
    lo..hi
}

/// Labels 1, 2 and 5 times a power of ten on a log axis, and leaves the other ticks bare.
fn log_label(v: &f64) -> String {
    let exponent = v.log10().floor();
    let mantissa = v / 10f64.powf(exponent);
    match [1.0, 2.0, 5.0].into_iter().find(|m| (mantissa - m).abs() < 0.02 * m) {
        Some(m) if (-2.0..=2.0).contains(&exponent) => format!("{}", m * 10f64.powf(exponent)),
        Some(m) => format!("{m}e{exponent}"),
        None => String::new(),
    }
}

fn save(path: &Path, buffer: Vec<u8>, size: (u32, u32)) -> Result<(), String> {
    crate::io::write::png_file(path, &buffer, size, 3, crate::io::write::Effort::Smallest)
}

fn grid(cells: usize) -> (usize, usize) {
    match cells {
        0..=1 => (1, 1),
        2 => (1, 2),
        3 => (1, 3),
        _ => (2, cells.div_ceil(2)),
    }
}

/// Error against CPU time: one panel per problem, log–log, a curve per integrator and mesh
/// (over dt), the Pareto front drawn through its points and ringed in black.
pub fn draw_accuracy(path: &Path, rows: &[AccuracyRow], _: &[StabilityRow]) -> Result<(), String> {
    register_font();
    let problems: Vec<Problem> = Problem::ALL.into_iter().filter(|p| rows.iter().any(|r| r.problem == *p)).collect();
    let (grid_rows, grid_cols) = grid(problems.len());
    let size = (PANEL.0 * grid_cols as u32, PANEL.1 * grid_rows as u32);
    let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let panels = root.split_evenly((grid_rows, grid_cols));
        for (panel, &problem) in panels.iter().zip(&problems) {
            let rows: Vec<&AccuracyRow> = rows.iter().filter(|r| r.problem == problem).collect();
            accuracy_panel(panel, problem, &rows).map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    save(path, buffer, size)
}

/// The corner of a log–log panel with the fewest points in it, for the legend.
fn emptiest_corner(points: &[(f64, f64)], x: &std::ops::Range<f64>, y: &std::ops::Range<f64>) -> SeriesLabelPosition {
    let fraction = |v: f64, r: &std::ops::Range<f64>| (v.ln() - r.start.ln()) / (r.end.ln() - r.start.ln());
    let corners = [
        (SeriesLabelPosition::LowerLeft, false, false),
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
    ];
    let count = |right: bool, upper: bool| {
        points
            .iter()
            .filter(|&&(px, py)| {
                let (fx, fy) = (fraction(px, x), fraction(py, y));
                (if right { fx > 0.55 } else { fx < 0.45 }) && (if upper { fy > 0.6 } else { fy < 0.4 })
            })
            .count()
    };
    corners.into_iter().min_by_key(|&(_, right, upper)| count(right, upper)).map_or(SeriesLabelPosition::LowerLeft, |c| c.0)
}

type Panel<'a> = DrawingArea<BitMapBackend<'a>, Shift>;
type DrawResult = Result<(), Box<dyn std::error::Error>>;

fn accuracy_panel(panel: &Panel, problem: Problem, rows: &[&AccuracyRow]) -> DrawResult {
    let plotted: Vec<&&AccuracyRow> = rows.iter().filter(|r| r.error.is_some_and(|e| e > 0.0)).collect();
    let x = log_range(plotted.iter().map(|r| r.cpu_seconds));
    let y = log_range(plotted.iter().map(|r| r.error.unwrap_or(0.0)));
    let mut chart = ChartBuilder::on(panel)
        .caption(format!("{}: {}", problem.name(), problem.error_label()), ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(62)
        .build_cartesian_2d(x.clone().log_scale(), y.clone().log_scale())?;
    chart
        .configure_mesh()
        .x_desc("CPU seconds per run")
        .y_desc("error")
        .x_label_formatter(&log_label)
        .y_label_formatter(&log_label)
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE)
        .draw()?;
    for kind in IntegratorKind::ALL {
        let colour = integrator_colour(kind);
        let mut edges: Vec<f64> = plotted.iter().filter(|r| r.integrator == kind && r.path == SolverPath::Exact).map(|r| r.edge_length).collect();
        edges.sort_by(f64::total_cmp);
        edges.dedup();
        let mut labelled = false;
        for edge in edges {
            let mut curve: Vec<(f64, f64)> = plotted
                .iter()
                .filter(|r| r.integrator == kind && r.path == SolverPath::Exact && r.edge_length == edge)
                .map(|r| (r.cpu_seconds, r.error.unwrap_or(0.0)))
                .collect();
            curve.sort_by(|a, b| a.0.total_cmp(&b.0));
            let series = chart.draw_series(LineSeries::new(curve.clone(), colour.stroke_width(2)))?;
            if !labelled {
                series.label(kind.name()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
                labelled = true;
            }
            chart.draw_series(curve.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
        }
    }
    // The fast path: one run per mesh, joined from coarse to fine.
    let mut fast: Vec<(f64, f64)> =
        plotted.iter().filter(|r| r.path == SolverPath::Fast).map(|r| (r.cpu_seconds, r.error.unwrap_or(0.0))).collect();
    if !fast.is_empty() {
        fast.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(fast.clone(), FAST_PATH_COLOUR.stroke_width(2)))?
            .label("fast path")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], FAST_PATH_COLOUR.stroke_width(2)));
        chart.draw_series(fast.iter().map(|&p| TriangleMarker::new(p, 5, FAST_PATH_COLOUR.filled())))?;
    }
    let mut front: Vec<(f64, f64)> = plotted.iter().filter(|r| r.pareto).map(|r| (r.cpu_seconds, r.error.unwrap_or(0.0))).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(front.clone(), BLACK.stroke_width(1)))?
        .label("Pareto front")
        .legend(|(x, y)| Circle::new((x + 9, y), 5, BLACK.stroke_width(2)));
    chart.draw_series(front.iter().map(|&p| Circle::new(p, 6, BLACK.stroke_width(2))))?;
    let all: Vec<(f64, f64)> = plotted.iter().map(|r| (r.cpu_seconds, r.error.unwrap_or(0.0))).collect();
    chart
        .configure_series_labels()
        .position(emptiest_corner(&all, &x, &y))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .label_font(("sans-serif", 13))
        .draw()?;
    Ok(())
}

/// Stability maps: dt against stiffness, one panel per map, a marker per run (shape by
/// integrator, colour by status), and the explicit limit 2/ω_max computed from each model.
pub fn draw_stability(path: &Path, _: &[AccuracyRow], rows: &[StabilityRow]) -> Result<(), String> {
    register_font();
    let maps: Vec<StabilityMap> = StabilityMap::ALL.into_iter().filter(|m| rows.iter().any(|r| r.map == *m)).collect();
    let size = (PANEL.0 * maps.len().max(1) as u32, PANEL.1 + 40);
    let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (maps_area, key_area) = root.split_vertically(size.1 - 40);
        let panels = maps_area.split_evenly((1, maps.len().max(1)));
        for (panel, &map) in panels.iter().zip(&maps) {
            let rows: Vec<&StabilityRow> = rows.iter().filter(|r| r.map == map).collect();
            stability_panel(panel, map, &rows).map_err(|e| e.to_string())?;
        }
        stability_key(&key_area).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    save(path, buffer, size)
}

/// Integrators sit side by side around each stiffness: a factor on the x coordinate.
fn integrator_offset(kind: IntegratorKind) -> f64 {
    match kind {
        IntegratorKind::SymplecticEuler => 0.85,
        IntegratorKind::ImplicitEuler => 1.0,
        IntegratorKind::Bdf2 => 1.0 / 0.85,
    }
}

fn stability_panel(panel: &Panel, map: StabilityMap, rows: &[&StabilityRow]) -> DrawResult {
    let x = log_range(rows.iter().map(|r| r.stiffness()));
    let y = log_range(rows.iter().map(|r| r.dt).chain(rows.iter().map(|r| r.explicit_limit)));
    let (title, unit) = match map {
        StabilityMap::Tensile => ("tensile pull: dt against tensile stiffness", "initial warp tensile slope, N/m"),
        StabilityMap::Bending => ("cantilever: dt against bending rigidity", "warp bending rigidity, N m"),
    };
    let mut chart = ChartBuilder::on(panel)
        .caption(title, ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(62)
        .build_cartesian_2d(x.log_scale(), y.log_scale())?;
    chart
        .configure_mesh()
        .x_desc(unit)
        .y_desc("dt, s")
        .x_label_formatter(&log_label)
        .y_label_formatter(&log_label)
        .label_style(("sans-serif", 13))
        .light_line_style(WHITE)
        .draw()?;
    let mut limit: Vec<(f64, f64)> = rows.iter().map(|r| (r.stiffness(), r.explicit_limit)).collect();
    limit.sort_by(|a, b| a.0.total_cmp(&b.0));
    limit.dedup_by(|a, b| a.0 == b.0);
    chart.draw_series(LineSeries::new(limit, BLACK.stroke_width(2)))?;
    for r in rows {
        let at = (r.stiffness() * integrator_offset(r.integrator), r.dt);
        chart.plotting_area().draw(&marker_on(r.integrator, at, status_colour(r.status)))?;
    }
    Ok(())
}

/// A run's marker: shape by integrator, colour by status.
fn marker_on<'a, DB: DrawingBackend + 'a, C: Clone + 'a>(kind: IntegratorKind, at: C, colour: RGBColor) -> DynElement<'a, DB, C> {
    let style = colour.filled();
    match kind {
        IntegratorKind::SymplecticEuler => Circle::new(at, 5, style).into_dyn(),
        IntegratorKind::ImplicitEuler => (EmptyElement::at(at) + Rectangle::new([(-4, -4), (4, 4)], style)).into_dyn(),
        IntegratorKind::Bdf2 => (EmptyElement::at(at) + Polygon::new(vec![(0, -6), (5, 4), (-5, 4)], style)).into_dyn(),
    }
}

/// The key under the maps: marker shapes for integrators, colours for statuses.
fn stability_key(area: &Panel) -> DrawResult {
    let text = ("sans-serif", 14).into_font().color(&BLACK);
    area.draw(&PathElement::new(vec![(12, 20), (36, 20)], BLACK.stroke_width(2)))?;
    area.draw(&Text::new("explicit limit 2/ω_max", (42, 12), text.clone()))?;
    let mut x = 210;
    for kind in IntegratorKind::ALL {
        area.draw(&marker_on(kind, (x + 6, 20), RGBColor(90, 90, 90)))?;
        area.draw(&Text::new(kind.name(), (x + 16, 12), text.clone()))?;
        x += 140;
    }
    for status in [Status::Bounded, Status::Inaccurate, Status::Diverged] {
        area.draw(&Rectangle::new([(x, 14), (x + 12, 26)], status_colour(status).filled()))?;
        let label = match status {
            Status::Inaccurate => format!("inaccurate (error > {:.0} %)", 100.0 * super::INACCURATE_ERROR),
            s => s.name().to_string(),
        };
        area.draw(&Text::new(label, (x + 18, 12), text.clone()))?;
        x += if status == Status::Inaccurate { 190 } else { 95 };
    }
    Ok(())
}
