//! How much memory a run will need, estimated from its mesh before the model is built, so
//! that a mesh too fine for the machine is refused with the largest edge length that fits
//! instead of aborting mid-build with "memory allocation failed".
//!
//! The figures are peak resident memory of `rosette run cusick-drape --set
//! mesh.edge_length=E --set solver.newton.preconditioner=P --duration 0.008` (two steps,
//! the factorisation included), measured with /usr/bin/time on the release build; see
//! docs/robustness.md for the table. The complete factor's fill grows as N log N under its
//! nested-dissection ordering, the other preconditioners' storage as N; each coefficient is
//! rounded up from the fit so that the estimate stays above every measurement.

use crate::sim::PreconditionerChoice;

/// The process before any mesh: code, the bundled presets, the thread pool, bytes.
const BASE_BYTES: f64 = 16e6;

/// The complete factor: bytes per vertex per log₂ of the vertex count. Measured 1.17
/// (475 to 52 511 vertices: 14.7 MB, 29 MB, 106 MB, 439 MB, 976 MB).
const CHOLESKY_BYTES_PER_VERTEX_LOG: f64 = 1250.0;

/// The incomplete factor: bytes per vertex. Measured 12.1 MB at 475 vertices growing by
/// 9.9 kB per vertex to 6504 and 25 731 vertices, 9.7 kB to 52 511 (505 MB).
const INCOMPLETE_BYTES_PER_VERTEX: f64 = 11_000.0;

/// Multigrid: bytes per vertex. Measured 13.8 MB at 475 vertices growing by 22.7 kB per
/// vertex to 6504, 22.2 kB to 25 731 and 21.4 kB to 52 511 (1.10 GB).
const MULTIGRID_BYTES_PER_VERTEX: f64 = 25_000.0;

/// Estimated peak memory, bytes, of a run on `vertices` vertices whose Newton solves use
/// `choice` (the explicit integrator, which builds no preconditioner, stays below the
/// incomplete factor's figure).
pub fn estimate_bytes(vertices: usize, choice: PreconditionerChoice) -> f64 {
    let n = vertices.max(2) as f64;
    let per_vertex = match choice {
        PreconditionerChoice::Auto if vertices >= PreconditionerChoice::AUTO_CHOLESKY_VERTICES => CHOLESKY_BYTES_PER_VERTEX_LOG * n.log2(),
        PreconditionerChoice::Cholesky => CHOLESKY_BYTES_PER_VERTEX_LOG * n.log2(),
        PreconditionerChoice::Multigrid => MULTIGRID_BYTES_PER_VERTEX,
        PreconditionerChoice::Auto | PreconditionerChoice::IncompleteCholesky => INCOMPLETE_BYTES_PER_VERTEX,
    };
    BASE_BYTES + per_vertex * n
}

/// Memory the system can give this process now, bytes: the least of MemAvailable in
/// /proc/meminfo, the address space left under the process's limit (`ulimit -v`) and the
/// room left in its control group (`memory.max`); `None` where none is known (then
/// nothing is refused).
pub fn available_bytes() -> Option<f64> {
    [system_available(), address_space_left(), cgroup_left()].into_iter().flatten().reduce(f64::min)
}

/// A number of kB on the line of /proc's `file` that starts with `key`.
fn proc_kb(file: &str, key: &str) -> Option<f64> {
    let info = std::fs::read_to_string(file).ok()?;
    let line = info.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn system_available() -> Option<f64> {
    proc_kb("/proc/meminfo", "MemAvailable:").map(|kb| kb * 1024.0)
}

/// The soft address-space limit less what the process has mapped already.
fn address_space_left() -> Option<f64> {
    #[cfg(unix)]
    {
        let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
        // SAFETY: getrlimit writes the limit into the struct it is given.
        if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0 || limit.rlim_cur == libc::RLIM_INFINITY {
            return None;
        }
        let mapped = proc_kb("/proc/self/status", "VmSize:").map_or(0.0, |kb| kb * 1024.0);
        Some((limit.rlim_cur as f64 - mapped).max(0.0))
    }
    #[cfg(not(unix))]
    None
}

/// The control group's memory.max less its memory.current (cgroup v2, the group the
/// process sees at /sys/fs/cgroup).
fn cgroup_left() -> Option<f64> {
    let read = |name: &str| std::fs::read_to_string(format!("/sys/fs/cgroup/{name}")).ok()?.trim().parse::<f64>().ok();
    Some((read("memory.max")? - read("memory.current").unwrap_or(0.0)).max(0.0))
}

/// Refuses a mesh of `vertices` vertices at edge length `edge` (m) whose run would need
/// more than `available` bytes, with the estimate and the finest edge length that fits
/// (vertex counts go as the inverse square of the edge length).
pub fn check(vertices: usize, edge: f64, choice: PreconditionerChoice, available: f64) -> Result<(), String> {
    let need = estimate_bytes(vertices, choice);
    if need <= available {
        return Ok(());
    }
    // The most vertices that fit, by bisection (the estimate grows with the count).
    let (mut lo, mut hi) = (0usize, vertices);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if estimate_bytes(mid, choice) <= available { lo = mid } else { hi = mid }
    }
    let fits = edge * (vertices as f64 / lo.max(1) as f64).sqrt();
    Err(format!(
        "mesh.edge_length = {edge:?} m gives {vertices} vertices, whose run needs about {:.1} GB (the measured estimate of \
         docs/robustness.md), more than the {:.1} GB available to this run (free memory, ulimit -v or the control group's limit); use mesh.edge_length = {:.3e} m or more",
        need / 1e9,
        available / 1e9,
        fits * 1.001
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_covers_every_measured_run() {
        // (vertices, peak kB) measured on the complete factor; see the module's doc.
        for (vertices, kb) in [(475, 14_676.0), (1696, 29_372.0), (6504, 105_784.0), (25_731, 438_612.0), (52_511, 975_700.0)] {
            let estimate = estimate_bytes(vertices, PreconditionerChoice::Cholesky);
            assert!(estimate >= kb * 1024.0, "{vertices} vertices: estimate {estimate:e} below the measured {kb} kB");
            assert!(estimate < 1.5 * kb * 1024.0 + BASE_BYTES, "{vertices} vertices: estimate {estimate:e} far above the measured {kb} kB");
        }
    }

    #[test]
    fn a_mesh_too_large_for_memory_is_refused_with_an_edge_that_fits() {
        let available = 8e9;
        let edge = 2.6e-4;
        let err = check(1_780_000, edge, PreconditionerChoice::Auto, available).unwrap_err();
        assert!(err.contains("mesh.edge_length") && err.contains("GB"), "{err}");
        let fits: f64 = err.rsplit("mesh.edge_length = ").next().unwrap().split(' ').next().unwrap().parse().unwrap();
        assert!(fits > edge);
        // The suggested edge's vertex count (∝ 1/h²) fits.
        let vertices = (1_780_000.0 * (edge / fits).powi(2)) as usize;
        assert!(estimate_bytes(vertices, PreconditionerChoice::Auto) <= available);
        assert!(check(vertices, fits, PreconditionerChoice::Auto, available).is_ok());
    }
}
