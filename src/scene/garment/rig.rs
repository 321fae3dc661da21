//! What a garment scene measures: whether and when it was sewn, its seams, its hem and its
//! shadow's drape coefficient against the form's section at the waist (docs/garments.md).

use super::super::drape;
use crate::garment::{Garment, form::Measurements};
use crate::scene::SceneConfig;
use crate::scene::measures::{GarmentMeasures, Measures};
use crate::scene::kinds::Rig;
use crate::sim::contact::Prop;
use crate::sim::{Model, State};
use glam::{DVec2, DVec3};

pub struct GarmentRig {
    centre: DVec2,
    /// The support section as a polygon (its points at its height), m.
    waist: Vec<DVec3>,
    /// The height the garment is held at, m.
    held_at: f64,
    waist_area: f64,
    pattern_area: f64,
    prominence: f64,
    hem: Vec<u32>,
    /// Side a of each seam, vertices in order.
    seam_lines: Vec<Vec<u32>>,
    seam_lengths: Vec<(f64, f64)>,
    panels: usize,
    seam_pairs: usize,
    sewn_at: Option<f64>,
    gap_at_weld: Option<f64>,
}

impl GarmentRig {
    pub fn new(garment: &Garment, form: &Prop, measurements: Option<&Measurements>, config: &SceneConfig) -> Self {
        let g = config.garment.as_ref().expect("a garment scene has its section");
        let centre = DVec2::from_array(g.form.axis) * g.units.metres();
        let z = if !garment.attached_edges.is_empty() {
            garment.attached_edges.iter().map(|e| e.1).sum::<f64>() / garment.attached_edges.len() as f64
        } else if let Some(m) = measurements {
            m.waist_height
        } else {
            garment.positions.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max)
        };
        let waist = super::section(form, centre, z, 360, 0.0);
        let waist_area = polygon_area(&waist);
        let pattern_area: f64 = garment.surface.corners.iter().map(|c| 0.5 * (c[1] - c[0]).perp_dot(c[2] - c[0])).sum();
        let reach = |area: f64| (area / std::f64::consts::PI).sqrt();
        let prominence = 0.03 * (reach(pattern_area + waist_area) - reach(waist_area)).max(config.mesh.edge_length);
        Self {
            centre,
            held_at: z,
            waist,
            waist_area,
            pattern_area,
            prominence,
            hem: garment.hem.clone(),
            seam_lines: garment.seams.iter().map(|s| s.iter().map(|p| p[0]).collect()).collect(),
            seam_lengths: garment.seam_lengths.clone(),
            panels: garment.meshes.len(),
            seam_pairs: garment.seam_pairs().len(),
            sewn_at: None,
            gap_at_weld: None,
        }
    }

    /// The seams were welded at `time` with the largest gap `gap` (m): vertices renumbered
    /// by `map`.
    pub fn welded(&mut self, map: &[u32], time: f64, gap: f64) {
        let remap = |v: &mut u32| *v = map[*v as usize];
        self.hem.iter_mut().for_each(remap);
        self.hem.sort_unstable();
        self.hem.dedup();
        self.seam_lines.iter_mut().flatten().for_each(remap);
        self.sewn_at = Some(time);
        self.gap_at_weld = Some(gap);
    }

    pub fn measures(&self, model: &Model, state: &State) -> GarmentMeasures {
        let x = &state.x;
        // The shadow of the cloth and the waist section together (the hole the waist leaves
        // in the cloth's own shadow is the support's, as the pedestal's is in Cusick's test).
        let mut points = x.clone();
        let mut triangles = model.triangles.clone();
        let first = points.len() as u32;
        points.push(DVec3::new(self.centre.x, self.centre.y, 0.0));
        points.extend(self.waist.iter().copied());
        let k = self.waist.len() as u32;
        triangles.extend((0..k).map(|i| [first, first + 1 + i, first + 1 + (i + 1) % k]));
        let shadow = drape::shadow(&points, &triangles, self.centre, 1024);
        let dc = drape::drape_coefficient(shadow.area, self.pattern_area + self.waist_area, self.waist_area);
        let nodes = drape::count_nodes(&shadow.outline, 0.1, self.prominence);
        let heights: Vec<f64> = self.hem.iter().map(|&v| x[v as usize].z).collect();
        let count = heights.len().max(1) as f64;
        let mean = heights.iter().sum::<f64>() / count;
        let spread = (heights.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / count).sqrt();
        let length = |line: &[u32]| line.windows(2).map(|w| x[w[0] as usize].distance(x[w[1] as usize])).sum::<f64>();
        GarmentMeasures {
            garment_drape_coefficient: dc,
            hem_height_max: heights.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            hem_height_mean: mean,
            hem_height_min: heights.iter().copied().fold(f64::INFINITY, f64::min),
            hem_height_spread: spread,
            hem_nodes: nodes,
            hem_radius_max: shadow.outline.iter().map(|o| o.1).fold(0.0, f64::max),
            hem_radius_min: shadow.outline.iter().map(|o| o.1).fold(f64::INFINITY, f64::min),
            open_seam_gap: model.sewing.largest_gap(x),
            panels: self.panels,
            pattern_area: self.pattern_area,
            seam_gap_at_weld: self.gap_at_weld,
            seam_pairs: self.seam_pairs,
            seams: self.seam_lines.iter().zip(&self.seam_lengths).map(|(line, &(a, b))| [length(line), a, b]).collect(),
            sewn: self.sewn_at.is_some(),
            sewn_at: self.sewn_at,
            shadow_area: shadow.area,
            waist_area: self.waist_area,
            off_form: None,
        }
    }

    /// The height the garment is held at on its form (its attached edges', the form's
    /// waist, or its top as placed), m.
    pub fn support_height(&self) -> f64 {
        self.held_at
    }

    /// The shadow's outline around the form's axis, (angle rad, radius m).
    pub fn shadow_outline(&self, model: &Model, state: &State) -> Vec<(f64, f64)> {
        drape::shadow(&state.x, &model.triangles, self.centre, 1024).outline
    }
}

fn polygon_area(points: &[DVec3]) -> f64 {
    let n = points.len();
    (0..n).map(|i| 0.5 * points[i].truncate().perp_dot(points[(i + 1) % n].truncate())).sum::<f64>().abs()
}

impl Rig for GarmentRig {
    fn finish(&self, model: &Model, state: &State) -> Measures {
        Measures::Garment(self.measures(model, state))
    }

    fn outline(&self, model: &Model, state: &State) -> Option<Vec<(f64, f64)>> {
        Some(self.shadow_outline(model, state))
    }

    crate::scene::kinds::any_rig!();
}
