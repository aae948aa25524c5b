//! Batches: a manoeuvre spec with a `[sweep]` table expands into the full product of its lists;
//! the runs execute in parallel (rayon) and write `results/<name>/run_NNNN/` plus one
//! `summary.csv`. A run that fails (invalid combination, divergence, spin-out) is marked and
//! the others go on. `--shard K/N` runs the K-th of N disjoint parts (runs with index mod N = K-1)
//! into `results/<name>.shard-K-of-N/`; [`merge`] joins the parts into `results/<name>/`.
//!
//! Outputs are byte-identical whatever the thread count: every run is deterministic and the
//! summary is written in run order.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::error::{read_input, Error, Result};
use crate::output::write_atomic;
use crate::run::{self, write_dir_atomic, RunOutput};
use crate::sim::Summary;
use crate::spec::{ManeuverFile, RunConfig};

/// Set by the CLI's SIGINT handler. A batch checks it before each run and a single run before it
/// writes; once set, the work stops and its temporary folder is removed, so a results folder is
/// either complete or left as it was before.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

fn check_interrupted(dir: &Path) -> Result<()> {
    if INTERRUPTED.load(Ordering::SeqCst) {
        Err(Error::Interrupted(format!("{} was not written (no partial results)", dir.display())))
    } else {
        Ok(())
    }
}

/// One run of a batch: its index, its swept values (key, value as text) and its validated config
/// (or why the combination is invalid).
#[derive(Debug, Clone)]
pub struct BatchRun {
    pub index: usize,
    pub params: Vec<(String, String)>,
    pub config: std::result::Result<RunConfig, String>,
}

/// A loaded spec: a single run, or a sweep's runs.
#[derive(Debug, Clone)]
pub struct Batch {
    pub name: String,
    pub spec_file: PathBuf,
    /// Swept keys in nesting order (empty for a single run).
    pub keys: Vec<String>,
    pub runs: Vec<BatchRun>,
}

impl Batch {
    /// True when the spec declares a sweep (results go into run folders with a summary.csv).
    pub fn is_sweep(&self) -> bool {
        !self.keys.is_empty()
    }
}

/// A part of a batch: the K-th (1-based) of N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || format!("'{s}' is not a shard; expected K/N with 1 <= K <= N, e.g. 2/8");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (k, n): (usize, usize) = (k.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
        if n == 0 || k == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }
}

impl Shard {
    fn contains(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }
    fn folder(&self, name: &str) -> String {
        format!("{name}.shard-{}-of-{}", self.k, self.n)
    }
}

