//! Fabric material laws: the in-plane strain energy of a woven sheet and its bending
//! stiffness tensor.
//!
//! Conventions (docs/references.md §1): x is the warp, y the weft. `nu_xy` is the contraction
//! along the weft per unit strain under a warp pull; reciprocity gives
//! `nu_yx = nu_xy · E_y / E_x` from the small-strain moduli. Fabric quantities are per unit
//! width: stresses and moduli in N/m, bending rigidities in N·m.

use crate::sim::curve::{CurveError, PiecewiseLinear};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Measured properties of a fabric, in SI units per unit width: the simulator's material,
/// and (with its curves as lists of points, [`FabricPoints`]) what a fabric file holds. One
/// definition serves both, so that a property is added in one place.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fabric<Curve = PiecewiseLinear> {
    /// Mass per unit area, kg/m².
    pub areal_density: f64,
    /// Thickness, m (enters eq. 3's twisting term and the contact thickness).
    pub thickness: f64,
    /// Warp tensile curve: stress (N/m) against engineering strain, measured in a uniaxial pull.
    pub tensile_warp: Curve,
    /// Weft tensile curve: stress (N/m) against engineering strain.
    pub tensile_weft: Curve,
    /// In-plane shear modulus G, N/m (per radian of engineering shear strain).
    pub shear_modulus: f64,
    /// Poisson ratio ν_xy: weft contraction per unit warp strain in a warp pull.
    pub poisson_warp: f64,
    /// Bending rigidity for bending along the warp (curvature in the warp direction), N·m.
    pub bending_warp: f64,
    /// Bending rigidity for bending along the weft, N·m.
    pub bending_weft: f64,
    /// Measured rigidity of a strip cut at 45°, N·m; replaces eq. 3's middle term when given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_bias: Option<f64>,
    /// Nonlinear bending: a warp moment–curvature curve, moment per unit width (N·m/m)
    /// against curvature (1/m). Its shape (moments over its initial slope) scales the
    /// rigidities with curvature in every direction; `bending_warp` keeps setting the
    /// small-curvature rigidity. `None` is linear bending.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending_curve: Option<Curve>,
}

/// A fabric as a file gives it: every curve a list of `[x, y]` points, not yet checked.
pub type FabricPoints = Fabric<Vec<[f64; 2]>>;

impl<C> Fabric<C> {
    /// The same fabric with every curve mapped by `f` (given the curve's key): the one place
    /// that lists the curves.
    pub fn try_map_curves<D, E>(&self, f: impl Fn(&'static str, &C) -> Result<D, E>) -> Result<Fabric<D>, E> {
        Ok(Fabric {
            areal_density: self.areal_density,
            thickness: self.thickness,
            tensile_warp: f("tensile_warp", &self.tensile_warp)?,
            tensile_weft: f("tensile_weft", &self.tensile_weft)?,
            shear_modulus: self.shear_modulus,
            poisson_warp: self.poisson_warp,
            bending_warp: self.bending_warp,
            bending_weft: self.bending_weft,
            bending_bias: self.bending_bias,
            bending_curve: self.bending_curve.as_ref().map(|c| f("bending_curve", c)).transpose()?,
        })
    }
}

impl FabricPoints {
    /// The material: every curve built and every property checked.
    pub fn to_fabric(&self) -> Result<Fabric, FabricError> {
        let fabric = self.try_map_curves(|key, points| PiecewiseLinear::new_material(points).map_err(|source| FabricError::Curve { key, source }))?;
        fabric.validate()?;
        Ok(fabric)
    }
}

/// A fabric property that is out of range, named by its preset key.
#[derive(Debug, Error, PartialEq)]
pub enum FabricError {
    #[error("fabric.{key} must be {expected}, got {value:?}")]
    OutOfRange { key: &'static str, expected: &'static str, value: f64 },
    #[error("fabric.{key}: {source}")]
    Curve { key: &'static str, source: CurveError },
    #[error(
        "fabric.poisson_warp = {nu:?} makes the in-plane energy non-convex with these tensile curves \
         (the material would have no stable state); use a value below {limit:.3} or stiffen the softest \
         segments of the curves"
    )]
    PoissonTooLarge { nu: f64, limit: f64 },
    #[error("fabric.{key} = {value:e} is below any fabric (at least {min:e} {unit}: {why}): check the units")]
    TooSmall { key: &'static str, value: f64, min: f64, unit: &'static str, why: &'static str },
    #[error("fabric.{key} = {value:e} is beyond any fabric (at most {max:e} in SI units; a 1 cm steel plate stays below it): check the units")]
    TooLarge { key: &'static str, value: f64, max: f64 },
    #[error(
        "fabric.{key} has a segment of slope {slope:e}, beyond any fabric (at most {max:e} in SI units; a 1 cm steel plate \
         stays below it): check the units of its points"
    )]
    SteepCurve { key: &'static str, slope: f64, max: f64 },
    #[error(
        "fabric.bending_bias = {bias:?} N·m is too small for bending_warp = {warp:?} and bending_weft = {weft:?}: \
         eq. 3 would need a negative twisting rigidity; use at least {min:.3e} N·m"
    )]
    BiasTooSmall { bias: f64, warp: f64, weft: f64, min: f64 },
}

