//! The runs behind the charts: which problems, integrators, time steps, meshes and
//! stiffnesses, how each run's error is measured against its known answer, and the
//! explicit stability limit each run is compared with.

use crate::reference::{euler_elastica_from_shortening, heavy_cantilever};
use crate::physics::{cantilever_lambda, weight_per_area};
use crate::scene::{Measures, RunOptions, Scene, SceneConfig, load_scene, run_scene};
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use glam::DVec3;

/// A bounded run is called inaccurate when its error against the known answer exceeds
/// this (relative for the elastica and tensile problems, absolute for the drape
/// coefficient).
pub const INACCURATE_ERROR: f64 = 0.05;

/// Below this extensometer strain a pull is not yet quasi-static (the grip starts from rest
/// and launches a stress wave), so the tensile error is taken above it, as in the tensile
/// tests.
const TENSILE_MIN_STRAIN: f64 = 0.002;

/// The problems with known answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Problem {
    /// ASTM D1388 cantilever: tip drop against the heavy elastica (docs/references.md §4).
    Cantilever,
    /// Pinned strip compressed 10 %: midspan deflection against the Euler elastica at the
    /// run's end-shortening (docs/references.md §5).
    Buckling,
    /// Warp strip pull: worst relative stress error against the input curve
    /// (docs/references.md §1).
    Tensile,
    /// Cusick drape, 30 cm specimen: drape coefficient against a fine-mesh run.
    Drape,
    /// A strip swinging from its top edge: period against the hanging chain's
    /// (docs/references.md §10), the one problem of the chart in motion.
    Swing,
}

impl Problem {
    pub const ALL: [Problem; 5] = [Self::Cantilever, Self::Buckling, Self::Tensile, Self::Drape, Self::Swing];

    pub fn name(self) -> &'static str {
        match self {
            Self::Cantilever => "cantilever",
            Self::Buckling => "euler-buckling",
            Self::Tensile => "tensile",
            Self::Drape => "drape",
            Self::Swing => "swing",
        }
    }

    /// What the error is, for chart titles and the summary.
    pub fn error_label(self) -> &'static str {
        match self {
            Self::Cantilever => "tip drop vs heavy elastica, relative",
            Self::Buckling => "midspan deflection vs elastica, relative",
            Self::Tensile => "worst stress vs input curve, relative",
            Self::Drape => "drape coefficient vs fine mesh, absolute",
            Self::Swing => "swing period vs hanging chain, relative",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    fn preset(self) -> &'static str {
        match self {
            Self::Cantilever => "cantilever",
            Self::Buckling => "euler-buckling",
            Self::Tensile => "tensile-warp",
            Self::Drape => "cusick-drape-30",
            Self::Swing => "swing",
        }
    }

    /// Changes to the bundled preset that shorten the run without changing the answer.
    fn overrides(self) -> &'static [&'static str] {
        match self {
            // Critically damped for its first mode (ω₁ ≈ 18 rad/s): settles in about half
            // a second instead of 1.3 s. Mass-proportional damping leaves the equilibrium,
            // and so the tip drop, unchanged.
            Self::Cantilever => &["solver.damping=30"],
            // Compressed at the preset's speed, then held for 1.8 s with the first mode
            // (ω₁ ≈ 10 rad/s) close to critically damped, instead of 7.8 s at 1/s.
            Self::Buckling => &["solver.damping=15", "scene.duration=2.0"],
            // Pulled to 6 % ten times faster than the preset: 0.6 s is still 500 times the
            // membrane wave's crossing time of the strip.
            Self::Tensile => &["test.speed=0.01", "scene.duration=0.6"],
            // A strip a quarter of the panel's width: every line across the width swings
            // as the same chain, so the period is the same for a quarter of the cost.
            Self::Swing => &["cloth.width=0.05"],
            Self::Drape => &[],
        }
    }
}

