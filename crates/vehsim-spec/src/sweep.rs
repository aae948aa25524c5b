//! Sweeps: a manoeuvre spec with a `[sweep]` table expands into the full product of its lists,
//! each combination validated into a [`RunConfig`] (or kept as an invalid run with the reason);
//! and what identifies a batch across machines ([`batch_digest`]). Nothing runs here: the
//! application runs the batch and writes its folders; the Python package and the FMU expand
//! specs through this module.

use std::path::{Path, PathBuf};

use crate::{ManeuverFile, RunConfig};
use vehsim_core::error::{Error, Result};
use vehsim_core::sim::Summary;

/// One run of a batch: its index, its swept values (key, value as text) and its validated config
/// (or why the combination is invalid).
#[derive(Debug, Clone)]
pub struct BatchRun {
    /// Index of the combination (the last swept key varies fastest), from 0.
    pub index: usize,
    /// The swept keys and their values as text, in nesting order.
    pub params: Vec<(String, String)>,
    /// The validated run, or why the combination is invalid.
    pub config: std::result::Result<RunConfig, String>,
}

/// A loaded spec: a single run, or a sweep's runs.
#[derive(Debug, Clone)]
pub struct Batch {
    /// The spec's `name`.
    pub name: String,
    /// The spec file, as given.
    pub spec_file: PathBuf,
    /// Swept keys in nesting order (empty for a single run).
    pub keys: Vec<String>,
    /// Every combination in index order.
    pub runs: Vec<BatchRun>,
    /// The spec as parsed (sweep included), written back as TOML: what [`batch_digest`] hashes,
    /// so comments and layout do not count.
    pub source: String,
}

impl Batch {
    /// True when the spec declares a sweep (results go into run folders with a summary.csv).
    pub fn is_sweep(&self) -> bool {
        !self.keys.is_empty()
    }
}

/// Most runs one sweep may expand to.
pub const MAX_RUNS: usize = 1_000_000;

/// Value of a swept key as text (strings without quotes).
pub fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The swept keys of a `[sweep]` table and their lists of values, in the table's order; a key for
/// which `refuse` gives a reason, or whose value is not a non-empty list, is bad input naming
/// `sweep.KEY`.
pub fn swept_lists(
    path: &Path,
    sweep: &toml::Table,
    refuse: &dyn Fn(&str) -> Option<String>,
) -> Result<(Vec<String>, Vec<Vec<toml::Value>>)> {
    let (mut keys, mut lists) = (Vec::new(), Vec::new());
    for (k, v) in sweep {
        if let Some(why) = refuse(k) {
            return Err(Error::key(path, &format!("sweep.{k}"), why));
        }
        match v {
            toml::Value::Array(a) if !a.is_empty() => {
                keys.push(k.clone());
                lists.push(a.clone());
            }
            _ => return Err(Error::key(path, &format!("sweep.{k}"), "expected a non-empty list of values")),
        }
    }
    Ok((keys, lists))
}

/// The value index of each swept key for combination `index` (mixed-radix digits, the last key
/// varying fastest), so that `vehsim run` and `vehsim envelope` number combinations alike.
pub fn combination(index: usize, lists: &[Vec<toml::Value>]) -> Vec<usize> {
    let mut rem = index;
    let mut choice = vec![0; lists.len()];
    for (d, l) in lists.iter().enumerate().rev() {
        choice[d] = rem % l.len();
        rem /= l.len();
    }
    choice
}

/// Set `value` at the dotted `key` of `table` (intermediate tables are created).
pub fn set_path(table: &mut toml::Table, key: &str, value: toml::Value) -> std::result::Result<(), String> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().ok_or("empty key")?;
    let mut t = table;
    for p in parts {
        let entry = t.entry(p.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry.as_table_mut().ok_or_else(|| format!("'{p}' in '{key}' is not a table"))?;
    }
    t.insert(last.to_string(), value);
    Ok(())
}

/// Expand the sweep of a spec read from `path` and parsed into `table` (`path` is named in
/// messages; the vehicle file and other paths inside the spec are resolved against its folder).
/// Bad input (a malformed sweep, a spec whose every combination is invalid) is an error;
/// individual invalid combinations are kept as invalid runs.
pub fn from_table(path: &Path, table: toml::Table) -> Result<Batch> {
    from_table_with(path, table, &mut |_, _| Ok(()))
}

