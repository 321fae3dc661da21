//! What each test rig measures, as one typed struct per rig.
//!
//! The scene kinds' rigs (`kinds/`) fill these in; the metrics JSON (`rosette run --metrics`), the
//! viewer's plots and CSV export, the chart, the bench and the tests read their fields, so
//! that a misspelt measure is a compile error rather than an empty plot. The JSON is the
//! serde form of these structs: each rig's measures are one object whose keys are the field
//! names. The fields are declared in alphabetical order, the order the keys had when the
//! measures were built as JSON maps, so files written before and after read the same; the
//! CSV export and the viewer's list of measures follow the same order.
//!
//! Units are SI as in the rest of the crate: stress and force per unit width in N/m,
//! lengths in m, angles in degrees where the name says so.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A rig's measurements at one moment (`Scene::measures`), serialised without a tag: the
/// JSON object is the variant's struct, and reading one back picks the variant whose
/// required fields are present (no two rigs share one).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Measures {
    Tensile(TensileMeasures),
    Cantilever(CantileverMeasures),
    Arc(ArcMeasures),
    Euler(EulerMeasures),
    Shear(ShearMeasures),
    /// Before `Drape`: a garment's JSON holds fields no drape has, a drape's lacks them.
    Garment(GarmentMeasures),
    Swing(SwingMeasures),
    Drape(DrapeMeasures),
}

/// The strip pull (paper Fig. 4–5): stress against strain as an extensometer and the
/// clamps see it, and the lateral contraction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TensileMeasures {
    /// (clamp strain, stress N/m): the strain from the clamps' separation.
    pub clamp_stress_strain: Vec<[f64; 2]>,
    /// Extensometer strain at the last sample.
    pub final_strain: f64,
    /// Stress at the last sample, N/m.
    pub final_stress: f64,
    /// (extensometer strain, lateral strain of the middle cross-section).
    pub lateral_strain: Vec<[f64; 2]>,
    /// −lateral strain over extensometer strain at the last sample (0 before any pull).
    pub poisson_ratio: f64,
    /// How strain and stress are taken ([`TensileMeasures::STRAIN_DEFINITION`]).
    pub strain_definition: String,
    /// (extensometer strain, stress N/m), a few dozen points evenly spaced in time.
    pub stress_strain: Vec<[f64; 2]>,
}

impl TensileMeasures {
    pub const STRAIN_DEFINITION: &str =
        "extensometer over the central half of the gauge length; stress = moving-clamp force / initial width";
}

/// The strip clamped horizontally and bending under its own weight (ASTM D1388).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CantileverMeasures {
    /// (B_θ / w)^(1/3), the bending length of the standard, m.
    pub bending_length: f64,
    /// Angle below the horizontal of the chord from the clamp to the tip, degrees.
    pub chord_angle_deg: f64,
    /// λ = w L³ / B_θ, the heavy elastica's one parameter.
    pub lambda: f64,
    /// Angle below the horizontal of the strip at its tip, degrees.
    pub tip_angle_deg: f64,
    /// How far the tip fell below the clamp, m.
    pub tip_drop: f64,
    /// Horizontal distance of the tip from the clamp line, m.
    pub tip_reach: f64,
}

/// Pure bending between rigid grips (KES-B style).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ArcMeasures {
    /// Curvature of a circle fitted to the middle half of the centre line, 1/m (0 when no
    /// circle fits).
    pub curvature: f64,
    /// Bending moment per unit width at midspan, N·m/m.
    pub moment: f64,
    /// Moment over curvature, N·m; absent while the strip is straight (JSON has no
    /// infinity, and a null would pass for a number).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rigidity: Option<f64>,
}

