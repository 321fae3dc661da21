//! scratch
use glam::{DVec2, DVec3};
use rosette::scene::load_scene;
use rosette::sim::*;

fn wool(linear: bool) -> Fabric {
    let (config, _) = load_scene("tensile-warp", &[]).unwrap();
    let mut f = config.fabric.to_fabric().unwrap();
    if linear {
        f.tensile_warp = PiecewiseLinear::linear(1000.0);
        f.tensile_weft = PiecewiseLinear::linear(800.0);
    }
    f
}

fn setup(linear: bool, bending: bool) -> (Model, State) {
    let mesh = Mesh::rectangle(0.06, 0.04, 0.01, Pattern::Jittered, 7).unwrap();
    let opts = PhysicsOptions { membrane: true, bending, gravity: DVec3::ZERO, damping: 0.0 };
    let model = Model::new(&mesh, &wool(linear), 0.3, opts).unwrap();
    let x: Vec<DVec3> = model.rest.iter().enumerate().map(|(i, p): (usize, &DVec2)| {
        let k = i as f64;
        DVec3::new(1.01 * p.x + 4e-4 * (1.3 * k).sin(), 0.995 * p.y + 3e-4 * (2.1 * k).cos(), 0.004 * (60.0 * p.x).sin() * (40.0 * p.y).cos() + 1e-3 * (0.7 * k).sin())
    }).collect();
    let mut s = State::at_rest(x);
    for (i, v) in s.v.iter_mut().enumerate() {
        let k = i as f64;
        *v = DVec3::new(0.05 * (1.7 * k).sin() + 0.02, 0.04 * (2.3 * k).cos() - 0.01, 0.06 * (0.9 * k + 1.0).sin() + 0.03);
    }
    (model, s)
}

fn limit(model: &Model) -> f64 {
    let rho = model.mass.iter().sum::<f64>() / model.vertex_area.iter().sum::<f64>();
    model.mean_edge_length / (model.max_membrane_stiffness() / rho).sqrt()
}

fn energy(model: &Model, s: &State) -> f64 { s.kinetic_energy(model) + model.potential_energy(&s.x) }


fn omega_max(model: &Model, x: &[DVec3]) -> f64 {
    // power iteration on M^-1/2 K M^-1/2 with finite-difference K
    let n = x.len();
    let mut u: Vec<DVec3> = (0..n).map(|i| DVec3::new((1.1*i as f64).sin(), (2.3*i as f64).cos(), 0.3*(0.7*i as f64).sin())).collect();
    let mut lam = 0.0;
    for _ in 0..3000 {
        let norm = u.iter().map(|v| v.length_squared()).sum::<f64>().sqrt();
        for v in u.iter_mut() { *v /= norm; }
        let d: Vec<DVec3> = (0..n).map(|i| u[i] / model.mass[i].sqrt()).collect();
        let eps = 1e-7;
        let xp: Vec<DVec3> = (0..n).map(|i| x[i] + eps * d[i]).collect();
        let xm: Vec<DVec3> = (0..n).map(|i| x[i] - eps * d[i]).collect();
        let (mut fp, mut fm) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
        model.forces(&xp, &mut fp); model.forces(&xm, &mut fm);
        let w: Vec<DVec3> = (0..n).map(|i| -(fp[i] - fm[i]) / (2.0 * eps) / model.mass[i].sqrt()).collect();
        lam = u.iter().zip(&w).map(|(a, b)| a.dot(*b)).sum::<f64>();
        u = w;
    }
    lam.sqrt()
}

fn setup2(pattern: Pattern, smooth: bool) -> (Model, State) {
    let mesh = Mesh::rectangle(0.06, 0.04, 0.005, pattern, 7).unwrap();
    let opts = PhysicsOptions { membrane: true, bending: false, gravity: DVec3::ZERO, damping: 0.0 };
    let model = Model::new(&mesh, &wool(true), 0.3, opts).unwrap();
    let x: Vec<DVec3> = model.rest.iter().enumerate().map(|(i, p)| {
        let k = i as f64;
        let r = if smooth { 0.0 } else { 1.0 };
        DVec3::new(1.01 * p.x + r*4e-4 * (1.3 * k).sin(), 0.995 * p.y + r*3e-4 * (2.1 * k).cos(), 0.004 * (60.0 * p.x).sin() * (40.0 * p.y).cos() + r*1e-3 * (0.7 * k).sin())
    }).collect();
    let mut s = State::at_rest(x);
    for (i, v) in s.v.iter_mut().enumerate() {
        let k = i as f64;
        let p = model.rest[i];
        *v = if smooth { DVec3::new(0.3 * (50.0*p.y).sin() + 0.02, 0.2*(40.0*p.x).cos(), 0.5 * (70.0*p.x + 30.0*p.y).sin()) }
             else { DVec3::new(0.05 * (1.7 * k).sin() + 0.02, 0.04 * (2.3 * k).cos() - 0.01, 0.06 * (0.9 * k + 1.0).sin() + 0.03) };
    }
    (model, s)
}

#[test]
fn explore2() {
    for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Jittered, Pattern::Equilateral] {
        for smooth in [false, true] {
            let (model, s0) = setup2(pattern, smooth);
            let lim = limit(&model);
            let restx: Vec<DVec3> = model.rest.iter().map(|p| DVec3::new(p.x, p.y, 0.0)).collect();
            let stretched: Vec<DVec3> = model.rest.iter().map(|p| DVec3::new(1.01*p.x, 1.01*p.y, 0.0)).collect();
            let w = omega_max(&model, &stretched);
            let _ = restx;
            eprintln!("{pattern:?} smooth {smooth}: estimate {lim:e}, 2/omega_max {:e} (ratio {:.3})", 2.0 / w, 2.0 / w / lim);
            for factor in [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7] {
                let mut s = s0.clone();
                let mut integ = Integrator::new(IntegratorKind::SymplecticEuler, factor * lim);
                let e0 = energy(&model, &s);
                let (mut lo, mut hi) = (e0, e0);
                let mut res = String::from("ok");
                for n in 0..2000 {
                    match integ.step(&model, &mut s) { Ok(_) => {} Err(_) => { res = format!("diverged at step {n}"); break; } }
                    let e = energy(&model, &s);
                    lo = lo.min(e); hi = hi.max(e);
                }
                eprintln!("  factor {factor}: range [{:+.4}, {:+.4}] {res}", lo / e0 - 1.0, hi / e0 - 1.0);
            }
        }
    }
}
