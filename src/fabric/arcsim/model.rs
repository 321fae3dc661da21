//! ARCSim's data-driven cloth model, evaluated as ARCSim's source defines it: the strain
//! measure, the interpolation of the stretching samples over strain and direction, their
//! doubling, the bending samples' lookup by hinge direction and curvature, and the hinge's
//! moment. docs/fabric-sheets.md (ARCSim materials) derives each step from the source lines
//! quoted there.
//!
//! Directions are angles from the material's u axis, which Rosette reads as the warp.

use super::material::ArcsimMaterial;
use std::f64::consts::FRAC_PI_2;

/// The strain sample of the strained rows: they apply fully once the largest principal
/// stretch reaches 1 + 1/6 (dde.cpp: `strain_value = (w[0] - 1)*6`, clamped to [0, 1]).
pub const STRAIN_SAMPLE: f64 = 1.0 / 6.0;
/// ARCSim doubles the interpolated stretching samples (dde.cpp: `real_elastic[i] *= 2`).
pub const STRETCH_DOUBLING: f64 = 2.0;
/// Curvature between bending samples, 1/m, for a uniform bend read on the strip's own
/// mesh: the lookup `value = alpha*0.2` with `alpha = curv/2` and `curv = θ·l/(A₀+A₁)`,
/// which is the curvature itself across such a strip (docs/fabric-sheets.md).
pub const CURVATURE_STEP: f64 = 10.0;
/// The rigidity per unit bending sample of a strip bent uniformly on its own mesh: the
/// hinge energy `ke·l²/(2(A₀+A₁))·θ²/4` sums to ½·(ke/4)·κ² per area.
pub const HINGE_FACTOR: f64 = 0.25;
/// The bending row for each Rosette direction: a bend along the warp (curvature along u)
/// folds the hinges whose edges lie across it, along v (row 2); along the weft, row 0; on
/// the bias, the 45° row.
pub const WARP_ROW: usize = 2;
pub const WEFT_ROW: usize = 0;
pub const BIAS_ROW: usize = 1;

/// ARCSim's stiffness [K₀, K₁, K₂, K₃] (N/m) for a state whose largest principal stretch
/// is `stretch` with its direction at `angle` (radians, folded into [0, π/2]): the zero-
/// strain row blended with the strained rows (interpolated over the angle in 22.5° steps)
/// by the weight 6·(stretch − 1) clamped to [0, 1]; each component clamped at zero, then
/// doubled (dde.cpp, `evaluate_stretching_sample`).
///
/// ARCSim clamps its weights just below 1 and 4 (`1-1e-6`, `4-1e-6`) so that its indices
/// stay in range; the blend here is exact at the ends, which moves a value by at most
/// 1e-6 of the difference between two rows.
pub fn stiffness(m: &ArcsimMaterial, stretch: f64, angle: f64) -> [f64; 4] {
    let strain_weight = ((stretch - 1.0) / STRAIN_SAMPLE).clamp(0.0, 1.0);
    let position = (angle.abs().min(FRAC_PI_2) / (FRAC_PI_2 / 4.0)).clamp(0.0, 4.0);
    let row = (position.floor() as usize).min(3);
    let a = position - row as f64;
    std::array::from_fn(|k| {
        let strained = (1.0 - a) * m.stretching[1 + row][k] + a * m.stretching[2 + row][k];
        let blended = (1.0 - strain_weight) * m.stretching[0][k] + strain_weight * strained;
        STRETCH_DOUBLING * blended.max(0.0)
    })
}

