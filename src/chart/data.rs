//! The chart's tables: rows, the Pareto front, and their CSV files (written by the sweep,
//! read back by the viewer).

use super::sweep::{Case, Outcome, Problem, Status};
use super::{ChartError, StabilityMap};
use crate::settings::SolverPath;
use crate::sim::IntegratorKind;
use std::fmt::Write as _;
use std::path::Path;

pub const ACCURACY_HEADER: &str = "problem,integrator,path,dt,dt_over_limit,edge_length,triangles,cpu_seconds,error,status,pareto";
pub const STABILITY_HEADER: &str = "map,problem,integrator,dt,explicit_limit_dt,dt_over_limit,tensile_scale,bending_scale,tensile_stiffness,bending_stiffness,triangles,cpu_seconds,error,status";

/// One run of the accuracy chart.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracyRow {
    pub problem: Problem,
    pub integrator: IntegratorKind,
    /// The exact solver path or the fast one (`solver.path`).
    pub path: SolverPath,
    /// Time step, s.
    pub dt: f64,
    /// The time step over the explicit stability limit of the same model.
    pub dt_over_limit: f64,
    /// Mesh edge length, m.
    pub edge_length: f64,
    pub triangles: usize,
    /// CPU seconds of the whole run.
    pub cpu_seconds: f64,
    /// Error against the known answer; `None` when the run diverged or gave no measure.
    pub error: Option<f64>,
    /// `ok`, `diverged` or `failed` (no measure).
    pub status: String,
    /// No other run of the problem is both cheaper and more accurate.
    pub pareto: bool,
}

/// One run of a stability map.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilityRow {
    pub map: StabilityMap,
    pub problem: Problem,
    pub integrator: IntegratorKind,
    /// Time step, s.
    pub dt: f64,
    /// Symplectic-Euler limit 2/ω_max of the run's model, s.
    pub explicit_limit: f64,
    pub tensile_scale: f64,
    pub bending_scale: f64,
    /// Initial warp tensile slope, N/m.
    pub tensile_stiffness: f64,
    /// Warp bending rigidity, N·m.
    pub bending_stiffness: f64,
    pub triangles: usize,
    pub cpu_seconds: f64,
    pub error: Option<f64>,
    pub status: Status,
}

impl StabilityRow {
    pub fn new(map: StabilityMap, o: &Outcome) -> Self {
        Self {
            map,
            problem: o.case.problem,
            integrator: o.case.integrator,
            dt: o.dt,
            explicit_limit: o.explicit_limit,
            tensile_scale: o.case.tensile_scale,
            bending_scale: o.case.bending_scale,
            tensile_stiffness: o.tensile_stiffness,
            bending_stiffness: o.bending_stiffness,
            triangles: o.triangles,
            cpu_seconds: o.cpu_seconds,
            error: o.error,
            status: o.status(),
        }
    }

    /// The stiffness the map varies: N/m for tensile, N·m for bending.
    pub fn stiffness(&self) -> f64 {
        match self.map {
            StabilityMap::Tensile => self.tensile_stiffness,
            StabilityMap::Bending => self.bending_stiffness,
        }
    }
}

/// Rows for the accuracy chart, with the Pareto front of each problem marked.
pub fn accuracy_rows(outcomes: &[Outcome]) -> Vec<AccuracyRow> {
    let mut rows: Vec<AccuracyRow> = outcomes
        .iter()
        .map(|o| AccuracyRow {
            problem: o.case.problem,
            integrator: o.case.integrator,
            path: o.case.path,
            dt: o.dt,
            dt_over_limit: o.dt / o.explicit_limit,
            edge_length: o.case.edge_length,
            triangles: o.triangles,
            cpu_seconds: o.cpu_seconds,
            error: if o.diverged { None } else { o.error },
            status: if o.diverged {
                "diverged"
            } else if o.error.is_some() {
                "ok"
            } else {
                "failed"
            }
            .to_string(),
            pareto: false,
        })
        .collect();
    mark_pareto(&mut rows);
    rows
}

/// Marks, per problem, the runs that no other run beats in both CPU time and error (ties
/// broken by the earlier row, so that equal runs are not all on the front).
pub fn mark_pareto(rows: &mut [AccuracyRow]) {
    let snapshot: Vec<(Problem, f64, Option<f64>)> = rows.iter().map(|r| (r.problem, r.cpu_seconds, r.error)).collect();
    for (i, row) in rows.iter_mut().enumerate() {
        let Some(error) = row.error else { continue };
        row.pareto = !snapshot.iter().enumerate().any(|(j, &(problem, cpu, other))| {
            let Some(other) = other else { return false };
            let no_worse = problem == row.problem && cpu <= row.cpu_seconds && other <= error;
            let better = cpu < row.cpu_seconds || other < error || j < i;
            j != i && no_worse && better
        });
    }
}

