//! `rosette bench`: the paper's Table 1 scenes and the Cusick drape at growing triangle
//! counts, each run as a child `rosette run` so that every case gets a fresh process: its
//! peak memory is its own and its thread count is set before rayon's pool exists.
//!
//! Reports CPU seconds per simulated second (the paper's unit ×100), the split of step time
//! into forces, linear solves and contact, memory per vertex (the peak resident size's
//! growth between the smallest and the largest drape, per vertex added) and the wall-clock
//! speed-up from one thread to two.

use crate::scene::Metrics;
use crate::settings::SolverPath;
use anyhow::{Context, Result, bail};
use serde::Serialize;
use crate::outln;
use std::fmt::Write;
use std::path::Path;
use std::process::Command;

/// One benchmark case: a scene, its overrides and the simulated window it runs.
struct Case {
    name: String,
    preset: &'static str,
    overrides: Vec<String>,
    /// Simulated seconds, or None for the scene's own duration (runs to settling).
    duration: Option<f64>,
    /// The paper's Table 1 CPU seconds per 10 ms, where it has this scene.
    paper: Option<f64>,
    /// Thread counts this case runs with (of those asked for); None: all of them. The whole
    /// fine drapes run on the two threads their targets are stated on.
    threads: Option<&'static [usize]>,
}

/// One measured run.
#[derive(Debug, Clone, Serialize)]
pub struct BenchRow {
    pub case: String,
    pub threads: usize,
    pub triangles: u64,
    pub vertices: u64,
    pub steps: u64,
    pub simulated_seconds: f64,
    pub wall_seconds: f64,
    pub cpu_seconds_per_simulated_second: f64,
    pub wall_seconds_per_simulated_second: f64,
    /// Shares of step time.
    pub forces_share: f64,
    pub solve_share: f64,
    pub contact_share: f64,
    /// The largest wall-clock speed-up any faster linear solver could give this run
    /// (Amdahl's bound): the reciprocal of the share of step time outside the solve.
    pub solver_speedup_bound: Option<f64>,
    pub newton_per_step: f64,
    pub cg_per_newton: f64,
    pub peak_memory_mb: f64,
    pub paper_cpu_seconds_per_10ms: Option<f64>,
    /// `exact` or `fast` (`solver.path`).
    pub path: String,
    /// The drape scenes' coefficient and nodes at the end of the run (a garment's: Cusick's
    /// against the form's waist, and the hem's nodes).
    pub drape_coefficient: Option<f64>,
    pub nodes: Option<usize>,
    /// The run stopped because the cloth settled.
    pub settled: Option<bool>,
    pub max_penetration: Option<f64>,
    pub self_intersections: Option<usize>,
    /// The step the run ended on, s.
    pub dt: f64,
    /// The swing's period against the hanging chain's, relative (swing scenes).
    pub period_error: Option<f64>,
}

/// Triangles of a `cusick-drape` disc at edge length `edge` are about 875·(0.0155/edge)².
fn drape_edge_for(triangles: f64) -> f64 {
    0.0155 * (875.0 / triangles).sqrt()
}

