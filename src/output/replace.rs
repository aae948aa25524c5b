//! Replacing a result folder atomically, and recovering from a process killed halfway.
//!
//! A folder `<parent>/<name>` is filled under the hidden temporary name `.<name>.tmp<PID>` and
//! then swapped in: on Linux with `renameat2(RENAME_EXCHANGE)` (one atomic step; the temporary
//! name then holds the old folder, which is removed), elsewhere or on a file system without it by
//! rename-aside (`<name>` to `.<name>.old<PID>`), rename-in, delete. At every instant `<name>` is
//! the complete old folder or the complete new one, except in the fallback's window between its
//! two renames, where `<name>` is missing and `.<name>.old<PID>` holds the old folder.
//!
//! [`recover_stale`] runs before each replace in the same parent: temporaries of processes that
//! no longer run are removed, and an aside copy whose `<name>` is missing is renamed back.
//! A path that exists but is not a real folder (a symlink, a file) is never replaced: a symlink
//! is not followed out of the output root.

use std::path::{Path, PathBuf};

use super::signals::{self, Temp};
use vehsim_core::error::{Error, Result};

fn io(path: &Path, e: std::io::Error) -> Error {
    Error::Io { path: path.to_path_buf(), source: e }
}

/// A temporary or aside name found in a folder: what it is for and which process made it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Leftover {
    /// Name of the final entry (`<name>`).
    pub name: String,
    /// `true` for an aside copy of an old folder (`.old`), `false` for a temporary (`.tmp`).
    pub aside: bool,
    pub pid: u32,
}

/// Parse `.<name>.tmp<PID>` / `.<name>.old<PID>` (also `.<name>.tmp<PID>.<ext>` of plots).
pub fn parse_leftover(file_name: &str) -> Option<Leftover> {
    let rest = file_name.strip_prefix('.')?;
    for (tag, aside) in [(".tmp", false), (".old", true)] {
        if let Some((name, tail)) = rest.rsplit_once(tag) {
            let digits = tail.split('.').next().unwrap_or("");
            if !name.is_empty() && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
                if let Ok(pid) = digits.parse() {
                    return Some(Leftover { name: name.to_string(), aside, pid });
                }
            }
        }
    }
    None
}

/// Does process `pid` still run (or exist under another user)?
pub fn process_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let Ok(p) = libc::pid_t::try_from(pid) else { return false };
    // SAFETY: kill with signal 0 only checks that the process exists; it sends nothing.
    let r = unsafe { libc::kill(p, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

fn remove_any(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(path),
        Ok(_) => std::fs::remove_file(path),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// Clean the leftovers of killed processes in `dir` and return one line per action (printed as
/// warnings by the caller). Leftovers of running processes are left alone.
pub fn recover_stale(dir: &Path) -> Vec<String> {
    let mut notes = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return notes };
    let mut found: Vec<(PathBuf, Leftover)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| parse_leftover(&e.file_name().to_string_lossy()).map(|l| (e.path(), l)))
        .filter(|(_, l)| !process_alive(l.pid))
        .collect();
    // Aside copies first, so that a missing folder is restored before its temporaries go.
    found.sort_by_key(|(p, l)| (!l.aside, p.clone()));
    for (path, l) in found {
        let dest = dir.join(&l.name);
        let restore = l.aside && std::fs::symlink_metadata(&dest).is_err();
        let done = if restore { std::fs::rename(&path, &dest) } else { remove_any(&path) };
        notes.push(match (done, restore) {
            (Ok(()), true) => format!(
                "restored {} from {} (left by process {} killed while replacing it)",
                dest.display(),
                path.display(),
                l.pid
            ),
            (Ok(()), false) => format!("removed {} (left by process {}, which no longer runs)", path.display(), l.pid),
            (Err(e), _) => format!("could not clean up {}: {e}", path.display()),
        });
    }
    notes
}

/// Swap `tmp` (a complete new folder) into `dest`; returns where the old folder now is, if any.
fn swap_in(tmp: &Path, dest: &Path) -> Result<Option<PathBuf>> {
    match std::fs::symlink_metadata(dest) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::rename(tmp, dest).map_err(|e| io(dest, e))?;
            Ok(None)
        }
        Err(e) => Err(io(dest, e)),
        Ok(m) if !m.is_dir() => Err(io(
            dest,
            std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "exists and is not a folder (a symlink or a file); not replaced",
            ),
        )),
        Ok(_) => {
            if exchange(tmp, dest).map_err(|e| io(dest, e))? {
                return Ok(Some(tmp.to_path_buf()));
            }
            let aside = aside_path(dest);
            remove_any(&aside).map_err(|e| io(&aside, e))?;
            std::fs::rename(dest, &aside).map_err(|e| io(dest, e))?;
            if let Err(e) = std::fs::rename(tmp, dest) {
                let _ = std::fs::rename(&aside, dest);
                return Err(io(dest, e));
            }
            Ok(Some(aside))
        }
    }
}

