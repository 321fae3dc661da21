//! `rosette chart`: speed against accuracy, and where each integrator stays stable.
//!
//! A sweep runs the laboratory problems with known answers (cantilever and post-buckled
//! strip against the elastica, the tensile curve against its input, the drape coefficient
//! against a fine mesh) over integrators, time steps and mesh sizes, and the stability
//! problems over time steps and tensile or bending stiffness. It writes `accuracy.csv` and
//! `stability.csv` and draws them as `accuracy.png` and `stability.png`.

pub mod data;
pub mod plot;
pub mod sweep;

pub use crate::io::progress::Progress;
pub use data::{AccuracyRow, StabilityRow};
pub use sweep::{Case, INACCURATE_ERROR, Outcome, Problem, Status, Step};

use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ChartError {
    #[error("cannot write {path}: {source}. Choose a writable directory with --out DIR")]
    Write { path: PathBuf, source: std::io::Error },
    #[error("cannot read {path}: {message}")]
    Read { path: PathBuf, message: String },
    #[error("cannot draw {path}: {message}")]
    Plot { path: PathBuf, message: String },
    #[error("the sweep was cancelled after {done} of {total} runs; nothing was written")]
    Cancelled { done: usize, total: usize },
}

/// What to sweep and where to write it.
#[derive(Debug, Clone)]
pub struct ChartOptions {
    pub out: PathBuf,
    /// The CI variant: fewer, smaller runs, no drape.
    pub quick: bool,
    /// Runs in parallel (each run is single-threaded).
    pub threads: usize,
}

/// What a sweep produced.
#[derive(Debug, Clone)]
pub struct ChartReport {
    pub accuracy: Vec<AccuracyRow>,
    pub stability: Vec<StabilityRow>,
    pub files: Vec<PathBuf>,
    /// One line per problem and per stability map.
    pub summary: Vec<String>,
}

/// The stability maps: which problem, and which stiffness is varied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StabilityMap {
    /// The tensile pull with both tensile curves scaled.
    Tensile,
    /// The cantilever with the bending rigidities scaled.
    Bending,
}

impl StabilityMap {
    pub const ALL: [StabilityMap; 2] = [Self::Tensile, Self::Bending];

