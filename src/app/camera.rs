//! Orbit camera (z up, as the scenes are: gravity is −z) and mouse rays for picking.
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

use glam::{DVec3, Vec3};

/// An orbiting camera looking at `target`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// Point looked at, m.
    pub target: DVec3,
    /// Angle about the z axis from +x, radians.
    pub yaw: f64,
    /// Elevation above the xy plane, radians (kept within ±89°).
    pub pitch: f64,
    /// Eye to target, m.
    pub distance: f64,
    /// Vertical field of view, radians.
    pub fov_y: f64,
}

/// A ray from the eye through a point of the screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

const PITCH_LIMIT: f64 = 89.0 * std::f64::consts::PI / 180.0;

/// How far the camera turns per pixel the mouse moves, radians.
const ORBIT_PER_PIXEL: f64 = 0.008;

impl Default for OrbitCamera {
    fn default() -> Self {
        Self { target: DVec3::ZERO, yaw: -60f64.to_radians(), pitch: 30f64.to_radians(), distance: 0.3, fov_y: 40f64.to_radians() }
    }
}

impl OrbitCamera {
    /// A camera from the default direction that frames the points `positions`.
    pub fn framing(positions: &[DVec3]) -> Self {
        let mut camera = Self::default();
        camera.frame(positions);
        camera
    }

    /// Keeps the direction and moves target and distance so that the bounding sphere of
    /// `positions` fills the view.
    pub fn frame(&mut self, positions: &[DVec3]) {
        let Some(first) = positions.first() else { return };
        let (lo, hi) = positions.iter().fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        self.target = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        self.distance = 1.15 * radius / (0.5 * self.fov_y).sin();
    }

    /// The renderer's camera with this view: the orbit geometry (eye, basis, projection)
    /// is defined once, in `render::Camera`.
    pub fn view(&self) -> crate::render::Camera {
        crate::render::Camera { target: self.target, yaw: self.yaw, pitch: self.pitch, distance: self.distance, fov_y: self.fov_y }
    }

    /// Eye position, m.
    pub fn eye(&self) -> DVec3 {
        self.view().eye()
    }

