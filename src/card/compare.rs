//! Fabrics side by side (`rosette compare`): each fabric draped on the same scene, the runs
//! in parallel, every settled drape rendered with one camera, and a contact sheet with the
//! fabric's name, drape coefficient and nodes under each picture.

use super::picture::{self, THREE_QUARTER, blit, placeholder};
use super::suite::parallel_map;
use super::{CardError, DrapeResult, Progress};
use crate::render::Headless;
use crate::scene::{CheckedScene, RunOptions, Scene, load_scene, run_scene};
use glam::DVec3;
use image::RgbaImage;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// One picture of the contact sheet, pixels.
pub const TILE: [u32; 2] = [420, 300];
/// The caption under each picture, pixels.
const CAPTION: u32 = 58;
/// The title above the pictures, pixels.
const TITLE: u32 = 44;
/// Pictures per row, at most.
const COLUMNS: usize = 4;

/// One fabric's drape.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The fabric as given (a bundled name or a file).
    pub fabric: String,
    /// Its `name`.
    pub name: String,
    #[serde(flatten)]
    pub result: DrapeResult,
    /// The run's wall time on its thread, s (the runs share the cores).
    pub wall_seconds: f64,
    /// Why the run failed, if it did (it then has no numbers).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The contact sheet's numbers (written as FILE.json).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    pub scene: String,
    /// The `--set` overrides every run had.
    pub overrides: Vec<String>,
    /// The camera every picture shares: yaw and pitch, degrees.
    pub camera_yaw_deg: f64,
    pub camera_pitch_deg: f64,
    pub entries: Vec<Entry>,
    /// Process CPU time of the runs and pictures, s.
    pub cpu_seconds: f64,
    pub wall_seconds: f64,
}

impl Comparison {
    /// The numbers as CSV, one row per fabric.
    pub fn csv(&self) -> String {
        let mut out = String::from(
            "fabric,name,drape_coefficient,nodes,outline_radius_min_mm,outline_radius_max_mm,settled,settle_time_s,converged,error\n",
        );
        for e in &self.entries {
            let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
            out += &format!(
                "{},{},{},{},{},{},{},{},{},{}\n",
                quote(&e.fabric),
                quote(&e.name),
                if e.result.drape_coefficient.is_finite() { e.result.drape_coefficient.to_string() } else { String::new() },
                e.result.nodes,
                e.result.outline_radius_min_mm,
                e.result.outline_radius_max_mm,
                e.result.settled,
                e.result.settle_time_s.map_or(String::new(), |t| t.to_string()),
                e.result.converged,
                quote(e.error.as_deref().unwrap_or(""))
            );
        }
        out
    }
}

/// Each fabric's scene: `scene` with `overrides` and `fabric.preset` set to the fabric, as
/// `rosette run SCENE --set fabric.preset=FABRIC` builds it. Refuses anything but a drape
/// scene, and names the fabric whose file is missing or wrong.
pub fn configs(fabrics: &[String], scene: &str, overrides: &[String]) -> Result<Vec<CheckedScene>, CardError> {
    if fabrics.is_empty() {
        return Err(CardError::BadInput("name at least one fabric to compare".into()));
    }
    fabrics
        .iter()
        .map(|fabric| {
            let mut all = overrides.to_vec();
            all.push(format!("fabric.preset={}", toml::Value::String(fabric.clone())));
            let (config, _) = load_scene(scene, &all).map_err(|e| CardError::BadInput(format!("fabric '{fabric}': {e}")))?;
            if !crate::scene::kinds::of(config.scene.kind).drapes() {
                return Err(CardError::BadInput(format!(
                    "--scene {scene}: not a drape or garment scene, so it has no drape coefficient to compare; use cusick-drape-30, cusick-drape, tablecloth or a garment such as skirt-gored-bias"
                )));
            }
            Ok(config)
        })
        .collect()
}

/// Runs every config (in parallel, one per core) to its end or until it settles.
pub fn run(fabrics: &[String], configs: Vec<CheckedScene>, progress: &Progress) -> Vec<(Entry, Option<Scene>)> {
    progress.set_total(configs.len());
    let jobs: Vec<(String, CheckedScene)> = fabrics.iter().cloned().zip(configs).collect();
    parallel_map(&jobs, |(fabric, config)| {
        let started = Instant::now();
        progress.start(fabric);
        let name = config.fabric.name.clone();
        let mut entry = Entry { fabric: fabric.clone(), name, ..Entry::default() };
        let outcome = Scene::build(config.clone()).map_err(|e| e.to_string()).and_then(|mut scene| {
            let (metrics, error) = run_scene(&mut scene, fabric, RunOptions::default());
            match (error, metrics.measures.garment().filter(|g| !g.sewn)) {
                (Some(e), _) => Err(e.to_string()),
                // An unsewn garment is not shown as if it were finished.
                (None, Some(g)) => Err(format!("not sewn: a seam was still {:.1} mm open at garment.sewing_time", 1e3 * g.open_seam_gap)),
                (None, None) => Ok((scene, metrics)),
            }
        });
        progress.finish(fabric);
        entry.wall_seconds = started.elapsed().as_secs_f64();
        match outcome {
            Ok((scene, metrics)) => {
                entry.result = DrapeResult::from_metrics(&metrics);
                (entry, Some(scene))
            }
            Err(e) => {
                entry.error = Some(e);
                (entry, None)
            }
        }
    })
}

