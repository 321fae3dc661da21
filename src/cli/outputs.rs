//! The kinds of file the commands write, as the output guard recognises them
//! (`rosette::io::guard`), and the guard's use for each command: every output checked
//! against the command's inputs, its other outputs and the files already there, before
//! any work.

use rosette::io::guard::{Kind, Plan, Signature};
use rosette::io::read::{Identity, files_read, file_id};
use rosette::scene::{SceneConfig, StepRecord};
use std::path::Path;

pub const METRICS: Kind = Kind { noun: "a metrics file", signature: Signature::Starts("{\n  \"preset\": ") };
pub const STEP_LOG: Kind = Kind { noun: "a step log", signature: Signature::Starts(StepRecord::CSV_HEADER) };
pub const OUTLINE: Kind = Kind { noun: "a shadow outline", signature: Signature::Starts("angle_deg,radius_m\n") };
pub const PICTURE: Kind = Kind { noun: "a picture", signature: Signature::Png };
pub const GLTF: Kind = Kind { noun: "a glTF export", signature: Signature::Glb };
pub const CARD_JSON: Kind = Kind { noun: "a fabric card's numbers", signature: Signature::Starts("{\n  \"fabric\": {") };
pub const COMPARE_JSON: Kind = Kind { noun: "a comparison's numbers", signature: Signature::Starts("{\n  \"scene\": ") };
pub const COMPARE_CSV: Kind = Kind { noun: "a comparison's table", signature: Signature::Starts("fabric,name,drape_coefficient,") };
pub const ACCURACY_CSV: Kind = Kind { noun: "a chart's accuracy table", signature: Signature::Starts(rosette::chart::data::ACCURACY_HEADER) };
pub const STABILITY_CSV: Kind = Kind { noun: "a chart's stability table", signature: Signature::Starts(rosette::chart::data::STABILITY_HEADER) };
pub const DRAPE_REFERENCE_CSV: Kind =
    Kind { noun: "a chart's drape reference", signature: Signature::Starts(rosette::chart::data::DRAPE_REFERENCE_HEADER) };
pub const BENCH_CSV: Kind = Kind { noun: "a benchmark table", signature: Signature::Starts("case,threads,") };
pub const BENCH_JSON: Kind = Kind { noun: "a benchmark's numbers", signature: Signature::Starts("[\n  {\n    \"case\": ") };
pub const ARCSIM_FILE: Kind = Kind { noun: "an ARCSim material", signature: Signature::Starts("// ARCSim material of ") };
pub const PATTERN_SCENE: Kind = Kind { noun: "an imported garment scene", signature: Signature::SecondLine("# Written by `rosette pattern import") };
pub const SEAMS_FILE: Kind = Kind { noun: "a suggested seams file", signature: Signature::Starts("# Seams suggested for ") };
pub const DXF_PATTERN: Kind = Kind { noun: "a DXF pattern", signature: Signature::Starts(rosette::garment::dxf::write::FIRST_LINES) };
pub const FABRIC_FILE: Kind = Kind { noun: "a fabric file", signature: Signature::SecondLine("# Written by `rosette fabric import") };

/// The files a command read (scenes, fabrics, sheets, through `rosette::io::read`), with
/// those its scenes will read when they are built ([`rosette::scene::props::files_named`]).
pub fn inputs(configs: &[&SceneConfig]) -> Vec<Identity> {
    let mut inputs = files_read();
    for config in configs {
        for (path, kind) in rosette::scene::props::files_named(config) {
            if file_id(&path).is_some() {
                let canonical = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
                inputs.push(Identity { id: file_id(&path), path, canonical, kind });
            }
        }
    }
    inputs
}

/// Checks `plan` against the inputs; the message for exit 2.
pub fn check(plan: &Plan, configs: &[&SceneConfig]) -> Result<(), String> {
    plan.check(&inputs(configs))
}

/// Creates the folder a command writes into (`--out DIR`), refusing a path that is a file.
pub fn folder(flag: &str, dir: &Path) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!("{flag} {}: is a file; {flag} names a folder to write into", dir.display()));
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{flag} {}: cannot write there (cannot create the folder: {e})", dir.display()))
}

/// Writes `text` to `--out PATH`, whole or not at all, or without `--out` to standard
/// output: `noun` names it in the error ("the material"), `hint` follows "wrote PATH".
pub fn write_or_print(out: Option<&Path>, text: &str, noun: &str, hint: &str) -> std::process::ExitCode {
    match out {
        Some(path) => match rosette::io::write::whole(path, text.as_bytes()) {
            Ok(()) => {
                rosette::errln!("wrote {}{hint}", path.display());
                std::process::ExitCode::SUCCESS
            }
            Err(e) => super::lost_output(format!("--out {}: cannot write {noun}: {e}", path.display())),
        },
        None => {
            rosette::out!("{text}");
            std::process::ExitCode::SUCCESS
        }
    }
}