    /// Unit forward, right and up vectors of the view.
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        self.view().basis()
    }

    /// Turns the camera by a mouse movement of (dx, dy) pixels.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.turn(-dx * ORBIT_PER_PIXEL, dy * ORBIT_PER_PIXEL);
    }

    /// Turns the camera about its target by `yaw` (about z) and `pitch` (up), radians; the
    /// elevation stays within ±89°.
    pub fn turn(&mut self, yaw: f64, pitch: f64) {
        self.yaw += yaw;
        self.pitch = (self.pitch + pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Slides the target with the mouse by (dx, dy) pixels of a view `height` pixels tall, so
    /// that the point under the cursor at the target's depth follows the cursor.
    pub fn pan(&mut self, dx: f64, dy: f64, height: f64) {
        let (_, right, up) = self.basis();
        let metres_per_pixel = 2.0 * self.distance * (0.5 * self.fov_y).tan() / height.max(1.0);
        self.target += metres_per_pixel * (-dx * right + dy * up);
    }

    /// Moves towards (positive `steps`) or away from the target; one step is 10 %.
    pub fn zoom(&mut self, steps: f64) {
        self.distance = (self.distance * (-0.1 * steps).exp()).clamp(1e-3, 1e3);
    }

    /// The ray through pixel (x, y) of a `width` × `height` view (y down).
    pub fn ray(&self, x: f64, y: f64, width: f64, height: f64) -> Ray {
        let (forward, right, up) = self.basis();
        let half = (0.5 * self.fov_y).tan();
        let aspect = width / height.max(1.0);
        let ndc_x = 2.0 * x / width.max(1.0) - 1.0;
        let ndc_y = 1.0 - 2.0 * y / height.max(1.0);
        let direction = (forward + right * (ndc_x * half * aspect) + up * (ndc_y * half)).normalize();
        Ray { origin: self.eye(), direction }
    }

    /// Eye, target and up vector in single precision, for the renderer.
    pub fn look_at(&self) -> (Vec3, Vec3, Vec3) {
        let (_, _, up) = self.basis();
        (self.eye().as_vec3(), self.target.as_vec3(), up.as_vec3())
    }
}

impl Ray {
    /// Point at distance `t` along the ray.
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.direction
    }

    /// Where the ray meets the plane through `point` with normal `normal`, if in front.
    pub fn hit_plane(&self, point: DVec3, normal: DVec3) -> Option<DVec3> {
        let denominator = self.direction.dot(normal);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let t = (point - self.origin).dot(normal) / denominator;
        (t > 0.0).then(|| self.at(t))
    }

    /// Nearest hit on the triangles of a mesh: (triangle index, distance along the ray).
    /// Möller–Trumbore, both faces (cloth is two-sided).
    pub fn hit_mesh(&self, positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for (index, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            let (e1, e2) = (b - a, c - a);
            let p = self.direction.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-18 {
                continue;
            }
            let inverse = 1.0 / det;
            let s = self.origin - a;
            let u = s.dot(p) * inverse;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(e1);
            let v = self.direction.dot(q) * inverse;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            let t = e2.dot(q) * inverse;
            if t > 0.0 && best.is_none_or(|(_, best_t)| t < best_t) {
                best = Some((index, t));
            }
        }
        best
    }

    /// The vertex nearest to where the ray first meets the mesh, and that point.
    pub fn pick_vertex(&self, positions: &[DVec3], triangles: &[[u32; 3]]) -> Option<(u32, DVec3)> {
        let (triangle, t) = self.hit_mesh(positions, triangles)?;
        let hit = self.at(t);
        let vertex = triangles[triangle]
            .into_iter()
            .min_by(|&a, &b| (positions[a as usize] - hit).length_squared().total_cmp(&(positions[b as usize] - hit).length_squared()))?;
        Some((vertex, hit))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        // Unit square in the xy plane, two triangles.
        let p = vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn the_centre_ray_hits_the_target() {
        let (p, t) = square();
        let mut camera = OrbitCamera::framing(&p);
        camera.pitch = 60f64.to_radians();
        let ray = camera.ray(400.0, 300.0, 800.0, 600.0);
        let (_, d) = ray.hit_mesh(&p, &t).expect("looks at the square");
        assert!((ray.at(d) - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-9);
        assert!((d - camera.distance).abs() < 1e-9);
    }

    #[test]
    fn picks_the_nearest_vertex_from_either_side() {
        let (p, t) = square();
        for z in [1.0, -1.0] {
            let ray = Ray { origin: DVec3::new(0.9, 0.8, z), direction: DVec3::new(0.0, 0.0, -z) };
            let (vertex, hit) = ray.pick_vertex(&p, &t).unwrap();
            assert_eq!(vertex, 2);
            assert!((hit - DVec3::new(0.9, 0.8, 0.0)).length() < 1e-12);
        }
        let miss = Ray { origin: DVec3::new(1.5, 0.5, 1.0), direction: DVec3::new(0.0, 0.0, -1.0) };
        assert!(miss.pick_vertex(&p, &t).is_none());
        let behind = Ray { origin: DVec3::new(0.5, 0.5, 1.0), direction: DVec3::new(0.0, 0.0, 1.0) };
        assert!(behind.hit_mesh(&p, &t).is_none());
    }

    #[test]
    fn corner_rays_span_the_field_of_view() {
        let camera = OrbitCamera::default();
        let (forward, _, _) = camera.basis();
        let top = camera.ray(400.0, 0.0, 800.0, 600.0);
        assert!((top.direction.angle_between(forward) - 0.5 * camera.fov_y).abs() < 1e-9);
    }

    #[test]
    fn pan_moves_the_point_under_the_cursor_with_it() {
        let camera = OrbitCamera::default();
        let mut panned = camera;
        panned.pan(50.0, 0.0, 600.0);
        let (_, right, _) = camera.basis();
        // After panning right by 50 px, the old target appears 50 px right of centre.
        let ray = panned.ray(450.0, 300.0, 800.0, 600.0);
        let hit = ray.hit_plane(camera.target, -camera.basis().0).unwrap();
        assert!((hit - camera.target).length() < 1e-9, "{hit:?}");
        assert!(panned.target.dot(right) < camera.target.dot(right));
    }

    #[test]
    fn orbit_keeps_the_camera_off_the_poles() {
        let mut camera = OrbitCamera::default();
        camera.orbit(0.0, 1e6);
        assert!(camera.pitch <= PITCH_LIMIT);
        assert!(camera.basis().1.is_finite());
    }
}
