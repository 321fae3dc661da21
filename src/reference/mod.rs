//! Independent physics reference solutions for Rosette's validation tests and charts.
//!
//! Everything here is textbook mechanics computed from scratch in `f64` with nothing but
//! `std` and the definitions in [`crate::physics`] (λ = w·L³/B), so that a test compares
//! the simulator against physics rather than against itself. The sources, formulas and check values are in `docs/references.md` (§1, §4, §5,
//! §6 and §7).
//!
//! Units: SI, per unit width as textile laboratories report fabric properties. Tensile
//! moduli, shear modulus and load per width in N/m; bending rigidity B in N·m (N·m²/m);
//! areal density in kg/m²; weight per area in N/m². Many results are dimensionless
//! (lengths over the strip length L, loads over the critical load) and say so.

mod chain;

pub use chain::{J0_FIRST_ZERO, bessel_j0, hanging_chain_mode, hanging_chain_period};

use crate::physics::cantilever_lambda;
use std::f64::consts::{FRAC_PI_2, PI};

// ---------------------------------------------------------------------------------------
// Shared numerics
// ---------------------------------------------------------------------------------------

/// State carried along a slender strip by the elastica integrators, all dimensionless
/// (arc length and coordinates divided by the strip length L):
/// `[θ, dθ/ds, x, y]`, θ being the tangent angle.
type StripState = [f64; 4];

/// One classical fourth-order Runge–Kutta step of size `h` from arc length `s`.
fn rk4_step(
    rhs: &impl Fn(f64, &StripState) -> StripState,
    s: f64,
    state: &StripState,
    h: f64,
) -> StripState {
    let offset = |base: &StripState, slope: &StripState, factor: f64| -> StripState {
        std::array::from_fn(|i| base[i] + factor * slope[i])
    };
    let k1 = rhs(s, state);
    let k2 = rhs(s + 0.5 * h, &offset(state, &k1, 0.5 * h));
    let k3 = rhs(s + 0.5 * h, &offset(state, &k2, 0.5 * h));
    let k4 = rhs(s + h, &offset(state, &k3, h));
    std::array::from_fn(|i| state[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
}

/// Which side of the sought boundary condition a shooting trial landed on.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum ShotOutcome {
    /// The trial parameter is below the solution.
    TooLow,
    /// The trial parameter is above the solution.
    TooHigh,
}

/// Bisects `[low, high]` (with `classify(low)` = TooLow and `classify(high)` = TooHigh)
/// until the bracket cannot shrink any further in floating point, and returns that final
/// bracket, two adjacent (or nearly adjacent) floats that straddle the solution.
///
/// Bisection on a *classification* rather than on the sign of a residual lets the
/// shooting functions reject non-physical branches (a strip curling back on itself) that
/// a plain residual would happily accept as roots.
fn bisect_bracket(
    mut low: f64,
    mut high: f64,
    classify: impl Fn(f64) -> ShotOutcome,
) -> (f64, f64) {
    loop {
        let middle = 0.5 * (low + high);
        if middle <= low || middle >= high {
            return (low, high);
        }
        match classify(middle) {
            ShotOutcome::TooLow => low = middle,
            ShotOutcome::TooHigh => high = middle,
        }
    }
}

/// The middle of [`bisect_bracket`]'s final bracket: the solution to machine precision.
fn bisect_to_machine_precision(low: f64, high: f64, classify: impl Fn(f64) -> ShotOutcome) -> f64 {
    let (low, high) = bisect_bracket(low, high, classify);
    0.5 * (low + high)
}

// ---------------------------------------------------------------------------------------
// Heavy cantilever (docs/references.md §4; Peirce 1930, ASTM D1388, BS 3356)
// ---------------------------------------------------------------------------------------

/// Number of RK4 steps used along the cantilever by [`heavy_cantilever`]. Quartering
/// the step changes the results by less than 1e-12 up to λ = 1000 and by less than 1e-8
/// up to λ = 10⁴ (see the convergence test).
pub const CANTILEVER_RK4_STEPS: usize = 4000;

/// Largest difference in angle (radians) allowed between the two shots that straddle the
/// solution before [`heavy_cantilever_states`] restarts the shooting from their average.
const CANTILEVER_RESTART_SEPARATION: f64 = 1e-10;

/// Shape of a heavy cantilever at its free end, all dimensionless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CantileverSolution {
    /// Vertical drop of the tip below the clamp, over the strip length L.
    pub tip_drop_over_l: f64,
    /// Horizontal distance from the clamp to the tip, over L.
    pub tip_reach_over_l: f64,
    /// Angle of the strip below the horizontal at the tip, radians.
    pub tip_angle_rad: f64,
    /// Angle below the horizontal of the chord from clamp to tip, radians (the angle the
    /// overhang test of ASTM D1388 reads off its 41.5° mark).
    pub chord_angle_rad: f64,
}

