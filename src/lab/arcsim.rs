//! The ARCSim round trip: a fabric imported from an ARCSim material, run through the
//! virtual laboratory, set beside the file's own values, ARCSim's model evaluated as its
//! source defines it (crate::fabric::arcsim::model).
//!
//! Held, within the tolerances of the sheets' round trip (tensile 3 %, bending 2 %, shear
//! 5 %): the warp and weft pulls at 2 %, 8.3 % and the strain sample 16.7 %; the bias
//! modulus of the zero-strain samples, read at 0.5 % on a long strip; each direction's
//! rigidity (the first sample over 4, read at 0.1 m⁻¹); the warp's moments at the sampled
//! curvatures 10–40 m⁻¹, up to where ARCSim's moment falls and Rosette's curve is held
//! rising instead; the shear modulus. A bend is held only where Rosette's free strip cannot
//! relax by more than the tolerance through its bending coupling ([`free_strip_relaxation`]).
//! Reported, not held: what the projection drops, the bias at strain (ARCSim's 45° strained
//! row weighs in from the first strain), the weft's and the bias's moments at 10–40 m⁻¹
//! (their own curvature samples) and ARCSim's own KES shear slope (its shear stiffens with
//! strain).

use super::report::{Property, ReadBack};
use super::{Direction, LabError, Strip, bend_to, load_at, shear, strain_pull};
use crate::fabric::arcsim::ArcsimMaterial;
use crate::fabric::arcsim::model::{BIAS_ROW, HINGE_FACTOR, STRAIN_SAMPLE, WARP_ROW, WEFT_ROW, moment, sample_curvatures, stiffness, uniaxial};
use crate::fabric::arcsim::project::{MAX_POISSON, warp_bending_curve, zero_strain_plate};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use crate::settings::FabricConfig;

/// Strains the axis pulls are read at: small, between the samples, the strain sample.
pub const PULL_STRAINS: [f64; 3] = [0.02, STRAIN_SAMPLE / 2.0, STRAIN_SAMPLE];
/// The strain the bias modulus is read at on Rosette's strip (its curves are straight to a
/// fraction of a per cent there).
pub const BIAS_MODULUS_STRAIN: f64 = 0.005;
/// The curvature each direction's rigidity is read at, 1/m: ARCSim's samples change its
/// secant by 1/100 of the step to the next sample there, under 1 % for the ten materials.
pub const SMALL_CURVATURE: f64 = 0.1;
pub const TENSILE_TOLERANCE: f64 = 0.03;
pub const BENDING_TOLERANCE: f64 = 0.02;
pub const SHEAR_TOLERANCE: f64 = 0.05;
/// KES-FB1's shear angles, degrees.
const SHEAR_ANGLES: [f64; 2] = [0.5, 5.0];

/// ARCSim's KES shear slope, N/m per radian: (τ(5°) − τ(0.5°))/4.5°, τ(γ) the shear stress
/// of a tensor shear γ/2, K₃ read at the principal stretch √(1 + γ) along 45°.
pub fn kes_shear_slope(m: &ArcsimMaterial) -> f64 {
    let tau = |deg: f64| {
        let gamma = deg.to_radians();
        stiffness(m, (1.0 + gamma).sqrt(), FRAC_PI_4)[3] * 0.5 * gamma
    };
    let [lo, hi] = SHEAR_ANGLES;
    (tau(hi) - tau(lo)) / (hi - lo).to_radians()
}

/// Which values [`readback`] reads: all, or only those it holds (cheaper: the bias pull to
/// 1 % instead of 20 %, no bends of the weft and bias beyond their rigidity).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    All,
    Held,
}

/// The relaxation of a free strip cut at `angle` (radians from the warp) of `fabric`:
/// D′₁₂²/(D′₁₁·D′₂₂) of its bending tensor turned to the strip. A narrow strip free to curl
/// across loses up to this share of its plate rigidity (docs/fabric-sheets.md, Bias);
/// ARCSim's hinges have no such coupling, and Rosette's has D₁₂ = ν·B_x (paper eq. 3).
pub fn free_strip_relaxation(fabric: &crate::sim::Fabric, angle: f64) -> f64 {
    let Ok(d) = crate::sim::BendingStiffness::new(fabric) else { return f64::NAN };
    let (s, c) = angle.sin_cos();
    let coupling = (d.d11 + d.d22 - 4.0 * d.d66) * c * c * s * s + d.d12 * (c.powi(4) + s.powi(4));
    coupling * coupling / (d.rigidity_at(angle) * d.rigidity_at(angle + std::f64::consts::FRAC_PI_2))
}

