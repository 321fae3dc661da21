//! The `rosette` command: runs bundled or custom scenes headless and reports metrics, or
//! opens the viewer. The command line's schema is `cli::args`, its handlers the rest of
//! `cli`.

use clap::Parser;
use rosette::errln;
use std::process::ExitCode;

/// The subcommands' work between the parsed command line and the library: checks before
/// any work, outputs, exit codes.
mod cli;

fn main() -> ExitCode {
    let code = cli::dispatch::dispatch(cli::args::Cli::parse());
    // Standard output that failed (a full disk; a closed pipe is no failure) is an output
    // lost: exit 4, unless the command already failed for a reason the caller needs more.
    match rosette::io::stdout::failure() {
        Some(e) => {
            errln!("error: cannot write to standard output: {e}");
            if code == ExitCode::SUCCESS { ExitCode::from(cli::EXIT_NO_OUTPUT) } else { code }
        }
        None => code,
    }
}
