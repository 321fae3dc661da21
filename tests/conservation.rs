//! Validates the time integrators' conservation laws on a free, undamped, crumpled sheet:
//! linear momentum (every integrator), angular momentum (symplectic Euler), bounded energy
//! without drift below the explicit stability limit, and a clean divergence report above it.

use glam::{DVec2, DVec3};
use rosette::scene::load_scene;
use rosette::sim::{Fabric, Integrator, IntegratorKind, Mesh, Minimizer, Model, Pattern, PhysicsOptions, PiecewiseLinear, PreconditionerChoice, State, StepError};

/// The paper's wool (bundled preset): nonlinear warp and weft curves, G = 40 N/m, ν = 0.15.
fn wool() -> Fabric {
    let (config, _) = load_scene("tensile-warp", &[]).expect("bundled preset loads");
    config.fabric.to_fabric().expect("bundled fabric is valid")
}

/// The wool with its curves replaced by their initial slopes (1000 and 800 N/m), so that the
/// membrane stiffness is the same in every state and a stability limit computed from the
/// largest stiffness is the limit of every state, not only of the stiffest one.
fn linear_wool() -> Fabric {
    let mut fabric = wool();
    fabric.tensile_warp = PiecewiseLinear::linear(1000.0);
    fabric.tensile_weft = PiecewiseLinear::linear(800.0);
    fabric
}

/// A free sheet (nothing pinned), no gravity, no damping.
fn free_model(fabric: &Fabric, pattern: Pattern, edge: f64, bending: bool) -> Model {
    let mesh = Mesh::rectangle(0.06, 0.04, edge, pattern, 7).unwrap();
    let options = PhysicsOptions { membrane: true, bending, gravity: DVec3::ZERO, damping: 0.0 };
    // Warp at 17° to the sample: nothing lines up with the mesh.
    Model::new(&mesh, fabric, 17f64.to_radians(), options).unwrap()
}

/// A crumpled, slightly stretched sheet centred on the origin, moving arbitrarily.
/// `rough` adds an independent displacement and velocity to every vertex (energy in every
/// mode, up to the mesh scale); without it the shape and velocity field are smooth.
fn crumpled(model: &Model, rough: bool) -> State {
    let r = if rough { 1.0 } else { 0.0 };
    let centre = DVec2::new(0.03, 0.02);
    let x = model
        .rest
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let k = i as f64;
            let q = p - centre;
            DVec3::new(
                1.01 * q.x + r * 4e-4 * (1.3 * k).sin(),
                0.995 * q.y + 0.05 * q.x * q.y + r * 3e-4 * (2.1 * k).cos(),
                0.004 * (60.0 * p.x).sin() * (40.0 * p.y).cos() + 0.02 * q.x * q.x + r * 1e-3 * (0.7 * k).sin(),
            )
        })
        .collect();
    let mut state = State::at_rest(x);
    for (i, v) in state.v.iter_mut().enumerate() {
        let k = i as f64;
        let p = model.rest[i];
        // A drift, a spin about an oblique axis and a smooth wave, plus per-vertex noise.
        let spin = DVec3::new(0.5, -1.0, 2.0).cross(state.x[i]);
        let wave = DVec3::new(0.3 * (50.0 * p.y).sin(), 0.2 * (40.0 * p.x).cos(), 0.5 * (70.0 * p.x + 30.0 * p.y).sin());
        let noise = DVec3::new(0.05 * (1.7 * k).sin(), 0.04 * (2.3 * k).cos(), 0.06 * (0.9 * k + 1.0).sin());
        *v = DVec3::new(0.02, -0.01, 0.03) + spin + wave + r * noise;
    }
    state
}

/// Explicit stability estimate: the fastest membrane wave, c = √(K_max/ρ_A), crossing one
/// (mean) edge in a step.
fn explicit_limit(model: &Model) -> f64 {
    let areal_density = model.mass.iter().sum::<f64>() / model.vertex_area.iter().sum::<f64>();
    model.mean_edge_length / (model.max_membrane_stiffness() / areal_density).sqrt()
}

/// Σ m|v|, the scale against which momentum round-off is judged, kg·m/s.
fn momentum_scale(model: &Model, state: &State) -> f64 {
    state.v.iter().zip(&model.mass).map(|(v, m)| m * v.length()).sum()
}

