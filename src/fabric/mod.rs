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
pub mod derived;
pub mod explain;
pub mod import;
pub mod sheet;
pub mod tensile;
pub mod units;
pub mod write;

pub use derived::{Derived, Import};
pub use import::{Expanded, derive, expand_sheets, merge_scene_sheets};
pub use sheet::{SheetError, SheetKind, Sheets};

use crate::settings::read::{PresetError, PresetKind, read_preset, refuse_fabric_preset};
use crate::settings::FabricConfig;
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

/// Why a fabric could not be loaded: the file could not be read or parsed (the settings
/// layer's refusal), or its sheets or keys are wrong.
#[derive(Debug, Error)]
pub enum LoadError {
    #[error(transparent)]
    Preset(#[from] PresetError),
    #[error("{file}: {source}")]
    Sheet { file: String, source: Box<SheetError> },
}

fn invalid(file: &str, message: String) -> LoadError {
    LoadError::Preset(PresetError::Invalid { file: file.into(), message })
}

/// Reads a fabric file's text: sheets converted, keys checked.
pub fn parse_fabric(text: &str, file: &str) -> Result<LoadedFabric, LoadError> {
    // A file's contents are quoted only where it is named as a fabric file (FILE.toml).
    let table = crate::io::read::parse_toml(text, Some(std::path::Path::new(file)), crate::io::read::FileKind::Fabric)
        .map_err(|message| PresetError::Syntax { file: file.into(), message })?;
    refuse_fabric_preset(&table).map_err(|message| invalid(file, message))?;
    let mut table = table;
    if let Some(dir) = std::path::Path::new(file).parent() {
        crate::appearance::resolve_in_table(&mut table, dir);
    }
    from_table(table, file)
}

/// A fabric file's table read: sheets converted, keys checked.
fn from_table(mut table: toml::Table, file: &str) -> Result<LoadedFabric, LoadError> {
    let sheet_error = |source| LoadError::Sheet { file: file.into(), source: Box::new(source) };
    let Expanded { sheets, import, warnings } = expand_sheets(&mut table).map_err(sheet_error)?;
    if let Some(look) = table.get("appearance") {
        crate::appearance::from_value(look).map_err(|e| invalid(file, e.message))?;
    }
    let config: FabricConfig =
        table.try_into().map_err(|e: toml::de::Error| invalid(file, e.message().trim().into()))?;
    config.to_fabric().map_err(|e| {
        let message = explain::explain(&import, e.key(), &e.to_string()).map_or_else(|| e.to_string(), |(text, _)| text);
        invalid(file, message)
    })?;
    // The file's own texture paths were made relative to the working directory as it was
    // read (`read_preset`, `parse_fabric`).
    config.look(None).map_err(|e| invalid(file, e.message))?;
    Ok(LoadedFabric { file: file.into(), config, sheets, import, warnings })
}

/// Loads a bundled fabric by name (`wool`), a fabric file by path, or an ARCSim material
/// file (`….json`).
pub fn load_fabric(spec: &str) -> Result<LoadedFabric, LoadError> {
    let (table, file) = read_preset(PresetKind::Fabric, spec, None, None)?;
    from_table(table, &file)
}
