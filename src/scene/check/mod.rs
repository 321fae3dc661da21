//! The checks a scene passes before anything is built: every number finite and in range,
//! the values consistent with each other and with the scene's kind, and the run short
//! enough for its step bound. Each refusal names the key and says how to fix it.
//!
//! Ranges are what the simulator can honour, not what is typical: a value is refused where
//! it would overflow the arithmetic, break the mesh or make a measure meaningless (a
//! support larger than the specimen), never merely because it is unusual.

mod garment;
pub mod memory;
mod motion;

pub use garment::MAX_SEWING_STIFFNESS;
pub use motion::check_motion_fits;

use super::kinds::{self, Specimen};
use super::plan::RunPlan;
use crate::sim::Fabric;
use crate::sim::contact::Prop;
use crate::settings::{PropConfig, PropKind, SceneConfig, SceneKind, SolverPath};
use crate::io::number::short;
pub use crate::settings::rule::{Invalid, invalid, non_negative, positive, positive_at_most};
use crate::sim::contact::MAX_REACH;
use crate::sim::mesh::{MAX_VERTICES, planned_vertices};

/// A point within the reach of the props' single-precision geometry.
fn point(key: &str, p: [f64; 3]) -> Result<(), Invalid> {
    if p.iter().any(|c| !c.is_finite()) {
        return Err(invalid(key, format!("{key} must be three finite coordinates in metres, got {p:?}")));
    }
    if p.iter().any(|c| c.abs() > MAX_REACH) {
        return Err(invalid(key, format!("{key} = {p:?} lies more than {MAX_REACH} m from the origin, beyond what contact resolves; move the scene nearer")));
    }
    Ok(())
}

/// Refuses a run of `duration` seconds (given by `key`) at steps of `dt` that needs more
/// than `max_steps` steps, with the bound to raise or the values to change.
pub fn check_step_count(key: &str, duration: f64, dt: f64, max_steps: u64) -> Result<(), Invalid> {
    let needed = (duration / dt).ceil();
    if needed > max_steps as f64 {
        // A bound past 1e15 steps would run for millennia: not worth offering.
        let raise = if needed < 1e15 { format!(", or raise the bound (--max-steps {needed:.0})") } else { String::new() };
        return Err(invalid(
            key,
            format!(
                "{key} = {} s at solver.dt = {} s needs {needed:.3e} steps, more than scene.max_steps = {max_steps}: \
                 use a larger solver.dt or a shorter duration{raise}",
                short(duration),
                short(dt)
            ),
        ));
    }
    Ok(())
}

/// A scene that passed the checks, with what they built on the way: the fabric, the
/// props, a garment's meshed pattern, and the run plan. Only the checks make one
/// ([`checked`], [`checked_for`]); it is all `Scene::build` accepts, and it reads as its
/// settings (`Deref`). A change to the settings goes back through the checks
/// ([`CheckedScene::into_config`], then `checked` or `Scene::new`).
#[derive(Clone)]
pub struct CheckedScene {
    config: SceneConfig,
    fabric: Fabric,
    props: Vec<Prop>,
    garment: Option<crate::garment::Garment>,
    plan: RunPlan,
}

/// What a checked scene hands `Scene::build`.
pub(crate) struct Checked {
    pub config: SceneConfig,
    pub fabric: Fabric,
    pub props: Vec<Prop>,
    pub garment: Option<crate::garment::Garment>,
    pub plan: RunPlan,
}

impl CheckedScene {
    /// How the scene will run: its design and levels, and what the plan chose over the
    /// scene's settings.
    pub fn plan(&self) -> &RunPlan {
        &self.plan
    }

