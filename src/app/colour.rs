//! What the viewer colours the cloth by: the fabric's own look or one of the renderer's
//! fields ([`ColorMap`]), and that field's per-vertex values for a snapshot (the renderer
//! draws the scale and its legend).

use super::worker::Snapshot;
use crate::render::{ColorMap, ScalarField};
use crate::sim::model::curvature_magnitude;

/// What the cloth's colour shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColourMap {
    /// The fabric's own colour and weave.
    #[default]
    Fabric,
    /// A strain or curvature field on the renderer's scale.
    Field(ColorMap),
}

impl ColourMap {
    /// The fabric, then every field in [`ColorMap::ALL`]'s order.
    pub const ALL: [ColourMap; 1 + ColorMap::ALL.len()] = {
        let mut all = [Self::Fabric; 1 + ColorMap::ALL.len()];
        let mut i = 0;
        while i < ColorMap::ALL.len() {
            all[i + 1] = Self::Field(ColorMap::ALL[i]);
            i += 1;
        }
        all
    };

    pub fn label(self) -> &'static str {
        match self {
            Self::Fabric => "fabric",
            Self::Field(map) => map.label(),
        }
    }

    /// The name a script gives it: `fabric`, or the field's `--colormap` name.
    pub fn key(self) -> &'static str {
        match self {
            Self::Fabric => "fabric",
            Self::Field(map) => map.name(),
        }
    }
}

/// The per-vertex field of `map` (triangle values averaged onto vertices), or `None` for a
/// field the scene does not model (e.g. bending switched off).
pub fn field(snapshot: &Snapshot, map: ColorMap) -> Option<ScalarField> {
    let per_triangle: Vec<f32> = match map.strain_component() {
        Some(k) => snapshot.triangle_strains.iter().map(|s| s[k]).collect(),
        None => snapshot.triangle_curvatures.iter().map(|k| curvature_magnitude(k.map(f64::from)) as f32).collect(),
    };
    let topology = &snapshot.topology;
    if per_triangle.len() != topology.triangles.len() || !topology.fits(&snapshot.positions) {
        return None;
    }
    Some(ScalarField::from_triangles(map, &per_triangle, &topology.triangles, topology.vertex_count))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_field_is_offered_after_the_fabric_with_its_colormap_name() {
        assert_eq!(ColourMap::ALL[0], ColourMap::Fabric);
        let keys: Vec<&str> = ColourMap::ALL.iter().map(|m| m.key()).collect();
        assert_eq!(keys, ["fabric", "warp", "weft", "shear", "bending"]);
        assert_eq!(ColourMap::Field(ColorMap::Bending).label(), "curvature |κ| (1/m)");
    }
}
