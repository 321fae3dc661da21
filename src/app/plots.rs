//! Live plots of the running test beside their references: the measured stress–strain
//! curve against the fabric's input curve (paper Fig. 4), the Euler end force against the
//! elastica, and any scalar measure over time.

use super::worker::Snapshot;
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints, Points};

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
    /// Adds the snapshot's scalar measures (starting afresh on a new scene or a reset).
    pub fn record(&mut self, snapshot: &Snapshot) {
        let scalars: Vec<(String, f64)> = snapshot
            .measures
            .as_object()
            .map(|m| m.iter().filter_map(|(k, v)| Some((k.clone(), v.as_f64().filter(|x| x.is_finite())?))).collect())
            .unwrap_or_default();
        let names: Vec<String> = scalars.iter().map(|(k, _)| k.clone()).collect();
        if snapshot.scene_generation != self.generation || names != self.names {
            self.generation = snapshot.scene_generation;
            self.names = names;
            self.rows.clear();
        }
        if self.rows.last().is_some_and(|(t, _)| *t >= snapshot.time) {
            return;
        }
        self.rows.push((snapshot.time, scalars.into_iter().map(|(_, v)| v).collect()));
        if self.rows.len() > HISTORY_LIMIT {
            let mut keep = false;
            self.rows.retain(|_| {
                keep = !keep;
                keep
            });
        }
    }

    /// The series of measure `name` over time.
    pub fn series(&self, name: &str) -> Vec<[f64; 2]> {
        let Some(k) = self.names.iter().position(|n| n == name) else { return Vec::new() };
        self.rows.iter().map(|(t, v)| [*t, v[k]]).collect()
    }
}

/// Complete elliptic integrals K(k) and E(k) of modulus k (0 ≤ k < 1) by the
/// arithmetic–geometric mean.
pub fn elliptic_ke(k: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    let mut sum = 0.5 * k * k;
    let mut power = 0.5;
    for _ in 0..40 {
        let c = 0.5 * (a - b);
        let (an, bn) = (0.5 * (a + b), (a * b).sqrt());
        power *= 2.0;
        sum += power * c * c;
        a = an;
        b = bn;
        if c.abs() < 1e-16 {
            break;
        }
    }
    let big_k = std::f64::consts::FRAC_PI_2 / a;
    (big_k, big_k * (1.0 - sum))
}

/// The pinned–pinned (first-mode) elastica: (end shortening Δ/L, P/P_cr) for end slopes up
/// to `max_shortening`. With k = sin(α/2): P/P_cr = (2K/π)², Δ/L = 2 − 2E/K.
pub fn elastica(max_shortening: f64) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0, 1.0]];
    for i in 1..200 {
        let k = 0.95 * i as f64 / 200.0;
        let (big_k, big_e) = elliptic_ke(k);
        let shortening = 2.0 - 2.0 * big_e / big_k;
        if shortening > max_shortening {
            break;
        }
        out.push([shortening, (2.0 * big_k / std::f64::consts::PI).powi(2)]);
    }
    out
}

fn array2(value: &serde_json::Value) -> Vec<[f64; 2]> {
    value
        .as_array()
        .map(|rows| rows.iter().filter_map(|r| Some([r.get(0)?.as_f64()?, r.get(1)?.as_f64()?])).collect())
        .unwrap_or_default()
}

/// Draws the plot that suits the running test; returns false when there is none (the
/// caller then offers the scalar history).
pub fn test_plot(ui: &mut egui::Ui, snapshot: &Snapshot) -> bool {
    let measures = &snapshot.measures;
    let config = &snapshot.config;
    if let Some(series) = measures.get("stress_strain") {
        let measured = array2(series);
        let angle = config.cloth.warp_angle_deg.rem_euclid(180.0);
        let (reference, label) = if angle.abs() < 1e-9 {
            (Some(&config.fabric.tensile_warp), "input warp curve")
        } else if (angle - 90.0).abs() < 1e-9 {
            (Some(&config.fabric.tensile_weft), "input weft curve")
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
    if let (Some(history), Some(euler)) = (measures.get("force_history"), measures.get("euler_load").and_then(|v| v.as_f64())) {
        let points: Vec<[f64; 2]> = history
            .as_array()
            .map(|rows| rows.iter().filter_map(|r| Some([r.get(1)?.as_f64()?, r.get(2)?.as_f64()? / euler])).collect())
            .unwrap_or_default();
        let top = points.iter().map(|p| p[0]).fold(0.0, f64::max).max(0.01);
        ui.label(format!("End force / Euler load ({euler:.3e} N/m) against end shortening; elastica dashed"));
        Plot::new("euler_live")
            .height(180.0)
            .legend(Legend::default())
            .x_axis_label("end shortening Δ/L")
            .y_axis_label("P / P_cr")
            .show(ui, |plot| {
                plot.line(Line::new("elastica", PlotPoints::from(elastica(top))).style(LineStyle::dashed_loose()).width(2.0));
                plot.hline(HLine::new("Euler load", 1.0).style(LineStyle::dotted_dense()));
                plot.points(Points::new("measured", PlotPoints::from(points)).radius(2.0));
            });
        ui.small("Fast compression runs above the quasi-static elastica until the higher modes settle.");
        return true;
    }
    false
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
    fn elliptic_integrals_match_tables() {
        let (k0, e0) = elliptic_ke(0.0);
        assert!((k0 - std::f64::consts::FRAC_PI_2).abs() < 1e-15 && (e0 - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        // m = k² = 0.5 (Abramowitz & Stegun table 17.1).
        let (k, e) = elliptic_ke(0.5f64.sqrt());
        assert!((k - 1.854_074_677_301_372).abs() < 1e-12, "{k}");
        assert!((e - 1.350_643_881_047_675).abs() < 1e-12, "{e}");
    }

    #[test]
    fn elastica_starts_at_the_euler_load_with_slope_one_half() {
        // Post-buckling: P/P_cr ≈ 1 + Δ/(2L) for small Δ/L; 1.0530 at Δ/L = 10 % (README).
        let curve = elastica(0.2);
        let near = |s: f64| curve.iter().min_by(|a, b| (a[0] - s).abs().total_cmp(&(b[0] - s).abs())).unwrap();
        let small = near(0.005);
        assert!(((small[1] - 1.0) / small[0] - 0.5).abs() < 0.01, "{small:?}");
        let ten = near(0.1);
        assert!((ten[0] - 0.1).abs() < 0.005);
        assert!((ten[1] - (1.0 + 0.53 * ten[0])).abs() < 0.003, "{ten:?}");
    }
}