/// As [`from_table`], calling `each(index, total)` before combination `index` of `total` is
/// validated (a caller's progress count, or its check for a stop request: an error it returns
/// ends the expansion with that error).
pub fn from_table_with(
    path: &Path,
    mut table: toml::Table,
    each: &mut dyn FnMut(usize, usize) -> Result<()>,
) -> Result<Batch> {
    crate::kind::expect(path, &table, crate::kind::SpecKind::Run)?;
    let source = toml::to_string(&table).unwrap_or_default();
    let sweep = match table.remove("sweep") {
        None => None,
        Some(toml::Value::Table(t)) => Some(t),
        Some(_) => return Err(Error::key(path, "sweep", "expected a table of key = [values]")),
    };
    let Some(sweep) = sweep.filter(|s| !s.is_empty()) else {
        let cfg = ManeuverFile::from_table(path, table)?.build(path)?;
        return Ok(Batch {
            name: cfg.name.clone(),
            spec_file: path.to_path_buf(),
            keys: Vec::new(),
            runs: vec![BatchRun { index: 0, params: Vec::new(), config: Ok(cfg) }],
            source,
        });
    };
    let refuse = |k: &str| (k == "name" || k == "sweep" || k.starts_with("sweep.")).then(|| "cannot be swept".into());
    let (keys, lists) = swept_lists(path, &sweep, &refuse)?;
    let total = lists.iter().try_fold(1usize, |a, l| a.checked_mul(l.len())).unwrap_or(usize::MAX);
    if total > MAX_RUNS {
        return Err(Error::key(path, "sweep", format!("{total} runs; at most {MAX_RUNS} allowed")));
    }
    let name = match table.get("name") {
        Some(toml::Value::String(s)) => s.clone(),
        _ => return Err(Error::key(path, "name", "expected a string")),
    };
    let mut runs = Vec::with_capacity(total);
    // Vehicle, tyre and .tir files are parsed once per distinct file over the combinations.
    let mut cache = crate::maneuver::BuildCache::default();
    for index in 0..total {
        each(index, total)?;
        let choice = combination(index, &lists);
        let mut t = table.clone();
        let mut params = Vec::with_capacity(keys.len());
        let mut err = None;
        for ((k, l), c) in keys.iter().zip(&lists).zip(&choice) {
            params.push((k.clone(), value_text(&l[*c])));
            if let Err(e) = set_path(&mut t, k, l[*c].clone()) {
                err = Some(format!("sweep key '{k}': {e}"));
            }
        }
        let config = match err {
            Some(e) => Err(e),
            None => ManeuverFile::from_table(path, t)
                .and_then(|f| f.build_cached(path, &mut cache))
                .map_err(|e| e.to_string()),
        };
        runs.push(BatchRun { index, params, config });
    }
    if let Some(first_err) = runs.iter().find_map(|r| r.config.as_ref().err()) {
        if runs.iter().all(|r| r.config.is_err()) {
            // The stored message starts with the file name already.
            let prefix = format!("{}: ", path.display());
            let first = first_err.strip_prefix(&prefix).unwrap_or(first_err);
            return Err(Error::input(path, format!("every sweep combination is invalid; the first: {first}")));
        }
    }
    Ok(Batch { name, spec_file: path.to_path_buf(), keys, runs, source })
}

/// What became of one run of a batch (the `status` column of summary.csv and the table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RunStatus {
    /// The run went to its end (passed or not).
    Ok,
    /// The run diverged or spun out ([`Summary::failed`]).
    Failed,
    /// The combination did not validate; nothing ran.
    Invalid,
}

vehsim_core::choice_names!(RunStatus {
    Ok => "ok",
    Failed => "failed",
    Invalid => "invalid",
});

impl RunStatus {
    /// The status of a run that ended with `summary`.
    pub fn of(summary: &Summary) -> Self {
        if summary.failed() {
            RunStatus::Failed
        } else {
            RunStatus::Ok
        }
    }

    /// True when the run wrote a run folder (it ran).
    pub fn ran(self) -> bool {
        self != RunStatus::Invalid
    }
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// SHA-256 of `bytes`, in hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest as _;
    sha2::Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// What identifies the batch a shard belongs to: SHA-256 over the vehsim version, the spec as
/// parsed ([`Batch::source`]) and the contents of every vehicle, tyre and `.tir` file its runs
/// name (contents, not paths: a copy of the same files elsewhere is the same batch). Shards of
/// one spec run with another `tyre_model`, another vehicle file or another vehsim differ.
pub fn batch_digest(batch: &Batch) -> Result<String> {
    // (vehicle file, whether its tyre's .tir is read: only by the Magic Formula providers)
    let mut files = std::collections::BTreeSet::new();
    for cfg in batch.runs.iter().filter_map(|r| r.config.as_ref().ok()) {
        use vehsim_core::tyre::TyreModelKind as K;
        files.insert((cfg.vehicle_file.clone(), matches!(cfg.tyre_model, K::Pacejka | K::AtiimPacejka)));
    }
    let mut text = format!("vehsim {}\nspec\n{}\n", env!("CARGO_PKG_VERSION"), batch.source).into_bytes();
    let mut add = |what: &str, path: &Path| -> Result<()> {
        let bytes = std::fs::read(path).map_err(|e| Error::Io { path: path.to_path_buf(), source: e })?;
        text.extend_from_slice(format!("{what} {}\n", sha256_hex(&bytes)).as_bytes());
        Ok(())
    };
    for (v, reads_tir) in &files {
        add("vehicle", v)?;
        let vf = crate::VehicleFile::load(v)?;
        let tyre_path = crate::files::resolve(v, &vf.tyre);
        add("tyre", &tyre_path)?;
        let tf = crate::tyre::TyreFileSpec::load(&tyre_path)?;
        if let Some(rel) = tf.pacejka.as_ref().and_then(|p| p.tir_file.as_ref()).filter(|_| *reads_tir) {
            add("tir", &crate::files::resolve(&tyre_path, rel))?;
        }
    }
    Ok(sha256_hex(&text))
}