/// Σ m|x × v|, the scale for angular momentum, kg·m²/s.
fn angular_momentum_scale(model: &Model, state: &State) -> f64 {
    state.x.iter().zip(&state.v).zip(&model.mass).map(|((x, v), m)| m * x.cross(*v).length()).sum()
}

/// Steps `state` `steps` times; returns the worst relative linear and angular momentum errors.
fn momentum_errors(model: &Model, integrator: &mut Integrator, state: &mut State, steps: usize) -> (f64, f64) {
    let (p0, l0) = (state.momentum(model), state.angular_momentum(model));
    let (mut worst_p, mut worst_l) = (0.0f64, 0.0f64);
    for n in 0..steps {
        integrator.step(model, state).unwrap_or_else(|e| panic!("{} step {n}: {e}", integrator.kind));
        worst_p = worst_p.max((state.momentum(model) - p0).length() / momentum_scale(model, state));
        worst_l = worst_l.max((state.angular_momentum(model) - l0).length() / angular_momentum_scale(model, state));
    }
    (worst_p, worst_l)
}

/// A stable step for each integrator: explicit at a fifth of its limit; the implicit ones at
/// 1 ms, where they are stable and take a few Newton iterations per step.
fn stable_dt(kind: IntegratorKind, model: &Model) -> f64 {
    if kind.is_explicit() { 0.2 * explicit_limit(model) } else { 1e-3 }
}

/// Implicit steps with the linear systems solved to round-off. The default CG tolerance (1e-5)
/// leaves a residual whose sum is a net force: with it the momentum leaks by ~1e-8 relative
/// in 200 steps (see `implicit_integrators_conserve_momentum_with_default_solver_settings`).
fn converged_integrator(kind: IntegratorKind, dt: f64) -> Integrator {
    let mut integrator = Integrator::new(kind, dt);
    if !kind.is_explicit() {
        integrator.newton.cg_tolerance = 1e-13;
        integrator.newton.cg_max_iterations = 20_000;
    }
    integrator
}

// ---------------------------------------------------------------------------------------
// Momentum
// ---------------------------------------------------------------------------------------

#[test]
fn every_integrator_conserves_linear_momentum_of_a_free_membrane() {
    // The membrane forces are equal and opposite edge tensions, so they sum to zero exactly
    // up to round-off; every integrator's update then conserves Σ m v.
    let model = free_model(&wool(), Pattern::Jittered, 0.01, false);
    for kind in IntegratorKind::ALL {
        let mut state = crumpled(&model, true);
        let mut integrator = converged_integrator(kind, stable_dt(kind, &model));
        let (p, l) = momentum_errors(&model, &mut integrator, &mut state, 200);
        eprintln!("{kind} (dt {:.3e} s): linear momentum error {p:.2e}, angular momentum error {l:.2e} (relative)", integrator.dt);
        // 1e-12: round-off. Each step adds relative errors of order ε = 2.2e-16 (forces summed
        // over a few neighbours; implicit velocities from position differences, ε|x|/(|v|Δt)
        // ≈ 2e-14 here), with random signs: √200 steps of them stay below 1e-12 unless
        // something is not conserved.
        assert!(p < 1e-12, "{kind}: linear momentum changed by {p:e} of Σm|v|");
        if kind == IntegratorKind::SymplecticEuler {
            // Symplectic Euler conserves L exactly for central and rotation-invariant forces:
            // L' = Σ m x_n × v' (as x' − x_n ∥ v') = L + Δt Σ x_n × f(x_n) = L. 1e-9 of
            // Σ m|x × v| is generous round-off.
            assert!(l < 1e-9, "{kind}: angular momentum changed by {l:e} of Σm|x×v|");
        }
    }
}

#[test]
fn symplectic_euler_conserves_momentum_with_bending() {
    // The bending energy ½ xᵀQx is invariant under translations and rotations (Q has zero row
    // sums and is symmetric), so linear and angular momentum are conserved as well.
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    let mut state = crumpled(&model, true);
    let mut integrator = Integrator::new(IntegratorKind::SymplecticEuler, stable_dt(IntegratorKind::SymplecticEuler, &model));
    let (p, l) = momentum_errors(&model, &mut integrator, &mut state, 200);
    eprintln!("symplectic-euler with bending: linear {p:.2e}, angular {l:.2e}");
    // Tolerances as in the membrane test.
    assert!(p < 1e-12, "linear momentum changed by {p:e} of Σm|v|");
    assert!(l < 1e-9, "angular momentum changed by {l:e} of Σm|x×v|");
}

