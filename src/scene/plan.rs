//! The run plan: the step design a scene runs on, resolved once from its settings.
//!
//! Everything about *how* a scene is stepped, as opposed to *what* it models, is decided
//! here and nowhere else: which design the scene takes, its levels (the meshes it settles
//! on, coarse to fine), and per level the integrator, time step, Newton's limits and
//! tolerance, the linear solver's preconditioner and the contact penalty. `Scene::build`
//! calls [`RunPlan::resolve`] once and builds each level from the settings it holds;
//! `rosette run SCENE --plan` prints it.
//!
//! ```text
//!   exact path ─────────────────────────────── Exact: the scene's own mesh and settings
//!   fast path ─┬ settles, no props or a ramp ─ Settling: coarse to fine, long steps
//!              ├ in motion (props, no ramp,
//!              │  or the swing) ────────────── Motion: own mesh, the step for motion
//!              ├ a garment ─────────────────── Garment: own mesh, the garment's step
//!              └ a laboratory rig ──────────── Exact (the loading is the experiment)
//! ```

use crate::settings::{Origin, SolverPath};
use super::kinds::Specimen;
use super::{SceneConfig, SceneError};
use crate::physics::{bending_length, weight_per_area};
use crate::sim::PreconditionerChoice;
use std::fmt::Write as _;

/// The path a scene opens on in the viewer: the user's where they set one (`--fast`,
/// `--exact`, `--set solver.path`, their own scene file); else the fast path for a garment,
/// whose error against the exact path is within the scatter of its folds (docs/fast-path.md)
/// and which a designer would otherwise wait several times as long for; else the scene's.
pub fn opening_path(config: &SceneConfig) -> SolverPath {
    if config.origins.by_user("solver.path") || super::kinds::of(config.scene.kind).specimen() != Specimen::Garment {
        config.solver.path
    } else {
        SolverPath::Fast
    }
}

/// Which step design a scene runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Design {
    /// The scene's own mesh and settings from start to end: the exact path, and on the
    /// fast path the laboratory's rigs, whose loading is the experiment.
    Exact,
    /// The fast path's coarse-to-fine settling: each level settles at long steps, then
    /// hands its cloth to the next finer one; the run ends when the scene's own mesh has
    /// settled (docs/fast-path.md, items 1–5).
    Settling,
    /// A cloth in motion on the fast path (a drop not watched for settling, the swing): the
    /// scene's own mesh at the step for cloth in motion (docs/fast-path.md, item 6).
    Motion,
    /// A garment on the fast path: its own mesh (its panels are sewn and welded once) at
    /// the garment's step (`solver.fast.garment_dt`), contact as for cloth in motion.
    Garment,
}

impl Design {
    pub fn describe(self) -> &'static str {
        match self {
            Self::Exact => "the scene's own mesh and settings throughout",
            Self::Settling => "coarse to fine: each level settles, then the next finer one",
            Self::Motion => "cloth in motion: the scene's own mesh at the fast path's step for motion",
            Self::Garment => "a garment: its own mesh at the fast path's step for garments",
        }
    }
}

/// One level of a run: a mesh and the settings its steps run with.
#[derive(Debug, Clone)]
pub struct Level {
    /// The level's mesh edge, m (the scene's own on the last level).
    pub edge_length: f64,
    /// Whether the fast path's settings apply (every design but `Exact`).
    pub fast: bool,
    /// The scene's settings as this level runs them: the mesh, solver and contact sections
    /// resolved; the model's sections as the scene has them.
    pub config: SceneConfig,
    /// Every setting the plan chose over the scene's value, and every value of the user's
    /// it kept where it would have chosen another.
    pub choices: Vec<Choice>,
}

/// A setting the plan chose over the value the scene had (a default or a bundled scene's),
/// or a value the user set that it kept although it would have chosen another.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Choice {
    /// The dotted key, as a scene file spells it.
    pub key: &'static str,
    /// The value the level runs with.
    pub value: String,
    /// The scene's value: the one replaced, or the user's one kept.
    pub scene_value: String,
    /// Who gave the scene's value: "the default", "the bundled scene" or "yours".
    pub origin: &'static str,
    /// The user's value stood, and `plan_value` is what the plan would have taken.
    pub kept: bool,
    pub plan_value: String,
    /// Why the plan takes its value, and what keeping the user's costs.
    pub why: &'static str,
}

