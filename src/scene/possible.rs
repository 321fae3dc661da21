//! What a run can honour and what its measures can be: the one place where a request is
//! checked against what the rig can do in the time given, and a measure against what is
//! physically possible.
//!
//! Before the run: a test's extent (strain, end shortening, shear angle) must be reached
//! within the scene's duration (`scene::check::check_motion_fits`, checked on loading); props must start clear of the cloth
//! ([`check_start`]); a screenshot's camera must leave the cloth some pixels
//! ([`check_camera`]). After it ([`judge`]): a drape coefficient outside [0, 1] is not a
//! drape coefficient and is reported as not measured; wrinkles no taller than the seeded
//! perturbation are the seed, not wrinkles; a motion the run ended before finishing (a
//! short `--duration`) is said in the metrics' notes.

use crate::settings::SceneConfig;
use super::{Measures, Metrics, Scene};
use crate::io::number::short;

/// Below this share of critical damping, an unsettled run suggests damping its swing harder.
const UNDERDAMPED_SHARE: f64 = 0.8;

/// For a cloth that hangs (its height more than a few contact layers) with less air damping
/// than [`critical_swing_damping`] for its height: that damping, and why it leaves the
/// rest state alone (damping does not move an equilibrium, only how soon the swing about it
/// dies out; docs/garments.md). Empty otherwise.
fn swing_damping_hint(scene: &Scene) -> String {
    let (low, high) = scene.state.x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.z), hi.max(p.z)));
    let height = high - low;
    if !height.is_finite() || height <= 5.0 * scene.config.contact.thickness {
        return String::new();
    }
    let critical = critical_swing_damping(height);
    let damping = scene.config.solver.damping;
    if damping >= UNDERDAMPED_SHARE * critical {
        return String::new();
    }
    format!(
        ", or damp its swing harder: hanging {} cm, it swings at {} rad/s, which solver.damping = {} 1/s damps critically \
         (it is {} 1/s; more than that slows the folds' creep, and no damping moves the equilibrium the cloth swings about)",
        short(100.0 * height),
        short(0.5 * critical),
        short(critical.round()),
        short(damping)
    )
}

/// The air damping ζ (1/s) that damps the swing of a cloth hanging `height` (m) critically:
/// drag −ζ·m·v on the hanging chain's first mode (docs/references.md §10),
/// ω = (j₀,₁/2)·√(g/L), is critical at ζ = 2ω = j₀,₁ √(g/L), about 10/s for a 55 cm skirt.
fn critical_swing_damping(height: f64) -> f64 {
    crate::reference::J0_FIRST_ZERO * (crate::physics::STANDARD_GRAVITY / height).sqrt()
}

/// Refuses props that start through the cloth: a vertex inside a prop, or an edge that
/// passes through one. Contact would push such a cloth out violently (or hold it threaded
/// on the prop), a start no laboratory has.
/// A cloth resting on a prop within its contact layer (the Cusick specimen on its
/// pedestal) is not through it: only a vertex deeper than the layer, or an edge between
/// two vertices outside the layer that passes through the prop, is.
pub fn check_start(scene: &Scene) -> Result<(), String> {
    let x = &scene.state.x;
    let layer = scene.config.contact.thickness;
    for (i, prop) in scene.props.iter().enumerate() {
        let distance: Vec<f64> = x.iter().map(|&p| prop.surface_point(p).distance).collect();
        let inside = distance.iter().position(|&d| d < -layer);
        let through = || {
            scene.model.edges.iter().find(|e| {
                let [a, b] = e.map(|v| v as usize);
                distance[a] > layer && distance[b] > layer && prop.segment_entry(x[a], x[b]).is_some()
            })
        };
        let at = match (inside, through()) {
            (Some(v), _) => x[v],
            (None, Some(e)) => 0.5 * (x[e[0] as usize] + x[e[1] as usize]),
            (None, None) => continue,
        };
        return Err(format!(
            "props[{i}] ('{}') starts through the cloth (at [{}, {}, {}] m): move it clear of the cloth (props[{i}].position), \
             or the cloth clear of it (cloth.position)",
            prop.name,
            short(at.x),
            short(at.y),
            short(at.z)
        ));
    }
    Ok(())
}

