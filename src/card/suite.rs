//! Running the card's tests: every test of the suite as one job on rayon's pool, the drape
//! first (it is the longest), then the card's numbers from their results.

use super::{Bending, Cantilever, Card, CardError, Cost, Curve, Drape, DrapeResult, FabricInfo, Progress, Shear, SheetValue, Tensile};
use crate::fabric::derived::{Import, KES_FM};
use crate::fabric::sheet::Sheets;
use crate::fabric::units::GF_CM_PER_CM;
use crate::lab::{self, CantileverTest, Direction, KesTensile, LabRuns, PureBending, ShearTest, TensilePull};
use crate::physics::{bending_length, weight_per_area};
use crate::settings::{FabricConfig, SCENES};
use crate::scene::{CheckedScene, Metrics, RunOptions, Scene, SceneConfig, load_scene, run_scene};
use crate::sim::BendingStiffness;
use std::time::Instant;

/// The scene the card drapes the fabric on: the standard 30 cm Cusick specimen.
pub const DRAPE_SCENE: &str = "cusick-drape-30";

/// Points of the shadow's outline kept in the card (the rig measures 1024).
const OUTLINE_POINTS: usize = 256;
/// Most points kept of a measured curve (the KES pull samples every step).
const CURVE_POINTS: usize = 100;

/// Strain as a fraction to %.
fn percent(curve: &[[f64; 2]]) -> Vec<[f64; 2]> {
    curve.iter().map(|q| [100.0 * q[0], q[1]]).collect()
}

/// A finished card: its numbers and the draped scene, for the pictures.
pub struct CardRun {
    pub card: Card,
    pub drape: Scene,
}

/// One test of the suite.
#[derive(Debug, Clone, Copy)]
enum Job {
    Drape,
    Kes(Direction),
    BiasPull,
    Bending(Direction),
    Cantilever(Direction),
    Shear,
}

impl Job {
    fn label(self) -> String {
        match self {
            Job::Drape => format!("drape ({DRAPE_SCENE})"),
            Job::Kes(d) => format!("tensile {}", d.name()),
            Job::BiasPull => "tensile bias".into(),
            Job::Bending(d) => format!("pure bending {}", d.name()),
            Job::Cantilever(d) => format!("cantilever {}", d.name()),
            Job::Shear => "shear".into(),
        }
    }
}

enum Outcome {
    Drape(Box<(Scene, Metrics)>),
    Kes(KesTensile),
    Pull(TensilePull),
    Bending(PureBending),
    Cantilever(CantileverTest),
    Shear(ShearTest),
}

/// `fabric` as the scene `config` runs it: the scene's own `[fabric]` keys other than the
/// fabric's name (and any `--set fabric.KEY`) laid over it (the drape scenes and the
/// garments turn the Poisson coupling off, docs/drape.md), as `rosette run SCENE --set
/// fabric.preset=FABRIC` lays them over a fabric file.
pub fn scene_fabric(config: &SceneConfig, fabric: &FabricConfig) -> Result<FabricConfig, CardError> {
    let bad = |m: String| CardError::BadInput(m);
    if config.own_fabric_keys.is_empty() {
        return Ok(fabric.clone());
    }
    let mut table = toml::Table::try_from(fabric).map_err(|e| bad(format!("fabric: {e}")))?;
    for (key, value) in config.own_fabric_keys.iter().filter(|(k, _)| !matches!(k.as_str(), "preset" | "name" | "description")) {
        crate::settings::fabric::lay_over(&mut table, key.clone(), value.clone());
    }
    toml::Value::Table(table).try_into().map_err(|e: toml::de::Error| bad(format!("fabric: {}", e.message())))
}

