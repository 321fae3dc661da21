//! `rosette fabric export --arcsim`: a fabric written as an ARCSim material file.

use super::outputs::{self, ARCSIM_FILE};
use super::bad_input;
use rosette::fabric::arcsim::export::{export as to_material, to_json_with_look};
use rosette::io::guard::Plan;
use rosette::errln;
use std::path::Path;
use std::process::ExitCode;

pub fn export(spec: &str, out: Option<&Path>, force: bool) -> ExitCode {
    let loaded = match rosette::fabric::load_fabric(spec) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    if let Some(path) = out {
        let mut plan = Plan::new(force);
        plan.add("--out", path, ARCSIM_FILE);
        if let Err(e) = outputs::check(&plan, &[]) {
            return bad_input(e);
        }
    }
    for w in &loaded.warnings {
        errln!("warning: {w}");
    }
    let material = match loaded.config.to_fabric().and_then(|f| to_material(&f)) {
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
    // The look travels with the material, its texture found from wherever the file goes.
    let text = to_json_with_look(&material, &comments, &loaded.config.appearance.anchored(None));
    outputs::write_or_print(out, &text, "the material", "")
}
