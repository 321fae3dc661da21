//! Where panels start: each wrapped without stretch on a cone (or cylinder, or flat ring)
//! around the form's axis, or flat on a vertical plane, at its arrangement point.

use super::pattern::{Around, PlacementConfig};
use glam::{DVec2, DVec3};

/// A panel's map from its plane (metres) to the scene.
#[derive(Debug, Clone, Copy)]
pub struct Placement {
    around: Around,
    /// Direction from the axis to the anchor, radians.
    angle: f64,
    /// Anchor's distance from the axis and height, m.
    distance: f64,
    height: f64,
    /// Cone's lean from the vertical, radians.
    flare: f64,
    /// The panel point placed at the arrangement point, m.
    anchor: DVec2,
    /// The form's axis (a point on it at the floor, z = 0), m.
    axis: DVec2,
}

impl Placement {
    pub fn new(config: &PlacementConfig, anchor: DVec2, axis: DVec2, metres: f64) -> Self {
        Self {
            around: config.around,
            angle: config.angle_deg.to_radians(),
            distance: config.distance * metres,
            height: config.height * metres,
            flare: config.flare_deg.to_radians(),
            anchor,
            axis,
        }
    }

    /// The scene position of panel point `p`. Both maps are isometries of the plane, and
    /// keep the outline's counter-clockwise side facing out (away from the axis, or up).
    pub fn position(&self, p: DVec2) -> DVec3 {
        let radial = |angle: f64| DVec3::new(angle.cos(), angle.sin(), 0.0);
        let axis = DVec3::new(self.axis.x, self.axis.y, 0.0);
        match self.around {
            Around::Plane => {
                let tangent = DVec3::new(-self.angle.sin(), self.angle.cos(), 0.0);
                let d = p - self.anchor;
                axis + self.distance * radial(self.angle) + d.x * tangent + (self.height + d.y) * DVec3::Z
            }
            Around::Cone if self.flare.sin() < 1e-9 => {
                let d = p - self.anchor;
                let angle = self.angle + d.x / self.distance;
                axis + self.distance * radial(angle) + (self.height + d.y) * DVec3::Z
            }
            Around::Cone => {
                // The cone's development: a sector around the apex, which lies above the
                // anchor at the slant distance ρ0 = R / sin α.
                let (sin, cos) = self.flare.sin_cos();
                let apex_distance = self.distance / sin;
                let d = p - (self.anchor + DVec2::new(0.0, apex_distance));
                let rho = d.length();
                let phi = d.x.atan2(-d.y);
                let angle = self.angle + phi / sin;
                axis + rho * sin * radial(angle) + (self.height + (apex_distance - rho) * cos) * DVec3::Z
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lengths along the panel survive every placement: the maps are isometries.
    #[test]
    fn placements_keep_lengths() {
        for (around, flare_deg) in [(Around::Plane, 0.0), (Around::Cone, 0.0), (Around::Cone, 14.0), (Around::Cone, 90.0)] {
            let config = PlacementConfig { around, angle_deg: 30.0, distance: 20.0, height: 100.0, flare_deg };
            let place = Placement::new(&config, DVec2::new(0.1, 0.5), DVec2::new(0.02, -0.01), 0.01);
            let (a, b) = (DVec2::new(0.1, 0.5), DVec2::new(0.11, 0.495));
            let chord = place.position(a).distance(place.position(b));
            // A short chord of a curved surface is shorter than the flat distance by
            // about d³/(24 r²): below 2e-5 m here.
            assert!((chord - a.distance(b)).abs() < 2e-5, "{around:?} {flare_deg}: {chord}");
            let anchor = place.position(DVec2::new(0.1, 0.5));
            let expect = DVec3::new(0.02, -0.01, 0.0) + 0.2 * DVec3::new(30f64.to_radians().cos(), 30f64.to_radians().sin(), 0.0) + DVec3::Z;
            assert!((anchor - expect).length() < 1e-12, "{around:?}: {anchor}");
        }
    }
}