/// Euler buckling of a strip compressed between pinned ends (paper Figs. 7–8).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EulerMeasures {
    /// Speed at which the ends approach each other, m/s.
    pub compression_speed: f64,
    /// End force when the strip first buckled (see `critical_load_definition`), N/m;
    /// absent until it has.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub critical_load: Option<f64>,
    /// [`EulerMeasures::CRITICAL_LOAD_DEFINITION`].
    pub critical_load_definition: String,
    /// (end shortening Δ/L, end force N/m) of the samples that were not quasi-static,
    /// at most about a hundred.
    pub dynamic_force: Vec<[f64; 2]>,
    /// End force at the last sample, N/m.
    pub end_force: f64,
    /// End shortening Δ/L at the last sample.
    pub end_shortening: f64,
    /// The pinned strip's Euler load π²B_θ/L², N/m.
    pub euler_load: f64,
    /// (t s, end shortening Δ/L, end force N/m, amplitude m), at most about a hundred rows.
    pub force_history: Vec<[f64; 4]>,
    /// (t s, lobes) at each change of the number of lobes.
    pub lobe_history: Vec<(f64, usize)>,
    /// Half waves of the centre line at the last sample.
    pub lobes: usize,
    /// Normal deflection of the centre line at midspan, m.
    pub midspan_deflection: f64,
    /// Out-of-balance load at the last sample (see `out_of_balance_definition`).
    pub out_of_balance: f64,
    /// [`EulerMeasures::OUT_OF_BALANCE_DEFINITION`].
    pub out_of_balance_definition: String,
    /// (end shortening Δ/L, end force N/m) of the quasi-static samples (out of balance
    /// under `kinds::euler::QUASI_STATIC_IMBALANCE`), at most about a hundred.
    pub quasi_static_force: Vec<[f64; 2]>,
}

impl EulerMeasures {
    pub const CRITICAL_LOAD_DEFINITION: &str = "end force when the largest normal deflection first exceeds 5 % of the length";
    pub const OUT_OF_BALANCE_DEFINITION: &str =
        "sum of |force| on the free vertices over the Euler load's total P_cr·w; 0 in static equilibrium";
}

/// Shear buckling: one edge clamped, the other moved along the warp (paper Figs. 9–10).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ShearMeasures {
    /// Angle of the cross direction from its rest direction, degrees.
    pub shear_angle_deg: f64,
    /// Largest normal deflection in the central region, m.
    pub wrinkle_amplitude: f64,
    /// Direction of the wrinkle crests from the warp, degrees in [0, 180); not measured
    /// (NaN, left out of the JSON) where there are no wrinkles (`possible::judge`).
    #[serde(default = "not_measured", skip_serializing_if = "is_not_measured")]
    pub wrinkle_angle_deg: f64,
    /// Wrinkles crossed by a line through the centre across the crests.
    pub wrinkle_count: usize,
    /// Wavelength along that line, m (0 with fewer than two half waves).
    pub wrinkle_wavelength: f64,
}

/// The Cusick drape (paper Fig. 6; BS 5058) and other drapes over a support.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DrapeMeasures {
    /// (A_shadow − A_support) / (A_specimen − A_support); not measured (NaN, left out of
    /// the JSON) where it falls outside [0, 1], a cloth that has not draped
    /// (`possible::judge`).
    #[serde(default = "not_measured", skip_serializing_if = "is_not_measured")]
    pub drape_coefficient: f64,
    /// (t s, drape coefficient, nodes) while the cloth drapes, at most about a hundred rows.
    pub history: Vec<(f64, f64, usize)>,
    /// Folds (nodes) of the shadow's outline.
    pub nodes: usize,
    /// Largest radius of the shadow's outline from the support's centre, m.
    pub outline_radius_max: f64,
    /// Smallest radius of the outline, m; absent when the outline is empty.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outline_radius_min: Option<f64>,
    /// Area of the vertical projection of the cloth, m².
    pub shadow_area: f64,
    /// Area of the flat specimen, m².
    pub specimen_area: f64,
    /// Area of the support (pedestal disc or table top), m².
    pub support_area: f64,
}

