//! The fabric card: the virtual laboratory's whole suite run on one fabric, written as one
//! PNG page and a JSON file (`rosette card`, the viewer's Fabric card window).
//!
//! The suite ([`compute`]): KES tensile pulls along the warp and the weft to 500 gf/cm and a
//! bias pull to the same strain, pure bending and the ASTM D1388 cantilever in the warp, weft
//! and bias, KES shear, and the 30 cm Cusick drape (`cusick-drape-30`). Every test is one of
//! `crate::lab`'s, on the meshes those tests were validated on; the tests are independent and
//! run in parallel on rayon's pool. [`Card`] holds what they read, each value beside the input
//! it should give back, in units a textile laboratory reports (each field's name carries its
//! unit). [`page`] draws the PNG page; [`picture`] renders the drape headless; [`compare`]
//! drapes several fabrics on one scene for a contact sheet (`rosette compare`).
//!
//! docs/card.md is the user's guide.

pub mod compare;
pub mod page;
pub mod picture;
mod suite;

pub use crate::io::progress::Progress;
pub use suite::{CardRun, compute, drape_config, scene_fabric};

use crate::lab::LabError;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Why a card could not be made.
#[derive(Debug, Error)]
pub enum CardError {
    /// The fabric or the scene is not usable: nothing was run.
    #[error("{0}")]
    BadInput(String),
    /// A virtual test failed (diverged or read nothing).
    #[error(transparent)]
    Lab(#[from] LabError),
    /// The drape failed.
    #[error("drape: {0}")]
    Drape(String),
    #[error("cancelled after {done} of {total} tests")]
    Cancelled { done: usize, total: usize },
    /// The page could not be drawn or a file written.
    #[error("{0}")]
    Output(String),
}

/// A card made: its numbers, its page and the draped scene.
pub struct Made {
    pub card: Card,
    /// The page's RGB pixels, [`page::SIZE`].
    pub page: Vec<u8>,
    /// Why the drape pictures are missing from the page, if they are (no graphics adapter).
    pub picture_error: Option<String>,
    /// The drape's final state.
    pub drape: crate::scene::Scene,
}

impl Made {
    /// The page as an image.
    pub fn page_image(&self) -> image::RgbImage {
        image::RgbImage::from_raw(page::SIZE.0, page::SIZE.1, self.page.clone()).expect("the page's size")
    }

    /// Writes `dir/stem.json` and `dir/stem.png`; returns their paths.
    pub fn write(&self, dir: &std::path::Path, stem: &str) -> Result<[std::path::PathBuf; 2], CardError> {
        let json = dir.join(format!("{stem}.json"));
        let png = dir.join(format!("{stem}.png"));
        let text = serde_json::to_string_pretty(&self.card).map_err(|e| CardError::Output(e.to_string()))? + "\n";
        crate::io::write::whole(&json, text.as_bytes()).map_err(|e| CardError::Output(format!("cannot write {}: {e}", json.display())))?;
        picture::save_png(&png, self.page.clone(), page::SIZE).map_err(CardError::Output)?;
        Ok([json, png])
    }
}

/// Runs the suite ([`compute`]), renders the drape and draws the page. A drape that cannot
/// be rendered (no graphics adapter) leaves a note on the page and in `picture_error`; the
/// numbers are all there. The cost covers the tests, the pictures and the page.
pub fn make(
    fabric: &crate::settings::FabricConfig,
    source: &str,
    sheets: Option<(&crate::fabric::Sheets, &crate::fabric::Import)>,
    progress: &Progress,
) -> Result<Made, CardError> {
    let wall = std::time::Instant::now();
    let cpu = cpu_time::ProcessTime::now();
    let CardRun { mut card, drape } = compute(fabric, source, sheets, progress)?;
    progress.set_stage("rendering the drape");
    let pictures = picture::drape_views(&drape, page::PICTURE);
    card.cost.cpu_seconds = cpu.elapsed().as_secs_f64();
    card.cost.wall_seconds = wall.elapsed().as_secs_f64();
    progress.set_stage("drawing the page");
    let picture_error = pictures.as_ref().err().map(|e| e.to_string());
    let page = page::draw(&card, pictures.as_ref().map_err(|_| picture_error.as_deref().unwrap_or_default())).map_err(CardError::Output)?;
    Ok(Made { card, page, picture_error, drape })
}

/// A curve with its axes' names and units, as the card shows it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    /// What the first value of each point is, with its unit, e.g. `strain (%)`.
    pub x: String,
    /// What the second value is, with its unit, e.g. `stress (N/m)`.
    pub y: String,
    pub points: Vec<[f64; 2]>,
}

