//! `rosette fabric export --arcsim`: a fabric written as an ARCSim material file.

use super::{EXIT_NO_OUTPUT, bad_input, check_writable};
use rosette::fabric::arcsim::export::{export, to_json};
use std::process::ExitCode;

/// Whether `out` is the file `spec` was read from (an output must not overwrite an input).
pub fn same_file(spec: &str, out: &std::path::Path) -> bool {
    match (std::fs::canonicalize(spec), std::fs::canonicalize(out)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

pub fn export_arcsim(spec: &str, out: Option<&std::path::Path>) -> ExitCode {
    let loaded = match rosette::fabric::load_fabric(spec) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    if let Some(path) = out {
        if same_file(spec, path) {
            return bad_input(format!("--out {}: is the fabric being exported; write the material to another file", path.display()));
        }
        if let Err(e) = check_writable("--out", path) {
            return bad_input(format!("{e:#}"));
        }
    }
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let material = match loaded.config.to_fabric().and_then(|f| export(&f)) {
        Ok(m) => m,
        Err(e) => return bad_input(format!("{}: {e}", loaded.file)),
    };
    let name = if loaded.config.name.is_empty() { spec.to_string() } else { loaded.config.name.clone() };
    let mut comments = vec![
        format!("ARCSim material of \"{name}\", written by `rosette fabric export --arcsim {spec}`."),
        "density: mass per area, kg/m². stretching: [c11, c12, c22, c33] in N/m, the zero-strain row, then the rows at".into(),
        "1/6 principal strain along 0, 22.5, 45, 67.5, 90 degrees from u (the warp); ARCSim doubles them. bending: N·m,".into(),
        "rows for hinges along u, at 45 degrees and along v, at 0-40 1/m; a strip's rigidity is a quarter of its sample.".into(),
        "What each value is and what Rosette's fabric keys leave out: Rosette's docs/fabric-sheets.md, ARCSim materials.".into(),
    ];
    if let Some(source) = loaded.sheets.arcsim.as_ref().and_then(|a| a.text.get("source")) {
        comments.push(format!("Imported from: {source}"));
    }
    if let Some(who) = loaded.sheets.measured_by() {
        comments.push(format!("Measured by {who}; cite their publication with the data."));
    }
    let text = to_json(&material, &comments);
    match out {
        Some(path) => match std::fs::write(path, text) {
            Ok(()) => {
                eprintln!("wrote {}", path.display());
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: cannot write {}: {e}", path.display());
                ExitCode::from(EXIT_NO_OUTPUT)
            }
        },
        None => {
            print!("{text}");
            ExitCode::SUCCESS
        }
    }
}
