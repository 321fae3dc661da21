//! The renderer's orbit camera (z up, as the scenes are: gravity is −z). Same conventions as
//! the viewer's `app::camera::OrbitCamera`, so one converts to the other field by field.
//!
//! ```text
//!          z
//!          |   eye = target + distance·(cos p cos y, cos p sin y, sin p)
//!          |  /
//!          | / p (pitch, elevation)
//!  target  +------- y
//!         / y (yaw, about z from +x)
//!        x
//! ```

use glam::{DVec3, Mat4, Vec3};

/// An orbiting camera looking at `target`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Point looked at, m.
    pub target: DVec3,
    /// Angle about the z axis from +x, radians.
    pub yaw: f64,
    /// Elevation above the xy plane, radians (keep within ±89°).
    pub pitch: f64,
    /// Eye to target, m.
    pub distance: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Self { target: DVec3::ZERO, yaw: -60f64.to_radians(), pitch: 30f64.to_radians(), distance: 0.3, fov_y: 40f64.to_radians() }
    }
}

/// Fraction of the view the framed box may fill, each way.
const FILL: f64 = 0.88;

impl Camera {
    /// Eye position, m.
    pub fn eye(&self) -> DVec3 {
        self.target + self.distance * self.backward()
    }

    /// Unit vector from the target to the eye.
    fn backward(&self) -> DVec3 {
        DVec3::new(self.pitch.cos() * self.yaw.cos(), self.pitch.cos() * self.yaw.sin(), self.pitch.sin())
    }

    /// Unit forward, right and up vectors of the view.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let forward = -self.backward();
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        (forward, right, up)
    }

    /// Keeps the direction, aims at the centre of the box `min`..`max` and moves to the
    /// nearest distance at which all eight corners are in view (`aspect` = width / height).
    pub fn frame_bounds(&mut self, min: DVec3, max: DVec3, aspect: f64) {
        let (forward, right, up) = self.basis();
        self.target = 0.5 * (min + max);
        let tan_y = FILL * (0.5 * self.fov_y).tan();
        let tan_x = tan_y * aspect.max(1e-3);
        let size = (max - min).length().max(1e-3);
        let mut distance: f64 = 0.0;
        for corner in 0..8 {
            let c = DVec3::new(
                if corner & 1 == 0 { min.x } else { max.x },
                if corner & 2 == 0 { min.y } else { max.y },
                if corner & 4 == 0 { min.z } else { max.z },
            ) - self.target;
            // The corner is at depth distance + c·forward; it fits when its offsets across the
            // view are within that depth times the half-angle tangents.
            let depth_offset = c.dot(forward);
            distance = distance.max(c.dot(right).abs() / tan_x - depth_offset).max(c.dot(up).abs() / tan_y - depth_offset);
        }
        // Never inside the box, whatever the angles.
        self.distance = distance.max(0.6 * size);
    }

    /// The matrix from world to clip space for a view `aspect` = width / height, with
    /// wgpu's depth range 0..1.
    pub fn view_proj(&self, aspect: f64) -> Mat4 {
        let (_, _, up) = self.basis();
        let view = glam::camera::rh::view::look_at_mat4(self.eye().as_vec3(), self.target.as_vec3(), up.as_vec3());
        let near = (self.distance * 0.01) as f32;
        let far = (self.distance * 100.0) as f32;
        let projection = glam::camera::rh::proj::directx::perspective(self.fov_y as f32, aspect.max(1e-3) as f32, near, far);
        projection * view
    }

    /// Where a world point lands in a `width` × `height` image: pixel (x right, y down),
    /// or `None` behind the eye.
    pub fn project(&self, point: DVec3, width: f64, height: f64) -> Option<[f64; 2]> {
        let clip = self.view_proj(width / height) * point.as_vec3().extend(1.0);
        (clip.w > 0.0).then(|| {
            let ndc = Vec3::new(clip.x / clip.w, clip.y / clip.w, clip.z / clip.w);
            [(f64::from(ndc.x) + 1.0) * 0.5 * width, (1.0 - f64::from(ndc.y)) * 0.5 * height]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_projects_to_the_centre_and_up_is_up() {
        let camera = Camera { target: DVec3::new(0.1, -0.2, 0.3), ..Camera::default() };
        let [x, y] = camera.project(camera.target, 320.0, 240.0).unwrap();
        assert!((x - 160.0).abs() < 1e-3 && (y - 120.0).abs() < 1e-3, "{x} {y}");
        let [_, above] = camera.project(camera.target + 0.01 * DVec3::Z, 320.0, 240.0).unwrap();
        assert!(above < 120.0, "z up is up on screen: {above}");
    }

    #[test]
    fn framed_box_corners_are_in_view_and_one_touches_the_margin() {
        let (min, max) = (DVec3::new(-0.05, -0.025, 0.0), DVec3::new(0.05, 0.025, 0.01));
        for (yaw, pitch, aspect) in [(-60.0f64, 30.0f64, 4.0 / 3.0), (0.0, 80.0, 1.0), (45.0, 5.0, 0.5)] {
            let mut camera = Camera { yaw: yaw.to_radians(), pitch: pitch.to_radians(), ..Camera::default() };
            camera.frame_bounds(min, max, aspect);
            let (w, h) = (400.0 * aspect, 400.0);
            let mut widest: f64 = 0.0;
            for corner in 0..8 {
                let p = DVec3::new(
                    if corner & 1 == 0 { min.x } else { max.x },
                    if corner & 2 == 0 { min.y } else { max.y },
                    if corner & 4 == 0 { min.z } else { max.z },
                );
                let [x, y] = camera.project(p, w, h).unwrap();
                let (fx, fy) = ((x / w - 0.5).abs() * 2.0, (y / h - 0.5).abs() * 2.0);
                assert!(fx <= FILL + 1e-4 && fy <= FILL + 1e-4, "corner {corner} at {fx} {fy}");
                widest = widest.max(fx).max(fy);
            }
            assert!(widest > FILL - 1e-3, "tight fit: {widest}");
        }
    }
}
