//! `rosette view`: the scene, a script and its outputs read and checked before any window
//! opens, then the viewer.

use super::outputs::{self, PICTURE};
use rosette::app::script::Script;
use rosette::app::session::Report;
use rosette::app::viewer::{self, ViewerOptions};
use rosette::errln;
use rosette::io::guard::{Kind, Plan, Signature};
use std::path::Path;
use std::process::ExitCode;

/// A session's report, as the output guard recognises one.
const SESSION_REPORT: Kind = Kind { noun: "a session report", signature: Signature::Starts(Report::START) };

/// Opens the viewer on `options`, with the session `script` where one is given. Bad input
/// (the scene, the script, an output) is refused with exit 2 before the window opens; a
/// session that fails exits with its step's code.
pub fn view(mut options: ViewerOptions, script: Option<&Path>, force: bool) -> ExitCode {
    match prepare(&mut options, script, force) {
        Ok(()) => {}
        Err(e) => return super::bad_input(e),
    }
    match viewer::run(options) {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            errln!("error: {e:#}");
            ExitCode::from(super::EXIT_BAD_INPUT)
        }
    }
}

/// Loads the first scene and the script and checks the session's outputs.
fn prepare(options: &mut ViewerOptions, script: Option<&Path>, force: bool) -> Result<(), String> {
    let spec = options.preset.clone().unwrap_or_else(|| viewer::default_scene().to_string());
    let config = viewer::load_first_scene(&spec, &options.overrides)?;
    if let Some(path) = script {
        let script = Script::load(path, &config).map_err(|e| e.to_string())?;
        let mut plan = Plan::new(force);
        let flags: Vec<(String, &Path)> = script.outputs().map(|(line, p)| (format!("--script screenshot (line {line})"), p)).collect();
        for (flag, path) in &flags {
            plan.add(flag, path, PICTURE);
        }
        if let Some(report) = &options.report {
            plan.add("--report", report, SESSION_REPORT);
        }
        outputs::check(&plan, &[&config])?;
        options.script = Some(script);
    }
    options.config = Some(config);
    Ok(())
}
