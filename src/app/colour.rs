//! The strain and bending colour maps: which per-triangle field of a snapshot to show, and
//! its per-vertex values and range (the renderer draws the scale and its legend).

use super::worker::Snapshot;

/// What the cloth's colour shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColourMap {
    /// The fabric's own colour and weave.
    #[default]
    Fabric,
    /// ε along the warp.
    WarpStrain,
    /// ε along the weft.
    WeftStrain,
    /// Engineering shear strain γ between warp and weft.
    Shear,
    /// Curvature magnitude √(κ_xx² + κ_yy² + 2κ_xy²), 1/m.
    Bending,
}

impl ColourMap {
    pub const ALL: [ColourMap; 5] = [Self::Fabric, Self::WarpStrain, Self::WeftStrain, Self::Shear, Self::Bending];

    pub fn label(self) -> &'static str {
        match self {
            Self::Fabric => "fabric",
            Self::WarpStrain => "warp strain ε_x",
            Self::WeftStrain => "weft strain ε_y",
            Self::Shear => "shear strain γ",
            Self::Bending => "curvature |κ| (1/m)",
        }
    }

    /// The name a script or the command line gives it: `fabric`, or the renderer's
    /// `--colormap` name.
    pub fn key(self) -> &'static str {
        match self {
            Self::Fabric => "fabric",
            Self::WarpStrain => "warp",
            Self::WeftStrain => "weft",
            Self::Shear => "shear",
            Self::Bending => "bending",
        }
    }

    /// Signed fields use a diverging scale centred on zero.
    pub fn signed(self) -> bool {
        matches!(self, Self::WarpStrain | Self::WeftStrain | Self::Shear)
    }
}

/// A field ready to colour: one value per vertex and the range the scale spans.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub values: Vec<f32>,
    pub min: f32,
    pub max: f32,
}

impl Field {
    /// Position of `value` on the scale, 0..1.
    pub fn normalised(&self, value: f32) -> f32 {
        if self.max > self.min { ((value - self.min) / (self.max - self.min)).clamp(0.0, 1.0) } else { 0.5 }
    }
}

/// The per-vertex field of `map` (triangle values averaged onto vertices), or `None` for
/// the fabric colour or a field the scene does not model (e.g. bending switched off).
pub fn field(snapshot: &Snapshot, map: ColourMap) -> Option<Field> {
    let per_triangle: Vec<f32> = match map {
        ColourMap::Fabric => return None,
        ColourMap::WarpStrain | ColourMap::WeftStrain | ColourMap::Shear => {
            let k = match map {
                ColourMap::WarpStrain => 0,
                ColourMap::WeftStrain => 1,
                _ => 2,
            };
            snapshot.triangle_strains.iter().map(|s| s[k]).collect()
        }
        ColourMap::Bending => {
            snapshot.triangle_curvatures.iter().map(|c| (c[0] * c[0] + c[1] * c[1] + 2.0 * c[2] * c[2]).sqrt()).collect()
        }
    };
    let topology = &snapshot.topology;
    if per_triangle.len() != topology.triangles.len() || !topology.fits(&snapshot.positions) {
        return None;
    }
    let n = topology.vertex_count;
    let (mut sum, mut count) = (vec![0.0f32; n], vec![0u32; n]);
    for (tri, value) in topology.triangles.iter().zip(&per_triangle) {
        for &v in tri {
            sum[v as usize] += value;
            count[v as usize] += 1;
        }
    }
    let values: Vec<f32> = sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / c as f32 } else { 0.0 }).collect();
    let largest = values.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    // A tiny floor keeps an unstrained cloth from showing round-off as full colour.
    let floor = if map == ColourMap::Bending { 1e-3 } else { 1e-5 };
    let extent = largest.max(floor);
    let (min, max) = if map.signed() { (-extent, extent) } else { (0.0, extent) };
    Some(Field { values, min, max })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_normalises_symmetrically_for_signed_maps() {
        let f = Field { values: vec![-0.01, 0.0, 0.02], min: -0.02, max: 0.02 };
        assert_eq!(f.normalised(0.0), 0.5);
        assert_eq!(f.normalised(0.02), 1.0);
        assert_eq!(f.normalised(-0.01), 0.25);
    }
}