/// The fewest pixels the cloth may span in a screenshot: fewer, and the picture shows
/// nothing recognisable.
pub const MIN_PICTURE_PIXELS: f64 = 8.0;

/// Refuses a camera distance at which the cloth (its largest extent) would span fewer than
/// [`MIN_PICTURE_PIXELS`] of a picture `height` pixels tall with the vertical field of view
/// `fov_y` (radians).
pub fn check_camera(config: &SceneConfig, distance: f64, height: u32, fov_y: f64) -> Result<(), String> {
    let c = &config.cloth;
    // A garment's cloth is its pattern: its largest panel stands for its extent.
    let garment = config.garment.as_ref().map_or(0.0, |g| g.panels.iter().map(|p| p.extent()).fold(0.0, f64::max) * g.units.metres());
    let size = c.diameter.max(c.length).max(c.width).max(garment);
    let pixels = size / (2.0 * distance * (0.5 * fov_y).tan()) * f64::from(height);
    if pixels < MIN_PICTURE_PIXELS {
        let farthest = size * f64::from(height) / (2.0 * (0.5 * fov_y).tan() * MIN_PICTURE_PIXELS);
        return Err(format!(
            "--camera distance {} m: the {} m cloth would span {:.1} of the picture's {height} pixels; use at most {} m, or leave the distance out to frame the scene",
            short(distance),
            short(size),
            pixels,
            short(farthest)
        ));
    }
    Ok(())
}

/// A shear wrinkle counts only where the sheet stands out of its plane by more than this
/// many times the seeded perturbation (`test.perturbation`, a random lift between 0 and
/// the amplitude): below, the "wrinkles" are the seed's own noise.
pub const WRINKLE_OVER_SEED: f64 = 2.0;

/// Checks a run's measures against what is possible and says in `metrics.notes` what was
/// not measured or not reached; `duration` is the time the run was asked to cover.
pub fn judge(scene: &Scene, metrics: &mut Metrics, duration: f64) {
    let config = &scene.config;
    match &mut metrics.measures {
        Measures::Drape(d) if !(0.0..=1.0).contains(&d.drape_coefficient) => {
            metrics.notes.push(format!(
                "drape_coefficient not measured: the shadow ({:.6} m²) against the specimen ({:.6} m²) and the support \
                 ({:.6} m²) gives {:.6}, outside [0, 1]: the cloth has not draped (it ran {} s{})",
                d.shadow_area,
                d.specimen_area,
                d.support_area,
                d.drape_coefficient,
                short(metrics.simulated_seconds),
                if metrics.settled == Some(false) { ", not settled" } else { "" }
            ));
            d.drape_coefficient = f64::NAN;
        }
        Measures::Garment(g) if g.sewn => {
            if let Some(reason) = off_form(scene) {
                metrics.notes.push(format!("garment measures withheld: {reason}"));
                g.withhold(reason);
            }
        }
        Measures::Shear(s) => {
            let seed = config.test.perturbation.unwrap_or(0.0);
            if s.wrinkle_amplitude <= WRINKLE_OVER_SEED * seed && s.wrinkle_count > 0 {
                metrics.notes.push(format!(
                    "no wrinkles counted: the sheet stands {} m out of its plane, not above {WRINKLE_OVER_SEED} times the seeded \
                     test.perturbation = {} m",
                    short(s.wrinkle_amplitude),
                    short(seed)
                ));
                s.wrinkle_count = 0;
                s.wrinkle_wavelength = 0.0;
                s.wrinkle_angle_deg = f64::NAN;
            }
        }
        _ => {}
    }
    if let (Some(n @ 1..), true) = (metrics.self_intersections, config.contact.self_collision) {
        metrics.notes.push(format!(
            "the cloth ends passing through itself in {n} places though contact.self_collision is on: the folds there are not physical{}",
            if scene.garment.is_some() {
                "; while a garment is sewn, self-collision leaves out the cloth near each seam still open (its two sides must \
                 meet), so panels can pass through each other there: place each panel with its seams facing the sides they \
                 are sewn to, and none lying over another"
            } else {
                ""
            }
        ));
    }
    if let (Some(false), true, None, Some(limit)) = (metrics.settled, metrics.stable, &metrics.stopped_at_limit, config.scene.settle_speed) {
        metrics.notes.push(format!(
            "not settled: at {} s the cloth still moved at {} mm/s RMS (scene.settle_speed = {} mm/s, held for scene.settle_window = {} s), \
             so its measures are of a cloth in motion; run longer (--duration, or scene.duration){}",
            short(scene.state.time),
            short(1e3 * scene.rms_speed()),
            short(1e3 * limit),
            short(config.scene.settle_window),
            swing_damping_hint(scene)
        ));
    }
    let end = scene.state.time;
    // The time is a sum of steps: a run to a motion's end may fall short of it by round-off.
    let unfinished = !scene.model.motions_finished(end * (1.0 + 1e-9) + 1e-12);
    if unfinished && metrics.stable && let Some(motion) = super::kinds::of(config.scene.kind).motion_time(config) {
        metrics.notes.push(format!(
            "{} not reached: the run covered {} s of the {} s its motion takes (asked for {} s)",
            motion.key,
            short(end),
            short(motion.seconds),
            short(duration)
        ));
    }
}

