//! Printing without panics: `println!` panics when standard output is a closed pipe
//! (`rosette presets | head -1`) or a full disk (`> /dev/full`), and `eprintln!` likewise
//! for standard error. Here a closed pipe stops the printing quietly, as other
//! command-line tools do, and any other failure is kept for the command to report once
//! with exit code 4 ([`failure`]); messages on standard error are best effort (where it is
//! gone there is nobody left to tell).

use std::io::Write;
use std::sync::Mutex;

#[derive(Default)]
struct State {
    /// The reader went away (a broken pipe): nothing more is printed.
    closed: bool,
    /// Why a write failed otherwise, once.
    failed: Option<String>,
}

static STATE: Mutex<State> = Mutex::new(State { closed: false, failed: None });

/// Writes `text` to standard output and flushes it; see the module's doc for failures.
pub fn write(text: &str) {
    let mut state = STATE.lock().unwrap_or_else(|p| p.into_inner());
    if state.closed || state.failed.is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => state.closed = true,
        Err(e) => state.failed = Some(e.to_string()),
    }
}

/// Writes `text` to standard error, ignoring failure.
pub fn diagnostic(text: &str) {
    let mut err = std::io::stderr().lock();
    let _ = err.write_all(text.as_bytes()).and_then(|()| err.flush());
}

/// Why standard output could not be written, if it could not (a closed pipe is not a
/// failure).
pub fn failure() -> Option<String> {
    STATE.lock().unwrap_or_else(|p| p.into_inner()).failed.clone()
}

/// Whether the reader of standard output has gone (nothing more is printed).
pub fn closed() -> bool {
    STATE.lock().unwrap_or_else(|p| p.into_inner()).closed
}

/// `println!` without the panic: see [`write`].
#[macro_export]
macro_rules! outln {
    () => { $crate::io::stdout::write("\n") };
    ($($arg:tt)*) => { $crate::io::stdout::write(&format!("{}\n", format_args!($($arg)*))) };
}

/// `print!` without the panic: see [`write`].
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => { $crate::io::stdout::write(&format!($($arg)*)) };
}

/// `eprintln!` without the panic: see [`diagnostic`].
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => { $crate::io::stdout::diagnostic(&format!("{}\n", format_args!($($arg)*))) };
}
