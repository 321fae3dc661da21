//! What a test rig's prescribed motion needs: its extent reached within the scene's
//! duration.

use super::Invalid;
use crate::io::number::short;
use crate::settings::{SceneConfig, SceneKind, ShearKinematics};

/// How long the rig's prescribed motion lasts, s, and the test key that sets its extent:
/// the tensile pull to `test.max_strain`, the Euler approach to `test.end_shortening`, the
/// shear to `test.shear_angle_deg`. None for rigs without one (the arc's roll takes half
/// the run by construction) or where a key is missing (refused elsewhere).
pub fn motion_time(config: &SceneConfig) -> Option<(&'static str, f64)> {
    let (t, c) = (&config.test, &config.cloth);
    let speed = t.speed?;
    match config.scene.kind {
        SceneKind::Tensile => Some(("test.max_strain", t.max_strain? * c.length / speed)),
        SceneKind::EulerBuckling => Some(("test.end_shortening", t.end_shortening? * c.length / speed)),
        SceneKind::ShearBuckling => {
            let angle = t.shear_angle_deg?.to_radians();
            let travel = match t.shear_kinematics.unwrap_or_default() {
                // The grip slides along the warp by width·tan γ.
                ShearKinematics::Simple => c.width * angle.tan(),
                // The grip swings through γ on a link of the width.
                ShearKinematics::Trellis => c.width * angle,
            };
            Some(("test.shear_angle_deg", travel / speed))
        }
        _ => None,
    }
}

/// Refuses a test whose extent the scene's own duration cannot reach: `test.max_strain =
/// 0.5` at 1 mm/s on a 10 cm strip needs 50 s, and a 6 s scene would end at 6 % with the
/// strain asked for nowhere in its results.
pub fn check_motion_fits(config: &SceneConfig) -> Result<(), Invalid> {
    let Some((key, needed)) = motion_time(config) else { return Ok(()) };
    let duration = config.scene.duration;
    // The step loop ends within a millionth of a step of the duration.
    if needed <= duration * (1.0 + 1e-9) {
        return Ok(());
    }
    let value = match key {
        "test.max_strain" => config.test.max_strain,
        "test.end_shortening" => config.test.end_shortening,
        _ => config.test.shear_angle_deg,
    }
    .unwrap_or(f64::NAN);
    let speed = config.test.speed.unwrap_or(f64::NAN);
    let also = ["test.speed", "scene.duration", "cloth.length", "cloth.width", "test.shear_kinematics"].map(String::from).to_vec();
    Err(Invalid {
        key: key.to_string(),
        also,
        message: format!(
            "{key} = {} at test.speed = {} m/s takes {} s, longer than scene.duration = {} s: the run would end at {:.0} % of it. \
             Set scene.duration to at least {}, or test.speed to at least {} m/s",
            short(value),
            short(speed),
            short(needed),
            short(duration),
            100.0 * duration / needed,
            short(needed),
            short(speed * needed / duration)
        ),
    })
}

