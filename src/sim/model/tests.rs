use super::bending::bending_patches;
use super::*;
use crate::sim::curve::PiecewiseLinear;
use crate::sim::mesh::Pattern;
use glam::DMat2;
use std::collections::HashMap;

pub(crate) fn test_fabric() -> Fabric {
    Fabric {
        areal_density: 0.2,
        thickness: 3e-4,
        tensile_warp: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.01, 10.0], [0.05, 200.0]]).unwrap(),
        tensile_weft: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.02, 12.0], [0.06, 150.0]]).unwrap(),
        shear_modulus: 30.0,
        poisson_warp: 0.2,
        bending_warp: 1.2e-5,
        bending_weft: 0.8e-5,
        bending_bias: None,
        bending_curve: None,
    }
}

/// The wool suiting of `presets/fabrics/wool.toml` (the paper's sample), written out so
/// that the simulator's own tests need no preset loader; `scene::load`'s tests hold the
/// two equal.
pub(crate) fn wool_suiting() -> Fabric {
    Fabric {
        areal_density: 0.137,
        thickness: 3.14e-4,
        tensile_warp: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.005, 5.0], [0.015, 20.0], [0.035, 98.0], [0.060, 490.5]]).unwrap(),
        tensile_weft: PiecewiseLinear::new_material(&[[0.0, 0.0], [0.006, 4.8], [0.018, 19.2], [0.040, 85.2], [0.070, 445.2]]).unwrap(),
        shear_modulus: 40.0,
        poisson_warp: 0.15,
        bending_warp: 9.0e-6,
        bending_weft: 7.0e-6,
        bending_bias: Some(5.6e-6),
        bending_curve: None,
    }
}

fn deformed(model: &Model, f: impl Fn(DVec2) -> DVec3) -> Vec<DVec3> {
    model.rest.iter().map(|&p| f(p)).collect()
}

#[test]
fn forces_are_minus_the_energy_gradient() {
    let mut nonlinear = test_fabric();
    // Stiffening, then softening moment–curvature knees (initial slope = bending_warp).
    nonlinear.bending_curve =
        Some(PiecewiseLinear::new_material(&[[0.0, 0.0], [2.0, 2.4e-5], [5.0, 1.2e-4], [9.0, 1.5e-4]]).unwrap());
    for (pattern, fabric) in [(Pattern::Alternating, test_fabric()), (Pattern::Jittered, test_fabric()), (Pattern::Alternating, nonlinear)] {
        let mesh = Mesh::rectangle(0.04, 0.03, 0.01, pattern, 3).unwrap();
        let model = Model::new(&mesh, &fabric, 0.4, PhysicsOptions::default()).unwrap();
        let x = deformed(&model, |p| {
            DVec3::new(p.x * 1.02 + 0.003 * p.y, p.y * 0.99, 0.2 * p.x * p.x + 0.1 * p.x * p.y + 0.001 * (p.y * 300.0).sin())
        });
        let mut f = vec![DVec3::ZERO; x.len()];
        model.forces(&x, &mut f);
        let h = 1e-7;
        for v in [0, 5, 11, x.len() - 1] {
            for c in 0..3 {
                let mut xp = x.clone();
                let mut xm = x.clone();
                xp[v][c] += h;
                xm[v][c] -= h;
                let numeric = -(model.potential_energy(&xp) - model.potential_energy(&xm)) / (2.0 * h);
                let scale = f.iter().map(|q| q.length()).fold(0.0, f64::max);
                assert!((numeric - f[v][c]).abs() < 1e-5 * scale, "{pattern:?} v{v} c{c}: {numeric} vs {}", f[v][c]);
            }
        }
    }
}

