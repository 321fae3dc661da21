//! A bias strip's bending length, and the plate rigidity that reproduces a measured one.
//!
//! The model's `bending_bias` is the rigidity B₄₅ of eq. 3: a cylindrical bend of a wide
//! sheet at 45° to the warp (docs/references.md §1). The cantilever standards measure
//! something else: a free strip, 25 mm wide, that may bend anticlastically. Along the bias
//! the rotated coupling D′₁₂ is large (D′₁₂²/(D′₁₁D′₂₂) ≈ 0.45 for the bundled wool), so the
//! strip relaxes a good share of its rigidity where nothing stops the cross-section from
//! curving the other way. Something does: bending the cross-section into a curve of
//! deflection v(y) while the strip has curvature κ stretches its fibres by κ·v(y), and the
//! sheet's stiffness E₄₅ along the strip resists that. Across the width this is a beam
//! (rigidity D′₂₂) on an elastic foundation (stiffness E₄₅·κ²) loaded at each free edge
//! by the moment D′₁₂·κ that the edge must shed:
//!
//! ```text
//!     D′₂₂ v'''' + E₄₅ κ² v = 0,   v''(±b/2) = −D′₁₂ κ / D′₂₂,   v'''(±b/2) = 0
//!
//!     ──────────────────────────────  strip, width b, seen end-on
//!     ╲__                        __╱  anticlastic edge zones, width ℓ = (4 D′₂₂/(E₄₅ κ²))^¼
//! ```
//!
//! Its solution (cosh·cos and sinh·sin modes; the classical analysis of the anticlastic
//! edge zone of a bent plate strip) gives the energy per area
//! ½κ²[D′₁₁ − (D′₁₂²/D′₂₂)·F(t)], t = b/(2ℓ),
//! F(t) = (cosh 2t − cos 2t) / (t·(sinh 2t + sin 2t)): F → 1 for a narrow strip (the free
//! beam, D′₁₁ − D′₁₂²/D′₂₂) and F → 1/t for a wide one (only two edge zones relax). Since
//! ℓ shrinks as the strip bends more, the strip's moment is a nonlinear law,
//! M(κ) = κ·[D′₁₁ − (D′₁₂²/D′₂₂)·(F + t·F′/4)]. The overhang test of such a strip is the
//! heavy elastica of docs/references.md §4 with M(κ) in place of B·κ, solved here by
//! shooting. The bending-twist coupling D′₁₆ = (B_x − B_y)/4 is left out: it vanishes
//! for a balanced fabric and a bent wide strip cannot twist without stretching either.
//!
//! [`plate_rigidity_for_bending_length`] inverts this: the B₄₅ whose 25 mm strip's
//! 41.5° overhang is twice the measured bias bending length. docs/fabric-sheets.md shows
//! how far it moves B₄₅ (5–15 %) and how closely the simulated strip follows the theory.

use crate::physics::{bending_length, rigidity_for_bending_length, weight_per_area};
use crate::sim::BendingStiffness;
use std::f64::consts::FRAC_PI_2;
use thiserror::Error;

/// The chord angle of the cantilever standards, degrees (ASTM D1388, BS 3356).
pub const STANDARD_CHORD_ANGLE_DEG: f64 = 41.5;

/// The standard strip's width, m (ASTM D1388: 25 mm).
pub const STANDARD_STRIP_WIDTH: f64 = 0.025;

/// What the bias strip's theory needs of a fabric, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasStrip {
    /// Mass per area, kg/m².
    pub areal_density: f64,
    /// Bending rigidities along the warp and the weft, N·m.
    pub bending_warp: f64,
    pub bending_weft: f64,
    /// The model's Poisson ratio ν_xy: it sets D₁₂ = ν·B_x (paper eq. 3).
    pub poisson_warp: f64,
    /// Small-strain modulus along the strip, at 45° to the warp, N/m.
    pub axial_modulus: f64,
    /// Strip width, m.
    pub width: f64,
}

#[derive(Debug, Error, PartialEq)]
pub enum BiasError {
    #[error(
        "a bias bending length of {measured_mm:.2} mm is shorter than any sheet with these warp and weft \
         rigidities can give ({shortest_mm:.2} mm, with no twisting rigidity at all): check c_bias, or the \
         warp and weft values it is combined with"
    )]
    TooShort { measured_mm: f64, shortest_mm: f64 },
    #[error("a bias bending length of {measured_mm:.1} mm needs a bias rigidity over 100 times the warp's; check c_bias and its unit")]
    TooLong { measured_mm: f64 },
}

