//! A long job (a card, a quick chart sweep) on a named thread of its own, off the UI and
//! solver threads, with the progress a window polls and the cancel switch it pulls.

use crate::io::progress::Progress;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Instant;

/// A job running on its own thread. Dropping it cancels the job and joins the thread.
pub struct Job<T> {
    pub progress: Arc<Progress>,
    pub started: Instant,
    thread: Option<JoinHandle<T>>,
}

impl<T: Send + 'static> Job<T> {
    /// Starts `work` on a thread named `name`, handing it the job's progress.
    pub fn start(name: &str, work: impl FnOnce(&Progress) -> T + Send + 'static) -> std::io::Result<Self> {
        let progress = Arc::new(Progress::default());
        let shared = Arc::clone(&progress);
        let thread = std::thread::Builder::new().name(name.into()).spawn(move || work(&shared))?;
        Ok(Self { progress, started: Instant::now(), thread: Some(thread) })
    }
}

impl<T> Job<T> {
    pub fn finished(&self) -> bool {
        self.thread.as_ref().is_none_or(JoinHandle::is_finished)
    }

    /// Waits for the job's end (at once when [`Self::finished`]) and returns what it gave;
    /// `None` when its thread panicked.
    pub fn join(mut self) -> Option<T> {
        self.thread.take().expect("joined once").join().ok()
    }
}

impl<T> Drop for Job<T> {
    fn drop(&mut self) {
        if let Some(thread) = self.thread.take() {
            self.progress.cancel();
            let _ = thread.join();
        }
    }
}
