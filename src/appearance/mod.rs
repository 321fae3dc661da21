//! A fabric's look: its colour, the weave or the printed image on it, and its sheen, as a
//! fabric file's `[appearance]` table gives them, checked into a [`Look`] that every
//! drawing of the fabric uses: the window and its swatch, headless screenshots, the fabric
//! card, the compare sheet and the glTF export.
//!
//! The look belongs to the fabric file ([`crate::settings::FabricConfig`]), beside the
//! mechanics, never to the simulator: `sim` knows nothing of it.
//!
//! - [`weave`]: plain, twill and satin textures generated from their interlacing, so no
//!   weave ships as a picture;
//! - [`texture`]: a fabric's own image (PNG or JPEG) read through `io::read`, checked,
//!   decoded once and kept;
//! - [`shade`]: the cloth's light (a diffuse base under a Charlie sheen, the model of glTF's
//!   `KHR_materials_sheen`) on the CPU, for the swatch beside the fabric editor; the shader
//!   `shaders/scene.wgsl` does the same on the GPU.
//!
//! docs/appearance.md is the user's account of the keys, the drawing and where each bundled
//! look came from.

pub mod shade;
pub mod texture;
pub mod weave;

pub use texture::TextureImage;
pub use weave::Weave;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::path::Path;
use std::sync::Arc;
use thiserror::Error;

/// An sRGB colour, as a fabric file writes it (`"#RRGGBB"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Colour(pub [u8; 3]);

impl Colour {
    /// `#RRGGBB` (the `#` may be left out), case-insensitive.
    pub fn parse(text: &str) -> Result<Self, String> {
        let hex = text.trim().strip_prefix('#').unwrap_or(text.trim());
        let bad = || format!("\"{text}\" is not a colour: write it in sRGB as \"#RRGGBB\", e.g. \"#2B3A67\" for an indigo");
        if hex.len() != 6 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
            return Err(bad());
        }
        let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| bad());
        Ok(Self([byte(0)?, byte(2)?, byte(4)?]))
    }

    /// `#RRGGBB`, upper case.
    pub fn hex(self) -> String {
        format!("#{:02X}{:02X}{:02X}", self.0[0], self.0[1], self.0[2])
    }

    /// sRGB components, 0..1.
    pub fn srgb(self) -> [f32; 3] {
        self.0.map(|c| f32::from(c) / 255.0)
    }

    /// Linear-light components, 0..1 (what shading multiplies).
    pub fn linear(self) -> [f32; 3] {
        self.srgb().map(srgb_to_linear)
    }
}

impl Serialize for Colour {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.hex())
    }
}

impl<'de> Deserialize<'de> for Colour {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        Colour::parse(&text).map_err(serde::de::Error::custom)
    }
}

/// sRGB to linear light (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Linear light to sRGB, clamped to 0..1.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// A fabric file's `[appearance]` table, as serde reads it; every key optional. Checked
/// into a [`Look`] by [`Look::check`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Appearance {
    /// The fabric's colour, sRGB. Without it: a terracotta, or with a texture white (the
    /// image as it is); with a texture it tints the image.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<Colour>,
    /// The weave drawn when there is no texture; plain when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weave: Option<Weave>,
    /// An image repeated over the cloth along its warp and weft (a print, a photograph of
    /// the fabric).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<TextureConfig>,
    /// A sheen over the base colour (glTF's `KHR_materials_sheen`); none when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sheen: Option<SheenConfig>,
}

impl Appearance {
    /// Whether nothing is set (the table is then not written).
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    /// The same look with its texture's path made absolute (relative paths taken against
    /// `base_dir`, else the working directory), for a file written elsewhere: a fabric
    /// export, an imported sheet written to `--out`. A bundled texture keeps its name.
    pub fn anchored(&self, base_dir: Option<&Path>) -> Self {
        let mut out = self.clone();
        if let Some(t) = &mut out.texture
            && !texture::is_bundled(&t.file)
        {
            let path = match base_dir {
                Some(base) => base.join(&t.file),
                None => Path::new(&t.file).to_path_buf(),
            };
            t.file = std::path::absolute(&path).unwrap_or(path).display().to_string();
        }
        out
    }
}

/// `[appearance.texture]`: an image and the size of one repeat of it on the cloth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureConfig {
    /// A PNG or JPEG file: a bundled texture's name (`assets/prints/…`) or a path, relative
    /// to the fabric file's folder.
    pub file: String,
    /// One repeat of the image on the cloth, along the warp (the image's width) and along
    /// the weft (its height), mm.
    pub size_mm: [f64; 2],
}

