//! The tensile test: an Instron-style strip pull at constant speed (paper Figs. 4–5), the
//! stress against the extensometer's strain.

use super::{Kind, MotionTime, ON_EDGE, Rig, Specimen, need, pin_all};
use crate::scene::measures::{Measures, TensileMeasures};
use crate::scene::strip::{Columns, group_force, vertices_where};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid};
use crate::io::number::short;
use crate::sim::{Model, Motion, State};
use glam::DVec3;

pub struct Tensile;

impl Kind for Tensile {
    fn name(&self) -> &'static str {
        "tensile"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Strip { clamped: false, grip: false }
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["max_strain", "speed"]
    }

    fn check(&self, c: &SceneConfig, _extent: f64) -> Result<(), Invalid> {
        let strain = need(self.name(), "test.max_strain", c.test.max_strain)?;
        if strain > 1.0 {
            return Err(invalid("test.max_strain", format!("test.max_strain = {} pulls past 100 % strain, where fabrics have long broken; use at most 1", short(strain))));
        }
        need(self.name(), "test.speed", c.test.speed)?;
        Ok(())
    }

    fn motion_time(&self, c: &SceneConfig) -> Option<MotionTime> {
        let strain = c.test.max_strain?;
        Some(MotionTime { key: "test.max_strain", extent: strain, seconds: strain * c.cloth.length / c.test.speed? })
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let (length, width, h) = (config.cloth.length, config.cloth.width, config.mesh.edge_length);
        let rest = model.rest.clone();
        let fixed = vertices_where(&rest, |p| p.x < ON_EDGE);
        let moving = vertices_where(&rest, |p| p.x > length - ON_EDGE);
        let speed = config.test.speed.expect("checked when loading");
        let stop = self.motion_time(config).expect("checked when loading").seconds;
        pin_all(model, x, &fixed);
        model.drive(&moving, x, Motion::Linear { velocity: DVec3::new(speed, 0.0, 0.0), start: 0.0, stop });
        let columns = Columns::new(&rest, length, h);
        let (lo, hi) = (columns.nearest(0.25 * length), columns.nearest(0.75 * length));
        let gauge_rest_length = columns.rest_x[hi] - columns.rest_x[lo];
        let mid = &columns.vertices[columns.nearest(0.5 * length)];
        let bottom = *mid.iter().min_by(|a, b| rest[**a as usize].y.total_cmp(&rest[**b as usize].y)).unwrap();
        let top = *mid.iter().max_by(|a, b| rest[**a as usize].y.total_cmp(&rest[**b as usize].y)).unwrap();
        Ok(Box::new(TensileRig {
            moving,
            width,
            length,
            gauge: (columns.vertices[lo].clone(), columns.vertices[hi].clone()),
            gauge_rest_length,
            mid_edges: (bottom, top),
            samples: Vec::new(),
        }))
    }

    /// The clamp force per width rises with the pull.
    fn plot_series(&self) -> &'static str {
        "final_stress"
    }

    fn final_stretch(&self, config: &SceneConfig) -> Option<f64> {
        config.test.max_strain
    }
}

struct TensileRig {
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

impl Rig for TensileRig {
    fn sample(&mut self, model: &Model, state: &State) {
        let mut f = vec![DVec3::ZERO; state.x.len()];
        model.forces(&state.x, &mut f);
        // The cloth pulls the moving clamp back (−x); the clamp carries the opposite.
        let stress = -group_force(&f, &self.moving).x / self.width;
        let clamp_strain = (model.prescribed_position(self.moving[0] as usize, state.time).x - self.length) / self.length;
        let mean_x = |g: &[u32]| g.iter().map(|&v| state.x[v as usize].x).sum::<f64>() / g.len() as f64;
        let extensometer = (mean_x(&self.gauge.1) - mean_x(&self.gauge.0)) / self.gauge_rest_length - 1.0;
        let (b, t) = self.mid_edges;
        let lateral = (state.x[t as usize].y - state.x[b as usize].y) / self.width - 1.0;
        self.samples.push([clamp_strain, extensometer, lateral, stress]);
    }

    fn finish(&self, _model: &Model, _state: &State) -> Measures {
        // A few dozen evenly spaced points of the pull.
        let stride = (self.samples.len() / 40).max(1);
        let picked: Vec<&[f64; 4]> = self.samples.iter().step_by(stride).collect();
        let last = self.samples.last().copied().unwrap_or([0.0; 4]);
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

    super::any_rig!();
}
