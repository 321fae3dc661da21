use super::incomplete::{PART_VERTICES, part_count};
use super::*;
use glam::{DMat3, DVec3};
use std::sync::Arc;

/// A chain of `n` vertices: springs between neighbours (anisotropic 3×3 blocks) and a
/// scalar second-difference "bending" matrix coupling vertices two apart.
fn banded_chain(n: usize) -> (BlockCsr, ScalarCsr, Vec<f64>) {
    let mut k = BlockCsr::with_pattern(n, (0..n as u32 - 1).map(|i| (i, i + 1)));
    let spring = DMat3::from_cols(DVec3::new(3.0, 0.5, 0.0), DVec3::new(0.5, 1.0, 0.2), DVec3::new(0.0, 0.2, 0.7));
    for a in 0..n as u32 - 1 {
        let b = a + 1;
        let (aa, bb, ab, ba) = (k.slot(a, a), k.slot(b, b), k.slot(a, b), k.slot(b, a));
        k.values[aa] += spring;
        k.values[bb] += spring;
        k.values[ab] -= spring;
        k.values[ba] -= spring;
    }
    let pairs = (0..n as u32 - 2).flat_map(|i| [(i, i + 1), (i + 1, i + 2), (i, i + 2)]);
    let mut q = ScalarCsr::with_pattern(n, pairs);
    for i in 0..n as u32 - 2 {
        // ½ (x_i − 2x_{i+1} + x_{i+2})² · 5
        let w = [1.0, -2.0, 1.0];
        for a in 0..3 {
            for b in 0..3 {
                let slot = q.slot(i + a, i + b);
                q.values[slot] += 5.0 * w[a as usize] * w[b as usize];
            }
        }
    }
    let mass = (0..n).map(|i| 1.0 + (i % 7) as f64 * 0.1).collect();
    (k, q, mass)
}

/// Adds the couplings' diagonal blocks k·c_i²·nnᵀ to the stiffness, where
/// `SystemMatrix::couplings` expects them.
fn add_coupling_diagonals(k: &mut BlockCsr, couplings: &[Coupling]) {
    for c in couplings {
        let nn = DMat3::from_cols(c.normal * c.normal.x, c.normal * c.normal.y, c.normal * c.normal.z);
        for (&v, &w) in c.vertices.iter().zip(&c.weights) {
            let slot = k.diagonal_slot(v);
            k.values[slot] += nn * (c.stiffness * w * w);
        }
    }
}

/// Vertices coupled only by contact (disjoint groups of four, stiffer than their mass,
/// each along its own normal): with the couplings in its pattern the incomplete factor
/// has no fill to drop and is exact up to its single-precision storage, so CG converges
/// at once; a factor that saw only the couplings' diagonal blocks needs many iterations per
/// coupled group (docs/performance-log.md).
#[test]
fn incomplete_factor_takes_the_contact_couplings_in() {
    let groups = 25;
    let n = 4 * groups;
    let mut k = BlockCsr::with_pattern(n, std::iter::empty());
    let mass = vec![1.0; n];
    let couplings: Vec<Coupling> = (0..groups)
        .map(|g| {
            let t = g as f64;
            Coupling {
                vertices: [g, g + groups, g + 2 * groups, g + 3 * groups].map(|v| v as u32),
                weights: [1.0, -0.2 - 0.01 * t, -0.3, -0.5 + 0.01 * t],
                normal: DVec3::new(t.sin(), t.cos(), 0.5).normalize(),
                stiffness: 10f64.powf(1.0 + t / 8.0),
            }
        })
        .collect();
    add_coupling_diagonals(&mut k, &couplings);
    let fixed = vec![false; n];
    let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: None, fixed: &fixed, couplings: &couplings };
    let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), 1.0, (i % 3) as f64)).collect();
    let mut x = vec![DVec3::ZERO; n];
    let preconditioner = a.preconditioner(FactorPattern::Wide);
    assert!(matches!(preconditioner, Preconditioner::IncompleteCholesky(_)), "the factorisation broke down");
    let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 500);
    let mut ax = vec![DVec3::ZERO; n];
    a.apply(&x, &mut ax);
    let error = ax.iter().zip(&b).map(|(p, q)| (*p - *q).length()).fold(0.0, f64::max);
    assert!(error < 1e-8, "residual {error} after {} iterations", report.iterations);
    assert!(report.iterations <= 3, "{} iterations", report.iterations);
}

