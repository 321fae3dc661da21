//! The units of the textile laboratories' sheets and their factors to SI.
//!
//! Every factor is exact: the gram-force is defined through standard gravity
//! (1 gf = 9.80665e-3 N), so each KES unit converts exactly; FAST reports SI already.
//! docs/fabric-sheets.md lists the same table for users; docs/references.md §8 gives the
//! definitions behind it.
//!
//! A sheet value is either a bare number, read in the standard's own unit for that field,
//! or a string "VALUE UNIT" (`"137 g/m²"`, `"0.092 gf·cm²/cm"`, `"9 µN·m"`), read in any
//! unit of the field's quantity listed here. Unit spellings are forgiving: `²`/`2`, `µ`/`u`,
//! `·`/`.`/`*` and spaces are all accepted; case is not (`Mg/cm²` is refused, not read as
//! mg/cm²).

use std::f64::consts::PI;

// The gram-force is 1 g under standard gravity, [`crate::physics::STANDARD_GRAVITY`].
// The factors are written as the decimals they are (the nearest f64), not computed:
// 9.80665e-3 / 1e-2 in floating point is one bit off 0.980665.

/// One gram-force, N: 1e-3 kg × 9.80665 m/s².
pub const GF: f64 = 9.80665e-3;
/// KES bending rigidity: 1 gf·cm²/cm = 1 gf·cm = 9.80665e-3 N × 1e-2 m = 9.80665e-5 N·m
/// (per unit width).
pub const GF_CM2_PER_CM: f64 = 9.80665e-5;
/// Load per unit width: 1 gf/cm = 9.80665e-3 N / 1e-2 m = 0.980665 N/m.
pub const GF_PER_CM: f64 = 0.980665;
/// KES shear rigidity: 1 gf/(cm·degree) = 0.980665 × 180/π = 56.1879 N/m per radian.
pub const GF_PER_CM_DEG: f64 = GF_PER_CM * 180.0 / PI;
/// KES tensile energy: 1 gf·cm/cm² = 9.80665e-5 J / 1e-4 m² = 0.980665 J/m² (the work per
/// area, load per width times strain).
pub const GF_CM_PER_CM2: f64 = 0.980665;
/// KES moment hysteresis per unit width: 1 gf·cm/cm = 9.80665e-3 N·m/m.
pub const GF_CM_PER_CM: f64 = GF;
/// KES mass per area: 1 mg/cm² = 1e-6 kg / 1e-4 m² = 0.01 kg/m².
pub const MG_PER_CM2: f64 = 0.01;
/// FAST and ASTM mass per area: 1 g/m² = 0.001 kg/m².
pub const G_PER_M2: f64 = 1e-3;
/// 1 oz/yd² (avoirdupois ounce, international yard) = 0.0339057 kg/m².
pub const OZ_PER_YD2: f64 = 0.028_349_523_125 / 0.836_127_36;
/// ASTM D1388 flexural rigidity: 1 mg·cm (mg/cm² × cm³) = 1e-3 gf·cm = 9.80665e-8 N·m.
pub const MG_CM: f64 = 9.80665e-8;

/// What a sheet field measures; each accepts the units listed in [`Quantity::units`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Mass per area, kg/m².
    ArealDensity,
    /// Thickness or a bending length, m.
    Length,
    /// Bending rigidity per unit width, N·m.
    Bending,
    /// Moment per unit width (bending hysteresis 2HB), N·m/m.
    MomentPerWidth,
    /// Shear rigidity per radian, N/m.
    ShearRigidity,
    /// Load per unit width, N/m.
    LoadPerWidth,
    /// Tensile or compressive energy per area, J/m².
    EnergyPerArea,
    /// A percentage: strains, resilience, shrinkage. Stored as a fraction.
    Percent,
    /// A pure number (linearity LT, friction MIU).
    Ratio,
    /// An area, m² (FAST formability).
    Area,
    /// A roughness or small length in µm, m (KES SMD).
    Roughness,
}