impl FabricError {
    /// The fabric key the error is about (the key under `fabric.`).
    pub fn key(&self) -> &'static str {
        match self {
            Self::OutOfRange { key, .. }
            | Self::Curve { key, .. }
            | Self::TooLarge { key, .. }
            | Self::TooSmall { key, .. }
            | Self::SteepCurve { key, .. } => key,
            Self::PoissonTooLarge { .. } => "poisson_warp",
            Self::BiasTooSmall { .. } => "bending_bias",
        }
    }
}

/// Ceilings far beyond any fabric, which put a typo's 1e300 in front of the user instead of
/// letting it overflow the solver's arithmetic into a NaN: a 1 cm steel plate, stiffer than
/// any cloth, has E·h ≈ 2e9 N/m, a bending rigidity E·h³/12 ≈ 2e4 N·m and 79 kg/m².
const MAX_AREAL_DENSITY: f64 = 1e3;
/// A floor for the mass: 1 g/m², a tenth of the lightest nonwovens. Lighter, the cloth has
/// no inertia to speak of and contact's penalty (scaled by the mass) no force: the Newton
/// solves then run to their limits on every step.
const MIN_AREAL_DENSITY: f64 = 1e-3;
const MAX_THICKNESS: f64 = 0.1;
const MAX_MODULUS: f64 = 1e11;
const MAX_RIGIDITY: f64 = 1e6;
/// Floors far below any fabric, which refuse a value that underflows to nothing (5e-324)
/// instead of letting it reach the metrics as a zero or a NaN: the thinnest chiffon is
/// about 0.05 mm thick, bends with about 5e-7 N·m and shears with about 10 N/m
/// (KES-F B ≈ 0.005 gf·cm and G ≈ 0.2 gf/cm/° for light silks; docs/robustness.md).
const MIN_THICKNESS: f64 = 1e-6;
const MIN_MODULUS: f64 = 1e-3;
const MIN_RIGIDITY: f64 = 1e-9;

/// Refuses `value` below `min` (after [`in_range`] has checked it is positive and finite).
fn at_least(key: &'static str, value: f64, min: f64, unit: &'static str, why: &'static str) -> Result<(), FabricError> {
    if value < min { Err(FabricError::TooSmall { key, value, min, unit, why }) } else { Ok(()) }
}

fn in_range(key: &'static str, value: f64, max: f64) -> Result<(), FabricError> {
    if !(value.is_finite() && value > 0.0) {
        Err(FabricError::OutOfRange { key, expected: "a positive finite number", value })
    } else if value > max {
        Err(FabricError::TooLarge { key, value, max })
    } else {
        Ok(())
    }
}

/// A curve's steepest segment, checked against `max` (N/m for tensile curves, N·m for the
/// bending curve).
fn curve_in_range(key: &'static str, curve: &PiecewiseLinear, max: f64) -> Result<(), FabricError> {
    let slope = curve.max_slope();
    if slope <= max {
        Ok(())
    } else {
        Err(FabricError::SteepCurve { key, slope, max })
    }
}

