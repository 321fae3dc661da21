//! Test rigs: how each laboratory test holds and drives the cloth, and what it measures.

use super::measures::{ArcMeasures, CantileverMeasures, DrapeMeasures, EulerMeasures, Measures, ShearMeasures, TensileMeasures};
use crate::settings::ShearKinematics;
use super::strip::{Columns, count_half_waves, fit_circle_radius, group_force, vertices_where};
use super::{SceneConfig, SceneError, SceneKind, drape};
use crate::physics::{STANDARD_GRAVITY, bending_length, cantilever_lambda, weight_per_area};
use crate::sim::{Model, Motion, State};
use glam::{DVec2, DVec3};

/// Rest coordinates are compared with this tolerance when picking edge vertices, m.
const ON_EDGE: f64 = 1e-9;

pub enum Rig {
    Tensile(Tensile),
    Cantilever(Cantilever),
    Arc(Arc),
    Euler(Euler),
    Shear(Shear),
    Drape(Drape),
    Garment(Box<super::garment::rig::GarmentRig>),
    Swing(super::swing::Swing),
}

pub struct Drape {
    /// Centre of the support, where the outline's radius is measured from.
    centre: DVec2,
    /// Area of the support (pedestal disc or table top), m².
    support_area: f64,
    /// Area of the flat specimen (its mesh), m².
    specimen_area: f64,
    /// Smallest prominence of a fold, m.
    prominence: f64,
    /// (t, drape coefficient, nodes) while the cloth drapes.
    history: Vec<(f64, f64, usize)>,
}

/// Largest out-of-balance load on the free vertices, Σ|f_i| over the Euler load's total
/// P_cr·w, at which an Euler-buckling sample counts as quasi-static.
///
/// As in dynamic relaxation, a state is static when the force left unbalanced on its free
/// vertices (what accelerates them, or is damped) is small against the load the structure
/// carries. By the momentum balance of each half of the strip, the end force then differs
/// from the force carried through the midspan by less than 2 % of P_cr, and the shape is
/// close to an equilibrium at the current end shortening, which is what the elastica
/// describes. The bundled scene's fast compression (10 % in 0.2 s, under half the first
/// mode's period) is never quasi-static by this measure (Σ|f_i| is 5–15 P_cr·w); its hold
/// becomes so once the ringing has decayed, within 1 % of its final force.
pub const QUASI_STATIC_IMBALANCE: f64 = 0.02;

/// Simulated seconds between the drape history's samples.
const DRAPE_SAMPLE_INTERVAL: f64 = 0.01;

/// Outline smoothing for node counting: about 6°, less than half the spacing of 10 nodes.
const NODE_SMOOTHING: f64 = 0.1;

impl Drape {
    fn measure(&self, model: &Model, state: &State, resolution: usize) -> (drape::Shadow, f64, usize) {
        let shadow = drape::shadow(&state.x, &model.triangles, self.centre, resolution);
        let dc = drape::drape_coefficient(shadow.area, self.specimen_area, self.support_area);
        let nodes = drape::count_nodes(&shadow.outline, NODE_SMOOTHING, self.prominence);
        (shadow, dc, nodes)
    }
}

pub struct Tensile {
    moving: Vec<u32>,
    width: f64,
    length: f64,
    /// Extensometer gauge marks: columns at a quarter and three quarters of the length.
    gauge: (Vec<u32>, Vec<u32>),
    gauge_rest_length: f64,
    /// The two edge vertices of the middle cross-section, for the lateral contraction.
    mid_edges: (u32, u32),
    /// (clamp strain, extensometer strain, lateral strain, stress N/m).
    samples: Vec<[f64; 4]>,
}

pub struct Cantilever {
    columns: Columns,
    length: f64,
}

pub struct Arc {
    columns: Columns,
    length: f64,
    width: f64,
    grip: Vec<u32>,
}

pub struct Euler {
    left: Vec<u32>,
    right: Vec<u32>,
    columns: Columns,
    width: f64,
    length: f64,
    /// (t, end shortening fraction, end force N/m, amplitude m, lobes, out-of-balance force
    /// over the Euler load).
    history: Vec<(f64, f64, f64, f64, usize, f64)>,
    speed: f64,
}

