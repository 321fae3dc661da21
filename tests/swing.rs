//! Cloth in motion against a known answer: a strip hung from its top edge swings as a
//! hanging chain (Bernoulli; docs/references.md §10), first-mode period
//! T₁ = (4π/j₀,₁)·√(L/g), when its bending length is small against its length. The exact
//! path at a short step keeps that period and the swing's amplitude; a long implicit-Euler
//! step lags by the phase error the method makes on an undamped oscillator.

mod common;

use common::run;
use rosette::physics::STANDARD_GRAVITY as GRAVITY;

/// The first zero of the Bessel function J₀ (Abramowitz and Stegun, Table 9.5).
const J0_FIRST_ZERO: f64 = 2.404_825_557_7;

/// The hanging chain's first-mode period, s.
fn chain_period(length: f64) -> f64 {
    4.0 * std::f64::consts::PI / J0_FIRST_ZERO * (length / GRAVITY).sqrt()
}

/// The largest sideways displacement of the free edge in the samples at or after `from` s,
/// and its time: (s, m).
fn peak_after(history: &[[f64; 2]], from: f64) -> (f64, f64) {
    history.iter().filter(|p| p[0] >= from).map(|p| (p[0], p[1].abs())).fold((from, 0.0), |a, b| if b.1 > a.1 { b } else { a })
}

/// The bundled swing (0.5 m of silk, 10 mm edges, BDF2 at 4 ms, no drag). The chain's theory
/// leaves out bending: its boundary layer at the clamp, √(B/(wL)) = 2 mm for this silk, is
/// 0.4 % of the length, and the period is held to 1 %. With no drag and a second-order step
/// 300 steps a period, the swing keeps nine tenths of its amplitude over two periods.
#[test]
fn a_hanging_strip_swings_with_the_chains_period() {
    let (config, m) = run("swing", &[]);
    let swing = m.measures.swing().expect("swing measures");
    let expected = chain_period(config.cloth.length);
    let period = swing.swing_period.expect("two half periods measured");
    let amplitude = config.test.swing_amplitude.unwrap();
    let (_, last) = peak_after(&swing.bottom_history, config.scene.duration - expected);
    println!("swing: period {period:.5} s, chain {expected:.5} s ({:+.3} %), last period's amplitude {last:.5} m of {amplitude} m", 100.0 * (period / expected - 1.0));
    assert!(swing.half_periods >= 3, "{} half periods", swing.half_periods);
    assert!((period / expected - 1.0).abs() < 0.01, "period {period} s against the chain's {expected} s");
    assert!(last > 0.9 * amplitude && last < 1.1 * amplitude, "amplitude {last} m after two periods, started at {amplitude} m");
}

/// Implicit Euler on an undamped oscillator of frequency ω turns each step by atan(ωh)
/// instead of ωh, so its period is longer by ωh/atan(ωh) (≈ 1 + (ωh)²/3), and shrinks the
/// amplitude by 1/√(1 + (ωh)²) a step. The fast path's 16 ms step for cloth in motion is
/// checked against both, relative to the short-step run: ωh ≈ 0.085 makes the period 0.24 %
/// longer, held to within a third of that, and the amplitude at the last period's peak is
/// held to within 0.05 of the prediction at that peak's time.
#[test]
fn a_long_implicit_euler_step_lags_and_damps_the_swing_as_its_phase_error_predicts() {
    let (_, short) = run("swing", &[]);
    let (config, long) = run("swing", &["solver.path=fast".into(), "solver.integrator=implicit-euler".into()]);
    let h = long.dt;
    assert!(h > 0.010, "the fast path takes the long step for cloth in motion: {h} s");
    assert!(long.converged && long.stable);
    let reference = short.measures.swing().unwrap().swing_period.unwrap();
    let swing = long.measures.swing().unwrap();
    let period = swing.swing_period.expect("two half periods measured");
    let omega_h = std::f64::consts::TAU / reference * h;
    let predicted = omega_h / omega_h.atan();
    let ratio = period / reference;
    let amplitude = config.test.swing_amplitude.unwrap();
    let (t, peak) = peak_after(&swing.bottom_history, config.scene.duration - reference);
    let kept = peak / amplitude;
    let kept_predicted = (1.0 + omega_h * omega_h).powf(-0.5 * t / h);
    println!("implicit Euler, {h} s: period ratio {ratio:.5} (predicted {predicted:.5}), amplitude kept {kept:.3} (predicted about {kept_predicted:.3})");
    assert!((ratio - predicted).abs() < (predicted - 1.0) / 3.0, "period ratio {ratio}, predicted {predicted}");
    assert!((kept - kept_predicted).abs() < 0.05, "amplitude kept {kept}, predicted {kept_predicted}");
}
