//! Rigid props (table, pedestal, ball, floor, meshes) as parry3d shapes.
//!
//! This is the one place where the simulator's f64 `DVec3` meets parry3d's f32 `Vec3`:
//! every query converts on the way in and out. f32 is ample for contact geometry at the
//! scale of a room (about 3e-8 m resolution at 1 m); the cloth itself stays in f64.

use glam::{DQuat, DVec3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::Ray;
use parry3d::shape::{Ball, Cuboid, Cylinder, HalfSpace, SharedShape, TriMesh, TriMeshFlags};
use thiserror::Error;

fn to_f32(v: DVec3) -> Vec3 {
    v.as_vec3()
}

fn to_f64(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// Farthest a prop or the cloth may lie from the origin, and the largest prop, m. The props'
/// f32 geometry resolves 6e-5 m there, a thirtieth of the default 2 mm contact layer;
/// farther out, contact would be decided by rounding.
pub const MAX_REACH: f64 = 1e3;

/// Smallest prop size, m: below a tenth of a millimetre the f32 geometry a metre from the
/// origin (6e-8 m) keeps too few digits of the shape.
pub const MIN_SIZE: f64 = 1e-4;

/// The geometric kinds of prop, in the simulator's z-up world.
#[derive(Debug, Clone, PartialEq)]
pub enum PropShape {
    /// The half-space below a horizontal plane through the prop's position.
    Ground,
    /// A box with these half-extents along its local x, y, z.
    Box { half_extents: DVec3 },
    /// A cylinder around its local z axis.
    Cylinder { radius: f64, height: f64 },
    Sphere { radius: f64 },
    /// A closed, outward-oriented triangle mesh, in local coordinates.
    Mesh { vertices: Vec<DVec3>, triangles: Vec<[u32; 3]> },
}

#[derive(Debug, Error)]
pub enum PropError {
    #[error("prop '{name}': {message}")]
    Invalid { name: String, message: String },
}

/// A rigid, static prop.
#[derive(Clone)]
pub struct Prop {
    pub name: String,
    pub shape: PropShape,
    /// Position of the prop's centre (the plane's point for the ground), m.
    pub position: DVec3,
    /// Orientation of the prop's local axes.
    pub rotation: DQuat,
    collider: SharedShape,
    pose: Pose,
}

impl std::fmt::Debug for Prop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prop").field("name", &self.name).field("shape", &self.shape).field("position", &self.position).finish()
    }
}

/// The nearest surface point of a prop to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Signed distance, m: negative inside the prop.
    pub distance: f64,
    /// The closest point on the surface.
    pub point: DVec3,
    /// Outward unit normal of the contact plane there.
    pub normal: DVec3,
}

/// How far from a prop's surface a ray cast's hit may lie and still be a hit: 10 µm, plus
/// a millionth of the hit's distance from the origin (about eight units in the last place
/// of the single precision the casts run in, so that props tens of metres out keep their
/// genuine hits). The false hits seen were millimetres off.
fn ray_hit_tolerance(point: DVec3) -> f64 {
    1e-5 + 1e-6 * point.length()
}

