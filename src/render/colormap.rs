//! Colour maps of strain and curvature fields: what each shows, its scale, and a field of
//! per-vertex values with the range the scale spans.

use std::fmt;
use std::str::FromStr;

/// A field the cloth can be coloured by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ColorMap {
    /// ε along the warp (the rosette's ε_xx).
    WarpStrain,
    /// ε along the weft (ε_yy).
    WeftStrain,
    /// Engineering shear strain γ between warp and weft.
    Shear,
    /// Curvature magnitude √(κ_xx² + κ_yy² + 2κ_xy²), 1/m.
    Bending,
}

impl ColorMap {
    pub const ALL: [ColorMap; 4] = [Self::WarpStrain, Self::WeftStrain, Self::Shear, Self::Bending];

    /// The name used on the command line (`--colormap warp`).
    pub fn name(self) -> &'static str {
        match self {
            Self::WarpStrain => "warp",
            Self::WeftStrain => "weft",
            Self::Shear => "shear",
            Self::Bending => "bending",
        }
    }

    /// The viewer's name for it, with its symbol and unit.
    pub fn label(self) -> &'static str {
        match self {
            Self::WarpStrain => "warp strain ε_x",
            Self::WeftStrain => "weft strain ε_y",
            Self::Shear => "shear strain γ",
            Self::Bending => "curvature |κ| (1/m)",
        }
    }

    /// The legend's title (the bitmap font has capitals, digits and a few signs).
    pub fn title(self) -> &'static str {
        match self {
            Self::WarpStrain => "WARP STRAIN",
            Self::WeftStrain => "WEFT STRAIN",
            Self::Shear => "SHEAR STRAIN",
            Self::Bending => "CURVATURE 1/M",
        }
    }

    /// Signed fields use a diverging scale centred on zero; magnitudes a sequential one.
    pub fn signed(self) -> bool {
        !matches!(self, Self::Bending)
    }

    /// The index of a strain map's component in `[ε_warp, ε_weft, γ]`
    /// ([`crate::sim::Model::triangle_strains`]); `None` for the curvature map.
    pub fn strain_component(self) -> Option<usize> {
        match self {
            Self::WarpStrain => Some(0),
            Self::WeftStrain => Some(1),
            Self::Shear => Some(2),
            Self::Bending => None,
        }
    }

    /// Row of this map in the renderer's gradient texture.
    pub(crate) fn row(self) -> u32 {
        Self::ALL.iter().position(|m| *m == self).expect("in ALL") as u32
    }

    /// Colour at `t` (0..1, clamped) of this map's scale, sRGB 0..1: blue–grey–red for
    /// signed fields, dark violet through teal to yellow for magnitudes.
    pub fn color(self, t: f32) -> [f32; 3] {
        const DIVERGING: [[f32; 3]; 3] = [[0.23, 0.30, 0.75], [0.87, 0.87, 0.87], [0.71, 0.02, 0.15]];
        const SEQUENTIAL: [[f32; 3]; 4] = [[0.27, 0.00, 0.33], [0.13, 0.57, 0.55], [0.48, 0.82, 0.32], [0.99, 0.91, 0.14]];
        let stops: &[[f32; 3]] = if self.signed() { &DIVERGING } else { &SEQUENTIAL };
        let x = if t.is_nan() { 0.5 } else { t.clamp(0.0, 1.0) } * (stops.len() - 1) as f32;
        let i = (x.floor() as usize).min(stops.len() - 2);
        let f = x - i as f32;
        std::array::from_fn(|c| stops[i][c] + f * (stops[i + 1][c] - stops[i][c]))
    }
}

impl fmt::Display for ColorMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ColorMap {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            format!("unknown colour map '{s}'; use one of {}", names.join(", "))
        })
    }
}

/// One value per cloth vertex and the range the colour scale spans.
#[derive(Debug, Clone, PartialEq)]
pub struct ScalarField {
    pub map: ColorMap,
    /// Per-vertex values, in the map's unit (strain: 1; curvature: 1/m).
    pub values: Vec<f32>,
    /// Value at the bottom of the scale.
    pub min: f32,
    /// Value at the top of the scale.
    pub max: f32,
}

impl ScalarField {
    /// Per-triangle values averaged onto the vertices, with a range that spans them:
    /// symmetric about zero for signed maps, from zero for magnitudes.
    pub fn from_triangles(map: ColorMap, per_triangle: &[f32], triangles: &[[u32; 3]], vertex_count: usize) -> Self {
        let (mut sum, mut count) = (vec![0.0f32; vertex_count], vec![0u32; vertex_count]);
        for (tri, &value) in triangles.iter().zip(per_triangle) {
            for &v in tri {
                sum[v as usize] += value;
                count[v as usize] += 1;
            }
        }
        let values: Vec<f32> = sum.iter().zip(&count).map(|(s, &c)| if c > 0 { s / c as f32 } else { 0.0 }).collect();
        let largest = values.iter().filter(|v| v.is_finite()).fold(0.0f32, |m, v| m.max(v.abs()));
        // A floor keeps an unstrained cloth from showing round-off at full colour.
        let floor = if map.signed() { 1e-5 } else { 1e-3 };
        let extent = largest.max(floor);
        let (min, max) = if map.signed() { (-extent, extent) } else { (0.0, extent) };
        Self { map, values, min, max }
    }

    /// Position of `value` on the scale, 0..1.
    pub fn normalised(&self, value: f32) -> f32 {
        if self.max > self.min { ((value - self.min) / (self.max - self.min)).clamp(0.0, 1.0) } else { 0.5 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_run_end_to_end_and_clamp() {
        assert_eq!(ColorMap::WarpStrain.color(0.0), [0.23, 0.30, 0.75]);
        assert_eq!(ColorMap::Shear.color(0.5), [0.87, 0.87, 0.87]);
        assert_eq!(ColorMap::Bending.color(1.0), [0.99, 0.91, 0.14]);
        assert_eq!(ColorMap::Bending.color(7.0), ColorMap::Bending.color(1.0));
        assert_eq!(ColorMap::Bending.color(-1.0), [0.27, 0.00, 0.33]);
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_listed() {
        for map in ColorMap::ALL {
            assert_eq!(map.name().parse::<ColorMap>(), Ok(map));
        }
        let e = "strain".parse::<ColorMap>().unwrap_err();
        assert!(e.contains("warp, weft, shear, bending"), "{e}");
    }

    #[test]
    fn triangle_values_average_onto_vertices_with_a_symmetric_range() {
        // Two triangles sharing the edge 1–2.
        let triangles = [[0, 1, 2], [1, 3, 2]];
        let f = ScalarField::from_triangles(ColorMap::WarpStrain, &[0.02, -0.01], &triangles, 4);
        assert_eq!(f.values, vec![0.02, 0.005, 0.005, -0.01]);
        assert_eq!((f.min, f.max), (-0.02, 0.02));
        assert_eq!(f.normalised(0.0), 0.5);
        let b = ScalarField::from_triangles(ColorMap::Bending, &[3.0, 1.0], &triangles, 4);
        assert_eq!((b.min, b.max), (0.0, 3.0));
        let flat = ScalarField::from_triangles(ColorMap::Shear, &[0.0, 0.0], &triangles, 4);
        assert!(flat.max > 0.0 && flat.normalised(0.0) == 0.5);
    }
}