/// `.<name>.old<PID>` beside `dest`.
fn aside_path(dest: &Path) -> PathBuf {
    let name = dest.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    dest.with_file_name(format!(".{name}.old{}", std::process::id()))
}

/// Atomically exchange two existing paths. `Ok(false)`: not supported here (use the fallback).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    use std::os::unix::ffi::OsStrExt;
    let ca = std::ffi::CString::new(a.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    let cb = std::ffi::CString::new(b.as_os_str().as_bytes()).map_err(std::io::Error::other)?;
    // SAFETY: two valid NUL-terminated paths relative to the current folder; no memory is shared.
    let r = unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
    if r == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP) => Ok(false),
        _ => Err(e),
    }
}

#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<bool> {
    Ok(false)
}

/// What an interruption leaves of `dest`, for the one line printed.
pub fn kept(dest: &Path) -> String {
    if dest.exists() {
        format!("{} left as it was; temporary output removed", dest.display())
    } else {
        format!("{} not written; temporary output removed", dest.display())
    }
}

/// A folder being written under its temporary name; [`Staged::commit`] swaps it into place,
/// dropping it uncommitted removes it (so an error path leaves `dest` as it was).
#[derive(Debug)]
pub struct Staged {
    dest: PathBuf,
    tmp: PathBuf,
    live: Option<Temp>,
}

impl Staged {
    /// Clean leftovers of killed processes beside `dest` (reported on stderr), then create the
    /// empty temporary folder.
    pub fn new(dest: &Path) -> Result<Self> {
        let Some(name) = dest.file_name() else {
            return Err(Error::input(dest, "not a usable output folder name"));
        };
        let parent = match dest.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        super::create_dir(&parent)?;
        for note in recover_stale(&parent) {
            eprintln!("warning: {note}");
        }
        let dest = parent.join(name);
        let tmp = super::temp_path(&dest);
        remove_any(&tmp).map_err(|e| io(&tmp, e))?;
        std::fs::create_dir(&tmp).map_err(|e| io(&tmp, e))?;
        let live = Some(Temp::register(&tmp, &dest));
        Ok(Staged { dest, tmp, live })
    }

    /// The temporary folder to fill.
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// `Err(Interrupted)` if a signal arrived (the caller returns it; the drop cleans up).
    pub fn check(&self) -> Result<()> {
        signals::check(|| kept(&self.dest))
    }

    /// Replace `dest` by the filled folder atomically and remove the old one.
    pub fn commit(mut self) -> Result<()> {
        self.check()?;
        let old = signals::committing(|| swap_in(&self.tmp, &self.dest))?;
        if let Some(old) = old {
            let _ = remove_any(&old);
        }
        self.live = None;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if self.live.is_some() {
            let _ = remove_any(&self.tmp);
        }
    }
}