/// The plate stiffnesses of a strip cut at 45°, for a model `bending_bias` of `b45`:
/// (D′₁₁, D′₁₂, D′₂₂) in N·m, with the model's split of eq. 3's middle term
/// ([`BendingStiffness::with_bias_rigidity`]).
pub fn rotated_45(strip: &BiasStrip, b45: f64) -> (f64, f64, f64) {
    let (bx, by) = (strip.bending_warp, strip.bending_weft);
    let BendingStiffness { d12, d66, .. } = BendingStiffness::with_bias_rigidity(bx, by, strip.poisson_warp, b45);
    // Rotating D by 45°: D′₁₁ = D′₂₂ = (D₁₁ + D₂₂ + 2D₁₂ + 4D₆₆)/4 = B₄₅ and
    // D′₁₂ = (D₁₁ + D₂₂ − 4D₆₆)/4 + D₁₂/2.
    (b45, 0.25 * (bx + by - 4.0 * d66) + 0.5 * d12, b45)
}

/// F(t) and t·F′(t) of the edge-zone solution (see the module notes).
fn edge_zone(t: f64) -> (f64, f64) {
    if t < 0.01 {
        // Series: F = 1 − (4/45) t⁴ + …, so t·F′ = −(16/45) t⁴.
        let t4 = t.powi(4);
        return (1.0 - 4.0 / 45.0 * t4, -16.0 / 45.0 * t4);
    }
    let x = 2.0 * t;
    // Everything divided by cosh 2t, so that wide strips do not overflow.
    let e = if x > 700.0 { 0.0 } else { 1.0 / x.cosh() };
    let n = 1.0 - x.cos() * e;
    let d = x.tanh() + x.sin() * e;
    let p = 1.0 + x.cos() * e;
    let f = n / (t * d);
    (f, 2.0 - f - 2.0 * n * p / (d * d))
}

/// The strip's moment–curvature law M(κ) (N·m/m against 1/m).
#[derive(Debug, Clone, Copy)]
pub struct StripLaw {
    d11: f64,
    /// D′₁₂²/D′₂₂, N·m: what a fully free cross-section sheds.
    shed: f64,
    /// t per √κ, √m.
    t_per_root_kappa: f64,
}

impl StripLaw {
    pub fn new(strip: &BiasStrip, b45: f64) -> Self {
        let (d11, d12, d22) = rotated_45(strip, b45);
        let t_per_root_kappa = 0.5 * strip.width * (strip.axial_modulus / (4.0 * d22)).powf(0.25);
        Self { d11, shed: d12 * d12 / d22, t_per_root_kappa }
    }

    /// The secant rigidity M/κ at curvature κ, N·m.
    fn secant(&self, kappa: f64) -> f64 {
        let (f, tfp) = edge_zone(self.t_per_root_kappa * kappa.abs().sqrt());
        self.d11 - self.shed * (f + 0.25 * tfp)
    }

    /// Moment per unit width at curvature κ, N·m/m.
    pub fn moment(&self, kappa: f64) -> f64 {
        kappa * self.secant(kappa)
    }

    /// dM/dκ, N·m, by a central difference (the law is smooth and the shooting below
    /// needs it to a few digits only).
    fn tangent(&self, kappa: f64) -> f64 {
        let h = 1e-6 * kappa.abs().max(1e-3);
        (self.moment(kappa + h) - self.moment(kappa - h)) / (2.0 * h)
    }
}

/// RK4 steps along the strip; the curvature profile is smooth, and doubling them moves
/// the chord angle by less than 1e-9°.
const STEPS: usize = 400;

