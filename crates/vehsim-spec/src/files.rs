//! Reading spec and data files: size limits, refusing what is not a regular file, TOML parsing
//! with messages that name the file, line and key, and paths relative to a spec file.

use std::path::{Path, PathBuf};

use vehsim_core::error::{Error, Result};

/// Largest spec (TOML) or `.tir` file read, bytes.
pub(crate) const MAX_SPEC_BYTES: u64 = 16 << 20;
/// Largest data file (CSV) read, bytes.
pub(crate) const MAX_DATA_BYTES: u64 = 256 << 20;

/// Read a text file, mapping a missing or unreadable file to a bad-input error. Spec and `.tir`
/// files above `MAX_SPEC_BYTES`, others above `MAX_DATA_BYTES` are refused without reading
/// further (so `/dev/zero` is no endless read).
pub fn read_input(path: &Path) -> Result<String> {
    use std::io::Read as _;
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let limit = if ext == "toml" || ext == "tir" { MAX_SPEC_BYTES } else { MAX_DATA_BYTES };
    let why = |e: std::io::Error| match e.kind() {
        std::io::ErrorKind::NotFound => "file not found".to_string(),
        std::io::ErrorKind::InvalidData => "not valid UTF-8 text".to_string(),
        _ => format!("cannot read: {e}"),
    };
    // A FIFO is refused before it is opened: opening one for reading blocks until a writer comes.
    {
        use std::os::unix::fs::FileTypeExt as _;
        if std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) {
            return Err(Error::input(path, "not a regular file (a named pipe)"));
        }
    }
    let f = std::fs::File::open(path).map_err(|e| Error::input(path, why(e)))?;
    let kind = f.metadata().map_err(|e| Error::input(path, why(e)))?.file_type();
    {
        use std::os::unix::fs::FileTypeExt as _;
        if kind.is_dir() || kind.is_char_device() || kind.is_block_device() || kind.is_socket() || kind.is_fifo() {
            return Err(Error::input(path, "not a regular file"));
        }
    }
    let mut text = String::new();
    f.take(limit + 1).read_to_string(&mut text).map_err(|e| Error::input(path, why(e)))?;
    if text.len() as u64 > limit {
        return Err(Error::input(path, format!("larger than the {} MiB allowed for this kind of file", limit >> 20)));
    }
    // A UTF-8 byte-order mark (some Windows editors write one) is not part of the text.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Parse TOML text into `T` (unknown keys are rejected by `T`'s serde attributes); the message
/// carries the line, the column and the key as reported by the toml crate, never the text of the
/// file (it may not be a spec at all, e.g. a mistyped path naming a system file), and a missing
/// key names the table it belongs in.
pub fn parse_toml<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    let de = toml::Deserializer::new(text);
    let parsed: T = serde_path_to_error::deserialize(de).map_err(|e| {
        let key = e.path().to_string();
        let table = if key.is_empty() || key == "." { None } else { Some(key.as_str()) };
        let inner = e.into_inner().to_string();
        if let Some(field) = missing_field(&inner) {
            let place = table.map_or("the top level (above any [table])".to_string(), |t| format!("table [{t}]"));
            return Error::input(path, format!("missing key '{field}' in {place}"));
        }
        let inner = without_source_lines(&inner);
        match table {
            None => Error::input(path, format!("invalid spec: {inner}")),
            Some(k) => Error::input(path, format!("invalid spec at key '{k}': {inner}")),
        }
    })?;
    // serde also reads a table from an array of its values in order: refuse that shape.
    if let Ok(value) = toml::from_str::<toml::Value>(text) {
        crate::strict::check::<T>(path, &value)?;
    }
    Ok(parsed)
}

/// The field named by serde's "missing field `x`" message.
fn missing_field(msg: &str) -> Option<&str> {
    let rest = &msg[msg.find("missing field `")? + "missing field `".len()..];
    rest.split('`').next()
}

/// A toml error message without the quoted source line and its markers, on one line.
fn without_source_lines(msg: &str) -> String {
    let quoted = |l: &str| {
        let t = l.trim_start();
        t.starts_with('|')
            || t.split_once(" |").is_some_and(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    msg.lines().map(str::trim).filter(|l| !l.is_empty() && !quoted(l)).collect::<Vec<_>>().join(": ")
}

/// Resolve `rel` against the folder of `spec_file` (paths inside spec files are relative to the file).
pub fn resolve(spec_file: &Path, rel: &str) -> PathBuf {
    let p = Path::new(rel);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        spec_file.parent().unwrap_or_else(|| Path::new(".")).join(p)
    }
}