fn number(value: Option<f64>) -> String {
    value.filter(|v| v.is_finite()).map_or(String::new(), |v| format!("{v:.6e}"))
}

fn write(path: &Path, text: &str) -> Result<(), ChartError> {
    crate::io::write::whole(path, text.as_bytes()).map_err(|source| ChartError::Write { path: path.to_path_buf(), source })
}

pub fn write_accuracy(path: &Path, rows: &[AccuracyRow]) -> Result<(), ChartError> {
    let mut text = format!("{ACCURACY_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{},{}",
            r.problem.name(),
            r.integrator.name(),
            r.path.name(),
            number(Some(r.dt)),
            number(Some(r.dt_over_limit)),
            r.edge_length,
            r.triangles,
            number(Some(r.cpu_seconds)),
            number(r.error),
            r.status,
            r.pareto
        );
    }
    write(path, &text)
}

pub fn write_stability(path: &Path, rows: &[StabilityRow]) -> Result<(), ChartError> {
    let mut text = format!("{STABILITY_HEADER}\n");
    for r in rows {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.map.name(),
            r.problem.name(),
            r.integrator.name(),
            number(Some(r.dt)),
            number(Some(r.explicit_limit)),
            number(Some(r.dt / r.explicit_limit)),
            r.tensile_scale,
            r.bending_scale,
            number(Some(r.tensile_stiffness)),
            number(Some(r.bending_stiffness)),
            r.triangles,
            number(Some(r.cpu_seconds)),
            number(r.error),
            r.status.name()
        );
    }
    write(path, &text)
}

/// The text of a file, or the error that names it.
fn read_text(path: &Path) -> Result<String, ChartError> {
    crate::io::read::read_text(path, crate::io::read::FileKind::Csv).map_err(|e| ChartError::Read { path: path.to_path_buf(), message: e.to_string() })
}

/// The records of a CSV file with the expected header, as fields.
fn records(path: &Path, header: &str) -> Result<Vec<Vec<String>>, ChartError> {
    records_in(&read_text(path)?, path, header)
}

/// The records of CSV text with the expected header, as fields; `origin` names the text in
/// errors.
fn records_in(text: &str, origin: &Path, header: &str) -> Result<Vec<Vec<String>>, ChartError> {
    let bad = |message: String| ChartError::Read { path: origin.to_path_buf(), message };
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return Err(bad(format!("the first line should be the header `{header}`")));
    }
    let columns = header.split(',').count();
    lines
        .enumerate()
        .map(|(i, line)| {
            let fields: Vec<String> = line.split(',').map(str::to_string).collect();
            if fields.len() == columns { Ok(fields) } else { Err(bad(format!("line {}: {} fields, expected {columns}", i + 2, fields.len()))) }
        })
        .collect()
}

fn parse_integrator(name: &str) -> Option<IntegratorKind> {
    IntegratorKind::ALL.into_iter().find(|k| k.name() == name)
}

fn parse_optional(text: &str) -> Result<Option<f64>, String> {
    if text.is_empty() { Ok(None) } else { text.parse().map(Some).map_err(|_| format!("`{text}` is not a number")) }
}

fn parse_number(text: &str) -> Result<f64, String> {
    parse_optional(text)?.ok_or_else(|| "a number is missing".to_string())
}

pub fn read_accuracy(path: &Path) -> Result<Vec<AccuracyRow>, ChartError> {
    parse_accuracy(&read_text(path)?, path)
}

/// The rows of `accuracy.csv` text (as [`read_accuracy`] reads from a file, e.g. a table
/// compiled into the binary); `origin` names the text in errors.
pub fn parse_accuracy(text: &str, origin: &Path) -> Result<Vec<AccuracyRow>, ChartError> {
    records_in(text, origin, ACCURACY_HEADER)?
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let row = || -> Result<AccuracyRow, String> {
                Ok(AccuracyRow {
                    problem: Problem::from_name(&f[0]).ok_or(format!("unknown problem `{}`", f[0]))?,
                    integrator: parse_integrator(&f[1]).ok_or(format!("unknown integrator `{}`", f[1]))?,
                    path: SolverPath::from_name(&f[2]).ok_or(format!("unknown solver path `{}`", f[2]))?,
                    dt: parse_number(&f[3])?,
                    dt_over_limit: parse_number(&f[4])?,
                    edge_length: parse_number(&f[5])?,
                    triangles: f[6].parse().map_err(|_| format!("`{}` is not a count", f[6]))?,
                    cpu_seconds: parse_number(&f[7])?,
                    error: parse_optional(&f[8])?,
                    status: f[9].clone(),
                    pareto: f[10] == "true",
                })
            };
            row().map_err(|message| ChartError::Read { path: origin.to_path_buf(), message: format!("line {}: {message}", i + 2) })
        })
        .collect()
}