/// The largest principal stretch of a Green strain `[G₀₀, G₁₁, G₀₁]` (tensor shear) and the
/// angle of its direction folded into [0, π/2], as ARCSim's 2×2 eigen decomposition gives
/// them (vectors.cpp, `eigen_decomposition<2>`: C = 2G + I, the eigenvector (l₁ − C₁₁, C₀₁);
/// `fabsf(atan2f(...))` in dde.cpp folds its sign; with C₀₁ = 0 the larger diagonal wins,
/// u on a tie).
pub fn principal(g: [f64; 3]) -> (f64, f64) {
    let (a, d, b) = (1.0 + 2.0 * g[0], 1.0 + 2.0 * g[1], 2.0 * g[2]);
    let l1 = 0.5 * (a + d + (4.0 * b * b + (a - d) * (a - d)).sqrt());
    // (l₁ − C₁₁, C₀₁) and (C₀₁, l₁ − C₀₀) are the same direction; the second is free of
    // cancellation where C₁₁ is the larger diagonal, so that a state a rounding error off
    // the v axis reads 90°, not any angle at all.
    let angle = match (b != 0.0, a >= d) {
        (true, true) => b.abs().atan2(l1 - d),
        (true, false) => (l1 - a).atan2(b.abs()),
        (false, true) => 0.0,
        (false, false) => FRAC_PI_2,
    };
    (l1.max(0.0).sqrt(), angle)
}

/// ARCSim's second Piola–Kirchhoff stress `[S₀₀, S₁₁, S₀₁]` (N/m) at Green strain `g`:
/// S = K(g)·g with K of the state itself, the secant law its forces use (physics.cpp,
/// `stretching_force`: grad = k0·G00·fuu + k2·G11·fvv + k1·(G00·fvv + G11·fuu) +
/// 2·k3·G01·fuv, the gradient of ½k0G00² + k1G00G11 + ½k2G11² + k3G01² at fixed k).
pub fn stress(m: &ArcsimMaterial, g: [f64; 3]) -> [f64; 3] {
    let (stretch, angle) = principal(g);
    let k = stiffness(m, stretch, angle);
    [k[0] * g[0] + k[1] * g[1], k[1] * g[0] + k[2] * g[1], k[3] * g[2]]
}

/// A uniaxial pull of a strip cut at `angle` (radians from u) to engineering strain
/// `strain` along it, its long edges free: the load per unit (unstretched) width, N/m, as
/// a tensile tester reads it.
///
/// Free edges carry no traction, so the stress is S = s·N⊗N with N the strip's axis; the
/// strain along it is fixed (G_NN = ((1 + ε)² − 1)/2) and the lateral and shear strains
/// follow from S_TT = S_NT = 0, solved by fixed-point iteration on K (for K held, the two
/// equations are linear). The load is |P·N| = |F·S·N| = (1 + ε)·s.
pub fn uniaxial(m: &ArcsimMaterial, angle: f64, strain: f64) -> f64 {
    // Exact axes for the axis pulls (cos π/2 is 6e-17, not 0).
    let (c, s) = if angle == FRAC_PI_2 { (0.0, 1.0) } else { (angle.cos(), angle.sin()) };
    let along = 0.5 * ((1.0 + strain).powi(2) - 1.0);
    // Green strain in the material frame from (G_NN, G_TT, G_NT).
    let to_material = |tt: f64, nt: f64| {
        [
            along * c * c + tt * s * s - 2.0 * nt * c * s,
            along * s * s + tt * c * c + 2.0 * nt * c * s,
            (along - tt) * c * s + nt * (c * c - s * s),
        ]
    };
    let (mut tt, mut nt) = (0.0, 0.0);
    for _ in 0..200 {
        let (stretch, principal_angle) = principal(to_material(tt, nt));
        let k = stiffness(m, stretch, principal_angle);
        // S as a linear function of (tt, nt) at this K: S = A·[tt, nt] + b.
        let s_of = |tt: f64, nt: f64| {
            let g = to_material(tt, nt);
            let sm = [k[0] * g[0] + k[1] * g[1], k[1] * g[0] + k[2] * g[1], k[3] * g[2]];
            // S_TT and S_NT in the strip's frame.
            (sm[0] * s * s + sm[1] * c * c - 2.0 * sm[2] * c * s, (sm[1] - sm[0]) * c * s + sm[2] * (c * c - s * s))
        };
        let b = s_of(0.0, 0.0);
        let col_tt = s_of(1.0, 0.0);
        let col_nt = s_of(0.0, 1.0);
        let (a11, a21) = (col_tt.0 - b.0, col_tt.1 - b.1);
        let (a12, a22) = (col_nt.0 - b.0, col_nt.1 - b.1);
        let det = a11 * a22 - a12 * a21;
        let (next_tt, next_nt) = if det.abs() > 1e-12 * (a11 * a22).abs().max((a12 * a21).abs()) {
            ((-b.0 * a22 + b.1 * a12) / det, (-a11 * b.1 + a21 * b.0) / det)
        } else {
            // A stiffness clamped to zero (a knit's negative sample): the strain it would
            // resist is free and stays where no load drives it.
            let nt = if a22 != 0.0 { -b.1 / a22 } else { 0.0 };
            (if a11 != 0.0 { (-b.0 - a12 * nt) / a11 } else { 0.0 }, nt)
        };
        let moved = (next_tt - tt).abs() + (next_nt - nt).abs();
        (tt, nt) = (next_tt, next_nt);
        if moved <= 1e-15 * (1.0 + along.abs()) {
            break;
        }
    }
    let sm = stress(m, to_material(tt, nt));
    let s_nn = sm[0] * c * c + sm[1] * s * s + 2.0 * sm[2] * c * s;
    (1.0 + strain) * s_nn
}

