//! What sheets give: the fabric keys derived from them, each with its source, and the
//! stated defaults used where a sheet is silent.

use super::sheet::SheetKind;
use super::units::GF_PER_CM;

/// Bulk density behind a missing thickness, kg/m³: woven apparel fabrics lie near
/// 300–500 kg/m³ (their fibres' 1300–1500 kg/m³ at a packing of a third).
pub const DEFAULT_BULK_DENSITY: f64 = 400.0;
/// Poisson ratio ν_xy when no sheet gives one (none of the standards measures it): the
/// value of the bundled fabrics, inside the 0.1–0.3 reported for plain wovens.
pub const DEFAULT_POISSON: f64 = 0.15;
/// Shear modulus when a sheet gives neither G nor EB5, N/m: 0.89 gf/(cm·deg), inside the
/// wool-suiting range of docs/references.md §8 (20–60 N/m).
pub const DEFAULT_SHEAR: f64 = 50.0;
/// Tensile curve when a sheet gives none: KES EMT 5 % and LT 0.65 at 500 gf/cm, a
/// mid-range woven apparel fabric (docs/fabric-sheets.md).
pub const DEFAULT_EMT: f64 = 0.05;
pub const DEFAULT_LT: f64 = 0.65;
/// KES load Fm, N/m (500 gf/cm).
pub const KES_FM: f64 = 500.0 * GF_PER_CM;
/// How far WT may stray from LT·Fm·EMT/2 when all three are given: KES prints each to
/// three figures and averages specimens separately, which leaves a few per cent.
pub const WT_TOLERANCE: f64 = 0.05;
/// How far two sections may disagree on one property before a warning.
pub const AGREEMENT: f64 = 0.10;
/// FAST's shear rigidity from the bias extension: G = 123/EB5 N/m, EB5 in %
/// (5 gf/cm = 4.903 N/m over 4·EB5/100, the bias modulus of a sheet with G ≪ E).
pub const FAST_SHEAR_CONSTANT: f64 = 123.0;

/// One fabric key derived from a sheet.
#[derive(Debug, Clone, PartialEq)]
pub struct Derived {
    /// The fabric key, e.g. `bending_warp`.
    pub key: &'static str,
    pub value: toml::Value,
    /// Where the value came from, one line, e.g.
    /// `kes.B_warp = 0.092 gf·cm²/cm × 9.80665e-5 N·m per gf·cm²/cm`.
    pub source: String,
    /// True for a stated default rather than a measurement.
    pub default: bool,
    /// The sheet section the value came from (None for defaults).
    pub section: Option<SheetKind>,
}

/// The fabric keys a set of sheets gives, and what the user should hear about them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Import {
    pub derived: Vec<Derived>,
    /// Defaults used and disagreements found, one sentence each.
    pub warnings: Vec<String>,
}

impl Import {
    /// The derived value of `key`, if any.
    pub fn get(&self, key: &str) -> Option<&Derived> {
        self.derived.iter().find(|d| d.key == key)
    }
}

