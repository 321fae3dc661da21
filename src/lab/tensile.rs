//! KES-FB1 tensile: a strip pulled until the load reaches Fm = 500 gf/cm.

use super::{Direction, LabError, scene_config};
use crate::fabric::units::{GF_CM_PER_CM2, GF_PER_CM};
use crate::scene::Scene;
use crate::settings::FabricConfig;
use crate::scene::strip::Columns;
use glam::DVec3;

/// KES's load at the end of the pull, N/m (500 gf/cm).
pub const KES_FM: f64 = 500.0 * GF_PER_CM;

/// What the virtual KES tensile test reports (docs/references.md §8).
#[derive(Debug, Clone, PartialEq)]
pub struct KesTensile {
    pub direction: Direction,
    /// The load the pull stops at, N/m.
    pub fm: f64,
    /// Strain at Fm (EMT), a fraction.
    pub emt: f64,
    /// Tensile energy ∫F dε from no load to Fm (WT), J/m².
    pub wt: f64,
    /// Linearity WT / (Fm·EMT/2) (LT).
    pub lt: f64,
    /// The measured loading curve up to Fm, one point per step, [strain, N/m]: the
    /// extensometer's strain over the middle half of the strip, the clamp's load over its
    /// width.
    pub curve: Vec<[f64; 2]>,
}

impl KesTensile {
    /// EMT in %, as KES prints it.
    pub fn emt_percent(&self) -> f64 {
        100.0 * self.emt
    }

    /// WT in gf·cm/cm², as KES prints it.
    pub fn wt_kes(&self) -> f64 {
        self.wt / GF_CM_PER_CM2
    }

