//! The Cusick drape test (docs/references.md §7, paper Fig. 6): drape coefficients inside
//! the ranges measured on real fabrics and above the independent-strip bound, ordered by
//! bending length, agreeing between resolved meshes and between random starts, with 4–10
//! folds, no self-intersection and no penetration of the pedestal. The figures these tests
//! print are recorded in docs/drape.md.

mod common;

use common::reference::{bending_rigidity_theta, independent_strip_drape_lower_bound};
use common::{drape_coefficient, run, run_all};
use rosette::scene::SceneConfig;

/// Bending length c = (B/w)^(1/3) with B the mean of warp and weft rigidities.
fn bending_length(c: &SceneConfig) -> f64 {
    (0.5 * (c.fabric.properties.bending_warp + c.fabric.properties.bending_weft) / (c.fabric.properties.areal_density * rosette::physics::STANDARD_GRAVITY)).cbrt()
}

/// Ranges of drape coefficient measured on real fabrics (docs/references.md §7): limp silks
/// 0.2–0.4, shirtings and light wools 0.4–0.7, denims 0.7–0.9. The light filament polyester is
/// softer than a shirting and stiffer than a silk crepe; the reference gives no class for
/// it, so it is held to the span of the two classes around it.
const MEASURED: [(&str, f64, f64); 5] =
    [("silk", 0.2, 0.4), ("polyester", 0.2, 0.7), ("cotton-shirting", 0.4, 0.7), ("wool", 0.4, 0.7), ("denim", 0.7, 0.9)];

/// The whole bundled library with its classes (docs/references.md §7): the five fabrics above and
/// the seven from measurement sheets (presets/fabrics, issue 26): the wools and cottons are
/// light wools and shirtings, the 14 oz denim a denim.
const LIBRARY: [(&str, f64, f64); 12] = [
    MEASURED[0],
    MEASURED[1],
    MEASURED[2],
    MEASURED[3],
    MEASURED[4],
    ("wool-plain-fast", 0.4, 0.7),
    ("wool-worsted", 0.4, 0.7),
    ("wool-flannel", 0.4, 0.7),
    ("cotton-poplin", 0.4, 0.7),
    ("cotton-oxford", 0.4, 0.7),
    ("cotton-lawn", 0.4, 0.7),
    ("denim-14oz", 0.7, 0.9),
];

/// Every bundled fabric on the paper's scene: it settles with every Newton solve converged,
/// folds into 4–10 nodes, stays out of the pedestal and itself, and drapes less than a disc
/// (DC < 1) but more stiffly than independent radial strips could (the strip bound of
/// docs/references.md §7). On 10.3 mm
/// edges: the paper's 15.5 mm edges are longer than silk's bending length (12 mm), too
/// coarse for its folds, which there come out an element or two wide (docs/drape.md).
#[test]
fn every_fabric_settles_into_clean_folds_above_the_strip_bound() {
    let results = run_all(
        "cusick-drape",
        MEASURED.iter().map(|(f, _, _)| vec![format!("fabric.preset={f}"), "mesh.edge_length=0.0103".into()]).collect(),
    );
    for ((fabric, _, _), (config, m)) in MEASURED.iter().zip(&results) {
        let dc = drape_coefficient(m);
        let nodes = m.measures.drape().expect("drape measures").nodes;
        println!("{fabric}: DC {dc:.3}, {nodes} nodes, settled at {:?} s", m.settle_time);
        assert_eq!(m.settled, Some(true), "{fabric} never settled");
        // Every Newton solve converged at the default iteration limit (the limit was raised
        // to 60 when a limp fabric's landing needed 46).
        assert!(m.converged && m.newton_limit_steps == 0, "{fabric}: {} steps at the Newton limit, worst {:e}", m.newton_limit_steps, m.worst_residual);
        let bound = strip_bound(config);
        assert!(dc > bound && dc < 1.0, "{fabric}: DC {dc:.3} outside ({bound:.3}, 1)");
        assert!((4..=10).contains(&nodes), "{fabric}: {nodes} nodes");
        assert_eq!(m.self_intersections, Some(0), "{fabric}");
        assert!(m.max_penetration.unwrap() < config.contact.thickness, "{fabric}: {:?}", m.max_penetration);
    }
}