/// A time step: in seconds, or as a multiple of the explicit stability limit of the run's
/// own model (so that explicit runs sit at known distances from their limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Step {
    Seconds(f64),
    OfLimit(f64),
    /// The scene's own step, left to the solver path: the fast path's runs, which choose
    /// their step per level as `rosette run --fast` does. The table records the step the
    /// run ended on.
    Scene,
}

/// One run to make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    pub problem: Problem,
    pub integrator: IntegratorKind,
    /// The exact solver path or the fast one.
    pub path: SolverPath,
    pub step: Step,
    /// Mesh edge length, m.
    pub edge_length: f64,
    /// Factor on both tensile curves (the stress at every strain).
    pub tensile_scale: f64,
    /// Factor on the bending rigidities (warp, weft, bias).
    pub bending_scale: f64,
}

/// What one run gave.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub case: Case,
    /// Time step used, s.
    pub dt: f64,
    /// The explicit method's stability limit 2/ω_max for this model, s.
    pub explicit_limit: f64,
    pub triangles: usize,
    /// Initial warp tensile slope, N/m, and warp bending rigidity, N·m, of the run.
    pub tensile_stiffness: f64,
    pub bending_stiffness: f64,
    /// CPU seconds of the thread that ran it.
    pub cpu_seconds: f64,
    /// The problem's raw measure (tip drop, deflection, worst stress error, DC).
    pub measure: Option<f64>,
    /// Error against the known answer (for the drape, filled in once the reference is in).
    pub error: Option<f64>,
    pub diverged: bool,
    /// Why the run failed, if it did.
    pub message: Option<String>,
}

impl Case {
    /// A short description of the run, e.g. `euler-buckling implicit-euler dt 1.0e-2 s, 10 mm
    /// edges`, with the stiffness factors when they are not 1.
    pub fn label(&self) -> String {
        let step = match self.step {
            Step::Seconds(dt) => format!("dt {dt:.1e} s"),
            Step::OfLimit(factor) => format!("dt {factor}x its limit"),
            Step::Scene => "the scene's dt".into(),
        };
        let millimetres = (self.edge_length * 1e4).round() / 10.0;
        let mut label = format!("{} {} {step}, {millimetres} mm edges", self.problem.name(), self.integrator);
        if self.path == SolverPath::Fast {
            label += ", fast path";
        }
        if self.tensile_scale != 1.0 {
            label += &format!(", tensile x{}", self.tensile_scale);
        }
        if self.bending_scale != 1.0 {
            label += &format!(", bending x{}", self.bending_scale);
        }
        label
    }

    /// The scene of this case with time step `dt` (None: the scene's own).
    fn config(&self, dt: Option<f64>) -> Result<SceneConfig, String> {
        let mut overrides: Vec<String> = self.problem.overrides().iter().map(|s| s.to_string()).collect();
        overrides.push(format!("mesh.edge_length={}", self.edge_length));
        overrides.push(format!("solver.integrator={}", self.integrator.name()));
        overrides.push(format!("solver.path={}", self.path.name()));
        if let Some(dt) = dt {
            overrides.push(format!("solver.dt={dt}"));
        }
        // An explicit run at a fraction of its stability limit takes as many steps as that
        // needs (tens of millions on the stiffest maps): the sweep's cases are bounded by
        // construction, not by the command line's default step bound.
        overrides.push(format!("scene.max_steps={}", i64::MAX));
        let mut config = load_scene(self.problem.preset(), &overrides).map_err(|e| e.to_string())?.0.into_config();
        let f = &mut config.fabric.properties;
        for point in f.tensile_warp.iter_mut().chain(f.tensile_weft.iter_mut()) {
            point[1] *= self.tensile_scale;
        }
        f.bending_warp *= self.bending_scale;
        f.bending_weft *= self.bending_scale;
        f.bending_bias = f.bending_bias.map(|b| b * self.bending_scale);
        if let Some(curve) = &mut f.bending_curve {
            curve.iter_mut().for_each(|p| p[1] *= self.bending_scale);
        }
        Ok(config)
    }

