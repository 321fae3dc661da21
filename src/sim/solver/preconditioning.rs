//! The preconditioner policy of Newton's solves: when to rebuild a factor, and how an
//! indefinite matrix is handled (shifted for the global factors, bounded for the
//! incomplete one).

use super::newton::NewtonProblem;
use super::report::{StepReport, Stopwatch};
use crate::sim::linalg::BlockCsr;
use crate::sim::model::CompressedEdges;
use super::settings::GlobalPreconditioner;
use super::Integrator;
use crate::sim::linalg::{CgReport, DirectFactor, DirectPattern, Multigrid, Preconditioner, SystemMatrix, pcg};
use glam::DVec3;
use std::sync::Arc;

impl Integrator {
    /// Whether the kept preconditioner should be rebuilt. A factor serves later iterations,
    /// and later steps: the matrix changes little from one to the next, and a factorisation
    /// costs several CG iterations. It is rebuilt once the iterations it has cost beyond
    /// what it took when new add up to what building it cost (the rent-or-buy rule: never
    /// more than twice the best choice made in hindsight).
    fn preconditioner_is_stale(&self, n: usize) -> bool {
        self.preconditioner.as_ref().is_none_or(|p| p.size != n || p.excess >= p.preconditioner.cost_in_iterations())
    }

    /// Solves Newton's system with a global preconditioner (the complete factor or the
    /// multigrid hierarchy) and the exact matrix H plus a shift s·M/h² (s = `self.shift`, a
    /// share of the inertia), s as small as keeps it positive definite (Levenberg and
    /// Marquardt's regularisation, in the mass metric). False, with nothing solved, if that
    /// takes more than `MAX_SHIFT`.
    ///
    /// A factor that fails (a pivot not positive) or a CG that meets negative curvature or
    /// returns no descent doubles s (from `MIN_SHIFT`), or sets it to the last shift a
    /// failure needed if that is more; the matrix is factored again only if the kept factor
    /// was made for a smaller shift. After each solve the next iteration tries half the
    /// shift with the same factor: a shift kept through a step slows Newton badly on a
    /// compressed sheet (`tests/conservation.rs`), where a shift is needed for only an
    /// iteration or two. The need returns in jumps, from zero to a large shift within an
    /// iteration, so climbing by doubling each time would fail many factorisations;
    /// starting from the last need fails few.
    ///
    /// Fine meshes do not take the bounded matrix of `CompressedEdges::Within` throughout,
    /// which scales the compressed edges' term at each vertex to at most 90 % of the
    /// inertia. The bound guards against the shortest waves, where a compressed edge's
    /// softening is largest, and inertia per vertex falls as the edge length squared: on a
    /// fine mesh nearly every free vertex is bounded, most to a small part of its
    /// softening, so that matrix is wrong in the long waves too and Newton converges only
    /// linearly (tiny steps, the gradient not falling). The exact matrix is positive
    /// definite in most of those iterations, and a shift makes it so in most of the rest,
    /// so the shifted exact matrix takes fewer Newton iterations (the fine drape's figures
    /// are in docs/performance-log.md).
    fn solve_shifted(&mut self, exact: &SystemMatrix, positions: &[DVec3], direction: &mut [DVec3], solve: &mut Solve) -> bool {
        let n = exact.fixed.len();
        let mut rebuild = false;
        let mut raised = false;
        loop {
            let shifted: Vec<f64> = exact.mass_diagonal.iter().map(|d| d * (1.0 + self.shift)).collect();
            let system = SystemMatrix { mass_diagonal: &shifted, ..*exact };
            // Doubles the shift, or takes the last one that had to be raised to; false once
            // it is at its largest.
            let needed = self.needed_shift;
            let mut raise = |shift: &mut f64| {
                if *shift >= MAX_SHIFT {
                    return false;
                }
                *shift = (2.0 * *shift).max(needed).clamp(MIN_SHIFT, MAX_SHIFT);
                raised = true;
                true
            };
            if rebuild || self.preconditioner_is_stale(n) {
                let factor = self.global_factor(&system, positions);
                solve.report.factorizations += 1;
                solve.watch.solve();
                match factor {
                    Some(factor) => self.preconditioner = Some(CachedPreconditioner { shift: self.shift, ..CachedPreconditioner::new(n, factor) }),
                    None if raise(&mut self.shift) => {
                        rebuild = true;
                        continue;
                    }
                    None => return false,
                }
            }
            let cached = self.preconditioner.as_mut().expect("built above");
            let cg = pcg(&system, &cached.preconditioner, solve.rhs, direction, solve.cg_tolerance, self.newton.cg_max_iterations);
            solve.report.cg_iterations += cg.iterations;
            solve.watch.solve();
            let descent = solve.rhs.iter().zip(direction.iter()).map(|(r, d)| r.dot(*d)).sum::<f64>() > 0.0;
            if cg.negative_curvature || !descent {
                if !raise(&mut self.shift) {
                    return false;
                }
                // A factor made for at least this shift is already at hand.
                rebuild = self.shift > cached.shift;
                continue;
            }
            cached.record(&cg);
            solve.report.shift = solve.report.shift.max(self.shift);
            if raised {
                self.needed_shift = self.shift;
            }
            // The next iteration tries half the shift, with the same factor.
            self.shift = if self.shift / 2.0 < MIN_SHIFT { 0.0 } else { self.shift / 2.0 };
            return true;
        }
    }

