//! The registries of what is bundled into the binary: scenes, fabrics and prop meshes,
//! each under the name users type.

/// A preset file bundled into the binary.
pub struct Bundled {
    pub name: &'static str,
    pub text: &'static str,
}

macro_rules! bundled {
    ($dir:literal; $($name:literal),* $(,)?) => {
        &[$(Bundled { name: $name, text: include_str!(concat!("../../presets/", $dir, $name, ".toml")) }),*]
    };
}

/// Bundled scenes; their file stems are the names users type.
pub const SCENES: &[Bundled] = bundled!("";
    "tensile-warp", "tensile-weft", "tensile-bias", "cantilever", "arc", "euler-buckling", "shear-buckling",
    "cusick-drape", "cusick-drape-30", "tablecloth", "sphere-drop",
    "skirt-circle", "skirt-gored-straight", "skirt-gored-bias", "shift-dress", "swing");

/// Bundled base settings a scene file names with `base = "NAME"` and lays its own keys
/// over: the settings a kind of scene shares, written once.
pub const BASES: &[Bundled] = bundled!("bases/"; "garment");

/// Bundled fabrics.
pub const FABRICS: &[Bundled] = bundled!("fabrics/"; "wool", "cotton-shirting", "denim", "polyester", "silk", "wool-plain-fast", "wool-worsted", "wool-flannel", "cotton-poplin", "cotton-oxford", "cotton-lawn", "denim-14oz", "11oz-black-denim", "royal-target", "white-dots-on-blk", "pink-ribbon-brown");

/// An asset file bundled into the binary.
pub struct Asset {
    pub name: &'static str,
    pub text: &'static str,
}

/// Bundled meshes, addressed by their path under the repository (`assets/cushion.obj`).
pub const ASSETS: &[Asset] = &[Asset { name: "assets/cushion.obj", text: include_str!("../../assets/cushion.obj") }];

/// An image bundled into the binary.
pub struct Image {
    pub name: &'static str,
    pub bytes: &'static [u8],
}

/// Bundled textures for `[appearance.texture]`, addressed by their path under the repository
/// (`assets/prints/white-dots-on-black.png`); `assets/prints/prints.py` draws them.
pub const IMAGES: &[Image] = &[
    Image { name: "assets/prints/white-dots-on-black.png", bytes: include_bytes!("../../assets/prints/white-dots-on-black.png") },
    Image { name: "assets/prints/pink-ribbon-on-brown.png", bytes: include_bytes!("../../assets/prints/pink-ribbon-on-brown.png") },
];