impl Fabric {
    /// Checks every property and that the laws built from them are stable.
    pub fn validate(&self) -> Result<(), FabricError> {
        in_range("areal_density", self.areal_density, MAX_AREAL_DENSITY)?;
        if self.areal_density < MIN_AREAL_DENSITY {
            return Err(FabricError::OutOfRange { key: "areal_density", expected: "at least 1e-3 kg/m² (1 g/m²; the lightest fabrics weigh about 10)", value: self.areal_density });
        }
        in_range("thickness", self.thickness, MAX_THICKNESS)?;
        in_range("shear_modulus", self.shear_modulus, MAX_MODULUS)?;
        in_range("bending_warp", self.bending_warp, MAX_RIGIDITY)?;
        in_range("bending_weft", self.bending_weft, MAX_RIGIDITY)?;
        at_least("thickness", self.thickness, MIN_THICKNESS, "m", "a thousandth of a millimetre; the thinnest fabrics are 0.05 mm")?;
        at_least("shear_modulus", self.shear_modulus, MIN_MODULUS, "N/m", "the softest fabrics shear with about 10 N/m")?;
        for (key, value) in [("bending_warp", self.bending_warp), ("bending_weft", self.bending_weft)] {
            at_least(key, value, MIN_RIGIDITY, "N·m", "the softest fabrics bend with about 5e-7 N·m")?;
        }
        for (key, curve) in [("tensile_warp", &self.tensile_warp), ("tensile_weft", &self.tensile_weft)] {
            at_least(key, curve.max_slope(), MIN_MODULUS, "N/m, its steepest segment", "fabrics stretch with hundreds of N/m or more")?;
        }
        if !(0.0..0.5).contains(&self.poisson_warp) {
            return Err(FabricError::OutOfRange {
                key: "poisson_warp",
                expected: "in [0, 0.5)",
                value: self.poisson_warp,
            });
        }
        if let Some(bias) = self.bending_bias {
            in_range("bending_bias", bias, MAX_RIGIDITY)?;
        }
        curve_in_range("tensile_warp", &self.tensile_warp, MAX_MODULUS)?;
        curve_in_range("tensile_weft", &self.tensile_weft, MAX_MODULUS)?;
        if let Some(curve) = &self.bending_curve {
            curve_in_range("bending_curve", curve, MAX_RIGIDITY)?;
        }
        MembraneLaw::new(self)?;
        BendingStiffness::new(self)?;
        Ok(())
    }

    /// Sub-element buckling for elements of edge length `edge`, m: compressive stress along
    /// the warp and the weft is capped at the Euler load of one element, π²B/ℓ², beyond which
    /// it grows at 1 % of the initial tensile slope. A triangle stands for cloth that would
    /// have buckled within it; without the cap coarse meshes lock in folds. A curve with
    /// compression points of its own is kept as it is.
    pub fn with_compression_buckling(&self, edge: f64) -> Result<Fabric, FabricError> {
        let branch = |key: &'static str, curve: &PiecewiseLinear, rigidity: f64| {
            let mut points: Vec<[f64; 2]> = curve.points().collect();
            // A material curve passes through the origin: its first point is the origin
            // unless it has points in compression.
            if points[0][0] < 0.0 {
                return Ok(curve.clone());
            }
            let slope = points[1][1] / points[1][0];
            let critical = std::f64::consts::PI.powi(2) * rigidity / (edge * edge);
            let knee = critical / slope;
            // Far enough that no cloth gets there: half its length.
            let far = 0.5f64.max(2.0 * knee);
            points.insert(0, [-knee, -critical]);
            points.insert(0, [-far, -critical - 0.01 * slope * (far - knee)]);
            PiecewiseLinear::new_material(&points).map_err(|source| FabricError::Curve { key, source })
        };
        let fabric = Fabric {
            tensile_warp: branch("tensile_warp", &self.tensile_warp, self.bending_warp)?,
            tensile_weft: branch("tensile_weft", &self.tensile_weft, self.bending_weft)?,
            ..self.clone()
        };
        fabric.validate()?;
        Ok(fabric)
    }
}