    /// The same scene on `path`: only the checks that read the path are made again and the
    /// plan resolved again; what the checks built is kept (a path does not change the
    /// fabric, the props or the pattern).
    pub fn with_path(self, path: SolverPath) -> Result<CheckedScene, Invalid> {
        if path == self.config.solver.path {
            return Ok(self);
        }
        let mut checked = self;
        checked.config.solver.path = path;
        let run = RunLength { seconds: checked.config.scene.duration, key: "scene.duration" };
        check_fast_steps(&checked.config, &run)?;
        check_fast_integrator(&checked.config)?;
        checked.plan = RunPlan::resolve(&checked.config).map_err(|e| invalid("solver.path", e.to_string()))?;
        Ok(checked)
    }

    /// The settings, to change and check again.
    pub fn into_config(self) -> SceneConfig {
        self.config
    }

    pub(crate) fn into_parts(self) -> Checked {
        Checked { config: self.config, fabric: self.fabric, props: self.props, garment: self.garment, plan: self.plan }
    }
}

impl std::fmt::Debug for CheckedScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CheckedScene").field("config", &self.config).field("plan", &self.plan).finish_non_exhaustive()
    }
}

impl std::ops::Deref for CheckedScene {
    type Target = SceneConfig;
    fn deref(&self) -> &SceneConfig {
        &self.config
    }
}

/// Checks a whole scene (see the module's doc).
pub fn checked(c: SceneConfig) -> Result<CheckedScene, Invalid> {
    checked_for(c, None)
}

/// [`checked`] for a run of `run_duration` seconds (`rosette run --duration`) instead of
/// the scene's own: the step count and the step's length are checked against it, and
/// named by its flag.
pub fn checked_for(c: SceneConfig, run_duration: Option<f64>) -> Result<CheckedScene, Invalid> {
    let s = &c.scene;
    positive("scene.duration", s.duration)?;
    let run = match run_duration {
        Some(d) => RunLength { seconds: positive("--duration", d)?, key: "--duration" },
        None => RunLength { seconds: s.duration, key: "scene.duration" },
    };
    positive("scene.settle_window", s.settle_window)?;
    if let Some(v) = s.settle_speed {
        positive("scene.settle_speed", v)?;
    }
    if let Some(v) = s.gravity_ramp {
        positive("scene.gravity_ramp", v)?;
    }
    if s.max_steps == 0 {
        return Err(invalid("scene.max_steps", "scene.max_steps must be at least 1".into()));
    }
    check_solver(&c, &run)?;
    check_step_count(run.key, run.seconds, c.solver.dt, s.max_steps)?;
    let (extent, garment) = if kinds::of(c.scene.kind).specimen() == Specimen::Garment {
        let (extent, garment) = garment::check(&c)?;
        (extent, Some(garment))
    } else {
        let extent = check_cloth(&c)?;
        check_mesh(&c, &extent)?;
        (extent.size, None)
    };
    let fabric = c.material().map_err(|e| invalid(&format!("fabric.{}", e.key()), e.to_string()))?;
    c.fabric.look(c.base_dir.as_deref()).map_err(|e| invalid(&format!("fabric.{}", e.key), e.message))?;
    check_test(&c, extent)?;
    check_contact(&c, extent)?;
    for (i, p) in c.props.iter().enumerate() {
        check_prop_keys(i, p)?;
        point(&format!("props[{i}].position"), p.position)?;
        if p.rotation_deg.iter().any(|a| !(a.is_finite() && a.abs() <= 360.0)) {
            return Err(invalid(&format!("props[{i}].rotation_deg"), format!("props[{i}].rotation_deg must be three angles between -360 and 360 degrees, got {:?}", p.rotation_deg)));
        }
    }
    let props = super::props::build_props(&c.props, c.base_dir.as_deref()).map_err(|e| invalid("props", e))?;
    let plan = RunPlan::resolve(&c).map_err(|e| invalid("solver.path", e.to_string()))?;
    Ok(CheckedScene { config: c, fabric, props, garment, plan })
}

/// How long the run is asked to be, and the key or flag that says so.
struct RunLength {
    seconds: f64,
    key: &'static str,
}