/// Right-hand side of the heavy elastica in state form, with θ measured below the
/// horizontal and y pointing down:
/// θ'' = −λ·(1 − s)·cos θ, x' = cos θ, y' = sin θ.
///
/// Derivation: the bending moment at s is the weight of the overhang beyond s times its
/// lever arm, M(s) = w ∫ₛᴸ (x(t) − x(s)) dt and B·θ' = M, so B·θ'' = −w·(L − s)·cos θ.
/// Scaling s and lengths by L leaves the single parameter λ = w·L³/B.
fn heavy_cantilever_rhs(lambda: f64) -> impl Fn(f64, &StripState) -> StripState {
    move |s, state| {
        let [angle, curvature, _, _] = *state;
        [
            curvature,
            -lambda * (1.0 - s) * angle.cos(),
            angle.cos(),
            angle.sin(),
        ]
    }
}

/// Classifies a trial curvature θ'(s₀) for the heavy cantilever continued from `origin`
/// (the state at step `origin_step` of `steps`, whose angle and position are known).
///
/// On the physical solution θ rises monotonically and stays below π/2, with θ' > 0 on
/// [0, 1) and θ'(1) = 0. A trial curvature is too low if θ' falls to zero before the tip
/// (the strip would then swing upward, a spurious branch for large λ), and too high if θ
/// reaches π/2 or θ' is still positive at the tip.
fn classify_cantilever_shot(
    lambda: f64,
    origin_step: usize,
    origin: StripState,
    trial_curvature: f64,
    steps: usize,
) -> ShotOutcome {
    let rhs = heavy_cantilever_rhs(lambda);
    let h = 1.0 / steps as f64;
    let mut state = origin;
    state[1] = trial_curvature;
    for step in origin_step..steps {
        state = rk4_step(&rhs, step as f64 * h, &state, h);
        let [angle, curvature, _, _] = state;
        if angle >= FRAC_PI_2 {
            return ShotOutcome::TooHigh;
        }
        if curvature < 0.0 {
            return ShotOutcome::TooLow;
        }
    }
    if state[1] > 0.0 {
        ShotOutcome::TooHigh
    } else {
        ShotOutcome::TooLow
    }
}

/// Solves the heavy cantilever and returns its state at every step (`steps + 1` entries,
/// from the clamp to the tip), by shooting on the curvature θ' with restarts.
///
/// Bracket: θ'(s) = λ ∫ₛ¹ (1 − t)·cos θ dt lies in [0, λ(1 − s)²/2] because
/// 0 < cos θ ≤ 1 on the physical branch. A zero curvature immediately curls upward (too
/// low); at the upper end θ'(t) ≥ λ(1 − t)²/2 > 0 up to the tip (too high). This bracket
/// holds for every λ and from any starting point, so no tuning is needed at large λ.
///
/// Restarts: for large λ the strip hangs nearly vertical under tension, where the linear
/// part of the equation, (π/2 − θ)'' ≈ λ(1 − s)(π/2 − θ), has a growing mode that
/// amplifies rounding by up to exp((2/3)·√λ) (10⁹ at λ = 1000). The two shots of the final
/// bisection bracket straddle the true solution, so wherever they separate by more than
/// [`CANTILEVER_RESTART_SEPARATION`] their average is still that accurate; the shooting
/// restarts from there for the rest of the strip. Below λ ≈ 1000 no restart is needed.
fn heavy_cantilever_states(lambda: f64, steps: usize) -> Vec<StripState> {
    assert!(
        lambda >= 0.0 && lambda.is_finite(),
        "λ = wL³/B must be finite and ≥ 0, got {lambda}"
    );
    assert!(steps >= 2, "need at least two RK4 steps, got {steps}");
    let rhs = heavy_cantilever_rhs(lambda);
    let h = 1.0 / steps as f64;
    let mut states: Vec<StripState> = Vec::with_capacity(steps + 1);
    states.push([0.0, 0.0, 0.0, 0.0]);
    let mut origin_step = 0;
    while origin_step < steps {
        let origin = states[origin_step];
        if FRAC_PI_2 - origin[0] <= CANTILEVER_RESTART_SEPARATION {
            // Vertical to within the tolerance: the rest of the strip hangs straight down,
            // since the decaying mode can only bring it closer still.
            let [angle, _, x, y] = states[origin_step];
            let hanging_angle = angle.min(FRAC_PI_2);
            states[origin_step] = [hanging_angle, 0.0, x, y];
            for hanging_step in 1..=steps - origin_step {
                states.push([hanging_angle, 0.0, x, y + hanging_step as f64 * h]);
            }
            break;
        }
        let remaining = 1.0 - origin_step as f64 * h;
        let (low_curvature, high_curvature) =
            bisect_bracket(0.0, 0.5 * lambda * remaining * remaining, |trial| {
                classify_cantilever_shot(lambda, origin_step, origin, trial, steps)
            });
        states[origin_step][1] = 0.5 * (low_curvature + high_curvature);
        let (mut low_shot, mut high_shot) = (origin, origin);
        low_shot[1] = low_curvature;
        high_shot[1] = high_curvature;
        let mut restart_step = steps;
        for step in origin_step..steps {
            low_shot = rk4_step(&rhs, step as f64 * h, &low_shot, h);
            high_shot = rk4_step(&rhs, step as f64 * h, &high_shot, h);
            states.push(std::array::from_fn(|i| 0.5 * (low_shot[i] + high_shot[i])));
            if (high_shot[0] - low_shot[0]).abs() > CANTILEVER_RESTART_SEPARATION {
                restart_step = step + 1;
                break;
            }
        }
        assert!(
            restart_step > origin_step + 1,
            "heavy cantilever shooting made no progress at λ = {lambda} with {steps} steps"
        );
        origin_step = restart_step;
    }
    states
}

