//! Error type of the vehsim crates and the checks that turn raw values into validated ones.
//!
//! Every user-facing input problem becomes [`Error::Input`], whose message names the file, the key
//! (or line) and what is allowed; the CLI maps it to exit code 2. Nothing in the library panics on
//! bad input.

use std::path::{Path, PathBuf};

/// Library error, each kind with its exit code ([`Error::exit_code`]): `Run` a run that could not
/// be carried out (1), `Input` and `Usage` the user's fault (2), `Io` the environment's (3: disk full,
/// permission, a collision), `Interrupted` a signal (130 for SIGINT, 143 for SIGTERM).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Bad input: a missing or malformed file, an unknown key, a non-physical value.
    #[error("{}: {message}", file.display())]
    Input {
        /// The spec or data file at fault.
        file: PathBuf,
        /// What is wrong: the key or line, the value and what is allowed.
        message: String,
    },
    /// A bad command-line flag value: the flag (`--jobs`) and what is allowed.
    #[error("{flag}: {message}")]
    Usage {
        /// The flag, e.g. `--jobs`.
        flag: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// Reading or writing a file failed for a reason outside the user's input.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file that could not be read or written.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// A run could not be carried out (not a bad input, not a simulation event).
    #[error("{0}")]
    Run(String),
    /// SIGINT or SIGTERM (`signal`, its number) stopped the work; nothing partial was written
    /// (`kept` says what was kept).
    #[error("interrupted: {kept}")]
    Interrupted {
        /// The signal number (2 SIGINT, 15 SIGTERM).
        signal: i32,
        /// What was kept of the work done before the signal.
        kept: String,
    },
}

impl Error {
    /// Process exit code for this error: 1 a run failed, 2 bad input, 3 an I/O or environment
    /// error, 128 + the signal number for an interruption (the shell's convention).
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Run(_) => 1,
            Error::Input { .. } | Error::Usage { .. } => 2,
            Error::Io { .. } => 3,
            Error::Interrupted { signal, .. } => (128 + signal).clamp(0, 255) as u8,
        }
    }

    /// A bad-input error about `file`.
    pub fn input(file: &Path, message: impl Into<String>) -> Self {
        Error::Input { file: file.to_path_buf(), message: message.into() }
    }

    /// A bad value of command-line flag `flag` (e.g. `--jobs`); `message` says what is allowed.
    pub fn usage(flag: &str, message: impl Into<String>) -> Self {
        Error::Usage { flag: flag.to_string(), message: message.into() }
    }

    /// A bad-input error about key `key` of `file`.
    pub fn key(file: &Path, key: &str, message: impl std::fmt::Display) -> Self {
        Error::Input { file: file.to_path_buf(), message: format!("key '{key}': {message}") }
    }
}

/// A number as a message shows it: plain decimals between 1e-4 and 1e7 (`0.15`, `60000`), short
/// scientific notation outside, with at most four significant digits (`1e300`, `-1e-20`,
/// `3.671e7`), so a huge or tiny input is never printed as hundreds of digits.
pub fn short_num(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() || a == 0.0 || (1e-4..1e7).contains(&a) {
        return format!("{v}");
    }
    let s = format!("{v:.3e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        _ => s,
    }
}

/// Library result type.
pub type Result<T> = std::result::Result<T, Error>;

/// `'text'` when `text` is a short plain token (letters, digits, `_ - . + e`), else a note that it
/// is not shown: for echoing a value read from a file that may not be a spec.
pub fn shown(text: &str) -> String {
    if text.len() <= 40 && text.chars().all(|c| c.is_ascii_alphanumeric() || "_-.+ ".contains(c)) {
        format!("'{text}'")
    } else {
        "(text not shown)".to_string()
    }
}

/// For `map_err` where `referrer` names another file under `key`: an error about that other file
/// also says which file and key referred to it.
pub fn referred_by<'a>(referrer: &'a Path, key: &'a str) -> impl FnOnce(Error) -> Error + 'a {
    move |e| match e {
        Error::Input { file, message } if file != referrer => {
            Error::Input { message: format!("{message} (named by {} key '{key}')", referrer.display()), file }
        }
        other => other,
    }
}

/// Which ends of a [`Bound`] are allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// `[lo, hi]`.
    Closed,
    /// `(lo, hi]`.
    LeftOpen,
    /// `(lo, hi)`.
    Open,
}

/// The allowed range of one numeric spec key, declared once: the check, its message and the
/// tests that hold the docs' key tables to the code all read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// Dotted key, e.g. `surface.mu`.
    pub key: &'static str,
    /// Lower end of the range.
    pub lo: f64,
    /// Upper end of the range.
    pub hi: f64,
    /// Which ends belong to the range.
    pub ends: Ends,
    /// Unit as the docs write it (`s`, `m/s`, `1/K`; empty when dimensionless).
    pub unit: &'static str,
}

impl Bound {
    /// A closed range `[lo, hi]`.
    pub const fn closed(key: &'static str, lo: f64, hi: f64, unit: &'static str) -> Self {
        Bound { key, lo, hi, ends: Ends::Closed, unit }
    }