fn cases(quick: bool) -> Vec<Case> {
    let case = |name: &str, preset, overrides: Vec<String>, duration, paper| Case {
        name: name.to_string(),
        preset,
        overrides,
        duration,
        paper,
        threads: None,
    };
    let mut out = vec![
        case("tensile-bias", "tensile-bias", vec![], Some(if quick { 0.5 } else { 6.0 }), Some(8.06)),
        case("euler-buckling", "euler-buckling", vec![], Some(if quick { 0.2 } else { 8.0 }), Some(1.39)),
        case("shear-buckling", "shear-buckling", vec![], Some(if quick { 0.2 } else { 2.2 }), Some(9.58)),
    ];
    // Whole runs to a settled cloth, each on the exact path and the fast one, side by side:
    // what a user waits for.
    let both = |out: &mut Vec<Case>, name: &str, preset, overrides: Vec<String>, duration, threads| {
        for path in SolverPath::ALL {
            let mut o = overrides.clone();
            o.push(path.setting());
            out.push(Case { threads, ..case(&format!("{name}, {}", path.name()), preset, o, duration, None) });
        }
    };
    // A run on the fast path only, on two threads (where the exact path's whole run would
    // take too long to bench).
    let fast = |out: &mut Vec<Case>, name: &str, preset, mut overrides: Vec<String>| {
        overrides.push(SolverPath::Fast.setting());
        out.push(Case { threads: Some(&[2]), ..case(name, preset, overrides, None, None) });
    };
    let edge = |e: f64| vec![format!("mesh.edge_length={e:.5}")];
    if quick {
        both(&mut out, "cusick-drape, to settling", "cusick-drape", vec![], None, None);
    } else {
        // The paper's Fig. 6 scene, against Table 1.
        out.push(case("cusick-drape, to settling", "cusick-drape", vec![], None, Some(9.36)));
        both(&mut out, "cusick-drape 7.5 mm, to settling", "cusick-drape", edge(0.0075), None, None);
        both(&mut out, "cusick-drape ~20000 tri, to settling", "cusick-drape", edge(0.00315), None, Some(&[2]));
        // The fast path's growth with the mesh, whole runs (the exact path's growth is the
        // two-step rows below: its whole runs at 80 000 triangles take hours).
        for n in [5000.0, 80000.0] {
            fast(&mut out, &format!("cusick-drape ~{} tri, to settling, fast", n as u64), "cusick-drape", edge(drape_edge_for(n)));
        }
        // Cloth dropped onto props: the tablecloth to settling, and the peers' drop of a
        // 1 m² cloth onto a sphere over its first 0.4 s (the fall and the wrap), on one thread.
        both(&mut out, "tablecloth, to settling", "tablecloth", vec![], None, None);
        both(&mut out, "sphere-drop, first 0.4 s", "sphere-drop", vec![], Some(0.4), Some(&[1]));
        // Garments sewn on the form and settled, on both paths, on two threads.
        for garment in ["skirt-gored-straight", "skirt-gored-bias", "skirt-circle", "shift-dress"] {
            both(&mut out, &format!("{garment}, to settling"), garment, vec![], None, Some(&[2]));
        }
        // The same garments at about 10k triangles (9 956, 9 956, 10 226 and 9 789), on the
        // fast path only: the exact path takes 4–7 minutes each there (docs/garments.md).
        for (garment, e) in [("skirt-gored-straight", 0.0108), ("skirt-gored-bias", 0.0108), ("skirt-circle", 0.0141), ("shift-dress", 0.013)] {
            fast(&mut out, &format!("{garment} ~10k tri, to settling, fast"), garment, edge(e));
        }
        // The same drop on the fast path with the quasi-Newton minimizer
        // (`solver.newton.minimizer`), the step design docs/fast-path.md measured against Newton.
        let quasi_newton = vec![SolverPath::Fast.setting(), "solver.newton.minimizer=quasi-newton".into()];
        out.push(Case { threads: Some(&[1]), ..case("sphere-drop, first 0.4 s, fast, quasi-newton", "sphere-drop", quasi_newton, Some(0.4), None) });
    }
    // The same window for every size, so that their costs compare: the first two 4 ms
    // steps of the lowering (gravity ramps up over 2 s), short enough for 80 000 triangles
    // to finish in minutes. Whole runs to settling cost more per simulated second than
    // this start (docs/solvers.md, Benchmarks).
    let sizes: &[(f64, f64)] =
        if quick { &[(800.0, 0.008), (5000.0, 0.008)] } else { &[(800.0, 0.008), (5000.0, 0.008), (20000.0, 0.008), (80000.0, 0.008)] };
    // Each size with the complete factor and with multigrid, side by side.
    for &(n, window) in sizes {
        for solver in SOLVERS {
            out.push(case(
                &format!("cusick-drape ~{} tri, first {window} s, {solver}", n as u64),
                "cusick-drape",
                vec![format!("mesh.edge_length={:.5}", drape_edge_for(n)), format!("solver.newton.preconditioner={solver}")],
                Some(window),
                None,
            ));
        }
    }
    // Cloth in motion with a known answer: the swing on both paths (its period against the
    // hanging chain's is in the metrics), one thread.
    both(&mut out, "swing", "swing", vec![], None, Some(&[1]));
    out
}

/// The global preconditioners the drape sizes are run with (`solver.newton.preconditioner`).
const SOLVERS: [&str; 2] = ["cholesky", "multigrid"];