/// The stiffness of `n` vertices in pairs (2i, 2i + 1), each pair joined by c·I: with unit
/// masses each pair's block is [[1, c], [c, 1]] ⊗ I₃, whose factor (exact on either pattern)
/// breaks down unless 1 + s > |c| for the diagonal shift s.
fn paired_vertices(n: usize, c: f64) -> BlockCsr {
    let mut k = BlockCsr::with_pattern(n, (0..n as u32 / 2).map(|i| (2 * i, 2 * i + 1)));
    for i in 0..n as u32 / 2 {
        for (row, col) in [(2 * i, 2 * i + 1), (2 * i + 1, 2 * i)] {
            let slot = k.slot(row, col);
            k.values[slot] = DMat3::IDENTITY * c;
        }
    }
    k
}

#[test]
fn incomplete_factors_start_from_the_shift_the_last_one_needed() {
    // Two vertices of unit mass joined by c·I (`paired_vertices`): at c = 1.005 only the
    // shifts from 1e-2 up succeed, at c = 0.5 all.
    let (hard, easy) = (paired_vertices(2, 1.005), paired_vertices(2, 0.5));
    let (mass, fixed) = ([1.0; 2], [false; 2]);
    let system = |k| SystemMatrix { mass_diagonal: &mass, stiffness: k, bending: None, fixed: &fixed, couplings: &[] };
    let shift = |p: Preconditioner| match p {
        Preconditioner::IncompleteCholesky(factor) => factor.shift,
        _ => panic!("the factorisation broke down at every shift"),
    };
    assert_eq!(shift(system(&easy).preconditioner(FactorPattern::Wide)), 0.0);
    let mut memory = ShiftMemory::default();
    assert_eq!(shift(system(&hard).preconditioner_remembering(FactorPattern::Wide, &mut memory)), 1e-2);
    // The next factors start where the last one ended, though the matrix needs none now...
    for _ in 0..2 {
        assert_eq!(shift(system(&easy).preconditioner_remembering(FactorPattern::Wide, &mut memory)), 1e-2);
    }
    // ...and every fourth tries the next smaller shift, so the start comes back down.
    assert_eq!(shift(system(&easy).preconditioner_remembering(FactorPattern::Wide, &mut memory)), 1e-3);
    // Each pattern remembers its own.
    assert_eq!(shift(system(&easy).preconditioner_remembering(FactorPattern::Ring, &mut memory)), 0.0);
    assert_eq!(shift(system(&easy).preconditioner_remembering(FactorPattern::Wide, &mut memory)), 1e-3);
}

#[test]
fn one_ring_factors_of_split_size_matrices_take_larger_shifts() {
    // Vertices of unit mass in pairs joined by 1.2·I (`paired_vertices`): every shift up to
    // 1e-1 fails; a one-ring factor of a matrix large enough to be split goes on to 0.3, one
    // of a smaller matrix or on the whole pattern does not.
    for (n, split) in [(2 * PART_VERTICES, true), (PART_VERTICES / 2, false)] {
        assert_eq!(factor_is_split(n), split);
        let k = paired_vertices(n, 1.2);
        let (mass, fixed) = (vec![1.0; n], vec![false; n]);
        let system = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: None, fixed: &fixed, couplings: &[] };
        let mut memory = ShiftMemory::default();
        match system.preconditioner_remembering(FactorPattern::Ring, &mut memory) {
            Preconditioner::IncompleteCholesky(factor) => assert!(split && factor.shift == 0.3, "n = {n}: shift {}", factor.shift),
            _ => assert!(!split, "n = {n}: no one-ring factor at any shift"),
        }
        assert!(matches!(system.preconditioner_remembering(FactorPattern::Wide, &mut memory), Preconditioner::BlockJacobi(_)), "n = {n}");
        // The next one-ring factor starts from the shift the last one needed.
        if split {
            let Preconditioner::IncompleteCholesky(factor) = system.preconditioner_remembering(FactorPattern::Ring, &mut memory) else { panic!("no factor") };
            assert_eq!(factor.shift, 0.3);
        }
    }
}