/// Refuses a size key the prop's shape does not read (a sphere's `height` would be
/// silently ignored).
fn check_prop_keys(i: usize, p: &PropConfig) -> Result<(), Invalid> {
    let reads: &[&str] = match p.shape {
        PropKind::Ground => &[],
        PropKind::Box => &["size"],
        PropKind::Cylinder => &["radius", "height"],
        PropKind::Sphere => &["radius"],
        PropKind::Mesh => &["file", "scale"],
    };
    let given = [("radius", p.radius.is_some()), ("height", p.height.is_some()), ("size", p.size.is_some()), ("file", p.file.is_some()), ("scale", p.scale.is_some())];
    match given.iter().find(|(key, set)| *set && !reads.contains(key)) {
        None => Ok(()),
        Some((key, _)) => {
            let shape = format!("{:?}", p.shape).to_lowercase();
            let its = if reads.is_empty() { "it has no size".to_string() } else { format!("it reads {}", reads.join(" and ")) };
            Err(invalid(&format!("props[{i}].{key}"), format!("props[{i}].{key} has no meaning for a {shape} ({its}); remove it")))
        }
    }
}

fn check_solver(c: &SceneConfig, run: &RunLength) -> Result<(), Invalid> {
    let (solver, duration) = (&c.solver, run.seconds);
    positive("solver.dt", solver.dt)?;
    if solver.dt > duration {
        return Err(invalid(
            "solver.dt",
            format!("solver.dt = {} s is longer than {} = {} s: the run would be one step past its end; use a shorter step", short(solver.dt), run.key, short(duration)),
        ));
    }
    non_negative("solver.damping", solver.damping)?;
    // Drag stronger than a step's inertia a billion times over leaves nothing to simulate
    // and loses the Newton system's digits.
    let most = 1e9 / solver.dt;
    if solver.damping > most {
        return Err(invalid("solver.damping", format!("solver.damping = {} 1/s stops any motion within a billionth of a step; use at most {}", short(solver.damping), short(most))));
    }
    let n = &solver.newton;
    /// Beyond a few tens the directions' products cost more than any solve they could save.
    const MAX_RECYCLED_DIRECTIONS: usize = 32;
    if n.max_iterations == 0 {
        return Err(invalid("solver.newton.max_iterations", format!("solver.newton.max_iterations must be at least 1 (default {}): with none, no step is solved", crate::sim::solver::DEFAULT_MAX_ITERATIONS)));
    }
    let (newton, fast_defaults) = (crate::sim::NewtonSettings::default(), crate::settings::FastSettings::default());
    for (key, count, default) in [("solver.newton.cg_max_iterations", n.cg_max_iterations, newton.cg_max_iterations), ("solver.fast.cg_max_iterations", solver.fast.cg_max_iterations, fast_defaults.cg_max_iterations)] {
        if count == 0 {
            return Err(invalid(key, format!("{key} must be at least 1 (default {default}): with none, Newton has no direction")));
        }
    }
    positive_at_most("solver.newton.tolerance", n.tolerance, 0.1, &format!("a tenth of an edge: Newton would stop before it starts; the default is {}", short(newton.tolerance)))?;
    positive("solver.newton.cg_tolerance", n.cg_tolerance)?;
    if n.cg_tolerance >= 1.0 {
        return Err(invalid("solver.newton.cg_tolerance", format!("solver.newton.cg_tolerance = {} must be below 1 (a relative residual; the default is {})", n.cg_tolerance, short(newton.cg_tolerance))));
    }
    if !(n.error_share.is_finite() && (0.0..1.0).contains(&n.error_share)) {
        return Err(invalid(
            "solver.newton.error_share",
            format!("solver.newton.error_share = {} must lie in [0, 1): a share of the step's local error (0: off)", short(n.error_share)),
        ));
    }
    for (key, count, default) in [("solver.newton.recycled_directions", n.recycled_directions, newton.recycled_directions), ("solver.fast.recycled_directions", solver.fast.recycled_directions, fast_defaults.recycled_directions)] {
        if count > MAX_RECYCLED_DIRECTIONS {
            return Err(invalid(
                key,
                format!("{key} = {count} is too many: each direction costs a matrix product per linear solve and two passes per CG iteration; use at most {MAX_RECYCLED_DIRECTIONS} (default {default}, 0: off)"),
            ));
        }
    }
    let fast = &solver.fast;
    positive("solver.fast.dt", fast.dt)?;
    positive("solver.fast.drop_dt", fast.drop_dt)?;
    positive("solver.fast.garment_dt", fast.garment_dt)?;
    check_fast_steps(c, run)?;
    positive("solver.fast.coarsest_edge_share", fast.coarsest_edge_share)?;
    for (key, share, default) in [("solver.fast.error_share", fast.error_share, fast_defaults.error_share), ("solver.fast.motion_error_share", fast.motion_error_share, fast_defaults.motion_error_share)] {
        if !(share.is_finite() && (0.0..1.0).contains(&share)) {
            return Err(invalid(key, format!("{key} = {} must lie in [0, 1): a share of the step's local error (0: off; default {default})", short(share))));
        }
    }
    check_fast_integrator(c)?;
    if let Some(a) = solver.adaptive.filter(|a| a.enabled) {
        positive("solver.adaptive.tolerance", a.tolerance)?;
        positive("solver.adaptive.dt_min", a.dt_min)?;
        positive("solver.adaptive.dt_max", a.dt_max)?;
        if !(a.dt_min <= solver.dt && solver.dt <= a.dt_max) {
            return Err(invalid(
                "solver.dt",
                format!("solver.dt = {} s must lie between solver.adaptive.dt_min = {} s and dt_max = {} s", solver.dt, a.dt_min, a.dt_max),
            ));
        }
        if solver.integrator.is_explicit() {
            return Err(invalid(
                "solver.adaptive",
                format!(
                    "solver.adaptive works with the implicit integrators; {} is stable only below a fixed \
                     limit: set solver.adaptive.enabled = false or solver.integrator = \"implicit-euler\"",
                    solver.integrator
                ),
            ));
        }
    }
    Ok(())
}