/// Runs the pulls, bends and shear on `fabric` (imported from `m`) and sets each reading
/// beside ARCSim's value; `scope` says whether the values the projection drops are read.
pub fn readback(m: &ArcsimMaterial, fabric: &FabricConfig, scope: Scope) -> Result<ReadBack, LabError> {
    const DROPS: &str = "the projection drops it";
    let all = scope == Scope::All;
    let material = fabric.to_fabric().map_err(|e| LabError::Setup { test: "ARCSim readback", message: e.to_string() })?;
    let mut out = ReadBack::default();
    let mut push = |field: String, unit: &'static str, sheet: f64, measured: f64, test: &'static str, tolerance: f64, unheld: Option<String>| {
        out.properties.push(Property { field, unit, sheet, measured, test, tolerance, unheld });
    };
    let reading = |curve: &[[f64; 2]], strain: f64| {
        load_at(curve, strain).ok_or_else(|| LabError::NoReading { test: "strain pull", message: format!("the pull did not reach {:.1} %", 100.0 * strain) })
    };
    for (d, angle) in [(Direction::Warp, 0.0), (Direction::Weft, FRAC_PI_2)] {
        let curve = strain_pull(fabric, d, 1.2 * STRAIN_SAMPLE, Strip::RIG)?;
        for strain in PULL_STRAINS {
            let field = format!("{} pull {:.1} %", d.name(), 100.0 * strain);
            push(field, "N/m", uniaxial(m, angle, strain), reading(&curve, strain)?, "strain pull", TENSILE_TOLERANCE, None);
        }
    }
    let bias = strain_pull(fabric, Direction::Bias, if all { 1.2 * STRAIN_SAMPLE } else { 2.0 * BIAS_MODULUS_STRAIN }, Strip::LONG)?;
    let e = BIAS_MODULUS_STRAIN;
    let (eu, ev, g, nu) = zero_strain_plate(m);
    let e45 = crate::reference::off_axis_modulus(eu, ev, g, nu.min(MAX_POISSON), FRAC_PI_4);
    let secant = reading(&bias, e)? / e;
    push("bias modulus".into(), "N/m", e45, secant, "long strip pull", TENSILE_TOLERANCE, None);
    if all {
        // ARCSim's strained rows weigh in from the first strain: w = 6·(λ₁ − 1).
        push(format!("bias secant {:.1} %", 100.0 * e), "N/m", uniaxial(m, FRAC_PI_4, e) / e, secant, "long strip pull", TENSILE_TOLERANCE, Some(DROPS.into()));
        for strain in &PULL_STRAINS[1..] {
            let field = format!("bias pull {:.1} %", 100.0 * strain);
            push(field, "N/m", uniaxial(m, FRAC_PI_4, *strain), reading(&bias, *strain)?, "long strip pull", TENSILE_TOLERANCE, Some(DROPS.into()));
        }
    }
    let held_curve = warp_bending_curve(m).and_then(|(_, held)| held);
    for (d, row) in [(Direction::Warp, WARP_ROW), (Direction::Weft, WEFT_ROW), (Direction::Bias, BIAS_ROW)] {
        let relaxation = free_strip_relaxation(&material, d.warp_angle_deg().to_radians());
        let relaxes = (relaxation > BENDING_TOLERANCE).then(|| {
            format!("Rosette's free strip may relax up to {:.1} % through its bending coupling D'12 (eq. 3); ARCSim's hinges have none", 100.0 * relaxation)
        });
        let (k, moment_read) = bend_to(fabric, d, SMALL_CURVATURE)?;
        push(format!("{} rigidity", d.name()), "µN·m", 1e6 * HINGE_FACTOR * m.bending[row][0], 1e6 * moment_read / k, "pure bending", BENDING_TOLERANCE, relaxes.clone());
        for kappa in sample_curvatures().into_iter().skip(1) {
            let in_warp_curve = d == Direction::Warp && held_curve.is_none_or(|(a, _)| kappa <= a);
            let unheld = match (in_warp_curve, &relaxes) {
                (true, None) => None,
                (true, Some(why)) => Some(why.clone()),
                (false, _) => Some(DROPS.to_string()),
            };
            if unheld.is_some() && !all {
                continue;
            }
            let (k, moment_read) = bend_to(fabric, d, kappa)?;
            let field = format!("{} moment {kappa:.0}/m", d.name());
            push(field, "µN·m/m", 1e6 * moment(m, row, k), 1e6 * moment_read, "pure bending", BENDING_TOLERANCE, unheld);
        }
    }
    let s = shear(fabric)?;
    push("shear modulus".into(), "N/m", m.stretching[0][3], s.modulus, "shear", SHEAR_TOLERANCE, None);
    if all {
        push("KES shear slope".into(), "N/m", kes_shear_slope(m), s.modulus, "shear", SHEAR_TOLERANCE, Some(DROPS.into()));
    }
    Ok(out)
}