    /// Runs the case to the end of its scene (or its first divergence).
    pub fn run(&self) -> Outcome {
        let mut outcome = Outcome::new(*self);
        if let Err(message) = self.run_into(&mut outcome) {
            outcome.message = Some(message);
        }
        outcome
    }

    fn run_into(&self, outcome: &mut Outcome) -> Result<(), String> {
        // The model does not depend on dt: build it once at a nominal step for the limit.
        let probe = Scene::new(self.config(Some(1e-3))?).map_err(|e| e.to_string())?;
        outcome.explicit_limit = explicit_limit(&probe);
        outcome.triangles = probe.model.triangle_count();
        let f = &probe.config.fabric.properties;
        let [a, b] = [f.tensile_warp[0], f.tensile_warp[1]];
        outcome.tensile_stiffness = (b[1] - a[1]) / (b[0] - a[0]);
        outcome.bending_stiffness = f.bending_warp;
        let dt = match self.step {
            Step::Seconds(dt) => Some(dt),
            Step::OfLimit(factor) => Some(factor * outcome.explicit_limit),
            Step::Scene => None,
        };
        let config = self.config(dt)?;
        let mut scene = Scene::new(config.clone()).map_err(|e| e.to_string())?;
        let cpu = cpu_time::ThreadTime::now();
        let (metrics, error) = run_scene(&mut scene, self.problem.name(), RunOptions::default());
        outcome.cpu_seconds = cpu.elapsed().as_secs_f64();
        outcome.dt = scene.integrator.dt;
        if let Some(e) = error {
            outcome.diverged = true;
            outcome.message = Some(e.to_string());
            return Ok(());
        }
        let (measure, error) = measure_error(self.problem, &config, &metrics.measures)?;
        outcome.measure = Some(measure);
        outcome.error = error;
        Ok(())
    }
}

/// The symplectic-Euler limit 2/ω_max of a scene's model (`Model::explicit_step_limit`). The
/// tensile pull stiffens as it goes (wool's last slope is 15.7 times its first), so there the
/// limit is also taken on the strip stretched uniformly to the test's final strain, and the
/// smaller of the two is the run's limit.
pub fn explicit_limit(scene: &Scene) -> f64 {
    let x = &scene.state.x;
    let at_rest = scene.model.explicit_step_limit(x);
    match crate::scene::kinds::of(scene.config.scene.kind).final_stretch(&scene.config) {
        Some(strain) => {
            let stretched: Vec<DVec3> = x.iter().map(|p| DVec3::new(p.x * (1.0 + strain), p.y, p.z)).collect();
            at_rest.min(scene.model.explicit_step_limit(&stretched))
        }
        _ => at_rest,
    }
}

/// The problem's measure and its error against the analytic answer (`None` for the drape,
/// whose reference is another run).
fn measure_error(problem: Problem, config: &SceneConfig, measures: &Measures) -> Result<(f64, Option<f64>), String> {
    let other_rig = || format!("{}: the scene's rig does not measure this problem", problem.name());
    let length = config.cloth.length;
    match problem {
        Problem::Cantilever => {
            // λ = w L³ / B with B the warp rigidity: the strip is cut along the warp.
            let weight = weight_per_area(config.fabric.properties.areal_density);
            let lambda = cantilever_lambda(weight, length, config.fabric.properties.bending_warp);
            let exact = heavy_cantilever(lambda).tip_drop_over_l;
            let drop = measures.cantilever().ok_or_else(other_rig)?.tip_drop / length;
            Ok((drop, Some((drop - exact).abs() / exact)))
        }
        Problem::Buckling => {
            let euler = measures.euler().ok_or_else(other_rig)?;
            let exact = euler_elastica_from_shortening(euler.end_shortening).midspan_deflection_over_l;
            let deflection = euler.midspan_deflection / length;
            Ok((deflection, Some((deflection - exact).abs() / exact)))
        }
        Problem::Tensile => {
            let curve = &measures.tensile().ok_or_else(other_rig)?.stress_strain;
            let input = &config.fabric.properties.tensile_warp;
            let mut worst = 0.0f64;
            let mut compared = 0;
            // A point that is not finite (written as null in the metrics) is not compared.
            for &[strain, stress] in curve.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
                if strain > TENSILE_MIN_STRAIN {
                    let expected = interpolate(input, strain);
                    worst = worst.max((stress - expected).abs() / expected);
                    compared += 1;
                }
            }
            // Too few samples to call it a curve: the pull did not run its course.
            let error = (compared >= 10).then_some(worst);
            Ok((worst, error))
        }
        Problem::Drape => Ok((measures.drape().ok_or_else(other_rig)?.drape_coefficient, None)),
        Problem::Swing => {
            let swing = measures.swing().ok_or_else(other_rig)?;
            // A run that damped the swing out before two half periods has no period to compare.
            let period = swing.swing_period.ok_or("the swing died out before two half periods: no period to compare")?;
            Ok((period, Some((period - swing.chain_period).abs() / swing.chain_period)))
        }
    }
}