/// Runs `case` in a child process with `threads` rayon threads.
fn run_case(exe: &Path, case: &Case, threads: usize) -> Result<BenchRow> {
    let mut cmd = Command::new(exe);
    cmd.arg("run").arg(case.preset).args(["--metrics", "-"]).env("RAYON_NUM_THREADS", threads.to_string());
    for o in &case.overrides {
        cmd.args(["--set", o]);
    }
    if let Some(d) = case.duration {
        cmd.args(["--duration", &d.to_string()]);
    }
    let output = cmd.output().with_context(|| format!("starting {}", exe.display()))?;
    if !output.status.success() {
        bail!("{}: rosette run failed: {}", case.name, String::from_utf8_lossy(&output.stderr).trim());
    }
    let m: Metrics = serde_json::from_slice(&output.stdout).with_context(|| format!("{}: reading the run's metrics", case.name))?;
    let (forces, solve, contact) = (m.step_time.forces, m.step_time.solve, m.step_time.contact);
    let total = (forces + solve + contact).max(f64::MIN_POSITIVE);
    let newton = m.newton_iterations as f64;
    Ok(BenchRow {
        case: case.name.clone(),
        threads,
        triangles: m.triangles as u64,
        vertices: m.vertices as u64,
        steps: m.steps,
        simulated_seconds: m.simulated_seconds,
        wall_seconds: m.wall_seconds,
        cpu_seconds_per_simulated_second: m.cpu_seconds_per_simulated_second,
        wall_seconds_per_simulated_second: m.wall_seconds / m.simulated_seconds,
        forces_share: forces / total,
        solve_share: solve / total,
        contact_share: contact / total,
        solver_speedup_bound: (forces + contact > 0.0).then(|| total / (forces + contact)),
        newton_per_step: newton / m.steps.max(1) as f64,
        cg_per_newton: m.cg_iterations as f64 / newton.max(1.0),
        peak_memory_mb: m.peak_memory_bytes.map_or(f64::NAN, |b| b as f64) / 1e6,
        paper_cpu_seconds_per_10ms: case.paper,
        path: if case.overrides.contains(&SolverPath::Fast.setting()) { "fast" } else { "exact" }.to_string(),
        // A garment's coefficient is Cusick's against the form's waist, its nodes the hem's.
        drape_coefficient: m.measures.drape().map(|d| d.drape_coefficient).or(m.measures.garment().map(|g| g.garment_drape_coefficient)),
        nodes: m.measures.drape().map(|d| d.nodes).or(m.measures.garment().map(|g| g.hem_nodes)),
        settled: m.settled,
        max_penetration: m.max_penetration,
        self_intersections: m.self_intersections,
        dt: m.dt,
        period_error: m.measures.swing().and_then(|s| Some(s.swing_period? / s.chain_period - 1.0)),
    })
}

/// Runs the benchmark and writes `bench.csv` and `bench.json` into `out`.
pub fn run(out: &Path, quick: bool, threads: &[usize]) -> Result<Vec<BenchRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let rows = measure(quick, threads, None)?;
    write(out, &rows)?;
    Ok(rows)
}

/// The names of the cases whose name contains `only` (every case without it), in the
/// order they run.
pub fn case_names(quick: bool, only: Option<&str>) -> Vec<String> {
    cases(quick).into_iter().map(|c| c.name).filter(|n| only.is_none_or(|o| n.contains(o))).collect()
}

/// Runs every case (those whose name contains `only`, where given) with every thread
/// count (each in a child `rosette run`) and prints the table and its summary.
pub fn measure(quick: bool, threads: &[usize], only: Option<&str>) -> Result<Vec<BenchRow>> {
    if let Some(t) = threads.iter().find(|&&t| t == 0) {
        bail!("--threads {t}: a run needs at least one thread");
    }
    let exe = std::env::current_exe().context("locating the rosette executable")?;
    let mut rows = Vec::new();
    outln!(
        "{:<46} {:>3} {:>7} {:>10} {:>10} {:>6} {:>6} {:>6} {:>7} {:>7} {:>8}",
        "case", "thr", "tris", "CPU s/s", "wall s/s", "forces", "solve", "contact", "newton", "cg/nwt", "peak MB"
    );
    for case in cases(quick).into_iter().filter(|c| only.is_none_or(|o| c.name.contains(o))) {
        for &t in threads.iter().filter(|t| case.threads.is_none_or(|only| only.contains(t))) {
            let row = run_case(&exe, &case, t)?;
            outln!(
                "{:<46} {:>3} {:>7} {:>10.4} {:>10.4} {:>5.0}% {:>5.0}% {:>6.0}% {:>7.2} {:>7.1} {:>8.1}",
                row.case,
                row.threads,
                row.triangles,
                row.cpu_seconds_per_simulated_second,
                row.wall_seconds_per_simulated_second,
                100.0 * row.forces_share,
                100.0 * row.solve_share,
                100.0 * row.contact_share,
                row.newton_per_step,
                row.cg_per_newton,
                row.peak_memory_mb
            );
            rows.push(row);
        }
    }
    summarise(&rows);
    Ok(rows)
}