/// The exact (large-deflection) heavy cantilever, [`heavy_cantilever`] with an explicit
/// number of RK4 steps, for convergence checks.
pub fn heavy_cantilever_with_steps(lambda: f64, rk4_steps: usize) -> CantileverSolution {
    let states = heavy_cantilever_states(lambda, rk4_steps);
    let [tip_angle, _, reach, drop] = *states.last().expect("at least one state");
    CantileverSolution {
        tip_drop_over_l: drop,
        tip_reach_over_l: reach,
        tip_angle_rad: tip_angle,
        chord_angle_rad: drop.atan2(reach),
    }
}

/// The exact heavy cantilever (Peirce's elastica) for λ = w·L³/B, dimensionless.
///
/// Solves θ'' = −λ·(1 − s)·cos θ on s ∈ [0, 1] with θ(0) = 0 (clamped horizontally) and
/// θ'(1) = 0 (free tip), then x' = cos θ, y' = sin θ (y down), by shooting on θ'(0)
/// with RK4 ([`CANTILEVER_RK4_STEPS`] steps) and bisection to machine precision,
/// restarting the shooting part-way along the strip where large λ makes it unstable.
/// w is the weight per area (N/m²), L the overhang (m), B the bending rigidity (N·m).
///
/// Checks: drop/L → λ/8 as λ → 0 (linear beam, w·L⁴/(8B)); λ = 2 → drop 0.2385, tip
/// 18.4°; λ = 8 → drop 0.6406, tip 53.9°, chord 41.49°; λ = 20 → drop 0.8299, tip 76.7°.
/// Valid for any λ ≥ 0; converged to 1e-12 up to λ = 1000 and to 1e-8 at λ = 10⁴.
pub fn heavy_cantilever(lambda: f64) -> CantileverSolution {
    heavy_cantilever_with_steps(lambda, CANTILEVER_RK4_STEPS)
}

/// Points (x/L, y/L) along the heavy cantilever for λ = w·L³/B, y measured downward from
/// the clamp, at `points` equally spaced arc lengths from the clamp (s = 0, the first
/// point (0, 0)) to the tip (s = L, the last point), for comparing whole shapes.
pub fn heavy_cantilever_profile(lambda: f64, points: usize) -> Vec<(f64, f64)> {
    assert!(
        points >= 2,
        "a profile needs at least the clamp and the tip, got {points} points"
    );
    // Integrate on a grid that contains every requested sample and is at least as fine
    // as the one used by `heavy_cantilever`, so both agree at the tip.
    let intervals = points - 1;
    let steps_per_interval = CANTILEVER_RK4_STEPS.div_ceil(intervals);
    let states = heavy_cantilever_states(lambda, intervals * steps_per_interval);
    states
        .iter()
        .step_by(steps_per_interval)
        .map(|&[_, _, x, y]| (x, y))
        .collect()
}

