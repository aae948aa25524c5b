//! Progress on the terminal for long work (sweeps being validated or run, long single runs).
//!
//! A [`Progress`] counts steps of known number. It stays invisible for its first
//! [`APPEAR_AFTER`], so quick work prints nothing, and it is silent altogether when stderr is not
//! a terminal (pipes, files, tests) or after [`set_quiet`] (the `--quiet` flag). It draws on
//! stderr only, so stdout stays clean for tables and results.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Work shorter than this shows no progress at all.
pub const APPEAR_AFTER: Duration = Duration::from_secs(2);

static QUIET: AtomicBool = AtomicBool::new(false);

/// Silence every progress display of this process (`--quiet`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::SeqCst);
}

/// True when progress may be drawn: not quiet and stderr is a terminal.
pub fn enabled() -> bool {
    !QUIET.load(Ordering::SeqCst) && std::io::stderr().is_terminal()
}

/// A counter of `len` steps of `unit` (e.g. "runs"), drawn after [`APPEAR_AFTER`] if [`enabled`].
/// Shared by reference across threads; cleared from the terminal when dropped.
pub struct Progress {
    bar: ProgressBar,
    /// Set when the work ends, so a still-waiting display thread never draws.
    done: Arc<(Mutex<bool>, Condvar)>,
    waiter: Option<std::thread::JoinHandle<()>>,
}

impl Progress {
    /// A counter of `len` steps of `unit`, shown only if [`enabled`].
    pub fn new(len: usize, unit: &str) -> Self {
        Self::with_display(len, unit, enabled())
    }

    /// As [`Progress::new`], with the decision to display made by the caller.
    pub fn with_display(len: usize, unit: &str, display: bool) -> Self {
        let bar = ProgressBar::with_draw_target(Some(len as u64), ProgressDrawTarget::hidden());
        let template = format!("{{spinner}} {{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, ETA {{eta}}");
        bar.set_style(ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()));
        let done = Arc::new((Mutex::new(false), Condvar::new()));
        let waiter = display.then(|| {
            let (bar, done) = (bar.clone(), Arc::clone(&done));
            std::thread::spawn(move || {
                let (lock, cv) = &*done;
                let finished = lock.lock().unwrap_or_else(|e| e.into_inner());
                let (finished, _) =
                    cv.wait_timeout_while(finished, APPEAR_AFTER, |f| !*f).unwrap_or_else(|e| e.into_inner());
                if !*finished {
                    bar.set_draw_target(ProgressDrawTarget::stderr());
                    bar.enable_steady_tick(Duration::from_millis(200));
                }
            })
        });
        Progress { bar, done, waiter }
    }

    /// One step done.
    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// Steps done so far (for the tests).
    #[cfg(test)]
    pub fn position(&self) -> u64 {
        self.bar.position()
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        let (lock, cv) = &*self.done;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cv.notify_all();
        if let Some(w) = self.waiter.take() {
            let _ = w.join();
        }
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quiet_disables_and_quick_work_ends_without_waiting() {
        set_quiet(true);
        assert!(!enabled());
        set_quiet(false);
        // A displayed counter dropped at once: its display thread wakes and ends without
        // waiting out APPEAR_AFTER (the test would take 2 s otherwise; it must not hang).
        let p = Progress::with_display(3, "runs", true);
        p.inc();
        p.inc();
        assert_eq!(p.position(), 2);
        let t = std::time::Instant::now();
        drop(p);
        assert!(t.elapsed() < APPEAR_AFTER, "drop waited for the display delay");
    }
}