/// Writes `bench.csv` and `bench.json` into `out`, each whole or not at all.
pub fn write(out: &Path, rows: &[BenchRow]) -> Result<()> {
    let (csv, json) = (out.join("bench.csv"), out.join("bench.json"));
    crate::io::write::whole(&csv, csv_text(rows).as_bytes()).with_context(|| format!("cannot write {}", csv.display()))?;
    let text = serde_json::to_string_pretty(rows)? + "\n";
    crate::io::write::whole(&json, text.as_bytes()).with_context(|| format!("cannot write {}", json.display()))?;
    outln!("wrote {} and {}", csv.display(), json.display());
    Ok(())
}

/// Prints the ratios the rows imply: against the paper, thread speed-up, memory per vertex.
fn summarise(rows: &[BenchRow]) {
    for r in rows.iter().filter(|r| r.threads == 1) {
        if let Some(paper) = r.paper_cpu_seconds_per_10ms {
            let ours = r.cpu_seconds_per_simulated_second * 0.01;
            outln!("{}: {ours:.5} CPU s per 10 ms, {:.0}x faster than the paper's {paper}", r.case, paper / ours);
        }
        if let Some(error) = r.period_error {
            outln!("{}: period {:+.3} % against the hanging chain's, at {} s steps, {:.2} wall s per simulated s", r.case, 100.0 * error, r.dt, r.wall_seconds_per_simulated_second);
        }
        if let Some(two) = rows.iter().find(|o| o.case == r.case && o.threads == 2) {
            outln!("{}: 1 -> 2 threads, wall-clock speed-up {:.2}x", r.case, r.wall_seconds / two.wall_seconds);
        }
    }
    for solver in SOLVERS {
        let drapes: Vec<&BenchRow> = rows.iter().filter(|r| r.threads == 1 && r.case.contains("first") && r.case.ends_with(solver)).collect();
        if let (Some(small), Some(large)) = (drapes.first(), drapes.last())
            && large.vertices > small.vertices
        {
            let per_vertex = (large.peak_memory_mb - small.peak_memory_mb) * 1e6 / (large.vertices - small.vertices) as f64;
            outln!("{solver}: memory {per_vertex:.0} bytes per vertex (peak resident growth from {} to {} vertices)", small.vertices, large.vertices);
            // Cost ∝ N^p between the smallest and the largest drape: p = 1 is linear growth.
            let exponent = (large.cpu_seconds_per_simulated_second / small.cpu_seconds_per_simulated_second).ln()
                / (large.triangles as f64 / small.triangles as f64).ln();
            outln!(
                "{solver}: cost growth, CPU per simulated second grows as (triangles)^{exponent:.2} from {} to {} triangles",
                small.triangles, large.triangles
            );
        }
    }
    // What any linear solver could gain at most (Amdahl's bound): the forces, assembly and
    // contact of the complete factor's run stay whatever the solver, so a solver that cost
    // nothing would leave them. The bound is generous: it assumes the same Newton
    // iterations and counts step time only, not the set-up outside the steps.
    for r in rows.iter().filter(|r| r.case.ends_with(SOLVERS[0])) {
        if let Some(bound) = r.solver_speedup_bound {
            outln!(
                "{} tri, {} thread(s): the linear solve is {:.0} % of the complete factor's step time; no solver can make this run more than {bound:.2}x faster",
                r.triangles,
                r.threads,
                100.0 * r.solve_share
            );
        }
    }
    // The fast path against the exact one on the same scene and threads: time to a settled
    // cloth, and what it settled on.
    for fast in rows.iter().filter(|r| r.path == "fast") {
        let exact_case = fast.case.replace(", fast", ", exact");
        let Some(exact) = rows.iter().find(|o| o.case == exact_case && o.threads == fast.threads) else { continue };
        let drape = |r: &BenchRow| r.drape_coefficient.map_or(String::new(), |dc| format!(", DC {dc:.3} with {} nodes", r.nodes.unwrap_or(0)));
        outln!(
            "{}, {} thread(s): fast path {:.1} s wall ({:.2}x real time{}) against exact {:.1} s ({}): {:.1}x faster",
            fast.case.trim_end_matches(", fast"),
            fast.threads,
            fast.wall_seconds,
            fast.simulated_seconds / fast.wall_seconds,
            drape(fast),
            exact.wall_seconds,
            drape(exact).trim_start_matches(", "),
            exact.wall_seconds / fast.wall_seconds
        );
    }
    // The fast path's growth: wall seconds per simulated second of whole runs against the
    // triangle count, between each pair of sizes.
    let mut growth: Vec<&BenchRow> =
        rows.iter().filter(|r| r.path == "fast" && r.case.starts_with("cusick-drape ~") && r.case.contains("to settling")).collect();
    growth.sort_by_key(|r| r.triangles);
    for pair in growth.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        if a.threads == b.threads && b.triangles > a.triangles {
            let exponent = (b.wall_seconds_per_simulated_second / a.wall_seconds_per_simulated_second).ln() / (b.triangles as f64 / a.triangles as f64).ln();
            outln!("fast path: wall s per simulated s grows as (triangles)^{exponent:.2} from {} to {} triangles", a.triangles, b.triangles);
        }
    }
    // Multigrid against the complete factor at each size and thread count (wall time).
    for r in rows.iter().filter(|r| r.case.ends_with(SOLVERS[1])) {
        let direct_case = r.case.replace(SOLVERS[1], SOLVERS[0]);
        if let Some(direct) = rows.iter().find(|o| o.case == direct_case && o.threads == r.threads) {
            outln!("{} tri, {} thread(s): multigrid {:.2}x the speed of the complete factor", r.triangles, r.threads, direct.wall_seconds / r.wall_seconds);
        }
    }
}