#[test]
fn block_factor_of_a_banded_matrix_is_exact_and_parts_still_converge() {
    for n in [50, 1000, PART_VERTICES + 1000, 3 * PART_VERTICES] {
        let (k, q, mass) = banded_chain(n);
        let fixed = vec![false; n];
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &[] };
        let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), 1.0, (i % 3) as f64)).collect();
        let mut x = vec![DVec3::ZERO; n];
        let preconditioner = a.preconditioner(FactorPattern::Wide);
        let Preconditioner::IncompleteCholesky(factor) = &preconditioner else { panic!("the factorisation broke down") };
        let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 500);
        let mut ax = vec![DVec3::ZERO; n];
        a.apply(&x, &mut ax);
        let error = ax.iter().zip(&b).map(|(p, q)| (*p - *q).length()).fold(0.0, f64::max);
        assert!(error < 1e-8, "n = {n}: residual {error} after {} iterations", report.iterations);
        if factor.part_count() == 1 {
            // No fill falls outside a band: the incomplete factor is the exact one (up to
            // its single-precision storage). This also catches an unsymmetric factor,
            // with which the conjugate gradient stalls.
            assert!(report.iterations <= 3, "n = {n}: {} iterations", report.iterations);
        } else {
            assert_eq!(factor.part_count(), if n < 2 * PART_VERTICES { 2 } else { n / PART_VERTICES });
            assert_eq!(factor.part_count(), part_count(n));
            assert!(report.iterations < 100, "n = {n}: {} iterations", report.iterations);
        }
    }
}

#[test]
fn complete_factor_solves_in_one_iteration_and_respects_fixed_vertices() {
    let n = 300;
    let (k, q, mass) = banded_chain(n);
    let mut fixed = vec![false; n];
    fixed[0] = true;
    fixed[150] = true;
    let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &[] };
    let pattern = Arc::new(DirectPattern::new(&a).expect("symbolic analysis"));
    assert!(pattern.fits(&a));
    let preconditioner = Preconditioner::Cholesky(DirectFactor::new(pattern, &a).expect("the factorisation failed"));
    let b: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).cos(), -1.0, (i % 4) as f64)).collect();
    let mut x = vec![DVec3::ZERO; n];
    let report = pcg(&a, &preconditioner, &b, &mut x, 1e-10, 50);
    assert!(report.iterations <= 2, "{} iterations with the exact factor", report.iterations);
    let mut ax = vec![DVec3::ZERO; n];
    a.apply(&x, &mut ax);
    for i in 0..n {
        let expected = if fixed[i] { DVec3::ZERO } else { b[i] };
        assert!((ax[i] - expected).length() < 1e-8, "row {i}: {:?} against {:?}", ax[i], expected);
    }
    assert_eq!(x[0], DVec3::ZERO);
    assert_eq!(x[150], DVec3::ZERO);
}

#[test]
fn pcg_solves_a_small_spd_system() {
    // A chain of three vertices coupled by springs along x plus a mass term.
    let mut k = BlockCsr::with_pattern(3, [(0, 1), (1, 2)].into_iter());
    let spring = DMat3::from_diagonal(DVec3::new(2.0, 1.0, 0.5));
    for (a, b) in [(0u32, 1u32), (1, 2)] {
        let (aa, bb, ab, ba) = (k.slot(a, a), k.slot(b, b), k.slot(a, b), k.slot(b, a));
        k.values[aa] += spring;
        k.values[bb] += spring;
        k.values[ab] -= spring;
        k.values[ba] -= spring;
    }
    let mass = [1.0, 2.0, 3.0];
    let fixed = [false; 3];
    let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: None, fixed: &fixed, couplings: &[] };
    let b = vec![DVec3::new(1.0, 0.0, 2.0), DVec3::new(-1.0, 3.0, 0.0), DVec3::new(0.5, 0.5, 0.5)];
    let mut x = vec![DVec3::ZERO; 3];
    let report = pcg(&a, &a.preconditioner(FactorPattern::Wide), &b, &mut x, 1e-12, 100);
    assert!(report.relative_residual < 1e-12);
    let mut ax = vec![DVec3::ZERO; 3];
    a.apply(&x, &mut ax);
    for i in 0..3 {
        assert!((ax[i] - b[i]).length() < 1e-10);
    }
}

