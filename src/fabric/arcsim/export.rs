//! From a Rosette fabric to an ARCSim material (`rosette fabric export --arcsim`).
//!
//! The inverse of the projection in [`super::project`] on what both models hold:
//!
//! - row 0 is the fabric's zero-strain plate (C11 = E_x/D, C12 = ν_yx·E_x/D, C22 = E_y/D,
//!   D = 1 − ν_xy·ν_yx, the moduli the tensile curves' first segments) halved, with
//!   c33 = G;
//! - rows 1 and 5 keep row 0's coupling and cross stiffness (Rosette's Poisson ratio and
//!   lateral stiffness do not change with the strain) and take c11 (row 1) or c22 (row 5)
//!   so that ARCSim's pull at the strain sample (1/6) loads as the fabric's curve does;
//! - rows 2–4 blend rows 1 and 5 linearly in the angle, so that ARCSim's strained
//!   stiffness turns from the warp's to the weft's as the principal direction does;
//! - bending rows 2, 0 and 1 are the warp's, the weft's and the bias's secant rigidities
//!   M(κ)/κ at 0–40 m⁻¹, times 4, with M(κ) the fabric's moment in that direction.
//!
//! Exporting a fabric, importing it and exporting again writes the same file; see
//! docs/fabric-sheets.md for what a fabric's curves lose between the samples.

use super::material::{ArcsimMaterial, BENDING_COLUMNS};
use crate::appearance::Appearance;
use super::model::{BIAS_ROW, HINGE_FACTOR, STRAIN_SAMPLE, WARP_ROW, WEFT_ROW, sample_curvatures};
use crate::sim::{BendingStiffness, Fabric, FabricError};
use std::f64::consts::FRAC_PI_4;

/// The ARCSim material of a fabric.
pub fn export(fabric: &Fabric) -> Result<ArcsimMaterial, FabricError> {
    fabric.validate()?;
    let (ex, ey) = (fabric.tensile_warp.initial_slope(), fabric.tensile_weft.initial_slope());
    let nu_xy = fabric.poisson_warp;
    let nu_yx = nu_xy * ey / ex;
    let d = 1.0 - nu_xy * nu_yx;
    let (k0, k1, k2) = (ex / d, nu_yx * ex / d, ey / d);
    let g = fabric.shear_modulus;
    let row0 = [0.5 * k0, 0.5 * k1, 0.5 * k2, g];
    // ARCSim's pull at the strain sample: load = λ·E₁·G_NN, E₁ = K₀ − K₁²/K₂ (warp).
    let stretch = 1.0 + STRAIN_SAMPLE;
    let green = 0.5 * (stretch * stretch - 1.0);
    let secant = |curve: &crate::sim::PiecewiseLinear| curve.value(STRAIN_SAMPLE) / (stretch * green);
    let row1 = [0.5 * (secant(&fabric.tensile_warp) + k1 * k1 / k2), row0[1], row0[2], g];
    let row5 = [row0[0], row0[1], 0.5 * (secant(&fabric.tensile_weft) + k1 * k1 / k0), g];
    let mut stretching = [row0; 6];
    for (i, row) in stretching.iter_mut().enumerate().skip(1) {
        let t = (i - 1) as f64 / 4.0;
        *row = std::array::from_fn(|k| (1.0 - t) * row1[k] + t * row5[k]);
    }
    stretching[1] = row1;
    stretching[5] = row5;
    let stiffness = BendingStiffness::new(fabric)?;
    let mut bending = [[0.0; BENDING_COLUMNS]; 3];
    let directions = [(WARP_ROW, fabric.bending_warp), (WEFT_ROW, fabric.bending_weft), (BIAS_ROW, stiffness.rigidity_at(FRAC_PI_4))];
    for (row, rigidity) in directions {
        for (j, kappa) in sample_curvatures().into_iter().enumerate() {
            bending[row][j] = secant_rigidity(fabric, rigidity, kappa) / HINGE_FACTOR;
        }
    }
    Ok(ArcsimMaterial { density: fabric.areal_density, stretching, bending })
}

/// M(κ)/κ of a cylindrical bend of rigidity `rigidity` at curvature `kappa` (the rigidity
/// itself at κ = 0). With a moment–curvature curve, Rosette evaluates the curve's secant
/// factor at the warp curvature storing the same linear energy, κ·√(B/B_x)
/// (`Model::bending_energy`).
pub fn secant_rigidity(fabric: &Fabric, rigidity: f64, kappa: f64) -> f64 {
    match &fabric.bending_curve {
        Some(curve) if kappa > 0.0 => {
            let equivalent = kappa * (rigidity / fabric.bending_warp).sqrt();
            rigidity * curve.value(equivalent) / (curve.initial_slope() * equivalent)
        }
        _ => rigidity,
    }
}

/// The material as ARCSim's JSON, with `//` comments (which ARCSim's reader, jsoncpp,
/// accepts, as in its own `aluminium.json`) saying where it came from. Numbers to ten
/// significant figures.
pub fn to_json(m: &ArcsimMaterial, comments: &[String]) -> String {
    to_json_with_look(m, comments, &Appearance::default())
}

/// [`to_json`] with the fabric's look as an `"appearance"` object beside the tables (left
/// out when the fabric has none): ARCSim reads the keys it knows and passes over the rest,
/// and Rosette reads it back as the fabric's `[appearance]`.
pub fn to_json_with_look(m: &ArcsimMaterial, comments: &[String], appearance: &Appearance) -> String {
    let number = |v: f64| {
        let v: f64 = format!("{v:.9e}").parse().expect("a formatted float parses");
        format!("{v:?}")
    };
    let rows = |rows: &[&[f64]]| rows.iter().map(|r| format!("        [{}]", r.iter().map(|&v| number(v)).collect::<Vec<_>>().join(", "))).collect::<Vec<_>>().join(",\n");
    let stretching: Vec<&[f64]> = m.stretching.iter().map(|r| r.as_slice()).collect();
    let bending: Vec<&[f64]> = m.bending.iter().map(|r| r.as_slice()).collect();
    let mut out = String::new();
    for c in comments {
        out += &format!("// {c}\n");
    }
    let look = if appearance.is_empty() {
        String::new()
    } else {
        let json = serde_json::to_string(appearance).expect("an appearance serialises");
        format!(",\n    \"appearance\": {json}")
    };
    out += &format!(
        "{{\n    \"density\": {},\n    \"stretching\": [\n{}\n    ],\n    \"bending\": [\n{}\n    ]{look}\n}}\n",
        number(m.density),
        rows(&stretching),
        rows(&bending)
    );
    out
}
