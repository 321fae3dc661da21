//! From ARCSim's model to Rosette's fabric keys: the projection, with each key's source.
//!
//! ARCSim's stretching stiffness varies with the strain and the direction of the largest
//! principal stretch jointly, and its bending with the hinge's direction and curvature;
//! Rosette has a tensile curve along the warp and the weft, a constant shear modulus and
//! Poisson ratio, three bending rigidities and one moment–curvature shape. The projection
//! keeps what a designer's tests along the axes read exactly and states what it drops
//! (docs/fabric-sheets.md, ARCSim materials, measures it):
//!
//! - `tensile_warp`, `tensile_weft`: ARCSim's own uniaxial pulls along u and v, to 50 %
//!   strain, within [`CURVE_TOLERANCE`] at every strain; their first segment is ARCSim's
//!   zero-strain modulus exactly.
//! - `shear_modulus`, `poisson_warp`: the zero-strain row (c33 and c12/c22).
//! - `bending_warp`, `bending_weft`, `bending_bias`: the first bending samples of the
//!   hinge rows across each direction, times [`HINGE_FACTOR`].
//! - `bending_curve`: the warp's moment–curvature law, when its samples vary.
//!
//! Dropped: the strained rows at 22.5°, 45° and 67.5° and their c12 and c33 (Rosette's
//! bias follows its warp and weft curves, its shear stays linear), and the weft and bias
//! bending samples beyond the first (Rosette scales every direction by the warp's shape).

use super::material::ArcsimMaterial;
use super::model::{BIAS_ROW, CURVATURE_STEP, HINGE_FACTOR, STRAIN_SAMPLE, WARP_ROW, WEFT_ROW, moment, uniaxial};
use crate::fabric::derived::{DEFAULT_BULK_DENSITY, Derived, Import};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// How closely the sampled curves follow ARCSim's, relative, at every strain or curvature
/// between their knots.
pub const CURVE_TOLERANCE: f64 = 1e-3;
/// The tensile curves are sampled to this strain; beyond it Rosette goes on along the last
/// segment (ARCSim's stress keeps growing as the cube of the stretch there).
pub const MAX_STRAIN: f64 = 0.5;
/// Where ARCSim's moment or load falls with growing curvature or strain, Rosette's curve
/// (which must rise) rises at this fraction of its initial slope, as the compression branch
/// of the tensile curves does (`Fabric::with_compression_buckling`).
pub const HOLD_SLOPE: f64 = 0.01;
/// E₄₅ over the smaller of E₀ and E₉₀ at zero strain above which a material behaves like a
/// knit: a woven's bias is soft (0.02–0.52 in the Wang–O'Brien–Ramamoorthi wovens), a
/// knit's loops resist alike in every direction (0.95–2.4 in their knits).
pub const KNIT_SIGNATURE: f64 = 0.75;
/// The largest Poisson ratio Rosette takes (its fabric check refuses 0.5 and above).
pub const MAX_POISSON: f64 = 0.49;

/// The zero-strain orthotropic plate of an ARCSim material: (E_u, E_v, G, ν_uv), N/m.
/// C11 = 2c11, C12 = 2c12 (negative values clamped to zero, as ARCSim does), C22 = 2c22,
/// C66 = c33: ARCSim doubles the samples, and its shear term k3·G01² in the tensor shear
/// G01 = γ/2 is ½·(k3/2)·γ².
pub fn zero_strain_plate(m: &ArcsimMaterial) -> (f64, f64, f64, f64) {
    let [c11, c12, c22, c33] = m.stretching[0];
    let (k0, k1, k2) = (2.0 * c11, 2.0 * c12.max(0.0), 2.0 * c22);
    (k0 - k1 * k1 / k2, k2 - k1 * k1 / k0, c33, k1 / k2)
}

/// The zero-strain modulus of a pull at 45° over the smaller axis modulus (see
/// [`KNIT_SIGNATURE`]).
pub fn bias_ratio(m: &ArcsimMaterial) -> f64 {
    let (eu, ev, g, nu) = zero_strain_plate(m);
    crate::reference::off_axis_modulus(eu, ev, g, nu, FRAC_PI_4) / eu.min(ev)
}