/// Chord angle, radians below the horizontal, of a strip of overhang `length` (m) with
/// the moment law `law` under weight `w` (N/m²), clamped horizontally at one end: the
/// heavy elastica (docs/references.md §4) θ' = κ, dM(κ)/ds = −w·(L − s)·cos θ, M(L) = 0,
/// by shooting on the clamp's curvature with bisection.
pub fn chord_angle(law: &StripLaw, w: f64, length: f64) -> f64 {
    let h = length / STEPS as f64;
    let rhs = |s: f64, y: [f64; 4]| -> [f64; 4] {
        let [theta, kappa, _, _] = y;
        [kappa, -w * (length - s) * theta.cos() / law.tangent(kappa), theta.cos(), theta.sin()]
    };
    // Ok(tip state) or Err(too low) / Err(too high) as in `reference::heavy_cantilever`.
    let shoot = |kappa0: f64| -> Result<[f64; 4], bool> {
        let mut y = [0.0, kappa0, 0.0, 0.0];
        for i in 0..STEPS {
            let s = i as f64 * h;
            let add = |a: [f64; 4], b: [f64; 4], f: f64| std::array::from_fn::<f64, 4, _>(|j| a[j] + f * b[j]);
            let k1 = rhs(s, y);
            let k2 = rhs(s + 0.5 * h, add(y, k1, 0.5 * h));
            let k3 = rhs(s + 0.5 * h, add(y, k2, 0.5 * h));
            let k4 = rhs(s + h, add(y, k3, h));
            y = std::array::from_fn(|j| y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
            if y[0] >= FRAC_PI_2 {
                return Err(false);
            }
            if y[1] < 0.0 {
                return Err(true);
            }
        }
        Ok(y)
    };
    // The clamp carries at most the whole overhang's weight at its full length: wL²/2.
    let mut high = 1.0 / length;
    while law.moment(high) < 0.5 * w * length * length {
        high *= 2.0;
    }
    let mut low = 0.0;
    let mut tip = [0.0; 4];
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if mid <= low || mid >= high || high - low < 1e-12 * high {
            break;
        }
        match shoot(mid) {
            Err(true) => low = mid,
            Err(false) => high = mid,
            Ok(y) => {
                tip = y;
                if y[1] > 0.0 { high = mid } else { low = mid }
            }
        }
    }
    if let Ok(y) = shoot(0.5 * (low + high)) {
        tip = y;
    }
    tip[3].atan2(tip[2])
}

/// The bending length (m) the cantilever standards would read on this strip with the
/// model's `bending_bias` = `b45`: half the overhang whose chord makes 41.5°.
pub fn strip_bending_length(strip: &BiasStrip, b45: f64) -> f64 {
    let law = StripLaw::new(strip, b45);
    let w = weight_per_area(strip.areal_density);
    let target = STANDARD_CHORD_ANGLE_DEG.to_radians();
    // The chord angle grows with the overhang; bracket, then bisect on ln L.
    let plate = bending_length(b45, w);
    let (mut low, mut high) = (plate, 2.0 * plate);
    while chord_angle(&law, w, low) > target {
        low *= 0.7;
    }
    while chord_angle(&law, w, high) < target {
        high *= 1.5;
    }
    while high / low - 1.0 > 1e-9 {
        let mid = (low * high).sqrt();
        if chord_angle(&law, w, mid) < target { low = mid } else { high = mid }
    }
    0.25 * (low + high)
}