/// The bundled drape scene `scene` with `fabric` in it ([`scene_fabric`]).
pub fn drape_config(scene: &str, fabric: &FabricConfig) -> Result<CheckedScene, CardError> {
    if !SCENES.iter().any(|s| s.name == scene) {
        return Err(CardError::BadInput(format!("no bundled scene named '{scene}'")));
    }
    let mut config = load_scene(scene, &[]).map_err(|e| CardError::BadInput(e.to_string()))?.0.into_config();
    config.fabric = scene_fabric(&config, fabric)?;
    crate::scene::check::checked(config).map_err(|e| CardError::BadInput(format!("{scene} with this fabric: {}", e.message)))
}

/// The strain the bias strip is pulled to: as far as the warp and weft input curves go, so
/// that the three pulls cover the same range.
fn bias_strain(fabric: &FabricConfig) -> f64 {
    let p = &fabric.properties;
    let last = |c: &[[f64; 2]]| c.last().map_or(0.0, |q| q[0]);
    last(&p.tensile_warp).max(last(&p.tensile_weft)).clamp(0.005, 0.5)
}

/// The strain at `load` on a piecewise-linear curve, the last segment extended past its
/// end (as the simulator's curves are).
fn strain_at(curve: &[[f64; 2]], load: f64) -> Option<f64> {
    let segment = curve.windows(2).find(|w| w[1][1] >= load).or_else(|| curve.windows(2).last())?;
    let (a, b) = (segment[0], segment[1]);
    (b[1] > a[1]).then(|| a[0] + (load - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
}

/// An input curve as the KES pull sees it: to 500 gf/cm, strain in %.
fn input_to_fm(curve: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = curve.iter().take_while(|p| p[1] < KES_FM).map(|p| [100.0 * p[0], p[1]]).collect();
    if let Some(e) = strain_at(curve, KES_FM) {
        out.push([100.0 * e, KES_FM]);
    }
    out
}

fn run_job(job: Job, fabric: &FabricConfig, drape: &CheckedScene, progress: &Progress) -> Result<Outcome, CardError> {
    let width = crate::fabric::bias::STANDARD_STRIP_WIDTH;
    Ok(match job {
        Job::Drape => {
            let mut scene = Scene::build(drape.clone()).map_err(|e| CardError::Drape(e.to_string()))?;
            let label = job.label();
            let mut report = |f: f64| progress.set_part(&label, f);
            let options = RunOptions { progress: Some(&mut report), ..RunOptions::default() };
            let (metrics, error) = run_scene(&mut scene, DRAPE_SCENE, options);
            if let Some(e) = error {
                return Err(CardError::Drape(e.to_string()));
            }
            Outcome::Drape(Box::new((scene, metrics)))
        }
        Job::Kes(d) => Outcome::Kes(lab::kes_tensile(fabric, d)?),
        Job::BiasPull => Outcome::Pull(lab::tensile_pull(fabric, Direction::Bias, bias_strain(fabric))?),
        Job::Bending(d) => Outcome::Bending(lab::pure_bending(fabric, d)?),
        Job::Cantilever(d) => Outcome::Cantilever(lab::cantilever_bending_length(fabric, d, width)?),
        Job::Shear => Outcome::Shear(lab::shear(fabric)?),
    })
}

/// Runs the card's tests on `fabric` (read from `source`; with its sheets, which are then
/// read back) and gathers the card. `progress` is updated as tests start and end, and
/// stops the card when cancelled.
pub fn compute(fabric: &FabricConfig, source: &str, sheets: Option<(&Sheets, &Import)>, progress: &Progress) -> Result<CardRun, CardError> {
    let wall = Instant::now();
    let cpu = cpu_time::ProcessTime::now();
    // Everything checked before the first run.
    let material = fabric.to_fabric().map_err(|e| CardError::BadInput(e.to_string()))?;
    let stiffness = BendingStiffness::new(&material).map_err(|e| CardError::BadInput(e.to_string()))?;
    fabric.look(None).map_err(|e| CardError::BadInput(format!("fabric.{}: {}", e.key, e.message)))?;
    let drape = drape_config(DRAPE_SCENE, fabric)?;
    let Results { runs, pull, scene, metrics, times } = run_suite(fabric, &drape, progress)?;
    let input_b = |d: Direction| stiffness.rigidity_at(-d.warp_angle_deg().to_radians());
    let p = &fabric.properties;
    let name = if fabric.name.is_empty() { fabric.preset.clone().unwrap_or_else(|| source.to_string()) } else { fabric.name.clone() };
    let card = Card {
        fabric: FabricInfo {
            name,
            description: fabric.description.clone(),
            source: source.into(),
            areal_density_g_per_m2: 1e3 * p.areal_density,
            thickness_mm: 1e3 * p.thickness,
            poisson_warp: p.poisson_warp,
            appearance: fabric.appearance.anchored(None),
        },
        tensile: tensile_section(fabric, &runs, &pull),
        pure_bending: bending_section(&runs, input_b),
        cantilever: cantilever_section(fabric, &runs, input_b),
        shear: shear_section(fabric, &runs),
        drape: drape_numbers(&scene, &metrics)?,
        sheet_readback: readback_section(fabric, sheets, runs)?,
        cost: Cost {
            cpu_seconds: cpu.elapsed().as_secs_f64(),
            wall_seconds: wall.elapsed().as_secs_f64(),
            threads: worker_threads(),
            tests: times,
        },
    };
    Ok(CardRun { card, drape: scene })
}

/// What the suite's jobs gave, sorted by test.
struct Results {
    runs: LabRuns,
    pull: TensilePull,
    scene: Scene,
    metrics: Metrics,
    /// Each job's label and wall time, s.
    times: Vec<(String, f64)>,
}

/// Runs every test of the suite as one job on rayon's pool, the drape first (it is the
/// longest); the first error, or the cancellation, ends the card.
fn run_suite(fabric: &FabricConfig, drape: &CheckedScene, progress: &Progress) -> Result<Results, CardError> {
    let mut jobs = vec![Job::Drape];
    jobs.extend(Direction::ALL.map(Job::Cantilever));
    jobs.push(Job::Shear);
    jobs.extend([Job::Kes(Direction::Warp), Job::Kes(Direction::Weft), Job::BiasPull]);
    jobs.extend(Direction::ALL.map(Job::Bending));
    progress.set_total(jobs.len());
    let results = parallel_map(&jobs, |&job| {
        progress.run(&job.label(), || {
            let started = Instant::now();
            let outcome = run_job(job, fabric, drape, progress);
            (outcome, started.elapsed().as_secs_f64())
        })
    });
    if progress.is_cancelled() {
        return Err(CardError::Cancelled { done: results.iter().flatten().count(), total: jobs.len() });
    }
    let mut times = Vec::new();
    let (mut runs, mut pull, mut drape_run) = (LabRuns::default(), None, None);
    for (job, result) in jobs.iter().zip(results) {
        let (outcome, seconds) = result.expect("not cancelled");
        times.push((job.label(), seconds));
        match outcome? {
            Outcome::Drape(d) => drape_run = Some(*d),
            Outcome::Kes(t) => first_run(runs.tensile.insert(t.direction, t)),
            Outcome::Pull(p) => pull = Some(p),
            Outcome::Bending(b) => first_run(runs.bending.insert(b.direction, b)),
            Outcome::Cantilever(c) => runs.cantilever.push(c),
            Outcome::Shear(s) => runs.shear = Some(s),
        }
    }
    let (scene, metrics) = drape_run.expect("the drape is a job");
    Ok(Results { runs, pull: pull.expect("the bias pull is a job"), scene, metrics, times })
}

/// The KES pulls along the warp and the weft against the input curves, and the bias pull
/// against the off-axis modulus of eq. 1.
fn tensile_section(fabric: &FabricConfig, runs: &LabRuns, pull: &TensilePull) -> Vec<Tensile> {
    let p = &fabric.properties;
    let mut tensile = Vec::new();
    for (d, input) in [(Direction::Warp, &p.tensile_warp), (Direction::Weft, &p.tensile_weft)] {
        let t = &runs.tensile[&d];
        tensile.push(Tensile {
            direction: d.name().into(),
            test: "KES-FB1: 10 cm × 5 cm strip pulled at 1 mm/s to 500 gf/cm (490.3 N/m)".into(),
            measured: Curve::new("strain (%)", "stress (N/m)", thin(&percent(&t.curve), CURVE_POINTS)),
            input: Curve::new("strain (%)", "stress (N/m)", input_to_fm(input)),
            input_label: format!("the fabric's tensile_{} curve", d.name()),
            emt_percent: Some(t.emt_percent()),
            input_emt_percent: strain_at(input, KES_FM).map(|e| 100.0 * e),
            lt: Some(t.lt),
            wt_gf_cm_per_cm2: Some(t.wt_kes()),
            e45_formula_n_per_m: None,
        });
    }
    // Small-strain moduli: the first segments of the input curves.
    let initial = |c: &[[f64; 2]]| c.get(1).map_or(f64::NAN, |q| q[1] / q[0]);
    let e45 = crate::reference::off_axis_modulus(initial(&p.tensile_warp), initial(&p.tensile_weft), p.shear_modulus, p.poisson_warp, 45f64.to_radians());
    let measured = thin(&percent(&pull.curve), CURVE_POINTS);
    // The line as far as the extensometer went (the middle of the strip, free of the clamps,
    // strains more than the clamps' separation says).
    let top = measured.iter().map(|q| q[0]).fold(100.0 * pull.max_strain, f64::max);
    tensile.push(Tensile {
        direction: "bias".into(),
        test: format!("10 cm × 5 cm strip cut at 45°, clamps pulled apart at 1 mm/s by {:.1} %", 100.0 * pull.max_strain),
        measured: Curve::new("strain (%)", "stress (N/m)", measured),
        input: Curve::new("strain (%)", "stress (N/m)", vec![[0.0, 0.0], [top, e45 * top / 100.0]]),
        input_label: format!("off-axis formula E45 = {e45:.1} N/m from the curves' first segments, G and ν (small strain)"),
        e45_formula_n_per_m: Some(e45),
        ..Tensile::default()
    });
    tensile
}

/// Pure bending in each direction against eq. 3's B_θ of the input (`input_b`, N·m).
fn bending_section(runs: &LabRuns, input_b: impl Fn(Direction) -> f64) -> Vec<Bending> {
    Direction::ALL
        .iter()
        .map(|&d| {
            let b = &runs.bending[&d];
            Bending {
                direction: d.name().into(),
                rigidity_un_m: 1e6 * b.rigidity,
                rigidity_gf_cm2_per_cm: b.kes(),
                input_rigidity_un_m: 1e6 * input_b(d),
                readings: Curve::new(
                    "curvature (1/cm)",
                    "moment (gf·cm/cm)",
                    b.readings.iter().map(|&(k, m)| [k / 100.0, m / GF_CM_PER_CM]).collect(),
                ),
            }
        })
        .collect()
}

/// The cantilever's bending lengths against the standard's c = (B/w)^⅓ of the input.
fn cantilever_section(fabric: &FabricConfig, runs: &LabRuns, input_b: impl Fn(Direction) -> f64) -> Vec<Cantilever> {
    let w = weight_per_area(fabric.properties.areal_density);
    runs.cantilever
        .iter()
        .map(|c| Cantilever {
            direction: c.direction.name().into(),
            strip_width_mm: 1e3 * c.strip_width,
            bending_length_mm: 1e3 * c.bending_length,
            overhang_mm: 1e3 * c.overhang,
            formula_bending_length_mm: 1e3 * bending_length(input_b(c.direction), w),
            runs: c.runs,
        })
        .collect()
}

/// The KES shear against the input's shear modulus.
fn shear_section(fabric: &FabricConfig, runs: &LabRuns) -> Shear {
    let s = runs.shear.as_ref().expect("the shear is a job");
    Shear {
        modulus_n_per_m: s.modulus,
        g_gf_per_cm_deg: s.kes(),
        input_modulus_n_per_m: fabric.properties.shear_modulus,
        curve: Curve::new("shear angle (°)", "force per grip length (N/m)", thin(&s.curve, CURVE_POINTS)),
    }
}

/// The sheets' values read back from the virtual tests (none without sheets).
fn readback_section(fabric: &FabricConfig, sheets: Option<(&Sheets, &Import)>, runs: LabRuns) -> Result<Vec<SheetValue>, CardError> {
    let Some((sheets, import)) = sheets.filter(|(sheets, _)| !sheets.is_empty()) else { return Ok(Vec::new()) };
    Ok(lab::readback_with(sheets, import, fabric, runs)?
        .properties
        .iter()
        .map(|q| SheetValue {
            field: q.field.clone(),
            unit: q.unit.into(),
            sheet: q.sheet,
            measured: q.measured,
            error_percent: 100.0 * q.error(),
            tolerance_percent: 100.0 * q.tolerance,
            test: q.test.into(),
            passes: q.passes(),
            held: q.held(),
        })
        .collect())
}

/// Threads the tests run on: one per core.
pub fn worker_threads() -> usize {
    std::thread::available_parallelism().map_or(2, |n| n.get())
}

/// `f` over `items` on [`worker_threads`] threads, each taking the next item as it
/// finishes one (the first items start first); the results in the items' order.
///
/// Plain threads rather than rayon's pool: the solver's own parallel loops run on rayon,
/// and a test waiting on one of them there would take up other tests' work, so that no
/// test's time could be told apart.
pub fn parallel_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let slots: Vec<std::sync::Mutex<Option<R>>> = items.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|s| {
        for _ in 0..worker_threads().min(items.len()) {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(item) = items.get(i) else { break };
                    let result = f(item);
                    *slots[i].lock().expect("one writer per slot") = Some(result);
                }
            });
        }
    });
    slots.into_iter().map(|slot| slot.into_inner().expect("one writer per slot").expect("every item was run")).collect()
}

