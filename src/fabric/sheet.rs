//! Measurement sheets: the `[kes]`, `[fast]` and `[cantilever]` sections of a fabric file,
//! each value read with its unit into SI and kept with what the sheet said.
//!
//! The field tables here are the single list of what each standard reports: parsing, the
//! errors, `rosette fabric template` and docs/fabric-sheets.md all follow them.

use super::units::{Quantity, factor, split_value};
use std::collections::BTreeMap;
use thiserror::Error;

/// Which standard a sheet section follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SheetKind {
    /// Kawabata Evaluation System (KES-FB1 tensile and shear, FB2 bending, FB3 compression,
    /// FB4 surface).
    Kes,
    /// CSIRO's Fabric Assurance by Simple Testing (FAST-1 to FAST-3).
    Fast,
    /// ASTM D1388 option A / BS 3356 cantilever bending lengths.
    Cantilever,
}

impl SheetKind {
    pub const ALL: [SheetKind; 3] = [SheetKind::Kes, SheetKind::Fast, SheetKind::Cantilever];

    /// The section name in a fabric file.
    pub fn section(self) -> &'static str {
        match self {
            SheetKind::Kes => "kes",
            SheetKind::Fast => "fast",
            SheetKind::Cantilever => "cantilever",
        }
    }

    /// The standard's name, for messages.
    pub fn title(self) -> &'static str {
        match self {
            SheetKind::Kes => "KES-F",
            SheetKind::Fast => "FAST",
            SheetKind::Cantilever => "ASTM D1388 / BS 3356 cantilever",
        }
    }

    /// The numeric fields of this kind of sheet.
    pub fn fields(self) -> &'static [Field] {
        match self {
            SheetKind::Kes => KES_FIELDS,
            SheetKind::Fast => FAST_FIELDS,
            SheetKind::Cantilever => CANTILEVER_FIELDS,
        }
    }
}

/// Free-text fields every section may carry.
pub const TEXT_FIELDS: &[(&str, &str)] = &[
    ("source", "where the sheet comes from: author, year, title, table"),
    ("specimen", "what was tested: fibre, weave, finish"),
    ("note", "anything a reader of the sheet should know"),
    ("standard", "the test standard and options used (e.g. \"ASTM D1388-18 option A\")"),
    ("measured_by", "who measured this specimen and where it was published; leave it out for values typical of a class"),
];

/// Whether a field feeds the simulator or is kept on the sheet only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Use {
    /// Converted into a fabric key.
    Model,
    /// Read, checked and kept for the record (hysteresis, surface, compression): the
    /// simulator's elastic model has no place for it.
    Record,
}

/// One numeric field of a sheet.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// The name as written in the file (directional fields add `_warp`, `_weft`, `_bias`).
    pub name: &'static str,
    pub quantity: Quantity,
    /// The standard's own unit: a bare number is read in it.
    pub unit: &'static str,
    /// The directions the field is reported in; empty if it has none. A plain name (no
    /// suffix) sets warp and weft alike.
    pub directions: &'static [&'static str],
    pub meaning: &'static str,
    pub use_: Use,
    /// A plausible value in `unit`, for the template (`rosette fabric template`).
    pub example: f64,
}

const WW: &[&str] = &["warp", "weft"];
const WWB: &[&str] = &["warp", "weft", "bias"];
const NONE: &[&str] = &[];

macro_rules! field {
    ($name:literal, $q:ident, $unit:literal, $dirs:expr, $use:ident, $example:literal, $meaning:literal) => {
        Field { name: $name, quantity: Quantity::$q, unit: $unit, directions: $dirs, use_: Use::$use, example: $example, meaning: $meaning }
    };
}