/// The strip bound with the most flexible direction's rigidity, so that no radial strip of
/// the specimen is stiffer than the one it assumes.
fn strip_bound(config: &SceneConfig) -> f64 {
    let f = &config.fabric.properties;
    // Paper eq. 3's middle term, from the bias rigidity or 2νB_x + G h²/3.
    let mid = match f.bending_bias {
        Some(bias) => 4.0 * bias - f.bending_warp - f.bending_weft,
        None => 2.0 * f.poisson_warp * f.bending_warp + f.shear_modulus * f.thickness * f.thickness / 3.0,
    };
    let b_min = (0..=90)
        .map(|d| bending_rigidity_theta(f.bending_warp, f.bending_weft, mid, (d as f64).to_radians()))
        .fold(f64::INFINITY, f64::min);
    independent_strip_drape_lower_bound(config.cloth.diameter, 0.18, f.areal_density, b_min, rosette::physics::STANDARD_GRAVITY)
}

/// Measured ranges and the bending-length order, on the standard's 30 cm specimen: the
/// classes of docs/references.md §7 are what the standard test (BS 5058) measures, and the
/// drape coefficient depends on the specimen's size: the paper's 36 cm disc hangs further
/// and reads lower (docs/drape.md). Every bundled fabric is held to its class; the figures
/// are in docs/fabrics/README.md.
#[test]
fn each_fabric_drapes_within_its_measured_range_in_bending_length_order() {
    let results =
        run_all("cusick-drape-30", LIBRARY.iter().map(|(f, _, _)| vec![format!("fabric.preset={f}")]).collect());
    let mut by_length = Vec::new();
    for ((fabric, lo, hi), (config, m)) in LIBRARY.iter().zip(&results) {
        let dc = drape_coefficient(m);
        println!(
            "{fabric}: DC {dc:.3}, {} nodes, bending length {:.1} mm, strip bound {:.3}",
            m.measures.drape().expect("a drape").nodes,
            1e3 * bending_length(config),
            strip_bound(config)
        );
        assert!(dc > strip_bound(config), "{fabric}: DC {dc:.3} below the strip bound");
        assert!((*lo..=*hi).contains(&dc), "{fabric}: DC {dc:.3} outside the measured {lo}–{hi}");
        by_length.push((bending_length(config), dc, *fabric));
    }
    // Stiffer fabric, higher coefficient, wherever bending lengths differ by more than 5 %
    // (wool and the cotton shirting have the same bending length to 0.3 %).
    by_length.sort_by(|a, b| a.0.total_cmp(&b.0));
    for i in 0..by_length.len() {
        for j in i + 1..by_length.len() {
            let (a, b) = (by_length[i], by_length[j]);
            if b.0 > 1.05 * a.0 {
                assert!(b.1 > a.1, "{} (c = {:.4} m, DC {:.3}) drapes less than {} (c = {:.4} m, DC {:.3})", b.2, b.0, b.1, a.2, a.0, a.1);
            }
        }
    }
}

/// A limp fabric landing on the pedestal at 7.5 mm edges: silk's hardest step (t = 0.976 s)
/// takes 46 Newton iterations, and at the default iteration limit every step's solve
/// converges (at the old limit of 30 that step stopped 29 times above the tolerance and the
/// run was reported as not converged).
#[test]
fn a_limp_fabric_lands_with_every_newton_solve_converged() {
    let overrides = ["fabric.preset=silk", "mesh.edge_length=0.0075", "scene.duration=1.0"].map(String::from);
    let (config, m) = run("cusick-drape", &overrides);
    assert_eq!(config.solver.newton.max_iterations, rosette::sim::solver::DEFAULT_MAX_ITERATIONS);
    assert!(m.converged && m.newton_limit_steps == 0, "{} steps at the Newton limit, worst {:e}", m.newton_limit_steps, m.worst_residual);
}