pub fn read_stability(path: &Path) -> Result<Vec<StabilityRow>, ChartError> {
    parse_stability(&read_text(path)?, path)
}

/// The rows of `stability.csv` text; `origin` names the text in errors.
pub fn parse_stability(text: &str, origin: &Path) -> Result<Vec<StabilityRow>, ChartError> {
    records_in(text, origin, STABILITY_HEADER)?
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let row = || -> Result<StabilityRow, String> {
                Ok(StabilityRow {
                    map: StabilityMap::from_name(&f[0]).ok_or(format!("unknown map `{}`", f[0]))?,
                    problem: Problem::from_name(&f[1]).ok_or(format!("unknown problem `{}`", f[1]))?,
                    integrator: parse_integrator(&f[2]).ok_or(format!("unknown integrator `{}`", f[2]))?,
                    dt: parse_number(&f[3])?,
                    explicit_limit: parse_number(&f[4])?,
                    tensile_scale: parse_number(&f[6])?,
                    bending_scale: parse_number(&f[7])?,
                    tensile_stiffness: parse_number(&f[8])?,
                    bending_stiffness: parse_number(&f[9])?,
                    triangles: f[10].parse().map_err(|_| format!("`{}` is not a count", f[10]))?,
                    cpu_seconds: parse_number(&f[11])?,
                    error: parse_optional(&f[12])?,
                    status: Status::from_name(&f[13]).ok_or(format!("unknown status `{}`", f[13]))?,
                })
            };
            row().map_err(|message| ChartError::Read { path: origin.to_path_buf(), message: format!("line {}: {message}", i + 2) })
        })
        .collect()
}

pub const DRAPE_REFERENCE_HEADER: &str = "edge_length,dt,triangles,cpu_seconds,drape_coefficient,model_revision";

/// The cached drape reference, if the file holds one made with `case`'s mesh and step.
pub fn read_drape_reference(path: &Path, case: &Case) -> Option<f64> {
    let super::Step::Seconds(dt) = case.step else { return None };
    let fields = records(path, DRAPE_REFERENCE_HEADER).ok()?.pop()?;
    let same = fields[0].parse::<f64>().ok()? == case.edge_length
        && fields[1].parse::<f64>().ok()? == dt
        && fields[5].parse::<u32>().ok()? == crate::sim::MODEL_REVISION;
    same.then(|| fields[4].parse().ok()).flatten()
}

pub fn write_drape_reference(path: &Path, outcome: &Outcome) -> Result<(), ChartError> {
    let text = format!(
        "{DRAPE_REFERENCE_HEADER}\n{},{},{},{},{},{}\n",
        outcome.case.edge_length,
        outcome.dt,
        outcome.triangles,
        number(Some(outcome.cpu_seconds)),
        number(outcome.measure),
        crate::sim::MODEL_REVISION
    );
    write(path, &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(cpu: f64, error: Option<f64>) -> AccuracyRow {
        AccuracyRow {
            problem: Problem::Cantilever,
            integrator: IntegratorKind::ImplicitEuler,
            path: SolverPath::Exact,
            dt: 0.01,
            dt_over_limit: 100.0,
            edge_length: 0.005,
            triangles: 10,
            cpu_seconds: cpu,
            error,
            status: "ok".into(),
            pareto: false,
        }
    }

    #[test]
    fn pareto_front_keeps_the_runs_nothing_beats_on_both_counts() {
        let mut rows = vec![
            row(1.0, Some(0.1)),  // cheapest: front
            row(2.0, Some(0.2)),  // beaten by the first on both
            row(3.0, Some(0.01)), // most accurate: front
            row(2.5, Some(0.05)), // between: front
            row(0.5, None),       // diverged: never on the front
            row(1.0, Some(0.1)),  // a tie with the first: only one of them
        ];
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        assert_eq!(front, [true, false, true, true, false, false]);
    }

    #[test]
    fn accuracy_csv_reads_back_what_was_written() {
        let mut rows = vec![row(1.0, Some(0.1)), row(2.0, None)];
        rows[1].status = "diverged".into();
        mark_pareto(&mut rows);
        let path = std::env::temp_dir().join(format!("rosette-accuracy-{}.csv", std::process::id()));
        write_accuracy(&path, &rows).unwrap();
        let back = read_accuracy(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].error, None);
        assert!(back[0].pareto && !back[1].pareto);
        assert!((back[0].cpu_seconds - 1.0).abs() < 1e-9);
    }
}