impl Curve {
    pub fn new(x: &str, y: &str, points: Vec<[f64; 2]>) -> Self {
        Self { x: x.into(), y: y.into(), points }
    }
}

/// The fabric the card is of.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FabricInfo {
    /// The fabric's `name`, or the bundled name or file it came from when it has none.
    pub name: String,
    pub description: String,
    /// Where it was read from (`presets/fabrics/wool.toml (bundled)`, a path, or `viewer`).
    pub source: String,
    pub areal_density_g_per_m2: f64,
    pub thickness_mm: f64,
    pub poisson_warp: f64,
    /// How it is drawn (the fabric's `[appearance]`, a texture's path made absolute).
    #[serde(default, skip_serializing_if = "crate::appearance::Appearance::is_empty")]
    pub appearance: crate::appearance::Appearance,
}

/// One tensile pull: the measured curve against the curve the fabric was given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Tensile {
    /// `warp`, `weft` or `bias`.
    pub direction: String,
    /// How the strip was pulled.
    pub test: String,
    /// Extensometer strain (%) against the clamp's load per width (N/m).
    pub measured: Curve,
    /// What the fabric should give: its input curve (warp, weft) or the off-axis formula's
    /// small-strain line σ = E₄₅·ε (bias, docs/references.md §1).
    pub input: Curve,
    /// Which input that is.
    pub input_label: String,
    /// KES EMT, the strain at 500 gf/cm, % (warp and weft).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub emt_percent: Option<f64>,
    /// The input curve's strain at 500 gf/cm, % (warp and weft).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input_emt_percent: Option<f64>,
    /// KES LT, linearity of the curve to 500 gf/cm (warp and weft).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lt: Option<f64>,
    /// KES WT, tensile energy to 500 gf/cm, gf·cm/cm² (warp and weft).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wt_gf_cm_per_cm2: Option<f64>,
    /// The off-axis formula's modulus E₄₅, N/m (bias).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e45_formula_n_per_m: Option<f64>,
}

/// Pure bending (KES-FB2) in one direction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Bending {
    pub direction: String,
    /// B read between 0.5 and 1.5 cm⁻¹, µN·m.
    pub rigidity_un_m: f64,
    /// The same in KES's unit, gf·cm²/cm.
    pub rigidity_gf_cm2_per_cm: f64,
    /// The fabric's small-curvature rigidity in this direction (eq. 3 off the axes), µN·m.
    pub input_rigidity_un_m: f64,
    /// The two readings: curvature (1/cm) and moment per width (gf·cm/cm).
    pub readings: Curve,
}

/// The ASTM D1388 / BS 3356 cantilever in one direction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Cantilever {
    pub direction: String,
    pub strip_width_mm: f64,
    /// Half the overhang at which the chord meets 41.5°, mm.
    pub bending_length_mm: f64,
    pub overhang_mm: f64,
    /// The standard's relation B = w·c³ solved for c with the fabric's input rigidity in
    /// this direction and w = ρ·g, mm.
    pub formula_bending_length_mm: f64,
    /// Cantilevers run in the search for 41.5°.
    pub runs: usize,
}

/// KES shear.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Shear {
    /// G, the mean slope from 0.5° to 5°, N/m (per radian).
    pub modulus_n_per_m: f64,
    /// G in KES's unit, gf/(cm·deg).
    pub g_gf_per_cm_deg: f64,
    /// The fabric's shear_modulus, N/m.
    pub input_modulus_n_per_m: f64,
    /// Shear angle (°) against force per grip length (N/m).
    pub curve: Curve,
}

/// The Cusick drape.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Drape {
    /// The scene it was draped on.
    pub scene: String,
    pub specimen_diameter_mm: f64,
    pub support_diameter_mm: f64,
    #[serde(flatten)]
    pub result: DrapeResult,
    pub vertices: usize,
    pub triangles: usize,
    pub edge_length_mm: f64,
    /// The shadow's outline: angle (°) against radius from the support's centre (mm).
    pub outline: Curve,
}