/// Value of a swept key as text (strings without quotes).
fn value_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// Set `value` at the dotted `key` of `table` (intermediate tables are created).
fn set_path(table: &mut toml::Table, key: &str, value: toml::Value) -> std::result::Result<(), String> {
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

/// Read a spec and expand its sweep. Bad input (unreadable file, malformed TOML or sweep, a spec
/// whose every combination is invalid) is an error; individual invalid combinations are kept as
/// invalid runs.
pub fn load(path: &Path) -> Result<Batch> {
    let text = read_input(path)?;
    from_text(path, &text)
}

/// As [`load`], for spec text already read from `path` (named in messages; the vehicle file and
/// other paths inside the spec are resolved against its folder).
pub fn from_text(path: &Path, text: &str) -> Result<Batch> {
    from_table(path, crate::error::parse_toml(path, text)?)
}

/// As [`load`], for a spec already parsed into a TOML table.
pub fn from_table(path: &Path, mut table: toml::Table) -> Result<Batch> {
    crate::spec::kind::expect(path, &table, crate::spec::kind::SpecKind::Run)?;
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
        });
    };
    let mut keys = Vec::new();
    let mut lists = Vec::new();
    for (k, v) in &sweep {
        if k == "name" || k == "sweep" || k.starts_with("sweep.") {
            return Err(Error::key(path, &format!("sweep.{k}"), "cannot be swept"));
        }
        match v {
            toml::Value::Array(a) if !a.is_empty() => {
                keys.push(k.clone());
                lists.push(a.clone());
            }
            _ => return Err(Error::key(path, &format!("sweep.{k}"), "expected a non-empty list of values")),
        }
    }
    let total: usize = lists.iter().map(|l| l.len()).product();
    if total > 1_000_000 {
        return Err(Error::key(path, "sweep", format!("{total} runs; at most 1000000 allowed")));
    }
    let name = match table.get("name") {
        Some(toml::Value::String(s)) => s.clone(),
        _ => return Err(Error::key(path, "name", "expected a string")),
    };
    let mut runs = Vec::with_capacity(total);
    let checked = crate::progress::Progress::new(total, "combinations checked");
    // Vehicle, tyre and .tir files are parsed once per distinct file over the combinations.
    let mut cache = crate::spec::maneuver::BuildCache::default();
    for index in 0..total {
        // Mixed-radix digits of the index, the last key varying fastest.
        let mut rem = index;
        let mut choice = vec![0; lists.len()];
        for (d, l) in lists.iter().enumerate().rev() {
            choice[d] = rem % l.len();
            rem /= l.len();
        }
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
        checked.inc();
    }
    drop(checked);
    if let Some(first_err) = runs.iter().find_map(|r| r.config.as_ref().err()) {
        if runs.iter().all(|r| r.config.is_err()) {
            // The stored message starts with the file name already.
            let prefix = format!("{}: ", path.display());
            let first = first_err.strip_prefix(&prefix).unwrap_or(first_err);
            return Err(Error::input(path, format!("every sweep combination is invalid; the first: {first}")));
        }
    }
    Ok(Batch { name, spec_file: path.to_path_buf(), keys, runs })
}

/// What happened to one run of a batch.
#[derive(Debug, Clone)]
pub struct RunRecord {
    pub index: usize,
    pub params: Vec<(String, String)>,
    /// `ok`, `failed` (diverged or spun out) or `invalid` (the combination did not validate).
    pub status: &'static str,
    pub summary: Option<Summary>,
    /// Why the run is invalid (empty otherwise).
    pub message: String,
}

/// Folder name of run `index` inside a batch folder.
pub fn run_folder(index: usize) -> String {
    format!("run_{index:04}")
}

/// Header of summary.csv for the swept `keys`.
pub fn summary_header(keys: &[String]) -> String {
    let mut cols = vec!["run".to_string(), "status".to_string()];
    cols.extend(keys.iter().cloned());
    for c in [
        "passed",
        "cones_hit",
        "peak_yaw_rate_radps",
        "peak_sideslip_rad",
        "peak_ay_mps2",
        "max_path_deviation_m",
        "min_speed_mps",
        "max_speed_mps",
        "max_speed_error_mps",
        "end_time_s",
        "end_reason",
        "message",
    ] {
        cols.push(c.to_string());
    }
    cols.join(",")
}

/// Quote a CSV field when it needs it.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// One summary.csv row.
pub fn summary_row(r: &RunRecord) -> String {
    let mut f = vec![run_folder(r.index), r.status.to_string()];
    f.extend(r.params.iter().map(|(_, v)| csv_field(v)));
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    match &r.summary {
        Some(s) => {
            f.push(s.passed.map_or(String::new(), |p| p.to_string()));
            f.push(s.cones_hit.to_string());
            f.push(s.peak_yaw_rate_radps.to_string());
            f.push(s.peak_sideslip_rad.to_string());
            f.push(s.peak_ay_mps2.to_string());
            f.push(opt(s.max_path_deviation_m));
            f.push(s.min_speed_mps.to_string());
            f.push(s.max_speed_mps.to_string());
            f.push(opt(s.max_speed_error_mps));
            f.push(s.end_time_s.to_string());
            f.push(s.end_reason.to_string());
        }
        None => f.extend(std::iter::repeat_n(String::new(), 11)),
    }
    f.push(csv_field(&r.message));
    f.join(",")
}