/// `[appearance.sheen]`: the glTF sheen of cloth (velvet's, satin's and silk's glow at
/// grazing angles).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SheenConfig {
    /// The sheen's colour, sRGB (glTF's `sheenColorFactor`): black is none, white the
    /// strongest.
    pub colour: Colour,
    /// How broad the sheen is, 0..1 (glTF's `sheenRoughnessFactor`): low for a satin's
    /// narrow glow at the silhouette, high for a brushed or napped fabric's soft one.
    #[serde(default = "default_roughness")]
    pub roughness: f64,
}

fn default_roughness() -> f64 {
    0.5
}

/// Why an `[appearance]` cannot be drawn: its key (under the fabric table,
/// `appearance.texture.size_mm`) and the message, which names the key and the fix.
#[derive(Debug, Clone, Error, PartialEq)]
#[error("{message}")]
pub struct AppearanceError {
    pub key: &'static str,
    pub message: String,
}

/// The repeat of a texture may be from a tenth of a millimetre (a fine yarn) to ten metres
/// (a panel print).
const REPEAT_MM: (f64, f64) = (0.1, 10_000.0);

/// What the cloth is drawn with: a checked [`Appearance`]. Only [`Look::check`] makes one
/// from a fabric file, so a texture in it has been read and decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct Look {
    /// The colour, sRGB: the tint of the weave, or of the image.
    pub colour: Colour,
    /// What is laid along the warp and weft.
    pub pattern: Pattern,
    /// One repeat of the pattern along the warp and along the weft, m.
    pub repeat_m: [f64; 2],
    pub sheen: Option<Sheen>,
}

/// The weave generated, or the fabric's own image.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    Weave(Weave),
    Image(Arc<TextureImage>),
}

/// A checked sheen: colour sRGB, roughness 0..1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sheen {
    pub colour: Colour,
    pub roughness: f32,
}

/// The look of a fabric with no `[appearance]`: the terracotta plain weave Rosette has
/// always drawn.
pub const DEFAULT_COLOUR: Colour = Colour([0xB8, 0x40, 0x29]);

impl Default for Look {
    fn default() -> Self {
        let weave = Weave::Plain;
        Self { colour: DEFAULT_COLOUR, pattern: Pattern::Weave(weave), repeat_m: [weave.repeat_m(); 2], sheen: None }
    }
}

impl Look {
    /// Checks `appearance` (from a fabric table; a relative texture path is taken against
    /// `base_dir`, where the scene's own `[fabric]` gave it) and reads its texture.
    pub fn check(appearance: &Appearance, base_dir: Option<&Path>) -> Result<Self, AppearanceError> {
        let error = |key: &'static str, message: String| AppearanceError { key, message };
        let sheen = match &appearance.sheen {
            None => None,
            Some(s) => {
                if !(s.roughness.is_finite() && (0.0..=1.0).contains(&s.roughness)) {
                    return Err(error(
                        "appearance.sheen.roughness",
                        format!("fabric.appearance.sheen.roughness must lie in 0..1 (glTF's sheenRoughnessFactor; 0.3 for a satin, 0.8 for a napped fabric), got {}", crate::io::number::short(s.roughness)),
                    ));
                }
                Some(Sheen { colour: s.colour, roughness: s.roughness as f32 })
            }
        };
        match (&appearance.texture, appearance.weave) {
            (Some(_), Some(weave)) => Err(error(
                "appearance.weave",
                format!(
                    "fabric.appearance.weave = \"{}\" has no effect beside appearance.texture (the image is drawn instead of the weave); remove one of them",
                    weave.name()
                ),
            )),
            (Some(t), None) => {
                for (k, axis) in [(0, "warp"), (1, "weft")] {
                    let v = t.size_mm[k];
                    if !(v.is_finite() && (REPEAT_MM.0..=REPEAT_MM.1).contains(&v)) {
                        return Err(error(
                            "appearance.texture.size_mm",
                            format!(
                                "fabric.appearance.texture.size_mm = [{}, {}]: the repeat along the {axis} must be from {} to {} mm (the image's size on the cloth), got {}",
                                crate::io::number::short(t.size_mm[0]),
                                crate::io::number::short(t.size_mm[1]),
                                REPEAT_MM.0,
                                REPEAT_MM.1,
                                crate::io::number::short(v)
                            ),
                        ));
                    }
                }
                let image = texture::load(&t.file, base_dir).map_err(|message| error("appearance.texture.file", format!("fabric.appearance.texture.file: {message}")))?;
                Ok(Self {
                    colour: appearance.colour.unwrap_or(Colour([255; 3])),
                    pattern: Pattern::Image(image),
                    repeat_m: t.size_mm.map(|v| 1e-3 * v),
                    sheen,
                })
            }
            (None, weave) => {
                let weave = weave.unwrap_or_default();
                Ok(Self { colour: appearance.colour.unwrap_or(DEFAULT_COLOUR), pattern: Pattern::Weave(weave), repeat_m: [weave.repeat_m(); 2], sheen })
            }
        }
    }

