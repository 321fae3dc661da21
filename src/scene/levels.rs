//! The fast path's coarse-to-fine settling of drapes.
//!
//! A drape is an equilibrium reached along a slow path, and the path is where the exact
//! run spends its time: thousands of Newton iterations on the user's mesh while the cloth
//! sinks, buckles at the rim and folds. The fold pattern is decided at a scale set by the
//! fabric's bending length, far above a fine mesh's edges. The fast path therefore takes
//! the path on a coarse mesh of the same specimen and only settles on the finer ones:
//!
//! ```text
//!   coarsest mesh: lowered from flat under the gravity ramp, until it settles
//!        │ positions and velocities carried over (barycentric, rest plane)
//!   mesh at half that edge: settles
//!        │
//!   the scene's own mesh: settles; the run stops there, as the exact path does
//! ```
//!
//! Each level halves the edge of the one before, so the transfer leaves every level only
//! the folds its coarser neighbour could not resolve to relax. Levels that resolve the folds
//! run at the fast path's long time step (`solver.fast.dt`), on which implicit Euler is as
//! stable as on the exact path's; a scene whose mesh is coarser than that keeps its own
//! step. A cloth dropped onto props (no gravity ramp) takes the long step on every level,
//! with the contact penalty rescaled to keep its stiffness (`plan::level`), and on every
//! level Newton stops at the step's own accuracy (`solver.fast.error_share`).

use super::run::SettleWatch;
use super::Scene;
use crate::sim::Mesh;

/// The finer levels still to come and the settling of the current one.
pub struct Levels {
    /// Finer levels, next first, each built when the scene was, so that a bad mesh is
    /// refused before any work.
    pending: Vec<Scene>,
    /// The current level's settling.
    watch: SettleWatch,
}

impl Levels {
    pub fn new(current: &Scene, pending: Vec<Scene>) -> Self {
        Self { pending, watch: SettleWatch::new(current) }
    }

    /// Whether the current level is the scene's own mesh.
    pub fn is_final(&self) -> bool {
        self.pending.is_empty()
    }
}

impl Scene {
    /// After a step on a coarse level: moves to the next finer level once the current one
    /// has settled.
    pub(super) fn refine_if_settled(&mut self) {
        let Some(mut levels) = self.levels.take() else { return };
        if !levels.is_final() {
            let rms = self.rms_speed();
            if levels.watch.observe_level(self, rms).is_some() {
                let next = levels.pending.remove(0);
                self.continue_on(next);
                levels.watch = SettleWatch::new(self);
            }
        }
        self.levels = Some(levels);
    }

    /// Carries this level's cloth over to `next`, the same scene on a finer mesh, and takes
    /// its place: positions and velocities by barycentric transfer in the rest plane (its
    /// clamped vertices keep their own prescribed places), time, step count, contact
    /// statistics and the rig's history.
    fn continue_on(&mut self, mut next: Scene) {
        let coarse = Mesh { rest: self.model.rest.clone(), triangles: self.model.triangles.clone() };
        for (i, e) in coarse.embed(&next.model.rest).iter().enumerate() {
            if !next.model.fixed[i] {
                next.state.x[i] = e.position(&self.state.x);
                next.state.v[i] = e.position(&self.state.v);
            }
        }
        next.state.time = self.state.time;
        next.state.steps = self.state.steps;
        next.integrator.contact_stats = self.integrator.contact_stats;
        self.model = next.model;
        self.topology = next.topology;
        self.state = next.state;
        self.integrator = next.integrator;
        self.sample_every = next.sample_every;
        self.level_edge = next.level_edge;
        self.level_solver = next.level_solver;
        let earlier = std::mem::replace(&mut self.rig, next.rig);
        self.rig.continue_history(earlier);
    }
}