/// Renders every settled drape with one camera, framed on all of them together, so that
/// the pictures compare at one scale. A run that failed gets a note instead.
pub fn pictures(scenes: &[Option<&Scene>]) -> Result<Vec<RgbaImage>, String> {
    let frames: Vec<Option<crate::render::Frame>> = scenes.iter().map(|s| s.map(picture::frame)).collect();
    let bounds: Vec<(DVec3, DVec3)> = frames.iter().flatten().map(picture::bounds).collect();
    let Some(&first) = bounds.first() else {
        return Ok(scenes.iter().map(|_| placeholder(TILE, "the run failed")).collect());
    };
    let (lo, hi) = bounds.iter().fold(first, |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
    let mut headless = Headless::new().map_err(|e| e.to_string())?;
    frames
        .iter()
        .map(|f| match f {
            Some(frame) => picture::render(&mut headless, frame, lo, hi, THREE_QUARTER, TILE).map_err(|e| e.to_string()),
            None => Ok(placeholder(TILE, "the run failed")),
        })
        .collect()
}

/// The contact sheet: a title, then the pictures in rows of up to four, each with its
/// fabric, DC and nodes under it. Returns the RGB pixels and the size.
pub fn contact_sheet(comparison: &Comparison, pictures: &[RgbaImage]) -> Result<(Vec<u8>, (u32, u32)), String> {
    crate::chart::plot::register_font();
    let n = comparison.entries.len().max(1);
    let columns = n.min(COLUMNS);
    let rows = n.div_ceil(columns);
    let size = (columns as u32 * TILE[0], TITLE + rows as u32 * (TILE[1] + CAPTION));
    let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
    let cell = |i: usize| ((i % columns) as u32 * TILE[0], TITLE + (i / columns) as u32 * (TILE[1] + CAPTION));
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let ink = RGBColor(30, 30, 35);
        let title = TextStyle::from(("sans-serif", 20).into_font()).color(&ink);
        let name = TextStyle::from(("sans-serif", 16).into_font()).color(&ink);
        let small = TextStyle::from(("sans-serif", 14).into_font()).color(&RGBColor(80, 80, 90));
        let bad = TextStyle::from(("sans-serif", 14).into_font()).color(&RGBColor(190, 30, 30));
        let heading = format!(
            "{}{}: one camera for all (yaw {:.0}°, pitch {:.0}°); DC = drape coefficient",
            comparison.scene,
            if comparison.overrides.is_empty() { String::new() } else { format!(" ({})", comparison.overrides.join(", ")) },
            comparison.camera_yaw_deg,
            comparison.camera_pitch_deg
        );
        root.draw_text(&heading, &title, (12, 12)).map_err(|e| e.to_string())?;
        for (i, e) in comparison.entries.iter().enumerate() {
            let (x, y) = cell(i);
            let (x, y) = (x as i32 + 10, (y + TILE[1]) as i32 + 6);
            let label = if e.name.is_empty() || e.name == e.fabric { e.fabric.clone() } else { format!("{} ({})", e.fabric, e.name) };
            root.draw_text(&picture::wrap(&label, 46)[0], &name, (x, y)).map_err(|e| e.to_string())?;
            let (line, style) = match &e.error {
                Some(error) => (picture::wrap(&format!("failed: {error}"), 52)[0].clone(), &bad),
                None => (format!("DC {}   {} nodes   {}", super::dc_text(e.result.drape_coefficient), e.result.nodes, e.result.settle_status()), &small),
            };
            root.draw_text(&line, style, (x, y + 24)).map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    for (i, picture) in pictures.iter().enumerate() {
        blit(&mut buffer, size.0, picture, cell(i));
    }
    Ok((buffer, size))
}

/// The camera the contact sheet uses, as recorded in [`Comparison`].
pub fn camera_angles() -> (f64, f64) {
    (THREE_QUARTER.yaw_deg, THREE_QUARTER.pitch_deg)
}