/// KES-F: the values of KES-FB1 to FB4 (docs/references.md §8).
pub const KES_FIELDS: &[Field] = &[
    field!("W", ArealDensity, "mg/cm²", NONE, Model, 16.8, "mass per area"),
    field!("T", Length, "mm", NONE, Model, 0.5, "thickness at 0.5 gf/cm² (KES-FB3 T0)"),
    field!("EMT", Percent, "%", WW, Model, 5.5, "tensile strain at Fm (KES-FB1)"),
    field!("LT", Ratio, "", WW, Model, 0.65, "tensile linearity: WT over the area under the straight line to (EMT, Fm)"),
    field!("WT", EnergyPerArea, "gf·cm/cm²", WW, Model, 8.9, "tensile energy ∫F dε up to Fm"),
    field!("RT", Percent, "%", WW, Record, 60.0, "tensile resilience: recovered over stored energy"),
    field!("Fm", LoadPerWidth, "gf/cm", NONE, Model, 500.0, "load the tensile test stops at (500 gf/cm unless the sheet says otherwise)"),
    field!("B", Bending, "gf·cm²/cm", WW, Model, 0.057, "bending rigidity: moment slope between 0.5 and 1.5 cm⁻¹ (KES-FB2)"),
    field!("2HB", MomentPerWidth, "gf·cm/cm", WW, Record, 0.05, "bending hysteresis width"),
    field!("G", ShearRigidity, "gf/(cm·deg)", WW, Model, 0.47, "shear rigidity: mean slope of shear force against angle, 0.5° to 5° (KES-FB1)"),
    field!("2HG", LoadPerWidth, "gf/cm", WW, Record, 0.8, "shear hysteresis at 0.5°"),
    field!("2HG5", LoadPerWidth, "gf/cm", WW, Record, 1.6, "shear hysteresis at 5°"),
    field!("LC", Ratio, "", NONE, Record, 0.35, "compression linearity (KES-FB3)"),
    field!("WC", EnergyPerArea, "gf·cm/cm²", NONE, Record, 0.15, "compression energy"),
    field!("RC", Percent, "%", NONE, Record, 50.0, "compression resilience"),
    field!("MIU", Ratio, "", NONE, Record, 0.2, "mean friction coefficient (KES-FB4)"),
    field!("MMD", Ratio, "", NONE, Record, 0.02, "mean deviation of MIU"),
    field!("SMD", Roughness, "µm", NONE, Record, 5.0, "geometric roughness"),
];

/// FAST: FAST-1 compression, FAST-2 bending, FAST-3 extension (docs/references.md §8).
pub const FAST_FIELDS: &[Field] = &[
    field!("W", ArealDensity, "g/m²", NONE, Model, 168.0, "mass per area"),
    field!("T2", Length, "mm", NONE, Model, 0.45, "thickness at 2 gf/cm² (FAST-1)"),
    field!("T100", Length, "mm", NONE, Record, 0.35, "thickness at 100 gf/cm² (FAST-1); ST = T2 − T100"),
    field!("C", Length, "mm", WW, Model, 15.0, "bending length (FAST-2, BS 3356 principle)"),
    field!("B", Bending, "µN·m", WW, Model, 5.6, "bending rigidity W·C³·g (FAST-2)"),
    field!("E5", Percent, "%", WW, Model, 0.7, "extension at 5 gf/cm (FAST-3)"),
    field!("E20", Percent, "%", WW, Model, 1.9, "extension at 20 gf/cm (FAST-3)"),
    field!("E100", Percent, "%", WW, Model, 4.6, "extension at 100 gf/cm (FAST-3)"),
    field!("EB5", Percent, "%", NONE, Model, 4.7, "bias extension at 5 gf/cm (FAST-3)"),
    field!("G", ShearRigidity, "N/m", NONE, Model, 26.2, "shear rigidity, 123/EB5 (FAST-3)"),
    field!("F", Area, "mm²", WW, Record, 0.45, "formability (E20 − E5)·B/14.7"),
    field!("RS", Percent, "%", WW, Record, 1.0, "relaxation shrinkage (FAST-4)"),
    field!("HE", Percent, "%", WW, Record, 4.0, "hygral expansion (FAST-4)"),
];

/// ASTM D1388 option A / BS 3356: bending lengths of strips cut along the warp, the weft
/// and the bias (docs/references.md §4 and §8).
pub const CANTILEVER_FIELDS: &[Field] = &[
    field!("W", ArealDensity, "g/m²", NONE, Model, 168.0, "mass per area"),
    field!("c", Length, "mm", WWB, Model, 15.0, "bending length: half the overhang at which the tip meets the 41.5° plane"),
    field!("overhang", Length, "mm", WWB, Model, 30.0, "overhang at the 41.5° plane (twice the bending length)"),
    field!("strip_width", Length, "mm", NONE, Model, 25.0, "width of the strip tested (the standard's 25 mm unless stated)"),
];

/// A value read from a sheet: in SI, with what the sheet said.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    /// The value in SI (fractions for percentages).
    pub si: f64,
    /// The value as written, with its unit (`"0.092 gf·cm²/cm"`).
    pub written: String,
}

/// One section of a sheet, its values by full field name (`B_warp`, `W`).
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    pub kind: SheetKind,
    /// Free-text fields: `source`, `specimen`, `note`, `standard`.
    pub text: BTreeMap<String, String>,
    pub values: BTreeMap<String, Reading>,
}