impl Euler {
    /// The Euler load of the pinned strip, π²B_θ/L² (N/m), B_θ across the strip's length.
    fn euler_load(&self, model: &Model) -> f64 {
        std::f64::consts::PI.powi(2) * model.bending_stiffness.rigidity_at(-model.warp_angle) / self.length.powi(2)
    }
}

pub struct Shear {
    moving: Vec<u32>,
    width: f64,
    length: f64,
}

impl Rig {
    /// Pins and drives the rig's vertices on `model` and prepares its measurements.
    pub fn attach(config: &SceneConfig, model: &mut Model, x: &[DVec3], clamp_band: f64) -> Result<Self, SceneError> {
        let (length, width, h) = (config.cloth.length, config.cloth.width, config.mesh.edge_length);
        let rest = model.rest.clone();
        let t = &config.test;
        let pin_all = |model: &mut Model, group: &[u32]| {
            for &v in group {
                model.pin(v, x[v as usize]);
            }
        };
        Ok(match config.scene.kind {
            SceneKind::Drape => {
                let centre = DVec2::new(config.cloth.position[0], config.cloth.position[1]);
                if let Some(radius) = t.clamp_radius {
                    let rigid: Vec<bool> = rest.iter().map(|p| p.length() <= radius * (1.0 + 1e-9)).collect();
                    for (v, _) in rigid.iter().enumerate().filter(|(_, r)| **r) {
                        model.pin(v as u32, x[v]);
                    }
                    model.set_clamped_region(&rigid)?;
                }
                let support_area = match (t.support_diameter, t.support_size) {
                    (Some(d), _) => std::f64::consts::PI * d * d / 4.0,
                    (None, Some([a, b])) => a * b,
                    (None, None) => unreachable!("checked when loading"),
                };
                let specimen_area: f64 = model.vertex_area.iter().sum();
                let reach = |area: f64| (area / std::f64::consts::PI).sqrt();
                let prominence = 0.03 * (reach(specimen_area) - reach(support_area)).max(h);
                Rig::Drape(Drape { centre, support_area, specimen_area, prominence, history: Vec::new() })
            }
            SceneKind::Tensile => {
                let fixed = vertices_where(&rest, |p| p.x < ON_EDGE);
                let moving = vertices_where(&rest, |p| p.x > length - ON_EDGE);
                let speed = t.speed.expect("checked when loading");
                let stop = crate::settings::validate::motion_time(config).expect("checked when loading").1;
                pin_all(model, &fixed);
                model.drive(&moving, x, Motion::Linear { velocity: DVec3::new(speed, 0.0, 0.0), start: 0.0, stop });
                let columns = Columns::new(&rest, length, h);
                let (lo, hi) = (columns.nearest(0.25 * length), columns.nearest(0.75 * length));
                let gauge_rest_length = columns.rest_x[hi] - columns.rest_x[lo];
                let mid = &columns.vertices[columns.nearest(0.5 * length)];
                let bottom = *mid.iter().min_by(|a, b| rest[**a as usize].y.total_cmp(&rest[**b as usize].y)).unwrap();
                let top = *mid.iter().max_by(|a, b| rest[**a as usize].y.total_cmp(&rest[**b as usize].y)).unwrap();
                Rig::Tensile(Tensile {
                    moving,
                    width,
                    length,
                    gauge: (columns.vertices[lo].clone(), columns.vertices[hi].clone()),
                    gauge_rest_length,
                    mid_edges: (bottom, top),
                    samples: Vec::new(),
                })
            }
            SceneKind::Cantilever | SceneKind::Arc => {
                let clamp = vertices_where(&rest, |p| p.x < ON_EDGE);
                pin_all(model, &clamp);
                let mut rigid = vec![false; rest.len()];
                clamp.iter().for_each(|&v| rigid[v as usize] = true);
                let free: Vec<DVec2> = rest.iter().map(|p| DVec2::new(p.x + clamp_band, p.y)).collect();
                let mut columns = Columns::new(&free, length + 2.0 * clamp_band, h);
                for x in &mut columns.rest_x {
                    *x -= clamp_band;
                }
                let rig = if config.scene.kind == SceneKind::Cantilever {
                    Rig::Cantilever(Cantilever { columns, length })
                } else {
                    // Pure bending: the far grip rolls the strip into an arc of the target
                    // curvature over the first half of the run, then holds while it settles.
                    let grip = vertices_where(&rest, |p| p.x > length - ON_EDGE);
                    grip.iter().for_each(|&v| rigid[v as usize] = true);
                    let curvature = t.curvature.expect("checked when loading");
                    model.drive(&grip, x, Motion::Roll { length, curvature, ramp: 0.5 * config.scene.duration });
                    Rig::Arc(Arc { columns, length, width, grip })
                };
                model.set_clamped_region(&rigid)?;
                rig
            }
            SceneKind::EulerBuckling => {
                let left = vertices_where(&rest, |p| p.x < ON_EDGE);
                let right = vertices_where(&rest, |p| p.x > length - ON_EDGE);
                let speed = t.speed.expect("checked when loading");
                let stop = crate::settings::validate::motion_time(config).expect("checked when loading").1;
                // Both ends move, each at half the approach speed, so the midspan stays put.
                model.drive(&left, x, Motion::Linear { velocity: DVec3::new(0.5 * speed, 0.0, 0.0), start: 0.0, stop });
                model.drive(&right, x, Motion::Linear { velocity: DVec3::new(-0.5 * speed, 0.0, 0.0), start: 0.0, stop });
                let columns = Columns::new(&rest, length, h);
                Rig::Euler(Euler { left, right, columns, width, length, history: Vec::new(), speed })
            }
            SceneKind::Garment => return Err(SceneError::Setup("garment scenes build their own rig (scene::garment)".into())),
            SceneKind::Swing => Rig::Swing(super::swing::Swing::attach(config, model, x, STANDARD_GRAVITY)?),
            SceneKind::ShearBuckling => {
                let clamped = vertices_where(&rest, |p| p.y < ON_EDGE);
                let moving = vertices_where(&rest, |p| p.y > width - ON_EDGE);
                let speed = t.speed.expect("checked when loading");
                let stop = crate::settings::validate::motion_time(config).expect("checked when loading").1;
                pin_all(model, &clamped);
                let motion = match t.shear_kinematics.unwrap_or_default() {
                    // The moving grip slides along the warp; the gap stays, so the cross yarns stretch.
                    ShearKinematics::Simple => Motion::Linear { velocity: DVec3::new(speed, 0.0, 0.0), start: 0.0, stop },
                    // The moving grip swings on the cross yarns, which keep their length.
                    ShearKinematics::Trellis => Motion::Swing { radius: width, angular_speed: speed / width, stop },
                };
                model.drive(&moving, x, motion);
                Rig::Shear(Shear { moving, width, length })
            }
        })
    }