    /// The look of a fabric as the renderer and the exporter take it: the checked look, or
    /// the default where the appearance no longer checks (a texture file removed since the
    /// fabric was loaded), so that a picture is still drawn.
    pub fn or_default(appearance: &Appearance, base_dir: Option<&Path>) -> Self {
        Self::check(appearance, base_dir).unwrap_or_default()
    }

    /// The pattern's texels, sRGB RGBA, warp along x: the weave generated or the image.
    pub fn texels(&self) -> Arc<image::RgbaImage> {
        match &self.pattern {
            Pattern::Weave(w) => w.texels(),
            Pattern::Image(t) => Arc::clone(&t.image),
        }
    }

    /// How the look is named in lists: `#2B3A67 twill, sheen #B0B8D0 0.4`.
    pub fn summary(&self) -> String {
        let pattern = match &self.pattern {
            Pattern::Weave(w) => format!("{} {}", self.colour.hex(), w.name()),
            Pattern::Image(t) => {
                let tint = if self.colour == Colour([255; 3]) { String::new() } else { format!(" tinted {}", self.colour.hex()) };
                let stem = Path::new(&t.name).file_stem().map_or_else(|| t.name.clone(), |s| s.to_string_lossy().into_owned());
                let mm = |m: f64| crate::io::number::short(1e3 * m);
                format!("print {stem}{tint}, {}×{} mm", mm(self.repeat_m[0]), mm(self.repeat_m[1]))
            }
        };
        match self.sheen {
            Some(s) => format!("{pattern}, sheen {} {:.2}", s.colour.hex(), s.roughness),
            None => pattern,
        }
    }
}

/// A fabric table's `[appearance]` value read, a refusal naming the key at fault: a colour
/// that is not one (`appearance.colour`, `appearance.sheen.colour`), else the table.
pub fn from_value(value: &toml::Value) -> Result<Appearance, AppearanceError> {
    value.clone().try_into().map_err(|e: toml::de::Error| {
        let not_a_colour = |v: Option<&toml::Value>| v.is_some_and(|v| v.as_str().is_none_or(|s| Colour::parse(s).is_err()));
        let key = if not_a_colour(value.get("colour")) {
            "appearance.colour"
        } else if not_a_colour(value.get("sheen").and_then(|s| s.get("colour"))) {
            "appearance.sheen.colour"
        } else {
            "appearance"
        };
        AppearanceError { key, message: format!("fabric.{key}: {}", e.message().trim()) }
    })
}

