//! The preconditioner policy of Newton's solves: when to rebuild a factor, and how an
//! indefinite matrix is handled (shifted for the global factors, bounded for the
//! incomplete one).

use super::newton::NewtonProblem;
use super::report::{StepReport, Stopwatch};
use crate::sim::linalg::BlockCsr;
use crate::sim::model::CompressedEdges;
use super::settings::GlobalPreconditioner;
use super::Integrator;
use crate::sim::linalg::{CgReport, DirectFactor, DirectPattern, FactorPattern, Multigrid, Preconditioner, SystemMatrix, factor_is_split, pcg, pcg_deflated};
use glam::DVec3;
use std::sync::Arc;

impl Integrator {
    /// Whether the kept preconditioner should be rebuilt. A factor serves later iterations,
    /// and later steps: the matrix changes little from one to the next, and a factorisation
    /// costs several CG iterations. It is rebuilt once the iterations it has cost beyond
    /// what it took when new add up to what building it cost (the rent-or-buy rule: never
    /// more than twice the best choice made in hindsight).
    fn preconditioner_is_stale(&self, fixed: &[bool]) -> bool {
        self.preconditioner.as_ref().is_none_or(|p| !p.fits(fixed) || p.excess >= p.preconditioner.cost_in_iterations())
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
            if rebuild || self.preconditioner_is_stale(exact.fixed) {
                let factor = self.global_factor(&system, positions);
                solve.report.factorizations += 1;
                solve.watch.solve();
                match factor {
                    Some(factor) => self.preconditioner = Some(CachedPreconditioner { shift: self.shift, ..CachedPreconditioner::new(exact.fixed, factor) }),
                    None if raise(&mut self.shift) => {
                        rebuild = true;
                        continue;
                    }
                    None => return false,
                }
            }
            let cached = self.preconditioner.as_mut().expect("built above");
            let cg = pcg(&system, &cached.preconditioner, solve.rhs, direction, solve.cg_tolerance, self.newton.cg_max_iterations);
            solve.report.count_solve(&cg);
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
            if self.preconditioner_is_stale(system.fixed) {
                let preconditioner = self.global_factor(&system, y).unwrap_or_else(|| system.preconditioner(FactorPattern::Wide));
                report.factorizations += 1;
                self.preconditioner = Some(CachedPreconditioner::new(system.fixed, preconditioner));
                watch.solve();
            }
            let cached = self.preconditioner.as_mut().expect("built above");
            let cg = pcg(&system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations);
            report.count_solve(&cg);
            watch.solve();
            cached.record(&cg);
        }
    }

    /// Solves Newton's system with the incomplete factor, made from the bounded matrix: on
    /// the exact matrix first, and again on the bounded one (assembled into `bounded`) if
    /// CG meets negative curvature or returns no descent; without the first attempt unless
    /// `exact_first` (the caller's choice, `NewtonSettings::retry_exact`), and `system` holds
    /// the exact matrix only then. A failed first attempt sets `bounded_throughout` for the
    /// rest of the step. Returns whether the direction was solved on the bounded matrix.
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
        exact_first: bool,
        bounded_throughout: &mut bool,
        report: &mut StepReport,
        watch: &mut Stopwatch,
    ) -> bool {
        let n = y.len();
        let mut bounded_ready = false;
        if self.preconditioner_is_stale(system.fixed) {
            // Factors are made from the bounded matrix. Made from the exact one, the Euler
            // strip's buckling onset under BDF2 came late, beyond the onset test's
            // tolerance, where the bounded one's is within it: near the bifurcation the
            // exact matrix is nearly singular,
            // its incomplete factor breaks down and is shifted, and Newton's steps along the
            // soft mode likely fell below the tolerance while the mode lagged.
            problem.assemble(y, bounded, CompressedEdges::Within(&problem.softening));
            bounded_ready = true;
            watch.forces();
            if let Some((pattern, work)) = self.preconditioner.as_ref().and_then(CachedPreconditioner::work_per_efold) {
                self.incomplete_pattern.record(pattern, work);
            }
            let pattern = self.incomplete_pattern.next();
            let bounded_system = SystemMatrix { stiffness: bounded, ..*system };
            let mut preconditioner = bounded_system.preconditioner_remembering(pattern, &mut self.incomplete_shift);
            report.factorizations += 1;
            if !matches!(preconditioner, Preconditioner::IncompleteCholesky(_)) {
                self.incomplete_pattern.broke_down(pattern);
                // Block Jacobi would serve a whole solve, hundreds of CG iterations on a
                // drape; the wide pattern breaks down far more rarely.
                if pattern == FactorPattern::Ring {
                    preconditioner = bounded_system.preconditioner_remembering(FactorPattern::Wide, &mut self.incomplete_shift);
                    report.factorizations += 1;
                }
            }
            self.preconditioner = Some(CachedPreconditioner::new(system.fixed, preconditioner));
            watch.solve();
        }
        let cached = self.preconditioner.as_mut().expect("built above");
        // Deflation where the factor is split: its parts drop the couplings between them,
        // and the slow modes that cross them are what the recycled directions hold. On one
        // part (meshes under `PART_VERTICES`) the 2 cm circle skirt took a fifth fewer CG
        // iterations but no less time, the products and passes costing what they saved;
        // split, the 10k circle skirt took a quarter fewer and a tenth less time
        // (docs/performance-log.md, "2026-12-05").
        let keep = if factor_is_split(n) { self.newton.recycled_directions } else { 0 };
        let recycled = &mut self.recycled;
        let deflation = (keep > 0).then_some(&*recycled);
        let exact = exact_first.then(|| {
            let cg = pcg_deflated(system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations, deflation);
            report.count_solve(&cg);
            watch.solve();
            cg
        });
        let descent = || gradient.iter().zip(direction.iter()).map(|(g, d)| g.dot(*d)).sum::<f64>() < 0.0;
        // (A bounded matrix is positive definite: a failure there is left to the line search
        // and its steepest-descent fallback.)
        let cg = match exact {
            Some(cg) if !cg.negative_curvature && descent() => cg,
            _ => {
                *bounded_throughout = true;
                if !bounded_ready {
                    problem.assemble(y, bounded, CompressedEdges::Within(&problem.softening));
                    watch.forces();
                }
                let system = SystemMatrix { stiffness: bounded, ..*system };
                let cg = pcg_deflated(&system, &cached.preconditioner, rhs, direction, cg_tolerance, self.newton.cg_max_iterations, deflation);
                report.count_solve(&cg);
                watch.solve();
                cached.record(&cg);
                recycled.remember(direction, keep);
                return true;
            }
        };
        cached.record(&cg);
        recycled.remember(direction, keep);
        false
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
    /// The fixed vertices of the matrix it was built from (its size too): a vertex fixed
    /// since (a pin, the viewer's mouse) or freed makes it another matrix. A factor whose
    /// row for a newly fixed vertex is still free moves that vertex in CG's directions,
    /// which Newton's system does not: a garment held by the mouse took 100 Newton
    /// iterations a step without converging until its factor aged out.
    fixed: Vec<bool>,
    pub preconditioner: Preconditioner,
    /// CG iterations per e-fold of residual reduction on its first solve.
    fresh_rate: Option<f64>,
    /// CG iterations spent beyond that rate since.
    excess: f64,
    /// CG iterations and e-folds of residual reduction over its life.
    iterations: f64,
    efolds: f64,
    /// The shift of the matrix it was made from (`Integrator::solve_shifted`).
    shift: f64,
}