/// Runs both implicit integrators from the same start, prints their momentum errors and
/// asserts the round-off bound on each.
fn assert_implicit_momentum(model: &Model, label: &str, make: impl Fn(IntegratorKind, f64) -> Integrator) {
    let errors: Vec<(IntegratorKind, f64)> = [IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2]
        .into_iter()
        .map(|kind| {
            let mut state = crumpled(model, true);
            let mut integrator = make(kind, stable_dt(kind, model));
            let (p, l) = momentum_errors(model, &mut integrator, &mut state, 200);
            eprintln!("{kind}, {label}: linear momentum error {p:.2e}, angular {l:.2e} (relative)");
            (kind, p)
        })
        .collect();
    for (kind, p) in errors {
        // Round-off, as in the membrane test.
        assert!(p < 1e-12, "{kind}, {label}: linear momentum changed by {p:e} of Σm|v|");
    }
}

/// Regression: Q's row sums were zero only to round-off (1e-12 N/m against entries up to
/// 77 N/m), so Qx had a net force that grew with |x| and drifted the momentum (2.2e-12 here,
/// 9e-11 with the sheet 1.7 m from the origin). Q is exactly symmetric with zero row
/// sums and the force is applied as Σ_b Q_ab (x_b − x_a).
#[test]
fn implicit_integrators_conserve_momentum_with_bending() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    assert_implicit_momentum(&model, "bending on, converged solves", converged_integrator);
}

/// Regression: with the default CG tolerance the residual of each Newton solve summed to a
/// net force (8.8e-8 of Σm|v| for implicit Euler). Unconstrained sheets have the Newton
/// direction shifted by the constant that zeroes it.
#[test]
fn implicit_integrators_conserve_momentum_with_default_solver_settings() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, false);
    assert_implicit_momentum(&model, "default Newton settings", Integrator::new);
}

// ---------------------------------------------------------------------------------------
// Energy and stability of the explicit integrator
// ---------------------------------------------------------------------------------------

/// Total energy at the time of the positions. Symplectic Euler as implemented (kick, then
/// drift) is the leapfrog scheme: the stored velocity is the one that carried x_{n−1} to x_n,
/// i.e. v at t_{n−½}. The velocity at t_n is v + (Δt/2)·f(x_n)/m.
fn synchronized_energy(model: &Model, state: &State, dt: f64) -> f64 {
    let mut f = vec![DVec3::ZERO; state.x.len()];
    model.forces(&state.x, &mut f);
    let kinetic: f64 = state.v.iter().zip(&f).zip(&model.mass).map(|((v, f), m)| 0.5 * m * (*v + 0.5 * dt * *f / *m).length_squared()).sum();
    kinetic + model.potential_energy(&state.x)
}

/// Kinetic energy of the stored velocities plus potential energy.
fn raw_energy(model: &Model, state: &State) -> f64 {
    state.kinetic_energy(model) + model.potential_energy(&state.x)
}