    /// Records one sample of the rig's time series.
    pub fn sample(&mut self, model: &Model, state: &State) {
        match self {
            Rig::Tensile(r) => {
                let mut f = vec![DVec3::ZERO; state.x.len()];
                model.forces(&state.x, &mut f);
                // The cloth pulls the moving clamp back (−x); the clamp carries the opposite.
                let stress = -group_force(&f, &r.moving).x / r.width;
                let clamp_strain = (model.prescribed_position(r.moving[0] as usize, state.time).x - r.length) / r.length;
                let mean_x = |g: &[u32]| g.iter().map(|&v| state.x[v as usize].x).sum::<f64>() / g.len() as f64;
                let extensometer = (mean_x(&r.gauge.1) - mean_x(&r.gauge.0)) / r.gauge_rest_length - 1.0;
                let (b, t) = r.mid_edges;
                let lateral = (state.x[t as usize].y - state.x[b as usize].y) / r.width - 1.0;
                r.samples.push([clamp_strain, extensometer, lateral, stress]);
            }
            Rig::Drape(r) => {
                // Rasterising the shadow costs as much as a Newton iteration on the paper's
                // mesh: the history is taken every DRAPE_SAMPLE_INTERVAL, not every step.
                if r.history.last().is_some_and(|h| state.time < h.0 + DRAPE_SAMPLE_INTERVAL - 1e-9) {
                    return;
                }
                let (_, dc, nodes) = r.measure(model, state, 256);
                r.history.push((state.time, dc, nodes));
            }
            Rig::Euler(r) => {
                let mut f = vec![DVec3::ZERO; state.x.len()];
                model.forces(&state.x, &mut f);
                // Compressed cloth pushes the left end towards −x and the right end towards +x.
                let force = 0.5 * (-group_force(&f, &r.left).x + group_force(&f, &r.right).x) / r.width;
                let span = model.prescribed_position(r.right[0] as usize, state.time).x
                    - model.prescribed_position(r.left[0] as usize, state.time).x;
                let shortening = 1.0 - span / r.length;
                let line = r.columns.centre_line(&state.x);
                let z: Vec<f64> = line.iter().map(|p| p.z).collect();
                let amplitude = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                // The load left unbalanced on the free vertices, what accelerates them (or is
                // damped): zero in static equilibrium. See QUASI_STATIC_IMBALANCE.
                let unbalanced: f64 = f.iter().zip(&model.fixed).filter(|(_, fixed)| !**fixed).map(|(fi, _)| fi.length()).sum();
                let imbalance = unbalanced / (r.euler_load(model) * r.width);
                r.history.push((state.time, shortening, force, amplitude, count_half_waves(&z, 0.2), imbalance));
            }
            Rig::Swing(r) => r.sample(state),
            _ => {}
        }
    }

