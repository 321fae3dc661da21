//! The command line's schema (clap): subcommands, their flags and their help.

use clap::{Parser, Subcommand};
use rosette::render;

#[derive(Parser)]
#[command(
    name = "rosette",
    version,
    about = "Woven-fabric simulator and virtual fabric laboratory",
    after_help = "Exit codes: 0 done; 2 bad input, refused before the run; 3 the simulation diverged; \
                  4 an output could not be rendered or written after the run (standard output included); 5 the run ended but \
                  some Newton solves did not converge (metrics: converged = false); 6 the run \
                  stopped at --max-steps or --max-wall; 8 a garment's seams were not closed by its \
                  sewing time; 9 a sewn garment did not end on its form (its drape measures withheld); \
                  130 or 143 stopped by Ctrl-C or SIGTERM. Metrics, outline and picture are kept for 3 to 9, 130 and 143."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// With no subcommand the viewer opens; exit after drawing N frames (smoke tests).
    #[arg(long, value_name = "N")]
    pub quit_after_frames: Option<u64>,
}

#[derive(Subcommand)]
pub enum Command {
    /// Run a scene headless and report its measurements.
    Run {
        /// A bundled scene name (see `rosette presets`) or the path of a scene file.
        preset: String,
        /// Override a preset value, e.g. --set fabric.areal_density=0.2, or a list's entry by index, e.g. --set garment.panels[1].grain_deg=45 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Simulated seconds (default: the scene's scene.duration).
        // A negative value is taken as a value (and refused naming the flag), not as a flag.
        #[arg(long, allow_hyphen_values = true)]
        duration: Option<f64>,
        /// Write the metrics JSON to FILE, or to standard output with '-'.
        #[arg(long, value_name = "FILE|-")]
        metrics: Option<String>,
        /// Drape scenes: write the final shadow outline as CSV (angle_deg, radius_m).
        #[arg(long, value_name = "FILE.csv")]
        outline: Option<String>,
        /// Write one CSV row per step: its Newton, CG and factorisation counts, Newton's
        /// shift, the cloth's RMS speed, the CPU time so far and the step's time by phase.
        #[arg(long, value_name = "FILE.csv")]
        step_log: Option<std::path::PathBuf>,
        /// Most steps the run may take (default: the scene's scene.max_steps, 1 000 000): a
        /// scene that needs more is refused before it starts.
        #[arg(long, value_name = "N")]
        max_steps: Option<u64>,
        /// Wall-clock seconds after which the run stops, keeping what it has (exit 6); a step
        /// in progress stops at its next Newton iteration, counted unconverged.
        #[arg(long, value_name = "SECONDS", default_value_t = DEFAULT_MAX_WALL, allow_hyphen_values = true)]
        max_wall: f64,
        /// Take the fast path (solver.path = "fast"): settling scenes settle coarse to fine,
        /// with longer steps and Newton solved to the step's own accuracy (docs/solvers.md).
        #[arg(long)]
        fast: bool,
        /// Print the run plan and exit without running: the step design resolved from the
        /// scene's settings, its levels, and per level the mesh, integrator, step, Newton,
        /// linear solver and contact settings.
        #[arg(long)]
        plan: bool,
        /// Write the cloth as glTF 2.0 binary (Blender, three.js): the final state, or with
        /// --export-frames an animation of the run.
        #[arg(long, value_name = "FILE.glb")]
        export: Option<std::path::PathBuf>,
        /// With --export: N frames spread evenly over the run (2 to 1000), played back at
        /// the simulated times.
        #[arg(long, value_name = "N", requires = "export")]
        export_frames: Option<usize>,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
        #[command(flatten)]
        screenshot: ScreenshotArgs,
    },
    /// Sweep integrators, time steps and meshes: error against CPU time and stability
    /// maps, as CSV and PNG (accuracy.csv/png, stability.csv/png).
    Chart {
        /// Directory for the CSV and PNG files (created if missing).
        #[arg(long, value_name = "DIR", default_value = "chart")]
        out: std::path::PathBuf,
        /// The small sweep the tests run: fewer and smaller runs, no drape.
        #[arg(long)]
        quick: bool,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// The fabric card: the virtual laboratory's tests and the 30 cm Cusick drape on one
    /// fabric, written as DIR/NAME.png (one page) and DIR/NAME.json.
    Card {
        /// A bundled fabric's name (see `rosette fabric list`) or a fabric file.
        fabric: String,
        /// Directory for the page and the JSON (created if missing).
        #[arg(long, value_name = "DIR", default_value = ".")]
        out: std::path::PathBuf,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// Drape several fabrics on one scene in parallel and set them side by side: a contact
    /// sheet PNG (same camera for all, DC and nodes under each) with its numbers as JSON and
    /// CSV beside it.
    Compare {
        /// Bundled fabric names or fabric files.
        #[arg(required = true, num_args = 1..)]
        fabrics: Vec<String>,
        /// The drape scene to run them on.
        #[arg(long, default_value = "cusick-drape-30")]
        scene: String,
        /// Override a scene value for every fabric, e.g. --set scene.duration=3 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// The contact sheet; FILE.json and FILE.csv are written beside it.
        #[arg(long, value_name = "FILE.png", default_value = "compare.png")]
        out: std::path::PathBuf,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// List the bundled scenes.
    Presets,
    /// Fabrics from measurement sheets (KES-F, FAST, ASTM D1388 / BS 3356 cantilever).
    Fabric {
        #[command(subcommand)]
        action: FabricAction,
    },
    /// Sewing patterns from other tools (GarmentCode's JSON specification) as garment scenes.
    Pattern {
        #[command(subcommand)]
        action: PatternAction,
    },
    /// Time the paper's Table 1 scenes and the Cusick drape at about 800, 5 000, 20 000
    /// and 80 000 triangles, on 1 and 2 threads; writes bench.csv and bench.json.
    Bench {
        /// Directory for bench.csv and bench.json.
        #[arg(long, default_value = "bench")]
        out: std::path::PathBuf,
        /// Short windows and the two smaller drapes only (about a minute).
        #[arg(long)]
        quick: bool,
        /// Thread counts to run each case with (1 to 1024).
        #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = super::parse_threads)]
        threads: Vec<usize>,
        /// Only the cases whose name contains TEXT (e.g. "skirt", "fast", "sphere-drop").
        #[arg(long, value_name = "TEXT")]
        only: Option<String>,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// Open the interactive viewer (the default when no subcommand is given).
    View {
        /// A bundled scene name or scene file (default: the Cusick drape, or Euler buckling).
        preset: Option<String>,
        /// Exit after drawing N frames (smoke tests).
        #[arg(long, value_name = "N")]
        quit_after_frames: Option<u64>,
        /// Override a scene value, e.g. --set mesh.edge_length=0.0075 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// Take the fast path (solver.path = "fast"): settling scenes settle coarse to fine,
        /// with longer steps and Newton solved to the step's own accuracy (docs/solvers.md).
        /// Garments open on it unless the path is set.
        #[arg(long, conflicts_with = "exact")]
        fast: bool,
        /// Take the exact path (solver.path = "exact"), the validated reference, also for
        /// a garment.
        #[arg(long)]
        exact: bool,
        /// Play a scripted session: a timeline of what a person does in the window (wait,
        /// switch fabric or path, recut, pin, drag, orbit, screenshot, quit; docs/viewer.md).
        #[arg(long, value_name = "FILE.toml")]
        script: Option<std::path::PathBuf>,
        /// Write the session's report (what each step saw) as JSON when it ends.
        #[arg(long, value_name = "FILE.json", requires = "script")]
        report: Option<std::path::PathBuf>,
        /// Replace existing files the session writes that are not Rosette's own output of the
        /// same kind (an input is never overwritten).
        #[arg(long)]
        force: bool,
    },
}

#[derive(Subcommand)]
pub enum FabricAction {
    /// Convert a sheet (a TOML file with [kes], [fast] and/or [cantilever] sections, an
    /// ARCSim material .json, or a bundled fabric's name) into a fabric file with every
    /// value's source.
    Import {
        /// The sheet file, an ARCSim material (.json), or a bundled fabric (see `rosette fabric list`).
        sheet: String,
        /// Write the fabric file here (default: standard output).
        #[arg(long, value_name = "FILE.toml")]
        out: Option<std::path::PathBuf>,
        /// Replace existing files that are not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// Print a sheet to fill in, every field with its unit and meaning.
    Template {
        /// Only this standard's section: kes, fast or cantilever.
        #[arg(long, value_name = "STANDARD")]
        standard: Option<String>,
    },
    /// Run the virtual laboratory tests on a fabric and set their readings beside its
    /// sheet (KES tensile, pure bending, shear, cantilever); exit 7 if any is outside its
    /// tolerance.
    Check {
        /// A bundled fabric's name or a fabric file with sheets.
        fabric: String,
    },
    /// List the bundled fabrics, the sheets they come from, and who measured them.
    List,
    /// Write a fabric (bundled name, fabric file or ARCSim material) as an ARCSim material
    /// file: density, stretching and bending samples (docs/fabric-sheets.md).
    Export {
        /// A bundled fabric's name, a fabric file or an ARCSim material (.json).
        fabric: String,
        /// Write ARCSim's material format (JSON), the one export format.
        #[arg(long, required = true)]
        arcsim: bool,
        /// Write the material here (default: standard output).
        #[arg(long, value_name = "FILE.json")]
        out: Option<std::path::PathBuf>,
        /// Replace an existing file that is not a material Rosette wrote (an input of the
        /// command is never overwritten).
        #[arg(long)]
        force: bool,
    },
}

/// Rendering the final state offscreen (`rosette run ... --screenshot`).
#[derive(clap::Args)]
pub struct ScreenshotArgs {
    /// Render the final state to this PNG file (offscreen, no display needed).
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<std::path::PathBuf>,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "1280x800", value_parser = render::Screenshot::parse_size)]
    pub size: [u32; 2],
    /// View direction, yaw and pitch in degrees, and optionally the distance in metres
    /// (default -60,30, framing the scene).
    #[arg(long, value_name = "YAW,PITCH[,DISTANCE]", value_parser = super::parse_camera, allow_hyphen_values = true)]
    pub camera: Option<(f64, f64, Option<f64>)>,
    /// Colour the cloth by a field: warp, weft, shear or bending.
    #[arg(long, value_name = "MAP")]
    pub colormap: Option<render::ColorMap>,
    /// Draw the mesh edges over the cloth.
    #[arg(long)]
    pub wireframe: bool,
}

/// A day: longer than any bundled scene takes, short enough that a runaway run ends.
pub const DEFAULT_MAX_WALL: f64 = 86_400.0;

#[derive(Subcommand)]
pub enum PatternAction {
    /// Convert a pattern into a garment scene file to run, view and edit
    /// (docs/garments.md): GarmentCode's specification (JSON: panels, their 3D placement,
    /// stitches) or pattern CAD's DXF (AAMA / ASTM D6673: pieces with cut and sew lines,
    /// grain lines, notches), sewn by its seams file.
    Import {
        /// The pattern: GarmentCode's `*_specification.json` or a `.dxf` from pattern CAD.
        spec: std::path::PathBuf,
        /// Write the scene file here (default: standard output).
        #[arg(long, value_name = "FILE.toml")]
        out: Option<std::path::PathBuf>,
        #[command(flatten)]
        pattern: PatternArgs,
        /// The fabric (a bundled name, see `rosette fabric list`).
        #[arg(long, default_value = rosette::garment::import::DEFAULT_FABRIC)]
        fabric: String,
        /// DXF: the seams file (default: NAME.seams.toml beside NAME.dxf, where there is one).
        #[arg(long, value_name = "FILE.toml")]
        seams: Option<std::path::PathBuf>,
        /// Replace an existing file that is not Rosette's own output of the same kind (an
        /// input of the command is never overwritten).
        #[arg(long)]
        force: bool,
    },
    /// Suggest seams for a DXF pattern: edges of the pieces that match in length and
    /// notches, paired by where the pieces go around the form, written as a seams file for
    /// the designer to check and keep (nothing is sewn that the file does not say).
    Seams {
        /// The pattern (`.dxf`).
        pattern: std::path::PathBuf,
        /// Write the suggested seams file here (default: standard output).
        #[arg(long, value_name = "FILE.toml")]
        out: Option<std::path::PathBuf>,
        #[command(flatten)]
        options: PatternArgs,
        /// Replace an existing file that is not Rosette's own output of the same kind.
        #[arg(long)]
        force: bool,
    },
    /// Write a garment's panels as a DXF pattern in the AAMA / ASTM D6673 convention (R12):
    /// outline (cut and sew lines), grain line, notches, names and units, for pattern CAD.
    Export {
        /// A garment scene: a bundled name, a scene file or a pattern (`.json`, `.dxf`).
        scene: String,
        /// The DXF file to write.
        #[arg(long, value_name = "FILE.dxf")]
        out: std::path::PathBuf,
        /// Override a scene value, e.g. --set garment.panels[0].grain_deg=45 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// The file's unit: mm (`Units: METRIC`) or in (`Units: ENGLISH`).
        #[arg(long, default_value = "mm")]
        units: String,
        /// Notches as AAMA's short lines instead of ASTM's points.
        #[arg(long)]
        aama: bool,
        /// Replace an existing file that is not Rosette's own output of the same kind.
        #[arg(long)]
        force: bool,
    },
}

/// How a pattern is read and placed (`pattern import`, `pattern seams`).
#[derive(clap::Args, Clone)]
pub struct PatternArgs {
    /// The form's bundled size (uk-10, uk-12, uk-14).
    #[arg(long, default_value = "uk-14")]
    pub form: String,
    /// GarmentCode: the warp's angle in each panel as drafted, degrees from its x axis (90,
    /// the default, runs it up and down the panel; 45 or 135 cuts every panel on the bias).
    /// DXF: the angle for pieces that have no grain line (refused without it).
    #[arg(long, allow_hyphen_values = true)]
    pub grain_deg: Option<f64>,
    /// DXF: the file's unit (mm, cm or in), whatever it says.
    #[arg(long)]
    pub units: Option<String>,
    /// DXF: a piece that goes to the form's front, whatever its name (repeatable).
    #[arg(long, value_name = "PIECE")]
    pub front: Vec<String>,
    /// DXF: a piece that goes to the form's back (repeatable).
    #[arg(long, value_name = "PIECE")]
    pub back: Vec<String>,
    /// DXF: a piece that goes to the arms' side (repeatable).
    #[arg(long, value_name = "PIECE")]
    pub sleeve: Vec<String>,
    /// DXF: where the pieces' tops go: waist (skirts, trousers) or shoulder (tops,
    /// dresses); default from the pieces' names.
    #[arg(long)]
    pub top: Option<String>,
}