#[test]
fn symplectic_euler_keeps_energy_bounded_without_drift_at_half_its_limit() {
    // Bending off: its explicit limit scales as h² and would set the step instead.
    let model = free_model(&linear_wool(), Pattern::Alternating, 0.005, false);
    let dt = 0.5 * explicit_limit(&model);
    let mut integrator = Integrator::new(IntegratorKind::SymplecticEuler, dt);
    // A smooth crumple and velocity field: the energy sits in resolved modes. (With
    // per-vertex noise most of it sits in mesh-scale modes, for which this step is ω·Δt ≈ 1;
    // no explicit method measures their energy to 5 % there.)
    let mut state = crumpled(&model, false);
    let e0 = synchronized_energy(&model, &state, dt);
    let (mut low, mut high) = (e0, e0);
    let (mut raw_low, mut raw_high) = (f64::INFINITY, 0.0f64);
    let (mut first, mut last) = (0.0, 0.0);
    const STEPS: usize = 2000;
    const WINDOW: usize = 500;
    for n in 0..STEPS {
        integrator.step(&model, &mut state).unwrap_or_else(|e| panic!("step {n}: {e}"));
        let e = synchronized_energy(&model, &state, dt);
        low = low.min(e);
        high = high.max(e);
        let raw = raw_energy(&model, &state);
        raw_low = raw_low.min(raw);
        raw_high = raw_high.max(raw);
        if n < WINDOW {
            first += e / WINDOW as f64;
        } else if n >= STEPS - WINDOW {
            last += e / WINDOW as f64;
        }
    }
    eprintln!(
        "dt = {dt:.3e} s (0.5 × {:.3e} s): energy {e0:.4e} J, range [{:+.4}, {:+.4}], drift between first and last {WINDOW} steps {:+.4}; \
         with the stored (half-step) velocities: [{:+.4}, {:+.4}]",
        explicit_limit(&model),
        low / e0 - 1.0,
        high / e0 - 1.0,
        last / first - 1.0,
        raw_low / e0 - 1.0,
        raw_high / e0 - 1.0
    );
    // 5 %: leapfrog conserves a modified energy exactly (linear case) and the energy within
    // O((ω·Δt)²/4) of it, oscillating, never drifting.
    assert!(low > 0.95 * e0 && high < 1.05 * e0, "energy left ±5 %: [{low:e}, {high:e}] J from {e0:e} J");
    // No drift: the averages over the first and the last quarter of the run agree.
    assert!((last / first - 1.0).abs() < 0.05, "energy drifted from {first:e} to {last:e} J");
}

#[test]
fn symplectic_euler_far_beyond_its_limit_diverges_and_keeps_the_last_good_state() {
    let model = free_model(&linear_wool(), Pattern::Alternating, 0.005, false);
    let dt = 3.0 * explicit_limit(&model);
    let mut integrator = Integrator::new(IntegratorKind::SymplecticEuler, dt);
    let mut state = crumpled(&model, false);
    for n in 0..2000 {
        let before = state.clone();
        match integrator.step(&model, &mut state) {
            Ok(_) => assert!(state.x.iter().all(|x| x.is_finite())),
            Err(error) => {
                eprintln!("diverged at step {n}: {error}");
                let StepError::Diverged { integrator: kind, dt: reported, time, .. } = &error;
                assert_eq!(*kind, IntegratorKind::SymplecticEuler);
                assert_eq!(*reported, dt);
                assert_eq!(*time, before.time);
                assert_eq!(state, before, "a rejected step must leave the state as it was");
                assert!(state.x.iter().chain(&state.v).all(|p| p.is_finite()));
                assert_eq!(state.steps, n as u64);
                return;
            }
        }
    }
    panic!("symplectic Euler at 3 × its stability limit (dt = {dt:e} s) ran 2000 steps without diverging");
}

// ---------------------------------------------------------------------------------------
// Accuracy of the inexact Newton solves
// ---------------------------------------------------------------------------------------

/// The default solver stops CG as soon as the remaining error is a tenth of Newton's
/// stopping tolerance (a vertex displacement of `tolerance` × the mean edge length), and
/// takes the tolerance itself as its promise: each step must land within it of the step
/// solved with exact linear solves and a thousand times tighter Newton tolerance. A
/// crumpled, spinning sheet with rough motion in every mode, from the same states. (With
/// every solve stopped at a relative residual of 0.9 implicit Euler missed by 2.2e-7 m,
/// twice the tolerance; as it is, by about a tenth of it.)
#[test]
fn default_newton_steps_land_within_the_tolerance_of_converged_steps() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    for kind in [IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2] {
        let mut reference = converged_integrator(kind, 1e-3);
        reference.newton.forcing = false;
        reference.newton.tolerance *= 1e-3;
        let mut default = Integrator::new(kind, 1e-3);
        let bound = default.newton.tolerance * model.mean_edge_length;
        let mut state = crumpled(&model, true);
        let mut worst = 0.0f64;
        for n in 0..10 {
            let mut fast = state.clone();
            let report = default.step(&model, &mut fast).unwrap_or_else(|e| panic!("{kind} step {n}: {e}"));
            assert!(!report.newton_unconverged, "{kind} step {n}: Newton did not converge");
            reference.step(&model, &mut state).unwrap_or_else(|e| panic!("{kind} reference step {n}: {e}"));
            let miss = fast.x.iter().zip(&state.x).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
            worst = worst.max(miss);
        }
        println!("{kind}: worst miss {worst:.2e} m against a tolerance of {bound:.2e} m");
        assert!(worst < bound, "{kind}: a default step missed the converged one by {worst:.2e} m (tolerance {bound:.2e} m)");
    }
}

