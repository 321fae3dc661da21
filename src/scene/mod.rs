//! Scenes: a preset turned into a model, an initial state, a test rig and its measurements.
//! One registry (`settings::SCENES`) feeds the command line, the tests and the viewer.

pub mod drape;
pub mod garment;
pub mod levels;
pub mod load;
pub mod measures;
pub mod check;
/// The memory estimate lives with the checks that use it before any mesh is built.
pub use check::memory;
pub mod possible;
pub mod props;
pub mod kinds;
pub mod run;
pub mod strip;
pub mod plan;
pub mod topology;

pub use measures::Measures;
pub use topology::Topology;
pub use crate::settings::{SceneConfig, SceneKind};
pub use kinds::Kind;
pub use check::CheckedScene;
pub use load::{RunFlags, load_scene, load_scene_with};
pub use run::{ContactEvents, Metrics, RunOptions, SettleWatch, StepRecord, run_scene};

use crate::sim::contact::ContactModel;
use crate::sim::{Integrator, Mesh, Model, ModelError, PhysicsOptions, State, StepError, StepReport};
use crate::physics::STANDARD_GRAVITY;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use kinds::{Rig, Specimen};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum SceneError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("{0}")]
    Setup(String),
    /// Settings the checks refused (`Scene::new`): the message names the key.
    #[error("{}", .0.message)]
    Invalid(check::Invalid),
}

impl From<check::Invalid> for SceneError {
    fn from(e: check::Invalid) -> Self {
        Self::Invalid(e)
    }
}

/// What the checks built, shared by every level of a scene.
struct Built<'a> {
    fabric: &'a crate::sim::Fabric,
    props: &'a [crate::sim::contact::Prop],
}

/// A scene ready to step: model, state, integrator and its rig's measurements.
pub struct Scene {
    pub config: SceneConfig,
    pub model: Model,
    pub state: State,
    pub integrator: Integrator,
    pub rig: Box<dyn Rig>,
    /// Rigid props the cloth collides with.
    pub props: Vec<crate::sim::contact::Prop>,
    /// Steps between measurement samples.
    sample_every: u64,
    /// The fast path's finer levels still to come (None on the exact path).
    levels: Option<levels::Levels>,
    /// The edge length of the fast path's level the scene is on (None: the scene's own
    /// mesh and settings).
    level_edge: Option<f64>,
    /// The solver settings the plan gave the level the scene is on: what a rebuilt
    /// integrator (a welded garment) is made from.
    level_solver: crate::settings::SolverSection,
    /// A garment's sewing (None for other scenes).
    pub garment: Option<garment::Sewing>,
    /// Wall-clock time past which no step starts another Newton iteration
    /// (`Integrator::deadline`, set from `--max-wall`); None: no bound.
    pub deadline: Option<std::time::Instant>,
    /// The mesh the model has now; replaced with the model (`Scene::topology`).
    topology: std::sync::Arc<Topology>,
    /// What the run plan chose over the scene's settings on the scene's own mesh, and the
    /// user's values it kept (`plan::Choice`).
    plan_choices: Vec<plan::Choice>,
}


/// From this many triangles a step runs on rayon's pool (`Scene::step`): the size from
/// which the model's, the contact's and the matrices' loops run in parallel (4 096
/// triangles or rows).
const POOL_STEP_TRIANGLES: usize = 4096;

impl Scene {
    /// Builds a scene the checks passed, with what they built (its fabric, props, a
    /// garment's pattern) and on the plan they resolved.
    pub fn build(checked: CheckedScene) -> Result<Self, SceneError> {
        let check::Checked { config, fabric, props, mut garment, plan } = checked.into_parts();
        let choices = plan.levels.last().map(|l| l.choices.clone()).unwrap_or_default();
        let mut levels = plan.levels.into_iter();
        let first = levels.next().expect("a plan has at least one level");
        let built = Built { fabric: &fabric, props: &props };
        let mut scene = Self::build_level(config.clone(), first, &built, garment.take())?;
        if plan.design == plan::Design::Settling {
            // Every finer level is built now, so that a bad mesh is refused before any work.
            let pending = levels.map(|level| Self::build_level(config.clone(), level, &built, None)).collect::<Result<_, _>>()?;
            scene.levels = Some(levels::Levels::new(&scene, pending));
        }
        scene.plan_choices = choices;
        Ok(scene)
    }

    /// Checks `config` and builds it: what a changed setting goes through.
    pub fn new(config: SceneConfig) -> Result<Self, SceneError> {
        Self::build(check::checked(config)?)
    }