/// Points of `f` from the origin: first the tangent `slope`·x to a knot close enough that
/// the tangent and `f` agree within half the tolerance, then knots at each of `breaks`
/// (increasing) and, between them, wherever the chord strays from `f` by more than
/// [`CURVE_TOLERANCE`].
pub fn sample(f: &dyn Fn(f64) -> f64, slope: f64, breaks: &[f64]) -> Vec<[f64; 2]> {
    let mut x1 = breaks[0] / 100.0;
    for _ in 0..60 {
        if (f(x1) - slope * x1).abs() <= 0.5 * CURVE_TOLERANCE * f(x1).abs() {
            break;
        }
        x1 *= 0.5;
    }
    let mut points = vec![[0.0, 0.0], [x1, slope * x1]];
    let mut a = points[1];
    let mut budget = MAX_KNOTS;
    for &b in breaks {
        let end = [b, f(b)];
        bisect(f, a, end, &mut points, &mut budget);
        a = end;
    }
    points
}

/// The most knots a sampled curve gets: a smooth ARCSim pull needs a few dozen; a material
/// whose load is flat or tiny (a relative tolerance never met) stops here instead of
/// splitting for ever.
const MAX_KNOTS: usize = 256;

/// Splits [a, b] where the chord strays from `f`, depth first, while `budget` knots remain.
fn bisect(f: &dyn Fn(f64) -> f64, a: [f64; 2], b: [f64; 2], points: &mut Vec<[f64; 2]>, budget: &mut usize) {
    let mid = 0.5 * (a[0] + b[0]);
    let (chord, exact) = (0.5 * (a[1] + b[1]), f(mid));
    if *budget > 0 && mid > a[0] && mid < b[0] && (chord - exact).abs() > CURVE_TOLERANCE * exact.abs() {
        *budget -= 1;
        let m = [mid, exact];
        bisect(f, a, m, points, budget);
        bisect(f, m, b, points, budget);
    } else {
        points.push(b);
    }
}

/// Makes every segment rise by at least `floor` per unit x; returns the x range that was
/// held, if any.
fn hold_rising(points: &mut [[f64; 2]], floor: f64) -> Option<(f64, f64)> {
    let mut held: Option<(f64, f64)> = None;
    for i in 1..points.len() {
        let least = points[i - 1][1] + floor * (points[i][0] - points[i - 1][0]);
        if points[i][1] < least {
            points[i][1] = least;
            held = Some((held.map_or(points[i - 1][0], |h| h.0), points[i][0]));
        }
    }
    held
}

fn float(v: f64) -> toml::Value {
    toml::Value::Float(v)
}

fn curve_value(points: &[[f64; 2]]) -> toml::Value {
    toml::Value::Array(points.iter().map(|p| toml::Value::Array(vec![float(p[0]), float(p[1])])).collect())
}

/// The tensile curve of ARCSim's pull at `angle`, rising; `name` names it in warnings.
fn tensile(m: &ArcsimMaterial, angle: f64, name: &str, modulus: f64, warnings: &mut Vec<String>) -> Vec<[f64; 2]> {
    let f = |e: f64| uniaxial(m, angle, e);
    let mut points = sample(&f, modulus, &[STRAIN_SAMPLE, MAX_STRAIN]);
    if let Some((a, b)) = hold_rising(&mut points, HOLD_SLOPE * modulus) {
        warnings.push(format!(
            "{name}: ARCSim's load falls between {:.1} and {:.1} % strain (its strained samples are softer than the \
             unstrained ones); Rosette's curve must rise, so it rises there at 1 % of its first slope",
            100.0 * a,
            100.0 * b
        ));
    }
    points
}

/// Curvatures (1/m) over which a curve departs from ARCSim's: where ARCSim's moment starts
/// to fall, and where it climbs back.
pub type HeldRange = (f64, f64);

