//! `rosette fabric`: sheets turned into fabric files, their template, the bundled list and
//! the virtual laboratory's check.

use super::outputs::{self, FABRIC_FILE};
use super::{EXIT_DIVERGED, EXIT_READBACK, bad_input, say_error};
use rosette::fabric::{SheetKind, load_fabric, write};
use rosette::io::guard::Plan;
use rosette::{errln, out, outln};
use std::path::Path;
use std::process::ExitCode;

pub fn template(standard: Option<&str>) -> ExitCode {
    let kind = match standard {
        None => None,
        Some(s) => match SheetKind::ALL.into_iter().find(|k| k.section() == s) {
            Some(k) => Some(k),
            None => return bad_input(format!("--standard {s}: use kes, fast or cantilever")),
        },
    };
    out!("{}", write::template(kind));
    ExitCode::SUCCESS
}

pub fn list() -> ExitCode {
    for b in rosette::settings::FABRICS {
        match rosette::fabric::parse_fabric(b.text, b.name) {
            Ok(f) => {
                let mut sheets: Vec<&str> = f.sheets.sections().map(|s| s.kind.section()).collect();
                sheets.extend(f.sheets.arcsim.as_ref().map(|_| "arcsim"));
                let from = if sheets.is_empty() { "keys".to_string() } else { sheets.join("+") };
                let who = match f.sheets.measured_by() {
                    Some(who) => format!("measured by {who}"),
                    None if sheets.is_empty() => "representative values".into(),
                    None => "typical of its class".into(),
                };
                let look = f.config.look(None).map_or_else(|e| format!("look: {e}"), |l| l.summary());
                outln!("{:<24} {:<16} {:<40} {:<52} {}", b.name, from, look, who, f.config.description);
            }
            Err(e) => outln!("{:<20} error: {e}", b.name),
        }
    }
    ExitCode::SUCCESS
}

pub fn import(sheet: &str, out: Option<&Path>, force: bool) -> ExitCode {
    let loaded = match load_fabric(sheet) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    if loaded.sheets.is_empty() {
        return bad_input(format!(
            "{sheet}: no [kes], [fast] or [cantilever] section (nor an [arcsim] material) to import; `rosette fabric template` prints a sheet to fill in"
        ));
    }
    if let Some(path) = out {
        let mut plan = Plan::new(force);
        plan.add("--out", path, FABRIC_FILE);
        if let Err(e) = outputs::check(&plan, &[]) {
            return bad_input(e);
        }
    }
    for w in &loaded.warnings {
        errln!("warning: {w}");
    }
    // A texture's path is written absolute: the fabric file may be written anywhere.
    let config = rosette::settings::FabricConfig { appearance: loaded.config.appearance.anchored(None), ..loaded.config.clone() };
    let table = match toml::Table::try_from(&config) {
        Ok(t) => t,
        Err(e) => return bad_input(e),
    };
    let text = write::fabric_file(&table, &loaded.sheets, &loaded.import, sheet);
    outputs::write_or_print(out, &text, "the fabric file", "")
}

pub fn check(fabric: &str) -> ExitCode {
    let loaded = match load_fabric(fabric) {
        Ok(f) => f,
        Err(e) => return bad_input(e),
    };
    if loaded.sheets.is_empty() {
        return bad_input(format!("{fabric}: no measurement sheet to check against (its keys are written directly)"));
    }
    for w in &loaded.warnings {
        errln!("warning: {w}");
    }
    match rosette::lab::readback(&loaded.sheets, &loaded.import, &loaded.config) {
        Ok(r) => {
            out!("{}", r.table());
            if r.all_pass() { ExitCode::SUCCESS } else { ExitCode::from(EXIT_READBACK) }
        }
        Err(e) => {
            say_error(&e);
            ExitCode::from(EXIT_DIVERGED)
        }
    }
}