/// Makes a relative texture path in a fabric file's table (`appearance.texture.file`)
/// relative to the working directory instead of the file's folder `dir`, so that it still
/// names the same image once the table is merged into a scene or written elsewhere. A
/// bundled texture's name is left as it is.
pub fn resolve_in_table(table: &mut toml::Table, dir: &Path) {
    let file = table
        .get_mut("appearance")
        .and_then(toml::Value::as_table_mut)
        .and_then(|a| a.get_mut("texture"))
        .and_then(toml::Value::as_table_mut)
        .and_then(|t| t.get_mut("file"));
    if let Some(toml::Value::String(file)) = file
        && !texture::is_bundled(file)
        && Path::new(file.as_str()).is_relative()
        && !dir.as_os_str().is_empty()
    {
        *file = dir.join(&*file).display().to_string();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_parse_as_srgb_hex_and_nothing_else() {
        assert_eq!(Colour::parse("#2b3A67"), Ok(Colour([0x2B, 0x3A, 0x67])));
        assert_eq!(Colour::parse("2B3A67").unwrap().hex(), "#2B3A67");
        for bad in ["#2B3A6", "#2B3A6G", "blue", "#2B3A6700", ""] {
            let e = Colour::parse(bad).unwrap_err();
            assert!(e.contains("#RRGGBB"), "{bad}: {e}");
        }
        let linear = Colour([255, 128, 0]).linear();
        assert!((linear[0] - 1.0).abs() < 1e-6 && (linear[1] - 0.2158).abs() < 1e-3 && linear[2] == 0.0, "{linear:?}");
    }

    fn appearance(text: &str) -> Appearance {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn bad_values_are_refused_naming_their_key() {
        let e = Look::check(&appearance("sheen = { colour = \"#FFFFFF\", roughness = 1.5 }"), None).unwrap_err();
        assert_eq!(e.key, "appearance.sheen.roughness");
        assert!(e.message.contains("0..1"), "{e}");
        let e = Look::check(&appearance("texture = { file = \"assets/prints/white-dots-on-black.png\", size_mm = [0, 10] }"), None).unwrap_err();
        assert_eq!(e.key, "appearance.texture.size_mm");
        assert!(e.message.contains("warp") && e.message.contains("got 0"), "{e}");
        let e = Look::check(&appearance("weave = \"twill\"\ntexture = { file = \"assets/prints/white-dots-on-black.png\", size_mm = [5, 5] }"), None).unwrap_err();
        assert_eq!(e.key, "appearance.weave");
        let e = Look::check(&appearance("texture = { file = \"no/such/print.png\", size_mm = [5, 5] }"), None).unwrap_err();
        assert_eq!(e.key, "appearance.texture.file");
        assert!(e.message.contains("no/such/print.png") && e.message.contains("no such file"), "{e}");
        assert!(toml::from_str::<Appearance>("color = \"#FFFFFF\"").unwrap_err().to_string().contains("color"));
        assert!(toml::from_str::<Appearance>("colour = \"red\"").unwrap_err().to_string().contains("#RRGGBB"));
    }

    #[test]
    fn a_table_that_does_not_read_names_the_colour_at_fault() {
        let value = |text: &str| toml::Value::Table(toml::from_str(text).unwrap());
        let e = from_value(&value("colour = \"blue\"")).unwrap_err();
        assert_eq!(e.key, "appearance.colour");
        assert!(e.message.starts_with("fabric.appearance.colour: ") && e.message.contains("#RRGGBB"), "{e}");
        let e = from_value(&value("colour = \"#102030\"\nsheen = { colour = 3 }")).unwrap_err();
        assert_eq!(e.key, "appearance.sheen.colour");
        let e = from_value(&value("shine = 1")).unwrap_err();
        assert_eq!(e.key, "appearance");
        assert!(e.message.contains("shine"), "{e}");
        assert_eq!(from_value(&value("weave = \"satin\"")).unwrap().weave, Some(Weave::Satin));
    }

    #[test]
    fn a_look_defaults_to_the_terracotta_plain_weave_and_a_print_to_its_own_colours() {
        assert_eq!(Look::check(&Appearance::default(), None).unwrap(), Look::default());
        let print = Look::check(&appearance("texture = { file = \"assets/prints/white-dots-on-black.png\", size_mm = [12, 8] }"), None).unwrap();
        assert_eq!(print.colour, Colour([255; 3]));
        assert_eq!(print.repeat_m, [0.012, 0.008]);
        assert_eq!(print.summary(), "print white-dots-on-black, 12×8 mm");
    }

    #[test]
    fn a_relative_texture_path_is_taken_from_the_fabric_files_folder() {
        let mut table: toml::Table = toml::from_str("[appearance.texture]\nfile = \"prints/a.png\"\nsize_mm = [1, 1]").unwrap();
        resolve_in_table(&mut table, Path::new("fabrics"));
        assert_eq!(table["appearance"]["texture"]["file"].as_str(), Some(Path::new("fabrics").join("prints/a.png").to_str().unwrap()));
        let mut bundled: toml::Table = toml::from_str("[appearance.texture]\nfile = \"assets/prints/white-dots-on-black.png\"\nsize_mm = [1, 1]").unwrap();
        resolve_in_table(&mut bundled, Path::new("fabrics"));
        assert_eq!(bundled["appearance"]["texture"]["file"].as_str(), Some("assets/prints/white-dots-on-black.png"));
    }
}
