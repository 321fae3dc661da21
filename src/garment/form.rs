//! The dress form: a torso generated from body measurements (bust, waist and hip girths
//! and their heights), or any closed OBJ body, as a parry3d mesh prop.
//!
//! The generated form stacks horizontal elliptical sections through the measured levels
//! (hip, waist, bust) and the neck and shoulders, each section's perimeter equal to the
//! girth measured there; between levels the half-widths and half-depths follow monotone
//! cubic curves, so that the waist is a smooth minimum and the hip a smooth maximum. The
//! size table and the sources of its values are in docs/garments.md.

use super::GarmentError;
use super::pattern::Units;
use serde::{Deserialize, Serialize};

/// Body measurements of a standard size, m.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Measurements {
    pub bust_girth: f64,
    pub waist_girth: f64,
    pub hip_girth: f64,
    /// Heights above the floor.
    pub bust_height: f64,
    pub waist_height: f64,
    pub hip_height: f64,
    /// Nape (back neck point) to waist, down the back: the torso length.
    pub torso_length: f64,
    /// Base of the neck around.
    pub neck_girth: f64,
    /// Across the back from shoulder point to shoulder point.
    pub shoulder_width: f64,
}

impl Measurements {
    /// The height of a named level of the form (`waist`, `hip` or `bust`), m; None for
    /// another name.
    pub fn level(&self, name: &str) -> Option<f64> {
        match name {
            "waist" => Some(self.waist_height),
            "hip" => Some(self.hip_height),
            "bust" => Some(self.bust_height),
            _ => None,
        }
    }
}

/// The bundled sizes, in metres (sources in docs/garments.md: girths and lengths of the
/// UK women's sizes 10, 12 and 14 as tabulated by Aldrich, whose bust girths step by 4 cm
/// as BS EN 13402-3's size designations do; heights derived from the same chart).
pub const SIZES: &[(&str, Measurements)] = &[
    ("uk-10", size(0.84, 0.64, 0.90, 0.360)),
    ("uk-12", size(0.88, 0.68, 0.94, 0.370)),
    ("uk-14", size(0.92, 0.72, 0.98, 0.380)),
];

/// A size from its three girths and neck girth; the vertical measures of the chart's
/// 164–168 cm figure (waist 104 cm above the floor, waist to hip 20.6 cm, nape to waist
/// 41 cm), the bust point taken 18 cm above the waist, and a shoulder width of 35.5 cm.
const fn size(bust: f64, waist: f64, hip: f64, neck: f64) -> Measurements {
    Measurements {
        bust_girth: bust,
        waist_girth: waist,
        hip_girth: hip,
        bust_height: 1.22,
        waist_height: 1.04,
        hip_height: 1.04 - 0.206,
        torso_length: 0.41,
        neck_girth: neck,
        shoulder_width: 0.355,
    }
}

/// `[garment.form]`: a standard size, measurements of one's own, or an OBJ body.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormConfig {
    /// A bundled size (`uk-10`, `uk-12`, `uk-14`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<String>,
    /// Measurements in the garment's units instead of a size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measurements: Option<Measurements>,
    /// An OBJ body instead of a generated form (read as `[[props]]` meshes are: a path
    /// relative to the scene file), scaled by `scale`; its floor is z = 0 and its axis the
    /// vertical through `axis`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obj: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Where the form's vertical axis stands, [x, y] in the garment's units.
    #[serde(default)]
    pub axis: [f64; 2],
}

impl FormConfig {
    /// The form's measurements in metres (None for an OBJ body).
    pub fn measurements(&self, units: Units) -> Result<Option<Measurements>, GarmentError> {
        let bad = |m: String| GarmentError::new(format!("garment.form: {m}"));
        match (&self.size, &self.measurements, &self.obj) {
            (Some(name), None, None) => SIZES.iter().find(|(n, _)| n == name).map(|(_, m)| Some(*m)).ok_or_else(|| {
                bad(format!("no size '{name}'; bundled sizes: {}", SIZES.iter().map(|s| s.0).collect::<Vec<_>>().join(", ")))
            }),
            (None, Some(m), None) => {
                let k = units.metres();
                let m = Measurements {
                    bust_girth: m.bust_girth * k,
                    waist_girth: m.waist_girth * k,
                    hip_girth: m.hip_girth * k,
                    bust_height: m.bust_height * k,
                    waist_height: m.waist_height * k,
                    hip_height: m.hip_height * k,
                    torso_length: m.torso_length * k,
                    neck_girth: m.neck_girth * k,
                    shoulder_width: m.shoulder_width * k,
                };
                check_measurements(&m, units).map_err(bad)?;
                Ok(Some(m))
            }
            (None, None, Some(_)) => Ok(None),
            _ => Err(bad("give exactly one of size, measurements or obj".into())),
        }
    }
}