/// The in-plane strain energy density ψ(ε_xx, ε_yy, γ_xy), J/m², of an orthotropic sheet with
/// nonlinear warp and weft curves and a linear Poisson coupling and shear.
///
/// ```text
/// ψ = F_x(ε_xx) + F_y(ε_yy) + (νν / 2D)(E_x ε_xx² + E_y ε_yy²) + (ν_yx E_x / D) ε_xx ε_yy + ½ G γ²
/// ```
/// with `F' = f` the measured curves, `E` their small-strain slopes, `νν = ν_xy ν_yx` and
/// `D = 1 − νν`. For linear curves this is exactly the plane-stress energy of paper eq. 1.
/// For nonlinear curves the quadratic correction makes a uniaxial pull reproduce the
/// measured curve exactly (σ_yy = 0 gives ε_yy = −ν_xy ε_xx and σ_xx = f_x(ε_xx)) as long as
/// the lateral strain stays on the curves' first segment, which holds by default because
/// compression continues the first tensile slope (see `curve`). A naive "secant modulus in
/// eq. 1" would not be the gradient of any energy, and a plain separable energy would miss
/// the measured curve by a factor of about ν_xy ν_yx of its nonlinear part.
#[derive(Debug, Clone)]
pub struct MembraneLaw {
    warp: PiecewiseLinear,
    weft: PiecewiseLinear,
    /// Quadratic correction stiffnesses νν E_x / D and νν E_y / D, N/m.
    correction_x: f64,
    correction_y: f64,
    /// Coupling stiffness ν_yx E_x / D = ν_xy E_y / D, N/m.
    coupling: f64,
    shear: f64,
}

