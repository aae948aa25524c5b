//! SIGINT and SIGTERM, handled alike by every command.
//!
//! [`install`] starts a thread (signal-hook) that, on the first signal, records it; the work checks
//! [`check`] between units of work (runs of a sweep, files of a command), removes its temporary
//! output and returns [`Error::Interrupted`]; `main` prints one line and exits 128 + signal number
//! (130 for SIGINT, 143 for SIGTERM). Work that has no such check point (one long run, a discovery
//! fit) is stopped by the same thread after [`GRACE`]: it removes every registered temporary and
//! exits itself. A second signal exits at once (after the same removal).
//!
//! Temporaries are registered ([`Temp`]) from creation until they are renamed into place or
//! removed; the registry lock is held across a commit, so a temporary is never removed while it is
//! being renamed.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, Ordering};
use std::sync::Mutex;
use std::time::Duration;

use vehsim_core::error::{Error, Result};

/// How long the work has to stop by itself after a signal before the handler ends the process.
pub const GRACE: Duration = Duration::from_millis(900);

/// The first signal received (0: none).
static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// Live temporaries: (temporary path, the final path it is meant to become).
static LIVE: Mutex<Vec<(PathBuf, PathBuf)>> = Mutex::new(Vec::new());

/// Serialises the process's last words: the first caller prints and exits, later ones wait.
static EXIT: Mutex<()> = Mutex::new(());

/// The signal that interrupted the work, if any (2 = SIGINT, 15 = SIGTERM).
pub fn received() -> Option<i32> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// Name of a signal number for messages.
pub fn name(sig: i32) -> &'static str {
    match sig {
        libc::SIGINT => "SIGINT",
        libc::SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// Exit code for an interruption: 128 + signal number (130 when no signal was recorded).
pub fn exit_code() -> u8 {
    (128 + received().unwrap_or(libc::SIGINT)).clamp(0, 255) as u8
}

/// Record `sig` as if it had been received (tests; and the handler).
pub fn raise(sig: i32) {
    let _ = SIGNAL.compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst);
}

/// `Err(Interrupted)` once a signal was received; `kept` says what is left as it was.
pub fn check(kept: impl FnOnce() -> String) -> Result<()> {
    match received() {
        None => Ok(()),
        Some(signal) => Err(Error::Interrupted { signal, kept: kept() }),
    }
}

/// A registered temporary: unregistered when dropped (the owner renames or removes the path).
#[derive(Debug)]
pub struct Temp {
    path: PathBuf,
}

impl Temp {
    /// Register `path`, a temporary that will become `dest`.
    pub fn register(path: &Path, dest: &Path) -> Self {
        lock().push((path.to_path_buf(), dest.to_path_buf()));
        Temp { path: path.to_path_buf() }
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        let mut live = lock();
        if let Some(i) = live.iter().rposition(|(p, _)| *p == self.path) {
            live.remove(i);
        }
    }
}

fn lock() -> std::sync::MutexGuard<'static, Vec<(PathBuf, PathBuf)>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Run `f` (a commit: renames of registered temporaries) with the registry locked, so that the
/// handler cannot remove a temporary halfway through.
pub fn committing<T>(f: impl FnOnce() -> T) -> T {
    let _live = lock();
    f()
}

/// Remove every registered temporary (files or folders); returns the final paths they were for.
fn remove_live() -> Vec<PathBuf> {
    let live = lock();
    let mut dests = Vec::new();
    for (tmp, dest) in live.iter() {
        match std::fs::symlink_metadata(tmp) {
            Ok(m) if m.is_dir() => {
                let _ = std::fs::remove_dir_all(tmp);
            }
            Ok(_) => {
                let _ = std::fs::remove_file(tmp);
            }
            Err(_) => {}
        }
        if !dests.contains(dest) {
            dests.push(dest.clone());
        }
    }
    // Keep the lock: the process is about to exit and nothing may start a commit now.
    std::mem::forget(live);
    dests
}

/// Print `line` on stderr and exit with `code`; only the first caller does so, any later caller
/// blocks until the process is gone.
pub fn exit_with(code: u8, line: &str) -> ! {
    let _g = EXIT.lock().unwrap_or_else(|e| e.into_inner());
    eprintln!("{line}");
    std::process::exit(code as i32)
}

/// The one line printed when a signal ends the work.
pub fn interrupted_line(detail: &str) -> String {
    let sig = received().unwrap_or(libc::SIGINT);
    format!("vehsim: interrupted by {}: {detail}", name(sig))
}

/// Install the SIGINT/SIGTERM handler thread (once, from `main`).
pub fn install() {
    let Ok(mut signals) = signal_hook::iterator::Signals::new([libc::SIGINT, libc::SIGTERM]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            raise(sig);
            // Give the work its chance to stop cleanly at its next check point; a second signal
            // cuts the wait short.
            let start = std::time::Instant::now();
            while start.elapsed() < GRACE && signals.pending().next().is_none() {
                std::thread::sleep(Duration::from_millis(20));
            }
            let dests = remove_live();
            let detail = if dests.is_empty() {
                "no partial output left".to_string()
            } else {
                let names: Vec<String> = dests.iter().map(|d| d.display().to_string()).collect();
                format!("removed the temporary output for {}; nothing partial was written", names.join(", "))
            };
            exit_with(exit_code(), &interrupted_line(&detail));
        }
    });
}

/// Treat a closed stdout (`vehsim validate *.toml | head -3`) as the reader having seen enough:
/// the panic that `println!` raises on EPIPE ends the process with exit 0 and no message, after
/// removing live temporaries. Every other panic keeps the default report.
pub fn quiet_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let msg = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.starts_with("failed printing to stdout") && msg.contains("Broken pipe") {
            remove_live();
            std::process::exit(0);
        }
        default(info);
    }));
}

/// The one place an error becomes a message and an exit code; an interruption ends the process
/// with its one line (130 / 143).
pub(crate) fn report(e: &Error) -> std::process::ExitCode {
    if let Error::Interrupted { kept, .. } = e {
        exit_with(e.exit_code(), &interrupted_line(kept));
    }
    eprintln!("error: {e}");
    std::process::ExitCode::from(e.exit_code())
}
