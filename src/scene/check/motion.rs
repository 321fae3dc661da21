//! What a test rig's prescribed motion needs: its extent reached within the scene's
//! duration.

use super::Invalid;
use crate::scene::kinds::{self, MotionTime};
use crate::io::number::short;
use crate::settings::SceneConfig;

/// Refuses a test whose extent the scene's own duration cannot reach: `test.max_strain =
/// 0.5` at 1 mm/s on a 10 cm strip needs 50 s, and a 6 s scene would end at 6 % with the
/// strain asked for nowhere in its results.
pub fn check_motion_fits(config: &SceneConfig) -> Result<(), Invalid> {
    let Some(MotionTime { key, extent: value, seconds: needed }) = kinds::of(config.scene.kind).motion_time(config) else { return Ok(()) };
    let duration = config.scene.duration;
    // The step loop ends within a millionth of a step of the duration.
    if needed <= duration * (1.0 + 1e-9) {
        return Ok(());
    }
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