impl MembraneLaw {
    pub fn new(fabric: &Fabric) -> Result<Self, FabricError> {
        let warp = fabric.tensile_warp.clone();
        let weft = fabric.tensile_weft.clone();
        let (ex, ey) = (warp.initial_slope(), weft.initial_slope());
        let nu_xy = fabric.poisson_warp;
        let nu_yx = nu_xy * ey / ex;
        let nunu = nu_xy * nu_yx;
        let d = 1.0 - nunu;
        let law = Self {
            correction_x: nunu * ex / d,
            correction_y: nunu * ey / d,
            coupling: nu_yx * ex / d,
            shear: fabric.shear_modulus,
            warp,
            weft,
        };
        // Convexity needs the 2×2 normal block of the tangent to stay positive definite on
        // the softest segments: (s_x + c_x)(s_y + c_y) > coupling².
        let softest = (law.warp.min_slope() + law.correction_x) * (law.weft.min_slope() + law.correction_y);
        if softest <= law.coupling * law.coupling * 1.0001 {
            // The largest ν_xy that keeps the softest combination convex, by bisection.
            let (mut lo, mut hi) = (0.0, nu_xy);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                let mut trial = fabric.clone();
                trial.poisson_warp = mid;
                let ok = {
                    let nyx = mid * ey / ex;
                    let nn = mid * nyx;
                    let dd = 1.0 - nn;
                    let s = (law.warp.min_slope() + nn * ex / dd) * (law.weft.min_slope() + nn * ey / dd);
                    s > (nyx * ex / dd).powi(2) * 1.0001
                };
                if ok { lo = mid } else { hi = mid }
            }
            return Err(FabricError::PoissonTooLarge { nu: nu_xy, limit: lo });
        }
        Ok(law)
    }

    /// Energy density ψ, J/m², at strain `[ε_xx, ε_yy, γ_xy]`.
    pub fn energy(&self, e: [f64; 3]) -> f64 {
        self.warp.integral(e[0])
            + self.weft.integral(e[1])
            + 0.5 * (self.correction_x * e[0] * e[0] + self.correction_y * e[1] * e[1])
            + self.coupling * e[0] * e[1]
            + 0.5 * self.shear * e[2] * e[2]
    }

    /// `(energy(e), stress(e))`, each curve searched once.
    pub fn energy_and_stress(&self, e: [f64; 3]) -> (f64, [f64; 3]) {
        let ((ix, fx), (iy, fy)) = (self.warp.integral_and_value(e[0]), self.weft.integral_and_value(e[1]));
        let energy = ix
            + iy
            + 0.5 * (self.correction_x * e[0] * e[0] + self.correction_y * e[1] * e[1])
            + self.coupling * e[0] * e[1]
            + 0.5 * self.shear * e[2] * e[2];
        let stress = [fx + self.correction_x * e[0] + self.coupling * e[1], fy + self.correction_y * e[1] + self.coupling * e[0], self.shear * e[2]];
        (energy, stress)
    }

    /// Stress `[σ_xx, σ_yy, τ_xy]` = ∂ψ/∂ε, N/m.
    pub fn stress(&self, e: [f64; 3]) -> [f64; 3] {
        [
            self.warp.value(e[0]) + self.correction_x * e[0] + self.coupling * e[1],
            self.weft.value(e[1]) + self.correction_y * e[1] + self.coupling * e[0],
            self.shear * e[2],
        ]
    }

    /// Tangent stiffness ∂σ/∂ε, N/m (symmetric, positive definite).
    pub fn tangent(&self, e: [f64; 3]) -> [[f64; 3]; 3] {
        [
            [self.warp.slope(e[0]) + self.correction_x, self.coupling, 0.0],
            [self.coupling, self.weft.slope(e[1]) + self.correction_y, 0.0],
            [0.0, 0.0, self.shear],
        ]
    }

    /// `(stress(e), tangent(e))`, each curve searched once.
    pub fn stress_and_tangent(&self, e: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let ((fx, sx), (fy, sy)) = (self.warp.value_and_slope(e[0]), self.weft.value_and_slope(e[1]));
        let stress = [fx + self.correction_x * e[0] + self.coupling * e[1], fy + self.correction_y * e[1] + self.coupling * e[0], self.shear * e[2]];
        let tangent = [[sx + self.correction_x, self.coupling, 0.0], [self.coupling, sy + self.correction_y, 0.0], [0.0, 0.0, self.shear]];
        (stress, tangent)
    }

    /// Largest tangent stiffness the law can reach, N/m (bounds explicit time steps).
    pub fn max_stiffness(&self) -> f64 {
        (self.warp.max_slope() + self.correction_x).max(self.weft.max_slope() + self.correction_y) + self.coupling
    }
}

/// Orthotropic plate bending stiffness in the warp frame, N·m:
/// ψ_b = ½ (D11 κ_xx² + 2 D12 κ_xx κ_yy + D22 κ_yy² + 4 D66 κ_xy²).
///
/// For a cylindrical bend of curvature κ in direction θ from the warp, ψ_b = ½ B_θ κ² with
/// B_θ = D11 cos⁴θ + (2 D12 + 4 D66) cos²θ sin²θ + D22 sin⁴θ: paper eq. 3 with D11 = B_x,
/// D22 = B_y, D12 = ν_xy B_x and D66 = G h³/12 (G in Pa, i.e. the sheet modulus over h).
/// A measured bias rigidity B_45 fixes the middle term instead: 2 D12 + 4 D66 = 4 B_45 − B_x − B_y.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendingStiffness {
    pub d11: f64,
    pub d12: f64,
    pub d22: f64,
    pub d66: f64,
}

impl BendingStiffness {
    pub fn new(fabric: &Fabric) -> Result<Self, FabricError> {
        let (bx, by) = (fabric.bending_warp, fabric.bending_weft);
        let poisson_term = fabric.poisson_warp * bx;
        // G h³/12 with G in Pa = (sheet modulus / h) · h³ / 12.
        let twist_paper = fabric.shear_modulus * fabric.thickness * fabric.thickness / 12.0;
        match fabric.bending_bias {
            None => Ok(Self { d11: bx, d12: poisson_term, d22: by, d66: twist_paper }),
            Some(bias) if 4.0 * bias - bx - by <= 0.0 => {
                Err(FabricError::BiasTooSmall { bias, warp: bx, weft: by, min: (bx + by) / 4.0 * 1.001 })
            }
            Some(bias) => Ok(Self::with_bias_rigidity(bx, by, fabric.poisson_warp, bias)),
        }
    }