impl Quantity {
    /// Accepted unit spellings (normalised, see [`normalise_unit`]) and their factors to SI.
    pub fn units(self) -> &'static [(&'static str, f64)] {
        match self {
            Quantity::ArealDensity => {
                &[("mg/cm2", MG_PER_CM2), ("g/m2", G_PER_M2), ("gsm", G_PER_M2), ("GSM", G_PER_M2), ("kg/m2", 1.0), ("oz/yd2", OZ_PER_YD2)]
            }
            Quantity::Length | Quantity::Roughness => &[("mm", 1e-3), ("cm", 1e-2), ("m", 1.0), ("um", 1e-6)],
            Quantity::Bending => &[("gfcm2/cm", GF_CM2_PER_CM), ("gfcm", GF_CM2_PER_CM), ("uNm", 1e-6), ("Nm", 1.0), ("mgcm", MG_CM)],
            Quantity::MomentPerWidth => &[("gfcm/cm", GF_CM_PER_CM), ("Nm/m", 1.0), ("N", 1.0)],
            Quantity::ShearRigidity => &[("gf/cmdeg", GF_PER_CM_DEG), ("gf/cm/deg", GF_PER_CM_DEG), ("gf/degcm", GF_PER_CM_DEG), ("N/m", 1.0), ("N/mrad", 1.0)],
            Quantity::LoadPerWidth => &[("gf/cm", GF_PER_CM), ("N/m", 1.0)],
            Quantity::EnergyPerArea => &[("gfcm/cm2", GF_CM_PER_CM2), ("J/m2", 1.0), ("N/m", 1.0)],
            Quantity::Percent => &[("%", 0.01)],
            Quantity::Ratio => &[("", 1.0), ("1", 1.0)],
            Quantity::Area => &[("mm2", 1e-6), ("m2", 1.0)],
        }
    }

    /// The largest value of this quantity any fabric sheet can hold, SI, and why: the
    /// ceilings the simulator's fabric checks use (a 1 cm steel plate stays below them), a
    /// percentage of 100, a sample within the kilometre contact resolves. None where a
    /// bound has no meaning (pure numbers).
    pub fn most(self) -> Option<(f64, &'static str)> {
        match self {
            Quantity::ArealDensity => Some((1e3, "1000 kg/m²: a 1 cm steel plate weighs 79")),
            Quantity::Bending => Some((1e6, "1e6 N·m: a 1 cm steel plate has 2e4")),
            Quantity::MomentPerWidth | Quantity::ShearRigidity | Quantity::LoadPerWidth | Quantity::EnergyPerArea => {
                Some((1e11, "1e11 in SI units: a 1 cm steel plate has 2e9 N/m"))
            }
            Quantity::Percent => Some((1.0, "100 %: a woven has broken long before")),
            Quantity::Length | Quantity::Roughness | Quantity::Area => Some((1e3, "a kilometre or a square kilometre, beyond any specimen")),
            Quantity::Ratio => None,
        }
    }

    /// The units a user may write, for error messages.
    pub fn spelled(self) -> &'static str {
        match self {
            Quantity::ArealDensity => "mg/cm², g/m², kg/m², oz/yd²",
            Quantity::Length | Quantity::Roughness => "mm, cm, m, µm",
            Quantity::Bending => "gf·cm²/cm, µN·m, N·m, mg·cm",
            Quantity::MomentPerWidth => "gf·cm/cm, N·m/m",
            Quantity::ShearRigidity => "gf/(cm·deg), N/m (per radian)",
            Quantity::LoadPerWidth => "gf/cm, N/m",
            Quantity::EnergyPerArea => "gf·cm/cm², J/m²",
            Quantity::Percent => "%",
            Quantity::Ratio => "none (a pure number)",
            Quantity::Area => "mm², m²",
        }
    }
}

/// Drops the characters people write differently: spaces, `·`, `.`, `*`, brackets; `²`/`³`
/// become `2`/`3`, `µ`/`μ` becomes `u` and `°` becomes `deg`. Case is kept: unit symbols
/// are case-sensitive (`Mg` is a megagram, `mg` a milligram; 10⁹ apart).
pub fn normalise_unit(unit: &str) -> String {
    unit.chars()
        .filter_map(|c| match c {
            ' ' | '·' | '⋅' | '.' | '*' | '(' | ')' | '\t' => None,
            '²' => Some("2".to_string()),
            '³' => Some("3".to_string()),
            'µ' | 'μ' => Some("u".to_string()),
            '°' => Some("deg".to_string()),
            c => Some(c.to_string()),
        })
        .collect()
}