/// How far the garment's top may end under the height it is held at before it has slid
/// off its form, m (a skirt settles a few centimetres at most), and how deep inside the
/// form, in contact layers, a garment may end before it is not on the form but in it.
const SLIP: f64 = 0.1;
const INSIDE_LAYERS: f64 = 3.0;

/// Why a sewn garment is not hanging on its form, if it is not: fallen below the floor,
/// slid down from where it is held, or ended inside the form deeper than its contact
/// layer allows. A garment's measures are those of a garment on its form; anything else
/// is said, not measured.
pub fn off_form(scene: &Scene) -> Option<String> {
    let rig = scene.rig.as_any().downcast_ref::<super::garment::rig::GarmentRig>()?;
    let x = &scene.state.x;
    let (low, high) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.z), hi.max(p.z)));
    let layer = scene.config.contact.thickness;
    if low < -(2.0 * layer).max(0.01) {
        return Some(format!("the garment fell off its form: its lowest point ends {} m below the floor", short(-low)));
    }
    let held = rig.support_height();
    if high < held - SLIP {
        return Some(format!(
            "the garment slid off its form: its top ends {} cm under the height it is held at ({} m); a pattern wider than the form \
             where it is held (the waist or the hips) slides down: take it in, or hold it there ([[garment.attachments]])",
            short(100.0 * (held - high)),
            short(held)
        ));
    }
    let form = scene.props.first()?;
    let deepest = x.iter().map(|&p| -form.surface_point(p).distance).fold(0.0, f64::max);
    (deepest > INSIDE_LAYERS * layer).then(|| {
        format!(
            "the garment ends {} mm inside its form, {} times its contact layer (contact.thickness = {} mm): the form does not \
             hold it; thicken the layer or shorten the step (solver.dt)",
            short(1e3 * deepest),
            short(deepest / layer),
            short(1e3 * layer)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A garment's metrics after one step, with `count` crossings put in their place (a
    /// real crossing needs a long run; `a_crossed_arrangement_is_refused_before_the_run`
    /// covers the start) and the notes judged again.
    fn notes_with_crossings(self_collision: bool, count: usize) -> Vec<String> {
        notes_after_a_step(&[format!("contact.self_collision={self_collision}")], count)
    }

    /// The notes of the coarse straight skirt (with `overrides`) after one step, judged
    /// as if it had ended with `count` self-intersections.
    fn notes_after_a_step(overrides: &[String], count: usize) -> Vec<String> {
        let overrides: Vec<String> = std::iter::once("mesh.edge_length=0.05".to_string()).chain(overrides.iter().cloned()).collect();
        let (config, _) = crate::scene::load_scene("skirt-gored-straight", &overrides).unwrap();
        let mut scene = Scene::build(config).unwrap();
        let (mut metrics, _) = crate::scene::run_scene(&mut scene, "crossed", crate::scene::RunOptions { duration: Some(0.004), ..Default::default() });
        metrics.self_intersections = Some(count);
        metrics.notes.clear();
        judge(&scene, &mut metrics, 0.004);
        metrics.notes
    }

    /// A 55 cm skirt's swing: the hanging chain's first mode, ω = (2.404826/2)·√(9.80665/0.55)
    /// = 5.0773 rad/s, damped critically by drag ζ = 2ω = 10.155/s (worked by hand).
    #[test]
    fn a_hanging_cloths_swing_is_damped_critically_at_twice_its_frequency() {
        assert!((critical_swing_damping(0.55) - 10.155).abs() < 1e-3, "{}", critical_swing_damping(0.55));
    }

    /// A cloth that ends through itself with self-collision on is said to, and for a
    /// garment the note says how sewing lets panels cross; with self-collision off
    /// crossing is what was asked for, and nothing is said.
    #[test]
    fn a_cloth_ending_through_itself_is_noted() {
        let notes = notes_with_crossings(true, 3);
        let note = notes.iter().find(|n| n.contains("passing through itself in 3 places")).unwrap_or_else(|| panic!("{notes:?}"));
        assert!(note.contains("near each seam still open"), "{note}");
        assert!(notes_with_crossings(true, 0).iter().all(|n| !n.contains("through itself")));
        assert!(notes_with_crossings(false, 3).iter().all(|n| !n.contains("through itself")));
    }

    /// A run that ends before the cloth settles says so, with the speed it still had and
    /// the key that sets the limit; a scene that does not watch settling says nothing.
    #[test]
    fn a_run_that_ends_unsettled_says_so() {
        let notes = notes_with_crossings(true, 0);
        let note = notes.iter().find(|n| n.starts_with("not settled")).unwrap_or_else(|| panic!("{notes:?}"));
        assert!(note.contains("scene.settle_speed = 1 mm/s") && note.contains("--duration"), "{note}");
        // The skirt hangs from the form at its bundled 4/s, under half of what damps its
        // swing critically.
        assert!(note.contains("solver.damping = ") && note.contains("(it is 4 1/s"), "{note}");
        // Past critical damping (about 10/s for its 53 cm) nothing more is suggested.
        let damped = notes_after_a_step(&["solver.damping=30".to_string()], 0);
        let note = damped.iter().find(|n| n.starts_with("not settled")).unwrap_or_else(|| panic!("{damped:?}"));
        assert!(!note.contains("solver.damping"), "{note}");
        let (config, _) = crate::scene::load_scene("tensile-warp", &[]).unwrap();
        let mut scene = Scene::build(config).unwrap();
        let (metrics, _) = crate::scene::run_scene(&mut scene, "tensile", crate::scene::RunOptions { duration: Some(0.002), ..Default::default() });
        assert!(metrics.settled.is_none() && metrics.notes.iter().all(|n| !n.starts_with("not settled")), "{:?}", metrics.notes);
    }

    /// A garment's cloth is its pattern: a camera 1.2 m from a skirt frames it (the
    /// largest gore, about 0.6 m, spans hundreds of pixels), one 1 km away does not.
    /// Before the pattern counted, every distance was refused for every garment.
    #[test]
    fn a_garment_is_framed_by_its_pattern() {
        let (config, _) = crate::scene::load_scene("skirt-gored-bias", &[]).unwrap();
        let fov = 40f64.to_radians();
        check_camera(&config, 1.2, 800, fov).unwrap();
        let refused = check_camera(&config, 1000.0, 800, fov).unwrap_err();
        assert!(refused.contains("would span"), "{refused}");
    }
}