    /// Solves Newton's system with a global preconditioner: the exact matrix shifted as
    /// little as keeps it positive definite (`solve_shifted`), or, once that has failed in
    /// this step, the bounded matrix (assembled into `bounded`) and a factor of it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_global(
        &mut self,
        problem: &NewtonProblem,
        system: &SystemMatrix,
        bounded: &mut BlockCsr,
        y: &[DVec3],
        rhs: &[DVec3],
        direction: &mut [DVec3],
        cg_tolerance: f64,
        bounded_throughout: &mut bool,
        report: &mut StepReport,
        watch: &mut Stopwatch,
    ) {
        let n = y.len();
        let mut solve = Solve { rhs, cg_tolerance, report: &mut *report, watch: &mut *watch };
        if !*bounded_throughout && !self.solve_shifted(system, y, direction, &mut solve) {
            // This step's remaining iterations take the bounded matrix, positive definite,
            // and a factor of it.
            *bounded_throughout = true;
            self.preconditioner = None;
        }
        if *bounded_throughout {
            problem.assemble(y, bounded, CompressedEdges::Within(&problem.softening));
            watch.forces();
            let system = SystemMatrix { stiffness: bounded, ..*system };
            if self.preconditioner_is_stale(n) {
                let preconditioner = self.global_factor(&system, y).unwrap_or_else(|| system.preconditioner());
                report.factorizations += 1;
                self.preconditioner = Some(CachedPreconditioner::new(n, preconditioner));
                watch.solve();
            }
            let cached = self.preconditioner.as_mut().expect("built above");
            let cg = pcg(&system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations);
            report.cg_iterations += cg.iterations;
            watch.solve();
            cached.record(&cg);
        }
    }

    /// Solves Newton's system with the incomplete factor, made from the bounded matrix: on
    /// the exact matrix first, and again on the bounded one (assembled into `bounded`) if
    /// CG meets negative curvature or returns no descent.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_incomplete(
        &mut self,
        problem: &NewtonProblem,
        system: &SystemMatrix,
        bounded: &mut BlockCsr,
        y: &[DVec3],
        gradient: &[DVec3],
        rhs: &[DVec3],
        direction: &mut [DVec3],
        cg_tolerance: f64,
        report: &mut StepReport,
        watch: &mut Stopwatch,
    ) {
        let n = y.len();
        let mut bounded_ready = false;
        if self.preconditioner_is_stale(n) {
            // Factors are made from the bounded matrix. Made from the exact one, the Euler
            // strip's buckling onset under BDF2 came late, beyond the onset test's
            // tolerance, where the bounded one's is within it: near the bifurcation the
            // exact matrix is nearly singular,
            // its incomplete factor breaks down and is shifted, and Newton's steps along the
            // soft mode likely fell below the tolerance while the mode lagged.
            problem.assemble(y, bounded, CompressedEdges::Within(&problem.softening));
            bounded_ready = true;
            watch.forces();
            let preconditioner = SystemMatrix { stiffness: bounded, ..*system }.preconditioner();
            report.factorizations += 1;
            self.preconditioner = Some(CachedPreconditioner::new(n, preconditioner));
            watch.solve();
        }
        let cached = self.preconditioner.as_mut().expect("built above");
        let mut cg = pcg(system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations);
        report.cg_iterations += cg.iterations;
        watch.solve();
        let descent = gradient.iter().zip(direction.iter()).map(|(g, d)| g.dot(*d)).sum::<f64>() < 0.0;
        // (A bounded matrix is positive definite: a failure there is left to the line search
        // and its steepest-descent fallback.)
        if cg.negative_curvature || !descent {
            if !bounded_ready {
                problem.assemble(y, bounded, CompressedEdges::Within(&problem.softening));
                watch.forces();
            }
            let system = SystemMatrix { stiffness: bounded, ..*system };
            cg = pcg(&system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations);
            report.cg_iterations += cg.iterations;
            watch.solve();
        }
        cached.record(&cg);
    }

    /// The global preconditioner of `system` (the cloth at `positions`): the complete factor
    /// on the model's pattern (made once) or the multigrid hierarchy; None if it is not
    /// positive definite (or the symbolic analysis failed).
    fn global_factor(&mut self, system: &SystemMatrix, positions: &[DVec3]) -> Option<Preconditioner> {
        if self.newton.preconditioner.global(system.fixed.len()) == Some(GlobalPreconditioner::Multigrid) {
            return Multigrid::new(system, positions).map(Preconditioner::Multigrid);
        }
        if self.direct_pattern.as_ref().is_none_or(|p| !p.fits(system)) {
            self.direct_pattern = DirectPattern::new(system).map(Arc::new);
        }
        let pattern = self.direct_pattern.clone()?;
        DirectFactor::new(pattern, system).map(Preconditioner::Cholesky)
    }
}