impl Section {
    /// The SI value of a field (`"B_warp"`), if the sheet gives it.
    pub fn si(&self, name: &str) -> Option<f64> {
        self.values.get(name).map(|r| r.si)
    }

    /// `kes.B_warp = 0.092 gf·cm²/cm`: the field as the sheet wrote it.
    pub fn quote(&self, name: &str) -> String {
        match self.values.get(name) {
            Some(r) => format!("{}.{name} = {}", self.kind.section(), r.written),
            None => format!("{}.{name}", self.kind.section()),
        }
    }

    /// The sheet's `source` line, if any.
    pub fn source(&self) -> Option<&str> {
        self.text.get("source").map(String::as_str)
    }
}

/// The sheet sections of one fabric file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sheets {
    pub kes: Option<Section>,
    pub fast: Option<Section>,
    pub cantilever: Option<Section>,
    /// An ARCSim material (`[arcsim]`): it gives every key itself, so it stands alone.
    pub arcsim: Option<super::arcsim::ArcsimSection>,
}

/// A sheet value written in a unit its field does not take (`SheetError::UnknownUnit`,
/// boxed: the details are six fields, and every sheet function returns the error).
#[derive(Debug, Error, PartialEq)]
#[error(
    "{section}.{field} = {written}: unknown unit '{unit}'{hint}; write a bare number in {default_unit} \
     or a string with one of: {accepted}"
)]
pub struct UnknownUnit {
    pub section: &'static str,
    pub field: String,
    pub written: String,
    pub unit: String,
    /// Where the unit is one of the field's own in another case: that it is refused, and why.
    pub hint: String,
    pub default_unit: &'static str,
    pub accepted: &'static str,
}