/// A compressed and sheared state in which many edges carry compression: the exact
/// in-plane Hessian must match the forces' derivative there, and the bounded one must
/// stay positive semi-definite once the allowance is added to its diagonal.
#[test]
fn compressed_edges_exact_and_bounded_stiffness() {
    let mesh = Mesh::rectangle(0.03, 0.02, 0.005, Pattern::Regular, 0).unwrap();
    let opts = PhysicsOptions { bending: false, gravity: DVec3::ZERO, ..Default::default() };
    let model = Model::new(&mesh, &test_fabric(), 0.0, opts).unwrap();
    let x = deformed(&model, |p| DVec3::new(0.97 * p.x + 0.05 * p.y, 1.01 * p.y, 0.002 * (80.0 * p.x).sin()));
    let n = x.len();
    let direction: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), (i as f64 * 0.7).cos(), (i as f64 * 1.3).sin())).collect();
    let mut k = model.stiffness_matrix();
    model.assemble_membrane_stiffness_within(&x, &mut k, CompressedEdges::Exact);
    let mut kd = vec![DVec3::ZERO; n];
    k.multiply(&direction, &mut kd);
    let h = 1e-8;
    let xp: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a + h * *d).collect();
    let xm: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a - h * *d).collect();
    let (mut fp, mut fm) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    model.forces(&xp, &mut fp);
    model.forces(&xm, &mut fm);
    for i in 0..n {
        let numeric = -(fp[i] - fm[i]) / (2.0 * h);
        assert!((numeric - kd[i]).length() < 1e-4 * (1.0 + kd[i].length()), "vertex {i}: {numeric} vs {}", kd[i]);
    }
    // The dropped term matters here: without it the product differs.
    let mut dropped = model.stiffness_matrix();
    model.assemble_membrane_stiffness(&x, &mut dropped);
    let mut dd = vec![DVec3::ZERO; n];
    dropped.multiply(&direction, &mut dd);
    let gap: f64 = dd.iter().zip(&kd).map(|(a, b)| (*a - *b).length()).sum();
    assert!(gap > 1e-3 * kd.iter().map(|v| v.length()).sum::<f64>(), "no compressed edges in the test state");
    // Bounded by an allowance far below the compression: dᵀ(K + A)d ≥ 0 for out-of-plane
    // and in-plane directions alike.
    let allowance = vec![1.0; n];
    let mut bounded = model.stiffness_matrix();
    model.assemble_membrane_stiffness_within(&x, &mut bounded, CompressedEdges::Within(&allowance));
    for seed in 0..20 {
        let d: Vec<DVec3> = (0..n)
            .map(|i| {
                let t = (i * 31 + seed * 17) as f64;
                DVec3::new((t * 0.37).sin(), (t * 0.91).cos(), (t * 1.7).sin() * 3.0)
            })
            .collect();
        let mut bd = vec![DVec3::ZERO; n];
        bounded.multiply(&d, &mut bd);
        let quadratic: f64 = (0..n).map(|i| d[i].dot(bd[i]) + allowance[i] * d[i].length_squared()).sum();
        assert!(quadratic >= -1e-12, "seed {seed}: {quadratic}");
    }
}

#[test]
fn stiffness_matches_force_derivative_in_tension() {
    let mesh = Mesh::rectangle(0.03, 0.02, 0.01, Pattern::Regular, 0).unwrap();
    let opts = PhysicsOptions { bending: false, gravity: DVec3::ZERO, ..Default::default() };
    let model = Model::new(&mesh, &test_fabric(), 0.0, opts).unwrap();
    // Biaxial stretch along the warp and weft of a right-triangle grid: no edge carries
    // compression, so the projected Hessian equals the exact one.
    let x = deformed(&model, |p| DVec3::new(1.03 * p.x, 1.025 * p.y, 0.0));
    let mut k = model.stiffness_matrix();
    model.assemble_membrane_stiffness(&x, &mut k);
    let direction: Vec<DVec3> = (0..x.len()).map(|i| DVec3::new((i as f64).sin(), (i as f64 * 0.7).cos(), 0.3)).collect();
    let mut kd = vec![DVec3::ZERO; x.len()];
    k.multiply(&direction, &mut kd);
    let h = 1e-8;
    let xp: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a + h * *d).collect();
    let xm: Vec<DVec3> = x.iter().zip(&direction).map(|(a, d)| *a - h * *d).collect();
    let (mut fp, mut fm) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
    model.forces(&xp, &mut fp);
    model.forces(&xm, &mut fm);
    for i in 0..x.len() {
        let numeric = -(fp[i] - fm[i]) / (2.0 * h);
        assert!((numeric - kd[i]).length() < 1e-4 * (1.0 + kd[i].length()), "vertex {i}: {numeric} vs {}", kd[i]);
    }
}

