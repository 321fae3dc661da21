//! Scene kinds: one file per kind of scene, each implementing [`Kind`] (what its test keys
//! must say, how long its prescribed motion lasts, how it holds and drives the cloth, what
//! it samples and measures, what the viewer plots first). [`of`] is the registry, the one
//! place a `SceneKind` is matched: adding a kind is a new file here, a variant of
//! `settings::SceneKind` and one line in `of`.

mod arc;
mod cantilever;
mod drape;
pub mod euler;
mod garment;
mod shear;
pub mod swing;
mod tensile;

use super::strip::{Columns, vertices_where};
use super::{Measures, SceneConfig, SceneError};
use crate::settings::SceneKind;
use crate::settings::rule::{Invalid, invalid, positive};
use crate::sim::{Model, State};
use glam::{DVec2, DVec3};
use std::any::Any;

/// Rest coordinates are compared with this tolerance when picking a strip's edge vertices, m.
const ON_EDGE: f64 = 1e-9;

/// The kind of scene `kind` is.
pub fn of(kind: SceneKind) -> &'static dyn Kind {
    match kind {
        SceneKind::Tensile => &tensile::Tensile,
        SceneKind::Cantilever => &cantilever::Cantilever,
        SceneKind::Arc => &arc::Arc,
        SceneKind::EulerBuckling => &euler::Euler,
        SceneKind::ShearBuckling => &shear::Shear,
        SceneKind::Drape => &drape::Drape,
        SceneKind::Garment => &garment::Garment,
        SceneKind::Swing => &swing::Swing,
    }
}

/// The cloth a kind of scene is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Specimen {
    /// A rectangular strip, `cloth.length` along x; `clamped`: held in a clamp band behind
    /// x = 0, a whole number of cells long; `grip`: with a band as long beyond its far end.
    Strip { clamped: bool, grip: bool },
    /// A disc (`cloth.diameter`) or rectangle centred on its position, laid on props.
    Sheet,
    /// Pattern pieces sewn on a form (`[garment]`).
    Garment,
}

/// A rig's prescribed motion: the test key that sets its extent, that extent as the
/// scene gives it, and the seconds the motion takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionTime {
    pub key: &'static str,
    pub extent: f64,
    pub seconds: f64,
}

/// What a kind of scene is and does; see the module's doc.
pub trait Kind: Sync {
    /// The kind as a scene file names it (`scene.kind`).
    fn name(&self) -> &'static str;

    /// The cloth the scene is made of.
    fn specimen(&self) -> Specimen;

    /// The `[test]` keys the kind reads (a key another kind would ignore is refused).
    fn test_keys(&self) -> &'static [&'static str] {
        &[]
    }

    /// The kind's own checks of its `[test]` keys, after the common ones; `extent` is the
    /// cloth's smallest size, m.
    fn check(&self, _config: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        Ok(())
    }

    /// How long the rig's prescribed motion lasts and the test key that sets its extent;
    /// None for a rig without one or where a key is missing (refused by `check`).
    fn motion_time(&self, _config: &SceneConfig) -> Option<MotionTime> {
        None
    }

    /// Where the cloth's rest points start: flat at `cloth.position`, unless the kind
    /// starts elsewhere.
    fn start(&self, config: &SceneConfig, rest: &[DVec2]) -> Vec<DVec3> {
        let origin = DVec3::from_array(config.cloth.position);
        rest.iter().map(|p| origin + DVec3::new(p.x, p.y, 0.0)).collect()
    }

    /// Pins and drives the rig's vertices on `model` (at positions `x`, with a clamp band of
    /// `clamp_band` m behind x = 0) and prepares its measurements.
    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], clamp_band: f64) -> Result<Box<dyn Rig>, SceneError>;

    /// The measure the viewer's "over time" plot opens on: the rig's response, which
    /// changes while the test runs. It names one of the rig's [`Measures::scalars`].
    fn plot_series(&self) -> &'static str;

    /// Whether the cloth moves freely throughout, loaded or not (a swing): the run plan
    /// then treats it as in motion, not as loaded slowly.
    fn moves_freely(&self) -> bool {
        false
    }

    /// The strain the test stretches the cloth to along x, where its stiffness at the end
    /// sets the explicit step limit.
    fn final_stretch(&self, _config: &SceneConfig) -> Option<f64> {
        None
    }

    /// Whether the scene settles into a drape whose coefficient fabrics can be compared by.
    fn drapes(&self) -> bool {
        false
    }

    /// Whether `run --outline` can write the drape's shadow outline.
    fn writes_outline(&self) -> bool {
        false
    }
}