// ---------------------------------------------------------------------------------------
// Complete elliptic integrals
// ---------------------------------------------------------------------------------------

/// Runs the arithmetic–geometric mean from (1, k') and returns (AGM, Σₙ≥₀ 2ⁿ⁻¹·cₙ²), the
/// two ingredients of K and E (Abramowitz & Stegun 17.6; DLMF 19.8.1–19.8.6), for
/// modulus k and complementary modulus k' = √(1 − k²), both given so that callers near
/// k = 1 can pass an accurate k' that √(1 − k²) would lose to rounding.
///
/// cₙ is updated as cₙ₊₁ = cₙ²/(4·aₙ₊₁), algebraically equal to (aₙ − bₙ)/2 but free of
/// the cancellation that difference suffers once aₙ ≈ bₙ.
fn agm_with_defect_sum(modulus: f64, complementary_modulus: f64) -> (f64, f64) {
    let mut a = 1.0_f64;
    let mut b = complementary_modulus;
    let mut c = modulus;
    let mut weight = 0.5; // 2ⁿ⁻¹ for n = 0
    let mut defect_sum = weight * c * c;
    // The AGM converges quadratically, within about ten iterations even for k' = 1e-300;
    // the bound only guards against a non-terminating loop.
    for _ in 0..64 {
        if c <= f64::EPSILON * a {
            break;
        }
        let next_a = 0.5 * (a + b);
        let next_b = (a * b).sqrt();
        c = c * c / (4.0 * next_a);
        a = next_a;
        b = next_b;
        weight *= 2.0;
        defect_sum += weight * c * c;
    }
    (a, defect_sum)
}

/// (K, E) from the modulus and the complementary modulus; K = +∞ and E = 1 at k' = 0.
fn complete_elliptic_pair(modulus: f64, complementary_modulus: f64) -> (f64, f64) {
    if complementary_modulus == 0.0 {
        return (f64::INFINITY, 1.0);
    }
    let (agm, defect_sum) = agm_with_defect_sum(modulus, complementary_modulus);
    let first_kind = PI / (2.0 * agm);
    (first_kind, first_kind * (1.0 - defect_sum))
}

fn complementary_modulus(k: f64) -> f64 {
    assert!(
        k.abs() <= 1.0,
        "elliptic modulus must satisfy |k| ≤ 1, got {k}"
    );
    // (1 − k)(1 + k) keeps more digits than 1 − k² as k approaches 1.
    ((1.0 - k.abs()) * (1.0 + k.abs())).sqrt()
}

/// Complete elliptic integral of the first kind K(k) = ∫₀^{π/2} dφ / √(1 − k² sin²φ),
/// with *modulus* k (not parameter m = k²), by the arithmetic–geometric mean:
/// K(k) = π / (2·AGM(1, √(1 − k²))). K(0) = π/2; K(±1) = +∞. Accurate to about 1e-15
/// (relative) for |k| ≤ 1.
pub fn ellip_k(k: f64) -> f64 {
    complete_elliptic_pair(k.abs(), complementary_modulus(k)).0
}

/// Complete elliptic integral of the second kind E(k) = ∫₀^{π/2} √(1 − k² sin²φ) dφ,
/// with modulus k, by the AGM: E(k) = K(k)·(1 − Σₙ≥₀ 2ⁿ⁻¹·cₙ²) with a₀ = 1,
/// b₀ = √(1 − k²), c₀ = k and cₙ₊₁ = (aₙ − bₙ)/2. E(0) = π/2; E(±1) = 1. Accurate to
/// about 1e-15 for |k| ≤ 1.
pub fn ellip_e(k: f64) -> f64 {
    complete_elliptic_pair(k.abs(), complementary_modulus(k)).1
}

// ---------------------------------------------------------------------------------------
// Euler buckling and the post-buckling elastica (docs/references.md §5)
// ---------------------------------------------------------------------------------------

/// Critical compressive load per unit width of a pinned–pinned strip, P_cr = π²·B/L²
/// (N/m), for bending rigidity `b` in N·m and length `l` in m. Clamped–clamped is 4× this;
/// the pinned mode n needs n²× this.
pub fn euler_critical_load_pinned(b: f64, l: f64) -> f64 {
    PI * PI * b / (l * l)
}