fn check_measurements(m: &Measurements, units: Units) -> Result<(), String> {
    let k = units.metres();
    let fields = [
        ("bust_girth", m.bust_girth),
        ("waist_girth", m.waist_girth),
        ("hip_girth", m.hip_girth),
        ("bust_height", m.bust_height),
        ("waist_height", m.waist_height),
        ("hip_height", m.hip_height),
        ("torso_length", m.torso_length),
        ("neck_girth", m.neck_girth),
        ("shoulder_width", m.shoulder_width),
    ];
    for (key, v) in fields {
        if !(v.is_finite() && v > 0.01 && v < 5.0) {
            return Err(format!("measurements.{key} = {} {} must be a body measurement between 1 cm and 5 m", v / k, units.name()));
        }
    }
    if !(m.hip_height < m.waist_height && m.waist_height < m.bust_height) {
        return Err("measurements: the heights must rise from hip to waist to bust".into());
    }
    if m.neck_girth >= m.waist_girth || m.waist_girth >= m.bust_girth.max(m.hip_girth) {
        return Err("measurements: the waist must be narrower than the bust or the hip, and the neck than the waist".into());
    }
    check_proportions(m, units)
}

/// The checks between fields, which the form's sections need in order: the shoulders
/// (`SHOULDER_DROP` under the nape) above the top of the bust (`BUST_TOP` over the bust
/// point), shoulders no wider than half the bust girth (the back's share of it), the
/// nape within a standing body's height, the hip section under it above the floor.
fn check_proportions(m: &Measurements, units: Units) -> Result<(), String> {
    let k = units.metres();
    let shown = |v: f64| format!("{} {}", crate::io::number::short(v / k), units.name());
    let nape = m.waist_height + m.torso_length;
    let least_torso = m.bust_height - m.waist_height + BUST_TOP + SHOULDER_DROP + 0.01;
    if m.torso_length < least_torso {
        return Err(format!(
            "measurements.torso_length = {} is shorter than the bust point's height over the waist ({}) and the shoulders above it need: \
             give at least {}, or lower bust_height",
            shown(m.torso_length),
            shown(m.bust_height - m.waist_height),
            shown(least_torso)
        ));
    }
    if m.shoulder_width > 0.5 * m.bust_girth {
        return Err(format!(
            "measurements.shoulder_width = {} is more than half the bust girth ({}): the back would be wider than the body around it; \
             measure from shoulder point to shoulder point across the back",
            shown(m.shoulder_width),
            shown(0.5 * m.bust_girth)
        ));
    }
    if nape > MAX_NAPE_HEIGHT {
        return Err(format!(
            "measurements: waist_height + torso_length = {} puts the nape higher than a standing body's ({}); check the units ({})",
            shown(nape),
            shown(MAX_NAPE_HEIGHT),
            units.name()
        ));
    }
    if m.hip_height < HIP_DEPTH + 0.01 {
        return Err(format!("measurements.hip_height = {} leaves no room for the form under the hip; give at least {}", shown(m.hip_height), shown(HIP_DEPTH + 0.01)));
    }
    Ok(())
}

/// The form's sections past the measured ones: the top of the bust over the bust point,
/// the shoulders under the nape, the form's lowest section under the hip, m.
const BUST_TOP: f64 = 0.08;
const SHOULDER_DROP: f64 = 0.045;
const HIP_DEPTH: f64 = 0.16;
/// The nape of a standing body 2.7 m tall (beyond the tallest recorded).
const MAX_NAPE_HEIGHT: f64 = 2.3;

