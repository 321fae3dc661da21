//! What the user sets: Newton's tolerances, the preconditioner, adaptive steps.

use serde::{Deserialize, Serialize};

/// Newton's default iteration limit per step. At 30 a limp fabric's landing could stop
/// short: silk on the 36 cm Cusick drape at 7.5 mm edges needed 46 iterations on one step
/// (and 31 and 29 on two others) and the run was reported as not converged, where every
/// other bundled fabric stayed under 30. A step only takes what it needs, so the higher
/// limit costs nothing where Newton converges.
pub const DEFAULT_MAX_ITERATIONS: usize = 60;

/// Newton and conjugate-gradient settings of the implicit integrators.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSettings {
    /// Maximum Newton iterations per step.
    pub max_iterations: usize,
    /// Newton stops when no vertex moves more than this fraction of the mean edge length.
    pub tolerance: f64,
    /// Newton also stops at a step under this share of the step's own integration error,
    /// implicit Euler's local error ½h·max|v_{n+1} − v_n|, estimated at each iterate and at
    /// most the last step's (an iterate far from the solution cannot loosen it): a solve
    /// an order of magnitude more exact than the step it serves adds nothing a user could
    /// see in a moving cloth, and its last iterations are most of a dynamic step's cost. At
    /// rest that error vanishes and `tolerance` alone decides, so equilibria are found as
    /// exactly as with it off. 0: off (the exact path).
    pub error_share: f64,
    /// Relative residual at which the conjugate gradient stops.
    pub cg_tolerance: f64,
    /// Maximum conjugate-gradient iterations per Newton iteration.
    pub cg_max_iterations: usize,
    /// Inexact Newton (Eisenstat and Walker's second forcing term): early iterations, far
    /// from the solution, solve their linear systems only to η_k = 0.9(|g_k|/|g_{k−1}|)²
    /// (at most 0.1, at least `cg_tolerance`) instead of `cg_tolerance`.
    pub forcing: bool,
    /// Newton starts from x_n + Δt(2v_n − v_{n−1}), where the last step's acceleration would
    /// carry the cloth, when Φ is lower there than at the inertial guess (the solution is
    /// the same to the Newton tolerance; only the start moves closer to it when the motion
    /// is smooth). Off by default: it saves Newton iterations where the motion is smooth
    /// (the drape, Euler buckling, the cantilever) but costs more where it flutters (shear
    /// buckling's wrinkles), and on the drape its tolerance-sized differences, amplified by
    /// the choice of folds, widen the scatter of the drape coefficient between random
    /// seeds (docs/performance-log.md has the figures and the commands that give them).
    pub warm_start: bool,
    /// The conjugate gradient's preconditioner.
    pub preconditioner: PreconditionerChoice,
    /// How a global preconditioner's solve treats an indefinite Newton matrix (compressed
    /// edges' softening outweighing inertia and bending).
    pub indefinite: Indefinite,
    /// With the incomplete factor, whether every iteration first solves on the exact
    /// matrix, after CG has met negative curvature there earlier in the same step. Off,
    /// the step's remaining iterations solve on the bounded matrix straight away, as a
    /// global preconditioner's do once its shifted solve has failed: a cloth landing on a
    /// prop buckles in most of its iterations, and each failed first attempt costs a
    /// partial CG solve and an assembly (on the sphere drop 2 028 of 6 682 CG iterations).
    /// Off, Newton also judges the bounded matrix's linearly converging iterations by their
    /// estimated distance to the solution, θ/(1 − θ) times the last direction where
    /// directions shrink by θ, instead of the last direction's length alone. On by default
    /// (the exact path); the fast path turns it off for drops. (Off and with `indefinite =
    /// "bound"`, the incomplete factor's solves take the bounded matrix from a step's first
    /// iteration, as the global ones do.)
    pub retry_exact: bool,
    /// How Φ is minimised: Newton's method, or the quasi-Newton step (`quasi_newton.rs`).
    pub minimizer: Minimizer,
    /// The quasi-Newton step's memory: how many of the last iterations' (step, gradient
    /// change) pairs correct its matrix.
    pub quasi_newton_history: usize,
    /// The quasi-Newton step's iterations before Newton finishes the solve from where it
    /// got to (Newton then has `max_iterations` of its own).
    pub quasi_newton_iterations: usize,
    /// How many of the last Newton directions deflate the incomplete factor's CG solves
    /// where that factor is split into parts (`PART_VERTICES` vertices and more;
    /// `linalg::pcg_deflated`): each solve starts from the best combination of them and
    /// keeps its search directions A-orthogonal to them, so that the slow motion a cloth
    /// repeats from step to step, which the split factor resolves worst, is solved for
    /// once. Each costs a matrix product per solve (all read in one pass) and two short
    /// passes per CG iteration. 0: off (the exact path); the fast path's garments take
    /// `solver.fast.recycled_directions`.
    pub recycled_directions: usize,
}

/// How an implicit step minimises its incremental potential.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Minimizer {
    /// Newton's method with the exact Hessian (shifted or bounded where indefinite),
    /// preconditioned conjugate gradients and a line search.
    #[default]
    Newton,
    /// L-BFGS on the projective-dynamics matrix of the model, factored once per step with
    /// no assembly and no conjugate gradient per iteration; Newton finishes a solve it has
    /// not converged in `quasi_newton_iterations`.
    QuasiNewton,
}