#[test]
fn rigid_motion_costs_no_energy() {
    let mesh = Mesh::rectangle(0.05, 0.03, 0.01, Pattern::Equilateral, 0).unwrap();
    let opts = PhysicsOptions { gravity: DVec3::ZERO, ..Default::default() };
    let model = Model::new(&mesh, &test_fabric(), 0.7, opts).unwrap();
    let rotation = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
    let x = deformed(&model, |p| rotation * DVec3::new(p.x, p.y, 0.0) + DVec3::new(1.0, -2.0, 0.5));
    let (membrane, bending) = model.elastic_energy(&x);
    // Round-off only: a strain of 1e-6 alone would store about 1e-12 J here.
    assert!(membrane.abs() < 1e-13, "{membrane}");
    assert!(bending.abs() < 1e-13, "{bending}");
}

/// A cylindrical bend of curvature κ in direction θ stores ½ B_θ κ² per unit area
/// (eq. 3). The discrete energy must converge to it on every triangulation and warp angle.
#[test]
fn cylindrical_bending_energy_converges_to_eq3() {
    let fabric = test_fabric();
    let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
    let kappa = 8.0;
    for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
        for (warp_deg, bend_deg) in [(0.0, 0.0), (30.0, 0.0), (0.0, 90.0), (45.0, 20.0)] {
            let mut errors = Vec::new();
            for h in [0.01, 0.005] {
                let mesh = Mesh::rectangle(0.1, 0.1, h, pattern, 11).unwrap();
                let model = Model::new(&mesh, &fabric, f64::to_radians(warp_deg), opts).unwrap();
                let dir = DVec2::from_angle(f64::to_radians(bend_deg));
                // Isometric roll: arclength s along `dir` wraps onto a circle of radius 1/κ.
                let x = deformed(&model, |p| {
                    let s = p.dot(dir);
                    let t = p.dot(dir.perp());
                    let along = dir * ((kappa * s).sin() / kappa) + dir.perp() * t;
                    DVec3::new(along.x, along.y, (1.0 - (kappa * s).cos()) / kappa)
                });
                // Free edges carry no moment (m_νν = 0), which a uniform roll violates,
                // so compare on the triangles that have all three neighbours.
                let energies = model.triangle_bending_energies(&x);
                let interior: Vec<usize> = (0..energies.len()).filter(|&t| model.is_interior_triangle(t)).collect();
                let bending: f64 = interior.iter().map(|&t| energies[t]).sum();
                let area: f64 = interior.iter().map(|&t| mesh.signed_area(t)).sum();
                let theta = f64::to_radians(bend_deg - warp_deg);
                let exact = 0.5 * model.bending_stiffness.rigidity_at(theta) * kappa * kappa * area;
                errors.push(((bending - exact) / exact).abs());
            }
            assert!(errors[1] < 0.01, "{pattern:?} warp {warp_deg} bend {bend_deg}: errors {errors:?}");
            assert!(errors[1] <= errors[0] + 1e-4, "{pattern:?}: error must not grow on refinement {errors:?}");
        }
    }
}

/// A roll of curvature κ across the warp's diagonal reads κ on every interior triangle:
/// the magnitude counts the twist κ_xy that the roll puts in the warp frame.
#[test]
fn a_roll_off_the_warp_reads_its_curvature_magnitude() {
    let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
    let kappa = 8.0;
    let mesh = Mesh::rectangle(0.1, 0.1, 0.005, Pattern::Regular, 11).unwrap();
    let model = Model::new(&mesh, &test_fabric(), f64::to_radians(30.0), opts).unwrap();
    let dir = DVec2::from_angle(f64::to_radians(75.0));
    let x = deformed(&model, |p| {
        let (s, t) = (p.dot(dir), p.dot(dir.perp()));
        let along = dir * ((kappa * s).sin() / kappa) + dir.perp() * t;
        DVec3::new(along.x, along.y, (1.0 - (kappa * s).cos()) / kappa)
    });
    let curvatures = model.triangle_curvatures(&x);
    for t in (0..curvatures.len()).filter(|&t| model.is_interior_triangle(t)) {
        let k = curvatures[t];
        assert!(k[2].abs() > 0.1 * kappa, "the roll twists the warp frame: {k:?}");
        let magnitude = curvature_magnitude(k);
        assert!((magnitude - kappa).abs() < 0.02 * kappa, "triangle {t}: {magnitude} for {kappa} ({k:?})");
    }
}