/// A drape coefficient for people: three decimals, or "not measured" where the run gave
/// none (a cloth that had not draped, `scene::possible::judge`).
pub fn dc_text(drape_coefficient: f64) -> String {
    if drape_coefficient.is_finite() { format!("{drape_coefficient:.3}") } else { "not measured".into() }
}

fn not_measured() -> f64 {
    f64::NAN
}

fn is_not_measured(value: &f64) -> bool {
    value.is_nan()
}

/// What a drape run came to, as the card and `rosette compare` both report it.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DrapeResult {
    /// (A_shadow − A_support)/(A_specimen − A_support); NaN, and absent from the JSON,
    /// where the run measured none.
    #[serde(default = "not_measured", skip_serializing_if = "is_not_measured")]
    pub drape_coefficient: f64,
    pub nodes: usize,
    pub outline_radius_min_mm: f64,
    pub outline_radius_max_mm: f64,
    /// Whether the cloth came to rest (RMS speed below the scene's settle speed).
    pub settled: bool,
    /// Simulated time at which it settled, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_time_s: Option<f64>,
    pub simulated_s: f64,
    /// Whether every Newton solve converged.
    pub converged: bool,
}

impl DrapeResult {
    /// From a run's metrics; the drape's own numbers stay zero where the run has no drape
    /// measures.
    pub fn from_metrics(metrics: &crate::scene::Metrics) -> Self {
        let mut result = Self {
            settled: metrics.settled.unwrap_or(false),
            settle_time_s: metrics.settle_time,
            simulated_s: metrics.simulated_seconds,
            converged: metrics.converged,
            ..Self::default()
        };
        if let Some(d) = metrics.measures.drape() {
            result.drape_coefficient = d.drape_coefficient;
            result.nodes = d.nodes;
            result.outline_radius_min_mm = 1e3 * d.outline_radius_min.unwrap_or(f64::NAN);
            result.outline_radius_max_mm = 1e3 * d.outline_radius_max;
        }
        if let Some(g) = metrics.measures.garment() {
            result.drape_coefficient = g.garment_drape_coefficient;
            result.nodes = g.hem_nodes;
            result.outline_radius_min_mm = 1e3 * g.hem_radius_min;
            result.outline_radius_max_mm = 1e3 * g.hem_radius_max;
        }
        result
    }

    /// "settled at T s", or "not settled after T s" with the time simulated: the card's and
    /// the contact sheet's wording.
    pub fn settle_status(&self) -> String {
        match (self.settled, self.settle_time_s) {
            (true, Some(t)) => format!("settled at {t:.2} s"),
            _ => format!("not settled after {:.2} s", self.simulated_s),
        }
    }
}

/// One sheet value read back by a virtual test (fabrics made from sheets).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SheetValue {
    /// The sheet field, e.g. `kes.B_warp`.
    pub field: String,
    pub unit: String,
    pub sheet: f64,
    pub measured: f64,
    pub error_percent: f64,
    pub tolerance_percent: f64,
    pub test: String,
    pub passes: bool,
    /// False for a value the fabric's keys cannot hold (an ARCSim sample its projection
    /// drops): reported, not held to the tolerance.
    #[serde(default = "held_by_default")]
    pub held: bool,
}

fn held_by_default() -> bool {
    true
}

/// What the card cost to make.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    /// Process CPU time of the whole card (tests, pictures, page), s.
    pub cpu_seconds: f64,
    pub wall_seconds: f64,
    /// Threads of the pool the tests ran on.
    pub threads: usize,
    /// Each test's wall time on its thread, s.
    pub tests: Vec<(String, f64)>,
}

/// Everything the card shows. Written as `NAME.json` beside the page.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Card {
    pub fabric: FabricInfo,
    /// Warp, weft and bias.
    pub tensile: Vec<Tensile>,
    /// Warp, weft and bias.
    pub pure_bending: Vec<Bending>,
    /// Warp, weft and bias, 25 mm strips.
    pub cantilever: Vec<Cantilever>,
    pub shear: Shear,
    pub drape: Drape,
    /// The sheet's values read back (empty for a fabric given by its keys).
    pub sheet_readback: Vec<SheetValue>,
    pub cost: Cost,
}