impl Prop {
    pub fn new(name: &str, shape: PropShape, position: DVec3, rotation: DQuat) -> Result<Self, PropError> {
        let invalid = |message: String| PropError::Invalid { name: name.to_string(), message };
        let positive = |what: &str, value: f64| {
            if !(value.is_finite() && value > 0.0) {
                Err(invalid(format!("{what} must be positive, got {value:?}")))
            } else if !(MIN_SIZE..=MAX_REACH).contains(&value) {
                Err(invalid(format!("{what} = {value:?} m is outside what contact resolves, {MIN_SIZE} to {MAX_REACH} m")))
            } else {
                Ok(())
            }
        };
        if !position.is_finite() || position.abs().max_element() > MAX_REACH {
            return Err(invalid(format!("position {:?} must be finite and within {MAX_REACH} m of the origin", position.to_array())));
        }
        if !rotation.is_finite() || !rotation.is_normalized() {
            return Err(invalid(format!("rotation {:?} is not a finite rotation; give finite angles", rotation.to_array())));
        }
        // parry3d's cylinder runs along its local y axis; ours along z.
        let mut local_frame = Quat::IDENTITY;
        let collider = match &shape {
            PropShape::Ground => SharedShape::new(HalfSpace::new(Vec3::Z)),
            PropShape::Box { half_extents } => {
                for v in half_extents.to_array() {
                    positive("every half-extent", v)?;
                }
                SharedShape::new(Cuboid::new(to_f32(*half_extents)))
            }
            PropShape::Cylinder { radius, height } => {
                positive("radius", *radius)?;
                positive("height", *height)?;
                local_frame = Quat::from_rotation_x(std::f32::consts::FRAC_PI_2);
                SharedShape::new(Cylinder::new(0.5 * *height as f32, *radius as f32))
            }
            PropShape::Sphere { radius } => {
                positive("radius", *radius)?;
                SharedShape::new(Ball::new(*radius as f32))
            }
            PropShape::Mesh { vertices, triangles } => {
                if triangles.is_empty() {
                    return Err(invalid("the mesh has no triangles".into()));
                }
                if let Some((i, v)) = vertices.iter().enumerate().find(|(_, v)| !v.is_finite() || v.abs().max_element() > MAX_REACH) {
                    return Err(invalid(format!("vertex {} at {:?} must be finite and within {MAX_REACH} m of the origin", i + 1, v.to_array())));
                }
                if let Some(t) = triangles.iter().find(|t| t.iter().any(|&i| i as usize >= vertices.len())) {
                    return Err(invalid(format!("triangle {t:?} refers to a vertex past the {} given", vertices.len())));
                }
                let points = vertices.iter().map(|v| to_f32(*v)).collect();
                // ORIENTED gives pseudo-normals, so that a point inside the closed mesh is
                // known to be inside.
                let mesh = TriMesh::with_flags(points, triangles.clone(), TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES)
                    .map_err(|e| invalid(format!("not a usable triangle mesh: {e:?}")))?;
                SharedShape::new(mesh)
            }
        };
        let pose = Pose::from_parts(to_f32(position), rotation.as_quat() * local_frame);
        Ok(Self { name: name.to_string(), shape, position, rotation, collider, pose })
    }

    /// Signed distance, closest surface point and outward normal at `x`. Only meaningful
    /// near the surface (within a few contact thicknesses), which is where it is used.
    pub fn surface_point(&self, x: DVec3) -> SurfacePoint {
        let query = to_f32(x);
        let projection = self.collider.project_point(&self.pose, query, true);
        let (point, inside) = if projection.is_inside {
            // A solid query returns the point itself when inside; ask for the boundary.
            let hollow = self.collider.project_point(&self.pose, query, false);
            (to_f64(hollow.point), true)
        } else {
            (to_f64(projection.point), false)
        };
        let offset = x - point;
        let length = offset.length();
        let distance = if inside { -length } else { length };
        let normal = if length > 1e-9 {
            offset / distance
        } else {
            // On the surface: take the normal from a point pushed slightly along the
            // gradient of a nearby query.
            self.normal_near(x)
        };
        self.refine(x, SurfacePoint { distance, point, normal })
    }

    /// The convex primitives' signed distance and normal in f64, in closed form. Resting
    /// contact sinks only g·h²/c ≈ 1e-7 m into its layer: the normal force read from that
    /// depth, and the normal itself, must not carry f32's 1e-8 m rounding, which parry's
    /// f32 closest point would give them (10 % of the force, and a normal from noise).
    fn refine(&self, x: DVec3, found: SurfacePoint) -> SurfacePoint {
        let local = self.rotation.inverse() * (x - self.position);
        let (distance, normal) = match &self.shape {
            PropShape::Ground => (local.z, DVec3::Z),
            PropShape::Sphere { radius } => (local.length() - radius, local.try_normalize().unwrap_or(DVec3::Z)),
            PropShape::Box { half_extents } => {
                let (d, n) = box_distance(local.abs(), *half_extents);
                (d, n * local.signum())
            }
            PropShape::Cylinder { radius, height } => {
                // A box in the (radial, axial) half-plane.
                let radial = local.truncate().length();
                let (d, n) = box_distance(DVec3::new(radial, local.z.abs(), 0.0), DVec3::new(*radius, 0.5 * height, 1.0));
                let direction = if radial > 0.0 { local.truncate() / radial } else { glam::DVec2::X };
                (d, DVec3::new(n.x * direction.x, n.x * direction.y, n.y * local.z.signum()))
            }
            PropShape::Mesh { .. } => return found,
        };
        let normal = self.rotation * normal;
        SurfacePoint { distance, point: x - distance * normal, normal }
    }