impl Choice {
    /// The choice in words, for `--plan`.
    pub fn describe(&self) -> String {
        if self.kept {
            format!("{} = {} (yours; the plan would take {}: {})", self.key, self.value, self.plan_value, self.why)
        } else {
            format!("{} = {} (replaces {}'s {}: {})", self.key, self.value, self.origin, self.scene_value, self.why)
        }
    }
}

/// Records the plan's choices for one level: a key the user set keeps their value, any
/// other takes the plan's.
struct Chooser<'a> {
    origins: &'a crate::settings::Origins,
    choices: Vec<Choice>,
}

impl Chooser<'_> {
    /// Sets `slot` (the setting at `key`) to `value` unless the user gave it; records the
    /// choice either way where the two differ.
    fn choose<T: PartialEq + Copy>(&mut self, key: &'static str, slot: &mut T, value: T, show: impl Fn(T) -> String, why: &'static str) {
        if *slot == value {
            return;
        }
        let origin = self.origins.of(key);
        let kept = origin == Origin::User;
        self.choices.push(Choice {
            key,
            value: show(if kept { *slot } else { value }),
            scene_value: show(*slot),
            origin: origin.name(),
            kept,
            plan_value: show(value),
            why,
        });
        if !kept {
            *slot = value;
        }
    }
}

/// How a scene runs: its design and its levels, coarsest first.
#[derive(Debug, Clone)]
pub struct RunPlan {
    pub design: Design,
    pub levels: Vec<Level>,
}

impl RunPlan {
    /// The plan of `config`'s run. Refuses a path the integrator cannot take.
    pub fn resolve(config: &SceneConfig) -> Result<Self, SceneError> {
        // An explicit integrator on a fast design is refused by the checks (`check::checked`).
        let design = design(config);
        let own = config.mesh.edge_length;
        let edges = match design {
            Design::Exact => {
                return Ok(Self { design, levels: vec![Level { edge_length: own, fast: false, config: config.clone(), choices: Vec::new() }] });
            }
            Design::Motion | Design::Garment => vec![own],
            Design::Settling => {
                let coarsest = coarsest_edge(config).map_err(crate::sim::ModelError::from)?;
                let mut edges = vec![own];
                while 2.0 * edges[0] <= coarsest {
                    edges.insert(0, 2.0 * edges[0]);
                }
                edges
            }
        };
        let levels = edges
            .into_iter()
            .map(|edge| {
                let (config, choices) = level_with_choices(config, Some(edge));
                Level { edge_length: edge, fast: true, config, choices }
            })
            .collect();
        Ok(Self { design, levels })
    }