/// The smallest and largest shifts `solve_shifted` adds, as shares of the inertia.
const MIN_SHIFT: f64 = 0.05;
const MAX_SHIFT: f64 = 6.4;

/// One Newton iteration's linear solve: its right-hand side and tolerance, and where its
/// work is counted.
struct Solve<'a> {
    rhs: &'a [DVec3],
    cg_tolerance: f64,
    report: &'a mut StepReport,
    watch: &'a mut Stopwatch,
}

/// A preconditioner with what it was built for and how quick it made CG when new.
pub(super) struct CachedPreconditioner {
    /// Vertices of the matrix it was built from.
    pub size: usize,
    pub preconditioner: Preconditioner,
    /// CG iterations per e-fold of residual reduction on its first solve.
    fresh_rate: Option<f64>,
    /// CG iterations spent beyond that rate since.
    excess: f64,
    /// The shift of the matrix it was made from (`Integrator::solve_shifted`).
    shift: f64,
}

impl CachedPreconditioner {
    fn new(size: usize, preconditioner: Preconditioner) -> Self {
        Self { size, preconditioner, fresh_rate: None, excess: 0.0, shift: 0.0 }
    }

    /// Counts a solve's iterations beyond the rate this preconditioner had when new.
    fn record(&mut self, cg: &CgReport) {
        // Iterations per e-fold of residual reduction: comparable across tolerances.
        let efolds = (-cg.relative_residual.max(1e-16).ln()).max(1.0);
        let fresh_rate = *self.fresh_rate.get_or_insert(cg.iterations as f64 / efolds);
        self.excess += (cg.iterations as f64 - fresh_rate * efolds).max(0.0);
    }
}

