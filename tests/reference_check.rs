//! Checks of the physics reference solutions in `tests/common/reference.rs` against the
//! values quoted in `docs/references.md`, known limits and second, independent methods,
//! so that the validation tests built on them compare the simulator with trusted numbers.

mod common;

use common::reference::*;
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, FRAC_PI_4, PI};

/// Asserts |actual − expected| ≤ tolerance with a message naming the quantity.
fn assert_close(what: &str, actual: f64, expected: f64, tolerance: f64) {
    assert!(
        (actual - expected).abs() <= tolerance,
        "{what}: got {actual}, expected {expected} ± {tolerance} (off by {:e})",
        (actual - expected).abs()
    );
}

/// Tolerance for a value printed with `decimals` decimal places: half a unit of the last.
fn printed_precision(decimals: i32) -> f64 {
    0.5 * 10f64.powi(-decimals)
}

// ---------------------------------------------------------------------------------------
// Heavy cantilever
// ---------------------------------------------------------------------------------------

#[test]
fn heavy_cantilever_matches_reference_sanity_values() {
    // (λ, tip drop / L, tip angle in degrees), docs/references.md §4.
    let quoted = [
        (2.0, 0.2385, 18.4),
        (8.0, 0.6406, 53.9),
        (20.0, 0.8299, 76.7),
    ];
    for (lambda, drop, tip_angle_deg) in quoted {
        let solution = heavy_cantilever(lambda);
        assert_close(
            &format!("tip drop/L at λ = {lambda}"),
            solution.tip_drop_over_l,
            drop,
            printed_precision(4),
        );
        assert_close(
            &format!("tip angle at λ = {lambda}"),
            solution.tip_angle_rad.to_degrees(),
            tip_angle_deg,
            printed_precision(1),
        );
    }
}

#[test]
fn heavy_cantilever_chord_reaches_overhang_test_angle_at_twice_the_bending_length() {
    // ASTM D1388 reads the bending length where the chord makes 41.5° (L = 2c, λ = 8);
    // docs/references.md §4 quotes the exact elastica chord angle there as 41.49°.
    let solution = heavy_cantilever(8.0);
    assert_close(
        "chord angle at λ = 8",
        solution.chord_angle_rad.to_degrees(),
        41.49,
        printed_precision(2),
    );
}

#[test]
fn heavy_cantilever_small_deflection_limit_is_lambda_over_eight() {
    // Linear beam theory: tip deflection w·L⁴/(8B), i.e. drop/L = λ/8.
    let lambda = 0.1;
    let linear_drop = lambda / 8.0;
    let solution = heavy_cantilever(lambda);
    assert_close(
        "drop/L at λ = 0.1",
        solution.tip_drop_over_l,
        linear_drop,
        0.005 * linear_drop,
    );
}

#[test]
fn heavy_cantilever_small_deflection_profile_is_the_linear_beam_shape() {
    // Linear beam under uniform load, clamped at s = 0 and free at s = 1:
    // y(s)/L = λ·(s⁴/24 − s³/6 + s²/4), x ≈ s. Nonlinear corrections are O(λ²) relative.
    let lambda = 0.01;
    let points = 11;
    for (index, &(x, y)) in heavy_cantilever_profile(lambda, points).iter().enumerate() {
        let s = index as f64 / (points - 1) as f64;
        let linear_y = lambda * (s.powi(4) / 24.0 - s.powi(3) / 6.0 + s * s / 4.0);
        assert_close(&format!("profile y at s = {s}"), y, linear_y, 1e-4 * lambda);
        assert_close(&format!("profile x at s = {s}"), x, s, 1e-4 * lambda);
    }
}