/// A measure that was not taken: NaN in memory, absent from the JSON (a null would pass
/// for a number).
fn not_measured() -> f64 {
    f64::NAN
}

fn is_not_measured(value: &f64) -> bool {
    value.is_nan()
}

/// One number among a rig's measures: a real value or a count, kept apart so that text
/// writes a count as an integer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scalar {
    Real(f64),
    Count(usize),
}

impl Scalar {
    pub fn value(self) -> f64 {
        match self {
            Scalar::Real(x) => x,
            Scalar::Count(n) => n as f64,
        }
    }
}

impl fmt::Display for Scalar {
    /// As the metrics JSON writes it (`0.5`, `0.00001`, `2.0`), an integer for a count.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Scalar::Count(n) => write!(f, "{n}"),
            Scalar::Real(x) => match serde_json::Number::from_f64(x) {
                Some(number) => write!(f, "{number}"),
                None => write!(f, "{x}"),
            },
        }
    }
}

/// One of a rig's series: rows of numbers under named columns (with units).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The measure's name (its JSON key).
    pub name: &'static str,
    /// Column names, one per value of a row.
    pub columns: &'static [&'static str],
    pub rows: Vec<Vec<f64>>,
}

fn series<const N: usize>(name: &'static str, columns: &'static [&'static str; N], rows: &[[f64; N]]) -> Series {
    Series { name, columns, rows: rows.iter().map(|r| r.to_vec()).collect() }
}

impl Measures {
    pub fn tensile(&self) -> Option<&TensileMeasures> {
        if let Measures::Tensile(m) = self { Some(m) } else { None }
    }

    pub fn cantilever(&self) -> Option<&CantileverMeasures> {
        if let Measures::Cantilever(m) = self { Some(m) } else { None }
    }

    pub fn arc(&self) -> Option<&ArcMeasures> {
        if let Measures::Arc(m) = self { Some(m) } else { None }
    }

    pub fn euler(&self) -> Option<&EulerMeasures> {
        if let Measures::Euler(m) = self { Some(m) } else { None }
    }

    pub fn shear(&self) -> Option<&ShearMeasures> {
        if let Measures::Shear(m) = self { Some(m) } else { None }
    }

    pub fn drape(&self) -> Option<&DrapeMeasures> {
        if let Measures::Drape(m) = self { Some(m) } else { None }
    }

    pub fn garment(&self) -> Option<&GarmentMeasures> {
        if let Measures::Garment(m) = self { Some(m) } else { None }
    }

    pub fn swing(&self) -> Option<&SwingMeasures> {
        if let Measures::Swing(m) = self { Some(m) } else { None }
    }

    /// The scalar measures that have a finite value now, by name, in the JSON's key order
    /// (definitions, which are text, and series are left out).
    pub fn scalars(&self) -> Vec<(&'static str, Scalar)> {
        use Scalar::{Count, Real};
        let all: Vec<(&'static str, Option<Scalar>)> = match self {
            Measures::Tensile(m) => vec![
                ("final_strain", Some(Real(m.final_strain))),
                ("final_stress", Some(Real(m.final_stress))),
                ("poisson_ratio", Some(Real(m.poisson_ratio))),
            ],
            Measures::Cantilever(m) => vec![
                ("bending_length", Some(Real(m.bending_length))),
                ("chord_angle_deg", Some(Real(m.chord_angle_deg))),
                ("lambda", Some(Real(m.lambda))),
                ("tip_angle_deg", Some(Real(m.tip_angle_deg))),
                ("tip_drop", Some(Real(m.tip_drop))),
                ("tip_reach", Some(Real(m.tip_reach))),
            ],
            Measures::Arc(m) => vec![
                ("curvature", Some(Real(m.curvature))),
                ("moment", Some(Real(m.moment))),
                ("rigidity", m.rigidity.map(Real)),
            ],
            Measures::Euler(m) => vec![
                ("compression_speed", Some(Real(m.compression_speed))),
                ("critical_load", m.critical_load.map(Real)),
                ("end_force", Some(Real(m.end_force))),
                ("end_shortening", Some(Real(m.end_shortening))),
                ("euler_load", Some(Real(m.euler_load))),
                ("lobes", Some(Count(m.lobes))),
                ("midspan_deflection", Some(Real(m.midspan_deflection))),
                ("out_of_balance", Some(Real(m.out_of_balance))),
            ],
            Measures::Shear(m) => vec![
                ("shear_angle_deg", Some(Real(m.shear_angle_deg))),
                ("wrinkle_amplitude", Some(Real(m.wrinkle_amplitude))),
                ("wrinkle_angle_deg", Some(Real(m.wrinkle_angle_deg))),
                ("wrinkle_count", Some(Count(m.wrinkle_count))),
                ("wrinkle_wavelength", Some(Real(m.wrinkle_wavelength))),
            ],
            Measures::Drape(m) => vec![
                ("drape_coefficient", Some(Real(m.drape_coefficient))),
                ("nodes", Some(Count(m.nodes))),
                ("outline_radius_max", Some(Real(m.outline_radius_max))),
                ("outline_radius_min", m.outline_radius_min.map(Real)),
                ("shadow_area", Some(Real(m.shadow_area))),
                ("specimen_area", Some(Real(m.specimen_area))),
                ("support_area", Some(Real(m.support_area))),
            ],
            Measures::Garment(m) => vec![
                ("garment_drape_coefficient", Some(Real(m.garment_drape_coefficient))),
                ("hem_height_max", Some(Real(m.hem_height_max))),
                ("hem_height_mean", Some(Real(m.hem_height_mean))),
                ("hem_height_min", Some(Real(m.hem_height_min))),
                ("hem_height_spread", Some(Real(m.hem_height_spread))),
                ("hem_nodes", Some(Count(m.hem_nodes))),
                ("hem_radius_max", Some(Real(m.hem_radius_max))),
                ("hem_radius_min", Some(Real(m.hem_radius_min))),
                ("open_seam_gap", Some(Real(m.open_seam_gap))),
                ("panels", Some(Count(m.panels))),
                ("pattern_area", Some(Real(m.pattern_area))),
                ("seam_gap_at_weld", m.seam_gap_at_weld.map(Real)),
                ("seam_pairs", Some(Count(m.seam_pairs))),
                ("sewn_at", m.sewn_at.map(Real)),
                ("shadow_area", Some(Real(m.shadow_area))),
                ("waist_area", Some(Real(m.waist_area))),
            ],
            Measures::Swing(m) => vec![
                ("chain_period", Some(Real(m.chain_period))),
                ("half_periods", Some(Count(m.half_periods))),
                ("swing_period", m.swing_period.map(Real)),
            ],
        };
        all.into_iter().filter_map(|(name, value)| Some((name, value.filter(|v| v.value().is_finite())?))).collect()
    }

    /// The scalar measure `name`, if the rig has it and it has a finite value now.
    pub fn scalar(&self, name: &str) -> Option<f64> {
        self.scalars().into_iter().find(|(n, _)| *n == name).map(|(_, v)| v.value())
    }

    /// The rig's series with their columns, in the JSON's key order.
    pub fn series(&self) -> Vec<Series> {
        const STRESS_STRAIN: [&str; 2] = ["strain", "stress_N_per_m"];
        const FORCE: [&str; 2] = ["end_shortening", "end_force_N_per_m"];
        match self {
            Measures::Tensile(m) => vec![
                series("clamp_stress_strain", &["clamp_strain", "stress_N_per_m"], &m.clamp_stress_strain),
                series("lateral_strain", &["strain", "lateral_strain"], &m.lateral_strain),
                series("stress_strain", &STRESS_STRAIN, &m.stress_strain),
            ],
            Measures::Euler(m) => {
                let lobes: Vec<[f64; 2]> = m.lobe_history.iter().map(|&(t, n)| [t, n as f64]).collect();
                vec![
                    series("dynamic_force", &FORCE, &m.dynamic_force),
                    series("force_history", &["time_s", "end_shortening", "end_force_N_per_m", "amplitude_m"], &m.force_history),
                    series("lobe_history", &["time_s", "lobes"], &lobes),
                    series("quasi_static_force", &FORCE, &m.quasi_static_force),
                ]
            }
            Measures::Drape(m) => {
                let rows: Vec<[f64; 3]> = m.history.iter().map(|&(t, dc, nodes)| [t, dc, nodes as f64]).collect();
                vec![series("history", &["time_s", "drape_coefficient", "nodes"], &rows)]
            }
            Measures::Swing(m) => vec![series("bottom_history", &["time_s", "displacement_m"], &m.bottom_history)],
            Measures::Cantilever(_) | Measures::Arc(_) | Measures::Shear(_) | Measures::Garment(_) => Vec::new(),
        }
    }
}

/// What the swing measures.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SwingMeasures {
    /// (time s, mean sideways displacement of the free edge m).
    pub bottom_history: Vec<[f64; 2]>,
    /// The hanging chain's first-mode period for the strip's length, s.
    pub chain_period: f64,
    /// Half periods between the free edge's zero crossings that were measured.
    pub half_periods: usize,
    /// The period measured, twice the mean time between zero crossings, s; None with fewer
    /// than two half periods (a run too short to tell).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swing_period: Option<f64>,
}

