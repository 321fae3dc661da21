//! The viewer's solver thread: bit-for-bit determinism against the headless path, and what
//! each command does to the running scene.

use glam::DVec3;
use rosette::app::worker::{Command, Snapshot, Worker};
use rosette::scene::{RunOptions, Scene, SceneConfig, load_scene, run_scene};
use rosette::sim::IntegratorKind;
use std::sync::Arc;
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(120);

fn preset(name: &str) -> SceneConfig {
    load_scene(name, &[]).unwrap_or_else(|e| panic!("{name}: {e}")).0.into_config()
}

fn spawn(name: &str, config: SceneConfig) -> Worker {
    let checked = rosette::scene::check::checked(config).unwrap_or_else(|e| panic!("{name}: {}", e.message));
    Worker::spawn(name, checked, None).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn bits(x: &[DVec3]) -> Vec<[u64; 3]> {
    x.iter().map(|p| p.to_array().map(f64::to_bits)).collect()
}

/// The same scene stepped directly with `Scene::step`.
fn stepped_directly(config: SceneConfig, steps: u64) -> Vec<DVec3> {
    let mut scene = Scene::new(config).unwrap();
    for _ in 0..steps {
        scene.step().unwrap();
    }
    scene.state.x
}

#[test]
fn worker_steps_match_direct_steps_bit_for_bit() {
    // Euler buckling starts from a seeded random perturbation and buckles through several
    // modes: any difference in operation order would show within a few steps.
    let config = preset("euler-buckling");
    let n = 60;
    let worker = spawn("euler-buckling", config.clone());
    for _ in 0..n {
        worker.send(Command::Step);
    }
    let snapshot = worker.sync(WAIT);
    assert_eq!(snapshot.steps, n);
    assert!(snapshot.error.is_none(), "{:?}", snapshot.error);
    let direct = stepped_directly(config.clone(), n);
    assert_eq!(bits(&snapshot.positions), bits(&direct), "worker and Scene::step differ");

    // And against the headless runner (`rosette run`) over the same simulated time.
    let mut scene = Scene::new(config).unwrap();
    let duration = Some(n as f64 * scene.integrator.dt);
    let (metrics, error) = run_scene(&mut scene, "euler-buckling", RunOptions { duration, ..Default::default() });
    assert!(error.is_none());
    assert_eq!(metrics.steps, n);
    assert_eq!(bits(&snapshot.positions), bits(&scene.state.x), "worker and run_scene differ");
}

#[test]
fn playing_paced_then_paused_matches_direct_steps() {
    // Free play goes through the paced loop; wherever it stops, the state is the one the
    // same number of direct steps gives.
    let config = preset("euler-buckling");
    let worker = spawn("euler-buckling", config.clone());
    worker.send(Command::Play);
    let playing = worker.wait_for(WAIT, |s| s.steps >= 25);
    assert!(playing.playing);
    worker.send(Command::Pause);
    let paused = worker.sync(WAIT);
    assert!(!paused.playing);
    let direct = stepped_directly(config, paused.steps);
    assert_eq!(bits(&paused.positions), bits(&direct));
    // Paused means no further steps.
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(worker.latest().steps, paused.steps);
}

#[test]
fn pacing_follows_wall_time_when_the_solver_is_faster() {
    // The tensile preset steps at 20 ms and costs well under that: play is paced, so after
    // about 0.3 s of wall time about 0.3 s is simulated, not the whole 6 s pull.
    let worker = spawn("tensile-warp", preset("tensile-warp"));
    worker.send(Command::Play);
    worker.sync(WAIT);
    std::thread::sleep(Duration::from_millis(300));
    let snapshot = worker.latest();
    assert!(snapshot.time > 0.05 && snapshot.time < 1.5, "simulated {} s in 0.3 s of wall time", snapshot.time);
    assert!(snapshot.stats.steps_per_second > 0.0);
}

#[test]
fn step_and_reset() {
    let config = preset("cantilever");
    let dt = config.solver.dt;
    let worker = spawn("cantilever", config);
    let start = worker.latest();
    assert_eq!((start.steps, start.time, start.playing), (0, 0.0, false));
    assert_eq!(start.positions.len(), start.stats.vertices);
    assert_eq!(start.topology.triangles.len(), start.stats.triangles);
    assert!(start.topology.fits(&start.positions));
    for _ in 0..3 {
        worker.send(Command::Step);
    }
    let stepped = worker.sync(WAIT);
    assert_eq!(stepped.steps, 3);
    assert!((stepped.time - 3.0 * dt).abs() < 1e-12);
    assert_ne!(bits(&stepped.positions), bits(&start.positions), "gravity moved the cloth");
    worker.send(Command::Reset);
    let reset = worker.sync(WAIT);
    assert_eq!((reset.steps, reset.time), (0, 0.0));
    assert_eq!(bits(&reset.positions), bits(&start.positions));
    assert!(reset.scene_generation > start.scene_generation);
}

#[test]
fn scene_stops_at_its_duration() {
    let mut config = preset("tensile-warp");
    config.scene.duration = 5.0 * config.solver.dt;
    // A pull the shorter run can finish: the checks refuse one it would stop short of.
    config.test.max_strain = Some(config.test.speed.unwrap() * config.scene.duration / config.cloth.length);
    let worker = spawn("tensile-warp", config);
    worker.send(Command::Play);
    let done = worker.wait_for(WAIT, |s| s.finished);
    assert!(done.finished && !done.playing);
    assert_eq!(done.steps, 5);
    let stress_strain = &done.measures.tensile().expect("tensile measures").stress_strain;
    assert!(!stress_strain.is_empty());
}

#[test]
fn a_settled_cloth_pauses_where_the_headless_run_stops() {
    // The cantilever settles about 1.3 s into its 3 s: play pauses there, at the step where
    // `rosette run` stops, instead of stepping a resting strip to the end.
    let config = preset("cantilever");
    let worker = spawn("cantilever", config.clone());
    worker.send(Command::Play);
    let done = worker.wait_for(WAIT, |s| s.finished);
    assert!(!done.playing);
    let settled_at = done.settled_at.expect("the strip settles");
    assert!(done.time < config.scene.duration - 0.5, "paused at {} s of {}", done.time, config.scene.duration);
    let mut scene = Scene::new(config).unwrap();
    let (metrics, error) = run_scene(&mut scene, "cantilever", RunOptions::default());
    assert!(error.is_none());
    assert_eq!((metrics.settle_time, metrics.steps), (Some(settled_at), done.steps));
    assert_eq!(bits(&done.positions), bits(&scene.state.x), "worker and run_scene differ");
    // Play again runs on past the settling, to the scene's end.
    worker.send(Command::Play);
    let resumed = worker.wait_for(WAIT, |s| s.steps > done.steps + 5);
    assert!(resumed.playing && resumed.settled_at == Some(settled_at));
}

#[test]
fn solver_change_keeps_the_state() {
    let worker = spawn("cantilever", preset("cantilever"));
    for _ in 0..4 {
        worker.send(Command::Step);
    }
    let before = worker.sync(WAIT);
    worker.send(Command::SetSolver { dt: 0.001, integrator: IntegratorKind::Bdf2 });
    let after = worker.sync(WAIT);
    assert_eq!(bits(&after.positions), bits(&before.positions));
    assert_eq!((after.time, after.steps), (before.time, before.steps));
    assert_eq!(after.config.solver.integrator, IntegratorKind::Bdf2);
    worker.send(Command::Step);
    let stepped = worker.sync(WAIT);
    assert!((stepped.time - before.time - 0.001).abs() < 1e-12);
    worker.send(Command::SetSolver { dt: -1.0, integrator: IntegratorKind::Bdf2 });
    assert!(worker.sync(WAIT).error.as_deref().is_some_and(|e| e.contains("solver.dt")));
}

/// Regression: the viewer's solver change rebuilt the integrator by hand and dropped the
/// scene's adaptive step control (and `max_stretch` and the contact statistics with it).
/// With adaptive steps on, three steps from a new Δt no longer add up to three times it.
#[test]
fn solver_change_keeps_adaptive_steps() {
    let (config, _) = load_scene("cantilever", &["solver.adaptive.tolerance=1e-3".into()]).unwrap();
    assert!(config.solver.adaptive.is_some_and(|a| a.enabled));
    let worker = spawn("cantilever", config.into_config());
    worker.send(Command::Step);
    let before = worker.sync(WAIT);
    worker.send(Command::SetSolver { dt: 0.002, integrator: IntegratorKind::ImplicitEuler });
    for _ in 0..3 {
        worker.send(Command::Step);
    }
    let after = worker.sync(WAIT);
    assert_eq!(after.steps, before.steps + 3);
    let fixed = before.time + 3.0 * 0.002;
    assert!((after.time - fixed).abs() > 1e-9, "the steps kept Δt fixed at 0.002 s: adaptive steps were dropped");
    assert!(after.config.solver.adaptive.is_some());
}

#[test]
fn fabric_change_restarts_and_a_bad_fabric_is_reported() {
    let worker = spawn("cantilever", preset("cantilever"));
    worker.send(Command::Step);
    let before = worker.sync(WAIT);
    let mut fabric = before.config.fabric.clone();
    fabric.properties.areal_density = -1.0;
    worker.send(Command::SetFabric(Box::new(fabric.clone())));
    let rejected = worker.sync(WAIT);
    let error = rejected.error.clone().expect("a negative density is rejected");
    assert!(error.contains("areal_density"), "{error}");
    assert_eq!(rejected.steps, 1, "the running scene is kept");
    fabric.properties.areal_density = 0.3;
    worker.send(Command::SetFabric(Box::new(fabric)));
    let applied = worker.sync(WAIT);
    assert!(applied.error.is_none());
    assert_eq!(applied.steps, 0, "the scene restarts with the new fabric");
    assert_eq!(applied.config.fabric.properties.areal_density, 0.3);
}

#[test]
fn run_test_measures_the_current_fabric() {
    let mut config = preset("cantilever");
    config.fabric.name = "designer's fabric".into();
    let worker = spawn("cantilever", config);
    worker.send(Command::RunTest("tensile-weft".into()));
    let snapshot = worker.sync(WAIT);
    assert_eq!(snapshot.scene_name, "tensile-weft");
    assert!(snapshot.playing);
    assert_eq!(snapshot.config.fabric.name, "designer's fabric");
    assert_eq!(snapshot.config.cloth.warp_angle_deg, 90.0, "the test's own geometry");
    worker.send(Command::RunTest("no-such-test".into()));
    assert!(worker.sync(WAIT).error.as_deref().is_some_and(|e| e.contains("tensile-warp")), "lists the tests");
}

#[test]
fn dragged_vertex_follows_the_target_and_is_released() {
    let worker = spawn("cantilever", preset("cantilever"));
    let start = worker.latest();
    // The free corner farthest from the clamp.
    let tip = (0..start.positions.len()).max_by(|&a, &b| start.positions[a].x.total_cmp(&start.positions[b].x)).unwrap() as u32;
    let target = start.positions[tip as usize] + DVec3::new(0.0, 0.0, 0.01);
    worker.send(Command::DragVertex { vertex: tip, mesh: start.topology.version, target });
    for _ in 0..40 {
        worker.send(Command::Step);
    }
    let held = worker.sync(WAIT);
    assert_eq!(held.dragged, Some(tip));
    assert!(held.fixed[tip as usize]);
    assert!((held.positions[tip as usize] - target).length() < 1e-12, "{:?} vs {target:?}", held.positions[tip as usize]);
    worker.send(Command::ReleaseDrag);
    for _ in 0..5 {
        worker.send(Command::Step);
    }
    let released = worker.sync(WAIT);
    assert_eq!(released.dragged, None);
    assert!(!released.fixed[tip as usize]);
    assert!(released.positions[tip as usize].z < target.z, "gravity takes it back down");
    // A clamped vertex is not taken from its clamp.
    let clamped = start.fixed.iter().position(|&f| f).unwrap() as u32;
    worker.send(Command::DragVertex { vertex: clamped, mesh: start.topology.version, target: DVec3::ONE });
    worker.send(Command::Step);
    let snapshot = worker.sync(WAIT);
    assert_eq!(snapshot.dragged, None);
    assert_eq!(snapshot.positions[clamped as usize], start.positions[clamped as usize]);
}

#[test]
fn diverged_step_keeps_the_last_good_state() {
    let mut config = preset("tensile-warp");
    config.solver.integrator = IntegratorKind::SymplecticEuler;
    config.solver.dt = 0.02;
    let worker = spawn("tensile-warp", config);
    worker.send(Command::Play);
    let failed = worker.wait_for(WAIT, |s| s.error.is_some());
    let error = failed.error.clone().unwrap();
    assert!(error.contains("diverged"), "{error}");
    assert!(!failed.playing);
    assert!(failed.positions.iter().all(|p| p.is_finite()));
    // The thread keeps serving commands.
    worker.send(Command::Reset);
    let reset: Arc<Snapshot> = worker.sync(WAIT);
    assert_eq!(reset.steps, 0);
}

/// The viewer's stats on a scene whose steps run on rayon's pool (4 096 triangles and up)
/// showed 0.012 ms "CPU per 10 ms simulated" beside a real-time factor of 0.24: the CPU
/// time was the worker thread's own, which waits while the pool works. Both figures now
/// come from one clock, so that playing flat out (the steps slower than real time) they
/// agree: the steps fill most of the window, and never more than all of it.
#[test]
fn step_time_and_real_time_factor_come_from_one_clock() {
    let mut config = preset("cusick-drape");
    config.mesh.edge_length = 0.0065;
    let worker = spawn("cusick-drape", config);
    assert!(worker.latest().stats.triangles >= 4096, "{} triangles: the steps would not run on the pool", worker.latest().stats.triangles);
    worker.send(Command::Play);
    let playing = worker.wait_for(WAIT, |s| s.steps >= 12);
    let s = playing.stats;
    assert!(s.real_time_factor > 0.0 && s.step_ms_per_10ms > 0.0, "{s:?}");
    // The share of the window the steps took: at most 1, and most of it when the solver is
    // slower than real time (the worker then steps back to back).
    let busy = s.real_time_factor * s.step_ms_per_10ms / 10.0;
    assert!(busy <= 1.0 + 1e-9, "the steps took {busy} of the window: {s:?}");
    if s.real_time_factor < 0.9 {
        assert!(busy > 0.5, "playing flat out, the steps took only {busy} of the window: {s:?}");
    }
    worker.send(Command::Pause);
}

/// The viewer died at the first frame after a garment's seams welded: the weld merges
/// the seams' vertices, the triangles keep their count, and the snapshots went on carrying
/// the unwelded mesh's triangles. Every snapshot of a garment stepped through its weld
/// carries the mesh its positions belong to, and the frame drawn from it is whole; a vertex
/// the mouse held across the weld is held at its merged vertex, and let go after it, it is
/// not left pinned.
#[test]
fn a_garment_welds_under_the_worker_and_every_snapshot_fits_its_mesh() {
    let mut config = load_scene("skirt-gored-bias", &["mesh.edge_length=0.035".into()]).unwrap().0.into_config();
    config.solver.path = rosette::settings::SolverPath::Fast;
    let worker = spawn("skirt-gored-bias", config);
    let start = worker.latest();
    // A free vertex on a seam line's side, held still by the mouse while the seams close.
    let held = (0..start.positions.len()).find(|&v| !start.fixed[v]).unwrap() as u32;
    worker.send(Command::DragVertex { vertex: held, mesh: start.topology.version, target: start.positions[held as usize] });
    let mut welded = None;
    for _ in 0..400 {
        worker.send(Command::Step);
        let snapshot = worker.sync(WAIT);
        assert!(snapshot.error.is_none(), "{:?}", snapshot.error);
        assert!(snapshot.topology.fits(&snapshot.positions), "{} positions for a mesh of {}", snapshot.positions.len(), snapshot.topology.vertex_count);
        assert_eq!(snapshot.fixed.len(), snapshot.positions.len());
        let topology = &snapshot.topology;
        let frame = rosette::render::Frame::from_cloth(&snapshot.positions, &topology.triangles, &topology.texture, topology.warp_angle);
        assert!(frame.cloth_is_whole());
        if snapshot.sewing.is_some_and(|s| s.sewn_at.is_some()) {
            welded = Some(snapshot);
            break;
        }
    }
    let welded = welded.expect("the skirt is sewn within 400 steps");
    assert!(welded.positions.len() < start.positions.len(), "the weld merged vertices");
    assert_ne!(welded.topology.version, start.topology.version);
    let (from, map) = welded.topology.merged_from.as_ref().expect("a weld says where its vertices came from");
    assert_eq!(*from, start.topology.version);
    let merged = map[held as usize];
    assert_eq!(welded.dragged, Some(merged), "the mouse holds the merged vertex");
    worker.send(Command::ReleaseDrag);
    worker.send(Command::Step);
    let released = worker.sync(WAIT);
    assert_eq!(released.dragged, None);
    assert!(!released.fixed[merged as usize], "the weld does not keep the mouse's hold as a pin");
    // A drag picked on the unwelded mesh is carried; one on an unrelated mesh is dropped.
    worker.send(Command::DragVertex { vertex: held, mesh: start.topology.version, target: released.positions[merged as usize] });
    worker.send(Command::Step);
    assert_eq!(worker.sync(WAIT).dragged, Some(merged));
    worker.send(Command::DragVertex { vertex: 0, mesh: u64::MAX, target: DVec3::ZERO });
    worker.send(Command::Step);
    assert_eq!(worker.sync(WAIT).dragged, None, "an index from a mesh the cloth no longer has names nothing");
}

/// A new fabric or new grains on a sewn garment re-drape it where it hangs: the same mesh,
/// the same positions to start from, the clock going on; a scene opened afresh sews from
/// flat panels.
#[test]
fn a_sewn_garment_re_drapes_in_a_new_fabric_and_grain() {
    let mut config = load_scene("skirt-gored-bias", &["mesh.edge_length=0.035".into()]).unwrap().0.into_config();
    config.solver.path = rosette::settings::SolverPath::Fast;
    let worker = spawn("skirt-gored-bias", config.clone());
    let mut sewn = None;
    for _ in 0..400 {
        worker.send(Command::Step);
        let snapshot = worker.sync(WAIT);
        if snapshot.sewing.is_some_and(|s| s.sewn_at.is_some()) {
            sewn = Some(snapshot);
            break;
        }
    }
    let sewn = sewn.expect("sewn within 400 steps");
    let mut silk = sewn.config.fabric.clone();
    silk.properties.areal_density *= 0.5;
    silk.name = "lighter".into();
    worker.send(Command::SetFabric(Box::new(silk)));
    let refabric = worker.sync(WAIT);
    assert!(refabric.error.is_none(), "{:?}", refabric.error);
    assert!(refabric.drape.from_sewn);
    assert_eq!(refabric.topology.version, sewn.topology.version, "the same mesh and texture: the same topology");
    assert_eq!(bits(&refabric.positions), bits(&sewn.positions), "it starts where it hung");
    assert_eq!(refabric.time, sewn.time);
    assert!(refabric.sewing.unwrap().sewn_at.is_some());
    // Other grains: the same mesh, its texture turned, the vertices' indices kept.
    worker.send(Command::SetGrains(vec![90.0; 4]));
    let regrained = worker.sync(WAIT);
    assert!(regrained.drape.from_sewn);
    assert_eq!(regrained.positions.len(), sewn.positions.len());
    assert_ne!(regrained.topology.version, sewn.topology.version);
    assert_eq!(regrained.topology.merged_from.as_ref().unwrap().0, refabric.topology.version);
    // An edit the checks refuse (a grain beyond a full turn) is refused with their message,
    // and the garment goes on as it was.
    worker.send(Command::SetGrains(vec![1000.0; 4]));
    let refused = worker.sync(WAIT);
    let error = refused.error.clone().expect("a grain of 1000° is refused");
    assert!(error.contains("grains not applied") && error.contains("grain_deg"), "{error}");
    assert_eq!(refused.topology.version, regrained.topology.version, "the running garment stays");
    worker.send(Command::LoadEdited { name: "skirt".into(), config: Box::new(config) });
    worker.send(Command::Step);
    let reloaded = worker.sync(WAIT);
    assert!(!reloaded.drape.from_sewn);
    assert!(reloaded.sewing.unwrap().sewn_at.is_none(), "a scene opened afresh sews from flat panels");
}

#[test]
fn a_hold_pauses_at_the_first_step_that_reaches_its_time_and_play_goes_on_from_there() {
    // What a script's wait for simulated time does: the scene stands at that moment for the
    // steps after it, and plays on from it when asked.
    let config = preset("cantilever");
    let dt = config.solver.dt;
    let worker = spawn("cantilever", config);
    let hold = 0.1;
    worker.send(Command::HoldAt(hold));
    let held = worker.wait_for(WAIT, |s| !s.playing && s.steps > 0);
    assert!(held.time >= hold - 1e-9 && held.time < hold + dt - 1e-9, "held at {} s for {hold} s with steps of {dt} s", held.time);
    assert_eq!(held.steps, (hold / dt - 1e-6).ceil() as u64);
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(worker.sync(WAIT).steps, held.steps, "a held scene stays where it stopped");
    // A hold at a time already reached leaves the scene where it is.
    worker.send(Command::HoldAt(0.5 * hold));
    let same = worker.sync(WAIT);
    assert_eq!((same.steps, same.playing), (held.steps, false));
    worker.send(Command::Play);
    let resumed = worker.wait_for(WAIT, |s| s.steps > held.steps + 3);
    assert!(resumed.playing && resumed.time > held.time);
}