/// The warp's moment–curvature curve, rising, and the curvatures over which it departs
/// from ARCSim's [start of the fall, where ARCSim's moment climbs back], if it does; None
/// when the warp's samples do not vary with the curvature.
pub fn warp_bending_curve(m: &ArcsimMaterial) -> Option<(Vec<[f64; 2]>, Option<HeldRange>)> {
    let row = &m.bending[WARP_ROW];
    if row.iter().all(|&v| (v - row[0]).abs() <= 1e-9 * row[0]) {
        return None;
    }
    let rigidity = HINGE_FACTOR * row[0];
    let breaks: Vec<f64> = (1..=4).map(|j| CURVATURE_STEP * j as f64).collect();
    let f = |k: f64| moment(m, WARP_ROW, k);
    let mut points = sample(&f, rigidity, &breaks);
    let floor = HOLD_SLOPE * rigidity;
    // Beyond the last sample ARCSim's hinge keeps its last rigidity: M = κ·ke₄/4.
    let line = HINGE_FACTOR * row[4];
    let &[x, _] = points.last().expect("sampled");
    let Some((a, _)) = hold_rising(&mut points, floor) else {
        points.push([2.0 * x, 2.0 * x * line]);
        return Some((points, None));
    };
    let &[x, y] = points.last().expect("sampled");
    // Where the held line y + floor·(κ − x) meets M = κ·line, if it does.
    let rejoin = if line > floor { ((y - floor * x) / (line - floor)).max(x) } else { f64::INFINITY };
    if rejoin.is_finite() {
        if rejoin > x {
            points.push([rejoin, rejoin * line]);
        }
        points.push([2.0 * rejoin, 2.0 * rejoin * line]);
    } else {
        points.push([2.0 * x, y + floor * x]);
    }
    Some((points, Some((a, rejoin))))
}

/// Fields of `m` below zero, which ARCSim clamps at zero after interpolating.
fn negative_samples(m: &ArcsimMaterial) -> Vec<String> {
    let mut out = Vec::new();
    for (i, row) in m.stretching.iter().enumerate() {
        for (j, &v) in row.iter().enumerate() {
            if v < 0.0 {
                out.push(format!("stretching[{i}][{j}] = {v}"));
            }
        }
    }
    out
}

