//! What every pattern import shares (GarmentCode's specification, pattern CAD's DXF): the
//! garment section it fills, the scene written around it, and the hem it finds
//! (docs/garments.md, "Importing a GarmentCode pattern" and "Patterns from pattern CAD").

use super::form::FormConfig;
use super::pattern::{PanelConfig, Units};
use super::seams::SeamConfig;
use super::{GarmentConfig, GarmentError};

/// What an import gives: the garment section, and what the reader chose for the user to
/// know (the hem it took, units assumed, pieces left out).
pub struct Imported {
    pub garment: GarmentConfig,
    pub notes: Vec<String>,
}

/// The fabric an imported garment is made of unless one is named.
pub const DEFAULT_FABRIC: &str = "cotton-shirting";

/// The form an imported garment goes on unless one is named: the largest bundled size.
pub fn default_form() -> FormConfig {
    FormConfig { size: Some("uk-14".into()), ..FormConfig::default() }
}

/// A garment section in centimetres with the sewing defaults of docs/garments.md.
pub fn garment(form: FormConfig, panels: Vec<PanelConfig>, seams: Vec<SeamConfig>, hem: Vec<String>, seam_ease: f64) -> GarmentConfig {
    GarmentConfig {
        units: Units::Cm,
        form,
        panels,
        seams,
        attachments: Vec::new(),
        hem,
        seam_ease,
        sewing_stiffness: super::default_sewing_stiffness(),
        sewing_ramp: super::default_sewing_ramp(),
        sewing_damping: super::default_sewing_damping(),
        sewing_time: super::default_sewing_time(),
        closed_share: super::default_closed_share(),
    }
}

/// Where an imported pattern came from, for the scene file's header.
pub struct Origin<'a> {
    /// What the file is, after "a garment imported from" ("GarmentCode's pattern specification").
    pub format: &'a str,
    /// The tool in a few words, for the scene's description ("GarmentCode").
    pub short: &'a str,
    /// How the panels start, a sentence.
    pub placement: &'a str,
}

/// The scene file of an imported garment named `name`, read from `source`, in `fabric`.
pub fn scene_text(imported: &Imported, origin: &Origin, source: &str, name: &str, fabric: &str) -> Result<String, GarmentError> {
    #[derive(serde::Serialize)]
    struct Section<'a> {
        garment: &'a GarmentConfig,
    }
    let garment = toml::to_string(&Section { garment: &imported.garment })
        .map_err(|e| GarmentError::new(format!("{source}: the garment cannot be written as TOML ({e})")))?;
    let clean = |text: &str| text.replace(['"', '\\', '\n', '\r'], "'");
    let (name, fabric) = (clean(name), clean(fabric));
    let (panels, seams) = (imported.garment.panels.len(), imported.garment.seams.len());
    Ok(format!(
        "# {name}: a garment imported from {} {}\n\
         # Written by `rosette pattern import` ({panels} panels, {seams} seams). Lengths in [garment] are in cm;\n\
         # {} Every other setting is a garment's\n\
         # (presets/bases/garment.toml in the repository).\n\
         base = \"garment\"\n\n\
         [scene]\ndescription = \"{name} ({panels} panels, from {}) in {fabric}\"\n\n[fabric]\npreset = \"{fabric}\"\n\n{garment}",
        origin.format,
        source.replace(['\n', '\r'], " "),
        origin.placement,
        clean(origin.short),
    ))
}

/// How far above the garment's lowest point a free edge's ends may lie and still be hem, in
/// the garment's units (cm).
const HEM_BAND: f64 = 3.0;

/// The hem: the free edges (`stitched[p]` lists panel p's sewn edges) at the garment's
/// bottom, both ends (`heights`, cm above the floor, by panel and edge) within [`HEM_BAND`]
/// of its lowest point, as `panel.edge`.
pub fn hem_edges(panels: &[PanelConfig], heights: &[Vec<[f64; 2]>], stitched: &[Vec<usize>]) -> Vec<String> {
    let lowest = heights.iter().flatten().flatten().copied().fold(f64::INFINITY, f64::min);
    let mut hem = Vec::new();
    for (p, edges) in heights.iter().enumerate() {
        for (e, ends) in edges.iter().enumerate() {
            if !stitched[p].contains(&e) && ends.iter().all(|&z| z < lowest + HEM_BAND) {
                hem.push(format!("{}.{}", panels[p].name, panels[p].edges[e].name));
            }
        }
    }
    hem
}

/// A note on the hem found.
pub fn hem_note(hem: &[String]) -> String {
    if hem.is_empty() { "no free edge at the garment's bottom: no hem".into() } else { format!("hem: {}", hem.join(", ")) }
}
