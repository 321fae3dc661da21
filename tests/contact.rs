//! Contact with props and with itself: no tunnelling at any stable step size, no passing
//! through a sharp edge, Coulomb friction against the inclined-plane law, and folds that
//! never cross.

use glam::DVec3;
use rosette::scene::{RunOptions, Scene, load_scene, run_scene};
use rosette::sim::Motion;

fn build(preset: &str, overrides: &[String]) -> Scene {
    let (config, _) = load_scene(preset, overrides).unwrap_or_else(|e| panic!("{e}"));
    Scene::build(config).unwrap_or_else(|e| panic!("{e}"))
}

fn strings(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// A 0.3 m cotton square dropped from 1 m onto a 2 mm plate: at impact it moves at 4.4 m/s,
/// 4.4 cm per 10 ms step, twenty times the plate's thickness. Each integrator runs at a
/// step it is stable at: the implicit ones at 10 ms, the explicit one at half its limit.
#[test]
fn a_fast_fall_onto_a_thin_plate_does_not_tunnel() {
    let base = strings(&[
        "cloth.length=0.3",
        "cloth.width=0.3",
        "cloth.position=[0.0, 0.0, 1.0]",
        "mesh.edge_length=0.02",
        "contact.self_collision=false",
        "test.support_size=[0.05, 0.05]", // read only by the drape coefficient, which this test does not use
        "props=[{shape = 'box', size = [0.4, 0.4, 0.002], position = [0.0, 0.0, -0.001]}]",
        "scene.duration=0.8",
        "scene.settle_speed=1e-9",
        // No air drag: it lands at full speed.
        "solver.damping=0",
    ]);
    for integrator in ["implicit-euler", "bdf2", "symplectic-euler"] {
        let mut overrides = base.clone();
        overrides.push(format!("solver.integrator={integrator}"));
        let probe = build("tablecloth", &overrides);
        let dt = if integrator == "symplectic-euler" { 0.5 * probe.model.explicit_step_limit(&probe.state.x) } else { 0.01 };
        overrides.push(format!("solver.dt={dt}"));
        let mut scene = build("tablecloth", &overrides);
        let (metrics, error) = run_scene(&mut scene, "fall", RunOptions::default());
        assert!(error.is_none(), "{integrator}: {error:?}");
        let thickness = scene.config.contact.thickness;
        let penetration = metrics.max_penetration.unwrap();
        assert!(penetration < 0.1 * thickness, "{integrator} at dt = {dt:.2e}: {penetration} m inside the plate");
        // All of the cloth is above the plate's top or hangs beside it, none below it
        // inside the plate's footprint.
        let below = scene.state.x.iter().filter(|p| p.x.abs() < 0.2 && p.y.abs() < 0.2 && p.z < 0.0).count();
        assert_eq!(below, 0, "{integrator}: {below} vertices went through the plate");
        // And it did land: the centre rests on the plate's surface layer.
        let centre = scene.state.x.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(centre < 2.0 * thickness, "{integrator}: lowest vertex at {centre} m, never landed");
    }
}

/// A strip lying on a box, its free end pulled down past the box's sharp edge at 0.5 m/s:
/// the cloth wraps the 90° edge under tension and must stay outside the box.
#[test]
fn a_cloth_pulled_over_a_sharp_edge_stays_outside() {
    for integrator in ["implicit-euler", "bdf2"] {
        let overrides = strings(&[
            &format!("solver.integrator={integrator}"),
            "cloth.length=0.4",
            "cloth.width=0.1",
            "cloth.position=[0.0, 0.0, 0.002]",
            "mesh.edge_length=0.01",
            "contact.self_collision=false",
            "test.support_size=[0.05, 0.05]", // read only by the drape coefficient, which this test does not use
            "test.perturbation=0.0",
            "props=[{shape = 'box', size = [0.3, 0.3, 0.1], position = [-0.05, 0.0, -0.05]}]",
            "scene.duration=0.5",
            "scene.settle_speed=1e-9",
        ]);
        let mut scene = build("tablecloth", &overrides);
        let x = scene.state.x.clone();
        let end: Vec<u32> = (0..x.len() as u32).filter(|&v| x[v as usize].x > 0.2 - 1e-9).collect();
        assert!(!end.is_empty());
        scene.model.drive(&end, &x, Motion::Linear { velocity: DVec3::new(0.0, 0.0, -0.5), start: 0.0, stop: 0.5 });
        let (metrics, error) = run_scene(&mut scene, "edge", RunOptions::default());
        assert!(error.is_none(), "{integrator}: {error:?}");
        let thickness = scene.config.contact.thickness;
        let penetration = metrics.max_penetration.unwrap();
        assert!(penetration < 0.1 * thickness, "{integrator}: {penetration} m inside the box");
        // The strip really was pulled over the edge: its end is 25 cm below the top.
        let lowest = scene.state.x.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(lowest < -0.2, "{integrator}: the end only reached {lowest} m");
        // Every vertex over the box's footprint is on or above its top.
        let inside = scene.state.x.iter().filter(|p| p.x < 0.1 - 1e-3 && p.z < -1e-4 && p.y.abs() < 0.15).count();
        assert_eq!(inside, 0, "{integrator}: {inside} vertices inside the box");
    }
}

/// A 1 m strip hung by its middle over a 1 cm square rod: each half hangs 0.5 m, and the
/// rod's two top edges turn the strip's tension T = ρ·w·L·g through 90°, pressing on the
/// vertex row at each edge with √2·T, √2·L/e = 71 times the row's own weight (1 cm
/// edges). With a soft penalty (c = 10 at 10 ms steps, k = c·m/Δt²) that load alone would
/// hold those vertices (√2·L/e)·g·Δt²/c = 6.9 mm deep into a 2 mm layer, 4.9 mm inside
/// the rod. Past the surface the penalty stiffens (`SURFACE_STIFFENING`): they stay
/// within a tenth of the layer of it.
#[test]
fn a_strip_hung_over_a_rod_stays_outside_it() {
    let (dt, stiffness, hanging, edge) = (0.01, 10.0, 0.5, 0.01);
    let overrides = strings(&[
        "cloth.length=1.0",
        "cloth.width=0.04",
        "cloth.position=[0.0, 0.0, 0.003]",
        &format!("mesh.edge_length={edge}"),
        &format!("solver.dt={dt}"),
        &format!("contact.stiffness={stiffness}"),
        "contact.self_collision=false",
        "test.perturbation=0.0",
        "test.support_size=[0.02, 0.02]", // read only by the drape coefficient, which this test does not use
        "props=[{shape = 'box', size = [0.01, 0.2, 0.01], position = [0.0, 0.0, -0.005]}]",
        "scene.duration=2.0",
        "scene.settle_speed=1e-9",
    ]);
    let mut scene = build("tablecloth", &overrides);
    let thickness = scene.config.contact.thickness;
    let g = rosette::physics::STANDARD_GRAVITY;
    let layer_alone = std::f64::consts::SQRT_2 * hanging / edge * g * dt * dt / stiffness - thickness;
    assert!(layer_alone > thickness, "the test needs a load that would take the layer's penalty past the surface: {layer_alone} m");
    let (metrics, error) = run_scene(&mut scene, "rod", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    let penetration = metrics.max_penetration.unwrap();
    assert!(penetration < 0.1 * thickness, "{penetration} m inside the rod (the layer's penalty alone: {layer_alone} m)");
    // It hangs on the rod: both ends near 0.5 m below it, none fallen off.
    let x = &scene.state.x;
    for side in [-1.0, 1.0] {
        let lowest = x.iter().filter(|p| p.x * side > 0.0).map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(lowest < -0.4 && lowest > -0.6, "the {side} half's end is at {lowest} m");
    }
}

/// A strip sliding without friction down one side of a V-shaped valley (a closed OBJ mesh
/// prop, sides at ±26.6°) and up the other, through its crease and back, at 24 ms steps:
/// each step moves a vertex up to 4 cm, and a vertex whose contact plane is the slope it
/// started on ends the step past the crease, below the far slope's surface, unless that
/// plane is renewed where it ended (without the renewal it went 11 mm into the valley).
/// The contact model holds every vertex outside the prop at any step size.
#[test]
fn a_strip_sliding_through_a_valley_stays_outside_it() {
    // The valley's cross-section in (x, z), extruded along y from −0.2 to 0.2 m: its top
    // runs from (−0.3, 0.15) down to the crease at the origin and up to (0.3, 0.15).
    let section = [(-0.3, 0.15), (0.0, 0.0), (0.3, 0.15), (0.3, -0.1), (-0.3, -0.1)];
    let mut obj = String::new();
    for y in [-0.2, 0.2] {
        for (x, z) in section {
            obj += &format!("v {x} {y} {z}\n");
        }
    }
    // End caps (the section's points are clockwise in (x, z), so these face out), then the
    // five sides.
    let mut faces: Vec<[usize; 3]> = Vec::new();
    for [a, b, c] in [[5, 4, 2], [5, 2, 1], [4, 3, 2]] {
        faces.push([a, b, c]);
        faces.push([c + 5, b + 5, a + 5]);
    }
    for a in 1..=5 {
        let b = a % 5 + 1;
        faces.push([a, b, b + 5]);
        faces.push([a, b + 5, a + 5]);
    }
    for [a, b, c] in faces {
        obj += &format!("f {a} {b} {c}\n");
    }
    let file = std::env::temp_dir().join(format!("rosette-valley-{}.obj", std::process::id()));
    std::fs::write(&file, obj).unwrap();
    let overrides = strings(&[
        "cloth.length=0.06",
        "cloth.width=0.03",
        "cloth.position=[-0.15, 0.0, 0.105]",
        "mesh.edge_length=0.01",
        "contact.self_collision=false",
        "contact.friction_static=0.0",
        "contact.friction_kinetic=0.0",
        "solver.damping=0",
        "solver.dt=0.024",
        "test.perturbation=0.0",
        "test.support_size=[0.02, 0.02]", // read only by the drape coefficient, which this test does not use
        &format!("props=[{{shape = 'mesh', file = '{}'}}]", file.display()),
        "scene.duration=1.5",
        "scene.settle_speed=1e-9",
    ]);
    let mut scene = build("tablecloth", &overrides);
    let thickness = scene.config.contact.thickness;
    let mut crossings = 0;
    let mut side = -1.0;
    let mut deepest = 0.0f64;
    while scene.state.time < 1.5 - 1e-9 {
        scene.step().unwrap_or_else(|e| panic!("{e}"));
        let centre = scene.state.x.iter().map(|p| p.x).sum::<f64>() / scene.state.x.len() as f64;
        if centre * side < 0.0 {
            crossings += 1;
            side = -side;
        }
        // Depth below the valley's surface z = |x|/2 from its two slopes' planes (the strip
        // stays over its top): a point below one plane is inside, as deep as it is below
        // that plane; one below both is as deep as it is below the nearer.
        for p in &scene.state.x {
            let below = |s: f64| (0.5 * s * p.x - p.z) / 1.25f64.sqrt();
            let (left, right) = (below(-1.0), below(1.0));
            let depth = if left > 0.0 && right > 0.0 { left.min(right) } else { left.max(right) };
            deepest = deepest.max(depth);
        }
    }
    std::fs::remove_file(&file).ok();
    assert!(crossings >= 2, "the strip crossed the crease {crossings} times");
    assert!(deepest < 0.1 * thickness, "{deepest} m inside the valley");
}

/// A stiff square on a plane tilted by θ: with μ_s = 0.5 and μ_k = 0.4 it must stay put at
/// 20° (tan θ = 0.36 < μ_s) and slide at 35° (tan θ = 0.70 > μ_s) with the block-on-incline
/// acceleration g(sin θ − μ_k cos θ) = 2.41 m/s².
#[test]
fn friction_follows_coulombs_law_on_an_incline() {
    coulomb_on_an_incline(false);
}

/// The same law with sticking vertices held in place over a step
/// (`contact.hold_sticking`) instead of held by the stiff smoothed friction: at 10° (tan θ /
/// μ_s = 0.35, inside the held margin) and 20° it must stay put, at 35° slide as before.
#[test]
fn held_friction_follows_coulombs_law_on_an_incline() {
    coulomb_on_an_incline(true);
}

fn coulomb_on_an_incline(hold: bool) {
    let run = |angle_deg: f64| {
        let theta = angle_deg.to_radians();
        // The plane's top face passes through the origin, its normal tilted about y.
        let normal = DVec3::new(-theta.sin(), 0.0, theta.cos());
        let centre = -0.05 * normal;
        let overrides = strings(&[
            "fabric.preset=denim",
            "cloth.length=0.1",
            "cloth.width=0.1",
            "mesh.edge_length=0.01",
            "contact.self_collision=false",
            "contact.friction_static=0.5",
            "contact.friction_kinetic=0.4",
            "contact.slip_speed=1e-3",
            "solver.damping=0",
            "solver.dt=0.002",
            "test.perturbation=0.0",
            "test.support_size=[0.05, 0.05]", // read only by the drape coefficient, which this test does not use
            &format!(
                "props=[{{shape = 'box', size = [2.0, 0.5, 0.1], position = [{}, {}, {}], rotation_deg = [0.0, {}, 0.0]}}]",
                centre.x, centre.y, centre.z, -angle_deg
            ),
            "scene.duration=0.6",
            "scene.settle_speed=1e-9",
            &format!("contact.hold_sticking={hold}"),
        ]);
        let mut scene = build("tablecloth", &overrides);
        // Lay the flat cloth on the incline at the contact thickness.
        let thickness = scene.config.contact.thickness;
        let tilt = glam::DQuat::from_rotation_y(-theta);
        for p in scene.state.x.iter_mut() {
            *p = tilt * DVec3::new(p.x, p.y, 0.0) + thickness * normal;
        }
        let downhill = tilt * DVec3::NEG_X;
        let mass: f64 = scene.model.mass.iter().sum();
        let mean_speed = |s: &Scene| s.state.v.iter().zip(&s.model.mass).map(|(v, m)| m * v.dot(downhill)).sum::<f64>() / mass;
        let mut samples = Vec::new();
        while scene.state.time < 0.6 - 1e-9 {
            scene.step().unwrap_or_else(|e| panic!("{e}"));
            samples.push((scene.state.time, mean_speed(&scene)));
        }
        samples
    };
    let g = rosette::physics::STANDARD_GRAVITY;
    let angles: &[f64] = if hold { &[10.0, 20.0] } else { &[20.0] };
    for &angle in angles {
        let still = run(angle);
        let (_, speed) = *still.last().unwrap();
        // Without friction it would slide at 1–2 m/s by now. Friction smoothed below the slip speed v_ε
        // and measured from each step's start would let it creep on at v_ε·tan θ/μ_s
        // (F/(μ_s N) = tan θ/μ_s): measured from where it stuck, static friction holds it.
        let creep = 1e-3 * angle.to_radians().tan() / 0.5;
        assert!(speed.abs() < 0.05 * creep, "at {angle}° the cloth slides at {speed} m/s (smoothed friction's creep: {creep} m/s)");
    }
    let sliding = run(35.0);
    let theta = 35f64.to_radians();
    let expected = g * (theta.sin() - 0.4 * theta.cos());
    let at = |t: f64| sliding.iter().find(|s| s.0 >= t - 1e-9).unwrap().1;
    let measured = (at(0.6) - at(0.2)) / 0.4;
    assert!((measured / expected - 1.0).abs() < 0.03, "sliding at {measured} m/s² vs g(sin θ − μ_k cos θ) = {expected}");
}

/// A limp square dropped onto a ball crumples into folds that press on each other. With
/// self-collision none of its edges crosses its triangles; without it they do, which is
/// what makes this test able to fail.
#[test]
fn folds_dropped_on_a_ball_never_pass_through_each_other() {
    let overrides = |self_collision: bool| {
        strings(&[
            "fabric.preset=silk",
            "cloth.length=0.5",
            "cloth.width=0.5",
            "cloth.position=[0.0, 0.0, 0.15]",
            "mesh.edge_length=0.0125",
            &format!("contact.self_collision={self_collision}"),
            "test.support_size=[0.1, 0.1]",
            "test.perturbation=0.01",
            "props=[{shape = 'sphere', radius = 0.1, position = [0.0, 0.0, 0.04]}, {shape = 'ground', position = [0.0, 0.0, -0.06]}]",
            "scene.duration=1.2",
            "scene.settle_speed=1e-9",
        ])
    };
    let mut scene = build("tablecloth", &overrides(true));
    let (metrics, error) = run_scene(&mut scene, "crumple", RunOptions::default());
    assert!(error.is_none(), "{error:?}");
    assert_eq!(metrics.self_intersections, Some(0), "{:?}", metrics.contact_events);
    assert!(metrics.max_penetration.unwrap() < 0.1 * scene.config.contact.thickness);
    let mut unprotected = build("tablecloth", &overrides(false));
    let (metrics, _) = run_scene(&mut unprotected, "crumple", RunOptions::default());
    assert!(metrics.self_intersections.unwrap() > 0, "the cloth never touched itself: the test proves nothing");
}