/// The first (single half-wave) post-buckling mode of a pinned–pinned strip, all
/// dimensionless.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EulerElastica {
    /// Elliptic modulus k = sin(α/2).
    pub k: f64,
    /// Angle α between the strip and the load axis at either pin, radians.
    pub end_angle_rad: f64,
    /// End-shortening Δ (pin-to-pin distance lost), over the strip length L.
    pub shortening_over_l: f64,
    /// Midspan deflection δ away from the load axis, over L.
    pub midspan_deflection_over_l: f64,
    /// Compressive load over the Euler load P_cr = π²·B/L².
    pub load_over_pcr: f64,
}

/// Closed-form elastica (Love §263; Timoshenko & Gere §2.7): a pinned strip is half a
/// wave of the pendulum equation θ'' = −(P/B)·sin θ, whose half period 2K(k)/√(P/B)
/// equals L, giving P/P_cr = (2K/π)², δ/L = k/K, Δ/L = 2·(1 − E/K), with k = sin(α/2).
///
/// It is parametrised by the complementary modulus k' = cos(α/2) because large
/// shortenings need k within 1e-16 of 1, which only k' can resolve.
fn euler_elastica_from_complementary_modulus(complementary: f64) -> EulerElastica {
    let k = ((1.0 - complementary) * (1.0 + complementary)).sqrt();
    let (complete_first, complete_second) = complete_elliptic_pair(k, complementary);
    EulerElastica {
        k,
        end_angle_rad: 2.0 * k.atan2(complementary),
        shortening_over_l: 2.0 * (1.0 - complete_second / complete_first),
        midspan_deflection_over_l: k / complete_first,
        load_over_pcr: (2.0 * complete_first / PI).powi(2),
    }
}

/// The pinned–pinned first-mode elastica of elliptic modulus k = sin(α/2), 0 ≤ k ≤ 1, in
/// the closed form above: for drawing the curve at evenly spaced end angles (the viewer's
/// Euler plot) rather than inverting it for one shortening.
pub fn euler_elastica_from_modulus(k: f64) -> EulerElastica {
    euler_elastica_from_complementary_modulus(complementary_modulus(k))
}

fn check_shortening(shortening_over_l: f64) {
    assert!(
        (0.0..2.0).contains(&shortening_over_l),
        "end-shortening Δ/L of a pinned elastica must lie in [0, 2), got {shortening_over_l}"
    );
}

/// Pinned–pinned first-mode elastica with end-shortening Δ/L ∈ [0, 2), from complete
/// elliptic integrals: Δ/L = 2·(1 − E(k)/K(k)) is inverted for k by bisection (it rises
/// monotonically from 0 at k = 0 to 2 as k → 1), then δ/L = k/K(k), P/P_cr = (2K(k)/π)²,
/// α = 2·asin k.
///
/// Checks: Δ/L = 5 % → δ/L = 0.1401, P/P_cr = 1.0257; Δ/L = 20 % → δ/L = 0.2663,
/// P/P_cr = 1.1127; small amplitude δ/L ≈ (2/π)·√(Δ/L).
pub fn euler_elastica_from_shortening(shortening_over_l: f64) -> EulerElastica {
    check_shortening(shortening_over_l);
    // The shortening falls as k' = cos(α/2) rises from 0 (a closed loop) to 1 (straight).
    let complementary = bisect_to_machine_precision(0.0, 1.0, |trial| {
        if euler_elastica_from_complementary_modulus(trial).shortening_over_l > shortening_over_l {
            ShotOutcome::TooLow
        } else {
            ShotOutcome::TooHigh
        }
    });
    euler_elastica_from_complementary_modulus(complementary)
}

/// Number of RK4 steps along the strip used by [`euler_elastica_shooting`] (even, so that
/// midspan is a grid point).
const EULER_SHOOTING_RK4_STEPS: usize = 2000;

/// Right-hand side of the compressed elastica in state form, with the load along x and
/// μ = P·L²/B: θ'' = −μ·sin θ, x' = cos θ, y' = sin θ.
fn euler_elastica_rhs(load_parameter: f64) -> impl Fn(f64, &StripState) -> StripState {
    move |_, state| {
        let [angle, curvature, _, _] = *state;
        [
            curvature,
            -load_parameter * angle.sin(),
            angle.cos(),
            angle.sin(),
        ]
    }
}

