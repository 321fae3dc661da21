//! The snapshot the renderer draws: plain arrays, no solver types.

use super::colormap::{ColorMap, ScalarField};
use crate::appearance::Look;
use crate::scene::Scene;
use crate::sim::contact::props::PropShape;
use crate::sim::model::curvature_magnitude;
use glam::{DVec2, DVec3};

/// Everything one picture needs, in world coordinates (m, z up).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Cloth vertex positions.
    pub cloth_positions: Vec<[f32; 3]>,
    /// Cloth triangles; their winding defines the front face (normal = (b−a)×(c−a)).
    pub cloth_triangles: Vec<[u32; 3]>,
    /// Per vertex: rest position along the warp and along the weft, m. The weave texture is
    /// laid along these, so it follows the warp whatever the cut.
    pub cloth_uv: Vec<[f32; 2]>,
    /// Colour the cloth by this field instead of its fabric look.
    pub cloth_scalar: Option<ScalarField>,
    /// Rigid props (not the ground: that is `floor_z`).
    pub props: Vec<PropMesh>,
    /// Height of the floor the shadow falls on, m; no shadow when `None`.
    pub floor_z: Option<f32>,
    /// How the cloth is drawn where no field colours it: its fabric's look.
    pub look: Look,
}

/// A prop's surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PropMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl Frame {
    /// A frame of a bare cloth: positions, triangles, and rest positions in the sample
    /// plane with the warp at `warp_angle` (radians from the rest x axis, as
    /// `sim::Model::warp_angle`). No props; the floor below the cloth (see
    /// [`Frame::floor_below`]).
    pub fn from_cloth(positions: &[DVec3], triangles: &[[u32; 3]], rest: &[DVec2], warp_angle: f64) -> Self {
        let (c, s) = (warp_angle.cos(), warp_angle.sin());
        let mut frame = Self {
            cloth_positions: positions.iter().map(|p| p.as_vec3().to_array()).collect(),
            cloth_triangles: triangles.to_vec(),
            // Rest coordinates rotated into the warp/weft frame.
            cloth_uv: rest.iter().map(|p| [(c * p.x + s * p.y) as f32, (-s * p.x + c * p.y) as f32]).collect(),
            ..Self::default()
        };
        frame.floor_z = frame.floor_below();
        frame
    }

    /// The scene's current state, the cloth in its fabric's look. With `color_map`, the
    /// cloth is coloured by that field (strain or curvature per triangle, averaged onto the
    /// vertices). A ground prop becomes the floor; without one the floor is put a little
    /// below everything.
    pub fn from_scene(scene: &Scene, color_map: Option<ColorMap>) -> Self {
        let model = &scene.model;
        let x = &scene.state.x;
        let (texture, warp_angle) = model.texture_space();
        let mut frame = Self::from_cloth(x, &model.triangles, texture, warp_angle);
        frame.look = Look::or_default(&scene.config.fabric.appearance, scene.config.base_dir.as_deref());
        if let Some(map) = color_map {
            frame.cloth_scalar = Some(scalar_field(scene, map));
        }
        let mut ground: Option<f32> = None;
        for prop in &scene.props {
            if matches!(prop.shape, PropShape::Ground) {
                let z = prop.position.z as f32;
                ground = Some(ground.map_or(z, |g| g.max(z)));
                continue;
            }
            let (positions, triangles) = prop.surface_mesh(0.0);
            frame.props.push(PropMesh { positions: positions.iter().map(|p| p.as_vec3().to_array()).collect(), triangles });
        }
        frame.floor_z = ground.or_else(|| frame.floor_below());
        frame
    }

    /// Whether the cloth's triangles and texture coordinates are those of its positions:
    /// every index names a position, one texture coordinate per position.
    pub fn cloth_is_whole(&self) -> bool {
        let n = self.cloth_positions.len();
        self.cloth_uv.len() == n && self.cloth_triangles.iter().flatten().all(|&v| (v as usize) < n)
    }

    /// Axis-aligned bounds of the cloth and the props, or `None` for an empty frame.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        bounds_of(self.cloth_positions.iter().chain(self.props.iter().flat_map(|p| p.positions.iter())))
    }

    /// What a camera should frame: the cloth, and below it the props and the floor down to
    /// half the cloth's width under its lowest point, so that the shadow shows on a low
    /// floor while a tall pedestal or table does not shrink the cloth to a sliver.
    pub fn view_bounds(&self) -> Option<(DVec3, DVec3)> {
        let Some((cloth_lo, cloth_hi)) = bounds_of(self.cloth_positions.iter()) else { return self.bounds() };
        let width = (cloth_hi - cloth_lo).truncate().max_element();
        let reach = cloth_lo.z - 0.5 * width;
        let (mut lo, mut hi) = (cloth_lo, cloth_hi);
        if let Some((props_lo, props_hi)) = bounds_of(self.props.iter().flat_map(|p| p.positions.iter())) {
            lo = lo.min(props_lo.max(DVec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, reach)));
            hi = hi.max(props_hi.min(DVec3::new(f64::INFINITY, f64::INFINITY, cloth_hi.z)));
        }
        if let Some(floor) = self.floor_z {
            lo.z = lo.z.min(f64::from(floor).max(reach));
        }
        Some((lo, hi))
    }

    /// A floor a quarter of the scene's size below its lowest point: close enough for the
    /// shadow to read as contact, far enough to show the cloth's shape.
    pub fn floor_below(&self) -> Option<f32> {
        let (lo, hi) = self.bounds()?;
        let size = (hi - lo).length().max(1e-3);
        Some((lo.z - 0.25 * size) as f32)
    }
}

/// The per-vertex field of `map` for the scene's current state.
fn scalar_field(scene: &Scene, map: ColorMap) -> ScalarField {
    let model = &scene.model;
    let x = &scene.state.x;
    let per_triangle: Vec<f32> = match map.strain_component() {
        Some(k) => model.triangle_strains(x).iter().map(|s| s[k] as f32).collect(),
        None => model.triangle_curvatures(x).into_iter().map(|k| curvature_magnitude(k) as f32).collect(),
    };
    ScalarField::from_triangles(map, &per_triangle, &model.triangles, x.len())
}

/// Axis-aligned bounds of the finite points, or `None` when there are none.
fn bounds_of<'a>(points: impl Iterator<Item = &'a [f32; 3]>) -> Option<(DVec3, DVec3)> {
    points.filter(|p| p.iter().all(|c| c.is_finite())).fold(None, |acc, p| {
        let p = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        Some(acc.map_or((p, p), |(lo, hi): (DVec3, DVec3)| (lo.min(p), hi.max(p))))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_follows_the_warp() {
        let rest = [DVec2::new(0.0, 0.0), DVec2::new(0.01, 0.0), DVec2::new(0.0, 0.01)];
        let x: Vec<DVec3> = rest.iter().map(|p| p.extend(0.0)).collect();
        let frame = Frame::from_cloth(&x, &[[0, 1, 2]], &rest, 90f64.to_radians());
        // With the warp along rest y, a step along rest x is a step against the weft.
        let close = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-7 && (a[1] - b[1]).abs() < 1e-7;
        assert!(close(frame.cloth_uv[1], [0.0, -0.01]), "{:?}", frame.cloth_uv[1]);
        assert!(close(frame.cloth_uv[2], [0.01, 0.0]), "{:?}", frame.cloth_uv[2]);
        assert!(frame.floor_z.unwrap() < 0.0);
    }
}