    /// One level of the scene's plan: `config` is the scene's own settings, kept for a
    /// later re-plan; the level's are what it is built and stepped with. `garment` is the
    /// pattern the checks meshed at the scene's own edge length.
    fn build_level(config: SceneConfig, level: plan::Level, built: &Built, garment: Option<crate::garment::Garment>) -> Result<Self, SceneError> {
        let edge_length = level.fast.then_some(level.edge_length);
        let level_config = level.config;
        let (fabric, props) = (built.fabric, built.props.to_vec());
        let options = PhysicsOptions {
            membrane: level_config.physics.membrane,
            bending: level_config.physics.bending,
            gravity: if level_config.physics.gravity { DVec3::new(0.0, 0.0, -STANDARD_GRAVITY) } else { DVec3::ZERO },
            damping: level_config.solver.damping,
        };
        let kind = kinds::of(level_config.scene.kind);
        if kind.specimen() == Specimen::Garment {
            let own_mesh = level_config.mesh.edge_length == config.mesh.edge_length;
            let parts = garment::build(&level_config, fabric, options, props, garment.filter(|_| own_mesh))?;
            let integrator = level_config.solver.integrator();
            let steps = (config.scene.duration / level_config.solver.dt).ceil().max(1.0) as u64;
            let rig: Box<dyn Rig> = Box::new(parts.rig);
            let (state, model, props) = (State::at_rest(parts.x), parts.model, parts.props);
            let sample_every = (steps / 400).max(1);
            let topology = std::sync::Arc::new(Topology::of(&model));
            return Ok(Self { state, config, model, integrator, rig, props, sample_every, levels: None, level_edge: edge_length, level_solver: level_config.solver, garment: Some(parts.sewing), deadline: None, topology, plan_choices: Vec::new() });
        }
        let c = &level_config.cloth;
        let warp = c.warp_angle_deg.to_radians();
        let drape = kind.specimen() == Specimen::Sheet;
        let (mesh, clamp_band) = match kind.specimen() {
            Specimen::Strip { clamped, grip } => strip_mesh(&level_config, clamped, grip)?,
            _ => (drape_mesh(&level_config)?, 0.0),
        };
        if let Some(available) = memory::available_bytes() {
            memory::check(mesh.rest.len(), level_config.mesh.edge_length, level_config.solver.newton.preconditioner, available).map_err(SceneError::Setup)?;
        }
        let mut model = Model::new(&mesh, fabric, warp, options)?;
        let origin = DVec3::from_array(c.position);
        let mut x = kind.start(&level_config, &mesh.rest);
        let rig = kind.attach(&level_config, &mut model, &x, clamp_band)?;
        if let Some(amplitude) = level_config.test.perturbation {
            let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(level_config.scene.seed);
            if drape {
                perturb_smoothly(&mut x, &model, origin, amplitude, &mut rng);
            } else {
                // The paper's start: a random displacement along the normal, between 0 and
                // the amplitude.
                for (i, p) in x.iter_mut().enumerate() {
                    if !model.fixed[i] {
                        p.z += rng.random_range(0.0..=amplitude);
                    }
                }
            }
        }
        if !props.is_empty() || level_config.contact.self_collision {
            let settings = level_config.contact;
            model.contact = Some(ContactModel::new(props.clone(), settings).map_err(SceneError::Setup)?);
        }
        let integrator = level_config.solver.integrator();
        let steps = (config.scene.duration / level_config.solver.dt).ceil().max(1.0) as u64;
        let sample_every = (steps / 400).max(1);
        let topology = std::sync::Arc::new(Topology::of(&model));
        Ok(Self { state: State::at_rest(x), config, model, integrator, rig, props, sample_every, levels: None, level_edge: edge_length, level_solver: level_config.solver, garment: None, deadline: None, topology, plan_choices: Vec::new() })
    }

    /// Changes the time step (s) and integrator, keeping positions, velocities, time and
    /// what contact has counted; every other solver setting (Newton, adaptive steps, the
    /// fast path's level) stays as the scene's configuration has it. BDF2's history starts
    /// afresh, as it must at a new step.
    pub fn set_solver(&mut self, dt: f64, kind: crate::sim::IntegratorKind) -> Result<(), SceneError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(SceneError::Setup(format!("solver.dt must be a positive number of seconds, got {dt}")));
        }
        self.config.solver.dt = dt;
        self.config.solver.integrator = kind;
        // A step set in the window is the user's: the plan keeps it.
        self.config.origins.record("solver.dt", crate::settings::Origin::User);
        self.config.origins.record("solver.integrator", crate::settings::Origin::User);
        self.level_solver = plan::level(&self.config, self.level_edge).solver;
        let mut integrator = self.level_solver.integrator();
        integrator.contact_stats = self.integrator.contact_stats;
        self.integrator = integrator;
        self.state.clear_history();
        Ok(())
    }

    /// What the run plan chose over the scene's settings on the scene's own mesh, and the
    /// user's values it kept.
    pub fn plan_choices(&self) -> &[plan::Choice] {
        &self.plan_choices
    }

    /// The cloth's mesh now, with a version that changes whenever the mesh does (a weld, a
    /// finer level): what snapshots and exports carry beside the positions.
    pub fn topology(&self) -> &std::sync::Arc<Topology> {
        &self.topology
    }

    /// Whether the scene is on its own mesh: always on the exact path, and on the fast path
    /// once its coarser levels have settled.
    pub fn at_final_level(&self) -> bool {
        self.levels.as_ref().is_none_or(|l| l.is_final())
    }

    /// Advances one step and samples the rig's measurements on schedule.
    ///
    /// A mesh large enough for parallel loops steps on a thread of rayon's pool: called
    /// from any other thread, each of the step's parallel loops (two per CG iteration)
    /// would be handed to the pool and the caller put to sleep until it ends, a futex wake
    /// and wait every time (the sphere drop's first 0.4 s on one thread: 6.6 s instead of
    /// 8.1 s); from a pool thread a loop starts in place and the other threads steal from
    /// it. A smaller mesh has no parallel loops and steps where it is called: handing its
    /// whole step to the pool cost the 400-triangle tensile test 40 % of its wall time.
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        if self.model.triangles.len() >= POOL_STEP_TRIANGLES {
            rayon::scope(|_| self.step_here())
        } else {
            self.step_here()
        }
    }

    fn step_here(&mut self) -> Result<StepReport, StepError> {
        if let (Some(ramp), true) = (self.config.scene.gravity_ramp, self.config.physics.gravity) {
            // Gravity at the end of the step, which is where implicit steps evaluate forces.
            let t = self.state.time + self.integrator.dt;
            self.model.options.gravity = DVec3::new(0.0, 0.0, -STANDARD_GRAVITY * (t / ramp).min(1.0));
        }
        self.sew_before_step();
        // The integrator may have been replaced (a finer level, a welded garment).
        self.integrator.deadline = self.deadline;
        let report = self.integrator.step(&self.model, &mut self.state)?;
        self.sew_after_step();
        if self.state.steps.is_multiple_of(self.sample_every) {
            self.rig.sample(&self.model, &self.state);
        }
        self.refine_if_settled();
        Ok(report)
    }

    /// The rig's measurements now.
    pub fn measures(&self) -> Measures {
        self.rig.finish(&self.model, &self.state)
    }
}

