//! Writing result files safely: every file goes to a hidden temporary name beside its final name
//! (created exclusively, so a planted symlink is never followed) and is renamed into place; on any
//! failure the temporary is removed, so nothing half-written ever carries a final name. Folders
//! are replaced whole ([`replace`]); SIGINT/SIGTERM are handled in [`signals`]; [`table`] reads
//! numeric CSV tables back; `num` prints numbers with a fixed number of significant digits.

pub(crate) mod num;
pub mod replace;
pub mod signals;
pub mod table;

use std::cell::Cell;
use std::io::Write as _;
use std::path::{Path, PathBuf};

pub use replace::{write_dir_atomic, Staged};

use vehsim_core::error::{Error, Result};

thread_local! {
    /// Fault injection for tests: when non-zero, this thread's file writes fail with "no space
    /// left on device" once this many more bytes would be written (a stand-in for a full disk).
    #[doc(hidden)]
    pub static FAIL_AFTER_BYTES: Cell<u64> = const { Cell::new(0) };
}

/// Temporary sibling name used while `path` is being written: `.<name>.tmp<PID>`.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}", std::process::id()))
}

fn write_new(tmp: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let budget = FAIL_AFTER_BYTES.get();
    let mut f = std::fs::OpenOptions::new().write(true).create_new(true).open(tmp)?;
    if budget > 0 {
        let n = bytes.len() as u64;
        if n >= budget {
            f.write_all(&bytes[..budget as usize - 1])?;
            return Err(std::io::Error::from_raw_os_error(libc::ENOSPC));
        }
        FAIL_AFTER_BYTES.set(budget - n);
    }
    f.write_all(bytes)
}

/// Write `bytes` to `path` through a temporary file and a rename. A symlink at `path` is replaced,
/// not followed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_path(path);
    let _live = signals::Temp::register(&tmp, path);
    if std::fs::symlink_metadata(&tmp).is_ok() {
        std::fs::remove_file(&tmp).map_err(|e| Error::Io { path: tmp.clone(), source: e })?;
    }
    if let Err(e) = write_new(&tmp, bytes) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::Io { path: path.to_path_buf(), source: e });
    }
    signals::committing(|| rename(&tmp, path))
}

/// Rename `tmp` onto `path`, removing `tmp` if that fails.
pub fn rename(tmp: &Path, path: &Path) -> Result<()> {
    std::fs::rename(tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(tmp);
        Error::Io { path: path.to_path_buf(), source: e }
    })
}

/// Create a folder and its parents.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Io { path: dir.to_path_buf(), source: e })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A full disk in the middle of a folder: the writer fails, the temporary file and folder go,
    /// the old folder stays whole and nothing half-written carries a final name.
    #[test]
    fn a_full_disk_leaves_no_file_under_a_final_name() {
        let d = std::env::temp_dir().join(format!("vehsim_full_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        let dest = d.join("r");
        write_dir_atomic(&dest, |t| write_atomic(&t.join("a.csv"), b"old")).unwrap();
        std::fs::write(d.join("single.csv"), "old").unwrap();
        FAIL_AFTER_BYTES.set(1000);
        let e = write_dir_atomic(&dest, |t| {
            write_atomic(&t.join("a.csv"), &[b'x'; 600])?;
            write_atomic(&t.join("b.csv"), &[b'y'; 600])
        })
        .unwrap_err();
        FAIL_AFTER_BYTES.set(10);
        let e2 = write_atomic(&d.join("single.csv"), b"new and longer").unwrap_err();
        FAIL_AFTER_BYTES.set(0);
        assert_eq!((e.exit_code(), e2.exit_code()), (3, 3), "{e}; {e2}");
        assert!(e.to_string().contains("No space left"), "{e}");
        let mut names: Vec<String> =
            std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        assert_eq!(names, ["r", "single.csv"]);
        assert_eq!(std::fs::read(dest.join("a.csv")).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&dest).unwrap().count(), 1);
        assert_eq!(std::fs::read(d.join("single.csv")).unwrap(), b"old");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
