//! The hanging chain: small sideways oscillations of a heavy, flexible, inextensible line
//! hung from one end (Daniel Bernoulli, 1733; docs/references.md §10). A strip of cloth
//! hung from its top edge, whose bending length is small against its length, swings as
//! such chains side by side.
//!
//! With s measured up from the free end, the tension is the weight below, T = w s, and the
//! sideways displacement u(s, t) obeys ∂²u/∂t² = g ∂/∂s (s ∂u/∂s). Its modes are
//! u = J₀(2ω√(s/g)) cos ωt; the fixed top u(L) = 0 makes 2ω√(L/g) a zero of J₀, so
//! ω_n = (j₀,ₙ / 2) √(g/L), and the first mode's period is T₁ = 4π/j₀,₁ · √(L/g).

/// The first zero of the Bessel function J₀.
pub const J0_FIRST_ZERO: f64 = 2.404_825_557_695_773;

/// J₀(x) by its power series Σ (−1)ᵏ (x/2)²ᵏ / (k!)², summed until the terms no longer
/// change the sum (converges for every x; used here for 0 ≤ x ≤ j₀,₁, where a few tens of
/// terms reach round-off).
pub fn bessel_j0(x: f64) -> f64 {
    let q = 0.25 * x * x;
    let (mut term, mut sum) = (1.0f64, 1.0f64);
    for k in 1..200 {
        term *= -q / (k * k) as f64;
        sum += term;
        if term.abs() < 1e-17 * sum.abs().max(1e-300) {
            break;
        }
    }
    sum
}

/// The first mode's shape at height `s` above the free end of a chain of length `length`,
/// normalised to 1 at the free end and 0 at the top: J₀(j₀,₁ √(s/L)).
pub fn hanging_chain_mode(s: f64, length: f64) -> f64 {
    bessel_j0(J0_FIRST_ZERO * (s / length).clamp(0.0, 1.0).sqrt())
}

/// The first mode's period of a hanging chain of length `length` (m) under gravity `g`
/// (m/s²), s.
pub fn hanging_chain_period(length: f64, g: f64) -> f64 {
    4.0 * std::f64::consts::PI / J0_FIRST_ZERO * (length / g).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bessel_j0_matches_tabulated_values_and_vanishes_at_its_first_zero() {
        // Abramowitz and Stegun, Table 9.1.
        assert!((bessel_j0(0.0) - 1.0).abs() < 1e-15);
        assert!((bessel_j0(1.0) - 0.765_197_686_557_966_6).abs() < 1e-14);
        assert!((bessel_j0(2.0) - 0.223_890_779_141_235_7).abs() < 1e-14);
        assert!(bessel_j0(J0_FIRST_ZERO).abs() < 1e-14);
    }

    #[test]
    fn the_first_period_is_about_five_and_a_quarter_times_the_root_of_length_over_g() {
        // 4π/j₀,₁ = 5.2255…; a 1 m chain under 9.81 m/s² swings in 1.668 s.
        assert!((hanging_chain_period(1.0, 1.0) - 5.225_481).abs() < 1e-5);
        assert!((hanging_chain_period(1.0, 9.81) - 1.668_36).abs() < 1e-4);
        assert!(hanging_chain_mode(1.0, 1.0).abs() < 1e-14, "the top does not move");
    }
}