/// Refining a resolved mesh by a factor 1.44 in edge length (7.5 mm, 3621 triangles, to
/// 5.2 mm, about 7600) moves the coefficient by less than 0.03. This is agreement between
/// resolved meshes, not independence of the mesh: the sub-element buckling cap depends on
/// the element size by construction, and the paper's 15.5 mm mesh, whose edge is near
/// wool's bending length (18 mm), reads higher (docs/drape.md, Convergence).
#[test]
fn drape_coefficient_agrees_between_two_resolved_meshes() {
    let results = run_all("cusick-drape", vec![vec!["mesh.edge_length=0.0075".into()], vec!["mesh.edge_length=0.0052".into()]]);
    let (coarse, fine) = (drape_coefficient(&results[0].1), drape_coefficient(&results[1].1));
    println!("DC {coarse:.3} ({} triangles), {fine:.3} ({} triangles)", results[0].1.triangles, results[1].1.triangles);
    assert!((coarse - fine).abs() < 0.03, "DC {coarse:.3} vs {fine:.3}");
}

#[test]
fn random_starts_scatter_the_coefficient_by_a_few_hundredths() {
    let results = run_all("cusick-drape", (1..=3).map(|seed| vec![format!("scene.seed={seed}")]).collect());
    let dcs: Vec<f64> = results.iter().map(|r| drape_coefficient(&r.1)).collect();
    let nodes: Vec<usize> = results.iter().map(|r| r.1.measures.drape().expect("drape measures").nodes).collect();
    println!("DC {dcs:?}, nodes {nodes:?}");
    let spread = dcs.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - dcs.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(spread < 0.05, "seeds scatter DC by {spread:.3}");
    assert!(dcs.windows(2).any(|w| w[0] != w[1]), "the seed changed nothing: the perturbation is not used");
}

/// The four wovens Wang, O'Brien and Ramamoorthi measured (ARCSim materials, issue 38) on
/// the standard's 30 cm specimen: they settle with every Newton solve converged, into 4–10
/// folds, out of the pedestal and themselves, between the independent-strip bound and a
/// flat disc. No drape coefficient of theirs was measured, so none is held to a class; nor
/// are they held to the bending-length order, which assumes linear bending: their moment
/// curves stiffen (the royal-target's warp by 72 % at 20 m⁻¹) or soften and recover (the
/// white-dots polyester's to 73 % at 10 m⁻¹). Their coefficients are in docs/fabrics/README.md.
#[test]
fn the_measured_arcsim_wovens_settle_into_clean_folds_above_the_strip_bound() {
    const WOVENS: [&str; 4] = ["11oz-black-denim", "royal-target", "white-dots-on-blk", "pink-ribbon-brown"];
    let results = run_all("cusick-drape-30", WOVENS.iter().map(|f| vec![format!("fabric.preset={f}")]).collect());
    for (fabric, (config, m)) in WOVENS.iter().zip(&results) {
        let dc = drape_coefficient(m);
        let nodes = m.measures.drape().expect("drape measures").nodes;
        // The strip bound with the lowest secant rigidity the fabric's moment curve reaches:
        // a softening curve makes the sheet more flexible than its first rigidity says.
        let softest = config.fabric.properties.bending_curve.as_ref().map_or(1.0, |c| {
            let slope = c[1][1] / c[1][0];
            c.iter().filter(|p| p[0] > 0.0).map(|p| p[1] / (p[0] * slope)).fold(1.0, f64::min)
        });
        let bound = strip_bound_scaled(config, softest);
        println!("{fabric}: DC {dc:.3}, {nodes} nodes, bending length {:.1} mm, strip bound {bound:.3}", 1e3 * bending_length(config));
        assert_eq!(m.settled, Some(true), "{fabric} never settled");
        assert!(m.converged && m.newton_limit_steps == 0, "{fabric}: {} steps at the Newton limit", m.newton_limit_steps);
        assert!(dc > bound && dc < 1.0, "{fabric}: DC {dc:.3} outside ({bound:.3}, 1)");
        assert!((4..=10).contains(&nodes), "{fabric}: {nodes} nodes");
        assert_eq!(m.self_intersections, Some(0), "{fabric}");
        assert!(m.max_penetration.unwrap() < config.contact.thickness, "{fabric}: {:?}", m.max_penetration);
    }
}

/// [`strip_bound`] with every rigidity scaled by `scale`.
fn strip_bound_scaled(config: &SceneConfig, scale: f64) -> f64 {
    let mut scaled = config.clone();
    let f = &mut scaled.fabric.properties;
    f.bending_warp *= scale;
    f.bending_weft *= scale;
    f.bending_bias = f.bending_bias.map(|b| b * scale);
    strip_bound(&scaled)
}