    /// Takes over the time series of `earlier`, the same rig on a coarser level of the fast
    /// path, so that the history runs from the start of the scene.
    pub fn continue_history(&mut self, earlier: Rig) {
        match (self, earlier) {
            (Rig::Drape(r), Rig::Drape(e)) => r.history.splice(0..0, e.history).for_each(drop),
            (Rig::Euler(r), Rig::Euler(e)) => r.history.splice(0..0, e.history).for_each(drop),
            _ => {}
        }
    }

    /// The rig's measurements at the end of the run.
    pub fn finish(&self, model: &Model, state: &State) -> Measures {
        match self {
            Rig::Tensile(r) => {
                // A few dozen evenly spaced points of the pull.
                let stride = (r.samples.len() / 40).max(1);
                let picked: Vec<&[f64; 4]> = r.samples.iter().step_by(stride).collect();
                let last = r.samples.last().copied().unwrap_or([0.0; 4]);
                let poisson = if last[1].abs() > 0.0 { -last[2] / last[1] } else { 0.0 };
                Measures::Tensile(TensileMeasures {
                    stress_strain: picked.iter().map(|s| [s[1], s[3]]).collect(),
                    clamp_stress_strain: picked.iter().map(|s| [s[0], s[3]]).collect(),
                    lateral_strain: picked.iter().map(|s| [s[1], s[2]]).collect(),
                    poisson_ratio: poisson,
                    final_stress: last[3],
                    final_strain: last[1],
                    strain_definition: TensileMeasures::STRAIN_DEFINITION.to_string(),
                })
            }
            Rig::Cantilever(r) => {
                let line = r.columns.centre_line(&state.x);
                let n = line.len();
                let (tip, before) = (line[n - 1], line[n - 2]);
                let drop = -tip.z;
                let tangent = tip - before;
                let weight = weight_per_area(model.mass.iter().sum::<f64>() / model.vertex_area.iter().sum::<f64>());
                let b = model.bending_stiffness.rigidity_at(-model.warp_angle);
                Measures::Cantilever(CantileverMeasures {
                    tip_drop: drop,
                    tip_reach: tip.x,
                    tip_angle_deg: (-tangent.z).atan2(tangent.x).to_degrees(),
                    chord_angle_deg: drop.atan2(tip.x).to_degrees(),
                    lambda: cantilever_lambda(weight, r.length, b),
                    bending_length: bending_length(b, weight),
                })
            }
            Rig::Arc(r) => {
                let line = r.columns.centre_line(&state.x);
                let points: Vec<(f64, f64)> = r
                    .columns
                    .rest_x
                    .iter()
                    .zip(&line)
                    .filter(|(x, _)| **x >= 0.25 * r.length && **x <= 0.75 * r.length)
                    .map(|(_, p)| (p.x, p.z))
                    .collect();
                let curvature = fit_circle_radius(&points).map_or(0.0, |radius| 1.0 / radius);
                // Bending moment per unit width at the midspan section, where the curvature is
                // fitted: by the balance of the half strip between it and the grip, it is the
                // moment of the grip's forces about the midspan centre line. (About the grip
                // line instead, any residual axial force would add itself times the arc's
                // sagitta.)
                let mut f = vec![DVec3::ZERO; state.x.len()];
                model.forces(&state.x, &mut f);
                let pivot = line[r.columns.nearest(0.5 * r.length)];
                let torque: f64 = r.grip.iter().map(|&v| (state.x[v as usize] - pivot).cross(f[v as usize]).y).sum();
                let moment = torque / r.width;
                Measures::Arc(ArcMeasures { curvature, moment, rigidity: (curvature > 0.0).then(|| moment / curvature) })
            }
            Rig::Euler(r) => {
                let critical = r.history.iter().find(|h| h.3 > 0.05 * r.length).map(|h| h.2);
                let line = r.columns.centre_line(&state.x);
                let mid = r.columns.nearest(0.5 * r.length);
                let last = r.history.last().copied().unwrap_or_default();
                let (quasi_static, dynamic): (Vec<_>, Vec<_>) = r.history.iter().partition(|h| h.5 < QUASI_STATIC_IMBALANCE);
                let force_curve = |samples: &[&(f64, f64, f64, f64, usize, f64)]| -> Vec<[f64; 2]> {
                    samples.iter().step_by((samples.len() / 100).max(1)).map(|h| [h.1, h.2]).collect()
                };
                // Lobe history as (t, lobes) at each change.
                let mut lobe_history: Vec<(f64, usize)> = Vec::new();
                for h in &r.history {
                    if h.3 > 1e-3 * r.length && lobe_history.last().is_none_or(|l| l.1 != h.4) {
                        lobe_history.push((h.0, h.4));
                    }
                }
                Measures::Euler(EulerMeasures {
                    critical_load: critical,
                    critical_load_definition: EulerMeasures::CRITICAL_LOAD_DEFINITION.to_string(),
                    euler_load: r.euler_load(model),
                    end_force: last.2,
                    end_shortening: last.1,
                    midspan_deflection: line[mid].z.abs(),
                    lobes: last.4,
                    lobe_history,
                    compression_speed: r.speed,
                    out_of_balance: last.5,
                    out_of_balance_definition: EulerMeasures::OUT_OF_BALANCE_DEFINITION.to_string(),
                    quasi_static_force: force_curve(&quasi_static),
                    dynamic_force: force_curve(&dynamic),
                    force_history: r.history.iter().step_by((r.history.len() / 100).max(1)).map(|h| [h.0, h.1, h.2, h.3]).collect(),
                })
            }
            Rig::Shear(r) => Measures::Shear(shear_measures(r, model, state)),
            Rig::Garment(r) => Measures::Garment(r.finish(model, state)),
            Rig::Swing(r) => Measures::Swing(r.finish()),
            Rig::Drape(r) => {
                let (shadow, dc, nodes) = r.measure(model, state, 1024);
                let radius_min = shadow.outline.iter().map(|o| o.1).fold(f64::INFINITY, f64::min);
                Measures::Drape(DrapeMeasures {
                    drape_coefficient: dc,
                    nodes,
                    shadow_area: shadow.area,
                    specimen_area: r.specimen_area,
                    support_area: r.support_area,
                    // None when the outline is empty.
                    outline_radius_min: radius_min.is_finite().then_some(radius_min),
                    outline_radius_max: shadow.outline.iter().map(|o| o.1).fold(0.0, f64::max),
                    history: r.history.iter().step_by((r.history.len() / 100).max(1)).copied().collect(),
                })
            }
        }
    }