/// Fine meshes (a complete factor) take the exact Hessian as Newton's matrix, shifted by a
/// share of the inertia where it is not positive definite. The rough crumpled sheet above,
/// compressed across its width, at a step of 2 ms: its exact matrix is indefinite in some
/// iterations, so the shift must engage, and each step must still land within Newton's
/// tolerance of the converged step (incomplete-factor path, exact solves, a thousand times
/// tighter tolerance), from the same states. (Measured: a fifth of the tolerance. At 5 ms
/// the sheet buckles within a step and even the incomplete path lands six tolerances away,
/// in another minimum or short of a slowly converging one, so the test keeps to 2 ms.)
#[test]
fn shifted_newton_steps_land_within_the_tolerance_of_converged_steps() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    let dt = 2e-3;
    let cases = [
        (IntegratorKind::ImplicitEuler, PreconditionerChoice::Cholesky),
        (IntegratorKind::Bdf2, PreconditionerChoice::Cholesky),
        (IntegratorKind::ImplicitEuler, PreconditionerChoice::Multigrid),
    ];
    for (kind, choice) in cases {
        let mut reference = converged_integrator(kind, dt);
        reference.newton.forcing = false;
        reference.newton.tolerance *= 1e-3;
        let mut shifted = Integrator::new(kind, dt);
        shifted.newton.preconditioner = choice;
        let bound = shifted.newton.tolerance * model.mean_edge_length;
        let mut state = crumpled(&model, true);
        let (mut worst, mut largest_shift) = (0.0f64, 0.0f64);
        for n in 0..10 {
            let mut fast = state.clone();
            let report = shifted.step(&model, &mut fast).unwrap_or_else(|e| panic!("{kind}, {choice:?}, step {n}: {e}"));
            assert!(!report.newton_unconverged, "{kind}, {choice:?}, step {n}: Newton did not converge");
            largest_shift = largest_shift.max(report.shift);
            reference.step(&model, &mut state).unwrap_or_else(|e| panic!("{kind} reference step {n}: {e}"));
            let miss = fast.x.iter().zip(&state.x).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
            worst = worst.max(miss);
        }
        println!("{kind}, {choice:?}: worst miss {worst:.2e} m against a tolerance of {bound:.2e} m; largest shift {largest_shift:.3} of the inertia");
        assert!(largest_shift > 0.0, "{kind}, {choice:?}: the exact matrix never needed a shift: the test no longer exercises it");
        assert!(worst < bound, "{kind}, {choice:?}: a shifted step missed the converged one by {worst:.2e} m (tolerance {bound:.2e} m)");
    }
}

