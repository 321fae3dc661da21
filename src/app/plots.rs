//! Live plots of the running test beside their references: the measured stress–strain
//! curve against the fabric's input curve (paper Fig. 4), the quasi-static Euler end force
//! against the elastica, and any scalar measure over time (by default one that the test
//! changes, see `scene::Kind::plot_series`).

use super::worker::Snapshot;
use crate::reference::euler_elastica_from_modulus;
use crate::scene::Measures;
use egui::Color32;
use egui_plot::{Corner, HLine, Legend, Line, LineStyle, Plot, PlotBounds, PlotPoints, Points};

/// Scalar measures sampled from the snapshots while the viewer watched.
#[derive(Debug, Default)]
pub struct History {
    generation: u64,
    /// Names of the scalar measures, in the order of each row's values.
    pub names: Vec<String>,
    /// (time s, values).
    pub rows: Vec<(f64, Vec<f64>)>,
}

/// Rows kept before the history is thinned to every other row.
const HISTORY_LIMIT: usize = 4000;

impl History {
    /// Adds the snapshot's scalar measures (starting afresh on a new scene or a reset). A
    /// measure that appears during the run (a critical load once the strip buckles, a
    /// rigidity once the curvature is not zero) joins the list without clearing what was
    /// recorded; rows without it hold NaN there.
    pub fn record(&mut self, snapshot: &Snapshot) {
        let scalars = snapshot.measures.scalars();
        if snapshot.scene_generation != self.generation {
            self.generation = snapshot.scene_generation;
            self.names.clear();
            self.rows.clear();
        }
        if self.rows.last().is_some_and(|(t, _)| *t >= snapshot.time) {
            return;
        }
        for &(name, _) in &scalars {
            if !self.names.iter().any(|n| n == name) {
                self.names.push(name.to_string());
                self.rows.iter_mut().for_each(|(_, v)| v.push(f64::NAN));
            }
        }
        let mut values = vec![f64::NAN; self.names.len()];
        for (name, value) in scalars {
            let k = self.names.iter().position(|n| n == name).expect("added above");
            values[k] = value.value();
        }
        self.rows.push((snapshot.time, values));
        if self.rows.len() > HISTORY_LIMIT {
            let mut keep = false;
            self.rows.retain(|_| {
                keep = !keep;
                keep
            });
        }
    }

    /// The series of measure `name` over time (the samples where it had a value).
    pub fn series(&self, name: &str) -> Vec<[f64; 2]> {
        let Some(k) = self.names.iter().position(|n| n == name) else { return Vec::new() };
        self.rows.iter().filter(|(_, v)| v[k].is_finite()).map(|(t, v)| [*t, v[k]]).collect()
    }
}

/// The pinned–pinned (first-mode) elastica as the plot draws it: (end shortening Δ/L,
/// P/P_cr) up to `max_shortening`, at evenly spaced elliptic moduli k = sin(α/2) from
/// `crate::reference` (docs/references.md §5), so that the curve is dense where it bends.
pub fn elastica(max_shortening: f64) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0, 1.0]];
    for i in 1..200 {
        let shape = euler_elastica_from_modulus(0.95 * i as f64 / 200.0);
        if shape.shortening_over_l > max_shortening {
            break;
        }
        out.push([shape.shortening_over_l, shape.load_over_pcr]);
    }
    out
}

