//! A second thread kept at hand for the passes over a few thousand rows that rayon's pool
//! cannot split profitably.
//!
//! Rayon hands work to a sleeping thread through the kernel, which costs about as much as a
//! product over the tablecloth's 1 681 rows: with its products on rayon's pool the
//! tablecloth ran 9 % slower (docs/performance-log.md, "2026-12-07: more levers on the
//! tablecloth's landing"). This thread spins between the passes of a solve, so that handing
//! it half a pass costs a cache line's trip, and sleeps once it has had nothing to do for
//! [`SPIN`]. Written by hand: no crate the project uses offers a join that spins.
//!
//! [`join`] runs one closure on the calling thread and one here. It falls back to running
//! both on the calling thread where the team is taken (another solve, or a nested call),
//! where the thread could not be started, or where rayon's pool has one thread (`rosette
//! bench --threads 1`, `RAYON_NUM_THREADS=1`), so that a run's thread count means what it
//! says. Callers split work so that the result does not depend on which thread did what.

use std::any::Any;
use std::cell::UnsafeCell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::thread::{self, Thread};
use std::time::{Duration, Instant};

/// The fewest rows, triangles or items a pass is split over the team for: below it a pass
/// takes a few microseconds, about what the hand-off costs. Above rayon's thresholds (4 096)
/// the passes go to rayon's pool instead.
pub const LEAST_ITEMS: usize = 1024;

/// How long the thread spins for the next job before it sleeps: longer than the gaps
/// between the passes of a conjugate-gradient solve, shorter than a Newton iteration's
/// force assembly. 1 ms ran the tablecloth headless 8 % faster (`farm-bench -n 5`, A/B
/// 0.92, 0.88–1.11) and in the window 15 % slower, its spin taking the core the software
/// renderer draws on (docs/performance-log.md, "2026-12-08: the second core").
const SPIN: Duration = Duration::from_micros(100);

/// The job handed over: a closure on the caller's stack, its lifetime erased. [`join`] does
/// not return before the thread has finished with it.
type Job = *mut (dyn FnMut() + Send);

struct Team {
    /// Written by the caller holding `in_use` before it raises `posted`; read by the
    /// thread after it sees `posted` raised.
    job: UnsafeCell<Option<Job>>,
    posted: AtomicU64,
    done: AtomicU64,
    sleeping: AtomicBool,
    in_use: AtomicBool,
    panic: Mutex<Option<Box<dyn Any + Send>>>,
    thread: Thread,
}

// SAFETY: `job` is written only by the one caller holding `in_use`, while the thread is
// idle (`done == posted`), and read only by the thread between seeing `posted` raised and
// raising `done`; the atomics order both. The job itself is `Send`.
unsafe impl Sync for Team {}
unsafe impl Send for Team {}

static TEAM: OnceLock<Option<Team>> = OnceLock::new();

fn team() -> Option<&'static Team> {
    TEAM.get_or_init(|| {
        let spawned = thread::Builder::new().name("rosette-team".into()).spawn(|| {
            if let Some(team) = TEAM.wait() {
                serve(team);
            }
        });
        spawned.ok().map(|handle| Team {
            job: UnsafeCell::new(None),
            posted: AtomicU64::new(0),
            done: AtomicU64::new(0),
            sleeping: AtomicBool::new(false),
            in_use: AtomicBool::new(false),
            panic: Mutex::new(None),
            thread: handle.thread().clone(),
        })
    })
    .as_ref()
}

/// The thread's loop: wait for a job (spinning, then asleep), run it, say so.
fn serve(team: &Team) -> ! {
    let mut seen = 0;
    loop {
        let idle_since = Instant::now();
        let mut spins = 0u32;
        loop {
            if team.posted.load(Ordering::Acquire) != seen {
                break;
            }
            spins = spins.wrapping_add(1);
            if !spins.is_multiple_of(64) || idle_since.elapsed() < SPIN {
                std::hint::spin_loop();
                continue;
            }
            // Announced before the last look, so that a caller posting after that look
            // sees it and wakes the thread (both sequentially consistent).
            team.sleeping.store(true, Ordering::SeqCst);
            if team.posted.load(Ordering::SeqCst) == seen {
                thread::park();
            }
            team.sleeping.store(false, Ordering::SeqCst);
        }
        seen += 1;
        // SAFETY: see `Team`'s `Sync`: the caller wrote the job before raising `posted`
        // and keeps it alive until `done` is raised.
        let job = unsafe { *team.job.get() }.expect("a job is posted with its closure");
        if let Err(payload) = panic::catch_unwind(AssertUnwindSafe(|| unsafe { (*job)() })) {
            *team.panic.lock().unwrap_or_else(|e| e.into_inner()) = Some(payload);
        }
        team.done.store(seen, Ordering::Release);
    }
}