    /// The plan in words, a line per level: what `rosette run --plan` prints.
    pub fn describe(&self, scene: &SceneConfig) -> String {
        let mut text = format!(
            "path {}: {} ({} level{})\n",
            scene.solver.path.name(),
            self.design.describe(),
            self.levels.len(),
            if self.levels.len() == 1 { "" } else { "s" }
        );
        for (i, level) in self.levels.iter().enumerate() {
            let (c, s, n) = (&level.config, &level.config.solver, &level.config.solver.newton);
            let mm = |m: f64| format!("{:.3} mm", 1e3 * m);
            let own = if i + 1 == self.levels.len() { " (the scene's mesh)" } else { "" };
            let _ = writeln!(text, "level {}: {} edges{own}", i + 1, mm(level.edge_length));
            let step = if s.dt != scene.solver.dt { format!(" (the scene's {} s)", scene.solver.dt) } else { String::new() };
            let _ = writeln!(text, "  step: {}, dt {} s{step}, damping {} 1/s{}", s.integrator.name(), s.dt, s.damping, if s.adaptive.is_some() { ", adaptive" } else { "" });
            let _ = writeln!(
                text,
                "  {}: at most {} iterations, tolerance {} of the mean edge{}, preconditioner {}{}, indefinite {}, retry exact {}{}{}",
                n.minimizer.name(),
                n.max_iterations,
                n.tolerance,
                if n.error_share > 0.0 { format!(" or {} of the step's local error", n.error_share) } else { String::new() },
                key_name(&n.preconditioner),
                if n.preconditioner == PreconditionerChoice::Auto {
                    format!(" (the complete factor from {} vertices)", PreconditionerChoice::AUTO_CHOLESKY_VERTICES)
                } else {
                    String::new()
                },
                key_name(&n.indefinite),
                n.retry_exact,
                if n.recycled_directions > 0 { format!(", CG deflated by the last {} directions", n.recycled_directions) } else { String::new() },
                if n.cg_max_iterations < crate::sim::NewtonSettings::default().cg_max_iterations { format!(", CG stopped at {} iterations a solve", n.cg_max_iterations) } else { String::new() },
            );
            for choice in &level.choices {
                let _ = writeln!(text, "  {}: {}", if choice.kept { "kept" } else { "chosen" }, choice.describe());
            }
            if !c.props.is_empty() || c.contact.self_collision {
                let factor = c.contact.stiffness / scene.contact.stiffness;
                let _ = writeln!(
                    text,
                    "  contact: stiffness {} m/dt²{}, pair list kept by {} motion, friction sticks below {:.2} mm/s{}",
                    c.contact.stiffness,
                    if factor != 1.0 { format!(" (the scene's × {factor:.3})") } else { String::new() },
                    if c.contact.relative_motion { "relative" } else { "absolute" },
                    1e3 * c.contact.slip_speed,
                    if c.contact.hold_sticking { ", sticking vertices held over a step" } else { "" },
                );
            }
        }
        text
    }
}

/// A setting's value as a scene file spells it.
fn key_name<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_value(value).ok().and_then(|v| v.as_str().map(str::to_string)).unwrap_or_default()
}

/// The design `config` runs on.
pub(crate) fn design(config: &SceneConfig) -> Design {
    if config.solver.path != SolverPath::Fast {
        return Design::Exact;
    }
    if super::kinds::of(config.scene.kind).specimen() == Specimen::Garment {
        return Design::Garment;
    }
    match (config.scene.settle_speed.is_some(), quasi_static(config)) {
        (true, _) => Design::Settling,
        (false, false) => Design::Motion,
        (false, true) => Design::Exact,
    }
}

/// The coarsest edge that still resolves the scene's folds: `solver.fast.coarsest_edge_share`
/// of the fabric's bending length (B/w)^(1/3), m (the weaker direction's).
fn coarsest_edge(config: &SceneConfig) -> Result<f64, crate::sim::FabricError> {
    let fabric = config.material()?;
    let weight = weight_per_area(fabric.areal_density);
    Ok(config.solver.fast.coarsest_edge_share * bending_length(fabric.bending_warp.min(fabric.bending_weft), weight))
}

/// Newton's iteration limit on the fast path's long steps.
const FAST_MAX_ITERATIONS: usize = 80;

/// Whether the scene loads its cloth slowly: no props to land on (except the swing, which
/// moves freely throughout), or props with gravity ramped up (a lowered specimen).
/// Otherwise the cloth is dropped onto its props, or swings, and is in motion at every step.
fn quasi_static(config: &SceneConfig) -> bool {
    let free_motion = super::kinds::of(config.scene.kind).moves_freely();
    (config.props.is_empty() && !free_motion) || config.scene.gravity_ramp.is_some()
}

/// The settings of one level: the scene's own for None (the exact design); on a fast-path
/// level, the scene on a mesh of `edge_length` with the fast path's step, Newton and
/// contact. Also what a settings change on a running scene re-plans with
/// (`Scene::set_solver`).
pub(super) fn level(config: &SceneConfig, edge_length: Option<f64>) -> SceneConfig {
    level_with_choices(config, edge_length).0
}