/// The fast path's steps fit in the run (the checks that read `solver.path`, with
/// [`check_fast_integrator`]).
fn check_fast_steps(c: &SceneConfig, run: &RunLength) -> Result<(), Invalid> {
    let (fast, duration) = (&c.solver.fast, run.seconds);
    if c.solver.path == SolverPath::Fast {
        positive_at_most("solver.fast.dt", fast.dt, duration, &format!("{}: the fast path's long step must fit in the run", run.key))?;
        positive_at_most("solver.fast.drop_dt", fast.drop_dt, duration, &format!("{}: a dropped cloth's step must fit in the run", run.key))?;
        positive_at_most("solver.fast.garment_dt", fast.garment_dt, duration, &format!("{}: a garment's step must fit in the run", run.key))?;
    }
    Ok(())
}

/// A fast design takes implicit steps.
fn check_fast_integrator(c: &SceneConfig) -> Result<(), Invalid> {
    if c.solver.integrator.is_explicit() && super::plan::design(c) != super::plan::Design::Exact {
        return Err(invalid(
            "solver.integrator",
            format!(
                "solver.path = \"fast\" takes implicit steps, which solver.integrator = \"{}\" cannot; \
                 use solver.integrator = \"implicit-euler\" or solver.path = \"exact\"",
                c.solver.integrator
            ),
        ));
    }
    Ok(())
}

/// The cloth's smallest extent, m (the disc's diameter or the rectangle's shorter side),
/// and the key that gives it.
struct Extent {
    size: f64,
    key: &'static str,
}