/// Integrates the pinned strip from s = 0 with θ(0) = α, θ'(0) = 0 (zero moment at the
/// pin) for load parameter μ = P·L²/B.
///
/// Returns the classification of μ (too low if the strip has not finished its half wave
/// by s = 1, i.e. θ'(1) < 0; too high if θ' has already turned back to ≥ 0 before the far
/// pin) and the states at s = 1/2 and s = 1.
fn shoot_pinned_elastica(
    end_angle: f64,
    load_parameter: f64,
) -> (ShotOutcome, StripState, StripState) {
    let rhs = euler_elastica_rhs(load_parameter);
    let steps = EULER_SHOOTING_RK4_STEPS;
    let h = 1.0 / steps as f64;
    let mut state: StripState = [end_angle, 0.0, 0.0, 0.0];
    let mut midspan = state;
    let mut outcome = ShotOutcome::TooLow;
    for step in 0..steps {
        state = rk4_step(&rhs, step as f64 * h, &state, h);
        if step + 1 == steps / 2 {
            midspan = state;
        }
        if state[1] >= 0.0 {
            outcome = ShotOutcome::TooHigh;
            break;
        }
    }
    (outcome, midspan, state)
}

/// Solves the pinned elastica for a given end angle α by shooting on μ = P·L²/B, and
/// returns the dimensionless shape measures (no elliptic integrals involved).
///
/// Bracket for μ: the pendulum's half period only grows with amplitude and equals 1 at
/// μ = π² for vanishing amplitude, so μ = π² is always too low; the upper end is doubled
/// until it overshoots.
fn euler_elastica_for_end_angle(end_angle: f64) -> EulerElastica {
    let euler_load_parameter = PI * PI;
    let classify = |trial: f64| shoot_pinned_elastica(end_angle, trial).0;
    let mut upper = 2.0 * euler_load_parameter;
    while classify(upper) == ShotOutcome::TooLow {
        upper *= 2.0;
    }
    let load_parameter = bisect_to_machine_precision(euler_load_parameter, upper, classify);
    let (_, midspan, far_end) = shoot_pinned_elastica(end_angle, load_parameter);
    EulerElastica {
        k: (0.5 * end_angle).sin(),
        end_angle_rad: end_angle,
        shortening_over_l: 1.0 - far_end[2],
        midspan_deflection_over_l: midspan[3],
        load_over_pcr: load_parameter / euler_load_parameter,
    }
}

/// The same pinned–pinned first-mode elastica as [`euler_elastica_from_shortening`], by a
/// second, independent method: θ'' = −(P/B)·sin θ is integrated with RK4 from one pin
/// (θ = α, θ' = 0), the load is found by shooting so that the moment vanishes again at
/// the far pin (θ'(L) = 0 closing the first half wave), and the end angle α by an outer
/// bisection until 1 − x(L)/L equals the requested Δ/L. δ/L is read at midspan.
///
/// Agrees with the elliptic-integral form to better than 1e-9 up to Δ/L = 1.5 (end angle
/// 172°). Beyond that the strip is close to a closed loop, the pendulum is close to its
/// separatrix and the shooting loses accuracy exponentially: use the elliptic form there.
pub fn euler_elastica_shooting(shortening_over_l: f64) -> EulerElastica {
    check_shortening(shortening_over_l);
    if shortening_over_l == 0.0 {
        return euler_elastica_from_complementary_modulus(1.0);
    }
    let end_angle = bisect_to_machine_precision(0.0, PI, |trial_angle| {
        if euler_elastica_for_end_angle(trial_angle).shortening_over_l < shortening_over_l {
            ShotOutcome::TooLow
        } else {
            ShotOutcome::TooHigh
        }
    });
    euler_elastica_for_end_angle(end_angle)
}

// ---------------------------------------------------------------------------------------
// Orthotropic plane stress (docs/references.md §1; paper eq. 1–3)
// ---------------------------------------------------------------------------------------

/// In-plane compliance of an orthotropic sheet rotated by θ: returns (S'₁₁, S'₁₂), the
/// strain along and across a uniaxial load applied at angle θ to the x (warp) axis, per
/// unit of that load.
///
/// Material axes (Lekhnitskii; Jones, *Mechanics of Composite Materials* §2.6), with
/// ν_xy the contraction along y under a load along x and ν_yx = ν_xy·E_y/E_x:
/// S₁₁ = 1/E_x, S₂₂ = 1/E_y, S₁₂ = −ν_xy/E_x, S₆₆ = 1/G (engineering shear strain).
/// Rotating the fourth-order compliance by θ (c = cos θ, s = sin θ):
/// S'₁₁ = S₁₁c⁴ + (2S₁₂ + S₆₆)c²s² + S₂₂s⁴,
/// S'₁₂ = S₁₂(c⁴ + s⁴) + (S₁₁ + S₂₂ − S₆₆)c²s².
fn rotated_compliance(ex: f64, ey: f64, g: f64, nu_xy: f64, theta_rad: f64) -> (f64, f64) {
    let s11 = 1.0 / ex;
    let s22 = 1.0 / ey;
    let s12 = -nu_xy / ex;
    let s66 = 1.0 / g;
    let (sin, cos) = theta_rad.sin_cos();
    let (c2, s2) = (cos * cos, sin * sin);
    let along = s11 * c2 * c2 + (2.0 * s12 + s66) * c2 * s2 + s22 * s2 * s2;
    let across = s12 * (c2 * c2 + s2 * s2) + (s11 + s22 - s66) * c2 * s2;
    (along, across)
}