/// [`level`], with the choices the plan made over the scene's values and the user's values
/// it kept.
fn level_with_choices(config: &SceneConfig, edge_length: Option<f64>) -> (SceneConfig, Vec<Choice>) {
    let mut level = config.clone();
    let Some(edge) = edge_length else { return (level, Vec::new()) };
    let mut chooser = Chooser { origins: &config.origins, choices: Vec::new() };
    let fast = &config.solver.fast;
    level.mesh.edge_length = edge;
    let yes_no = |b: bool| b.to_string();
    let number = |v: f64| crate::io::number::short(v);
    let count = |v: usize| v.to_string();
    // The pair list is kept across Newton iterations by the cloth's motion relative to its
    // common fall (docs/fast-path.md, item 3).
    chooser.choose(
        "contact.relative_motion",
        &mut level.contact.relative_motion,
        true,
        yes_no,
        "the pair list follows the cloth's motion relative to its common fall (docs/fast-path.md, item 3)",
    );
    // Long steps follow a quasi-static load through near-equilibria, which holds where
    // the mesh resolves the folds. On a mesh whose elements are as wide as the folds the
    // drape depends on the path at the scale of an element, and the scene keeps its step.
    // A cloth dropped onto a prop takes the shorter `drop_dt` on any mesh (its folds
    // depend on the fall's path at every step), with the contact penalty's factor raised
    // with the square of the step so that its stiffness c·m/Δt² stays the scene's: a
    // vertex arriving at speed v then stops within v·Δt/√c of the same layer as at the
    // scene's own step.
    let resolved = coarsest_edge(config).is_ok_and(|coarsest| edge <= coarsest * (1.0 + 1e-9));
    // A garment's gravity ramp lowers it onto the form, but its panels are drawn together
    // by the sewing and then hang: cloth in motion on a body, on its own mesh, at its own
    // step (`garment_dt`, with the penalty rescaled as a drop's).
    let kind = design(config);
    let slow = quasi_static(config) && kind != Design::Garment;
    let long_dt = match (slow, kind) {
        (true, _) => resolved.then_some(fast.dt),
        (false, Design::Garment) => Some(fast.garment_dt),
        (false, _) => Some(fast.drop_dt),
    };
    if let Some(long_dt) = long_dt.filter(|&d| d > config.solver.dt) {
        let why_dt = match (slow, kind) {
            (true, _) => "the fast path's long step for a slowly loaded cloth on a mesh that resolves its folds (solver.fast.dt)",
            (false, Design::Garment) => "the fast path's step for a garment (solver.fast.garment_dt)",
            (false, _) => "the fast path's step for a cloth dropped onto props (solver.fast.drop_dt)",
        };
        chooser.choose("solver.dt", &mut level.solver.dt, long_dt, number, why_dt);
        if !slow {
            // The penalty's stiffness c·m/Δt² stays the scene's at the longer step.
            let scaled = config.contact.stiffness * (level.solver.dt / config.solver.dt).powi(2);
            chooser.choose(
                "contact.stiffness",
                &mut level.contact.stiffness,
                scaled,
                number,
                "scaled with the square of the step, so that the contact layer is as stiff as at the scene's step",
            );
        }
        // The first step after a transfer relaxes, in one long step, what the coarser
        // mesh could not resolve; Newton gets the iterations that takes.
        let iterations = level.solver.newton.max_iterations.max(FAST_MAX_ITERATIONS);
        chooser.choose(
            "solver.newton.max_iterations",
            &mut level.solver.newton.max_iterations,
            iterations,
            count,
            "a long step relaxes in one step what a coarser level or the last step left",
        );
        // On a slowly loaded drape at long steps the incomplete factor leaves CG tens of
        // iterations per Newton iteration; the complete factor a few, and it is rebuilt
        // rarely. A falling cloth's contacts and shifts change from one iteration to the
        // next, and rebuilding the complete factor that often costs more than the
        // incomplete factor's extra CG iterations (docs/fast-path.md), at any size.
        // A preconditioner a bundled scene names is its own choice, as the default `auto`
        // is the plan's to make; the user's stands, with a word where the plan differs.
        if level.solver.newton.preconditioner == PreconditionerChoice::Auto || config.origins.by_user("solver.newton.preconditioner") {
            let factor = if slow { PreconditionerChoice::Cholesky } else { PreconditionerChoice::IncompleteCholesky };
            chooser.choose(
                "solver.newton.preconditioner",
                &mut level.solver.newton.preconditioner,
                factor,
                |p| key_name(&p),
                "the complete factor serves a slowly loaded drape's long steps; a moving cloth's matrix changes too often for it",
            );
        }
    }
    choose_newton_stops(&mut chooser, &mut level, kind, slow);
    (level, chooser.choices)
}