    pub fn name(self) -> &'static str {
        match self {
            Self::Tensile => "tensile",
            Self::Bending => "bending",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    fn problem(self) -> Problem {
        match self {
            Self::Tensile => Problem::Tensile,
            Self::Bending => Problem::Cantilever,
        }
    }
}

/// The sweep: every case of the accuracy chart, of each stability map, and the drape's
/// fine-mesh reference.
pub struct Plan {
    pub accuracy: Vec<Case>,
    pub stability: Vec<(StabilityMap, Case)>,
    pub drape_reference: Option<Case>,
}

fn case(problem: Problem, integrator: IntegratorKind, step: Step, edge_length: f64) -> Case {
    Case { problem, integrator, path: SolverPath::Exact, step, edge_length, tensile_scale: 1.0, bending_scale: 1.0 }
}

impl Plan {
    pub fn new(quick: bool) -> Self {
        use IntegratorKind::*;
        let mut accuracy = Vec::new();
        // Mesh edge lengths per problem, coarse to fine, and implicit time steps, s.
        // Explicit runs are placed at 0.9 of their own stability limit, and on the coarsest
        // mesh also at 0.45 (except the drape).
        let problems: Vec<(Problem, Vec<f64>, Vec<f64>)> = if quick {
            vec![
                (Problem::Cantilever, vec![0.005], vec![0.02, 0.005]),
                (Problem::Buckling, vec![0.01], vec![0.01]),
                (Problem::Tensile, vec![0.01], vec![0.05, 0.01, 0.002]),
                (Problem::Swing, vec![0.01], vec![0.016, 0.004]),
            ]
        } else {
            vec![
                (Problem::Cantilever, vec![0.005, 0.0025, 0.001667], vec![0.02, 0.005]),
                (Problem::Buckling, vec![0.01, 0.006667, 0.005], vec![0.01, 0.004]),
                (Problem::Tensile, vec![0.01, 0.005, 0.0025], vec![0.05, 0.01, 0.002]),
                (Problem::Drape, vec![0.03, 0.0225, 0.0155], vec![0.008, 0.004]),
                (Problem::Swing, vec![0.01, 0.005], vec![0.016, 0.008, 0.004, 0.002]),
            ]
        };
        for (problem, edges, dts) in problems {
            for (i, &edge) in edges.iter().enumerate() {
                for &dt in &dts {
                    accuracy.push(case(problem, ImplicitEuler, Step::Seconds(dt), edge));
                    accuracy.push(case(problem, Bdf2, Step::Seconds(dt), edge));
                }
                // An explicit drape needs tens of thousands of steps at its stability limit,
                // and the limit shrinks with the edge: the finer meshes would take most of
                // the sweep's time, so the explicit drape runs on the coarsest mesh only.
                if problem != Problem::Drape || i == 0 {
                    accuracy.push(case(problem, SymplecticEuler, Step::OfLimit(0.9), edge));
                }
                if i == 0 && !quick && problem != Problem::Drape {
                    accuracy.push(case(problem, SymplecticEuler, Step::OfLimit(0.45), edge));
                }
                // The equilibrium problems on the fast path as `--fast` runs them (its step
                // chosen per level), beside exact Newton on the same meshes.
                if matches!(problem, Problem::Cantilever | Problem::Drape) {
                    accuracy.push(Case { path: SolverPath::Fast, ..case(problem, ImplicitEuler, Step::Scene, edge) });
                }
                // The swing on the fast path's step for cloth in motion, with both implicit
                // integrators: the error a long step makes on a moving cloth.
                if problem == Problem::Swing {
                    for integrator in [ImplicitEuler, Bdf2] {
                        accuracy.push(Case { path: SolverPath::Fast, ..case(problem, integrator, Step::Scene, edge) });
                    }
                }
            }
        }
        // Stability: coarse meshes, time steps as multiples of each model's explicit limit.
        // Implicit runs start above the limit: below it they show nothing the explicit runs
        // do not, and cost a Newton solve per tiny step. Wool's bending rigidity is scaled
        // up to board-like values because the membrane sets the explicit limit of a
        // 4 mm mesh until the rigidity is about a thousand times wool's.
        let tensile_scales: &[f64] = if quick { &[0.25, 2.0] } else { &[0.0625, 0.25, 1.0, 4.0, 16.0] };
        let bending_scales: &[f64] = if quick { &[1.0, 16384.0] } else { &[1.0, 64.0, 1024.0, 4096.0, 16384.0] };
        let explicit_factors: &[f64] = if quick { &[0.5, 1.5, 4.0] } else { &[0.5, 0.9, 0.97, 1.03, 1.25, 2.0, 8.0] };
        let implicit_factors: &[f64] = if quick { &[4.0, 64.0] } else { &[4.0, 32.0, 256.0, 1024.0] };
        let mut stability = Vec::new();
        for map in StabilityMap::ALL {
            let (edge, scales) = match map {
                StabilityMap::Tensile => (0.01, tensile_scales),
                // 10 cells along the 4 cm strip: within 5 % of the elastica at every λ here.
                StabilityMap::Bending => (0.004, bending_scales),
            };
            for &scale in scales {
                let mut add = |integrator, factor| {
                    let mut c = case(map.problem(), integrator, Step::OfLimit(factor), edge);
                    match map {
                        StabilityMap::Tensile => c.tensile_scale = scale,
                        StabilityMap::Bending => c.bending_scale = scale,
                    }
                    stability.push((map, c));
                };
                for &factor in explicit_factors {
                    add(SymplecticEuler, factor);
                }
                for &factor in implicit_factors {
                    add(ImplicitEuler, factor);
                    add(Bdf2, factor);
                }
            }
        }
        // The drape's reference: 1.5 times finer than the finest mesh swept.
        let drape_reference = (!quick).then(|| case(Problem::Drape, ImplicitEuler, Step::Seconds(0.004), 0.0103));
        Self { accuracy, stability, drape_reference }
    }
}

/// Runs the sweep, writes the CSVs and PNGs into `options.out`, and returns what it wrote.
pub fn run(options: &ChartOptions) -> Result<ChartReport, ChartError> {
    run_with_progress(options, &Progress::default())
}

/// [`run`], reporting each run's start and end to `progress` and stopping early, with
/// [`ChartError::Cancelled`] and no files written, once `progress` is cancelled. The runs and
/// their results are those of [`run`].
pub fn run_with_progress(options: &ChartOptions, progress: &Progress) -> Result<ChartReport, ChartError> {
    let out = &options.out;
    std::fs::create_dir_all(out).map_err(|source| ChartError::Write { path: out.clone(), source })?;
    let plan = Plan::new(options.quick);
    let reference_file = out.join("drape-reference.csv");
    let cached = plan.drape_reference.and_then(|c| data::read_drape_reference(&reference_file, &c));
    // Every run, the uncached drape reference included, goes through one pool. The
    // reference, the longest run, goes first so that the pool does not end on it alone.
    let mut jobs: Vec<Case> = plan.accuracy.clone();
    jobs.extend(plan.stability.iter().map(|(_, c)| *c));
    if let (Some(reference), None) = (plan.drape_reference, cached) {
        jobs.insert(0, reference);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.max(1))
        .thread_name(|i| format!("rosette-chart-{i}"))
        .build()
        .expect("a thread pool");
    progress.set_total(jobs.len());
    let outcomes: Vec<Option<Outcome>> = pool.install(|| jobs.par_iter().map(|case| progress.run(&case.label(), || case.run())).collect());
    if progress.is_cancelled() {
        return Err(ChartError::Cancelled { done: outcomes.iter().flatten().count(), total: jobs.len() });
    }
    let outcomes: Vec<Outcome> = outcomes.into_iter().flatten().collect();
    // Runs that could not be set up or measured (not divergences, which are results).
    let failures: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.diverged)
        .filter_map(|o| Some(format!("{} {} dt {:.3e}: {}", o.case.problem.name(), o.case.integrator, o.dt, o.message.as_ref()?)))
        .collect();
    let mut outcomes = outcomes.into_iter();
    let reference = match (plan.drape_reference, cached) {
        (_, Some(value)) => Some(value),
        (Some(_), None) => {
            let outcome = outcomes.next().expect("the reference run");
            data::write_drape_reference(&reference_file, &outcome)?;
            outcome.measure
        }
        (None, None) => None,
    };
    let mut accuracy: Vec<Outcome> = outcomes.by_ref().take(plan.accuracy.len()).collect();
    for o in accuracy.iter_mut().filter(|o| o.case.problem == Problem::Drape) {
        o.error = match (o.measure, reference) {
            (Some(dc), Some(reference)) if !o.diverged => Some((dc - reference).abs()),
            _ => None,
        };
    }
    let stability: Vec<StabilityRow> = plan.stability.iter().zip(outcomes).map(|((map, _), o)| StabilityRow::new(*map, &o)).collect();
    let accuracy = data::accuracy_rows(&accuracy);
    let mut files = vec![out.join("accuracy.csv"), out.join("stability.csv")];
    data::write_accuracy(&files[0], &accuracy)?;
    data::write_stability(&files[1], &stability)?;
    if plan.drape_reference.is_some() {
        files.push(reference_file);
    }
    for (name, draw) in [
        ("accuracy.png", plot::draw_accuracy as fn(&Path, &[AccuracyRow], &[StabilityRow]) -> Result<(), String>),
        ("stability.png", plot::draw_stability),
    ] {
        let path = out.join(name);
        draw(&path, &accuracy, &stability).map_err(|message| ChartError::Plot { path: path.clone(), message })?;
        files.push(path);
    }
    let mut summary = summarise(&accuracy, &stability, reference);
    summary.extend(failures.into_iter().map(|f| format!("failed: {f}")));
    Ok(ChartReport { accuracy, stability, files, summary })
}