/// Young's modulus of an orthotropic sheet loaded uniaxially at angle θ (radians) to the
/// x axis: 1/E_θ = cos⁴θ/E_x + (1/G − 2ν_xy/E_x)·cos²θ·sin²θ + sin⁴θ/E_y.
/// Moduli `ex`, `ey`, `g` in N/m (or all in Pa); ν_xy dimensionless as above.
/// E_0 = E_x, E_90 = E_y, and at 45°: 1/G = 4/E₄₅ − (1 − 2ν_xy)/E_x − 1/E_y.
pub fn off_axis_modulus(ex: f64, ey: f64, g: f64, nu_xy: f64, theta_rad: f64) -> f64 {
    let (along, _) = rotated_compliance(ex, ey, g, nu_xy, theta_rad);
    1.0 / along
}

/// Poisson ratio of an orthotropic sheet under uniaxial load at angle θ (radians) to the
/// x axis: the contraction perpendicular to the load over the extension along it,
/// ν_θ = −S'₁₂(θ)/S'₁₁(θ) (so S'₁₂ = −ν_θ/E_θ). ν_0 = ν_xy, ν_90 = ν_yx = ν_xy·E_y/E_x;
/// with G ≪ E it is close to 1 at 45° (a bias pull necks strongly).
pub fn off_axis_poisson(ex: f64, ey: f64, g: f64, nu_xy: f64, theta_rad: f64) -> f64 {
    let (along, across) = rotated_compliance(ex, ey, g, nu_xy, theta_rad);
    -across / along
}

/// Bending rigidity of a strip cut at angle θ (radians) to the warp (paper eq. 3):
/// B_θ = B_x·cos⁴θ + mid·cos²θ·sin²θ + B_y·sin⁴θ, all in N·m.
/// `mid` = 2ν_xy·B_x + 4·G·h³/12 (G in Pa, h the thickness in m), or a measured value.
pub fn bending_rigidity_theta(bx: f64, by: f64, mid: f64, theta_rad: f64) -> f64 {
    let (sin, cos) = theta_rad.sin_cos();
    let (c2, s2) = (cos * cos, sin * sin);
    bx * c2 * c2 + mid * c2 * s2 + by * s2 * s2
}

// ---------------------------------------------------------------------------------------
// Shear of a sheet between a clamped and a sliding edge (docs/references.md §6)
// ---------------------------------------------------------------------------------------

/// Angle (degrees, from the clamped edge) of the major principal stretch of a simple
/// shear, measured in the deformed sheet.
///
/// The clamped edge lies along x; the opposite edge slides along x, the gap along y being
/// held, so F = [[1, t], [0, 1]] with t = tan γ. The left Cauchy–Green tensor
/// b = F·Fᵀ = [[1 + t², t], [t, 1]] has its major eigenvector at φ with
/// tan 2φ = 2b₁₂/(b₁₁ − b₂₂) = 2/t, hence φ = ½·atan2(2, t) = 45° − ½·atan(t/2)
/// ≈ 45° − γ/4 to first order (41.71° at γ = 13°). It tends to 45° as γ → 0; material
/// lines are then stretched most along the diagonal the sliding edge pulls on.
/// (The same direction in the undeformed sheet, from C = FᵀF, is 45° + ½·atan(t/2).)
///
/// For an isotropic material this is also the principal stress direction, along which
/// wrinkle crests run. A fabric with G ≪ E does not follow it: see
/// [`simple_shear_principal_stress_angle_deg`].
pub fn simple_shear_principal_tension_angle_deg(gamma_rad: f64) -> f64 {
    (0.5 * 2.0_f64.atan2(gamma_rad.tan())).to_degrees()
}