/// The scalar factor solves (diag + Q) ⊗ I₃ exactly, with fixed vertices' rows eliminated
/// (zero there), whatever the ordering its analysis chose: checked by multiplying back.
#[test]
fn scalar_factor_solves_its_matrix_on_every_coordinate() {
    let n = 40;
    let (_, q, mass) = banded_chain(n);
    let mut fixed = vec![false; n];
    fixed[0] = true;
    fixed[17] = true;
    let pattern = ScalarPattern::new(&q, &fixed).expect("analysis");
    let factor = ScalarFactor::new(&pattern, &mass, &q).expect("positive definite");
    let r: Vec<DVec3> = (0..n).map(|i| DVec3::new((i as f64).sin(), (0.3 * i as f64).cos(), 1.0 + i as f64 * 0.01)).collect();
    let mut z = vec![DVec3::ZERO; n];
    factor.solve(&pattern, &r, &mut z);
    for i in 0..n {
        if fixed[i] {
            assert_eq!(z[i], DVec3::ZERO);
            continue;
        }
        // Row i of (diag + Q) z over the free columns.
        let mut row = mass[i] * z[i];
        for (j, v) in q.entries_of_row(i as u32) {
            if !fixed[j as usize] {
                row += v * z[j as usize];
            }
        }
        assert!((row - r[i]).length() < 1e-10 * r[i].length().max(1.0), "row {i}: {row} against {}", r[i]);
    }
}

/// The chain with its ends fixed and contact couplings between vertices far apart, for the
/// products of several vectors at once.
fn coupled_chain(n: usize) -> (BlockCsr, ScalarCsr, Vec<f64>, Vec<bool>, Vec<Coupling>) {
    let (mut k, q, mass) = banded_chain(n);
    let mut fixed = vec![false; n];
    fixed[0] = true;
    fixed[n / 2] = true;
    let couplings: Vec<Coupling> = (0..n as u32 / 8)
        .map(|g| Coupling {
            vertices: [g, g + n as u32 / 4, g + n as u32 / 2, g + 3 * n as u32 / 4],
            weights: [1.0, -0.25, -0.35, -0.4],
            normal: DVec3::new(0.3, (g as f64).cos(), 0.6).normalize(),
            stiffness: 40.0,
        })
        .collect();
    add_coupling_diagonals(&mut k, &couplings);
    (k, q, mass, fixed, couplings)
}

fn wave(n: usize, phase: f64) -> Vec<DVec3> {
    (0..n).map(|i| DVec3::new((i as f64 * 0.01 + phase).sin(), (i as f64 * 0.003).cos(), 0.5 + phase)).collect()
}

/// k products at once are the k products one by one (the rows read once, the couplings and
/// fixed vertices as in `apply`), on the calling thread and in parallel chunks, for k under
/// four, a multiple of four and between (the vectors go four at a time, the rest one by one).
#[test]
fn products_of_vectors_side_by_side_are_the_products_one_by_one() {
    for n in [200, 2 * 4096 + 40] {
        let (k, q, mass, fixed, couplings) = coupled_chain(n);
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &couplings };
        for count in [3, 6, 8] {
            let columns: Vec<Vec<DVec3>> = (0..count).map(|j| wave(n, j as f64)).collect();
            let side_by_side: Vec<DVec3> = (0..n).flat_map(|i| columns.iter().map(move |c| c[i])).collect();
            let mut together = vec![DVec3::ONE; count * n];
            a.apply_many(count, &side_by_side, &mut together);
            for (j, column) in columns.iter().enumerate() {
                let mut alone = vec![DVec3::ZERO; n];
                a.apply(column, &mut alone);
                for i in 0..n {
                    let (x, y) = (together[i * count + j], alone[i]);
                    assert!((x - y).length() <= 1e-12 * y.length().max(1.0), "n = {n}, {count} vectors, column {j}, row {i}: {x:?} against {y:?}");
                }
            }
        }
    }
}

