//! `rosette chart --quick`: the sweep behind the speed/accuracy and stability charts writes
//! CSV files of the expected shape and non-blank PNGs, and the stability map agrees with
//! the explicit limit 2/ω_max computed from each model: symplectic Euler diverges above it
//! and stays bounded below it, while the implicit integrators stay bounded at those steps.

use rosette::settings::SolverPath;
use rosette::chart::{ChartOptions, INACCURATE_ERROR, Plan, Problem, Progress, Status};
use rosette::sim::IntegratorKind;
use std::path::Path;

fn lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).lines().map(str::to_string).collect()
}

/// The picture has the size of its panels and is not blank: plenty of ink, and the
/// integrators' or statuses' colours among it.
fn check_png(path: &Path, width: u32, height: u32) {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
    assert_eq!(image.dimensions(), (width, height), "{}", path.display());
    let pixels = image.pixels().count();
    let ink = image.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    let coloured = image.pixels().filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 80).count();
    println!("{}: {:.1} % ink, {coloured} coloured pixels", path.display(), 100.0 * ink as f64 / pixels as f64);
    assert!(ink > pixels / 50, "{}: nearly blank", path.display());
    assert!(coloured > 200, "{}: no data markers drawn", path.display());
}

#[test]
fn quick_chart_writes_its_tables_and_pictures_and_explicit_runs_fail_above_their_limit() {
    let out = std::env::temp_dir().join(format!("rosette-chart-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // Through the viewer's entry point, which `run` calls with a progress nobody watches.
    let progress = Progress::default();
    let report = rosette::chart::run_with_progress(&ChartOptions { out: out.clone(), quick: true, threads: 2 }, &progress)
        .unwrap_or_else(|e| panic!("{e}"));
    for line in &report.summary {
        println!("{line}");
    }
    let plan = Plan::new(true);
    // The progress counted every planned run (the quick sweep has no drape reference), and
    // none is left running.
    assert_eq!((progress.done(), progress.total()), (plan.accuracy.len() + plan.stability.len(), plan.accuracy.len() + plan.stability.len()));
    assert!(progress.running().is_empty() && !progress.is_cancelled());

    // The CSV files: their headers, and one row per planned run.
    let accuracy = lines(&out.join("accuracy.csv"));
    assert_eq!(accuracy[0], "problem,integrator,path,dt,dt_over_limit,edge_length,triangles,cpu_seconds,error,status,pareto");
    assert_eq!(accuracy.len() - 1, plan.accuracy.len());
    let stability = lines(&out.join("stability.csv"));
    assert_eq!(
        stability[0],
        "map,problem,integrator,dt,explicit_limit_dt,dt_over_limit,tensile_scale,bending_scale,tensile_stiffness,bending_stiffness,triangles,cpu_seconds,error,status"
    );
    assert_eq!(stability.len() - 1, plan.stability.len());
    let accuracy_columns = accuracy[0].split(',').count();
    assert!(accuracy.iter().all(|l| l.split(',').count() == accuracy_columns));
    let stability_columns = stability[0].split(',').count();
    assert!(stability.iter().all(|l| l.split(',').count() == stability_columns));
    // What was written reads back as what the sweep returned.
    let rows = rosette::chart::data::read_stability(&out.join("stability.csv")).unwrap();
    assert_eq!(rows.len(), report.stability.len());
    assert!(rosette::chart::data::read_accuracy(&out.join("accuracy.csv")).unwrap().iter().any(|r| r.pareto));

    // Stability against the computed limit, at each stiffness of each map.
    let explicit = |r: &rosette::chart::StabilityRow| r.integrator == IntegratorKind::SymplecticEuler;
    let above: Vec<_> = rows.iter().filter(|r| r.dt > 1.1 * r.explicit_limit).collect();
    assert!(above.iter().filter(|r| explicit(r)).count() >= 4 && above.iter().filter(|r| !explicit(r)).count() >= 8);
    for r in &above {
        let diverged = r.status == Status::Diverged;
        assert_eq!(diverged, explicit(r), "{:?} at dt = {:.3e} s, {:.2} x its limit: {:?}", r.integrator, r.dt, r.dt / r.explicit_limit, r.status);
    }
    let below: Vec<_> = rows.iter().filter(|r| r.dt < 0.9 * r.explicit_limit).collect();
    assert!(!below.is_empty());
    for r in &below {
        assert_eq!(r.status, Status::Bounded, "{:?} at {:.2} x its limit", r.integrator, r.dt / r.explicit_limit);
    }

    // Each problem's best run is within the accuracy threshold of its analytic answer, so
    // the errors charted are the method's, not a broken measure's.
    for problem in [Problem::Cantilever, Problem::Buckling, Problem::Tensile, Problem::Swing] {
        let best = report.accuracy.iter().filter(|r| r.problem == problem).filter_map(|r| r.error).fold(f64::INFINITY, f64::min);
        println!("{}: best error {best:.3e}", problem.name());
        assert!(best < INACCURATE_ERROR, "{}: best error {best}", problem.name());
    }

    // The fast path is charted beside exact Newton on the cantilever's mesh, and lands on
    // the same elastica: its error is the mesh's, not the path's.
    let fast: Vec<_> = report.accuracy.iter().filter(|r| r.path == SolverPath::Fast).collect();
    assert!(fast.iter().any(|r| r.problem == Problem::Cantilever), "no fast-path cantilever in the quick sweep");
    assert!(fast.iter().any(|r| r.problem == Problem::Swing), "no fast-path swing in the quick sweep");
    for r in &fast {
        let error = r.error.unwrap_or_else(|| panic!("fast path on {}: {}", r.problem.name(), r.status));
        println!("{} fast path: error {error:.3e} in {:.3} CPU s", r.problem.name(), r.cpu_seconds);
        assert!(error < INACCURATE_ERROR, "{} fast path: error {error}", r.problem.name());
    }

    let (w, h) = rosette::chart::plot::PANEL;
    // Four problems (the quick sweep has no drape): two rows of two panels.
    check_png(&out.join("accuracy.png"), 2 * w, 2 * h);
    check_png(&out.join("stability.png"), 2 * w, h + 40);
    std::fs::remove_dir_all(&out).ok();
}

/// The command line: an output directory that cannot be made is bad input (exit code 2),
/// reported before any run starts.
#[test]
fn chart_command_reports_an_unwritable_output_directory() {
    let blocker = std::env::temp_dir().join(format!("rosette-chart-blocker-{}", std::process::id()));
    std::fs::write(&blocker, "a file, not a directory").unwrap();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_rosette"))
        .args(["chart", "--quick", "--out"])
        .arg(blocker.join("out"))
        .output()
        .unwrap();
    std::fs::remove_file(&blocker).ok();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("cannot write") && stderr.contains("--out"), "{stderr}");
}