    /// A range `(lo, hi]`.
    pub const fn left_open(key: &'static str, lo: f64, hi: f64, unit: &'static str) -> Self {
        Bound { key, lo, hi, ends: Ends::LeftOpen, unit }
    }

    /// An open range `(lo, hi)`.
    pub const fn open(key: &'static str, lo: f64, hi: f64, unit: &'static str) -> Self {
        Bound { key, lo, hi, ends: Ends::Open, unit }
    }

    /// True when finite `v` is within the range.
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite()
            && match self.ends {
                Ends::Closed => v >= self.lo && v <= self.hi,
                Ends::LeftOpen => v > self.lo && v <= self.hi,
                Ends::Open => v > self.lo && v < self.hi,
            }
    }

    /// The range in interval notation, e.g. `(0, 2]`.
    pub fn interval(&self) -> String {
        let (l, r) = match self.ends {
            Ends::Closed => ('[', ']'),
            Ends::LeftOpen => ('(', ']'),
            Ends::Open => ('(', ')'),
        };
        format!("{l}{}, {}{r}", short_num(self.lo), short_num(self.hi))
    }

    /// What the error message says is allowed: `expected a finite number in [lo, hi]` for a
    /// closed range, else `expected lo < name <= hi (unit)` with the key's last part as name.
    pub fn allowed(&self) -> String {
        let name = self.key.rsplit('.').next().unwrap_or(self.key);
        let unit = if self.unit.is_empty() { String::new() } else { format!(" ({})", self.unit) };
        let (lo, hi) = (short_num(self.lo), short_num(self.hi));
        match self.ends {
            Ends::Closed => format!("expected a finite number in [{lo}, {hi}]"),
            Ends::LeftOpen => format!("expected {lo} < {name} <= {hi}{unit}"),
            Ends::Open => format!("expected {lo} < {name} < {hi}{unit}"),
        }
    }
}

/// Checks on one spec file's numeric values. Each check returns the first violation as a
/// bad-input error naming the file, the key, the value and what is allowed.
pub struct Checker<'a> {
    /// The spec file the checked values come from (named in every error).
    pub file: &'a Path,
}

impl<'a> Checker<'a> {
    /// A checker whose errors name `file`.
    pub fn new(file: &'a Path) -> Self {
        Self { file }
    }

    fn fail(&self, key: &str, v: f64, allowed: &str) -> Error {
        Error::key(self.file, key, format!("value {} is not allowed; {allowed}", short_num(v)))
    }

    /// Finite (not NaN, not infinite).
    pub fn finite(&self, key: &str, v: f64) -> Result<f64> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.fail(key, v, "expected a finite number"))
        }
    }

    /// Finite and strictly positive.
    pub fn positive(&self, key: &str, v: f64) -> Result<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.fail(key, v, "expected a finite number > 0"))
        }
    }

    /// Finite, > 0 and <= `hi`: `expected 0 < name <= hi (unit)` with the key's last part as name.
    pub fn positive_up_to(&self, key: &str, v: f64, hi: f64, unit: &str) -> Result<f64> {
        if v.is_finite() && v > 0.0 && v <= hi {
            Ok(v)
        } else {
            let name = key.rsplit('.').next().unwrap_or(key);
            Err(self.fail(key, v, &format!("expected 0 < {name} <= {} ({unit})", short_num(hi))))
        }
    }

    /// Finite and >= 0.
    pub fn non_negative(&self, key: &str, v: f64) -> Result<f64> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.fail(key, v, "expected a finite number >= 0"))
        }
    }

    /// Finite and within [lo, hi].
    pub fn range(&self, key: &str, v: f64, lo: f64, hi: f64) -> Result<f64> {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(v)
        } else {
            Err(self.fail(key, v, &format!("expected a finite number in [{}, {}]", short_num(lo), short_num(hi))))
        }
    }

    /// Within `b` (its key and message).
    pub fn bound(&self, b: &Bound, v: f64) -> Result<f64> {
        if b.contains(v) {
            Ok(v)
        } else {
            Err(self.fail(b.key, v, &b.allowed()))
        }
    }

    /// Generic condition with a custom description of what is allowed.
    pub fn require(&self, key: &str, v: f64, ok: bool, allowed: &str) -> Result<f64> {
        if v.is_finite() && ok {
            Ok(v)
        } else {
            Err(self.fail(key, v, allowed))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::short_num;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(short_num(1e300), "1e300");
        assert_eq!(short_num(-1e-20), "-1e-20");
        assert_eq!(short_num(36_714_286.0), "3.671e7");
        assert_eq!(short_num(0.15), "0.15");
        assert_eq!(short_num(60000.0), "60000");
        assert_eq!(short_num(0.0), "0");
        assert_eq!(short_num(f64::NAN), "NaN");
        assert!(short_num(f64::MAX).len() <= 12, "{}", short_num(f64::MAX));
    }
}