/// Why a sheet cannot be read. Every message names the field and says how to fix it.
#[derive(Debug, Error, PartialEq)]
pub enum SheetError {
    #[error("[{section}] must be a table of measured values such as `W = {example}`")]
    NotATable { section: &'static str, example: &'static str },
    #[error(
        "{section}.{field}: a {title} sheet has no such field; its fields are {known} \
         (`rosette fabric template` prints them with their units)"
    )]
    UnknownField { section: &'static str, title: &'static str, field: String, known: String },
    #[error("{0}")]
    UnknownUnit(Box<UnknownUnit>),
    #[error("{section}.{field} = {written}: expected a number in {default_unit} or a string \"VALUE UNIT\" such as \"{example}\"")]
    NotAValue { section: &'static str, field: String, written: String, default_unit: &'static str, example: String },
    #[error("{section}.{field} = {written}: must be {expected}")]
    OutOfRange { section: &'static str, field: String, written: String, expected: String },
    #[error("{section}.{field} and {section}.{other} both given: {fix}")]
    Duplicate { section: &'static str, field: String, other: String, fix: String },
    #[error("{fields}: {message}")]
    Inconsistent { fields: String, message: String },
    #[error("{what} is missing: {fix}")]
    Missing { what: String, fix: String },
    #[error("{0}")]
    Arcsim(#[from] super::arcsim::ArcsimError),
}

impl Sheets {
    /// True if the file has no sheet section.
    pub fn is_empty(&self) -> bool {
        self.kes.is_none() && self.fast.is_none() && self.cantilever.is_none() && self.arcsim.is_none()
    }

    /// Who measured the fabric, from the first section that says (`measured_by`); None for
    /// sheets typical of a class and for fabrics without sheets.
    pub fn measured_by(&self) -> Option<&str> {
        let arcsim = self.arcsim.as_ref().and_then(|a| a.text.get("measured_by"));
        arcsim.or_else(|| self.sections().find_map(|s| s.text.get("measured_by"))).map(String::as_str)
    }

    /// The sections present, in the order KES, FAST, cantilever.
    pub fn sections(&self) -> impl Iterator<Item = &Section> {
        [&self.kes, &self.fast, &self.cantilever].into_iter().flatten()
    }

    /// Removes the sheet sections from a fabric table and reads them; the table keeps its
    /// other keys.
    pub fn take(table: &mut toml::Table) -> Result<Sheets, SheetError> {
        let mut sheets = Sheets::default();
        for kind in SheetKind::ALL {
            let Some(value) = table.remove(kind.section()) else { continue };
            let section = read_section(kind, &value)?;
            match kind {
                SheetKind::Kes => sheets.kes = Some(section),
                SheetKind::Fast => sheets.fast = Some(section),
                SheetKind::Cantilever => sheets.cantilever = Some(section),
            }
        }
        if let Some(value) = table.remove("arcsim") {
            if let Some(other) = sheets.sections().next() {
                return Err(SheetError::Inconsistent {
                    fields: format!("[arcsim] and [{}]", other.kind.section()),
                    message: "an ARCSim material gives every fabric key itself; keep it alone, or convert the other sheet in a file of its own".into(),
                });
            }
            let text: Vec<&str> = TEXT_FIELDS.iter().map(|(n, _)| *n).filter(|n| *n != "standard").collect();
            sheets.arcsim = Some(super::arcsim::ArcsimSection::read(&value, &text)?);
        }
        Ok(sheets)
    }
}

/// Splits `B_warp` into the field `B` and the direction `warp`.
fn split_direction(name: &str) -> (&str, Option<&str>) {
    for dir in ["warp", "weft", "bias"] {
        if let Some(base) = name.strip_suffix(dir).and_then(|b| b.strip_suffix('_')) {
            return (base, Some(dir));
        }
    }
    (name, None)
}

fn known_fields(kind: SheetKind) -> String {
    let mut names: Vec<String> = TEXT_FIELDS.iter().map(|(n, _)| n.to_string()).collect();
    for f in kind.fields() {
        if f.directions.is_empty() {
            names.push(f.name.to_string());
        } else {
            names.extend(f.directions.iter().map(|d| format!("{}_{d}", f.name)));
        }
    }
    names.join(", ")
}

fn read_section(kind: SheetKind, value: &toml::Value) -> Result<Section, SheetError> {
    let section = kind.section();
    let table = value.as_table().ok_or(SheetError::NotATable { section, example: kind.fields()[0].unit })?;
    let mut out = Section { kind, text: BTreeMap::new(), values: BTreeMap::new() };
    for (name, value) in table {
        if TEXT_FIELDS.iter().any(|(n, _)| n == name) {
            let text = value.as_str().ok_or_else(|| SheetError::OutOfRange {
                section,
                field: name.clone(),
                written: value.to_string(),
                expected: "a quoted string".into(),
            })?;
            out.text.insert(name.clone(), text.to_string());
            continue;
        }
        let (base, direction) = split_direction(name);
        let field = kind
            .fields()
            .iter()
            .find(|f| f.name == base && direction.is_none_or(|d| f.directions.contains(&d)))
            .ok_or_else(|| SheetError::UnknownField { section, title: kind.title(), field: name.clone(), known: known_fields(kind) })?;
        let reading = read_value(section, name, field, value)?;
        match (direction, field.directions.is_empty()) {
            (Some(_), _) | (None, true) => {
                out.values.insert(name.clone(), reading);
            }
            (None, false) => {
                // A plain name stands for warp and weft alike.
                for dir in WW {
                    let full = format!("{base}_{dir}");
                    let both = Reading { si: reading.si, written: format!("{} (both directions)", reading.written) };
                    out.values.insert(full, both);
                }
            }
        }
    }
    // A plain name and a directional one for the same field would silently shadow each other.
    for field in kind.fields().iter().filter(|f| !f.directions.is_empty()) {
        for dir in WW {
            let full = format!("{}_{dir}", field.name);
            if table.contains_key(field.name) && table.contains_key(&full) {
                return Err(SheetError::Duplicate {
                    section,
                    field: field.name.to_string(),
                    other: full,
                    fix: format!("give {0} for both directions or {0}_warp and {0}_weft, not both", field.name),
                });
            }
        }
    }
    Ok(out)
}

fn read_value(section: &'static str, name: &str, field: &Field, value: &toml::Value) -> Result<Reading, SheetError> {
    let example = format!("{} {}", example_number(field.quantity), if field.unit.is_empty() { "" } else { field.unit })
        .trim()
        .to_string();
    let not_a_value = || SheetError::NotAValue {
        section,
        field: name.to_string(),
        written: value.to_string(),
        default_unit: unit_or_none(field.unit),
        example: example.clone(),
    };
    let (number, unit, written) = match value {
        toml::Value::Float(v) => (*v, None, format_bare(*v, field.unit)),
        toml::Value::Integer(v) => (*v as f64, None, format_bare(*v as f64, field.unit)),
        toml::Value::String(text) => {
            let (number, unit) = split_value(text).ok_or_else(not_a_value)?;
            (number, Some(unit), text.trim().to_string())
        }
        _ => return Err(not_a_value()),
    };
    let scale = match unit.filter(|u| !u.is_empty()) {
        None => factor(field.quantity, field.unit).expect("every field's own unit is in its quantity's table"),
        Some(u) => factor(field.quantity, u).ok_or_else(|| SheetError::UnknownUnit(Box::new(UnknownUnit {
            section,
            field: name.to_string(),
            written: written.clone(),
            unit: u.to_string(),
            hint: super::units::case_variant(field.quantity, u).map_or(String::new(), |v| {
                format!(" (unit symbols are case-sensitive: M is mega, m milli; {v} is written in lower case)")
            }),
            default_unit: unit_or_none(field.unit),
            accepted: field.quantity.spelled(),
        })))?,
    };
    let si = number * scale;
    let positive_needed = field.use_ == Use::Model;
    if !si.is_finite() || si < 0.0 || (positive_needed && si == 0.0) {
        let expected = if positive_needed { "a positive number" } else { "zero or a positive number" };
        return Err(SheetError::OutOfRange { section, field: name.to_string(), written, expected: format!("{expected} ({})", field.meaning) });
    }
    if let Some((most, why)) = field.quantity.most()
        && si > most
    {
        // The bound in the unit the value was written in.
        let unit = unit.filter(|u| !u.is_empty()).unwrap_or(field.unit);
        let expected = format!("at most {} {unit} ({why})", crate::io::number::short(most / scale));
        return Err(SheetError::OutOfRange { section, field: name.to_string(), written, expected });
    }
    Ok(Reading { si, written })
}

fn unit_or_none(unit: &'static str) -> &'static str {
    if unit.is_empty() { "a pure number" } else { unit }
}

fn format_bare(v: f64, unit: &str) -> String {
    let v = crate::io::number::short(v);
    if unit.is_empty() { v } else { format!("{v} {unit}") }
}

fn example_number(q: Quantity) -> &'static str {
    match q {
        Quantity::ArealDensity => "137",
        Quantity::Length | Quantity::Roughness => "0.3",
        Quantity::Bending => "0.09",
        Quantity::ShearRigidity => "0.7",
        Quantity::Percent => "5.2",
        _ => "0.6",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fabric::units::{GF_CM2_PER_CM, GF_PER_CM_DEG};

    fn sheets(text: &str) -> Result<Sheets, SheetError> {
        let mut table: toml::Table = text.parse().unwrap();
        Sheets::take(&mut table)
    }

    #[test]
    fn reads_bare_numbers_in_the_standards_units_and_strings_with_units() {
        let s = sheets("[kes]\nW = 13.7\nB_warp = 0.092\nB_weft = \"7 µN·m\"\nG = 0.7\nEMT = 5.5\nsource = \"x\"").unwrap();
        let kes = s.kes.unwrap();
        assert!((kes.si("W").unwrap() - 0.137).abs() < 1e-15);
        assert!((kes.si("B_warp").unwrap() - 0.092 * GF_CM2_PER_CM).abs() < 1e-20);
        assert!((kes.si("B_weft").unwrap() - 7e-6).abs() < 1e-20);
        assert!((kes.si("G_warp").unwrap() - 0.7 * GF_PER_CM_DEG).abs() < 1e-12, "a plain name sets both directions");
        assert_eq!(kes.si("EMT_weft"), Some(0.055));
        assert_eq!(kes.source(), Some("x"));
        assert_eq!(kes.quote("B_warp"), "kes.B_warp = 0.092 gf·cm²/cm");
    }

    #[test]
    fn bad_sheets_name_the_field_and_the_fix() {
        let err = sheets("[kes]\nW = \"13.7 lb/ft2\"").unwrap_err().to_string();
        assert!(err.contains("kes.W") && err.contains("lb/ft2") && err.contains("g/m²"), "{err}");
        let err = sheets("[fast]\nB_warp = -5").unwrap_err().to_string();
        assert!(err.contains("fast.B_warp") && err.contains("positive"), "{err}");
        let err = sheets("[kes]\nBwarp = 0.1").unwrap_err().to_string();
        assert!(err.contains("kes.Bwarp") && err.contains("B_warp"), "{err}");
        let err = sheets("[cantilever]\nc_bias = \"about 2 cm\"").unwrap_err().to_string();
        assert!(err.contains("cantilever.c_bias") && err.contains("VALUE UNIT"), "{err}");
        let err = sheets("[kes]\nB = 0.1\nB_warp = 0.1").unwrap_err().to_string();
        assert!(err.contains("kes.B") && err.contains("B_warp"), "{err}");
        let err = sheets("kes = 3").unwrap_err().to_string();
        assert!(err.contains("[kes]"), "{err}");
        assert!(sheets("[kes]\nB_bias = 0.1").is_err(), "KES reports no bias bending");
    }
}