/// The fabric keys an ARCSim material gives, each with its source, and the warnings.
/// `origin` names the material (`arcsim.data = "…"` or `[arcsim]`); keys in `explicit`
/// (written directly in the fabric file) are left to the file.
pub fn derive(m: &ArcsimMaterial, origin: &str, explicit: &toml::Table) -> Import {
    let mut out = Import::default();
    let mut push = |key: &'static str, value: toml::Value, source: String, default: bool| {
        out.derived.push(Derived { key, value, source, default, section: None });
    };
    let mut warnings = Vec::new();
    let (eu, ev, g, nu_raw) = zero_strain_plate(m);
    let s = &m.stretching;
    push("areal_density", float(m.density), format!("{origin}: density = {} kg/m² (ARCSim's area density)", m.density), false);
    if !explicit.contains_key("thickness") {
        let value = m.density / DEFAULT_BULK_DENSITY;
        warnings.push(format!(
            "thickness: an ARCSim material has none; using the mass per area over {DEFAULT_BULK_DENSITY} kg/m³ = {:.2} mm \
             (it sets the contact thickness; the bias rigidity comes from the file)",
            value * 1e3
        ));
        push("thickness", float(value), format!("default: mass per area / {DEFAULT_BULK_DENSITY} kg/m³"), true);
    }
    let warp = tensile(m, 0.0, "tensile_warp", eu, &mut warnings);
    push(
        "tensile_warp",
        curve_value(&warp),
        format!(
            "{origin}: stretching[0] and [1] (c11 {} and {} N/m): ARCSim's pull along u, load per width (1+ε)·S₀₀, S = 2·samples·Green strain, to {} % strain",
            s[0][0],
            s[1][0],
            100.0 * MAX_STRAIN
        ),
        false,
    );
    let weft = tensile(m, FRAC_PI_2, "tensile_weft", ev, &mut warnings);
    push(
        "tensile_weft",
        curve_value(&weft),
        format!("{origin}: stretching[0] and [5] (c22 {} and {} N/m): ARCSim's pull along v, as for the warp", s[0][2], s[5][2]),
        false,
    );
    push("shear_modulus", float(g), format!("{origin}: stretching[0][3] = c33 = {} N/m (doubled, on the tensor shear γ/2)", s[0][3]), false);
    let nu = nu_raw.min(MAX_POISSON);
    if nu_raw > MAX_POISSON {
        warnings.push(format!("poisson_warp: c12/c22 = {nu_raw:.3} at zero strain; Rosette's membrane takes at most {MAX_POISSON}, used instead"));
    }
    push("poisson_warp", float(nu), format!("{origin}: stretching[0][1]/[0][2] = c12/c22 = {}/{}", s[0][1].max(0.0), s[0][2]), false);
    let rows = [("bending_warp", WARP_ROW), ("bending_weft", WEFT_ROW), ("bending_bias", BIAS_ROW)];
    let mut rigidity = [0.0; 3];
    for (i, (key, row)) in rows.into_iter().enumerate() {
        rigidity[i] = HINGE_FACTOR * m.bending[row][0];
        let across = ["hinges along v, across a warp bend", "hinges along u, across a weft bend", "hinges at 45°"][i];
        push(key, float(rigidity[i]), format!("{origin}: bending[{row}][0] = {:e} N·m × ¼ ({across})", m.bending[row][0]), false);
    }
    // Eq. 3's middle term must stay positive: B₄₅ > (B_x + B_y)/4.
    let least = 0.25 * (rigidity[0] + rigidity[1]) * 1.001;
    if rigidity[2] < least {
        warnings.push(format!(
            "bending_bias: bending[{BIAS_ROW}][0]/4 = {:.3e} N·m is below what eq. 3 allows with these warp and weft rigidities; {least:.3e} used",
            rigidity[2]
        ));
        if let Some(d) = out.derived.iter_mut().find(|d| d.key == "bending_bias") {
            d.value = float(least);
        }
    }
    if let Some((curve, held)) = warp_bending_curve(m) {
        if let Some((a, rejoin)) = held {
            warnings.push(format!(
                "bending_curve: ARCSim's warp moment (bending[{WARP_ROW}]) falls beyond {a:.1} m⁻¹, a negative stiffness its \
                 hinge forces hide; Rosette's curve must rise, so it holds the moment there, rising at 1 % of the \
                 rigidity, until ARCSim's moment climbs back at {rejoin:.1} m⁻¹"
            ));
        }
        out.derived.push(Derived {
            key: "bending_curve",
            value: curve_value(&curve),
            source: format!(
                "{origin}: bending[{WARP_ROW}] ({} N·m at 0–40 m⁻¹): M = κ·ke(κ)/4, ke linear between samples every {CURVATURE_STEP} m⁻¹, held beyond",
                m.bending[WARP_ROW].iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(", ")
            ),
            default: false,
            section: None,
        });
    }
    let negative = negative_samples(m);
    if !negative.is_empty() {
        warnings.push(format!(
            "{origin}: negative samples ({}); ARCSim clamps each interpolated stiffness at zero, and so does the import",
            negative.join(", ")
        ));
    }
    let ratio = bias_ratio(m);
    if ratio > KNIT_SIGNATURE {
        warnings.push(format!(
            "{origin}: at zero strain its bias is as stiff as its axes (E45 {ratio:.2} of the softer axis; a woven's is below \
             {KNIT_SIGNATURE}): it behaves like a knit, outside the scope of Rosette's woven model"
        ));
    }
    out.warnings = warnings;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A load that no relative tolerance can follow (zero at the knots, tiny between them,
    /// or flat) is sampled with a bounded number of knots instead of splitting for ever.
    #[test]
    fn sampling_is_bounded_whatever_the_load() {
        let wild = |e: f64| if (e * 1e6).round() as i64 % 2 == 0 { 0.0 } else { 5e-324 };
        for (f, slope) in [(&wild as &dyn Fn(f64) -> f64, 0.0), (&|_: f64| 0.0, 0.0), (&|e: f64| (1e3 * e).sin(), 1e3)] {
            let points = sample(f, slope, &[STRAIN_SAMPLE, MAX_STRAIN]);
            assert!(points.len() <= MAX_KNOTS + 4, "{} knots", points.len());
            assert!(points.windows(2).all(|w| w[1][0] > w[0][0]), "knots increase");
        }
    }
}
