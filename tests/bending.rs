//! Bending validation: the arc under end moments (κ = m/B_θ, docs/references.md §3) and the heavy
//! cantilever against the elastica (docs/references.md §4), over warp angles and triangulations, and
//! the free bias strip against the anticlastic strip theory (docs/fabric-sheets.md, Bias).

mod common;

use common::reference::{bending_rigidity_theta, heavy_cantilever};
use rosette::scene::{Measures, RunOptions, Scene, SceneConfig, load_scene, run_scene};

fn run(preset: &str, overrides: &[String]) -> (SceneConfig, Measures) {
    let (config, _) = load_scene(preset, overrides).unwrap_or_else(|e| panic!("{e}"));
    let mut scene = Scene::build(config.clone()).unwrap_or_else(|e| panic!("{e}"));
    let (metrics, error) = run_scene(&mut scene, preset, RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    (config.into_config(), metrics.measures)
}

/// B_θ of paper eq. 3 from the fabric's inputs, with θ the bending direction from the warp.
fn rigidity(config: &SceneConfig, theta_deg: f64) -> f64 {
    let f = &config.fabric.properties;
    let middle = match f.bending_bias {
        Some(bias) => 4.0 * bias - f.bending_warp - f.bending_weft,
        // 2ν B_x + 4 G_Pa h³/12 with G_Pa = G / h.
        None => 2.0 * f.poisson_warp * f.bending_warp + f.shear_modulus * f.thickness * f.thickness / 3.0,
    };
    bending_rigidity_theta(f.bending_warp, f.bending_weft, middle, theta_deg.to_radians())
}

fn set(pairs: &[(&str, String)]) -> Vec<String> {
    pairs.iter().map(|(k, v)| format!("{k}={v}")).collect()
}

/// A strip in pure bending between rigid grips forms an arc of curvature m/B_θ, with m
/// the measured grip moment per unit width. The curvature is fitted over the middle half,
/// away from the grips; 1 % is the tolerance for a converged mesh (3 mm edges on
/// an 8 cm strip).
fn arc_check(warps: &[f64]) {
    for &warp in warps {
        for integrator in ["implicit-euler", "bdf2"] {
            if integrator == "bdf2" && warp != warps[0] {
                continue; // one angle suffices to show the integrator does not matter
            }
            let (config, m) = run(
                "arc",
                &set(&[
                    ("cloth.warp_angle_deg", warp.to_string()),
                    ("solver.integrator", integrator.into()),
                    ("mesh.edge_length", "0.003".into()),
                ]),
            );
            let m = m.arc().expect("arc measures");
            let expected = m.moment / rigidity(&config, -warp);
            let curvature = m.curvature;
            let error = (curvature - expected).abs() / expected;
            println!("arc warp {warp}° {integrator}: κ = {curvature:.4} 1/m, m/B_θ = {expected:.4}, error {:.3} %", error * 100.0);
            assert!(error < 0.01, "warp {warp}°, {integrator}: κ = {curvature}, m/B_θ = {expected}");
        }
    }
}

#[test]
fn arc_curvature_is_moment_over_rigidity_along_warp_and_weft() {
    arc_check(&[0.0, 90.0]);
}

/// Off the principal axes the rotated coupling D'12 is large (D'12²/(D'11 D'22) ≈ 0.45 at
/// 45° for this wool) and the bias membrane is soft, so the anticlastic boundary layer at
/// each free edge (Searle's effect, width ~ √(R h), fixed by the curvature and the sheet)
/// relaxes the bend: the measured rigidity falls short of B_θ by a share proportional to
/// 1/W. KES-B-like specimens (2 cm long, 10 and 20 cm wide) are measured; the test checks
/// the shortfall really halves when the width doubles, then removes the 1/W term
/// (Richardson: B∞ = 2 B(2W) − B(W)) and holds that to the 1 %.
#[test]
fn arc_rigidity_off_axis_converges_to_b_theta_as_the_edge_layers_shrink() {
    for warp in [30.0, 45.0] {
        let ratio = |width: f64| {
            let (config, m) = run(
                "arc",
                &set(&[
                    ("cloth.warp_angle_deg", warp.to_string()),
                    ("cloth.length", "0.02".into()),
                    ("cloth.width", width.to_string()),
                    ("mesh.edge_length", "0.002".into()),
                    ("test.clamp_length", "0.004".into()),
                ]),
            );
            m.arc().expect("arc measures").rigidity.expect("the strip bent") / rigidity(&config, -warp)
        };
        let (narrow, wide) = (ratio(0.1), ratio(0.2));
        let extrapolated = 2.0 * wide - narrow;
        let halving = (1.0 - wide) / (1.0 - narrow);
        println!("arc warp {warp}°: B/B_θ = {narrow:.4} (10 cm), {wide:.4} (20 cm), shortfall ratio {halving:.3}, extrapolated {extrapolated:.4}");
        assert!((0.4..0.6).contains(&halving), "the shortfall should scale as 1/W: ratio {halving}");
        assert!((extrapolated - 1.0).abs() < 0.01, "warp {warp}°: extrapolated B/B_θ = {extrapolated}");
    }
}

fn cantilever_check(patterns: &[&str], warps: &[f64], fabric: &[&str]) {
    let fabric: Vec<String> = fabric.iter().map(|s| s.to_string()).collect();
    let (base, _) = load_scene("cantilever", &fabric).unwrap();
    let w = base.fabric.properties.areal_density * rosette::physics::STANDARD_GRAVITY;
    for &pattern in patterns {
        for &warp in warps {
            let b = rigidity(&base, -warp);
            for lambda in [1.0, 8.0, 50.0] {
                // λ = 1 bends least, so the clamp's discretisation error weighs most: 24 cells.
                let cells = if lambda < 2.0 { 24.0 } else { 16.0 };
                let length: f64 = (lambda * b / w).cbrt();
                let mut overrides = set(&[
                    ("mesh.pattern", pattern.into()),
                    ("cloth.warp_angle_deg", warp.to_string()),
                    ("cloth.length", length.to_string()),
                    ("cloth.width", (0.5 * length).to_string()),
                    ("mesh.edge_length", (length / cells).to_string()),
                    ("test.clamp_length", (length / 8.0).to_string()),
                ]);
                overrides.extend(fabric.iter().cloned());
                let (_, m) = run("cantilever", &overrides);
                let exact = heavy_cantilever(lambda);
                let m = m.cantilever().expect("cantilever measures");
                let drop = m.tip_drop / length;
                let angle = m.tip_angle_deg;
                let exact_angle = exact.tip_angle_rad.to_degrees();
                let (drop_error, angle_error) =
                    ((drop - exact.tip_drop_over_l).abs() / exact.tip_drop_over_l, (angle - exact_angle).abs() / exact_angle);
                println!(
                    "{pattern} warp {warp}° λ {lambda}: drop/L {drop:.4} vs {:.4} ({:.2} %), tip angle {angle:.2}° vs {exact_angle:.2}° ({:.2} %)",
                    exact.tip_drop_over_l,
                    drop_error * 100.0,
                    angle_error * 100.0
                );
                assert!(drop_error < 0.02 && angle_error < 0.02, "{pattern} warp {warp} λ {lambda}");
            }
        }
    }
}

/// Tip drop and tip angle of the heavy cantilever against the elastica computed here by
/// shooting, for λ = wL³/B from 1 to 50, on two triangulations, along the warp and the
/// weft of the paper's wool. The overhang is cut into 16 cells (24 at λ = 1); 2 % is the
/// issue's tolerance.
#[test]
fn cantilever_follows_the_heavy_elastica_along_warp_and_weft() {
    cantilever_check(&["alternating", "regular"], &[0.0, 90.0], &[]);
}

/// The third warp angle, 45°, with bending made isotropic (B_warp = B_weft = B_bias): the
/// discretisation must not care how the mesh sits relative to the warp.
#[test]
fn cantilever_is_independent_of_the_warp_angle_for_isotropic_bending() {
    let iso = ["fabric.bending_warp=7e-6", "fabric.bending_weft=7e-6", "fabric.bending_bias=7e-6"];
    cantilever_check(&["alternating", "regular"], &[45.0], &iso);
}

/// The free bias strip's theory (docs/fabric-sheets.md, Bias), derived here apart from
/// `rosette::fabric::bias`: the plate stiffness rotated to the strip's axis as a fourth-order
/// tensor, the strip's energy per area taken from the edge-zone solution and differentiated
/// numerically for its moment, and the heavy elastica integrated in moment form from the
/// free tip back to the clamp.
mod strip_theory {
    use std::f64::consts::FRAC_PI_2;

    /// The plate's bending stiffness in the warp frame as the tensor D_ijkl of
    /// ψ = ½ D_ijkl κ_ij κ_kl: D₁₁₁₁ = B_x, D₂₂₂₂ = B_y, D₁₁₂₂ = D₁₂ and D₁₂₁₂ = D₆₆ (and
    /// their symmetric places), with eq. 3's middle term 2D₁₂ + 4D₆₆ = 4B₄₅ − B_x − B_y
    /// split as the model documents (docs/references.md §1): D₁₂ = ν·B_x where the term
    /// allows it, the rest twist. Rotated by `theta` (radians from the warp) and read back
    /// as (D′₁₁, D′₁₂, D′₂₂).
    pub fn rotated_plate(bx: f64, by: f64, nu: f64, b45: f64, theta: f64) -> (f64, f64, f64) {
        let middle = 4.0 * b45 - bx - by;
        let d12 = (nu * bx).min(0.25 * middle);
        let d66 = 0.25 * (middle - 2.0 * d12);
        let mut d = [[[[0.0f64; 2]; 2]; 2]; 2];
        d[0][0][0][0] = bx;
        d[1][1][1][1] = by;
        (d[0][0][1][1], d[1][1][0][0]) = (d12, d12);
        for (i, j) in [(0, 1), (1, 0)] {
            for (k, l) in [(0, 1), (1, 0)] {
                d[i][j][k][l] = d66;
            }
        }
        let (s, c) = theta.sin_cos();
        // Rows of R are the strip's axes in the warp frame.
        let r = [[c, s], [-s, c]];
        let rotated = |p: usize, q: usize, m: usize, n: usize| {
            let mut sum = 0.0;
            for a in 0..2 {
                for b in 0..2 {
                    for e in 0..2 {
                        for f in 0..2 {
                            sum += r[p][a] * r[q][b] * r[m][e] * r[n][f] * d[a][b][e][f];
                        }
                    }
                }
            }
            sum
        };
        (rotated(0, 0, 0, 0), rotated(0, 0, 1, 1), rotated(1, 1, 1, 1))
    }

    /// The strip's moment law M(κ), N·m/m, as the derivative of its energy per area
    /// U(κ) = ½κ²[D′₁₁ − (D′₁₂²/D′₂₂)·F(t)], t = (b/2)·(E κ²/(4D′₂₂))^¼,
    /// F(t) = (cosh 2t − cos 2t)/(t·(sinh 2t + sin 2t)).
    pub struct Law {
        pub d11: f64,
        pub shed: f64,
        pub d22: f64,
        pub axial_modulus: f64,
        pub width: f64,
    }

    impl Law {
        fn energy(&self, kappa: f64) -> f64 {
            let t = 0.5 * self.width * (self.axial_modulus * kappa * kappa / (4.0 * self.d22)).powf(0.25);
            let f = if t < 1e-3 { 1.0 } else { ((2.0 * t).cosh() - (2.0 * t).cos()) / (t * ((2.0 * t).sinh() + (2.0 * t).sin())) };
            0.5 * kappa * kappa * (self.d11 - self.shed * f)
        }

        pub fn moment(&self, kappa: f64) -> f64 {
            let h = 1e-4 * kappa;
            (self.energy(kappa + h) - self.energy(kappa - h)) / (2.0 * h)
        }

        /// κ for a moment `m` ≥ 0: the secant rigidity lies between D′₁₁ − D′₁₂²/D′₂₂ (a
        /// fully relaxed cross-section) and D′₁₁ (none), which brackets it.
        fn curvature(&self, m: f64) -> f64 {
            if m <= 0.0 {
                return 0.0;
            }
            let (mut low, mut high) = (m / self.d11 * 0.999, m / (self.d11 - self.shed) * 1.001);
            for _ in 0..40 {
                let mid = 0.5 * (low + high);
                if self.moment(mid) < m { low = mid } else { high = mid }
            }
            0.5 * (low + high)
        }
    }

    /// The chord angle (radians) of a strip of overhang `length` (m) and weight per area
    /// `w` (N/m²) clamped level: from the free tip (θ = θ_tip, M = 0) back to the clamp,
    /// dM/ds = −w·(L − s)·cos θ and dθ/ds = κ(M), shooting on θ_tip until θ = 0 at the clamp.
    pub fn chord_angle(law: &Law, w: f64, length: f64) -> f64 {
        const STEPS: usize = 100;
        let h = length / STEPS as f64;
        // State (θ, M, x, y) against the distance u = L − s from the tip; x and y are the
        // tip's offsets from the clamp, summed on the way.
        let rhs = |u: f64, y: [f64; 4]| [-law.curvature(y[1]), w * u * y[0].cos(), y[0].cos(), y[0].sin()];
        let shoot = |tip_angle: f64| {
            let mut y = [tip_angle, 0.0, 0.0, 0.0];
            for step in 0..STEPS {
                let u = step as f64 * h;
                let add = |a: [f64; 4], k: [f64; 4], f: f64| std::array::from_fn::<f64, 4, _>(|i| a[i] + f * k[i]);
                let k1 = rhs(u, y);
                let k2 = rhs(u + 0.5 * h, add(y, k1, 0.5 * h));
                let k3 = rhs(u + 0.5 * h, add(y, k2, 0.5 * h));
                let k4 = rhs(u + h, add(y, k3, h));
                y = std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            }
            y
        };
        let (mut low, mut high) = (0.0, FRAC_PI_2);
        for _ in 0..40 {
            let mid = 0.5 * (low + high);
            if shoot(mid)[0] < 0.0 { low = mid } else { high = mid }
        }
        let y = shoot(0.5 * (low + high));
        y[3].atan2(y[2])
    }

    /// The bending length (m) the cantilever standards read: half the overhang whose chord
    /// makes 41.5° below the level, found by regula falsi (Illinois) on ln L between an
    /// overhang of one and of four plate bending lengths `plate`.
    pub fn bending_length(law: &Law, w: f64, plate: f64) -> f64 {
        let miss = |ln_length: f64| chord_angle(law, w, ln_length.exp()) - 41.5f64.to_radians();
        let (mut a, mut b) = (plate.ln(), (4.0 * plate).ln());
        let (mut fa, mut fb) = (miss(a), miss(b));
        assert!(fa < 0.0 && fb > 0.0, "the 41.5° overhang lies between one and four plate bending lengths");
        for _ in 0..60 {
            if (b - a).abs() < 1e-10 {
                break;
            }
            let c = b - fb * (b - a) / (fb - fa);
            let fc = miss(c);
            if fc == 0.0 {
                return 0.5 * c.exp();
            }
            if (fc > 0.0) == (fb > 0.0) {
                fa *= 0.5;
            } else {
                (a, fa) = (b, fb);
            }
            (b, fb) = (c, fc);
        }
        0.5 * b.exp()
    }
}

/// The bias strip (issue 26). A strip cut on the bias is mostly free edge: the rotated
/// coupling D′₁₂ is large there (D′₁₂²/(D′₁₁D′₂₂) ≈ 0.45 for this wool), so the strip bends
/// anticlastically wherever the sheet's stiffness along it lets it, and eq. 3's B₄₅, a
/// plate's rigidity in cylindrical bending, does not give its droop (the narrow strip of
/// λ = 1 below, half as wide as long, droops 26 % more than the elastica with B₄₅). The
/// model keeps `bending_bias` as the plate's B₄₅ and maps a measured bias bending length to
/// it through the strip theory of src/fabric/bias.rs: a beam on an elastic foundation
/// across the width, solved with the heavy elastica (docs/fabric-sheets.md, Bias). Here the
/// bundled wool's bias strip is measured as ASTM D1388 does, overhang at 41.5°, and set
/// against that theory, derived in this file ([`strip_theory`]) apart from both the
/// simulator and src/fabric/bias.rs: within 1 % on the standard's 25 mm strip and on a
/// 50 mm one. src/fabric/bias.rs, which the importer uses to map a measured bias bending
/// length to B₄₅, is held to the same derivation within 1e-4. The plate value (B₄₅/w)^⅓ is printed for
/// comparison. The theory leaves out the clamp, which holds the cross-section straight at
/// the root: where the edge zones are as wide as the strip and the clamp as near as the
/// width, as for the λ = 1 strip, that matters and the theory overstates the droop.
#[test]
fn bias_cantilever_follows_the_anticlastic_strip_theory() {
    use rosette::fabric::bias::{BiasStrip, strip_bending_length};
    use rosette::lab::{Direction, cantilever_bending_length};
    let (config, _) = load_scene("cantilever", &[]).unwrap();
    let f = config.fabric.to_fabric().unwrap();
    let b45 = config.fabric.properties.bending_bias.expect("the bundled wool has a bias rigidity");
    let w = f.areal_density * rosette::physics::STANDARD_GRAVITY;
    let axial = rosette::reference::off_axis_modulus(
        f.tensile_warp.initial_slope(),
        f.tensile_weft.initial_slope(),
        f.shear_modulus,
        f.poisson_warp,
        std::f64::consts::FRAC_PI_4,
    );
    let (d11, d12, d22) = strip_theory::rotated_plate(f.bending_warp, f.bending_weft, f.poisson_warp, b45, std::f64::consts::FRAC_PI_4);
    let plate = (b45 / w).cbrt();
    for width in [0.025, 0.05] {
        let law = strip_theory::Law { d11, shed: d12 * d12 / d22, d22, axial_modulus: axial, width };
        let theory = strip_theory::bending_length(&law, w, plate);
        let strip = BiasStrip {
            areal_density: f.areal_density,
            bending_warp: f.bending_warp,
            bending_weft: f.bending_weft,
            poisson_warp: f.poisson_warp,
            axial_modulus: axial,
            width,
        };
        let production = strip_bending_length(&strip, b45);
        assert!((production / theory - 1.0).abs() < 1e-4, "{width} m strip: src/fabric/bias.rs gives {production} m, the derivation {theory} m");
        let measured = cantilever_bending_length(&config.fabric, Direction::Bias, width).unwrap().bending_length;
        let error = measured / theory - 1.0;
        println!(
            "bias strip {:.1} mm wide: bending length {:.3} mm, strip theory {:.3} mm ({:+.2} %), plate (B₄₅/w)^⅓ {:.3} mm ({:+.2} %)",
            width * 1e3,
            measured * 1e3,
            theory * 1e3,
            100.0 * error,
            plate * 1e3,
            100.0 * (measured / plate - 1.0)
        );
        assert!(error.abs() < 0.01, "{width} m strip: {measured} m against the strip theory's {theory} m");
    }
}

/// The cantilever error shrinks as the mesh is refined (λ = 8, the ASTM D1388 point).
#[test]
fn cantilever_error_shrinks_on_refinement() {
    let (base, _) = load_scene("cantilever", &[]).unwrap();
    let w = base.fabric.properties.areal_density * rosette::physics::STANDARD_GRAVITY;
    let length: f64 = (8.0 * rigidity(&base, 0.0) / w).cbrt();
    let exact = heavy_cantilever(8.0);
    let mut errors = Vec::new();
    for cells in [6.0, 12.0, 24.0] {
        let (_, m) = run(
            "cantilever",
            &set(&[
                ("cloth.length", length.to_string()),
                ("cloth.width", (0.5 * length).to_string()),
                ("mesh.edge_length", (length / cells).to_string()),
                ("test.clamp_length", (length / 6.0).to_string()),
            ]),
        );
        let drop = m.cantilever().expect("cantilever measures").tip_drop / length;
        errors.push((drop - exact.tip_drop_over_l).abs());
    }
    println!("cantilever λ = 8 tip-drop errors at 6, 12, 24 cells: {errors:?}");
    assert!(errors[1] < errors[0] && errors[2] < errors[1], "{errors:?}");
}

/// Nonlinear bending: with a measured moment–curvature curve along the warp, pure bending to
/// a curvature κ must need the curve's moment M(κ). The curve stiffens 2.5-fold past
/// 10 1/m; the bend (20 1/m) is well past the knee. 1 % as for the linear arc.
#[test]
fn arc_follows_a_nonlinear_moment_curvature_curve() {
    let curve = [[0.0, 0.0], [10.0, 9.0e-5], [30.0, 5.4e-4]];
    let (config, m) = run(
        "arc",
        &set(&[
            ("fabric.bending_curve", format!("{curve:?}")),
            ("mesh.edge_length", "0.003".into()),
        ]),
    );
    assert_eq!(config.fabric.properties.bending_warp, 9e-6, "the curve's initial slope is the warp rigidity");
    let m = m.arc().expect("arc measures");
    let kappa = m.curvature;
    // The curve at the measured curvature, interpolated here.
    let expected = 9.0e-5 + (kappa - 10.0) * (5.4e-4 - 9.0e-5) / 20.0;
    let moment = m.moment;
    let error = (moment - expected).abs() / expected;
    println!("nonlinear arc: κ = {kappa:.3} 1/m, moment {moment:.4e} vs curve {expected:.4e} ({:.2} %)", error * 100.0);
    assert!(error < 0.01, "{moment} vs {expected}");
}

/// Settling detection stops a static test early without changing its answer: the
/// cantilever preset watches for settling (RMS speed below 0.1 mm/s for 0.2 s), stops well
/// before its 3 s, and its tip drop matches a run of the full duration to 0.1 %.
#[test]
fn settled_cantilever_stops_early_with_the_same_answer() {
    let (config, _) = load_scene("cantilever", &[]).unwrap();
    let mut settling = Scene::build(config.clone()).unwrap();
    let (early, _) = run_scene(&mut settling, "cantilever", RunOptions::default());
    let mut full_config = config.into_config();
    full_config.scene.settle_speed = None;
    let mut full = Scene::new(full_config).unwrap();
    let (complete, _) = run_scene(&mut full, "cantilever", RunOptions::default());
    assert_eq!(early.settled, Some(true));
    assert_eq!(complete.settled, None);
    assert!(early.simulated_seconds < 0.7 * complete.simulated_seconds, "{} s vs {} s", early.simulated_seconds, complete.simulated_seconds);
    let tip_drop = |m: &Measures| m.cantilever().expect("cantilever measures").tip_drop;
    let (a, b) = (tip_drop(&early.measures), tip_drop(&complete.measures));
    println!("settled at {:?} s: tip drop {a} vs {b} after the full {} s", early.settle_time, complete.simulated_seconds);
    assert!((a - b).abs() < 1e-3 * b);
}