/// Draws the plot that suits the running test; returns false when there is none (the
/// caller then offers the scalar history).
pub fn test_plot(ui: &mut egui::Ui, snapshot: &Snapshot) -> bool {
    let config = &snapshot.config;
    if let Measures::Tensile(tensile) = &*snapshot.measures {
        let measured = tensile.stress_strain.clone();
        let angle = config.cloth.warp_angle_deg.rem_euclid(180.0);
        let (reference, label) = if angle.abs() < 1e-9 {
            (Some(&config.fabric.properties.tensile_warp), "input warp curve")
        } else if (angle - 90.0).abs() < 1e-9 {
            (Some(&config.fabric.properties.tensile_weft), "input weft curve")
        } else {
            (None, "")
        };
        let top = measured.iter().map(|p| p[0]).fold(config.test.max_strain.unwrap_or(0.06), f64::max);
        ui.label("Stress–strain: measured (extensometer) against the fabric's input curve");
        Plot::new("stress_strain_live")
            .height(180.0)
            .legend(Legend::default())
            .x_axis_label("strain")
            .y_axis_label("stress (N/m)")
            .show(ui, |plot| {
                if let Some(points) = reference {
                    let clipped: Vec<[f64; 2]> = points.iter().copied().filter(|p| p[0] <= top * 1.05).collect();
                    plot.line(Line::new(label, PlotPoints::from(clipped)).style(LineStyle::dashed_loose()).width(2.0));
                }
                plot.line(Line::new("measured", PlotPoints::from(measured)).width(2.0));
            });
        if reference.is_none() {
            ui.small("Off-axis pull: the sheet shears and necks; no closed-form reference for nonlinear curves.");
        }
        return true;
    }
    if let Measures::Swing(swing) = &*snapshot.measures {
        // The chain's first mode released from rest: a cos(2πt/T₁) (docs/references.md §10).
        let amplitude = config.test.swing_amplitude.unwrap_or(0.0);
        let end = swing.bottom_history.last().map_or(0.0, |p| p[0]);
        let chain: Vec<[f64; 2]> =
            (0..=400).map(|i| end * i as f64 / 400.0).map(|t| [t, amplitude * (std::f64::consts::TAU * t / swing.chain_period).cos()]).collect();
        let measured = match swing.swing_period {
            Some(p) => format!("period {p:.4} s against the chain's {:.4} s ({:+.2} %)", swing.chain_period, 100.0 * (p / swing.chain_period - 1.0)),
            None => format!("the chain's period {:.4} s; the swing's needs two half periods", swing.chain_period),
        };
        ui.label(format!("Free edge's sideways displacement: {measured}"));
        Plot::new("swing_live").height(180.0).legend(Legend::default()).x_axis_label("time (s)").y_axis_label("displacement (m)").show(ui, |plot| {
            plot.line(Line::new("hanging chain", PlotPoints::from(chain)).style(LineStyle::dashed_loose()).width(2.0));
            plot.line(Line::new("measured", PlotPoints::from(swing.bottom_history.clone())).width(2.0));
        });
        return true;
    }
    if let Measures::Euler(measured) = &*snapshot.measures {
        let euler = measured.euler_load;
        let points = euler_points(&measured.quasi_static_force, &measured.dynamic_force, euler);
        // Fixed axes: shortening up to the run's own (the test's target, or further if the
        // scene ran on), P/P_cr up to EULER_FORCE_TOP, so that the dynamic spikes of a fast
        // compression (up to 20 P_cr) cannot squash the elastica's 1.0–1.05 into a line.
        let target = config.test.end_shortening.unwrap_or(0.0);
        let right = points.dynamic.iter().chain(&points.quasi_static).map(|p| p[0]).fold(target, f64::max).max(0.01) * 1.05;
        let (off_scale, none_yet) = (points.off_scale, points.quasi_static.is_empty());
        ui.label(format!("End force / Euler load ({euler:.3e} N/m) against end shortening; elastica dashed"));
        Plot::new("euler_live")
            .height(180.0)
            .legend(Legend::default().position(Corner::LeftTop))
            .x_axis_label("end shortening Δ/L")
            .y_axis_label("P / P_cr")
            .allow_zoom(false)
            .allow_drag(false)
            .allow_scroll(false)
            .allow_boxed_zoom(false)
            .show(ui, |plot| {
                plot.set_plot_bounds(PlotBounds::from_min_max([0.0, 0.0], [right, EULER_FORCE_TOP]));
                // The straight strip's branch (P rises to P_cr at a shortening of P_cr over
                // the membrane stiffness, ~1e-5 here), then the first-mode elastica.
                let mut reference = vec![[0.0, 0.0]];
                reference.extend(elastica(right));
                plot.line(Line::new("elastica", PlotPoints::from(reference)).style(LineStyle::dashed_loose()).width(2.0));
                plot.hline(HLine::new("Euler load", 1.0).style(LineStyle::dotted_dense()));
                plot.points(Points::new("dynamic", PlotPoints::from(points.dynamic)).color(Color32::from_gray(110)).radius(1.5));
                plot.points(Points::new("quasi-static", PlotPoints::from(points.quasi_static)).color(Color32::from_rgb(90, 200, 255)).radius(3.0));
            });
        let mut note = format!(
            "Quasi-static: out-of-balance load on the free vertices under {:.0} % of P_cr·w (the rest drawn grey as dynamic).",
            100.0 * crate::scene::kinds::euler::QUASI_STATIC_IMBALANCE
        );
        if off_scale > 0 {
            note += &format!(" {off_scale} samples outside 0–{EULER_FORCE_TOP} P_cr are off the scale.");
        }
        if none_yet {
            note += " None yet: a fast compression rings; the hold settles onto the elastica.";
        }
        ui.small(note);
        return true;
    }
    false
}