/// Options of a batch execution.
#[derive(Debug, Clone, Copy, Default)]
pub struct Options {
    /// Worker threads (`None`: all cores).
    pub jobs: Option<usize>,
    pub shard: Option<Shard>,
    /// Show a progress bar (only drawn on a terminal).
    pub progress: bool,
}

/// Result of [`execute`]: the folder written and the records in run order.
#[derive(Debug, Clone)]
pub struct BatchResult {
    pub dir: PathBuf,
    pub records: Vec<RunRecord>,
}

fn execute_one(run: &BatchRun, dir: Option<&Path>) -> Result<RunRecord> {
    let (status, summary, message) = match &run.config {
        Err(msg) => ("invalid", None, msg.clone()),
        Ok(cfg) => {
            let out: RunOutput = run::execute(cfg);
            if let Some(d) = dir {
                let rd = d.join(run_folder(run.index));
                crate::output::create_dir(&rd)?;
                run::write_run_files(&rd, cfg, &out, &run.params)?;
            }
            let status = if out.summary.failed() { "failed" } else { "ok" };
            (status, Some(out.summary), String::new())
        }
    };
    Ok(RunRecord { index: run.index, params: run.params.clone(), status, summary, message })
}

/// Summary-only mode (`[output] runs = false`): the course layout of each distinct vehicle, as
/// `layout.json` when the sweep has one vehicle, else `layout_<vehicle name>.json`.
fn write_layouts(dir: &Path, runs: &[&BatchRun]) -> Result<()> {
    let mut layouts: Vec<(String, serde_json::Value)> = Vec::new();
    for cfg in runs.iter().filter_map(|r| r.config.as_ref().ok()) {
        if layouts.iter().any(|(n, _)| *n == cfg.vehicle.name) {
            continue;
        }
        if let Some(l) = run::build_maneuver(cfg).layout() {
            layouts.push((cfg.vehicle.name.clone(), l));
        }
    }
    let single = layouts.len() == 1;
    for (name, layout) in &layouts {
        let file = if single {
            "layout.json".to_string()
        } else {
            let safe: String =
                name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
            format!("layout_{safe}.json")
        };
        let json = serde_json::to_string_pretty(layout).map_err(|e| Error::Run(format!("{file}: {e}")))?;
        write_atomic(&dir.join(file), (json + "\n").as_bytes())?;
    }
    Ok(())
}