/// A column of bench.csv: its header, and how a row writes its field.
type Column = (&'static str, fn(&BenchRow) -> String);

/// The columns of bench.csv, each its header beside how a row writes it (an absent value
/// is an empty field).
const COLUMNS: &[Column] = &[
    ("case", |r| format!("\"{}\"", r.case)),
    ("threads", |r| r.threads.to_string()),
    ("triangles", |r| r.triangles.to_string()),
    ("vertices", |r| r.vertices.to_string()),
    ("steps", |r| r.steps.to_string()),
    ("simulated_seconds", |r| r.simulated_seconds.to_string()),
    ("wall_seconds", |r| r.wall_seconds.to_string()),
    ("cpu_seconds_per_simulated_second", |r| r.cpu_seconds_per_simulated_second.to_string()),
    ("wall_seconds_per_simulated_second", |r| r.wall_seconds_per_simulated_second.to_string()),
    ("forces_share", |r| r.forces_share.to_string()),
    ("solve_share", |r| r.solve_share.to_string()),
    ("contact_share", |r| r.contact_share.to_string()),
    ("solver_speedup_bound", |r| optional(r.solver_speedup_bound)),
    ("newton_per_step", |r| r.newton_per_step.to_string()),
    ("cg_per_newton", |r| r.cg_per_newton.to_string()),
    ("peak_memory_mb", |r| r.peak_memory_mb.to_string()),
    ("paper_cpu_seconds_per_10ms", |r| optional(r.paper_cpu_seconds_per_10ms)),
    ("path", |r| r.path.clone()),
    ("drape_coefficient", |r| optional(r.drape_coefficient)),
    ("nodes", |r| optional(r.nodes)),
    ("settled", |r| optional(r.settled)),
    ("max_penetration", |r| optional(r.max_penetration)),
    ("self_intersections", |r| optional(r.self_intersections)),
    ("dt", |r| r.dt.to_string()),
    ("period_error", |r| optional(r.period_error)),
];

fn optional<T: std::fmt::Display>(value: Option<T>) -> String {
    value.map_or(String::new(), |v| v.to_string())
}

fn csv_text(rows: &[BenchRow]) -> String {
    let mut f = String::new();
    let _ = writeln!(f, "{}", COLUMNS.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(","));
    for r in rows {
        let _ = writeln!(f, "{}", COLUMNS.iter().map(|(_, value)| value(r)).collect::<Vec<_>>().join(","));
    }
    f
}
