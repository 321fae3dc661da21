//! The subcommands' work between the parsed command line and the library: the checks
//! before any work (inputs, outputs, what the run can honour), the progress bars, the
//! outputs and the exit codes.

pub mod arcsim;
pub mod args;
pub mod card;
pub mod dispatch;
pub mod fabric;
pub mod outputs;
pub mod pattern;
pub mod run;
pub mod sweeps;
pub mod view;

use rosette::errln;
use std::io::IsTerminal;
use std::process::ExitCode;

/// Exit codes (also in `--help` and the README): 0 done, 2 bad input (refused before the
/// run), 3 the simulation diverged, 4 an output could not be rendered or written after the
/// run, 5 the run ended but some Newton solves did not converge, 6 the run stopped at its
/// step or wall-time bound, 7 a fabric's virtual tests disagree with its sheet, 8 a
/// garment's seams were not closed by its sewing time, 9 a sewn garment did not end on its
/// form; 128 + the signal where Ctrl-C or SIGTERM stopped the run.
pub const EXIT_BAD_INPUT: u8 = 2;
pub const EXIT_DIVERGED: u8 = 3;
pub const EXIT_NO_OUTPUT: u8 = 4;
pub const EXIT_NOT_CONVERGED: u8 = 5;
pub const EXIT_STOPPED: u8 = 6;
/// `rosette fabric check`: a virtual test read a sheet value outside its tolerance.
pub const EXIT_READBACK: u8 = 7;
/// A garment whose seams were still open at `garment.sewing_time`: not finished.
pub const EXIT_NOT_SEWN: u8 = 8;
/// A sewn garment that did not end hanging on its form (slid off, fell, ended inside it):
/// its drape measures are withheld.
pub const EXIT_OFF_FORM: u8 = 9;

/// Says an error on standard error, its numbers to a few figures (a value of 1e300 quoted
/// as its 301 digits helps nobody).
pub fn say_error(message: impl std::fmt::Display) {
    errln!("error: {}", rosette::io::number::shorten_in(&message.to_string()));
}

pub fn bad_input(message: impl std::fmt::Display) -> ExitCode {
    say_error(message);
    ExitCode::from(EXIT_BAD_INPUT)
}

/// An output that failed after the work was done.
pub fn lost_output(message: impl std::fmt::Display) -> ExitCode {
    say_error(message);
    ExitCode::from(EXIT_NO_OUTPUT)
}

/// Most threads `rosette bench --threads` takes: far more than any machine it runs on has
/// cores, few enough that a typo (10000) is caught.
pub const MAX_THREADS: usize = 1024;

/// `--threads N`: a run needs at least one thread.
pub fn parse_threads(text: &str) -> Result<usize, String> {
    let n: usize = text.trim().parse().map_err(|_| format!("'{text}' is not a whole number of threads"))?;
    if !(1..=MAX_THREADS).contains(&n) {
        return Err(format!("{n} threads: a run takes 1 to {MAX_THREADS}"));
    }
    Ok(n)
}

/// Nearest and farthest camera (`--camera YAW,PITCH,DISTANCE`), m: nearer, the camera's
/// near plane (a hundredth of the distance) falls below the renderer's single-precision
/// depth; farther, the scene is past the kilometre its geometry resolves
/// (`rosette::sim::contact::MAX_REACH`). `run` further checks that the cloth spans some
/// pixels at the distance given.
pub const CAMERA_DISTANCE: (f64, f64) = (1e-3, rosette::sim::contact::MAX_REACH);

/// `--camera YAW,PITCH[,DISTANCE]`, the distance within [`CAMERA_DISTANCE`].
pub fn parse_camera(text: &str) -> Result<(f64, f64, Option<f64>), String> {
    let view = rosette::render::Screenshot::parse_view(text)?;
    if let (_, _, Some(distance)) = view {
        let (near, far) = CAMERA_DISTANCE;
        if !(near..=far).contains(&distance) {
            return Err(format!(
                "--camera {text}: a distance of {} m is outside {near} to {far} m; leave it out to frame the scene",
                rosette::io::number::short(distance)
            ));
        }
    }
    Ok(view)
}

/// Shows `progress` on a bar on stderr while `work` runs, where someone watches.
pub fn with_bar<T>(label: &str, progress: &rosette::card::Progress, work: impl FnOnce() -> T) -> T {
    if !std::io::stderr().is_terminal() {
        return work();
    }
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent}% ({elapsed})").expect("valid template").progress_chars("=> "),
    );
    let done = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                bar.set_position((progress.fraction() * 1000.0) as u64);
                let running = progress.running().join(", ");
                let stage = progress.stage().unwrap_or(running);
                bar.set_message(format!("{label}: {}/{} {stage}", progress.done(), progress.total()));
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            bar.finish_and_clear();
        });
        let result = work();
        done.store(true, std::sync::atomic::Ordering::Relaxed);
        result
    })
}