/// Run the batch (or its shard) and write its folder under `out_root` atomically.
pub fn execute(batch: &Batch, out_root: &Path, opts: Options) -> Result<BatchResult> {
    let selected: Vec<&BatchRun> =
        batch.runs.iter().filter(|r| opts.shard.is_none_or(|s| s.contains(r.index))).collect();
    let folder = match opts.shard {
        Some(s) => s.folder(&batch.name),
        None => batch.name.clone(),
    };
    let dir = out_root.join(folder);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.unwrap_or(0))
        .build()
        .map_err(|e| Error::Run(format!("thread pool: {e}")))?;
    // Shown after a few seconds: a long single run or a sweep.
    let bar =
        crate::progress::Progress::with_display(selected.len(), "runs", opts.progress && crate::progress::enabled());
    let mut records = Vec::new();
    if !batch.is_sweep() {
        // A single run keeps the flat layout results/<name>/timeseries.csv.
        let run = &batch.runs[0];
        let cfg = run.config.as_ref().map_err(|e| Error::input(&batch.spec_file, e.clone()))?;
        let out = run::execute(cfg);
        check_interrupted(&dir)?;
        write_dir_atomic(&dir, |tmp| {
            run::write_run_files(tmp, cfg, &out, &[])?;
            if cfg.output.plots {
                crate::plot::runs::plot_results(tmp, tmp)?;
            }
            Ok(())
        })?;
        bar.inc();
        let status = if out.summary.failed() { "failed" } else { "ok" };
        records.push(RunRecord {
            index: 0,
            params: Vec::new(),
            status,
            summary: Some(out.summary),
            message: String::new(),
        });
    } else {
        let plots = batch.runs.iter().any(|r| r.config.as_ref().is_ok_and(|c| c.output.plots));
        let per_run = batch.runs.iter().any(|r| r.config.as_ref().is_ok_and(|c| c.output.runs));
        write_dir_atomic(&dir, |tmp| {
            if !per_run {
                write_layouts(tmp, &selected)?;
            }
            let run_dir = per_run.then_some(tmp);
            let recs: Vec<Result<RunRecord>> = pool.install(|| {
                selected
                    .par_iter()
                    .map(|r| {
                        check_interrupted(&dir)?;
                        let rec = execute_one(r, run_dir);
                        bar.inc();
                        rec
                    })
                    .collect()
            });
            check_interrupted(&dir)?;
            for r in recs {
                records.push(r?);
            }
            let mut csv = summary_header(&batch.keys);
            csv.push('\n');
            for r in &records {
                csv.push_str(&summary_row(r));
                csv.push('\n');
            }
            write_atomic(&tmp.join("summary.csv"), csv.as_bytes())?;
            if let Some(s) = opts.shard {
                let meta = serde_json::json!({"name": batch.name, "k": s.k, "n": s.n, "runs": batch.runs.len()});
                write_atomic(&tmp.join("shard.json"), format!("{meta}\n").as_bytes())?;
            } else if plots {
                crate::plot::runs::plot_batch(tmp, records.len(), &batch.name)?;
            }
            Ok(())
        })?;
    }
    drop(bar);
    Ok(BatchResult { dir, records })
}

/// Join shard folders (`<name>.shard-K-of-N`) into `<name>/` beside them, checking that they are
/// the complete, disjoint parts of one batch. The merged summary.csv is identical to the one an
/// unsharded run writes.
pub fn merge(shards: &[PathBuf]) -> Result<PathBuf> {
    let first = shards.first().ok_or_else(|| Error::Run("no shard folders given".into()))?;
    let mut name = None;
    let mut n_shards = None;
    let mut total = None;
    let mut seen_k = std::collections::BTreeSet::new();
    let mut header = None;
    let mut rows: Vec<(usize, String)> = Vec::new();
    for d in shards {
        let meta_path = d.join("shard.json");
        let meta: serde_json::Value = serde_json::from_str(&read_input(&meta_path)?)
            .map_err(|e| Error::input(&meta_path, format!("not a shard description: {e}")))?;
        let get = |k: &str| meta.get(k).cloned().unwrap_or(serde_json::Value::Null);
        let (nm, k, n, runs) = (get("name"), get("k").as_u64(), get("n").as_u64(), get("runs").as_u64());
        let (Some(nm), Some(k), Some(n), Some(runs)) = (nm.as_str().map(str::to_string), k, n, runs) else {
            return Err(Error::input(&meta_path, "expected name, k, n and runs"));
        };
        if name.get_or_insert(nm.clone()) != &nm
            || *n_shards.get_or_insert(n) != n
            || *total.get_or_insert(runs) != runs
        {
            return Err(Error::input(&meta_path, "shards of different batches cannot be merged"));
        }
        if !seen_k.insert(k) {
            return Err(Error::input(&meta_path, format!("shard {k} of {n} given twice")));
        }
        let csv_path = d.join("summary.csv");
        let text = read_input(&csv_path)?;
        let mut lines = text.lines();
        let h = lines.next().unwrap_or_default().to_string();
        if header.get_or_insert(h.clone()) != &h {
            return Err(Error::input(&csv_path, "summary columns differ between shards"));
        }
        for l in lines {
            let idx = l
                .split(',')
                .next()
                .and_then(|f| f.strip_prefix("run_"))
                .and_then(|f| f.parse::<usize>().ok())
                .ok_or_else(|| Error::input(&csv_path, format!("malformed row: {l}")))?;
            rows.push((idx, l.to_string()));
        }
    }
    let (name, n, total) = (name.unwrap_or_default(), n_shards.unwrap_or(0), total.unwrap_or(0) as usize);
    if seen_k.len() as u64 != n {
        let missing: Vec<String> = (1..=n).filter(|k| !seen_k.contains(k)).map(|k| k.to_string()).collect();
        return Err(Error::input(first, format!("incomplete: shard(s) {} of {n} missing", missing.join(", "))));
    }
    rows.sort_by_key(|r| r.0);
    if rows.len() != total || rows.iter().enumerate().any(|(i, r)| r.0 != i) {
        return Err(Error::input(
            first,
            format!("the shards hold {} runs, not the batch's {total} runs 0..{total}", rows.len()),
        ));
    }
    let parent = first.parent().unwrap_or_else(|| Path::new("."));
    let dest = parent.join(&name);
    write_dir_atomic(&dest, |tmp| {
        for d in shards {
            for e in std::fs::read_dir(d).map_err(|e| Error::Io { path: d.clone(), source: e })? {
                let e = e.map_err(|e| Error::Io { path: d.clone(), source: e })?;
                let fname = e.file_name();
                if fname.to_string_lossy().starts_with("run_") {
                    std::fs::rename(e.path(), tmp.join(&fname))
                        .map_err(|err| Error::Io { path: e.path(), source: err })?;
                }
            }
        }
        let mut csv = header.clone().unwrap_or_default();
        csv.push('\n');
        for (_, r) in &rows {
            csv.push_str(r);
            csv.push('\n');
        }
        write_atomic(&tmp.join("summary.csv"), csv.as_bytes())
    })?;
    for d in shards {
        let _ = std::fs::remove_dir_all(d);
    }
    Ok(dest)
}