#[test]
fn heavy_cantilever_is_converged_in_step_size() {
    // Quartering the RK4 step must not move the solution: the reference is exact to far
    // better than any simulator tolerance, also at large λ where restarts are needed.
    let cases = [
        (0.1, 1e-12),
        (2.0, 1e-12),
        (8.0, 1e-12),
        (20.0, 1e-12),
        (100.0, 1e-12),
        (1000.0, 1e-12),
        (1e4, 1e-8),
    ];
    for (lambda, tolerance) in cases {
        let default = heavy_cantilever(lambda);
        let fine = heavy_cantilever_with_steps(lambda, 4 * CANTILEVER_RK4_STEPS);
        assert_close(
            &format!("drop/L at λ = {lambda}"),
            default.tip_drop_over_l,
            fine.tip_drop_over_l,
            tolerance,
        );
        assert_close(
            &format!("reach/L at λ = {lambda}"),
            default.tip_reach_over_l,
            fine.tip_reach_over_l,
            tolerance,
        );
        assert_close(
            &format!("tip angle at λ = {lambda}"),
            default.tip_angle_rad,
            fine.tip_angle_rad,
            tolerance,
        );
    }
}

#[test]
fn heavy_cantilever_limits_and_monotonicity() {
    let straight = heavy_cantilever(0.0);
    assert_close(
        "drop/L without weight",
        straight.tip_drop_over_l,
        0.0,
        1e-15,
    );
    assert_close(
        "reach/L without weight",
        straight.tip_reach_over_l,
        1.0,
        1e-12,
    );

    // Heavier strips droop more, reach less, and tend to hang vertically.
    let lambdas = [0.1, 1.0, 2.0, 8.0, 20.0, 100.0, 1000.0, 1e4];
    let solutions: Vec<_> = lambdas
        .iter()
        .map(|&lambda| heavy_cantilever(lambda))
        .collect();
    for pair in solutions.windows(2) {
        assert!(
            pair[1].tip_drop_over_l > pair[0].tip_drop_over_l,
            "drop must grow with λ: {pair:?}"
        );
        assert!(
            pair[1].tip_reach_over_l < pair[0].tip_reach_over_l,
            "reach must shrink with λ: {pair:?}"
        );
        assert!(
            pair[1].tip_angle_rad > pair[0].tip_angle_rad - 1e-9,
            "tip angle must grow with λ: {pair:?}"
        );
    }
    let very_heavy = solutions.last().expect("non-empty");
    assert_close(
        "tip angle at λ = 1e4",
        very_heavy.tip_angle_rad,
        FRAC_PI_2,
        1e-9,
    );
    // The strip stays on the physical branch: it never curls back behind the clamp.
    assert!(very_heavy.tip_reach_over_l > 0.0 && very_heavy.tip_reach_over_l < 0.05);
    // Every point is on a unit-length strip: drop and reach fit inside it.
    for solution in &solutions {
        let chord = solution.tip_drop_over_l.hypot(solution.tip_reach_over_l);
        assert!(
            chord <= 1.0 + 1e-12,
            "chord longer than the strip: {solution:?}"
        );
    }
}