/// One line per problem (the Pareto front from cheap to accurate) and per stability map
/// (the explicit runs' fate either side of the limit).
fn summarise(accuracy: &[AccuracyRow], stability: &[StabilityRow], drape_reference: Option<f64>) -> Vec<String> {
    let mut lines = Vec::new();
    for problem in Problem::ALL {
        let rows: Vec<&AccuracyRow> = accuracy.iter().filter(|r| r.problem == problem).collect();
        if rows.is_empty() {
            continue;
        }
        let mut front: Vec<&&AccuracyRow> = rows.iter().filter(|r| r.pareto).collect();
        front.sort_by(|a, b| a.cpu_seconds.total_cmp(&b.cpu_seconds));
        let diverged = rows.iter().filter(|r| r.status == "diverged").count();
        let front_text: Vec<String> = front
            .iter()
            .map(|r| format!("{} dt {:.2e} h {:.4} ({:.3} s, {:.2e})", r.integrator, r.dt, r.edge_length, r.cpu_seconds, r.error.unwrap_or(f64::NAN)))
            .collect();
        let reference = match (problem, drape_reference) {
            (Problem::Drape, Some(dc)) => format!(" [reference DC {dc:.4}]"),
            _ => String::new(),
        };
        lines.push(format!("{}: {} runs, {diverged} diverged{reference}; Pareto front: {}", problem.name(), rows.len(), front_text.join(", ")));
    }
    for map in StabilityMap::ALL {
        let rows: Vec<&StabilityRow> = stability.iter().filter(|r| r.map == map).collect();
        if rows.is_empty() {
            continue;
        }
        let count = |pred: &dyn Fn(&StabilityRow) -> bool| rows.iter().filter(|r| pred(r)).count();
        let explicit = |r: &StabilityRow| r.integrator == IntegratorKind::SymplecticEuler;
        lines.push(format!(
            "stability ({} stiffness): explicit below its limit {} bounded of {}, above 1.1x {} diverged of {}; implicit {} diverged of {}",
            map.name(),
            count(&|r| explicit(r) && r.dt < r.explicit_limit && r.status != Status::Diverged),
            count(&|r| explicit(r) && r.dt < r.explicit_limit),
            count(&|r| explicit(r) && r.dt > 1.1 * r.explicit_limit && r.status == Status::Diverged),
            count(&|r| explicit(r) && r.dt > 1.1 * r.explicit_limit),
            count(&|r| !explicit(r) && r.status == Status::Diverged),
            count(&|r| !explicit(r)),
        ));
    }
    lines
}
