//! From the parsed command line to the subcommand that carries it out.

use super::args::{Cli, Command, FabricAction, PatternAction, ScreenshotArgs};
use super::run::{RunLimits, RunOutputs};
use super::{fabric, sweeps};
use rosette::app::viewer::ViewerOptions;
use rosette::errln;
use rosette::outln;
use rosette::settings::{self as preset, SolverPath};
use std::process::ExitCode;

/// Carries out the parsed command line.
pub fn dispatch(cli: Cli) -> ExitCode {
    match cli.command {
        None if !rosette::app::viewer::display_available() => {
            // The main job where no window can open: the default drape, headless, with a
            // picture of it.
            errln!("no display (DISPLAY and WAYLAND_DISPLAY unset): running cusick-drape headless instead of the viewer");
            let shot = ScreenshotArgs {
                screenshot: Some("cusick-drape.png".into()),
                size: [1280, 800],
                camera: None,
                colormap: None,
                wireframe: false,
            };
            let code = super::run::run("cusick-drape", &[], &RunLimits::default(), &RunOutputs::default(), &shot);
            if code == ExitCode::SUCCESS {
                errln!("wrote cusick-drape.png; `rosette run PRESET --screenshot FILE.png` for other scenes");
            }
            code
        }
        None => super::view::view(ViewerOptions { quit_after_frames: cli.quit_after_frames, ..ViewerOptions::default() }, None, false),
        Some(Command::View { preset, quit_after_frames, mut overrides, fast, exact, script, report, force }) => {
            if fast {
                overrides.push(SolverPath::Fast.setting());
            }
            if exact {
                overrides.push(SolverPath::Exact.setting());
            }
            let options = ViewerOptions { preset, quit_after_frames, overrides, report, ..ViewerOptions::default() };
            super::view::view(options, script.as_deref(), force)
        }
        Some(Command::Presets) => {
            for (name, description) in preset::scene_descriptions() {
                outln!("{name:<16} {description}");
            }
            ExitCode::SUCCESS
        }
        Some(Command::Bench { out, quick, threads, only, force }) => sweeps::bench(&out, quick, &threads, only.as_deref(), force),
        Some(Command::Chart { out, quick, force }) => sweeps::chart(out, quick, force),
        Some(Command::Card { fabric, out, force }) => super::card::card(&fabric, &out, force),
        Some(Command::Compare { fabrics, scene, overrides, out, force }) => super::card::compare(&fabrics, &scene, &overrides, &out, force),
        Some(Command::Fabric { action }) => match action {
            FabricAction::Template { standard } => fabric::template(standard.as_deref()),
            FabricAction::List => fabric::list(),
            FabricAction::Import { sheet, out, force } => fabric::import(&sheet, out.as_deref(), force),
            FabricAction::Check { fabric } => fabric::check(&fabric),
            FabricAction::Export { fabric, arcsim: _, out, force } => super::arcsim::export(&fabric, out.as_deref(), force),
        },
        Some(Command::Pattern { action }) => match action {
            PatternAction::Import { spec, out, pattern, fabric, seams, force } => super::pattern::import(&spec, out.as_deref(), &pattern, &fabric, seams.as_deref(), force),
            PatternAction::Seams { pattern, out, options, force } => super::pattern::seams(&pattern, out.as_deref(), &options, force),
            PatternAction::Export { scene, out, overrides, units, aama, force } => super::pattern::export(&scene, &out, &overrides, &units, aama, force),
        },
        Some(Command::Run { preset, mut overrides, duration, metrics, outline, step_log, max_steps, max_wall, fast, plan, export, export_frames, force, screenshot }) => {
            if fast {
                overrides.push(SolverPath::Fast.setting());
            }
            if plan {
                return super::run::print_plan(&preset, &overrides, duration);
            }
            let outputs = RunOutputs {
                metrics: metrics.as_deref(),
                outline: outline.as_deref(),
                step_log: step_log.as_deref(),
                export: export.as_deref(),
                export_frames,
                force,
            };
            super::run::run(&preset, &overrides, &RunLimits { duration, max_steps, max_wall }, &outputs, &screenshot)
        }
    }
}