/// At most `n` points of `points`, evenly spaced by index, the last one kept.
fn thin(points: &[[f64; 2]], n: usize) -> Vec<[f64; 2]> {
    if points.len() <= n {
        return points.to_vec();
    }
    let step = points.len().div_ceil(n);
    let mut out: Vec<[f64; 2]> = points.iter().step_by(step).copied().collect();
    if out.last() != points.last() {
        out.extend(points.last());
    }
    out
}

/// A map insert that found no earlier value (each direction is run once).
fn first_run<T>(previous: Option<T>) {
    debug_assert!(previous.is_none(), "each test runs once");
}

/// The drape's numbers from its run.
fn drape_numbers(scene: &Scene, metrics: &Metrics) -> Result<Drape, CardError> {
    if metrics.measures.drape().is_none() {
        return Err(CardError::Drape("the scene reported no drape measures".into()));
    }
    let outline = scene.rig.outline(&scene.model, &scene.state).unwrap_or_default();
    let step = (outline.len() / OUTLINE_POINTS).max(1);
    let c = &scene.config;
    Ok(Drape {
        scene: DRAPE_SCENE.into(),
        specimen_diameter_mm: 1e3 * c.cloth.diameter,
        support_diameter_mm: 1e3 * c.test.support_diameter.unwrap_or(0.0),
        result: DrapeResult::from_metrics(metrics),
        vertices: metrics.vertices,
        triangles: metrics.triangles,
        edge_length_mm: 1e3 * c.mesh.edge_length,
        outline: Curve::new(
            "angle (°)",
            "radius (mm)",
            outline.iter().step_by(step).map(|&(a, r)| [a.to_degrees(), 1e3 * r]).collect(),
        ),
    })
}