/// A rig: how a scene holds and drives its cloth, what it samples while it runs and
/// measures at the end.
pub trait Rig: Send {
    /// Records one sample of the rig's time series.
    fn sample(&mut self, _model: &Model, _state: &State) {}

    /// The rig's measurements now.
    fn finish(&self, model: &Model, state: &State) -> Measures;

    /// Takes over the time series of `earlier`, the same rig on a coarser level of the fast
    /// path, so that the history runs from the start of the scene.
    fn continue_history(&mut self, _earlier: Box<dyn Rig>) {}

    /// The drape's shadow outline, (angle rad, radius m); None for rigs without one.
    fn outline(&self, _model: &Model, _state: &State) -> Option<Vec<(f64, f64)>> {
        None
    }

    /// The rig as `Any`, for the scene kinds' own code that knows its type (a garment's
    /// sewing reaches its rig this way).
    fn as_any_mut(&mut self) -> &mut dyn Any;
    fn as_any(&self) -> &dyn Any;
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
}

/// A test value the kind requires (`kind` as the scene file names it): present and positive.
fn need(kind: &str, key: &str, v: Option<f64>) -> Result<f64, Invalid> {
    let v = v.ok_or_else(|| invalid(key, format!("{key} is required for a {kind} scene")))?;
    positive(key, v)
}

/// Pins a strip's clamp (rest x < 0, the clamp band, and the clamp line) and lays its
/// columns along the free length, counted from the clamp line. Returns the columns and the
/// rigid set (the clamp), to which a grip may add before `Model::set_clamped_region`.
fn clamp_strip(config: &SceneConfig, model: &mut Model, x: &[DVec3], clamp_band: f64) -> (Columns, Vec<bool>) {
    let (length, h) = (config.cloth.length, config.mesh.edge_length);
    let clamp = vertices_where(&model.rest, |p| p.x < ON_EDGE);
    pin_all(model, x, &clamp);
    let mut rigid = vec![false; model.rest.len()];
    clamp.iter().for_each(|&v| rigid[v as usize] = true);
    let free: Vec<DVec2> = model.rest.iter().map(|p| DVec2::new(p.x + clamp_band, p.y)).collect();
    let mut columns = Columns::new(&free, length + 2.0 * clamp_band, h);
    for x in &mut columns.rest_x {
        *x -= clamp_band;
    }
    (columns, rigid)
}

/// Pins each vertex of `group` where it is.
fn pin_all(model: &mut Model, x: &[DVec3], group: &[u32]) {
    for &v in group {
        model.pin(v, x[v as usize]);
    }
}

/// The `Any` views every rig gives.
macro_rules! any_rig {
    () => {
        fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
            self
        }
        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
        fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
            self
        }
    };
}
pub(crate) use any_rig;

#[cfg(test)]
mod tests {
    use super::*;

    /// Each kind answers to the name a scene file gives it, and reads only test keys the
    /// scene schema has.
    #[test]
    fn every_kind_is_registered_under_its_scene_file_name() {
        let schema_keys = ["max_strain", "end_shortening", "shear_angle_deg", "speed", "curvature", "clamp_length", "shear_kinematics", "clamp_radius", "support_diameter", "support_size", "swing_amplitude"];
        for kind in SceneKind::ALL {
            let name = of(kind).name();
            let parsed: SceneKind = toml::Value::String(name.into()).try_into().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(parsed, kind, "{name}");
            for key in of(kind).test_keys() {
                assert!(schema_keys.contains(key), "{name} reads test.{key}, which the schema lacks");
            }
        }
    }

    /// A missing test value is refused in the words of the scene file: its key, and the
    /// kind as `scene.kind` spells it.
    #[test]
    fn a_missing_test_value_is_refused_naming_the_kind_as_the_file_does() {
        type Remove = fn(&mut SceneConfig);
        let cases: [(&str, &str, Remove); 3] = [
            ("tensile-warp", "test.max_strain", |c| c.test.max_strain = None),
            ("euler-buckling", "test.end_shortening", |c| c.test.end_shortening = None),
            ("shear-buckling", "test.shear_angle_deg", |c| c.test.shear_angle_deg = None),
        ];
        for (scene, key, remove) in cases {
            let (checked, _) = crate::scene::load::load_scene(scene, &[]).unwrap_or_else(|e| panic!("{scene}: {e}"));
            let mut config = (*checked).clone();
            remove(&mut config);
            let kind = of(config.scene.kind);
            let refusal = kind.check(&config, 1.0).expect_err(key);
            assert_eq!(refusal.key, key);
            assert_eq!(refusal.message, format!("{key} is required for a {} scene", kind.name()));
        }
    }
}
