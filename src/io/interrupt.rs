//! Ctrl-C (SIGINT) and SIGTERM as a request to stop: a run that catches one stops at the
//! end of its step and keeps what a `--max-wall` stop keeps (its metrics, its step log,
//! its pictures), then exits with 128 + the signal's number, as shells report a command a
//! signal ended. A second signal ends the process at once (the handler is removed after
//! the first). Hand-written on `libc::signal` rather than a crate: a flag and two calls.

use std::sync::atomic::{AtomicI32, Ordering};

/// The signal received, 0 where none was.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

#[cfg(unix)]
extern "C" fn on_signal(signal: libc::c_int) {
    RECEIVED.store(signal, Ordering::SeqCst);
    // SAFETY: restoring the default disposition is async-signal-safe.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
    }
}

/// Catches SIGINT and SIGTERM from here on.
pub fn catch() {
    #[cfg(unix)]
    // SAFETY: the handler only stores to an atomic and resets its own disposition, both
    // async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t);
    }
}

/// The signal that asked the process to stop, if one did.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(signal),
    }
}

/// The signal's name for messages.
pub fn name(signal: i32) -> &'static str {
    #[cfg(unix)]
    {
        match signal {
            libc::SIGINT => "SIGINT (Ctrl-C)",
            libc::SIGTERM => "SIGTERM",
            _ => "a signal",
        }
    }
    #[cfg(not(unix))]
    {
        let _ = signal;
        "a signal"
    }
}