    /// Eq. 3 with a measured bias rigidity `bias` (N·m) in place of the paper's middle term
    /// (docs/references.md §1): 2 D12 + 4 D66 = 4 B_45 − B_x − B_y, split so that D12 keeps
    /// the Poisson coupling ν_xy·B_x where the term allows it and the rest is twist, D66.
    /// The term must be positive; [`BendingStiffness::new`] refuses a `bias` that makes it
    /// not ([`FabricError::BiasTooSmall`]), and other callers keep `bias` above (B_x + B_y)/4.
    pub fn with_bias_rigidity(bending_warp: f64, bending_weft: f64, poisson_warp: f64, bias: f64) -> Self {
        let (bx, by) = (bending_warp, bending_weft);
        let middle = 4.0 * bias - bx - by;
        let d12 = (poisson_warp * bx).min(0.25 * middle);
        Self { d11: bx, d12, d22: by, d66: 0.25 * (middle - 2.0 * d12) }
    }

    /// Isotropic stiffness with rigidity `b` in every direction (D12 + 2 D66 = b, no Poisson coupling).
    pub fn isotropic(b: f64) -> Self {
        Self { d11: b, d12: 0.0, d22: b, d66: 0.5 * b }
    }

    /// Rigidity for cylindrical bending at angle `theta` (radians) from the warp, N·m (eq. 3).
    pub fn rigidity_at(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        self.d11 * c.powi(4) + (2.0 * self.d12 + 4.0 * self.d66) * c * c * s * s + self.d22 * s.powi(4)
    }

