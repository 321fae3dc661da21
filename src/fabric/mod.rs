//! Fabrics from measurement sheets: KES-F, FAST and ASTM D1388 / BS 3356 cantilever
//! results turned into the simulator's fabric keys, each with its source.
//!
//! A fabric file may hold `[kes]`, `[fast]` and `[cantilever]` sections instead of (or
//! beside) the fabric keys, or an ARCSim material in `[arcsim]` ([`arcsim`]);
//! [`expand_sheets`] converts them when the file is loaded. The
//! conversions use the exact unit factors of [`units`]; the tensile curves are built as
//! [`tensile`] describes; a measured bias bending length goes through the strip theory of
//! [`bias`]. `rosette fabric import` writes the converted file with every value's source
//! ([`write`]); docs/fabric-sheets.md is the user's guide to all of it.

pub mod arcsim;
pub mod bias;
pub mod explain;
pub mod import;
pub mod sheet;
pub mod tensile;
pub mod units;
pub mod write;

pub use import::{Derived, Import, derive, expand_sheets, merge_scene_sheets};
pub use sheet::{SheetError, SheetKind, Sheets};

use crate::scene::preset::{FABRICS, FabricConfig};
use thiserror::Error;

/// A fabric file read with its sheets: the fabric, and what it came from.
#[derive(Debug, Clone)]
pub struct LoadedFabric {
    /// Where it was read from (`presets/fabrics/wool.toml (bundled)` or a path).
    pub file: String,
    pub config: FabricConfig,
    pub sheets: Sheets,
    /// The keys the sheets gave, with their sources.
    pub import: Import,
    /// Defaults used and disagreements found while converting the sheets.
    pub warnings: Vec<String>,
}

#[derive(Debug, Error)]
pub enum LoadError {
    #[error("{source}")]
    Read { source: crate::io::read::ReadError },
    #[error("no bundled fabric named '{name}' and no such file; bundled fabrics: {available}")]
    Unknown { name: String, available: String },
    #[error("{file}: {message}")]
    Syntax { file: String, message: String },
    #[error("{file}: {source}")]
    Sheet { file: String, source: Box<SheetError> },
    #[error("{file}: {message}")]
    Invalid { file: String, message: String },
}

/// Reads a fabric file's text: sheets converted, keys checked.
pub fn parse_fabric(text: &str, file: &str) -> Result<LoadedFabric, LoadError> {
    // A file's contents are quoted only where it is named as a fabric file (FILE.toml).
    let table = crate::io::read::parse_toml(text, Some(std::path::Path::new(file)), crate::io::read::FileKind::Fabric)
        .map_err(|message| LoadError::Syntax { file: file.into(), message })?;
    crate::scene::preset::refuse_fabric_preset(&table).map_err(|message| LoadError::Invalid { file: file.into(), message })?;
    from_table(table, file)
}

/// A fabric file's table read: sheets converted, keys checked.
fn from_table(mut table: toml::Table, file: &str) -> Result<LoadedFabric, LoadError> {
    let sheet_error = |source| LoadError::Sheet { file: file.into(), source: Box::new(source) };
    let sheets = Sheets::take(&mut table).map_err(sheet_error)?;
    let import = if sheets.is_empty() { Import::default() } else { derive(&sheets, &table).map_err(sheet_error)? };
    let warnings = import::apply(&mut table, &import);
    let config: FabricConfig =
        table.try_into().map_err(|e: toml::de::Error| LoadError::Invalid { file: file.into(), message: e.message().trim().into() })?;
    config.to_fabric().map_err(|e| {
        let message = explain::explain(&import, e.key(), &e.to_string()).map_or_else(|| e.to_string(), |(text, _)| text);
        LoadError::Invalid { file: file.into(), message }
    })?;
    Ok(LoadedFabric { file: file.into(), config, sheets, import, warnings })
}

/// Whether `spec` names an ARCSim material file (`….json`) rather than a fabric file.
pub fn is_arcsim_file(spec: &str) -> bool {
    std::path::Path::new(spec).extension().is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// An ARCSim material file read as a fabric: the file is the fabric's `[arcsim]` section
/// (`data = "FILE"`), named after the file.
fn load_arcsim(spec: &str) -> Result<LoadedFabric, LoadError> {
    from_table(crate::scene::preset::arcsim_fabric_table(spec), spec)
}

/// Loads a bundled fabric by name (`wool`), a fabric file by path, or an ARCSim material
/// file (`….json`).
pub fn load_fabric(spec: &str) -> Result<LoadedFabric, LoadError> {
    if is_arcsim_file(spec) {
        return load_arcsim(spec);
    }
    let is_path = spec.contains('/') || spec.contains('\\') || spec.ends_with(".toml");
    if !is_path && let Some(b) = FABRICS.iter().find(|b| b.name == spec) {
        return parse_fabric(b.text, &format!("presets/fabrics/{}.toml (bundled)", b.name));
    }
    let path = std::path::Path::new(spec);
    if !path.exists() && !is_path {
        let available = FABRICS.iter().map(|b| b.name).collect::<Vec<_>>().join(", ");
        return Err(LoadError::Unknown { name: spec.into(), available });
    }
    let text = crate::io::read::read_text(path, crate::io::read::FileKind::Fabric).map_err(|source| LoadError::Read { source })?;
    parse_fabric(&text, spec)
}
