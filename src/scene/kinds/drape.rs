//! A cloth falling or resting on props until it settles: the Cusick drape test (paper
//! Fig. 6, BS 5058), a tablecloth. The drape coefficient and the nodes of its shadow.

use super::{Kind, Rig, Specimen};
use crate::scene::drape::{Shadow, count_nodes, drape_coefficient, shadow};
use crate::scene::measures::{DrapeMeasures, Measures};
use crate::scene::{SceneConfig, SceneError};
use crate::settings::rule::{Invalid, invalid, positive_at_most};
use crate::sim::{Model, State};
use glam::{DVec2, DVec3};

/// Simulated seconds between the drape history's samples.
const DRAPE_SAMPLE_INTERVAL: f64 = 0.01;

/// Outline smoothing for node counting: about 6°, less than half the spacing of 10 nodes.
const NODE_SMOOTHING: f64 = 0.1;

pub struct Drape;

impl Kind for Drape {
    fn name(&self) -> &'static str {
        "drape"
    }

    fn specimen(&self) -> Specimen {
        Specimen::Sheet
    }

    fn test_keys(&self) -> &'static [&'static str] {
        &["clamp_radius", "support_diameter", "support_size"]
    }

    fn check(&self, c: &SceneConfig, extent: f64) -> Result<(), Invalid> {
        check_support(c, extent)
    }

    fn attach(&self, config: &SceneConfig, model: &mut Model, x: &[DVec3], _clamp_band: f64) -> Result<Box<dyn Rig>, SceneError> {
        let t = &config.test;
        let centre = DVec2::new(config.cloth.position[0], config.cloth.position[1]);
        if let Some(radius) = t.clamp_radius {
            let rigid: Vec<bool> = model.rest.iter().map(|p| p.length() <= radius * (1.0 + 1e-9)).collect();
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
        let prominence = 0.03 * (reach(specimen_area) - reach(support_area)).max(config.mesh.edge_length);
        Ok(Box::new(DrapeRig { centre, support_area, specimen_area, prominence, history: Vec::new() }))
    }

    /// The shadow shrinks as the cloth falls around the pedestal.
    fn plot_series(&self) -> &'static str {
        "drape_coefficient"
    }

    fn drapes(&self) -> bool {
        true
    }

    fn writes_outline(&self) -> bool {
        true
    }
}

/// The drape's clamp and support: inside the specimen, so that the drape coefficient
/// (A_shadow − A_support)/(A_specimen − A_support) stays between 0 and 1.
fn check_support(c: &SceneConfig, extent: f64) -> Result<(), Invalid> {
    let t = &c.test;
    if c.props.is_empty() {
        return Err(invalid("props", "a drape scene needs at least one [[props]] table to drape over".into()));
    }
    let (cloth, disc) = (&c.cloth, c.cloth.diameter != 0.0);
    let specimen_area = if disc { std::f64::consts::PI * cloth.diameter.powi(2) / 4.0 } else { cloth.length * cloth.width };
    if let Some(r) = t.clamp_radius {
        positive_at_most("test.clamp_radius", r, 0.5 * extent, "the specimen's own radius, which would leave nothing to drape")?;
    }
    let support_area = match (t.support_diameter, t.support_size) {
        (Some(d), _) => {
            positive_at_most("test.support_diameter", d, extent, "the specimen, whose drape coefficient would then exceed 1")?;
            std::f64::consts::PI * d * d / 4.0
        }
        (None, Some([a, b])) => {
            let (along_x, along_y) = if disc { (cloth.diameter, cloth.diameter) } else { (cloth.length, cloth.width) };
            positive_at_most("test.support_size", a, along_x, "the specimen along x, whose drape coefficient would then exceed 1")?;
            positive_at_most("test.support_size", b, along_y, "the specimen along y, whose drape coefficient would then exceed 1")?;
            a * b
        }
        (None, None) => {
            return Err(invalid("test.support_diameter", "a drape scene needs test.support_diameter (a pedestal) or test.support_size (a table top), m".into()));
        }
    };
    if support_area >= specimen_area {
        return Err(invalid(
            if t.support_diameter.is_some() { "test.support_diameter" } else { "test.support_size" },
            format!("the support's area {support_area:.4} m² is not smaller than the specimen's {specimen_area:.4} m²: the drape coefficient would have no meaning; use a smaller support"),
        ));
    }
    Ok(())
}

struct DrapeRig {
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

impl DrapeRig {
    fn measure(&self, model: &Model, state: &State, resolution: usize) -> (Shadow, f64, usize) {
        let shadow = shadow(&state.x, &model.triangles, self.centre, resolution);
        let dc = drape_coefficient(shadow.area, self.specimen_area, self.support_area);
        let nodes = count_nodes(&shadow.outline, NODE_SMOOTHING, self.prominence);
        (shadow, dc, nodes)
    }
}

impl Rig for DrapeRig {
    fn sample(&mut self, model: &Model, state: &State) {
        // Rasterising the shadow costs as much as a Newton iteration on the paper's mesh:
        // the history is taken every DRAPE_SAMPLE_INTERVAL, not every step.
        if self.history.last().is_some_and(|h| state.time < h.0 + DRAPE_SAMPLE_INTERVAL - 1e-9) {
            return;
        }
        let (_, dc, nodes) = self.measure(model, state, 256);
        self.history.push((state.time, dc, nodes));
    }

    fn continue_history(&mut self, earlier: Box<dyn Rig>) {
        if let Ok(earlier) = earlier.into_any().downcast::<DrapeRig>() {
            self.history.splice(0..0, earlier.history).for_each(drop);
        }
    }

    fn finish(&self, model: &Model, state: &State) -> Measures {
        let (shadow, dc, nodes) = self.measure(model, state, 1024);
        let radius_min = shadow.outline.iter().map(|o| o.1).fold(f64::INFINITY, f64::min);
        Measures::Drape(DrapeMeasures {
            drape_coefficient: dc,
            nodes,
            shadow_area: shadow.area,
            specimen_area: self.specimen_area,
            support_area: self.support_area,
            // None when the outline is empty.
            outline_radius_min: radius_min.is_finite().then_some(radius_min),
            outline_radius_max: shadow.outline.iter().map(|o| o.1).fold(0.0, f64::max),
            history: self.history.iter().step_by((self.history.len() / 100).max(1)).copied().collect(),
        })
    }

    fn outline(&self, model: &Model, state: &State) -> Option<Vec<(f64, f64)>> {
        Some(self.measure(model, state, 1024).0.outline)
    }

    super::any_rig!();
}