/// Deflated CG solves the same system as plain CG (the residual checked by the product, not
/// by the solver), from any recycled space: empty, holding a dependent or a zero column, or
/// holding solutions of nearby systems, with which every solve takes fewer iterations (396
/// against 516 over the six). Holding the
/// solution itself, it returns it without iterating. Slow modes of a long chain under a
/// block-diagonal preconditioner are what it is for.
#[test]
fn deflated_cg_solves_the_system_and_fewer_iterations_with_nearby_solutions() {
    let n = 600;
    let (k, q, mass, fixed, couplings) = coupled_chain(n);
    let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &couplings };
    let jacobi = Preconditioner::BlockJacobi(a.block_jacobi());
    let residual = |x: &[DVec3], b: &[DVec3]| relative_residual(&a, x, b);
    let solve = |b: &[DVec3], recycled: Option<&Recycled>| solved(&a, &jacobi, b, recycled);
    // Earlier systems: loads that drift as a cloth's slow motion does.
    let mut recycled = Recycled::default();
    let mut plain_total = 0;
    let mut deflated_total = 0;
    for step in 0..6 {
        let b = wave(n, 0.05 * step as f64);
        let (x_plain, plain) = solve(&b, None);
        let (x_deflated, deflated) = solve(&b, Some(&recycled));
        assert!(residual(&x_plain, &b) < 2e-8, "plain CG, step {step}");
        assert!(residual(&x_deflated, &b) < 2e-8, "deflated CG, step {step}: {}", residual(&x_deflated, &b));
        assert!(x_deflated[0] == DVec3::ZERO && x_deflated[n / 2] == DVec3::ZERO, "fixed vertices moved");
        if step == 0 {
            assert_eq!(deflated, plain, "with nothing recycled the solve is plain CG's");
        } else {
            assert!(deflated < plain, "step {step}: deflated {deflated} against plain {plain} iterations");
        }
        plain_total += plain;
        deflated_total += deflated;
        recycled.remember(&x_deflated, 4);
    }
    println!("deflated {deflated_total} against plain {plain_total} CG iterations");
    // A zero column and one that repeats another are left out, not divided by.
    let b = wave(n, 0.4);
    let (x, _) = solve(&b, None);
    let mut degenerate = Recycled::default();
    degenerate.remember(&x, 4);
    degenerate.remember(&vec![DVec3::ZERO; n], 4);
    degenerate.remember(&x.iter().map(|v| *v * 3.0).collect::<Vec<_>>(), 4);
    let (x_again, iterations) = solve(&b, Some(&degenerate));
    assert_eq!(iterations, 0, "the recycled space holds the solution");
    assert!(residual(&x_again, &b) < 1e-8, "{}", residual(&x_again, &b));
    // Columns of another mesh are forgotten.
    degenerate.remember(&wave(n + 1, 0.0), 4);
    let (x_other, _) = solve(&b, Some(&degenerate));
    assert!(residual(&x_other, &b) < 2e-8);
}

/// Long enough for the solve's passes to run in two halves on the team (2 000 rows) or in
/// parallel chunks on rayon's pool (8 232), deflated CG still solves the system (the
/// residual checked by the product), and gives the same iterate, bit for bit, on one thread
/// and on two: the partial sums are added in the chunks' order.
#[test]
fn deflated_cg_in_parallel_chunks_solves_the_system_the_same_on_any_thread_count() {
    for n in [2_000, 2 * 4096 + 40] {
        let (k, q, mass, fixed, couplings) = coupled_chain(n);
        let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &couplings };
        let jacobi = Preconditioner::BlockJacobi(a.block_jacobi());
        let mut recycled = Recycled::default();
        for phase in [0.0, 0.05, 0.1, 0.15, 0.2, 0.25] {
            let mut x = vec![DVec3::ZERO; n];
            pcg_deflated(&a, &jacobi, &wave(n, phase), &mut x, 1e-8, 5000, None);
            recycled.remember(&x, 8);
        }
        let b = wave(n, 0.3);
        let solve_on = |threads: usize, deflation: Option<&Recycled>| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| solved(&a, &jacobi, &b, deflation))
        };
        let (plain, plain_iterations) = solve_on(2, None);
        let (one, deflated_iterations) = solve_on(1, Some(&recycled));
        let (two, _) = solve_on(2, Some(&recycled));
        assert_eq!(one, two, "{n} rows: one thread and two");
        assert!(deflated_iterations < plain_iterations, "{n} rows: deflated {deflated_iterations} against plain {plain_iterations} iterations");
        for x in [&plain, &two] {
            let residual = relative_residual(&a, x, &b);
            assert!(residual < 2e-8, "{n} rows: {residual}");
        }
    }
}

/// Deflated CG from zero to a relative residual of 1e-8 (at most 5 000 iterations): the
/// solution and the iterations it took, the solve asserted to have met the tolerance
/// without meeting negative curvature.
fn solved(a: &SystemMatrix, preconditioner: &Preconditioner, b: &[DVec3], recycled: Option<&Recycled>) -> (Vec<DVec3>, usize) {
    let mut x = vec![DVec3::ZERO; b.len()];
    let report = pcg_deflated(a, preconditioner, b, &mut x, 1e-8, 5000, recycled);
    assert!(!report.negative_curvature && report.relative_residual <= 1e-8, "{report:?}");
    (x, report.iterations)
}