/// The team, taken for one [`join`], where it may be used now.
fn take() -> Option<&'static Team> {
    if rayon::current_num_threads() < 2 {
        return None;
    }
    let team = team()?;
    if thread::current().id() == team.thread.id() {
        return None;
    }
    team.in_use.compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed).ok()?;
    Some(team)
}

/// Runs `a` on this thread and `b` on the team's, and returns both results once both are
/// done; both on this thread where the team cannot be had (see the module's comment). A
/// panic in either is raised here, after both have finished.
pub fn join<RA, RB: Send>(a: impl FnOnce() -> RA, b: impl FnOnce() -> RB + Send) -> (RA, RB) {
    let Some(team) = take() else {
        return (a(), b());
    };
    let mut b = Some(b);
    let mut result_b = None;
    let mut call = || result_b = b.take().map(|b| b());
    let job: &mut (dyn FnMut() + Send) = &mut call;
    // SAFETY: the lifetime is erased only while this function waits below for the thread
    // to finish with the closure, whatever `a` does (its panic is caught first).
    let job: Job = unsafe { std::mem::transmute::<&mut (dyn FnMut() + Send), Job>(job) };
    unsafe { *team.job.get() = Some(job) };
    let posted = team.posted.fetch_add(1, Ordering::SeqCst) + 1;
    if team.sleeping.load(Ordering::SeqCst) {
        team.thread.unpark();
    }
    let result_a = panic::catch_unwind(AssertUnwindSafe(a));
    let mut spins = 0u32;
    while team.done.load(Ordering::Acquire) != posted {
        // Spin while the other half is likely still running; give the core away if the
        // thread is not being scheduled (a busy machine).
        spins = spins.saturating_add(1);
        if spins < 4096 {
            std::hint::spin_loop();
        } else {
            thread::yield_now();
        }
    }
    let panic_b = team.panic.lock().unwrap_or_else(|e| e.into_inner()).take();
    team.in_use.store(false, Ordering::Release);
    match (result_a, panic_b) {
        (Err(payload), _) | (Ok(_), Some(payload)) => panic::resume_unwind(payload),
        (Ok(a), None) => (a, result_b.expect("the team's thread ran its half")),
    }
}

/// [`join`] of two halves of a list: `a`'s results followed by `b`'s.
pub fn join_in_order<T: Send>(a: impl FnOnce() -> Vec<T>, b: impl FnOnce() -> Vec<T> + Send) -> Vec<T> {
    let (mut low, high) = join(a, b);
    low.extend(high);
    low
}

#[cfg(test)]
mod tests {
    use super::join;

    #[test]
    fn both_halves_run_and_return_their_results() {
        let data: Vec<u64> = (0..10_000).collect();
        let (lo, hi) = data.split_at(5_000);
        for _ in 0..1_000 {
            let (a, b) = join(|| lo.iter().sum::<u64>(), || hi.iter().sum::<u64>());
            assert_eq!(a + b, 10_000 * 9_999 / 2);
        }
    }

    #[test]
    fn a_panic_on_the_teams_thread_is_raised_to_the_caller_and_the_team_recovers() {
        let caught = std::panic::catch_unwind(|| join(|| 1, || panic!("on the team's thread")));
        assert!(caught.is_err());
        assert_eq!(join(|| 2, || 3), (2, 3));
    }

    #[test]
    fn nested_joins_run_on_the_calling_thread() {
        let (a, (b, c)) = join(|| 1, || join(|| 2, || 3));
        assert_eq!((a, b, c), (1, 2, 3));
    }
}