/// A garment's measurements, SI units (m, m², s).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GarmentMeasures {
    /// (A_shadow − A_waist) / (A_pattern + A_waist − A_waist): the Cusick drape coefficient
    /// with the form's section at the waist as the support and the flat pattern around it
    /// as the specimen (a full-circle skirt's is exactly Cusick's).
    pub garment_drape_coefficient: f64,
    /// Height of the hem above the floor: mean, lowest, highest, and its standard
    /// deviation (the hem's evenness), m.
    pub hem_height_max: f64,
    pub hem_height_mean: f64,
    pub hem_height_min: f64,
    pub hem_height_spread: f64,
    /// Folds (nodes) of the shadow's outline around the form's axis.
    pub hem_nodes: usize,
    /// Largest and smallest radius of the shadow's outline from the form's axis, m.
    pub hem_radius_max: f64,
    pub hem_radius_min: f64,
    /// Largest distance between a seam's vertex pairs now, m (zero once welded).
    pub open_seam_gap: f64,
    /// Pattern pieces, and vertex pairs along the seams.
    pub panels: usize,
    /// Area of the flat pattern, m².
    pub pattern_area: f64,
    /// Largest distance between seam pairs when they were welded, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seam_gap_at_weld: Option<f64>,
    pub seam_pairs: usize,
    /// Per seam: its length along side a now, and the rest lengths of sides a and b, m.
    pub seams: Vec<[f64; 3]>,
    /// Whether every seam was closed and welded.
    pub sewn: bool,
    /// When the seams were welded, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sewn_at: Option<f64>,
    /// Area of the garment's vertical projection together with the form's waist section, m².
    pub shadow_area: f64,
    /// Area of the form's section the drape coefficient is taken against, m².
    pub waist_area: f64,
    /// Why the garment is not hanging on its form (slid off, fallen, inside it), where it
    /// is not: its drape measures are then withheld (null).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub off_form: Option<String>,
}

