//! Writing result files safely: everything goes to a temporary name in the destination folder and
//! is renamed into place, so a reader never sees a half-written file. [`table`] reads numeric
//! CSV tables back; [`num`] prints numbers with a fixed number of significant digits.

pub mod num;
pub mod table;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Temporary sibling name used while `path` is being written.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}", std::process::id()))
}

/// Write `bytes` to `path` through a temporary file and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_path(path);
    std::fs::write(&tmp, bytes).map_err(|e| Error::Io { path: tmp.clone(), source: e })?;
    rename(&tmp, path)
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
