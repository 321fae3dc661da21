//! Adaptive time steps (`solver.adaptive`): the step follows the local error estimate,
//! shrinking where the cloth accelerates and growing where it is calm, and the answers stay
//! those of physics: a free fall against ½gt², a heavy cantilever against the elastica.

mod common;

use common::reference::heavy_cantilever;
use glam::DVec3;
use rosette::physics::STANDARD_GRAVITY as GRAVITY;
use rosette::scene::{RunOptions, Scene, load_scene, run_scene};
use rosette::sim::{AdaptiveStep, Fabric, Integrator, IntegratorKind, Mesh, Model, Pattern, PhysicsOptions, State};

fn wool() -> Fabric {
    let (config, _) = load_scene("tensile-warp", &[]).expect("bundled preset loads");
    config.fabric.to_fabric().expect("bundled fabric is valid")
}

/// A free sheet falling from rest under gravity: every vertex accelerates at g, so implicit
/// Euler's local position error is exactly ½h²g a step (it falls that much too far), and
/// after time T it has fallen ½gT² + ½g·Σh². The control must keep each step's error
/// within twice its tolerance, which bounds h by √(4τ/g), and the fall must exceed ½gT² by
/// exactly what the steps taken imply.
#[test]
fn free_fall_steps_keep_their_error_within_the_tolerance() {
    let mesh = Mesh::rectangle(0.04, 0.04, 0.01, Pattern::Alternating, 1).unwrap();
    let options = PhysicsOptions { membrane: true, bending: true, gravity: DVec3::new(0.0, 0.0, -GRAVITY), damping: 0.0 };
    let model = Model::new(&mesh, &wool(), 0.0, options).unwrap();
    let x0: Vec<DVec3> = model.rest.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect();
    let mut state = State::at_rest(x0);
    let tolerance = 1e-5;
    let mut integrator = Integrator::new(IntegratorKind::ImplicitEuler, 1e-4);
    integrator.adaptive = Some(AdaptiveStep { enabled: true, tolerance, dt_min: 1e-6, dt_max: 0.05 });
    let (mut excess, mut steps, mut largest) = (0.0, 0, 0.0f64);
    while state.time < 0.2 {
        let report = integrator.step(&model, &mut state).unwrap();
        let local = 0.5 * report.dt * report.dt * GRAVITY;
        assert!(local <= 2.0 * tolerance * (1.0 + 1e-9), "a step of {} s made a local error of {local:e} m", report.dt);
        // Implicit Euler: v is exact (v = −g t), x gains h·v_{n+1} = h·v_n − g h², half a
        // g h² more than the exact motion's h·v_n − ½ g h².
        excess += local;
        steps += 1;
        largest = largest.max(report.dt);
    }
    let exact = 0.5 * GRAVITY * state.time * state.time;
    let fall = -state.x[0].z;
    println!("{steps} steps (largest {largest:.4} s), fall {fall:.6} m vs ½gt² {exact:.6} m, excess {:.3e}", fall - exact);
    assert!(((fall - exact) - excess).abs() < 1e-3 * excess, "fall {fall} vs {exact}, expected excess {excess}");
    // The steps grow to the largest the tolerance allows: h = √(2τ/g) within the control's
    // safety factor and dead band, not the 0.1 ms it started from.
    let allowed = (4.0 * tolerance / GRAVITY).sqrt();
    assert!(largest > 0.5 * (2.0 * tolerance / GRAVITY).sqrt() && largest <= allowed, "largest step {largest}");
}

/// The cantilever settling under its own weight: adaptive steps reach the elastica's tip
/// drop (the same 2 % as the fixed-step test) in fewer steps than the preset's fixed 5 ms.
#[test]
fn adaptive_cantilever_matches_the_elastica_in_fewer_steps() {
    let run = |overrides: &[&str]| {
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        let (config, _) = load_scene("cantilever", &overrides).unwrap();
        let mut scene = Scene::build(config.clone()).unwrap();
        let (m, error) = run_scene(&mut scene, "cantilever", RunOptions::default());
        assert!(error.is_none(), "{error:?}");
        (config, m)
    };
    let (config, fixed) = run(&[]);
    let (_, adaptive) = run(&["solver.adaptive.tolerance=2e-5", "solver.adaptive.dt_max=0.05"]);
    let f = &config.fabric.properties;
    let length = config.cloth.length;
    let lambda = f.areal_density * GRAVITY * length.powi(3) / f.bending_warp;
    let exact = heavy_cantilever(lambda).tip_drop_over_l;
    let drop = |m: &rosette::scene::Metrics| m.measures.cantilever().expect("cantilever measures").tip_drop / length;
    println!(
        "λ {lambda:.2}: fixed {} steps, drop/L {:.4}; adaptive {} steps ({} rejected), {:.4}; elastica {exact:.4}",
        fixed.steps,
        drop(&fixed),
        adaptive.steps,
        adaptive.rejected_steps,
        drop(&adaptive)
    );
    assert_eq!(adaptive.settled, Some(true));
    assert!((drop(&adaptive) - exact).abs() < 0.02 * exact, "adaptive drop/L {} vs {exact}", drop(&adaptive));
    assert!(adaptive.steps < fixed.steps, "{} adaptive steps vs {} fixed", adaptive.steps, fixed.steps);
}

/// An explicit integrator has a fixed stability limit: asking it for adaptive steps is a
/// configuration error that says what to do.
#[test]
fn adaptive_steps_with_an_explicit_integrator_are_refused() {
    let err = load_scene("cantilever", &["solver.integrator=symplectic-euler".into(), "solver.dt=1e-5".into(), "solver.adaptive.tolerance=1e-5".into()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("solver.adaptive") && err.contains("implicit-euler"), "{err}");
    let err = load_scene("cantilever", &["solver.adaptive.dt_max=0.001".into()]).unwrap_err().to_string();
    assert!(err.contains("dt_max"), "{err}");
}