    fn normal_near(&self, x: DVec3) -> DVec3 {
        // Central differences of the distance field, step 0.1 mm.
        let e = 1e-4;
        let d = |p: DVec3| {
            let projection = self.collider.project_point(&self.pose, to_f32(p), true);
            let distance = (p - to_f64(projection.point)).length();
            if projection.is_inside { -distance } else { distance }
        };
        let g = DVec3::new(
            d(x + DVec3::X * e) - d(x - DVec3::X * e),
            d(x + DVec3::Y * e) - d(x - DVec3::Y * e),
            d(x + DVec3::Z * e) - d(x - DVec3::Z * e),
        );
        g.try_normalize().unwrap_or(DVec3::Z)
    }

    /// First point where the segment from `a` to `b` enters the prop, with the surface
    /// normal there, or None. A segment starting inside reports no entry.
    ///
    /// parry3d's ray cast against a cylinder can report a hit for a ray that only grazes
    /// it: a 1.6 mm segment 2.15 mm from the pedestal's rim, above its top, was reported
    /// as entering it, and the 80 000-triangle Cusick drape was refused as starting
    /// through its pedestal. A hit is kept unless its point lies outside the prop (by more
    /// than [`ray_hit_tolerance`]); past one that does, the cast goes on from there.
    pub fn segment_entry(&self, a: DVec3, b: DVec3) -> Option<SurfacePoint> {
        let d = b - a;
        let length = d.length();
        if length < 1e-12 {
            return None;
        }
        if self.surface_point(a).distance < 0.0 {
            return None;
        }
        let direction = d / length;
        let mut travelled = 0.0;
        for _ in 0..4 {
            let origin = a + travelled * direction;
            let ray = Ray::new(to_f32(origin), to_f32(direction));
            let hit = self.collider.cast_ray_and_get_normal(&self.pose, &ray, (length - travelled) as f32, false)?;
            let point = origin + direction * hit.time_of_impact as f64;
            let tolerance = ray_hit_tolerance(point);
            // A hit inside the prop is an entry whose point is imprecise: the segment got in.
            if self.surface_point(point).distance <= tolerance {
                let normal = to_f64(hit.normal).normalize();
                return Some(SurfacePoint { distance: 0.0, point, normal: if normal.dot(d) < 0.0 { normal } else { -normal } });
            }
            travelled += hit.time_of_impact as f64 + tolerance;
            if travelled >= length {
                return None;
            }
        }
        None
    }

    /// The prop's surface as triangles in world coordinates, for rendering and export.
    /// The ground is a square of side `ground_extent` centred under its position.
    pub fn surface_mesh(&self, ground_extent: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let (local, triangles): (Vec<Vec3>, Vec<[u32; 3]>) = match &self.shape {
            PropShape::Ground => {
                let s = 0.5 * ground_extent as f32;
                (vec![Vec3::new(-s, -s, 0.0), Vec3::new(s, -s, 0.0), Vec3::new(s, s, 0.0), Vec3::new(-s, s, 0.0)], vec![[0, 1, 2], [0, 2, 3]])
            }
            PropShape::Box { half_extents } => Cuboid::new(to_f32(*half_extents)).to_trimesh(),
            PropShape::Cylinder { radius, height } => Cylinder::new(0.5 * *height as f32, *radius as f32).to_trimesh(96),
            PropShape::Sphere { radius } => Ball::new(*radius as f32).to_trimesh(48, 24),
            PropShape::Mesh { vertices, triangles } => (vertices.iter().map(|v| to_f32(*v)).collect(), triangles.clone()),
        };
        let world = local.into_iter().map(|p| to_f64(self.pose * p)).collect();
        (world, triangles)
    }
}