/// Fill a fresh temporary folder next to `dest` with `fill`, then replace `dest` by it atomically.
/// On any error or a signal the temporary is removed and `dest` is left as it was. Leftovers of
/// killed processes beside `dest` are cleaned first (reported on stderr).
pub fn write_dir_atomic(dest: &Path, fill: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let staged = Staged::new(dest)?;
    staged.check()?;
    fill(staged.path())?;
    staged.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("vehsim_replace_{tag}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn leftover_names_parse_and_others_do_not() {
        assert_eq!(parse_leftover(".dlc.tmp123"), Some(Leftover { name: "dlc".into(), aside: false, pid: 123 }));
        assert_eq!(parse_leftover(".a.b.old9"), Some(Leftover { name: "a.b".into(), aside: true, pid: 9 }));
        assert_eq!(parse_leftover(".x.png.tmp77.png").map(|l| l.pid), Some(77));
        for n in ["dlc", ".dlc", ".dlc.tmp", ".dlc.tmpx1", "..tmp1", ".git"] {
            assert_eq!(parse_leftover(n), None, "{n}");
        }
    }

    #[test]
    fn replace_swaps_whole_folders_and_failure_keeps_the_old_one() {
        let d = scratch("swap");
        let dest = d.join("r");
        write_dir_atomic(&dest, |t| std::fs::write(t.join("a"), "1").map_err(|e| io(t, e))).unwrap();
        write_dir_atomic(&dest, |t| std::fs::write(t.join("b"), "2").map_err(|e| io(t, e))).unwrap();
        assert!(!dest.join("a").exists());
        assert_eq!(std::fs::read_to_string(dest.join("b")).unwrap(), "2");
        let e = write_dir_atomic(&dest, |t| {
            std::fs::write(t.join("c"), "3").unwrap();
            Err(Error::Run("boom".into()))
        });
        assert!(e.is_err());
        assert_eq!(std::fs::read_to_string(dest.join("b")).unwrap(), "2");
        assert!(!dest.join("c").exists());
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("r")], "no temporaries left");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_symlink_or_file_in_the_way_is_not_replaced_or_followed() {
        let d = scratch("link");
        let outside = d.join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::fs::write(outside.join("keep"), "x").unwrap();
        let root = d.join("root");
        std::fs::create_dir(&root).unwrap();
        std::os::unix::fs::symlink(&outside, root.join("r")).unwrap();
        let e = write_dir_atomic(&root.join("r"), |t| std::fs::write(t.join("a"), "1").map_err(|e| io(t, e)));
        assert_eq!(e.unwrap_err().exit_code(), 3);
        assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 1);
        assert!(std::fs::symlink_metadata(root.join("r")).unwrap().file_type().is_symlink());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn leftovers_of_dead_processes_are_removed_or_restored() {
        let d = scratch("stale");
        // A pid above the kernel's maximum (4194304) never runs.
        let dead = 4_999_999;
        std::fs::create_dir(d.join(format!(".gone.old{dead}"))).unwrap();
        std::fs::write(d.join(format!(".gone.old{dead}")).join("f"), "old").unwrap();
        std::fs::create_dir(d.join(format!(".gone.tmp{dead}"))).unwrap();
        std::fs::create_dir(d.join("kept")).unwrap();
        std::fs::create_dir(d.join(format!(".kept.old{dead}"))).unwrap();
        std::fs::write(d.join(format!(".file.csv.tmp{dead}")), "partial").unwrap();
        let mine = d.join(format!(".mine.tmp{}", std::process::id()));
        std::fs::create_dir(&mine).unwrap();
        let notes = recover_stale(&d);
        assert_eq!(notes.len(), 4, "{notes:?}");
        assert_eq!(std::fs::read_to_string(d.join("gone/f")).unwrap(), "old");
        let mut names: Vec<String> =
            std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        assert_eq!(names, vec![format!(".mine.tmp{}", std::process::id()), "gone".into(), "kept".into()]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