impl CachedPreconditioner {
    fn new(fixed: &[bool], preconditioner: Preconditioner) -> Self {
        Self { fixed: fixed.to_vec(), preconditioner, fresh_rate: None, excess: 0.0, iterations: 0.0, efolds: 0.0, shift: 0.0 }
    }

    /// Whether it was built for a matrix with these vertices fixed.
    pub fn fits(&self, fixed: &[bool]) -> bool {
        self.fixed == fixed
    }

    /// Counts a solve's iterations beyond the rate this preconditioner had when new.
    fn record(&mut self, cg: &CgReport) {
        // Iterations per e-fold of residual reduction: comparable across tolerances.
        let efolds = (-cg.relative_residual.max(1e-16).ln()).max(1.0);
        let fresh_rate = *self.fresh_rate.get_or_insert(cg.iterations as f64 / efolds);
        self.excess += (cg.iterations as f64 - fresh_rate * efolds).max(0.0);
        // A solve stopped at the iteration limit measures no rate: held against the first
        // solve's, itself stopped there, no later count would show the factor ageing (at a
        // limit of 200 the 10k straight skirt's solves all ran to it, one factor kept from
        // the sewing through the fall; docs/performance-log.md). The next solve takes a
        // fresh factor.
        if cg.stopped_short() {
            self.excess = f64::INFINITY;
        }
        self.iterations += cg.iterations as f64;
        self.efolds += efolds;
    }