/// The bending sample ARCSim uses for a hinge whose edge lies along `row` (0: u, 1: 45°,
/// 2: v) at hinge curvature `kappa` (1/m): linear between the samples at 0, 10, 20, 30 and
/// 40 m⁻¹, constant beyond (dde.cpp, `bending_stiffness`). ARCSim reads the table with the
/// signed dihedral angle, so a hinge folded the other way extrapolates below the first
/// sample; Rosette's bending is symmetric and uses the magnitude.
pub fn bending_sample(m: &ArcsimMaterial, row: usize, kappa: f64) -> f64 {
    let value = (kappa.abs() / CURVATURE_STEP).min(4.0);
    let i = (value.floor() as usize).min(3);
    let f = value - i as f64;
    let samples = &m.bending[row];
    ((1.0 - f) * samples[i] + f * samples[i + 1]).max(0.0)
}

/// The moment per unit width (N·m/m) of a strip bent uniformly to curvature `kappa` on its
/// own mesh, its hinges in bending row `row`: κ·ke(κ)/4, the secant law of ARCSim's hinge
/// force (physics.cpp, `bending_force`: −ke·shape·θ·∇θ/2 at the state's own ke).
pub fn moment(m: &ArcsimMaterial, row: usize, kappa: f64) -> f64 {
    HINGE_FACTOR * kappa * bending_sample(m, row, kappa)
}