/// The cloth's size and place.
fn check_cloth(c: &SceneConfig) -> Result<Extent, Invalid> {
    let cloth = &c.cloth;
    if !(cloth.warp_angle_deg.is_finite() && cloth.warp_angle_deg.abs() <= 360.0) {
        return Err(invalid("cloth.warp_angle_deg", format!("cloth.warp_angle_deg must be an angle between -360 and 360 degrees, got {}", short(cloth.warp_angle_deg))));
    }
    point("cloth.position", cloth.position)?;
    let size = |key: &str, v: f64| positive_at_most(key, v, MAX_REACH, "larger than the room contact resolves");
    let sheet = kinds::of(c.scene.kind).specimen() == Specimen::Sheet;
    let disc = sheet && cloth.diameter != 0.0;
    if disc {
        let d = size("cloth.diameter", cloth.diameter)?;
        for (key, v) in [("cloth.length", cloth.length), ("cloth.width", cloth.width)] {
            if v != 0.0 {
                return Err(invalid(key, format!("{key} has no meaning for a disc (cloth.diameter = {} m); remove it, or set cloth.diameter = 0 for a rectangle", short(d))));
            }
        }
        return Ok(Extent { size: d, key: "cloth.diameter" });
    }
    if cloth.diameter != 0.0 {
        return Err(invalid("cloth.diameter", "cloth.diameter is read by drape scenes only; this scene's cloth is the rectangle cloth.length × cloth.width".into()));
    }
    if sheet && (cloth.length == 0.0 || cloth.width == 0.0) {
        return Err(invalid(
            "cloth.diameter",
            "a drape cloth needs cloth.diameter (a disc) or cloth.length and cloth.width (a rectangle), in metres".into(),
        ));
    }
    let length = size("cloth.length", cloth.length)?;
    let width = size("cloth.width", cloth.width)?;
    Ok(if length <= width { Extent { size: length, key: "cloth.length" } } else { Extent { size: width, key: "cloth.width" } })
}

fn check_mesh(c: &SceneConfig, extent: &Extent) -> Result<(), Invalid> {
    let h = positive("mesh.edge_length", c.mesh.edge_length)?;
    // Each triangle's bending stencil needs neighbours that are not collinear with it: one
    // element across leaves them in a row (singular), two is the fewest that every pattern
    // and bundled scene builds with.
    let most = extent.size / 2.0;
    if h > most {
        return Err(invalid(
            "mesh.edge_length",
            format!(
                "mesh.edge_length = {} m leaves fewer than 2 elements across the cloth's {} m ({}); use at most {} m, or a larger cloth",
                short(h),
                short(extent.size),
                extent.key,
                short(most)
            ),
        ));
    }
    // The mesh generators refuse past their vertex cap too, but only after the fabric (whose
    // buckling branch divides by the edge length squared) has been checked.
    let cloth = &c.cloth;
    let disc = kinds::of(c.scene.kind).specimen() == Specimen::Sheet && cloth.diameter != 0.0;
    let planned = |h: f64| {
        if disc { planned_vertices(cloth.diameter, None, h, c.mesh.pattern) } else { planned_vertices(cloth.length, Some(cloth.width), h, c.mesh.pattern) }
    };
    let vertices = planned(h);
    if vertices > MAX_VERTICES {
        // The finest edge under the cap, by bisection on its logarithm (the count falls as
        // the edge grows, and two elements across is far under the cap).
        let (mut fails, mut passes) = (h, most);
        for _ in 0..100 {
            let mid = (fails * passes).sqrt();
            if planned(mid) > MAX_VERTICES { fails = mid } else { passes = mid }
        }
        let least = 1.001 * passes;
        return Err(invalid("mesh.edge_length", format!("mesh.edge_length = {} m gives about {} vertices, more than the limit of {MAX_VERTICES}; use at least {least:.3e} m", short(h), short(vertices as f64))));
    }
    Ok(())
}