    /// An incomplete factor's pattern and what it cost over its life, building included,
    /// in multiply-adds per e-fold of residual reduction; None for other preconditioners or
    /// one that solved nothing.
    fn work_per_efold(&self) -> Option<(FactorPattern, f64)> {
        let Preconditioner::IncompleteCholesky(factor) = &self.preconditioner else { return None };
        let iterations = self.iterations + factor.cost_in_iterations;
        (self.efolds > 0.0).then(|| (factor.pattern, iterations * factor.iteration_cost / self.efolds))
    }
}

/// The pattern of the next incomplete factor, by the work each has measured: multiply-adds
/// per e-fold of residual reduction over a factor's life, its building included, smoothed
/// over the factors made since. Which is cheaper depends on what sets the slow modes
/// (`FactorPattern`) and can change within a run, so the one not taken is tried again after
/// a number of factors that doubles, up to `MAX_PROBE_INTERVAL`, each time it is found
/// still the dearer. Counts, not clocks, decide: a run takes the same path on every machine.
#[derive(Debug, Clone)]
pub(super) struct PatternChoice {
    /// Smoothed work per e-fold, by pattern (`Wide`, `Ring`); None until measured.
    work: [Option<f64>; 2],
    /// Factors made since each pattern was last taken.
    since: [usize; 2],
    /// Factors after which the pattern not taken is tried again.
    interval: usize,
    /// The pattern of the factor in use, and whether it was a trial of the dearer one.
    current: (usize, bool),
}

const MIN_PROBE_INTERVAL: usize = 4;
const MAX_PROBE_INTERVAL: usize = 64;

impl Default for PatternChoice {
    fn default() -> Self {
        Self { work: [None; 2], since: [0; 2], interval: MIN_PROBE_INTERVAL, current: (0, false) }
    }
}

impl PatternChoice {
    const PATTERNS: [FactorPattern; 2] = [FactorPattern::Wide, FactorPattern::Ring];

    /// The pattern for the factor about to be made: each once in turn (the wide first),
    /// then the cheaper, or the other when its retrial is due.
    pub(super) fn next(&mut self) -> FactorPattern {
        let (pick, trial) = match self.work {
            [None, _] => (0, false),
            [Some(_), None] => (1, false),
            [Some(wide), Some(ring)] => {
                let best = usize::from(ring < wide);
                if self.since[1 - best] >= self.interval { (1 - best, true) } else { (best, false) }
            }
        };
        self.since = self.since.map(|s| s + 1);
        self.since[pick] = 0;
        self.current = (pick, trial);
        Self::PATTERNS[pick]
    }

    /// A retired factor's work per e-fold of residual reduction.
    pub(super) fn record(&mut self, pattern: FactorPattern, work: f64) {
        if work.is_finite() && work > 0.0 {
            self.measured(pattern, work);
        }
    }

    /// A factorisation on `pattern` broke down even shifted: that pattern counts as the
    /// dearer until a later trial succeeds.
    pub(super) fn broke_down(&mut self, pattern: FactorPattern) {
        self.measured(pattern, f64::INFINITY);
    }