#[test]
fn heavy_cantilever_profile_is_an_arc_length_parametrised_strip() {
    let lambda = 8.0;
    let points = 101;
    let spacing = 1.0 / (points - 1) as f64;
    let profile = heavy_cantilever_profile(lambda, points);
    assert_eq!(profile.len(), points);
    assert_eq!(profile[0], (0.0, 0.0));
    let tip = heavy_cantilever(lambda);
    let &(tip_x, tip_y) = profile.last().expect("non-empty");
    assert_close("profile tip x", tip_x, tip.tip_reach_over_l, 1e-12);
    assert_close("profile tip y", tip_y, tip.tip_drop_over_l, 1e-12);
    // Samples are equally spaced in arc length, so each chord is a hair shorter than the
    // arc between them (the strip is curved), never longer.
    for pair in profile.windows(2) {
        let chord = (pair[1].0 - pair[0].0).hypot(pair[1].1 - pair[0].1);
        assert!(
            chord <= spacing * (1.0 + 1e-12) && chord >= spacing * (1.0 - 1e-3),
            "chord {chord} vs {spacing}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// Complete elliptic integrals
// ---------------------------------------------------------------------------------------

/// K and E by the trapezoidal rule on the periodic integrands, which converges
/// geometrically, as an independent check of the AGM.
fn elliptic_by_quadrature(k: f64) -> (f64, f64) {
    let intervals = 20_000;
    let h = FRAC_PI_2 / intervals as f64;
    let (mut first, mut second) = (0.0, 0.0);
    for index in 0..=intervals {
        let weight = if index == 0 || index == intervals {
            0.5
        } else {
            1.0
        };
        let root = (1.0 - (k * (index as f64 * h).sin()).powi(2)).sqrt();
        first += weight * h / root;
        second += weight * h * root;
    }
    (first, second)
}

#[test]
fn elliptic_integrals_match_known_values() {
    assert_close("K(0)", ellip_k(0.0), FRAC_PI_2, 1e-15);
    assert_close("E(0)", ellip_e(0.0), FRAC_PI_2, 1e-15);
    assert_close("K(1/√2)", ellip_k(FRAC_1_SQRT_2), 1.854074677301372, 1e-12);
    assert_close("E(1/√2)", ellip_e(FRAC_1_SQRT_2), 1.350643881047675, 1e-12);
    assert_eq!(ellip_k(1.0), f64::INFINITY);
    assert_eq!(ellip_e(1.0), 1.0);
    // The integrals depend on k² only.
    assert_eq!(ellip_k(-0.3), ellip_k(0.3));
}

#[test]
fn elliptic_integrals_match_quadrature() {
    for k in [0.1, 0.3, 0.5, 0.7, 0.9, 0.99] {
        let (first, second) = elliptic_by_quadrature(k);
        assert_close(&format!("K({k})"), ellip_k(k), first, 1e-12);
        assert_close(&format!("E({k})"), ellip_e(k), second, 1e-12);
    }
}

#[test]
fn elliptic_integrals_satisfy_legendre_relation() {
    // Legendre: E·K' + E'·K − K·K' = π/2, with primes the complementary modulus.
    for k in [0.05, 0.2, 0.5, FRAC_1_SQRT_2, 0.9, 0.999] {
        let complementary = (1.0 - k * k).sqrt();
        let (first, second) = (ellip_k(k), ellip_e(k));
        let (first_c, second_c) = (ellip_k(complementary), ellip_e(complementary));
        let legendre = second * first_c + second_c * first - first * first_c;
        assert_close(
            &format!("Legendre relation at k = {k}"),
            legendre,
            FRAC_PI_2,
            1e-12,
        );
    }
}

// ---------------------------------------------------------------------------------------
// Euler buckling
// ---------------------------------------------------------------------------------------

#[test]
fn euler_critical_load_is_pi_squared_b_over_l_squared() {
    let bending_rigidity = 10e-6; // N·m, a light wool suiting
    let length = 0.1; // m
    assert_close(
        "P_cr",
        euler_critical_load_pinned(bending_rigidity, length),
        PI * PI * 1e-3,
        1e-15,
    );
}

#[test]
fn euler_elastica_matches_reference_sanity_values() {
    // (Δ/L, δ/L, P/P_cr), docs/references.md §5.
    for (shortening, deflection, load) in [(0.05, 0.1401, 1.0257), (0.20, 0.2663, 1.1127)] {
        let elastica = euler_elastica_from_shortening(shortening);
        assert_close(
            &format!("Δ/L at {shortening}"),
            elastica.shortening_over_l,
            shortening,
            1e-14,
        );
        assert_close(
            &format!("δ/L at Δ/L = {shortening}"),
            elastica.midspan_deflection_over_l,
            deflection,
            printed_precision(4),
        );
        assert_close(
            &format!("P/P_cr at Δ/L = {shortening}"),
            elastica.load_over_pcr,
            load,
            printed_precision(4),
        );
        assert_close(
            "k = sin(α/2)",
            elastica.k,
            (0.5 * elastica.end_angle_rad).sin(),
            1e-14,
        );
    }
}

#[test]
fn euler_elastica_small_amplitude_limit() {
    // Linearised post-buckling: δ/L ≈ (2/π)·√(Δ/L) and P → P_cr.
    let shortening = 1e-4;
    let elastica = euler_elastica_from_shortening(shortening);
    let linear_deflection = 2.0 / PI * shortening.sqrt();
    assert_close(
        "δ/L at Δ/L = 1e-4",
        elastica.midspan_deflection_over_l,
        linear_deflection,
        0.01 * linear_deflection,
    );
    assert_close("P/P_cr at Δ/L = 1e-4", elastica.load_over_pcr, 1.0, 1e-3);
}

#[test]
fn euler_elastica_elliptic_and_shooting_methods_agree() {
    for shortening in [1e-4, 0.01, 0.05, 0.2, 0.5, 1.0, 1.5] {
        let elliptic = euler_elastica_from_shortening(shortening);
        let shooting = euler_elastica_shooting(shortening);
        let context = |what: &str| format!("{what} at Δ/L = {shortening}");
        assert_close(&context("k"), shooting.k, elliptic.k, 1e-6);
        assert_close(
            &context("end angle"),
            shooting.end_angle_rad,
            elliptic.end_angle_rad,
            1e-6,
        );
        assert_close(
            &context("Δ/L"),
            shooting.shortening_over_l,
            elliptic.shortening_over_l,
            1e-6,
        );
        assert_close(
            &context("δ/L"),
            shooting.midspan_deflection_over_l,
            elliptic.midspan_deflection_over_l,
            1e-6,
        );
        assert_close(
            &context("P/P_cr"),
            shooting.load_over_pcr,
            elliptic.load_over_pcr,
            1e-6,
        );
    }
}

#[test]
fn euler_elastica_from_the_modulus_is_the_one_from_the_shortening() {
    // The viewer draws the curve at evenly spaced moduli; each point is the elastica that
    // the shortening it gives leads back to.
    for k in [0.05, 0.3, 0.6, 0.9, 0.95] {
        let shape = euler_elastica_from_modulus(k);
        assert_close(&format!("k at k = {k}"), shape.k, k, 1e-13);
        let back = euler_elastica_from_shortening(shape.shortening_over_l);
        assert_close(&format!("k back at k = {k}"), back.k, k, 1e-12);
        assert_close(&format!("P/P_cr at k = {k}"), shape.load_over_pcr, back.load_over_pcr, 1e-12);
        assert_close(&format!("δ/L at k = {k}"), shape.midspan_deflection_over_l, back.midspan_deflection_over_l, 1e-12);
    }
}

#[test]
fn euler_elastica_handles_near_loop_shortening() {
    // Δ/L = 1.9 needs k within 1e-16 of 1; there K = 2/(2 − Δ/L) = 20 exactly and
    // δ/L = k/K = 0.05, which only the complementary-modulus parametrisation resolves.
    let elastica = euler_elastica_from_shortening(1.9);
    assert_close(
        "δ/L at Δ/L = 1.9",
        elastica.midspan_deflection_over_l,
        0.05,
        1e-12,
    );
    assert_close(
        "P/P_cr at Δ/L = 1.9",
        elastica.load_over_pcr,
        (40.0 / PI).powi(2),
        1e-9,
    );
}

// ---------------------------------------------------------------------------------------
// Orthotropic plane stress
// ---------------------------------------------------------------------------------------

/// A woven fabric with G ≪ E (N/m): warp stiffer than weft, soft in shear.
const FABRIC_EX: f64 = 4000.0;
const FABRIC_EY: f64 = 2500.0;
const FABRIC_G: f64 = 40.0;
const FABRIC_NU_XY: f64 = 0.3;

/// Strains (along, across) a unit uniaxial load at angle θ, computed by rotating the
/// stress into the material axes, applying the material compliance, and rotating the
/// strain back: an independent route to S'₁₁ and S'₁₂.
fn strains_by_tensor_rotation(ex: f64, ey: f64, g: f64, nu_xy: f64, theta: f64) -> (f64, f64) {
    let (sin, cos) = theta.sin_cos();
    // Unit uniaxial stress along (cos θ, sin θ) in material axes.
    let (stress_xx, stress_yy, stress_xy) = (cos * cos, sin * sin, sin * cos);
    let strain_xx = stress_xx / ex - nu_xy / ex * stress_yy;
    let strain_yy = stress_yy / ey - nu_xy / ex * stress_xx;
    let tensor_shear_strain = 0.5 * stress_xy / g;
    let normal_strain = |(dx, dy): (f64, f64)| {
        strain_xx * dx * dx + strain_yy * dy * dy + 2.0 * tensor_shear_strain * dx * dy
    };
    (normal_strain((cos, sin)), normal_strain((-sin, cos)))
}

#[test]
fn off_axis_modulus_recovers_material_axes_and_bias_identity() {
    let modulus =
        |theta: f64| off_axis_modulus(FABRIC_EX, FABRIC_EY, FABRIC_G, FABRIC_NU_XY, theta);
    assert_close("E at 0°", modulus(0.0), FABRIC_EX, 1e-12 * FABRIC_EX);
    assert_close("E at 90°", modulus(FRAC_PI_2), FABRIC_EY, 1e-12 * FABRIC_EY);
    // docs/references.md §1: at 45°, 1/G = 4/E₄₅ − (1 − 2ν_xy)/E_x − 1/E_y.
    let bias = modulus(FRAC_PI_4);
    let shear_compliance = 4.0 / bias - (1.0 - 2.0 * FABRIC_NU_XY) / FABRIC_EX - 1.0 / FABRIC_EY;
    assert_close(
        "1/G from the bias modulus",
        shear_compliance,
        1.0 / FABRIC_G,
        1e-12 / FABRIC_G,
    );
    // With G ≪ E the bias modulus is close to 4G.
    assert_close("E₄₅ ≈ 4G", bias, 4.0 * FABRIC_G, 0.05 * 4.0 * FABRIC_G);
}

#[test]
fn off_axis_poisson_recovers_material_axes_and_bias_necking() {
    let poisson =
        |theta: f64| off_axis_poisson(FABRIC_EX, FABRIC_EY, FABRIC_G, FABRIC_NU_XY, theta);
    assert_close("ν at 0°", poisson(0.0), FABRIC_NU_XY, 1e-12);
    assert_close(
        "ν at 90° (reciprocity)",
        poisson(FRAC_PI_2),
        FABRIC_NU_XY * FABRIC_EY / FABRIC_EX,
        1e-12,
    );
    assert_close("ν at 45° with G ≪ E", poisson(FRAC_PI_4), 1.0, 0.05);
}

#[test]
fn off_axis_compliance_matches_explicit_tensor_rotation() {
    for degrees in [0.0, 10.0, 30.0, 45.0, 60.0, 77.0, 90.0, 135.0] {
        let theta = f64::to_radians(degrees);
        let (along, across) =
            strains_by_tensor_rotation(FABRIC_EX, FABRIC_EY, FABRIC_G, FABRIC_NU_XY, theta);
        let modulus = off_axis_modulus(FABRIC_EX, FABRIC_EY, FABRIC_G, FABRIC_NU_XY, theta);
        let poisson = off_axis_poisson(FABRIC_EX, FABRIC_EY, FABRIC_G, FABRIC_NU_XY, theta);
        assert_close(
            &format!("E at {degrees}°"),
            modulus,
            1.0 / along,
            1e-10 * modulus,
        );
        assert_close(&format!("ν at {degrees}°"), poisson, -across / along, 1e-12);
    }
}

#[test]
fn off_axis_properties_of_an_isotropic_sheet_do_not_depend_on_angle() {
    let (young, poisson_ratio) = (1000.0, 0.3);
    let shear = young / (2.0 * (1.0 + poisson_ratio));
    for degrees in [0.0, 20.0, 45.0, 70.0] {
        let theta = f64::to_radians(degrees);
        assert_close(
            "isotropic E",
            off_axis_modulus(young, young, shear, poisson_ratio, theta),
            young,
            1e-9,
        );
        assert_close(
            "isotropic ν",
            off_axis_poisson(young, young, shear, poisson_ratio, theta),
            poisson_ratio,
            1e-12,
        );
    }
}

#[test]
fn bending_rigidity_theta_interpolates_warp_weft_and_bias() {
    let (warp, weft, middle) = (12e-6, 8e-6, 15e-6);
    assert_close(
        "B at 0°",
        bending_rigidity_theta(warp, weft, middle, 0.0),
        warp,
        1e-18,
    );
    assert_close(
        "B at 90°",
        bending_rigidity_theta(warp, weft, middle, FRAC_PI_2),
        weft,
        1e-18,
    );
    assert_close(
        "B at 45°",
        bending_rigidity_theta(warp, weft, middle, FRAC_PI_4),
        (warp + weft + middle) / 4.0,
        1e-18,
    );
}

// ---------------------------------------------------------------------------------------
// Simple shear
// ---------------------------------------------------------------------------------------

/// Angle (degrees, deformed sheet) of the most stretched material line of simple shear by
/// angle γ, found by bisecting for the zero of d|F·N|²/dψ over unit N = (cos ψ, sin ψ)
/// and mapping the winner through F: independent of the closed form.
fn most_stretched_direction_deg(gamma: f64) -> f64 {
    let shear = gamma.tan();
    let deformed = |psi: f64| (psi.cos() + shear * psi.sin(), psi.sin());
    // d/dψ [(cos ψ + t·sin ψ)² + sin²ψ], positive at ψ = 0 and negative at ψ = 90° for
    // γ > 0; |F·N|² is a single harmonic in 2ψ, so the root in between is the maximum.
    let slope = |psi: f64| {
        let (sin, cos) = psi.sin_cos();
        2.0 * (cos + shear * sin) * (shear * cos - sin) + 2.0 * sin * cos
    };
    let (mut low, mut high) = (0.0, FRAC_PI_2);
    while high - low > 1e-15 {
        let middle = 0.5 * (low + high);
        if slope(middle) > 0.0 {
            low = middle;
        } else {
            high = middle;
        }
    }
    let (x, y) = deformed(0.5 * (low + high));
    y.atan2(x).to_degrees()
}

#[test]
fn simple_shear_principal_tension_tends_to_45_degrees() {
    assert_close(
        "principal angle at γ = 1e-9",
        simple_shear_principal_tension_angle_deg(1e-9),
        45.0,
        1e-6,
    );
    assert_close(
        "principal angle at γ = 0",
        simple_shear_principal_tension_angle_deg(0.0),
        45.0,
        1e-12,
    );
}

#[test]
fn simple_shear_principal_tension_matches_maximum_stretch_search() {
    for degrees in [1.0, 5.0, 13.0, 30.0, 45.0] {
        let gamma = f64::to_radians(degrees);
        assert_close(
            &format!("principal angle at γ = {degrees}°"),
            simple_shear_principal_tension_angle_deg(gamma),
            most_stretched_direction_deg(gamma),
            1e-9,
        );
    }
    // First order: 45° − γ/4, so 41.71° at the paper's 13°.
    assert_close(
        "principal angle at 13°",
        simple_shear_principal_tension_angle_deg(f64::to_radians(13.0)),
        41.71,
        printed_precision(2),
    );
}

#[test]
fn simple_shear_principal_stress_of_isotropic_sheet_follows_the_stretch() {
    // An isotropic hyperelastic stress is coaxial with b = F·Fᵀ.
    let (young, poisson_ratio) = (1000.0, 0.3);
    let shear = young / (2.0 * (1.0 + poisson_ratio));
    for degrees in [1.0, 13.0, 30.0] {
        let gamma = f64::to_radians(degrees);
        assert_close(
            &format!("isotropic stress angle at γ = {degrees}°"),
            simple_shear_principal_stress_angle_deg(young, young, shear, poisson_ratio, gamma),
            simple_shear_principal_tension_angle_deg(gamma),
            1e-9,
        );
    }
}

#[test]
fn simple_shear_principal_stress_of_fabric_is_steeper_than_45_degrees() {
    let gamma = f64::to_radians(13.0);
    let fabric = simple_shear_principal_stress_angle_deg(
        FABRIC_EX,
        FABRIC_EY,
        FABRIC_G,
        FABRIC_NU_XY,
        gamma,
    );
    assert!(
        fabric > 45.0 && fabric < 90.0 - 13.0,
        "fabric stress angle {fabric}"
    );
    // Without shear stiffness or Poisson coupling only the tilted weft yarns carry load.
    let yarns_only =
        simple_shear_principal_stress_angle_deg(FABRIC_EX, FABRIC_EY, 1e-9, 0.0, gamma);
    assert_close("yarn-only stress angle", yarns_only, 90.0 - 13.0, 1e-6);
}

// ---------------------------------------------------------------------------------------
// Cusick drape
// ---------------------------------------------------------------------------------------

/// Paper geometry: 36 cm specimen on an 18 cm support disk (m).
const SPECIMEN_DIAMETER: f64 = 0.36;
const SUPPORT_DIAMETER: f64 = 0.18;
use rosette::physics::STANDARD_GRAVITY;

#[test]
fn cusick_drape_coefficient_spans_flat_to_hanging() {
    let area = |diameter: f64| PI * diameter * diameter / 4.0;
    let flat =
        cusick_drape_coefficient(area(SPECIMEN_DIAMETER), SPECIMEN_DIAMETER, SUPPORT_DIAMETER);
    let hanging =
        cusick_drape_coefficient(area(SUPPORT_DIAMETER), SPECIMEN_DIAMETER, SUPPORT_DIAMETER);
    assert_close("DC of a flat specimen", flat, 1.0, 1e-12);
    assert_close("DC of a hanging specimen", hanging, 0.0, 1e-12);
    let halfway = 0.5 * (area(SPECIMEN_DIAMETER) + area(SUPPORT_DIAMETER));
    assert_close(
        "DC halfway",
        cusick_drape_coefficient(halfway, SPECIMEN_DIAMETER, SUPPORT_DIAMETER),
        0.5,
        1e-12,
    );
}

#[test]
fn independent_strip_drape_bound_uses_the_cantilever_reach() {
    // Choose B so that the 9 cm overhang has λ = 8, whose reach is known from above.
    let areal_density = 0.2; // kg/m²
    let overhang = 0.5 * (SPECIMEN_DIAMETER - SUPPORT_DIAMETER);
    let lambda = 8.0;
    let bending_rigidity = areal_density * STANDARD_GRAVITY * overhang.powi(3) / lambda;
    let bound = independent_strip_drape_lower_bound(
        SPECIMEN_DIAMETER,
        SUPPORT_DIAMETER,
        areal_density,
        bending_rigidity,
        STANDARD_GRAVITY,
    );
    let shadow_radius =
        0.5 * SUPPORT_DIAMETER + heavy_cantilever(lambda).tip_reach_over_l * overhang;
    let outer_radius = 0.5 * SPECIMEN_DIAMETER;
    let support_radius = 0.5 * SUPPORT_DIAMETER;
    let expected = (shadow_radius.powi(2) - support_radius.powi(2))
        / (outer_radius.powi(2) - support_radius.powi(2));
    assert_close("independent-strip DC at λ = 8", bound, expected, 1e-12);
}

#[test]
fn independent_strip_drape_bound_falls_with_limpness() {
    let areal_density = 0.2; // kg/m², light wool suiting
    let bound = |bending_rigidity: f64| {
        independent_strip_drape_lower_bound(
            SPECIMEN_DIAMETER,
            SUPPORT_DIAMETER,
            areal_density,
            bending_rigidity,
            STANDARD_GRAVITY,
        )
    };
    // A board-stiff specimen stays flat.
    assert_close("DC of a rigid specimen", bound(1e3), 1.0, 1e-6);
    // From denim-stiff down to silk-limp (N·m), the bound falls and stays within [0, 1].
    let rigidities = [200e-6, 50e-6, 15e-6, 6e-6, 1e-6];
    let bounds: Vec<f64> = rigidities.iter().map(|&rigidity| bound(rigidity)).collect();
    for pair in bounds.windows(2) {
        assert!(
            pair[1] < pair[0],
            "the bound must fall as the fabric gets limper: {bounds:?}"
        );
    }
    assert!(
        bounds.iter().all(|&dc| (0.0..=1.0).contains(&dc)),
        "bounds out of range: {bounds:?}"
    );
}