/// The hinges read zero on every quadratic surface (whose curvature each triangle's fitted
/// Hessian reproduces), on any triangulation and warp angle, so they leave constant
/// curvatures to the fitted stencils.
#[test]
fn hinges_vanish_on_quadratic_surfaces() {
    let f = |p: DVec2| 0.3 + 2.0 * p.x - p.y + 40.0 * p.x * p.x - 25.0 * p.x * p.y + 10.0 * p.y * p.y;
    for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
        let mesh = Mesh::rectangle(0.1, 0.08, 0.01, pattern, 5).unwrap();
        let (_, hinges) = bending_patches(&mesh, 0.4, &vec![false; mesh.rest.len()]).unwrap();
        assert!(hinges.len() > 100, "{pattern:?}: {} hinges", hinges.len());
        // A kink as sharp as this surface's curvature (about 100 /m) over an edge
        // (0.01 m) would read about 1.
        for h in &hinges {
            let reading: f64 = h.vertices.iter().zip(&h.stencil).map(|(&v, s)| s * f(mesh.rest[v as usize])).sum();
            assert!(reading.abs() < 1e-9, "{pattern:?}: hinge reads {reading:e}");
        }
        // And a zigzag does register.
        let zigzag = |v: u32| if (mesh.rest[v as usize].x / 0.01).round() as i64 % 2 == 0 { 0.001 } else { -0.001 };
        let loudest = hinges.iter().map(|h| h.vertices.iter().zip(&h.stencil).map(|(&v, s)| s * zigzag(v)).sum::<f64>().abs()).fold(0.0, f64::max);
        assert!(loudest > 0.05, "{pattern:?}: a 1 mm zigzag reads at most {loudest:e}");
    }
}

/// Smallest μ with Q v = μ (L M⁻¹ L) v over deflections that vanish within two rings of
/// the edge, against c_min: the continuum plate's 2E = ∫ D:∇∇w:∇∇w ≥ c_min ∫(Δw)² for
/// such w (c_min the smallest eigenvalue of 𝔻 on (w_xx, w_yy, √2 w_xy)), and L M⁻¹ L is
/// ∫(Δw)² with the cotangent Laplacian L and lumped areas M.
fn softest_deflection(mesh: &Mesh, model: &Model) -> f64 {
    let n = mesh.rest.len();
    let mut near_edge = vec![false; n];
    let mut owners: HashMap<[u32; 2], u32> = HashMap::new();
    for tri in &mesh.triangles {
        for k in 0..3 {
            *owners.entry(sorted_edge(tri[(k + 1) % 3], tri[(k + 2) % 3])).or_default() += 1;
        }
    }
    for (e, count) in &owners {
        if *count == 1 {
            e.iter().for_each(|&v| near_edge[v as usize] = true);
        }
    }
    for _ring in 0..2 {
        let grown = near_edge.clone();
        for tri in &mesh.triangles {
            if tri.iter().any(|&v| grown[v as usize]) {
                tri.iter().for_each(|&v| near_edge[v as usize] = true);
            }
        }
    }
    let inner: Vec<usize> = (0..n).filter(|&v| !near_edge[v]).collect();
    let mut index = vec![usize::MAX; n];
    inner.iter().enumerate().for_each(|(i, &v)| index[v] = i);
    let m = inner.len();
    let mut laplacian = faer::Mat::<f64>::zeros(m, m);
    for tri in &mesh.triangles {
        for k in 0..3 {
            let (o, a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize, tri[(k + 2) % 3] as usize);
            let (ea, eb) = (mesh.rest[a] - mesh.rest[o], mesh.rest[b] - mesh.rest[o]);
            let w = 0.5 * ea.dot(eb) / ea.perp_dot(eb).abs();
            for (p, q) in [(a, b), (b, a)] {
                if index[p] != usize::MAX {
                    laplacian[(index[p], index[p])] += w;
                    if index[q] != usize::MAX {
                        laplacian[(index[p], index[q])] -= w;
                    }
                }
            }
        }
    }
    use faer::linalg::solvers::DenseSolveCore;
    let inverse = laplacian.llt(faer::Side::Lower).expect("Dirichlet Laplacian").inverse();
    let q = model.bending_newton_matrix(&deformed(model, |p| p.extend(0.0))).unwrap();
    let mut qm = faer::Mat::<f64>::zeros(m, m);
    for (a, b, v) in q.entries() {
        let (i, j) = (index[a as usize], index[b as usize]);
        if i != usize::MAX && j != usize::MAX {
            qm[(i, j)] = v;
        }
    }
    let root_area = faer::Mat::<f64>::from_fn(m, m, |i, j| if i == j { model.vertex_area[inner[i]].sqrt() } else { 0.0 });
    let s = &root_area * &inverse * &qm * &inverse * &root_area;
    let smallest = s.self_adjoint_eigenvalues(faer::Side::Lower).unwrap()[0];
    let d = model.bending_stiffness;
    let c_min = (0.5 * (d.d11 + d.d22) - (0.25 * (d.d11 - d.d22).powi(2) + d.d12 * d.d12).sqrt()).min(2.0 * d.d66);
    smallest / c_min
}