/// The plan's choices of when Newton and CG stop: the error share, a garment's deflated
/// and bounded solves, and the bounded matrix kept through a landing step.
fn choose_newton_stops(chooser: &mut Chooser<'_>, level: &mut SceneConfig, kind: Design, slow: bool) {
    let fast = level.solver.fast;
    let yes_no = |b: bool| b.to_string();
    let number = |v: f64| crate::io::number::short(v);
    let count = |v: usize| v.to_string();
    // Garments keep the tighter share: at the motion's, the shift dress settled on 3 hem
    // nodes instead of the exact path's 5 and the circle skirt did not settle in 6 s
    // (docs/performance-log.md).
    let (share, why_share) = if kind == Design::Motion {
        (fast.motion_error_share, "Newton stops at a share of the step's own error for cloth in motion (solver.fast.motion_error_share)")
    } else {
        (fast.error_share, "Newton stops at a share of the step's own error (solver.fast.error_share)")
    };
    chooser.choose("solver.newton.error_share", &mut level.solver.newton.error_share, share, number, why_share);
    // A garment coming to rest repeats its slow swing from step to step: its solves are
    // deflated by the last Newton directions (docs/fast-path.md, item 7). A few of its
    // solves run to thousands of CG iterations even on a fresh factor: they stop at the
    // fast path's limit, and Newton goes on with a fresh factor (item 8).
    if kind == Design::Garment {
        chooser.choose(
            "solver.newton.recycled_directions",
            &mut level.solver.newton.recycled_directions,
            fast.recycled_directions,
            count,
            "a garment coming to rest repeats its slow swing: its solves are deflated by the last directions (solver.fast.recycled_directions)",
        );
        let limit = level.solver.newton.cg_max_iterations.min(fast.cg_max_iterations);
        chooser.choose(
            "solver.newton.cg_max_iterations",
            &mut level.solver.newton.cg_max_iterations,
            limit,
            count,
            "a garment's rare solves of thousands of CG iterations stop there and Newton goes on with a fresh factor (solver.fast.cg_max_iterations)",
        );
    }
    // A cloth landing on a prop buckles in most iterations of its landing steps: once
    // the exact matrix has failed in a step, the rest of the step is solved on the
    // bounded one instead of trying the exact one first again (docs/fast-path.md).
    if !slow {
        chooser.choose(
            "solver.newton.retry_exact",
            &mut level.solver.newton.retry_exact,
            false,
            yes_no,
            "a landing cloth buckles in most iterations: once the exact matrix fails in a step, the rest of the step takes the bounded one",
        );
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    fn plan(preset: &str, overrides: &[&str]) -> (SceneConfig, RunPlan) {
        let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        let (config, _) = load_scene(preset, &overrides).unwrap();
        let plan = RunPlan::resolve(&config).unwrap();
        (config.into_config(), plan)
    }

    #[test]
    fn the_exact_path_and_the_laboratory_rigs_run_the_scenes_own_settings() {
        for (preset, path) in [("cusick-drape", "exact"), ("sphere-drop", "exact"), ("tensile-warp", "fast"), ("euler-buckling", "fast")] {
            let (config, plan) = plan(preset, &[&format!("solver.path={path}")]);
            assert_eq!(plan.design, Design::Exact, "{preset} on the {path} path");
            assert_eq!(plan.levels.len(), 1);
            let level = &plan.levels[0];
            assert!(!level.fast);
            assert_eq!(serde_json::to_value(&level.config).unwrap(), serde_json::to_value(&config).unwrap(), "{preset}: the settings are the scene's");
        }
    }

    #[test]
    fn a_settling_drape_halves_its_edge_from_the_coarsest_that_resolves_its_folds() {
        let (config, plan) = plan("cusick-drape", &["solver.path=fast", "mesh.edge_length=0.00315"]);
        assert_eq!(plan.design, Design::Settling);
        let coarsest = coarsest_edge(&config).unwrap();
        let edges: Vec<f64> = plan.levels.iter().map(|l| l.edge_length).collect();
        assert_eq!(*edges.last().unwrap(), 0.00315, "the run ends on the scene's mesh");
        assert!(edges[0] <= coarsest && 2.0 * edges[0] > coarsest, "{edges:?} against the coarsest {coarsest}");
        for pair in edges.windows(2) {
            assert!((pair[0] - 2.0 * pair[1]).abs() < 1e-12, "{edges:?}");
        }
        for level in &plan.levels {
            assert_eq!(level.config.mesh.edge_length, level.edge_length);
            assert_eq!(level.config.solver.dt, config.solver.fast.dt, "a lowered drape takes the long step on levels that resolve its folds");
            assert_eq!(level.config.contact.stiffness, config.contact.stiffness, "a lowered drape keeps its contact penalty");
            assert_eq!(level.config.solver.newton.error_share, config.solver.fast.error_share);
        }
    }

    #[test]
    fn cloth_in_motion_keeps_its_mesh_at_the_step_for_motion_with_the_penalty_rescaled() {
        let mut config = load_scene("sphere-drop", &["solver.path=fast".into()]).unwrap().0.into_config();
        config.scene.settle_speed = None;
        let dropped = RunPlan::resolve(&config).unwrap();
        assert_eq!(dropped.design, Design::Motion);
        assert_eq!(dropped.levels.len(), 1);
        let level = &dropped.levels[0].config;
        let ratio = config.solver.fast.drop_dt / config.solver.dt;
        assert_eq!(level.mesh.edge_length, config.mesh.edge_length);
        assert_eq!(level.solver.dt, config.solver.fast.drop_dt);
        assert!((level.contact.stiffness - config.contact.stiffness * ratio * ratio).abs() < 1e-9 * level.contact.stiffness);
        assert!(level.contact.relative_motion && !level.solver.newton.retry_exact);
        assert_eq!(level.solver.newton.preconditioner, PreconditionerChoice::IncompleteCholesky);
        assert_eq!(level.solver.newton.error_share, config.solver.fast.motion_error_share);
        // The swing moves freely with no prop: the same design.
        let (_, swing) = plan("swing", &["solver.path=fast"]);
        assert_eq!(swing.design, Design::Motion);
        assert_eq!(swing.levels[0].config.solver.dt, config.solver.fast.drop_dt);
    }

    /// A garment is lowered onto its form by a gravity ramp, but sewn and hung it moves on a
    /// body: it keeps its own mesh and takes the garment's step, with the contact penalty
    /// rescaled as a drop's is, and the settling levels' Newton share (the motion's moved the
    /// dress's hem nodes).
    #[test]
    fn a_garment_takes_the_garment_step_on_its_own_mesh() {
        let (config, plan) = plan("skirt-circle", &["solver.path=fast"]);
        assert_eq!(plan.design, Design::Garment);
        assert_eq!(plan.levels.len(), 1);
        let level = &plan.levels[0].config;
        let ratio = config.solver.fast.garment_dt / config.solver.dt;
        assert_eq!(level.mesh.edge_length, config.mesh.edge_length);
        assert_eq!(level.solver.dt, config.solver.fast.garment_dt, "not the scene's own step");
        assert!((level.contact.stiffness - config.contact.stiffness * ratio * ratio).abs() < 1e-9 * level.contact.stiffness);
        assert_eq!(level.solver.newton.preconditioner, PreconditionerChoice::IncompleteCholesky);
        assert_eq!(level.solver.newton.error_share, config.solver.fast.error_share);
        assert_eq!(level.solver.newton.recycled_directions, config.solver.fast.recycled_directions);
        assert!(plan.describe(&config).contains("deflated by the last 8 directions"), "{}", plan.describe(&config));
        // Only garments: the exact path and the other designs keep plain CG.
        assert_eq!(config.solver.newton.recycled_directions, 0);
        let (_, drape) = super::tests::plan("cusick-drape", &["solver.path=fast"]);
        assert!(drape.levels.iter().all(|l| l.config.solver.newton.recycled_directions == 0));
    }

    /// What the user set stands: for every key the fast path's plan may change, a value set
    /// with `--set` is the one the scene's own mesh runs with, and the plan says it kept it
    /// and what it would have taken; left to the default or the bundled scene, the plan's
    /// value runs and the plan says what it replaced.
    #[test]
    fn every_key_the_plan_changes_stands_where_the_user_set_it() {
        // (scene, key, a value of the user's unlike the plan's, how the level holds it)
        type Read = fn(&SceneConfig) -> String;
        let cases: [(&str, &str, &str, Read); 9] = [
            ("tablecloth", "contact.relative_motion", "false", |c| c.contact.relative_motion.to_string()),
            ("tablecloth", "solver.dt", "0.008", |c| c.solver.dt.to_string()),
            ("tablecloth", "contact.stiffness", "250", |c| c.contact.stiffness.to_string()),
            ("tablecloth", "solver.newton.max_iterations", "2", |c| c.solver.newton.max_iterations.to_string()),
            ("tablecloth", "solver.newton.preconditioner", "\"cholesky\"", |c| format!("\"{}\"", key_name(&c.solver.newton.preconditioner))),
            ("tablecloth", "solver.newton.error_share", "0.02", |c| c.solver.newton.error_share.to_string()),
            ("skirt-gored-bias", "solver.newton.recycled_directions", "2", |c| c.solver.newton.recycled_directions.to_string()),
            ("skirt-gored-bias", "solver.newton.cg_max_iterations", "2500", |c| c.solver.newton.cg_max_iterations.to_string()),
            ("tablecloth", "solver.newton.retry_exact", "true", |c| c.solver.newton.retry_exact.to_string()),
        ];
        for (scene, key, value, read) in cases {
            let (default_config, default_plan) = plan(scene, &["solver.path=fast"]);
            let level = default_plan.levels.last().unwrap();
            let chosen = level.choices.iter().find(|c| c.key == key).unwrap_or_else(|| panic!("{scene}: the plan changes {key}"));
            assert!(!chosen.kept);
            assert_eq!(chosen.value, read(&level.config).trim_matches('"'), "{key}: the value run is the one printed");
            assert_ne!(chosen.scene_value, chosen.value);
            let described = default_plan.describe(&default_config);
            assert!(described.contains(&format!("chosen: {key} = {}", chosen.value)) && described.contains("replaces"), "{described}");
            let (config, user_plan) = plan(scene, &["solver.path=fast", &format!("{key}={value}")]);
            let level = user_plan.levels.last().unwrap();
            assert_eq!(read(&level.config), value, "{scene}: {key} set by the user stands");
            let kept = level.choices.iter().find(|c| c.key == key).unwrap_or_else(|| panic!("{scene}: {key} kept without a word"));
            // The plan's own value (the stiffness it would scale from the user's own).
            assert!(kept.kept && kept.origin == "yours" && kept.value == value.trim_matches('"') && kept.plan_value != kept.value, "{kept:?}");
            assert!(user_plan.describe(&config).contains(&format!("kept: {key} = ")), "{}", user_plan.describe(&config));
        }
    }

    #[test]
    fn a_fast_path_the_integrator_cannot_take_is_refused_naming_both_keys() {
        // The checks refuse it when the scene is loaded, before any plan is made.
        let message = load_scene("swing", &["solver.path=fast".into(), "solver.integrator=symplectic-euler".into(), "solver.dt=1e-5".into()]).unwrap_err().to_string();
        assert!(message.contains("solver.path") && message.contains("solver.integrator"), "{message}");
    }
}