/// Linear interpolation of a piecewise-linear curve, continued past its ends with the end
/// segments' slopes (the fabric model's rule).
fn interpolate(curve: &[[f64; 2]], x: f64) -> f64 {
    let i = curve.windows(2).position(|w| x < w[1][0]).unwrap_or(curve.len() - 2);
    let (a, b) = (curve[i], curve[i + 1]);
    a[1] + (b[1] - a[1]) / (b[0] - a[0]) * (x - a[0])
}

/// Stability status of a run, as the stability chart draws it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Bounded, with an error within [`INACCURATE_ERROR`].
    Bounded,
    /// Bounded, but the error exceeds [`INACCURATE_ERROR`] (or the measure is missing).
    Inaccurate,
    /// The step was rejected as divergent.
    Diverged,
}

impl Status {
    pub fn name(self) -> &'static str {
        match self {
            Self::Bounded => "bounded",
            Self::Inaccurate => "inaccurate",
            Self::Diverged => "diverged",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        [Self::Bounded, Self::Inaccurate, Self::Diverged].into_iter().find(|s| s.name() == name)
    }
}

impl Outcome {
    /// A case not yet run.
    pub fn new(case: Case) -> Self {
        Self {
            case,
            dt: f64::NAN,
            explicit_limit: f64::NAN,
            triangles: 0,
            tensile_stiffness: f64::NAN,
            bending_stiffness: f64::NAN,
            cpu_seconds: 0.0,
            measure: None,
            error: None,
            diverged: false,
            message: None,
        }
    }

    pub fn status(&self) -> Status {
        match (self.diverged, self.error) {
            (true, _) => Status::Diverged,
            (false, Some(e)) if e <= INACCURATE_ERROR => Status::Bounded,
            _ => Status::Inaccurate,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_follows_the_curve_and_continues_its_end_slopes() {
        let curve = [[0.0, 0.0], [0.01, 10.0], [0.02, 30.0]];
        assert_eq!(interpolate(&curve, 0.005), 5.0);
        assert!((interpolate(&curve, 0.015) - 20.0).abs() < 1e-12);
        assert!((interpolate(&curve, 0.03) - 50.0).abs() < 1e-12);
        assert!((interpolate(&curve, -0.01) + 10.0).abs() < 1e-12);
    }

    #[test]
    fn status_follows_divergence_then_the_error_threshold() {
        let case = Case {
            problem: Problem::Tensile,
            integrator: IntegratorKind::Bdf2,
            path: SolverPath::Exact,
            step: Step::Seconds(0.01),
            edge_length: 0.01,
            tensile_scale: 1.0,
            bending_scale: 1.0,
        };
        let mut outcome = Outcome::new(case);
        outcome.error = Some(0.5 * INACCURATE_ERROR);
        assert_eq!(outcome.status(), Status::Bounded);
        outcome.error = Some(2.0 * INACCURATE_ERROR);
        assert_eq!(outcome.status(), Status::Inaccurate);
        outcome.error = None;
        assert_eq!(outcome.status(), Status::Inaccurate);
        outcome.diverged = true;
        assert_eq!(outcome.status(), Status::Diverged);
    }
}