/// Angle (degrees, from the clamped edge, in the deformed sheet) of the major principal
/// Cauchy stress of the same simple shear F = [[1, tan γ], [0, 1]] (x = warp along the
/// clamped edge, y = weft across the gap), for an orthotropic Saint-Venant–Kirchhoff sheet
/// with the plane-stress moduli of docs/references.md §1 (N/m, or all in Pa).
///
/// Green strain E = ½(FᵀF − I) = [[0, t/2], [t/2, t²/2]]; material-axis stress
/// S_xx = Q₁₁E_xx + Q₁₂E_yy, S_yy = Q₁₂E_xx + Q₂₂E_yy, S_xy = G·2E_xy with
/// Q₁₁ = E_x/(1 − ν_xy·ν_yx), Q₂₂ = E_y/(1 − ν_xy·ν_yx), Q₁₂ = ν_xy·E_y/(1 − ν_xy·ν_yx);
/// Cauchy stress σ = F·S·Fᵀ (J = 1); angle ½·atan2(2σ_xy, σ_xx − σ_yy).
///
/// This is the direction a tension field (wrinkle crests) follows when the gap is held.
/// With G ≪ E the weft yarns, stretched by √(1 + t²) − 1, carry most of the stress, so
/// the angle is steeper than 45°, tending towards the tilted weft at 90° − γ; for an
/// isotropic material it equals [`simple_shear_principal_tension_angle_deg`].
pub fn simple_shear_principal_stress_angle_deg(
    ex: f64,
    ey: f64,
    g: f64,
    nu_xy: f64,
    gamma_rad: f64,
) -> f64 {
    let t = gamma_rad.tan();
    let strain_xy = 0.5 * t;
    let strain_yy = 0.5 * t * t;
    let nu_yx = nu_xy * ey / ex;
    let poisson_factor = 1.0 - nu_xy * nu_yx;
    let q22 = ey / poisson_factor;
    let q12 = nu_xy * ey / poisson_factor;
    // E_xx is zero in simple shear: the clamped-edge direction is not stretched.
    let s_xx = q12 * strain_yy;
    let s_yy = q22 * strain_yy;
    let s_xy = g * 2.0 * strain_xy;
    // σ = F·S·Fᵀ with F = [[1, t], [0, 1]].
    let sigma_xx = s_xx + 2.0 * t * s_xy + t * t * s_yy;
    let sigma_xy = s_xy + t * s_yy;
    let sigma_yy = s_yy;
    (0.5 * (2.0 * sigma_xy).atan2(sigma_xx - sigma_yy)).to_degrees()
}

// ---------------------------------------------------------------------------------------
// Cusick drape test (docs/references.md §7; BS 5058, ISO 9073-9)
// ---------------------------------------------------------------------------------------

fn disk_area(diameter: f64) -> f64 {
    0.25 * PI * diameter * diameter
}

/// Drape coefficient DC = (A_shadow − A_disk)/(A_specimen − A_disk), dimensionless:
/// the fraction of the overhanging annulus still covered by the vertical projection of
/// the draped fabric (1 = stays flat, 0 = hangs straight down). `shadow_area` in m²,
/// diameters of the circular specimen and of the support disk in m.
pub fn cusick_drape_coefficient(
    shadow_area: f64,
    specimen_diameter: f64,
    support_diameter: f64,
) -> f64 {
    let support_area = disk_area(support_diameter);
    (shadow_area - support_area) / (disk_area(specimen_diameter) - support_area)
}

/// Lower bound of the Cusick drape coefficient from independent radial strips: each
/// strip of the overhang L = (D − d)/2 bends as a heavy cantilever (docs/references.md §4) with
/// λ = w·L³/B, w = ρ_A·g, so its tip reaches r = d/2 + (x_tip/L)·L and the shadow is the
/// disk of radius r: DC = (π·r² − A_disk)/(A_specimen − A_disk).
///
/// Real fabric cannot drape this far: the hoop (circumferential) stiffness that the
/// strips ignore forces folds, so a correct simulation's DC lies above this bound.
/// Units: diameters in m, `areal_density` in kg/m², `bending_rigidity` in N·m, `g` in
/// m/s².
pub fn independent_strip_drape_lower_bound(
    specimen_diameter: f64,
    support_diameter: f64,
    areal_density: f64,
    bending_rigidity: f64,
    g: f64,
) -> f64 {
    let overhang = 0.5 * (specimen_diameter - support_diameter);
    let lambda = cantilever_lambda(areal_density * g, overhang, bending_rigidity);
    let reach = heavy_cantilever(lambda).tip_reach_over_l * overhang;
    let shadow_radius = 0.5 * support_diameter + reach;
    cusick_drape_coefficient(
        PI * shadow_radius * shadow_radius,
        specimen_diameter,
        support_diameter,
    )
}
