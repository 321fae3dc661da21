//! ARCSim materials: the data-driven cloth files of ARCSim (Narain, Samii and O'Brien's
//! adaptive cloth simulator), which carry the fabrics Wang, O'Brien and Ramamoorthi
//! measured (*Data-Driven Elastic Models for Cloth*, ACM TOG 30(4), 2011).
//!
//! - [`material`]: the file read and checked (`density`, `stretching`, `bending`).
//! - [`model`]: ARCSim's model evaluated as its source defines it.
//! - [`project`]: the projection onto Rosette's fabric keys.
//! - [`export`]: a Rosette fabric written as an ARCSim material.
//!
//! A fabric file takes a material in an `[arcsim]` section, either by reference
//! (`data = "materials/11oz-black-denim.json"`, read from the working directory as ARCSim
//! reads its configuration's `data`) or inline (`density`, `stretching`, `bending`), with
//! ARCSim's configuration multipliers (`density_mult`, `stretching_mult`, `bending_mult`,
//! `thicken`) if wanted. docs/fabric-sheets.md (ARCSim materials) is the user's guide and
//! the derivation of every factor.

pub mod export;
pub mod material;
pub mod model;
pub mod project;

pub use material::{ArcsimError, ArcsimMaterial};

use std::collections::BTreeMap;

/// ARCSim's configuration multipliers of a material (conf.cpp, `parse(Material*&, …)`):
/// `thicken` multiplies all three.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Multipliers {
    pub density: f64,
    pub stretching: f64,
    pub bending: f64,
    pub thicken: f64,
}

impl Default for Multipliers {
    fn default() -> Self {
        Self { density: 1.0, stretching: 1.0, bending: 1.0, thicken: 1.0 }
    }
}

impl Multipliers {
    /// The material as ARCSim simulates it with these multipliers.
    pub fn apply(&self, m: &ArcsimMaterial) -> ArcsimMaterial {
        let mut out = m.clone();
        out.density *= self.density * self.thicken;
        out.stretching.iter_mut().flatten().for_each(|v| *v *= self.stretching * self.thicken);
        out.bending.iter_mut().flatten().for_each(|v| *v *= self.bending * self.thicken);
        out
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::default()
    }
}

/// A fabric file's `[arcsim]` section, read.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcsimSection {
    /// The material as the file gives it.
    pub file_material: ArcsimMaterial,
    pub multipliers: Multipliers,
    /// The material file it was read from (`data`), if not inline.
    pub data: Option<String>,
    /// Free text: `source`, `specimen`, `note`, `measured_by`.
    pub text: BTreeMap<String, String>,
    /// The material file's `"appearance"` (a fabric Rosette exported), as a fabric table's
    /// `[appearance]`, a relative texture path made relative to the working directory.
    pub appearance: Option<toml::Value>,
}

/// A material file's `"appearance"` as a fabric table's `[appearance]`, its texture's
/// relative path taken from the file's folder; `file` names the file in errors.
fn look_table(json: &serde_json::Value, file: &str) -> Result<toml::Value, ArcsimError> {
    let field = |message: String| ArcsimError::Field { file: file.into(), field: "appearance".into(), message };
    let value = toml::Value::try_from(json).map_err(|e| field(format!("cannot be read as a fabric's [appearance]: {e}")))?;
    let mut holder = toml::Table::new();
    holder.insert("appearance".into(), value);
    if let Some(dir) = std::path::Path::new(file).parent() {
        crate::appearance::resolve_in_table(&mut holder, dir);
    }
    Ok(holder.remove("appearance").expect("just inserted"))
}

/// The section's keys besides the free-text ones.
const KEYS: [&str; 8] = ["data", "density", "stretching", "bending", "density_mult", "stretching_mult", "bending_mult", "thicken"];

impl ArcsimSection {
    /// The material as simulated: multipliers applied.
    pub fn material(&self) -> ArcsimMaterial {
        self.multipliers.apply(&self.file_material)
    }

    /// How its values are named in sources: `arcsim.data = "FILE"` or `[arcsim]`.
    pub fn origin(&self) -> String {
        match &self.data {
            Some(path) => format!("arcsim.data = \"{path}\""),
            None => "[arcsim]".into(),
        }
    }

    /// Reads an `[arcsim]` section; `text_fields` are the free-text names it accepts.
    pub fn read(value: &toml::Value, text_fields: &[&str]) -> Result<Self, ArcsimError> {
        let file = "[arcsim]";
        let field = |name: &str, message: String| ArcsimError::Field { file: file.into(), field: format!("arcsim.{name}"), message };
        let table = value.as_table().ok_or_else(|| field("", "must be a table: data = \"FILE.json\", or density, stretching and bending".into()))?;
        let mut text = BTreeMap::new();
        for (name, v) in table {
            if text_fields.contains(&name.as_str()) {
                let s = v.as_str().ok_or_else(|| field(name, format!("{v} must be a quoted string")))?;
                text.insert(name.clone(), s.to_string());
            } else if !KEYS.contains(&name.as_str()) {
                return Err(field(name, format!("not a key of [arcsim]; its keys are {}, {}", KEYS.join(", "), text_fields.join(", "))));
            }
        }
        let mut multipliers = Multipliers::default();
        for (name, slot) in [
            ("density_mult", &mut multipliers.density),
            ("stretching_mult", &mut multipliers.stretching),
            ("bending_mult", &mut multipliers.bending),
            ("thicken", &mut multipliers.thicken),
        ] {
            if let Some(v) = table.get(name) {
                let x = v.as_float().or_else(|| v.as_integer().map(|i| i as f64));
                match x {
                    Some(x) if x.is_finite() && x > 0.0 => *slot = x,
                    _ => return Err(field(name, format!("{v} must be a positive number (ARCSim's multiplier of the material's values)"))),
                }
            }
        }
        let inline = ["density", "stretching", "bending"].iter().any(|k| table.contains_key(*k));
        let mut appearance = None;
        let (file_material, data) = match (table.get("data"), inline) {
            (Some(_), true) => {
                return Err(field("data", "and inline samples both given: name the material file or give density, stretching and bending, not both".into()));
            }
            (Some(path), false) => {
                let path = path.as_str().ok_or_else(|| field("data", format!("{path} must be the material file's path in quotes")))?;
                let (m, look) = material::read_document(std::path::Path::new(path))?;
                appearance = look.map(|json| look_table(&json, path)).transpose()?;
                (m, Some(path.to_string()))
            }
            (None, true) => {
                let json = |k: &str| table.get(k).map(|v| serde_json::to_value(v).expect("TOML values convert to JSON"));
                let m = material::from_fields(file, "arcsim.", json("density").as_ref(), json("stretching").as_ref(), json("bending").as_ref())?;
                (m, None)
            }
            (None, false) => return Err(field("data", "missing: name an ARCSim material file (data = \"FILE.json\") or give density, stretching and bending".into())),
        };
        // The multiplied material must still be in range.
        let section = Self { file_material, multipliers, data, text, appearance };
        let applied = section.material();
        let (low, high) = material::DENSITY_RANGE;
        if !(low..=high).contains(&applied.density) {
            return Err(field("density_mult", format!("makes the mass per area {} kg/m², outside {low}–{high}", applied.density)));
        }
        Ok(section)
    }
}