    fn measured(&mut self, pattern: FactorPattern, work: f64) {
        let i = Self::PATTERNS.iter().position(|&p| p == pattern).expect("one of the two");
        self.work[i] = Some(match self.work[i] {
            Some(old) if old.is_finite() && work.is_finite() => 0.5 * (old + work),
            _ => work,
        });
        if self.current == (i, true) {
            // A trial of the dearer pattern: wait twice as long for the next if it is still
            // the dearer, start over if it won.
            let other = self.work[1 - i].unwrap_or(f64::INFINITY);
            self.interval = if work < other { MIN_PROBE_INTERVAL } else { (2 * self.interval).min(MAX_PROBE_INTERVAL) };
            self.current.1 = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use FactorPattern::{Ring, Wide};

    /// `n` factors in a row, each measured at `work` for its pattern; the patterns taken.
    fn run(choice: &mut PatternChoice, n: usize, work: impl Fn(FactorPattern) -> f64) -> Vec<FactorPattern> {
        (0..n)
            .map(|_| {
                let pattern = choice.next();
                choice.record(pattern, work(pattern));
                pattern
            })
            .collect()
    }

    /// A solve stopped at CG's iteration limit renews the factor. Held against a first solve
    /// that itself stopped there, later solves stopping there too would never count as
    /// slower: at a limit of 200 the 10k straight skirt kept one factor from its sewing
    /// through its fall, every solve running to the limit.
    #[test]
    fn a_solve_stopped_at_the_limit_renews_the_factor() {
        use crate::sim::linalg::{CgReport, Preconditioner};
        let solve = |iterations, relative_residual, reached| CgReport { iterations, relative_residual, negative_curvature: false, reached };
        let mut cached = CachedPreconditioner::new(&[false; 2], Preconditioner::BlockJacobi(vec![glam::DMat3::IDENTITY; 2]));
        cached.record(&solve(40, 1e-3, true));
        cached.record(&solve(38, 1e-3, true));
        assert_eq!(cached.excess, 0.0, "solves at the factor's first rate add no excess");
        cached.record(&solve(60, 1e-3, true));
        assert!(cached.excess > 19.0 && cached.excess.is_finite(), "a slower solve adds its extra iterations: {}", cached.excess);
        let mut stopped = CachedPreconditioner::new(&[false; 2], Preconditioner::BlockJacobi(vec![glam::DMat3::IDENTITY; 2]));
        stopped.record(&solve(200, 0.6, false));
        assert!(stopped.excess.is_infinite(), "a first solve stopped at the limit: {}", stopped.excess);
        cached.record(&solve(200, 0.6, false));
        assert!(cached.excess.is_infinite());
    }

    #[test]
    fn the_cheaper_pattern_is_taken_and_the_other_retried_ever_less_often() {
        let mut choice = PatternChoice::default();
        let taken = run(&mut choice, 40, |p| if p == Ring { 1.0 } else { 3.0 });
        assert_eq!(&taken[..2], &[Wide, Ring], "each is measured once, the wide first");
        let trials: Vec<usize> = (2..taken.len()).filter(|&i| taken[i] == Wide).collect();
        // Retried once 4 factors have been made since it was last taken (the wide at 0, the
        // ring at 1-4), then 8, then 16: each trial found the wide still the dearer.
        assert_eq!(trials, vec![5, 14, 31]);
        // A change in which is cheaper is picked up at the next trial.
        let taken = run(&mut choice, 80, |p| if p == Ring { 5.0 } else { 1.0 });
        assert_eq!(taken.last(), Some(&Wide));
        assert!(taken[taken.len() - 10..].iter().all(|&p| p == Wide));
    }

    #[test]
    fn a_pattern_that_broke_down_is_left_until_its_trial() {
        let mut choice = PatternChoice::default();
        assert_eq!(choice.next(), Wide);
        choice.record(Wide, 2.0);
        assert_eq!(choice.next(), Ring);
        choice.broke_down(Ring);
        let next: Vec<FactorPattern> = run(&mut choice, 4, |_| 2.0);
        assert_eq!(next, vec![Wide; 4]);
        // Its trial succeeds and is cheaper: it is taken from then on.
        assert_eq!(choice.next(), Ring);
        choice.record(Ring, 1.0);
        assert_eq!(run(&mut choice, 3, |p| if p == Ring { 1.0 } else { 2.0 }), vec![Ring; 3]);
    }
}