    /// The drape's shadow outline, (angle rad, radius m); None for other rigs.
    pub fn outline(&self, model: &Model, state: &State) -> Option<Vec<(f64, f64)>> {
        match self {
            Rig::Drape(r) => Some(r.measure(model, state, 1024).0.outline),
            Rig::Garment(r) => Some(r.outline(model, state)),
            _ => None,
        }
    }
}

/// Wrinkle direction, count and wavelength from the normal deflection field.
fn shear_measures(r: &Shear, model: &Model, state: &State) -> ShearMeasures {
    // Angle between the deformed cross direction (clamp to grip) and its rest direction.
    let grip = state.x[r.moving[0] as usize] - DVec3::new(model.rest[r.moving[0] as usize].x, 0.0, 0.0);
    let shear_angle = grip.x.atan2(grip.y);
    // Structure tensor of the deflection gradient over the central region, in the deformed
    // plane: wrinkle crests run across the dominant gradient direction.
    let inside = |p: DVec2| p.y > 0.15 * r.width && p.y < 0.85 * r.width && p.x > 0.15 * r.length && p.x < 0.85 * r.length;
    let mut j = [0.0f64; 3];
    let mut amplitude = 0.0f64;
    for tri in &model.triangles {
        let rest_c = tri.iter().map(|&v| model.rest[v as usize]).sum::<DVec2>() / 3.0;
        if !inside(rest_c) {
            continue;
        }
        let p = tri.map(|v| state.x[v as usize]);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let det = e1.x * e2.y - e2.x * e1.y;
        if det.abs() < 1e-14 {
            continue;
        }
        // Gradient of the linear interpolant of z over the triangle's xy projection.
        let (dz1, dz2) = (e1.z, e2.z);
        let gx = (dz1 * e2.y - dz2 * e1.y) / det;
        let gy = (dz2 * e1.x - dz1 * e2.x) / det;
        let area = 0.5 * det.abs();
        j[0] += area * gx * gx;
        j[1] += area * gy * gy;
        j[2] += area * gx * gy;
        for q in &p {
            amplitude = amplitude.max(q.z.abs());
        }
    }
    // Principal direction of the larger eigenvalue of [[j0, j2], [j2, j1]].
    let gradient_angle = 0.5 * (2.0 * j[2]).atan2(j[0] - j[1]);
    let crest_angle = (gradient_angle + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI);
    // Sample z along the line through the centre across the crests.
    let centre = state.x.iter().sum::<DVec3>() / state.x.len() as f64;
    let across = DVec2::from_angle(gradient_angle);
    let half = 0.5 * r.length.min(r.width / crest_angle.sin().abs().max(0.2));
    let samples = 240;
    let mut profile = Vec::with_capacity(samples);
    for k in 0..samples {
        let s = -half + 2.0 * half * k as f64 / (samples - 1) as f64;
        let q = DVec2::new(centre.x, centre.y) + s * across;
        if let Some(z) = interpolate_z(model, state, q) {
            profile.push((s, z - centre.z));
        }
    }
    let zs: Vec<f64> = profile.iter().map(|p| p.1).collect();
    let half_waves = count_half_waves(&zs, 0.2);
    let span = profile.last().map_or(0.0, |p| p.0) - profile.first().map_or(0.0, |p| p.0);
    let wavelength = if half_waves >= 2 { 2.0 * span / half_waves as f64 } else { 0.0 };
    ShearMeasures {
        shear_angle_deg: shear_angle.to_degrees(),
        wrinkle_angle_deg: crest_angle.to_degrees(),
        wrinkle_count: half_waves.div_ceil(2),
        wrinkle_wavelength: wavelength,
        wrinkle_amplitude: amplitude,
    }
}

/// z of the deformed surface above the point `q` of the xy plane (first triangle found).
fn interpolate_z(model: &Model, state: &State, q: DVec2) -> Option<f64> {
    for tri in &model.triangles {
        let p = tri.map(|v| state.x[v as usize]);
        let (a, b, c) = (p[0].truncate(), p[1].truncate(), p[2].truncate());
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-14 {
            continue;
        }
        let la = (b - q).perp_dot(c - q) / area;
        let lb = (c - q).perp_dot(a - q) / area;
        let lc = 1.0 - la - lb;
        if la >= -1e-9 && lb >= -1e-9 && lc >= -1e-9 {
            return Some(la * p[0].z + lb * p[1].z + lc * p[2].z);
        }
    }
    None
}