/// The model's `bending_bias` (the plate's B₄₅, N·m) for which the strip reproduces a
/// measured bias bending length `c` (m): its overhang 2c makes the standard's 41.5°.
pub fn plate_rigidity_for_bending_length(strip: &BiasStrip, c: f64) -> Result<f64, BiasError> {
    let w = weight_per_area(strip.areal_density);
    let (length, target) = (2.0 * c, STANDARD_CHORD_ANGLE_DEG.to_radians());
    // More rigidity, less droop. Eq. 3's middle term must stay positive (material.rs),
    // so B₄₅ > (B_x + B_y)/4.
    let softest = 0.25 * (strip.bending_warp + strip.bending_weft) * (1.0 + 1e-6);
    let ceiling = 100.0 * strip.bending_warp.max(strip.bending_weft);
    // The bending lengths the rigidity's range gives, compared first: far outside it (a
    // 1 m bending length), the droop of a strip 2c long is no guide (its elastica folds
    // back on itself).
    if c > strip_bending_length(strip, ceiling) {
        return Err(BiasError::TooLong { measured_mm: c * 1e3 });
    }
    let droop = |b45: f64| chord_angle(&StripLaw::new(strip, b45), w, length);
    if droop(softest) < target {
        return Err(BiasError::TooShort { measured_mm: c * 1e3, shortest_mm: strip_bending_length(strip, softest) * 1e3 });
    }
    let mut high = rigidity_for_bending_length(c, w).max(softest * 1.01);
    while droop(high) > target {
        high *= 2.0;
        if high > ceiling {
            return Err(BiasError::TooLong { measured_mm: c * 1e3 });
        }
    }
    let mut low = softest;
    while high / low - 1.0 > 1e-9 {
        let mid = (low * high).sqrt();
        if droop(mid) > target { low = mid } else { high = mid }
    }
    Ok((low * high).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::heavy_cantilever;
    use crate::sim::{Fabric, PiecewiseLinear};

    fn wool(width: f64) -> BiasStrip {
        BiasStrip {
            areal_density: 0.137,
            bending_warp: 9e-6,
            bending_weft: 7e-6,
            poisson_warp: 0.15,
            axial_modulus: 148.4,
            width,
        }
    }

    #[test]
    fn the_45_degree_stiffness_follows_the_models_split_of_eq3() {
        let strip = wool(0.025);
        let fabric = Fabric {
            areal_density: 0.137,
            thickness: 3e-4,
            tensile_warp: PiecewiseLinear::linear(1000.0),
            tensile_weft: PiecewiseLinear::linear(800.0),
            shear_modulus: 40.0,
            poisson_warp: 0.15,
            bending_warp: 9e-6,
            bending_weft: 7e-6,
            bending_bias: Some(5.6e-6),
            bending_curve: None,
        };
        let d = BendingStiffness::new(&fabric).unwrap();
        let (d11, d12, d22) = rotated_45(&strip, 5.6e-6);
        // D′₁₂ at 45° from the model's own tensor: (D₁₁ + D₂₂ − 4D₆₆)/4 + D₁₂/2.
        let d12_model = 0.25 * (d.d11 + d.d22 - 4.0 * d.d66) + 0.5 * d.d12;
        assert!((d11 - d.rigidity_at(std::f64::consts::FRAC_PI_4)).abs() < 1e-18);
        assert_eq!(d11, d22);
        assert!((d12 - d12_model).abs() < 1e-18, "{d12} vs {d12_model}");
    }

    #[test]
    fn edge_zone_function_has_its_narrow_and_wide_limits() {
        assert!((edge_zone(1e-3).0 - 1.0).abs() < 1e-12);
        let (f, tfp) = edge_zone(0.0101);
        let (fs, tfps) = (1.0 - 4.0 / 45.0 * 0.0101f64.powi(4), -16.0 / 45.0 * 0.0101f64.powi(4));
        assert!((f - fs).abs() < 1e-9 && (tfp - tfps).abs() < 1e-9, "the series and the closed form meet");
        let (f, tfp) = edge_zone(50.0);
        assert!((f - 1.0 / 50.0).abs() < 1e-12 && (tfp + 1.0 / 50.0).abs() < 1e-12);
        assert_eq!(edge_zone(800.0).0, 1.0 / 800.0, "no overflow for very wide strips");
    }

    #[test]
    fn a_strip_without_coupling_is_the_plain_elastica() {
        // With D′₁₂ = 0 nothing relaxes: the chord angle is the elastica's at λ = wL³/B.
        let mut strip = wool(0.025);
        strip.poisson_warp = 0.0;
        let b45 = 0.25 * (9e-6 + 7e-6) * 2.0; // 4D₆₆ = B_x + B_y makes D′₁₂ = 0.
        let law = StripLaw::new(&strip, b45);
        let w = weight_per_area(0.137);
        for lambda in [2.0, 8.0, 20.0] {
            let length: f64 = (lambda * b45 / w).cbrt();
            let exact = heavy_cantilever(lambda).chord_angle_rad;
            assert!((chord_angle(&law, w, length) - exact).abs() < 1e-8, "λ = {lambda}");
        }
    }

    #[test]
    fn bias_mapping_inverts_the_strip_and_relaxation_grows_as_the_strip_narrows() {
        let b45 = 5.6e-6;
        let w = weight_per_area(0.137);
        let plate = bending_length(b45, w);
        let mut last = 0.0;
        for width in [0.008, 0.025, 0.1] {
            let strip = wool(width);
            let c = strip_bending_length(&strip, b45);
            assert!(c < plate && c > last, "width {width}: {c} vs plate {plate}");
            last = c;
            let back = plate_rigidity_for_bending_length(&strip, c).unwrap();
            assert!((back - b45).abs() < 1e-6 * b45, "width {width}: {back} vs {b45}");
        }
        let err = plate_rigidity_for_bending_length(&wool(0.025), 0.004).unwrap_err();
        assert!(matches!(err, BiasError::TooShort { .. }), "{err}");
    }
}