/// |b − A x| / |b| over the free vertices, by the product: independent of the solver's own
/// residual.
fn relative_residual(a: &SystemMatrix, x: &[DVec3], b: &[DVec3]) -> f64 {
    let mut ax = vec![DVec3::ZERO; x.len()];
    a.apply(x, &mut ax);
    let norm = |v: &mut dyn Iterator<Item = DVec3>| v.map(|e| e.length_squared()).sum::<f64>().sqrt();
    norm(&mut ax.iter().zip(b).zip(a.fixed).map(|((p, q), &f)| if f { DVec3::ZERO } else { *p - *q })) / norm(&mut b.iter().zip(a.fixed).map(|(q, &f)| if f { DVec3::ZERO } else { *q }))
}

/// Recycled directions that nearly repeat one another (as a run's last Newton directions do
/// near rest: WᵀAW's pivots down to 1e-7 of its diagonal) still deflate: the solve converges
/// in fewer iterations than plain CG, as with well-separated directions. Kept, such
/// columns make the projection inexact, and the residual grew steadily to 10³ times the
/// right-hand side's, in double precision too.
#[test]
fn deflated_cg_converges_with_nearly_repeated_directions() {
    let n = 600;
    let (k, q, mass, fixed, couplings) = coupled_chain(n);
    let a = SystemMatrix { mass_diagonal: &mass, stiffness: &k, bending: Some(&q), fixed: &fixed, couplings: &couplings };
    let jacobi = Preconditioner::BlockJacobi(a.block_jacobi());
    let solve = |b: &[DVec3], recycled: Option<&Recycled>| solved(&a, &jacobi, b, recycled);
    let mut recycled = Recycled::default();
    let (x0, _) = solve(&wave(n, 0.0), None);
    let (x1, _) = solve(&wave(n, 0.05), None);
    let unit = |x: &[DVec3]| {
        let norm = x.iter().map(|v| v.length_squared()).sum::<f64>().sqrt();
        x.iter().map(|v| *v / norm).collect::<Vec<_>>()
    };
    let (u0, u1) = (unit(&x0), unit(&x1));
    let columns: Vec<Vec<DVec3>> = (0..8)
        .map(|j| {
            // The same direction again and again, each time with a little of another in it.
            let epsilon = 3e-4 * (j as f64 + 1.0);
            u0.iter().zip(&u1).enumerate().map(|(i, (p, q))| *p + epsilon * (*q + DVec3::splat((i as f64 * 0.37 * (j as f64 + 1.0)).sin()) * 1e-3)).collect()
        })
        .collect();
    for column in &columns {
        recycled.remember(column, 8);
    }
    // As badly conditioned as a run's near rest: the pivots of CᵀAC's Cholesky factor, as
    // shares of its diagonal, fall far below 1e-5.
    let products: Vec<Vec<DVec3>> = columns
        .iter()
        .map(|c| {
            let mut ac = vec![DVec3::ZERO; n];
            a.apply(c, &mut ac);
            ac
        })
        .collect();
    let free = |c: &[DVec3], d: &[DVec3]| c.iter().zip(d).zip(&fixed).filter(|(_, f)| !**f).map(|((x, y), _)| x.dot(*y)).sum::<f64>();
    let gram: Vec<Vec<f64>> = columns.iter().map(|c| products.iter().map(|ad| free(c, ad)).collect()).collect();
    let mut l = vec![vec![0.0; 8]; 8];
    let mut worst_pivot = 1.0_f64;
    for j in 0..8 {
        let pivot = gram[j][j] - (0..j).map(|s| l[j][s] * l[j][s]).sum::<f64>();
        worst_pivot = worst_pivot.min(pivot / gram[j][j]);
        l[j][j] = pivot.sqrt();
        for i in j + 1..8 {
            l[i][j] = (gram[i][j] - (0..j).map(|s| l[i][s] * l[j][s]).sum::<f64>()) / l[j][j];
        }
    }
    assert!(worst_pivot < 1e-5, "the columns should nearly repeat: worst pivot ratio {worst_pivot:e}");
    let b = wave(n, 0.1);
    let (plain, plain_iterations) = solve(&b, None);
    let (deflated, deflated_iterations) = solve(&b, Some(&recycled));
    for x in [&plain, &deflated] {
        let residual = relative_residual(&a, x, &b);
        assert!(residual < 2e-8, "{residual}");
    }
    assert!(deflated_iterations < plain_iterations, "deflated {deflated_iterations} against plain {plain_iterations} iterations");
}