    /// The strain at a load (N/m) on the measured curve, e.g. FAST's E5, E20 and E100.
    pub fn strain_at(&self, load: f64) -> Option<f64> {
        let i = self.curve.iter().position(|p| p[1] >= load)?;
        if i == 0 {
            return Some(self.curve[0][0]);
        }
        let (a, b) = (self.curve[i - 1], self.curve[i]);
        Some(a[0] + (load - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
    }
}

/// Pulls a strip of `fabric` cut along `direction` on the `tensile-warp` rig (10 cm gauge,
/// 5 cm wide, 1 mm/s) until the load reaches Fm = 500 gf/cm, as KES-FB1 does, and reads
/// EMT, WT and LT by KES's definitions from the curve sampled every step. The load and
/// strain are those of the rig: the clamp's force over the strip's width, and the
/// extensometer between the columns at a quarter and three quarters of the length.
pub fn kes_tensile(fabric: &FabricConfig, direction: Direction) -> Result<KesTensile, LabError> {
    const TEST: &str = "KES tensile";
    // The clamp travels up to a 100 % strain; the test stops at Fm long before.
    let config = scene_config(TEST, "tensile-warp", fabric, |c| {
        c.cloth.warp_angle_deg = direction.warp_angle_deg();
        c.test.max_strain = Some(1.0);
        c.scene.duration = c.cloth.length / c.test.speed.unwrap_or(0.001);
        c.scene.settle_speed = None;
    })?;
    let (length, width, h) = (config.cloth.length, config.cloth.width, config.mesh.edge_length);
    let mut scene = Scene::new(config).map_err(|e| LabError::Setup { test: TEST, message: e.to_string() })?;
    let rest = scene.model.rest.clone();
    let moving: Vec<usize> = (0..rest.len()).filter(|&v| rest[v].x > length - 1e-9).collect();
    let columns = Columns::new(&rest, length, h);
    let (lo, hi) = (columns.nearest(0.25 * length), columns.nearest(0.75 * length));
    let gauge = columns.rest_x[hi] - columns.rest_x[lo];
    let mean_x = |x: &[DVec3], col: usize| columns.vertices[col].iter().map(|&v| x[v as usize].x).sum::<f64>() / columns.vertices[col].len() as f64;
    let mut curve = vec![[0.0, 0.0]];
    let mut f = vec![DVec3::ZERO; rest.len()];
    while scene.state.time < scene.config.scene.duration {
        scene.step().map_err(|e| LabError::Diverged { test: TEST, message: e.to_string() })?;
        f.iter_mut().for_each(|fi| *fi = DVec3::ZERO);
        scene.model.forces(&scene.state.x, &mut f);
        // The cloth pulls the moving clamp back (−x); the clamp carries the opposite.
        let load = -moving.iter().map(|&v| f[v].x).sum::<f64>() / width;
        let strain = (mean_x(&scene.state.x, hi) - mean_x(&scene.state.x, lo)) / gauge - 1.0;
        if load >= KES_FM {
            let a = *curve.last().expect("starts at the origin");
            let emt = a[0] + (KES_FM - a[1]) / (load - a[1]) * (strain - a[0]);
            curve.push([emt, KES_FM]);
            let wt = crate::fabric::tensile::energy(&curve);
            return Ok(KesTensile { direction, fm: KES_FM, emt, wt, lt: wt / (KES_FM * emt / 2.0), curve });
        }
        curve.push([strain, load]);
    }
    Err(LabError::NoReading { test: TEST, message: "the strip did not reach 500 gf/cm by 100 % strain".into() })
}

/// A strip's size for [`strain_pull`], m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strip {
    pub length: f64,
    pub width: f64,
    /// Mesh edge length.
    pub edge: f64,
}

impl Strip {
    /// The KES and ISO rig's strip: 10 cm between the clamps, 5 cm wide, on 5 mm edges.
    pub const RIG: Strip = Strip { length: 0.10, width: 0.05, edge: 0.005 };
    /// A long strip for bias pulls: 20 cm by 2.5 cm on 5 mm edges. A strip cut off the
    /// fabric's axes shears as it stretches; held at both ends, the shear is confined to the
    /// ends, and the middle half the extensometer reads pulls nearly as a free strip would.
    pub const LONG: Strip = Strip { length: 0.20, width: 0.025, edge: 0.005 };
}

/// Pulls `strip` of `fabric` cut along `direction` at the rig's 1 mm/s to `max_strain` and
/// returns its curve sampled every step, [extensometer strain over the middle half, the
/// moving clamp's load per unit width in N/m], from the unloaded start.
pub fn strain_pull(fabric: &FabricConfig, direction: Direction, max_strain: f64, strip: Strip) -> Result<Vec<[f64; 2]>, LabError> {
    const TEST: &str = "strain pull";
    if !(max_strain.is_finite() && max_strain > 0.0 && max_strain <= 1.0) {
        return Err(LabError::Setup { test: TEST, message: format!("the strain to pull to must be in (0, 1], got {max_strain}") });
    }
    let config = scene_config(TEST, "tensile-warp", fabric, |c| {
        c.cloth.warp_angle_deg = direction.warp_angle_deg();
        c.cloth.length = strip.length;
        c.cloth.width = strip.width;
        c.mesh.edge_length = strip.edge;
        c.test.max_strain = Some(max_strain);
        c.scene.duration = max_strain * strip.length / c.test.speed.unwrap_or(0.001);
        c.scene.settle_speed = None;
    })?;
    let mut scene = Scene::new(config).map_err(|e| LabError::Setup { test: TEST, message: e.to_string() })?;
    let rest = scene.model.rest.clone();
    let moving: Vec<usize> = (0..rest.len()).filter(|&v| rest[v].x > strip.length - 1e-9).collect();
    let columns = Columns::new(&rest, strip.length, strip.edge);
    let (lo, hi) = (columns.nearest(0.25 * strip.length), columns.nearest(0.75 * strip.length));
    let gauge = columns.rest_x[hi] - columns.rest_x[lo];
    let mean_x = |x: &[DVec3], col: usize| columns.vertices[col].iter().map(|&v| x[v as usize].x).sum::<f64>() / columns.vertices[col].len() as f64;
    let mut curve = vec![[0.0, 0.0]];
    let mut f = vec![DVec3::ZERO; rest.len()];
    while scene.state.time < scene.config.scene.duration - 1e-9 {
        scene.step().map_err(|e| LabError::Diverged { test: TEST, message: e.to_string() })?;
        f.iter_mut().for_each(|fi| *fi = DVec3::ZERO);
        scene.model.forces(&scene.state.x, &mut f);
        let load = -moving.iter().map(|&v| f[v].x).sum::<f64>() / strip.width;
        let strain = (mean_x(&scene.state.x, hi) - mean_x(&scene.state.x, lo)) / gauge - 1.0;
        curve.push([strain, load]);
    }
    Ok(curve)
}

/// The load on a sampled pull curve at `strain`, by linear interpolation between steps.
pub fn load_at(curve: &[[f64; 2]], strain: f64) -> Option<f64> {
    let i = curve.iter().position(|p| p[0] >= strain)?;
    if i == 0 {
        return Some(curve[0][1]);
    }
    let (a, b) = (curve[i - 1], curve[i]);
    Some(a[1] + (strain - a[0]) / (b[0] - a[0]) * (b[1] - a[1]))
}

/// What a strip pull to a given strain reports: the tensile rig's own measures.
#[derive(Debug, Clone, PartialEq)]
pub struct TensilePull {
    pub direction: Direction,
    /// The strain the clamp pulled to (by the clamps' separation), a fraction.
    pub max_strain: f64,
    /// (extensometer strain, stress N/m) from the unloaded start, then the rig's few dozen
    /// points evenly spaced in time (`TensileMeasures::stress_strain`).
    pub curve: Vec<[f64; 2]>,
    /// −lateral strain over extensometer strain at the end of the pull.
    pub poisson_ratio: f64,
}

/// Pulls a strip of `fabric` cut along `direction` on the `tensile-warp` rig (10 cm gauge,
/// 5 cm wide, 1 mm/s) to `max_strain` and returns the rig's stress–strain curve. Unlike
/// [`kes_tensile`] it stops at a strain, not a load: a bias strip, which shears rather than
/// stretches its yarns, may not reach KES's 500 gf/cm before it has doubled in length.
pub fn tensile_pull(fabric: &FabricConfig, direction: Direction, max_strain: f64) -> Result<TensilePull, LabError> {
    const TEST: &str = "tensile pull";
    if !(max_strain.is_finite() && max_strain > 0.0 && max_strain <= 1.0) {
        return Err(LabError::Setup { test: TEST, message: format!("the strain to pull to must be in (0, 1], got {max_strain}") });
    }
    let config = scene_config(TEST, "tensile-warp", fabric, |c| {
        c.cloth.warp_angle_deg = direction.warp_angle_deg();
        c.test.max_strain = Some(max_strain);
        c.scene.duration = max_strain * c.cloth.length / c.test.speed.unwrap_or(0.001);
        c.scene.settle_speed = None;
    })?;
    let m = super::run(TEST, config)?;
    let t = m.measures.tensile().ok_or_else(|| LabError::NoReading { test: TEST, message: "the rig reported no tensile measures".into() })?;
    // The rig samples after its steps; the strip starts unloaded and unstretched.
    let curve = std::iter::once([0.0, 0.0]).chain(t.stress_strain.iter().copied().filter(|p| p[0] > 0.0)).collect();
    Ok(TensilePull { direction, max_strain, curve, poisson_ratio: t.poisson_ratio })
}