/// Drops on the fast path keep the bounded matrix for the rest of a step once the exact
/// one has met negative curvature (`retry_exact` off) instead of trying the exact matrix
/// first in every iteration. The rough crumpled sheet above at 1 ms, with the incomplete
/// factor: the exact matrix must fail in some iterations (the count of CG iterations then
/// differs from the retrying solver's), and each step must still land within Newton's
/// tolerance of the converged step, from the same states. (Measured: a quarter of the
/// tolerance. At 2 ms the retrying solver itself lands 2.8 tolerances away on one step,
/// the kept one too: the crumpled sheet's potential has more than one minimum there.)
#[test]
fn steps_that_keep_the_bounded_matrix_land_within_the_tolerance_of_converged_steps() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    let dt = 1e-3;
    for kind in [IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2] {
        let mut reference = converged_integrator(kind, dt);
        reference.newton.forcing = false;
        reference.newton.tolerance *= 1e-3;
        let incomplete = || {
            let mut integrator = Integrator::new(kind, dt);
            integrator.newton.preconditioner = PreconditionerChoice::IncompleteCholesky;
            integrator
        };
        let mut retrying = incomplete();
        let mut keeping = incomplete();
        keeping.newton.retry_exact = false;
        let bound = keeping.newton.tolerance * model.mean_edge_length;
        let mut state = crumpled(&model, true);
        let (mut worst, mut cg_keeping, mut cg_retrying) = (0.0f64, 0, 0);
        for n in 0..10 {
            let mut kept = state.clone();
            let report = keeping.step(&model, &mut kept).unwrap_or_else(|e| panic!("{kind} step {n}: {e}"));
            assert!(!report.newton_unconverged, "{kind} step {n}: Newton did not converge");
            cg_keeping += report.cg_iterations;
            cg_retrying += retrying.step(&model, &mut state.clone()).unwrap_or_else(|e| panic!("{kind} retrying step {n}: {e}")).cg_iterations;
            reference.step(&model, &mut state).unwrap_or_else(|e| panic!("{kind} reference step {n}: {e}"));
            let miss = kept.x.iter().zip(&state.x).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
            worst = worst.max(miss);
        }
        println!("{kind}: worst miss {worst:.2e} m against a tolerance of {bound:.2e} m; CG iterations {cg_keeping} keeping the bounded matrix, {cg_retrying} retrying the exact one");
        assert_ne!(cg_keeping, cg_retrying, "{kind}: the exact matrix never failed: the test no longer exercises the bounded one");
        assert!(worst < bound, "{kind}: a step keeping the bounded matrix missed the converged one by {worst:.2e} m (tolerance {bound:.2e} m)");
    }
}

/// The quasi-Newton step (the fast path's step for cloth in motion) minimises the same
/// incremental potential by L-BFGS on a constant matrix, to the fast path's tolerance (a
/// tenth of the step's own integration error). The rough crumpled sheet above at 1 ms, both
/// integrators: each step must land within the tolerance it stopped at of the converged
/// Newton step from the same state, with the quasi-Newton iterations alone (a budget large
/// enough that Newton never finishes the solve), so that its own convergence test is what
/// is checked.
#[test]
fn quasi_newton_steps_land_within_the_tolerance_of_converged_steps() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    let dt = 1e-3;
    for kind in [IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2] {
        let mut reference = converged_integrator(kind, dt);
        reference.newton.forcing = false;
        reference.newton.tolerance *= 1e-3;
        let mut quasi = Integrator::new(kind, dt);
        quasi.newton.minimizer = Minimizer::QuasiNewton;
        quasi.newton.quasi_newton_iterations = 2000;
        quasi.newton.error_share = 0.1;
        let mut state = crumpled(&model, true);
        let (mut worst, mut iterations) = (0.0f64, 0);
        for n in 0..10 {
            let mut fast = state.clone();
            let report = quasi.step(&model, &mut fast).unwrap_or_else(|e| panic!("{kind} step {n}: {e}"));
            assert!(!report.newton_unconverged, "{kind} step {n}: the solve did not converge");
            assert_eq!(report.newton_iterations, 0, "{kind} step {n}: Newton had to finish the quasi-Newton solve");
            iterations += report.quasi_newton_iterations;
            reference.step(&model, &mut state).unwrap_or_else(|e| panic!("{kind} reference step {n}: {e}"));
            let miss = fast.x.iter().zip(&state.x).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
            let tolerance = report.newton_tolerance * model.mean_edge_length;
            worst = worst.max(miss / tolerance);
        }
        println!("{kind}: worst miss {worst:.2} of the step's tolerance; {iterations} quasi-Newton iterations in 10 steps");
        assert!(worst < 1.0, "{kind}: a quasi-Newton step missed the converged one by {worst:.2} of its tolerance");
    }
}

/// The quasi-Newton directions are corrected as Newton's are on a free sheet, so that the
/// solve's residual leaves no net force: momentum is conserved to round-off.
#[test]
#[ignore = "open: on a free crumpled sheet the quasi-Newton step (opt-in) drifts the linear momentum by 1e-4 and the angular by 1e-2 of their scale over 200 steps, where Newton keeps both to round-off; the cause is not found yet (docs/fast-path.md, What was tried)"]
fn quasi_newton_steps_conserve_momentum() {
    let model = free_model(&wool(), Pattern::Jittered, 0.01, true);
    assert_implicit_momentum(&model, "quasi-Newton", |kind, dt| {
        let mut integrator = Integrator::new(kind, dt);
        integrator.newton.minimizer = Minimizer::QuasiNewton;
        integrator
    });
}
