//! Physical constants and the defining relations of the bending tests, each written once.
//!
//! Everything that weighs cloth reads gravity here: the simulator's default gravity, the
//! scenes' measurements, the sheet importer (which turns a measured bending length into a
//! rigidity) and the virtual laboratory (which reads the bending length back). With one
//! value the round trip c → B → c is exact. The module uses nothing but `std`, so `sim`,
//! `fabric`, `scene` and `reference` can all import it without a circle.
//!
//! Units: SI, per unit width as textile laboratories report fabric properties: bending
//! rigidity B in N·m (N·m²/m), weight per area w in N/m², lengths in m.

/// Standard gravity, m/s²: the value that defines the gram-force (3rd CGPM, 1901), so that
/// the KES and FAST unit conversions (docs/references.md §8) and the weight of cloth agree.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Weight per area w = ρ_A·g, N/m², of cloth with mass per area `areal_density` (kg/m²)
/// under [`STANDARD_GRAVITY`].
pub fn weight_per_area(areal_density: f64) -> f64 {
    areal_density * STANDARD_GRAVITY
}

/// Peirce's bending length c = (B/w)^(1/3), m, of a strip of rigidity `bending_rigidity`
/// (N·m) and weight per area `weight_per_area` (N/m²): docs/references.md §4 (Peirce;
/// ASTM D1388; BS 3356) and §8 (the cantilever's B = w·c³).
pub fn bending_length(bending_rigidity: f64, weight_per_area: f64) -> f64 {
    (bending_rigidity / weight_per_area).cbrt()
}

/// The rigidity B = w·c³, N·m, that a measured bending length `bending_length` (m) gives
/// cloth of weight per area `weight_per_area` (N/m²): the inverse of [`bending_length`]
/// (docs/references.md §8; FAST's B = W·C³·g).
pub fn rigidity_for_bending_length(bending_length: f64, weight_per_area: f64) -> f64 {
    weight_per_area * bending_length.powi(3)
}

/// The heavy cantilever's one parameter λ = w·L³/B (dimensionless) for a strip of
/// overhang `length` (m), weight per area `weight_per_area` (N/m²) and rigidity
/// `bending_rigidity` (N·m): docs/references.md §4. λ = 8 is an overhang of twice the
/// bending length, where the standards' 41.5° chord is read.
pub fn cantilever_lambda(weight_per_area: f64, length: f64, bending_rigidity: f64) -> f64 {
    weight_per_area * length.powi(3) / bending_rigidity
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_overhang_of_twice_the_bending_length_is_lambda_eight() {
        // L = 2c gives λ = w·8c³/B = 8 by the definition of c (docs/references.md §4).
        let (b, w) = (7.4e-6, 1.344);
        let c = bending_length(b, w);
        assert!((cantilever_lambda(w, 2.0 * c, b) - 8.0).abs() < 1e-12);
        assert!((rigidity_for_bending_length(c, w) - b).abs() < 1e-12 * b);
    }

    #[test]
    fn a_gram_force_is_a_gram_under_standard_gravity() {
        assert_eq!(weight_per_area(1e-3), 9.80665e-3);
    }
}