/// Splits `"137 g/m²"` into `(137.0, "g/m²")`: the longest prefix that reads as a number,
/// and the rest trimmed. None if no prefix is a number.
pub fn split_value(text: &str) -> Option<(f64, &str)> {
    let text = text.trim();
    let mut best = None;
    for (end, _) in text.char_indices().skip(1).chain(std::iter::once((text.len(), ' '))) {
        if let Ok(v) = text[..end].trim().parse::<f64>() {
            best = Some((v, text[end..].trim()));
        }
    }
    best
}

/// The factor from `unit` to SI for `quantity`, or None if the unit is not one of its own.
pub fn factor(quantity: Quantity, unit: &str) -> Option<f64> {
    let unit = normalise_unit(unit);
    quantity.units().iter().find(|(u, _)| *u == unit).map(|(_, f)| *f)
}

/// The unit of `quantity` that `unit` would be with its letters in another case (`Mg/cm²`
/// for `mg/cm²`), for the hint in the error that refuses it.
pub fn case_variant(quantity: Quantity, unit: &str) -> Option<&'static str> {
    let unit = normalise_unit(unit);
    quantity.units().iter().find(|(u, _)| u.eq_ignore_ascii_case(&unit)).map(|(u, _)| *u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::STANDARD_GRAVITY;

    #[test]
    fn kes_factors_are_the_exact_gram_force_ones() {
        assert!((GF_CM2_PER_CM - GF * 1e-2).abs() < 1e-20);
        assert!((GF - 1e-3 * STANDARD_GRAVITY).abs() < 1e-18);
        assert!((MG_CM - 1e-3 * GF_CM2_PER_CM).abs() < 1e-22);
        assert!((GF_PER_CM - 0.980665).abs() < 1e-15);
        assert!((GF_PER_CM_DEG - 0.980665 * 180.0 / PI).abs() < 1e-12);
        assert!((GF_PER_CM_DEG - 56.1879).abs() < 1e-4, "docs/references.md §8 rounds it to 56.19");
        assert!((GF_CM_PER_CM2 - 0.980665).abs() < 1e-15);
        assert!((MG_PER_CM2 - 0.01).abs() < 1e-18);
        assert!((OZ_PER_YD2 * 1e3 - 33.9057).abs() < 1e-4);
    }

    #[test]
    fn values_with_units_split_and_convert() {
        assert_eq!(split_value("137 g/m²"), Some((137.0, "g/m²")));
        assert_eq!(split_value("1.2e-5N·m"), Some((1.2e-5, "N·m")));
        assert_eq!(split_value("4.7 %"), Some((4.7, "%")));
        assert_eq!(split_value("0.65"), Some((0.65, "")));
        assert_eq!(split_value("g/m2"), None);
        assert_eq!(factor(Quantity::Bending, "gf·cm²/cm"), Some(GF_CM2_PER_CM));
        assert_eq!(factor(Quantity::Bending, "gf.cm2/cm"), Some(GF_CM2_PER_CM));
        assert_eq!(factor(Quantity::Bending, "µN·m"), Some(1e-6));
        assert_eq!(factor(Quantity::Bending, "uN m"), Some(1e-6));
        assert_eq!(factor(Quantity::ShearRigidity, "gf/(cm·deg)"), Some(GF_PER_CM_DEG));
        assert_eq!(factor(Quantity::ArealDensity, "oz/yd²"), Some(OZ_PER_YD2));
        assert_eq!(factor(Quantity::ArealDensity, "lb/ft2"), None);
        assert_eq!(factor(Quantity::Bending, "g/m2"), None, "a unit of another quantity is refused");
        assert_eq!(factor(Quantity::ArealDensity, "Mg/cm²"), None, "unit symbols are case-sensitive");
        assert_eq!(case_variant(Quantity::ArealDensity, "Mg/cm²"), Some("mg/cm2"));
        assert_eq!(factor(Quantity::ShearRigidity, "n/m"), None);
        assert_eq!(factor(Quantity::ShearRigidity, "gf/(cm·°)"), Some(GF_PER_CM_DEG));
    }
}