impl Minimizer {
    pub fn name(self) -> &'static str {
        match self {
            Self::Newton => "newton",
            Self::QuasiNewton => "quasi-newton",
        }
    }
}

/// How Newton's solves with a global preconditioner (the complete factor, multigrid) treat
/// compressed edges' negative stiffness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Indefinite {
    /// The exact matrix, shifted by as small a share of the inertia as keeps it positive
    /// definite: quadratic convergence where the cloth buckles, at the price of a new
    /// factor whenever the shift must rise.
    #[default]
    Shift,
    /// The softening bounded so that the matrix is positive definite by construction
    /// (`CompressedEdges::Within`): no factor is rebuilt for a shift, Newton converges
    /// linearly along buckling modes.
    Bound,
}

/// Which factor preconditions the Newton systems' conjugate gradient.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum PreconditionerChoice {
    /// The complete factor from `AUTO_CHOLESKY_VERTICES` vertices up, the incomplete one below.
    #[default]
    Auto,
    /// Block incomplete LDLᵀ, on the matrix's whole pattern or on its one-ring, whichever
    /// has measured cheaper so far in the run: cheap to build, and enough on coarse meshes,
    /// where the bending modes it misses are few.
    IncompleteCholesky,
    /// Sparse Cholesky (faer, with a fill-reducing ordering): more memory and a costlier
    /// build, but CG iterations that stay at a few per Newton iteration at any mesh size.
    Cholesky,
    /// Smoothed-aggregation multigrid with the rigid modes as coarse spaces (`multigrid`):
    /// a cycle whose cost grows linearly with the mesh, but CG iterations that grow too;
    /// slower than the complete factor at every drape size measured, so `Auto` never takes
    /// it.
    Multigrid,
}

/// The global preconditioners, solved for with the exact matrix shifted where it is
/// indefinite (`Integrator::solve_shifted`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum GlobalPreconditioner {
    Cholesky,
    Multigrid,
}

impl PreconditionerChoice {
    /// From this many vertices `Auto` takes the complete factor. The threshold sits near
    /// where the drape's measured costs cross, above the size of the contact-heavy
    /// tablecloth, where the incomplete factor is far cheaper; beyond it the complete factor
    /// wins by a margin that grows with the mesh (docs/performance-log.md).
    pub const AUTO_CHOLESKY_VERTICES: usize = 3000;

    /// The global preconditioner for a mesh of `vertices`, or None for the incomplete factor.
    pub(super) fn global(self, vertices: usize) -> Option<GlobalPreconditioner> {
        match self {
            Self::Auto => (vertices >= Self::AUTO_CHOLESKY_VERTICES).then_some(GlobalPreconditioner::Cholesky),
            Self::IncompleteCholesky => None,
            Self::Cholesky => Some(GlobalPreconditioner::Cholesky),
            Self::Multigrid => Some(GlobalPreconditioner::Multigrid),
        }
    }
}

impl Default for NewtonSettings {
    fn default() -> Self {
        Self { max_iterations: DEFAULT_MAX_ITERATIONS, tolerance: 1e-5, error_share: 0.0, cg_tolerance: 1e-3, cg_max_iterations: 3000, forcing: true, warm_start: false, preconditioner: PreconditionerChoice::Auto, indefinite: Indefinite::Shift, retry_exact: true, minimizer: Minimizer::Newton, quasi_newton_history: 8, quasi_newton_iterations: 400, recycled_directions: 0 }
    }
}

/// Adaptive time steps for the implicit integrators: each step's local position error is
/// estimated and the next Δt chosen to keep it near `tolerance`; a step whose error is more
/// than twice that, or whose Newton solve did not converge, is taken again with a smaller Δt.
///
/// Implicit Euler's position after one step is x_n + h v_n + h² a_{n+1} where the exact
/// motion gives x_n + h v_n + ½h² a: the local error is ½h²|a| = ½h|v_{n+1} − v_n|, largest
/// where the cloth accelerates (a fall, a buckling snap) and vanishing when it moves
/// steadily or rests. Δt then grows as h ∝ √(tolerance/|a|). For BDF2 the same estimate is
/// conservative (its error is third order); its two-step history is restarted whenever Δt
/// changes, as its fixed-step formula requires.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AdaptiveStep {
    /// Off: Δt stays at `solver.dt` (so that a preset's adaptive section can be switched off
    /// from the command line).
    pub enabled: bool,
    /// Largest local position error per step, m.
    pub tolerance: f64,
    /// Smallest and largest Δt, s.
    pub dt_min: f64,
    pub dt_max: f64,
}

impl Default for AdaptiveStep {
    fn default() -> Self {
        Self { enabled: true, tolerance: 1e-4, dt_min: 1e-5, dt_max: 0.02 }
    }
}

impl AdaptiveStep {
    /// The factor by which Δt should change after a step whose error estimate was `error`.
    pub(super) fn factor(&self, error: f64) -> f64 {
        if error <= 0.0 {
            return 1.5;
        }
        (0.9 * (self.tolerance / error).sqrt()).clamp(0.25, 1.5)
    }
}