/// One horizontal section of the form: its height and half-axes along x (across the body)
/// and y (front to back), m.
#[derive(Debug, Clone, Copy)]
struct Section {
    z: f64,
    half_width: f64,
    half_depth: f64,
}

/// Half-width of an ellipse with this perimeter (m) and depth/width ratio, by Ramanujan's
/// second approximation of the perimeter (relative error below 1e-9 for these ratios).
fn half_width(perimeter: f64, ratio: f64) -> f64 {
    let h = ((1.0 - ratio) / (1.0 + ratio)).powi(2);
    perimeter / (std::f64::consts::PI * (1.0 + ratio) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt())))
}

/// Depth over width of the sections at the hip, waist and bust (a chosen shape, not part
/// of the size chart: dress forms are about this much deeper than a circle is not).
const SECTION_RATIO: f64 = 0.78;

fn sections(m: &Measurements) -> Vec<Section> {
    let ellipse = |z: f64, girth: f64, ratio: f64| {
        let a = half_width(girth, ratio);
        Section { z, half_width: a, half_depth: ratio * a }
    };
    let neck_base = m.waist_height + m.torso_length;
    let neck_radius = m.neck_girth / std::f64::consts::TAU;
    vec![
        ellipse(m.hip_height - HIP_DEPTH, 0.93 * m.hip_girth, SECTION_RATIO),
        ellipse(m.hip_height, m.hip_girth, SECTION_RATIO),
        ellipse(m.waist_height, m.waist_girth, SECTION_RATIO),
        ellipse(m.bust_height, m.bust_girth, SECTION_RATIO),
        ellipse(m.bust_height + BUST_TOP, 0.96 * m.bust_girth, 0.72),
        Section { z: neck_base - SHOULDER_DROP, half_width: 0.5 * m.shoulder_width, half_depth: 0.055 },
        Section { z: neck_base, half_width: neck_radius, half_depth: neck_radius },
        Section { z: neck_base + 0.07, half_width: neck_radius, half_depth: neck_radius },
    ]
}

/// Fritsch–Carlson monotone cubic through (x_i, y_i), evaluated at `x`.
fn monotone_cubic(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let n = xs.len();
    let i = xs.partition_point(|&v| v <= x).clamp(1, n - 1) - 1;
    let slope = |k: usize| (ys[k + 1] - ys[k]) / (xs[k + 1] - xs[k]);
    let tangent = |k: usize| {
        if k == 0 || k == n - 1 {
            return 0.0;
        }
        let (a, b) = (slope(k - 1), slope(k));
        if a * b <= 0.0 { 0.0 } else { 2.0 * a * b / (a + b) }
    };
    let h = xs[i + 1] - xs[i];
    let t = ((x - xs[i]) / h).clamp(0.0, 1.0);
    let (t2, t3) = (t * t, t * t * t);
    (2.0 * t3 - 3.0 * t2 + 1.0) * ys[i] + (t3 - 2.0 * t2 + t) * h * tangent(i) + (-2.0 * t3 + 3.0 * t2) * ys[i + 1] + (t3 - t2) * h * tangent(i + 1)
}

/// Segments around each ring of the generated form.
const RING_SEGMENTS: usize = 72;
/// Height between rings, m.
const RING_SPACING: f64 = 0.01;