/// A fixed-width table of the records for the terminal (at most `max_rows` rows).
pub fn table(keys: &[String], records: &[RunRecord], max_rows: usize) -> String {
    let mut lines = Vec::new();
    let mut head = vec!["run".to_string(), "status".to_string()];
    head.extend(keys.iter().cloned());
    head.extend([
        "end".into(),
        "passed".into(),
        "cones".into(),
        "peak r rad/s".into(),
        "peak beta deg".into(),
        "peak ay m/s2".into(),
    ]);
    lines.push(head);
    for r in records.iter().take(max_rows) {
        let mut l = vec![run_folder(r.index), r.status.to_string()];
        l.extend(r.params.iter().map(|p| p.1.clone()));
        match &r.summary {
            Some(s) => l.extend([
                s.end_reason.to_string(),
                s.passed.map_or("-".into(), |p| p.to_string()),
                s.cones_hit.to_string(),
                format!("{:.3}", s.peak_yaw_rate_radps),
                format!("{:.2}", s.peak_sideslip_rad.to_degrees()),
                format!("{:.2}", s.peak_ay_mps2),
            ]),
            None => l.extend(["-".into(), "-".into(), "-".into(), "-".into(), "-".into(), "-".into()]),
        }
        lines.push(l);
    }
    let widths: Vec<usize> =
        (0..lines[0].len()).map(|c| lines.iter().map(|l| l.get(c).map_or(0, |s| s.len())).max().unwrap_or(0)).collect();
    let mut out = String::new();
    for l in &lines {
        let cells: Vec<String> = l.iter().zip(&widths).map(|(s, w)| format!("{s:<w$}")).collect();
        out.push_str(cells.join("  ").trim_end());
        out.push('\n');
    }
    if records.len() > max_rows {
        out.push_str(&format!("... {} more runs (see summary.csv)\n", records.len() - max_rows));
    }
    out
}