/// A rectangular strip for the laboratory tests. Strips clamped at one end carry a clamp
/// band behind x = 0, a whole number of cells long, and the mesh is made at the exact
/// column spacing so that a column of vertices lies on the clamp line; a strip with a
/// `grip` has as long a band beyond its far end. Returns the mesh and the clamp band's
/// length.
fn strip_mesh(config: &SceneConfig, clamped: bool, grip: bool) -> Result<(Mesh, f64), SceneError> {
    let (c, h) = (&config.cloth, config.mesh.edge_length);
    let (clamp_band, spacing) = if clamped {
        let cells = (c.length / h).round().max(1.0);
        let spacing = c.length / cells;
        let clamp_cells = (config.test.clamp_length.unwrap_or(2.0 * h) / spacing).round().max(2.0);
        (clamp_cells * spacing, spacing)
    } else {
        (0.0, h)
    };
    // The arc also has a grip band beyond the free length.
    let grip_band = if grip { clamp_band } else { 0.0 };
    let mut mesh = Mesh::rectangle(c.length + clamp_band + grip_band, c.width, spacing, config.mesh.pattern, config.scene.seed)
        .map_err(ModelError::from)?;
    for p in &mut mesh.rest {
        p.x -= clamp_band;
    }
    Ok((mesh, clamp_band))
}

/// A drape specimen centred on the origin: a disc (`cloth.diameter`) or a rectangle.
fn drape_mesh(config: &SceneConfig) -> Result<Mesh, SceneError> {
    let (c, h) = (&config.cloth, config.mesh.edge_length);
    if c.diameter > 0.0 {
        return Ok(Mesh::disc(c.diameter, h).map_err(ModelError::from)?);
    }
    let mut mesh = Mesh::rectangle(c.length, c.width, h, config.mesh.pattern, config.scene.seed).map_err(ModelError::from)?;
    for p in &mut mesh.rest {
        *p -= glam::DVec2::new(c.length, c.width) / 2.0;
    }
    Ok(mesh)
}

/// Drape scenes start from a flat cloth lifted by a smooth random ripple: a sum of angular
/// modes k = 2..12 with random phases, growing with the square of the
/// distance from the centre. Unlike noise per vertex it is the same surface whatever the
/// mesh, so runs at different resolutions start alike, and it breaks the symmetry that
/// would otherwise leave a perfect disc undecided where to fold.
fn perturb_smoothly(x: &mut [DVec3], model: &Model, origin: DVec3, amplitude: f64, rng: &mut impl Rng) {
    // Equal amplitudes and random phases: no fold count is favoured, the fabric picks it.
    let modes: Vec<(f64, f64, f64)> = (2..=12).map(|k| (k as f64, 1.0, rng.random_range(0.0..std::f64::consts::TAU))).collect();
    let norm: f64 = modes.iter().map(|m| m.1).sum();
    let reach = model.rest.iter().map(|p| p.length()).fold(0.0, f64::max).max(1e-9);
    for (i, p) in x.iter_mut().enumerate() {
        if model.fixed[i] {
            continue;
        }
        let r = (*p - origin).truncate();
        let angle = r.y.atan2(r.x);
        let ripple: f64 = modes.iter().map(|(k, a, phase)| a * (k * angle + phase).cos()).sum::<f64>() / norm;
        p.z += amplitude * (r.length() / reach).powi(2) * ripple;
    }
}