/// No deflection is much softer than a plate: the softest one, relative to c_min, is at
/// least a quarter of the continuum's bound of 1 on every triangulation. A discrete
/// operator may be softer at the mesh scale, and the fitted stencils alone are, far below
/// a quarter; with the hinges the softest deflection is the smooth one, well above it.
#[test]
fn no_mesh_scale_deflection_escapes_bending() {
    let fabric = test_fabric();
    let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
    for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
        let mesh = Mesh::rectangle(0.12, 0.1, 0.005, pattern, 11).unwrap();
        let model = Model::new(&mesh, &fabric, 0.3, opts).unwrap();
        let softest = softest_deflection(&mesh, &model);
        assert!(softest > 0.25, "{pattern:?}: the softest deflection has {softest:.3} of the plate's bending energy");
    }
}

/// A Gaussian bump w = a·exp(−r²/σ²) four edges wide (σ = 4h) stores within 10 % of the
/// plate energy ½ ∫ D:∇∇w:∇∇w (computed from the exact Hessian by quadrature), on every
/// triangulation; the fitted stencils alone store too little there, by more than that.
#[test]
fn smooth_bumps_bend_as_a_plate() {
    let fabric = test_fabric();
    let opts = PhysicsOptions { membrane: false, gravity: DVec3::ZERO, ..Default::default() };
    let (warp, h, sigma, a) = (0.3f64, 0.005, 0.02, 0.001);
    let centre = DVec2::new(0.1, 0.1);
    for pattern in [Pattern::Regular, Pattern::Alternating, Pattern::Equilateral, Pattern::Jittered] {
        let mesh = Mesh::rectangle(0.2, 0.2, h, pattern, 11).unwrap();
        let model = Model::new(&mesh, &fabric, warp, opts).unwrap();
        let x = deformed(&model, |p| p.extend(a * (-(p - centre).length_squared() / (sigma * sigma)).exp()));
        let d = model.bending_stiffness.voigt();
        let (n, cell) = (400, 0.2 / 400.0);
        let rotation = DMat2::from_angle(-warp);
        let mut plate = 0.0;
        for i in 0..n {
            for j in 0..n {
                let p = DVec2::new((i as f64 + 0.5) * cell, (j as f64 + 0.5) * cell) - centre;
                let e = a * (-p.length_squared() / (sigma * sigma)).exp() / sigma.powi(4);
                let hessian = DMat2::from_cols(
                    e * DVec2::new(4.0 * p.x * p.x - 2.0 * sigma * sigma, 4.0 * p.x * p.y),
                    e * DVec2::new(4.0 * p.x * p.y, 4.0 * p.y * p.y - 2.0 * sigma * sigma),
                );
                // In the warp frame.
                let hw = rotation * hessian * rotation.transpose();
                let k = [hw.x_axis.x, hw.y_axis.y, hw.y_axis.x];
                plate += 0.5 * (0..3).map(|r| (0..3).map(|c| d[r][c] * k[r] * k[c]).sum::<f64>()).sum::<f64>() * cell * cell;
            }
        }
        let ratio = model.bending_energy(&x) / plate;
        assert!((ratio - 1.0).abs() < 0.1, "{pattern:?}: the bump stores {ratio:.3} of the plate's energy");
    }
}