impl GarmentMeasures {
    /// Withholds the measures of a garment hanging on its form, saying why (`reason`).
    pub fn withhold(&mut self, reason: String) {
        for value in [
            &mut self.garment_drape_coefficient,
            &mut self.hem_height_max,
            &mut self.hem_height_mean,
            &mut self.hem_height_min,
            &mut self.hem_height_spread,
            &mut self.hem_radius_max,
            &mut self.hem_radius_min,
            &mut self.shadow_area,
        ] {
            *value = f64::NAN;
        }
        self.hem_nodes = 0;
        self.off_form = Some(reason);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One of each rig's measures, every optional value present.
    fn every_rig() -> Vec<Measures> {
        vec![
            Measures::Tensile(TensileMeasures { strain_definition: TensileMeasures::STRAIN_DEFINITION.into(), ..Default::default() }),
            Measures::Cantilever(CantileverMeasures::default()),
            Measures::Arc(ArcMeasures { rigidity: Some(1.0), ..Default::default() }),
            Measures::Euler(EulerMeasures { critical_load: Some(1.0), ..Default::default() }),
            Measures::Shear(ShearMeasures::default()),
            Measures::Drape(DrapeMeasures { outline_radius_min: Some(1.0), ..Default::default() }),
        ]
    }

    #[test]
    fn scalars_and_series_name_the_json_keys_in_their_order() {
        for measures in every_rig() {
            let text = serde_json::to_string(&measures).unwrap();
            let value: serde_json::Value = serde_json::from_str(&text).unwrap();
            let object = value.as_object().unwrap();
            // The keys as written, in the struct's order, are sorted (the map's order).
            let written: Vec<&String> = object.keys().collect();
            let positions: Vec<usize> = written.iter().map(|k| text.find(&format!("\"{k}\":")).unwrap()).collect();
            assert!(positions.is_sorted(), "{measures:?}: fields not declared in alphabetical order");
            let numbers: Vec<&str> = object.iter().filter(|(_, v)| v.is_number()).map(|(k, _)| k.as_str()).collect();
            let scalars: Vec<&str> = measures.scalars().iter().map(|s| s.0).collect();
            assert_eq!(scalars, numbers);
            let arrays: Vec<&str> = object.iter().filter(|(_, v)| v.is_array()).map(|(k, _)| k.as_str()).collect();
            let series: Vec<&str> = measures.series().iter().map(|s| s.name).collect();
            assert_eq!(series, arrays);
        }
    }

    #[test]
    fn each_rig_reads_back_as_itself() {
        for measures in every_rig() {
            let back: Measures = serde_json::from_str(&serde_json::to_string(&measures).unwrap()).unwrap();
            assert_eq!(back, measures);
        }
        // A missing optional value is left out of the JSON (a null would pass for a number)
        // and reads back as absent.
        let arc = Measures::Arc(ArcMeasures { curvature: 0.0, moment: 0.0, rigidity: None });
        let text = serde_json::to_string(&arc).unwrap();
        assert_eq!(text, r#"{"curvature":0.0,"moment":0.0}"#);
        assert_eq!(serde_json::from_str::<Measures>(&text).unwrap(), arc);
    }

    #[test]
    fn scalars_leave_out_what_has_no_finite_value_and_print_as_the_json_does() {
        let drape = Measures::Drape(DrapeMeasures { nodes: 7, outline_radius_max: 0.25, ..Default::default() });
        let scalars = drape.scalars();
        assert!(scalars.iter().all(|s| s.0 != "outline_radius_min"));
        assert_eq!(drape.scalar("nodes"), Some(7.0));
        for (_, value) in scalars {
            let json = match value {
                Scalar::Real(x) => serde_json::to_string(&x).unwrap(),
                Scalar::Count(n) => serde_json::to_string(&n).unwrap(),
            };
            assert_eq!(value.to_string(), json);
        }
        assert_eq!(Scalar::Real(1e-5).to_string(), serde_json::to_string(&1e-5).unwrap());
        let cantilever = Measures::Cantilever(CantileverMeasures { tip_angle_deg: f64::NAN, ..Default::default() });
        assert_eq!(cantilever.scalar("tip_angle_deg"), None);
        assert_eq!(cantilever.scalar("tip_drop"), Some(0.0));
    }
}