    /// The matrix 𝔻 acting on `[κ_xx, κ_yy, κ_xy]` so that ψ_b = ½ κᵀ𝔻κ.
    pub fn voigt(&self) -> [[f64; 3]; 3] {
        [[self.d11, self.d12, 0.0], [self.d12, self.d22, 0.0], [0.0, 0.0, 4.0 * self.d66]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wool_like(poisson: f64) -> Fabric {
        Fabric {
            areal_density: 0.137,
            thickness: 3.14e-4,
            tensile_warp: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.005, 5.0], [0.015, 20.0], [0.035, 98.0], [0.06, 490.5]])
                .unwrap(),
            tensile_weft: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 8.0], [0.04, 80.0]]).unwrap(),
            shear_modulus: 40.0,
            poisson_warp: poisson,
            bending_warp: 1e-5,
            bending_weft: 8e-6,
            bending_bias: None,
            bending_curve: None,
        }
    }

    /// Solves σ_yy(ε_xx, ε_yy) = 0 for ε_yy by Newton's method (a uniaxial warp pull).
    fn lateral_strain(law: &MembraneLaw, exx: f64) -> f64 {
        let mut eyy = 0.0;
        for _ in 0..50 {
            let s = law.stress([exx, eyy, 0.0])[1];
            eyy -= s / law.tangent([exx, eyy, 0.0])[1][1];
        }
        eyy
    }

    #[test]
    fn uniaxial_pull_reproduces_the_measured_curve_with_poisson_coupling() {
        let fabric = wool_like(0.3);
        let law = MembraneLaw::new(&fabric).unwrap();
        let nu_xy = 0.3;
        for i in 1..=40 {
            let exx = 0.0015 * i as f64;
            let eyy = lateral_strain(&law, exx);
            let sxx = law.stress([exx, eyy, 0.0])[0];
            let measured = fabric.tensile_warp.value(exx);
            assert!((sxx - measured).abs() < 1e-9 * measured, "ε={exx}: {sxx} vs {measured}");
            assert!((eyy + nu_xy * exx).abs() < 1e-12, "lateral contraction is ν_xy ε");
        }
    }

    #[test]
    fn linear_law_is_plane_stress_eq1() {
        let mut fabric = wool_like(0.2);
        fabric.tensile_warp = PiecewiseLinear::linear(1000.0);
        fabric.tensile_weft = PiecewiseLinear::linear(500.0);
        let law = MembraneLaw::new(&fabric).unwrap();
        let (ex, ey, nxy) = (1000.0, 500.0, 0.2);
        let nyx = nxy * ey / ex;
        let d = 1.0 - nxy * nyx;
        let e = [0.01, -0.004, 0.02];
        let s = law.stress(e);
        assert!((s[0] - ex / d * (e[0] + nyx * e[1])).abs() < 1e-12);
        assert!((s[1] - ey / d * (nxy * e[0] + e[1])).abs() < 1e-12);
        assert!((s[2] - 40.0 * e[2]).abs() < 1e-12);
    }

    #[test]
    fn stress_is_the_gradient_of_energy() {
        let law = MembraneLaw::new(&wool_like(0.25)).unwrap();
        let e = [0.021, -0.007, 0.013];
        let s = law.stress(e);
        for k in 0..3 {
            let mut ep = e;
            let mut em = e;
            ep[k] += 1e-7;
            em[k] -= 1e-7;
            let numeric = (law.energy(ep) - law.energy(em)) / 2e-7;
            assert!((numeric - s[k]).abs() < 1e-5 * (1.0 + s[k].abs()), "component {k}");
        }
        // The combined evaluation is the same law.
        for e in [e, [-0.004, 0.031, -0.02], [0.0, 0.0, 0.0], [0.09, -0.05, 0.2]] {
            assert_eq!(law.stress_and_tangent(e), (law.stress(e), law.tangent(e)));
        }
    }

    #[test]
    fn too_large_poisson_ratio_is_rejected_with_a_limit() {
        let mut fabric = wool_like(0.49);
        // A very soft compression branch makes the coupling dominate.
        fabric.tensile_weft = PiecewiseLinear::new_material(&[[-0.01, -0.01], [0.0, 0.0], [0.01, 100.0]]).unwrap();
        let err = MembraneLaw::new(&fabric).unwrap_err();
        match err {
            FabricError::PoissonTooLarge { limit, .. } => assert!(limit > 0.0 && limit < 0.49),
            other => panic!("unexpected {other:?}"),
        }
    }

    #[test]
    fn eq3_directional_rigidity() {
        let fabric = wool_like(0.2);
        let d = BendingStiffness::new(&fabric).unwrap();
        assert_eq!(d.rigidity_at(0.0), 1e-5);
        assert!((d.rigidity_at(std::f64::consts::FRAC_PI_2) - 8e-6).abs() < 1e-18);
        let g_pa = 40.0 / 3.14e-4;
        let middle = 2.0 * 0.2 * 1e-5 + 4.0 * g_pa * 3.14e-4f64.powi(3) / 12.0;
        let expected45 = 0.25 * (1e-5 + middle + 8e-6);
        assert!((d.rigidity_at(std::f64::consts::FRAC_PI_4) - expected45).abs() < 1e-15);
        let mut with_bias = fabric.clone();
        with_bias.bending_bias = Some(6e-6);
        let d = BendingStiffness::new(&with_bias).unwrap();
        assert!((d.rigidity_at(std::f64::consts::FRAC_PI_4) - 6e-6).abs() < 1e-18);
        with_bias.bending_bias = Some(1e-6);
        assert!(matches!(BendingStiffness::new(&with_bias), Err(FabricError::BiasTooSmall { .. })));
    }

    #[test]
    fn bad_values_name_their_key() {
        let mut fabric = wool_like(0.2);
        fabric.areal_density = -0.1;
        let msg = fabric.validate().unwrap_err().to_string();
        assert!(msg.contains("fabric.areal_density") && msg.contains("-0.1"), "{msg}");
        let mut fabric = wool_like(0.7);
        fabric.areal_density = 0.1;
        assert!(fabric.validate().unwrap_err().to_string().contains("poisson_warp"));
    }
}
