//! The explicit stability limit the model reports (2/ω_max by power iteration) separates
//! stable from divergent symplectic-Euler steps, and a blow-up is caught with that limit in
//! its message.

use glam::DVec3;
use rosette::sim::{Fabric, Integrator, IntegratorKind, Mesh, Model, Pattern, PhysicsOptions, PiecewiseLinear, State, StepError};

fn sheet(pattern: Pattern, bending: bool) -> (Model, Vec<DVec3>) {
    let fabric = Fabric {
        areal_density: 0.137,
        thickness: 3.14e-4,
        tensile_warp: PiecewiseLinear::linear(1000.0),
        tensile_weft: PiecewiseLinear::linear(800.0),
        shear_modulus: 40.0,
        poisson_warp: 0.15,
        bending_warp: 9e-6,
        bending_weft: 7e-6,
        bending_bias: None,
        bending_curve: None,
    };
    let mesh = Mesh::rectangle(0.06, 0.04, 0.005, pattern, 5).unwrap();
    let options = PhysicsOptions { gravity: DVec3::ZERO, bending, ..Default::default() };
    let model = Model::new(&mesh, &fabric, 0.3, options).unwrap();
    // A tiny random displacement puts energy into every mode, the fastest included.
    let x = model
        .rest
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let t = i as f64;
            DVec3::new(p.x, p.y, 0.0) + 1e-7 * DVec3::new((t * 1.7).sin(), (t * 2.3).cos(), (t * 0.9).sin())
        })
        .collect();
    (model, x)
}

/// Steps symplectic Euler `steps` times at `dt`; returns the error if it diverged.
fn run(model: &Model, x: &[DVec3], dt: f64, steps: usize) -> Option<StepError> {
    let mut integrator = Integrator::new(IntegratorKind::SymplecticEuler, dt);
    let mut state = State::at_rest(x.to_vec());
    (0..steps).find_map(|_| integrator.step(model, &mut state).err())
}

/// Regression: on the jittered mesh, nearly ill-posed quadratic fits once gave the bending
/// matrix eigenvalues a million times too high (a limit of 5e-7 s instead of 4e-5 s); the
/// order-of-magnitude check against h/c below catches that.
///
/// Leapfrog is stable for dt < 2/ω_max: at 0.9 of the reported limit a perturbed sheet
/// stays bounded for 4000 steps; at 1.1 the fastest mode grows by a factor of about 2 per
/// step and the blow-up is caught within 400 steps.
#[test]
fn reported_limit_separates_stable_from_divergent_steps() {
    for (pattern, bending) in [(Pattern::Alternating, false), (Pattern::Equilateral, false), (Pattern::Jittered, true)] {
        let (model, x) = sheet(pattern, bending);
        let limit = model.explicit_step_limit(&x);
        // The CFL-like estimate h/√(E/ρ_A) is the right order of magnitude.
        let cfl = model.mean_edge_length / (model.max_membrane_stiffness() / 0.137f64).sqrt();
        println!("{pattern:?} bending {bending}: limit {limit:.4e} s, h/c = {cfl:.4e} s");
        assert!(limit > 0.2 * cfl && limit < 2.0 * cfl);
        assert!(run(&model, &x, 0.9 * limit, 4000).is_none(), "{pattern:?}: unstable below the reported limit");
        let err = run(&model, &x, 1.1 * limit, 400).expect("diverges above the reported limit");
        let message = err.to_string();
        assert!(message.contains("symplectic-euler") && message.contains("stable here only below dt"), "{message}");
    }
}


/// An explicit drape above its limit is caught within a few steps, with contact and
/// self-collision on: the blow-up shows as vertices faster than the cloth's fastest wave,
/// and its paths are not swept for collisions (that sweep over a scene-sized box never
/// ended). At ten times the limit the run stops with a divergence, not a hang.
#[test]
fn explicit_drape_above_its_limit_is_caught_not_swept() {
    use rosette::scene::{RunOptions, Scene, load_scene, run_scene};
    let overrides: Vec<String> =
        ["mesh.edge_length=0.03", "solver.integrator=symplectic-euler", "solver.dt=0.003"].iter().map(|s| s.to_string()).collect();
    let (config, _) = load_scene("cusick-drape-30", &overrides).unwrap();
    let mut scene = Scene::build(config).unwrap();
    let limit = scene.model.explicit_step_limit(&scene.state.x);
    assert!(0.003 > 5.0 * limit, "the test needs dt far above the limit {limit:e}");
    let (metrics, error) = run_scene(&mut scene, "cusick-drape-30", RunOptions { duration: Some(1.0), ..Default::default() });
    let message = error.expect("the explicit drape must diverge").to_string();
    println!("{} steps: {message}", metrics.steps);
    assert!(metrics.steps < 20 && !metrics.stable, "{} steps", metrics.steps);
    assert!(message.contains("symplectic-euler") && message.contains("stable here only below"), "{message}");
}

/// `--max-wall` holds within a step: past the scene's deadline Newton starts no further
/// iteration, so a step that one pathological scene would spend minutes on ends at once,
/// reported unconverged (never passed off as converged), and the run stops at its bound.
#[test]
fn a_wall_time_bound_stops_newton_within_the_step() {
    use rosette::scene::{RunOptions, Scene, load_scene, run_scene};
    let (config, _) = load_scene("sphere-drop", &["mesh.edge_length=0.05".to_string()]).unwrap();
    let mut scene = Scene::build(config.clone()).unwrap();
    let report = scene.step().unwrap();
    assert!(!report.newton_unconverged && report.newton_iterations > 0, "the first step converges without a bound");
    let mut bounded = Scene::build(config).unwrap();
    bounded.deadline = Some(std::time::Instant::now());
    let report = bounded.step().unwrap();
    assert!(report.newton_unconverged && report.newton_iterations == 0, "{report:?}");
    // Through the run: the bound's deadline is the scene's while it runs, and cleared after.
    let mut run = Scene::new(scene.config.clone()).unwrap();
    let (metrics, _) = run_scene(&mut run, "bounded", RunOptions { max_wall_seconds: Some(1e-3), ..Default::default() });
    assert!(metrics.stopped_at_limit.is_some() && metrics.steps <= 2, "{:?} after {} steps", metrics.stopped_at_limit, metrics.steps);
    assert!(run.deadline.is_none());
}
