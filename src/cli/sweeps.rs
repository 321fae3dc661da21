//! `rosette chart` and `rosette bench`: long sweeps whose outputs are checked before the
//! first run, so that a bad `--out` costs nothing.

use super::outputs::{self, ACCURACY_CSV, BENCH_CSV, BENCH_JSON, DRAPE_REFERENCE_CSV, PICTURE, STABILITY_CSV};
use super::{EXIT_DIVERGED, bad_input, lost_output, say_error};
use rosette::io::guard::Plan;
use rosette::{errln, outln};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub fn chart(out: PathBuf, quick: bool, force: bool) -> ExitCode {
    use rosette::chart::ChartError;
    if let Err(e) = outputs::folder("--out", &out) {
        return bad_input(e);
    }
    let mut plan = Plan::new(force);
    for (name, kind) in [("accuracy.csv", ACCURACY_CSV), ("stability.csv", STABILITY_CSV), ("accuracy.png", PICTURE), ("stability.png", PICTURE)] {
        plan.add("--out", &out.join(name), kind);
    }
    if !quick {
        plan.add("--out", &out.join("drape-reference.csv"), DRAPE_REFERENCE_CSV);
    }
    if let Err(e) = outputs::check(&plan, &[]) {
        return bad_input(e);
    }
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    match rosette::chart::run(&rosette::chart::ChartOptions { out, quick, threads }) {
        Ok(report) => {
            for line in &report.summary {
                outln!("{line}");
            }
            for file in &report.files {
                errln!("wrote {}", file.display());
            }
            ExitCode::SUCCESS
        }
        Err(e @ (ChartError::Write { .. } | ChartError::Plot { .. })) => lost_output(e),
        Err(e) => bad_input(e),
    }
}

pub fn bench(out: &Path, quick: bool, threads: &[usize], only: Option<&str>, force: bool) -> ExitCode {
    if let Err(e) = outputs::folder("--out", out) {
        return bad_input(e);
    }
    if let Some(only) = only
        && rosette::bench::case_names(quick, Some(only)).is_empty()
    {
        let all = rosette::bench::case_names(quick, None);
        return bad_input(format!("--only {only}: no bench case's name contains it; the cases{} are: {}", if quick { " with --quick" } else { "" }, all.join("; ")));
    }
    let mut plan = Plan::new(force);
    plan.add("--out", &out.join("bench.csv"), BENCH_CSV);
    plan.add("--out", &out.join("bench.json"), BENCH_JSON);
    if let Err(e) = outputs::check(&plan, &[]) {
        return bad_input(e);
    }
    let rows = match rosette::bench::measure(quick, threads, only) {
        Ok(rows) => rows,
        Err(e) => {
            say_error(format!("{e:#}"));
            return ExitCode::from(EXIT_DIVERGED);
        }
    };
    match rosette::bench::write(out, &rows) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => lost_output(format!("{e:#}")),
    }
}
