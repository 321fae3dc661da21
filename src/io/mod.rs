//! The command line's files: what a command reads and what it writes.
//!
//! - [`read`]: the one reader of the files a user names (scenes, fabrics and sheets, OBJ
//!   props, the chart's cached reference). Only regular files, each kind with its own size
//!   limit, checked before anything is opened, so that `/dev/zero`, a FIFO or a folder is
//!   refused instead of hanging or filling memory. Every file read is remembered, so that
//!   the output guard can tell an output that would overwrite one.
//! - [`guard`]: the outputs a command will write, checked together before any work: none
//!   may be an input of the command or another of its outputs, and an existing file that
//!   is not Rosette's own output of the same kind is replaced only with `--force`.
//! - [`write`]: every file written whole or not at all (written beside, then renamed), and
//!   PNGs marked as Rosette's own so that the guard recognises them.
//! - [`stdout`]: printing that neither panics nor lies: a closed pipe ends the printing
//!   quietly, a full disk is reported once with the exit code for a lost output.
//! - [`number`]: numbers in messages, to a few significant figures.
//! - [`interrupt`]: Ctrl-C and SIGTERM as a request to stop a run at the end of a step.
//! - [`progress`]: how far a long job (a card, a chart's sweep) has got, shared with whoever
//!   shows it, and its cancel switch.
//!
//! docs/robustness.md is the user's account of all of it.

pub mod guard;
pub mod interrupt;
pub mod number;
pub mod progress;
pub mod read;
pub mod stdout;
pub mod write;