/// Signed distance and outward normal of a point `p ≥ 0` (first octant, by symmetry) to
/// the box of half-extents `h`.
fn box_distance(p: DVec3, h: DVec3) -> (f64, DVec3) {
    let q = p - h;
    let outside = q.max(DVec3::ZERO);
    let length = outside.length();
    if length > 0.0 {
        return (length, outside / length);
    }
    // Inside: the nearest face.
    let axis = if q.x >= q.y && q.x >= q.z { DVec3::X } else if q.y >= q.z { DVec3::Y } else { DVec3::Z };
    (q.max_element(), axis)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_stands_on_z() {
        let p = Prop::new("pedestal", PropShape::Cylinder { radius: 0.09, height: 0.2 }, DVec3::new(0.0, 0.0, -0.1), DQuat::IDENTITY).unwrap();
        let top = p.surface_point(DVec3::new(0.0, 0.0, 0.01));
        assert!((top.distance - 0.01).abs() < 1e-6, "{top:?}");
        assert!((top.normal - DVec3::Z).length() < 1e-5);
        let side = p.surface_point(DVec3::new(0.1, 0.0, -0.1));
        assert!((side.distance - 0.01).abs() < 1e-6, "{side:?}");
        let inside = p.surface_point(DVec3::new(0.0, 0.0, -0.003));
        assert!((inside.distance + 0.003).abs() < 1e-6, "{inside:?}");
        assert!((inside.normal - DVec3::Z).length() < 1e-5, "{inside:?}");
        let entry = p.segment_entry(DVec3::new(0.0, 0.0, 0.5), DVec3::new(0.0, 0.0, -0.5)).unwrap();
        assert!(entry.point.z.abs() < 1e-6 && entry.normal.z > 0.99, "{entry:?}");
        assert!(p.segment_entry(DVec3::new(0.0, 0.0, -0.05), DVec3::new(0.0, 0.0, 0.5)).is_none());
    }

    /// A segment above a cylinder's top and outside its radius everywhere (the 80 000-triangle
    /// Cusick specimen's edge across the pedestal's rim, 0.8 mm outside it and 2 mm above)
    /// does not enter it; the same segment lowered through the side does, on the surface.
    #[test]
    fn a_segment_grazing_a_cylinders_rim_does_not_enter_it() {
        let p = Prop::new("pedestal", PropShape::Cylinder { radius: 0.09, height: 0.3 }, DVec3::new(0.0, 0.0, -0.15), DQuat::IDENTITY).unwrap();
        let (a, b) = (DVec3::new(0.090807, 0.00081, 0.001991), DVec3::new(0.090807, -0.00081, 0.001993));
        assert!(p.segment_entry(a, b).is_none());
        let (a, b) = (DVec3::new(0.0908, 0.0, -0.01), DVec3::new(0.0892, 0.0, -0.01));
        let entry = p.segment_entry(a, b).expect("enters through the side");
        assert!((entry.point.x - 0.09).abs() < 1e-5 && entry.normal.x > 0.99, "{entry:?}");
    }

    #[test]
    fn ground_and_box() {
        let g = Prop::new("floor", PropShape::Ground, DVec3::new(0.0, 0.0, -1.0), DQuat::IDENTITY).unwrap();
        let s = g.surface_point(DVec3::new(3.0, 2.0, -1.5));
        assert!((s.distance + 0.5).abs() < 1e-6 && s.normal.z > 0.99, "{s:?}");
        let b = Prop::new("table", PropShape::Box { half_extents: DVec3::new(0.5, 0.5, 0.01) }, DVec3::ZERO, DQuat::IDENTITY).unwrap();
        let e = b.segment_entry(DVec3::new(0.2, 0.0, 1.0), DVec3::new(0.2, 0.0, -1.0)).unwrap();
        assert!((e.point.z - 0.01).abs() < 1e-6);
        assert!(Prop::new("bad", PropShape::Sphere { radius: -1.0 }, DVec3::ZERO, DQuat::IDENTITY).is_err());
    }
}

#[cfg(test)]
mod refine_tests {
    use super::*;

    #[test]
    fn rotated_box_distance_is_exact() {
        let theta = 35f64.to_radians();
        let normal = DVec3::new(-theta.sin(), 0.0, theta.cos());
        let b = Prop::new("incline", PropShape::Box { half_extents: DVec3::new(1.0, 0.25, 0.05) }, -0.05 * normal, DQuat::from_rotation_y(-theta)).unwrap();
        for d in [1e-7, 1e-3, 0.01, -1e-3] {
            let x = DVec3::new(0.1, 0.02, 0.0).project_onto_normalized(DVec3::Y) + DQuat::from_rotation_y(-theta) * DVec3::new(0.3, 0.0, 0.0) + d * normal;
            let s = b.surface_point(x);
            assert!((s.distance - d).abs() < 1e-12, "{d}: {s:?}");
            assert!((s.normal - normal).length() < 1e-6, "{s:?}");
        }
    }
}