/// The generated form's closed, outward-oriented surface (axis at the origin, floor z = 0).
pub fn form_mesh(m: &Measurements) -> (Vec<glam::DVec3>, Vec<[u32; 3]>) {
    let sections = sections(m);
    let zs: Vec<f64> = sections.iter().map(|s| s.z).collect();
    let widths: Vec<f64> = sections.iter().map(|s| s.half_width).collect();
    let depths: Vec<f64> = sections.iter().map(|s| s.half_depth).collect();
    let (bottom, top) = (zs[0], *zs.last().unwrap());
    let rings = ((top - bottom) / RING_SPACING).ceil() as usize;
    let mut vertices = vec![glam::DVec3::new(0.0, 0.0, bottom)];
    for r in 0..=rings {
        let z = bottom + (top - bottom) * r as f64 / rings as f64;
        let (a, b) = (monotone_cubic(&zs, &widths, z), monotone_cubic(&zs, &depths, z));
        for k in 0..RING_SEGMENTS {
            let t = std::f64::consts::TAU * k as f64 / RING_SEGMENTS as f64;
            vertices.push(glam::DVec3::new(a * t.cos(), b * t.sin(), z));
        }
    }
    vertices.push(glam::DVec3::new(0.0, 0.0, top));
    let ring = |r: usize, k: usize| (1 + r * RING_SEGMENTS + k % RING_SEGMENTS) as u32;
    let mut triangles = Vec::new();
    for k in 0..RING_SEGMENTS {
        triangles.push([0, ring(0, k + 1), ring(0, k)]);
        let apex = vertices.len() as u32 - 1;
        triangles.push([apex, ring(rings, k), ring(rings, k + 1)]);
    }
    for r in 0..rings {
        for k in 0..RING_SEGMENTS {
            triangles.push([ring(r, k), ring(r, k + 1), ring(r + 1, k + 1)]);
            triangles.push([ring(r, k), ring(r + 1, k + 1), ring(r + 1, k)]);
        }
    }
    (vertices, triangles)
}

/// The girth of a generated form's section at height `z` (m): the perimeter of its ellipse.
pub fn girth_at(m: &Measurements, z: f64) -> f64 {
    let sections = sections(m);
    let zs: Vec<f64> = sections.iter().map(|s| s.z).collect();
    let a = monotone_cubic(&zs, &sections.iter().map(|s| s.half_width).collect::<Vec<_>>(), z);
    let b = monotone_cubic(&zs, &sections.iter().map(|s| s.half_depth).collect::<Vec<_>>(), z);
    let h = ((a - b) / (a + b)).powi(2);
    std::f64::consts::PI * (a + b) * (1.0 + 3.0 * h / (10.0 + (4.0 - 3.0 * h).sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sections through the measured levels have the measured girths: the polygon of
    /// the mesh's ring there, summed edge by edge, against the size chart.
    #[test]
    fn the_form_has_the_measured_girths() {
        for (name, m) in SIZES {
            let (vertices, _) = form_mesh(m);
            for (level, z, girth) in [("hip", m.hip_height, m.hip_girth), ("waist", m.waist_height, m.waist_girth), ("bust", m.bust_height, m.bust_girth)] {
                // The ring nearest the level (rings are 1 cm apart; the girth is an extremum
                // or varies slowly there).
                let ring: Vec<_> = vertices.iter().filter(|v| (v.z - z).abs() < 0.5 * RING_SPACING + 1e-9).take(RING_SEGMENTS).collect();
                assert_eq!(ring.len(), RING_SEGMENTS, "{name} {level}");
                let perimeter: f64 = (0..RING_SEGMENTS).map(|k| ring[k].distance(*ring[(k + 1) % RING_SEGMENTS])).sum();
                // A 72-gon inscribed in the ellipse is about 0.1 % short of it; the ring may
                // sit up to half a centimetre off the level.
                assert!((perimeter / girth - 1.0).abs() < 0.01, "{name} {level}: {perimeter} vs {girth}");
            }
        }
    }

    /// Measurements that each lie in a body's range but contradict each other are refused,
    /// naming the field; every bundled size passes, and every accepted form is finite.
    #[test]
    fn measurements_that_contradict_each_other_are_refused() {
        for (name, m) in SIZES {
            check_measurements(m, Units::M).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let base = SIZES[0].1;
        let cases: [(&str, Measurements); 4] = [
            ("torso_length", Measurements { torso_length: 0.15, ..base }),
            ("shoulder_width", Measurements { shoulder_width: 0.6, ..base }),
            ("nape", Measurements { waist_height: 2.0, bust_height: 2.2, hip_height: 1.8, ..base }),
            ("hip_height", Measurements { hip_height: 0.1, ..base }),
        ];
        for (field, m) in cases {
            let err = check_measurements(&m, Units::M).unwrap_err();
            assert!(err.contains(field), "{field}: {err}");
        }
        let (vertices, _) = form_mesh(&base);
        assert!(vertices.iter().all(|v| v.is_finite()));
    }
}
