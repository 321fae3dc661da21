//! How far a long job (a card's tests, a chart's sweep) has got, shared between the threads
//! that do the work and whoever shows it (the command line's bar, the viewer's window), with
//! the switch that asks the job to stop early.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// A job's counts, the items in progress and its cancel switch. Every method takes `&self`,
/// so one `Progress` is shared by reference or in an `Arc`.
#[derive(Debug, Default)]
pub struct Progress {
    /// Items in the job, 0 until it is planned ([`Self::set_total`]).
    total: AtomicUsize,
    done: AtomicUsize,
    cancel: AtomicBool,
    /// Labels of the items in progress, in the order they started.
    running: Mutex<Vec<String>>,
    /// The fraction done of one long item in progress, by its label.
    part: Mutex<Option<(String, f64)>>,
    /// What the job does after its items (pictures, a page), once it has got there.
    stage: Mutex<Option<String>>,
}

impl Progress {
    /// Items in the job (0 until it has been planned).
    pub fn total(&self) -> usize {
        self.total.load(Ordering::Relaxed)
    }

    pub fn set_total(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
    }

    /// Items finished (or skipped after a cancel).
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    /// Items done, counting the long item's part done while it runs, over all items: 0 to 1.
    pub fn fraction(&self) -> f64 {
        let total = self.total();
        if total == 0 {
            return 0.0;
        }
        let part = self.part.lock().ok().and_then(|p| p.clone());
        let partial = part.filter(|(label, _)| self.running().contains(label)).map_or(0.0, |(_, f)| f);
        ((self.done() as f64 + partial) / total as f64).min(1.0)
    }

    /// The items in progress now.
    pub fn running(&self) -> Vec<String> {
        self.running.lock().map(|r| r.clone()).unwrap_or_default()
    }

    /// The stage after the items, if reached.
    pub fn stage(&self) -> Option<String> {
        self.stage.lock().ok().and_then(|s| s.clone())
    }

    pub fn set_stage(&self, stage: &str) {
        if let Ok(mut s) = self.stage.lock() {
            *s = Some(stage.into());
        }
    }

    /// Asks the job to stop: items not yet started are skipped and those in progress end
    /// (an item is not stopped half way).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// Records that the item `label` has started.
    pub fn start(&self, label: &str) {
        if let Ok(mut r) = self.running.lock() {
            r.push(label.into());
        }
    }

    /// Records that the item `label` has ended: one entry of that label leaves the items in
    /// progress (two items may share a label) and the count done grows.
    pub fn finish(&self, label: &str) {
        if let Ok(mut running) = self.running.lock()
            && let Some(i) = running.iter().position(|l| l == label)
        {
            running.remove(i);
        }
        self.done.fetch_add(1, Ordering::Relaxed);
    }

    /// Runs the item `label` unless the job was cancelled (then it counts as done, skipped,
    /// and gives `None`), keeping the counts and the items in progress.
    pub fn run<T>(&self, label: &str, work: impl FnOnce() -> T) -> Option<T> {
        if self.is_cancelled() {
            self.done.fetch_add(1, Ordering::Relaxed);
            return None;
        }
        self.start(label);
        let out = work();
        self.finish(label);
        Some(out)
    }

    /// The fraction (0 to 1) done of the item `label`, counted by [`Self::fraction`] while
    /// it runs: for an item long enough that whole items alone would leave the bar still.
    pub fn set_part(&self, label: &str, fraction: f64) {
        if let Ok(mut part) = self.part.lock() {
            match part.as_mut() {
                Some((l, f)) if l == label => *f = fraction,
                _ => *part = Some((label.into(), fraction)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_count_with_the_long_items_part_and_a_cancel_skips_the_rest() {
        let p = Progress::default();
        assert_eq!(p.fraction(), 0.0);
        p.set_total(4);
        assert_eq!(p.run("a", || 1), Some(1));
        p.start("drape");
        p.set_part("drape", 0.5);
        assert_eq!(p.running(), ["drape"]);
        assert_eq!(p.fraction(), 1.5 / 4.0);
        p.finish("drape");
        assert_eq!(p.fraction(), 2.0 / 4.0, "a finished item counts whole, its part no more");
        p.cancel();
        assert_eq!(p.run("b", || 2), None);
        assert_eq!((p.done(), p.total()), (3, 4));
    }

    #[test]
    fn items_sharing_a_label_leave_one_at_a_time() {
        let p = Progress::default();
        p.start("wool");
        p.start("wool");
        p.finish("wool");
        assert_eq!(p.running(), ["wool"]);
    }
}