fn check_test(c: &SceneConfig, extent: f64) -> Result<(), Invalid> {
    let t = &c.test;
    let kind = kinds::of(c.scene.kind);
    let given = [
        ("max_strain", t.max_strain.is_some()),
        ("end_shortening", t.end_shortening.is_some()),
        ("shear_angle_deg", t.shear_angle_deg.is_some()),
        ("speed", t.speed.is_some()),
        ("curvature", t.curvature.is_some()),
        ("clamp_length", t.clamp_length.is_some()),
        ("shear_kinematics", t.shear_kinematics.is_some()),
        ("clamp_radius", t.clamp_radius.is_some()),
        ("support_diameter", t.support_diameter.is_some()),
        ("support_size", t.support_size.is_some()),
        ("swing_amplitude", t.swing_amplitude.is_some()),
    ];
    // A key another kind would read is refused here, where this kind would ignore it.
    if let Some((key, _)) = given.iter().find(|(key, set)| *set && !kind.test_keys().contains(key)) {
        let readers: Vec<SceneKind> = SceneKind::ALL.into_iter().filter(|k| kinds::of(*k).test_keys().contains(key)).collect();
        let key = format!("test.{key}");
        return Err(invalid(&key, format!("{key} has no effect on a {:?} scene (it is read by {readers:?} scenes); remove it", c.scene.kind)));
    }
    let length = c.cloth.length;
    if let Some(a) = t.perturbation {
        non_negative("test.perturbation", a)?;
        // A perturbation breaks the symmetry; one larger than an element stretches the
        // mesh's edges past √2 before the run starts.
        let h = c.mesh.edge_length;
        if a > h {
            return Err(invalid("test.perturbation", format!("test.perturbation = {} m is larger than an element (mesh.edge_length = {} m); use at most {}", short(a), short(h), short(h))));
        }
    }
    kind.check(c, extent)?;
    if let Some(v) = t.clamp_length {
        positive_at_most("test.clamp_length", v, length, "the strip's length, cloth.length")?;
    }
    motion::check_motion_fits(c)
}

fn check_contact(c: &SceneConfig, extent: f64) -> Result<(), Invalid> {
    let k = &c.contact;
    let key = |e: &str| e.split_whitespace().next().unwrap_or("contact").trim_end_matches(':').to_string();
    k.validate().map_err(|e| invalid(&key(&e), e))?;
    positive_at_most("contact.thickness", k.thickness, 0.5 * extent, "half the cloth's size: the whole cloth would float on the layer")?;
    if let Some(v) = k.self_thickness {
        // Thicker than an element, the layer would push every neighbour apart and list
        // pairs by the hundred per vertex.
        positive_at_most("contact.self_thickness", v, c.mesh.edge_length, "an element, mesh.edge_length")?;
    }
    let default = crate::sim::contact::ContactSettings::default().stiffness;
    positive_at_most("contact.stiffness", k.stiffness, 1e4 * default, &format!("the default {} times ten thousand, where the Newton system loses its digits", short(default)))?;
    for (name, mu) in [("contact.friction_static", k.friction_static), ("contact.friction_kinetic", k.friction_kinetic)] {
        if mu > 10.0 {
            return Err(invalid(name, format!("{name} = {} is beyond any pair of surfaces (rubber on rubber is about 1); use at most 10", short(mu))));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scene::load_scene;
    use crate::scene::plan::Design;
    use crate::settings::SolverPath;

    /// A checked scene moved to another path keeps what its checks built and is planned
    /// for that path; a path its integrator cannot take is refused naming the key.
    #[test]
    fn a_checked_scene_changes_path_through_the_checks_that_read_it() {
        let (garment, _) = load_scene("skirt-gored-straight", &["solver.path=exact".into()]).unwrap();
        assert_eq!(garment.plan().design, Design::Exact);
        let fast = garment.with_path(SolverPath::Fast).unwrap();
        assert_eq!(fast.plan().design, Design::Garment);
        assert!(fast.garment.is_some(), "the pattern the checks meshed is kept");
        let (swing, _) = load_scene("swing", &["solver.integrator=symplectic-euler".into(), "solver.dt=1e-5".into()]).unwrap();
        let refused = swing.with_path(SolverPath::Fast).unwrap_err();
        assert_eq!(refused.key, "solver.integrator", "{}", refused.message);
    }
}