/// The curvatures of the bending samples on a strip's own mesh, 1/m.
pub fn sample_curvatures() -> [f64; 5] {
    std::array::from_fn(|j| CURVATURE_STEP * j as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material() -> ArcsimMaterial {
        let mut stretching = [[100.0, 20.0, 200.0, 30.0]; 6];
        for (i, row) in stretching.iter_mut().enumerate().skip(1) {
            // The strained rows stiffen differently with the angle.
            *row = [130.0 + i as f64, 20.0, 230.0 - i as f64, 30.0 + 2.0 * i as f64];
        }
        ArcsimMaterial { density: 0.2, stretching, bending: [[1e-5, 2e-5, 3e-5, 4e-5, 5e-5]; 3] }
    }

    #[test]
    fn principal_stretch_and_its_folded_angle() {
        let (l, a) = principal([0.1, 0.0, 0.0]);
        assert!((l - 1.2f64.sqrt()).abs() < 1e-15 && a == 0.0);
        let (l, a) = principal([0.0, 0.1, 0.0]);
        assert!((l - 1.2f64.sqrt()).abs() < 1e-15 && a == FRAC_PI_2);
        // Pure tensor shear: principal axes at ±45°, both fold to 45°.
        for sign in [1.0, -1.0] {
            let (l, a) = principal([0.0, 0.0, sign * 0.05]);
            assert!((l - 1.1f64.sqrt()).abs() < 1e-15 && (a - FRAC_PI_2 / 2.0).abs() < 1e-15, "{l} {a}");
        }
    }

    #[test]
    fn stiffness_blends_strain_and_angle_and_doubles() {
        let m = material();
        assert_eq!(stiffness(&m, 1.0, 0.0), [200.0, 40.0, 400.0, 60.0]);
        assert_eq!(stiffness(&m, 0.9, 1.0), [200.0, 40.0, 400.0, 60.0], "compression reads the zero-strain row");
        // Half way to the strain sample along u: half row 0, half row 1.
        let k = stiffness(&m, 1.0 + STRAIN_SAMPLE / 2.0, 0.0);
        assert!((k[0] - (100.0 + 131.0)).abs() < 1e-12 && (k[3] - (30.0 + 32.0)).abs() < 1e-12, "{k:?}");
        // Fully strained at 33.75°: 1.5 rows past the 0° one, half-way between rows 2 and 3.
        let k = stiffness(&m, 2.0, 33.75f64.to_radians());
        assert!((k[0] - 2.0 * 132.5).abs() < 1e-9, "{k:?}");
        let mut negative = m.clone();
        negative.stretching[0][1] = -20.0;
        assert_eq!(stiffness(&negative, 1.0, 0.0)[1], 0.0, "a negative blend is clamped at zero");
    }

    #[test]
    fn a_warp_pull_follows_the_secant_law_in_green_strain() {
        let m = material();
        for strain in [0.01, 0.05, 0.1, STRAIN_SAMPLE, 0.3] {
            let k = stiffness(&m, 1.0 + strain, 0.0);
            let g = 0.5 * ((1.0 + strain) * (1.0 + strain) - 1.0);
            let expected = (1.0 + strain) * (k[0] - k[1] * k[1] / k[2]) * g;
            let got = uniaxial(&m, 0.0, strain);
            assert!((got - expected).abs() < 1e-12 * expected, "{strain}: {got} vs {expected}");
        }
    }

    #[test]
    fn a_bias_pull_at_small_strain_has_the_orthotropic_modulus() {
        // At zero strain the sheet is the orthotropic plate C11 = 2c11, C12 = 2c12,
        // C22 = 2c22, C66 = c33 (the doubling and the tensor shear's half cancel).
        let m = material();
        let (c11, c12, c22, c66) = (200.0, 40.0, 400.0, 30.0);
        let (ex, ey) = (c11 - c12 * c12 / c22, c22 - c12 * c12 / c11);
        let e45 = crate::reference::off_axis_modulus(ex, ey, c66, c12 / c22, std::f64::consts::FRAC_PI_4);
        let strain = 1e-7;
        let got = uniaxial(&m, std::f64::consts::FRAC_PI_4, strain) / strain;
        assert!((got - e45).abs() < 1e-5 * e45, "{got} vs {e45}");
    }

    #[test]
    fn bending_samples_are_read_every_ten_per_metre_and_held_beyond() {
        let m = material();
        assert_eq!(bending_sample(&m, 2, 0.0), 1e-5);
        assert!((bending_sample(&m, 2, 15.0) - 2.5e-5).abs() < 1e-20);
        assert_eq!(bending_sample(&m, 2, 40.0), 5e-5);
        assert_eq!(bending_sample(&m, 2, 90.0), 5e-5);
        assert!((moment(&m, 2, 20.0) - 0.25 * 20.0 * 3e-5).abs() < 1e-18);
    }
}