/// Top of the Euler plot's force axis, P/P_cr: the elastica is at 1.053 at 10 % shortening
/// and 1.113 at 20 %; this leaves room for the dynamic overshoot around it.
pub const EULER_FORCE_TOP: f64 = 2.0;

/// The Euler rig's samples as (Δ/L, P/P_cr): quasi-static and dynamic, without those off
/// the plot's scale (below 0 or above [`EULER_FORCE_TOP`]), which are counted.
#[derive(Debug, Default, PartialEq)]
pub struct EulerPoints {
    pub quasi_static: Vec<[f64; 2]>,
    pub dynamic: Vec<[f64; 2]>,
    pub off_scale: usize,
}

/// Splits the Euler rig's force samples for the plot: `quasi_static` and `dynamic` are its
/// `quasi_static_force` and `dynamic_force` (rows of Δ/L, P N/m; the rig sorts them by their
/// out-of-balance load, see [`crate::scene::kinds::euler::QUASI_STATIC_IMBALANCE`]) and `euler` is
/// P_cr, N/m. Samples off the scale are dropped, not allowed to stretch the axis.
pub fn euler_points(quasi_static: &[[f64; 2]], dynamic: &[[f64; 2]], euler: f64) -> EulerPoints {
    let mut points = EulerPoints::default();
    let mut on_scale = |rows: &[[f64; 2]]| -> Vec<[f64; 2]> {
        let scaled = rows.iter().map(|&[s, p]| [s, p / euler]);
        let (kept, dropped): (Vec<[f64; 2]>, Vec<[f64; 2]>) = scaled.partition(|p| (0.0..=EULER_FORCE_TOP).contains(&p[1]));
        points.off_scale += dropped.len();
        kept
    };
    let (quasi_static, dynamic) = (on_scale(quasi_static), on_scale(dynamic));
    EulerPoints { quasi_static, dynamic, ..points }
}

/// Plots measure `name` over time.
pub fn history_plot(ui: &mut egui::Ui, history: &History, name: &str) {
    Plot::new("history_live").height(160.0).x_axis_label("time (s)").y_axis_label(name).show(ui, |plot| {
        plot.line(Line::new(name, PlotPoints::from(history.series(name))).width(2.0));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elastica_starts_at_the_euler_load_with_slope_one_half() {
        // Post-buckling: P/P_cr ≈ 1 + Δ/(2L) for small Δ/L; 1.0530 at Δ/L = 10 %
        // (docs/references.md §5).
        let curve = elastica(0.2);
        let near = |s: f64| curve.iter().min_by(|a, b| (a[0] - s).abs().total_cmp(&(b[0] - s).abs())).unwrap();
        let small = near(0.005);
        assert!(((small[1] - 1.0) / small[0] - 0.5).abs() < 0.01, "{small:?}");
        let ten = near(0.1);
        assert!((ten[0] - 0.1).abs() < 0.005);
        assert!((ten[1] - (1.0 + 0.53 * ten[0])).abs() < 0.003, "{ten:?}");
    }
}
