//! Batches: a manoeuvre spec with a `[sweep]` table expands into the full product of its lists;
//! the runs execute in parallel (rayon) and write `results/<name>/run_NNNN/` plus one
//! `summary.csv`. A run that fails (invalid combination, divergence, spin-out) is marked and
//! the others go on. `--shard K/N` runs the K-th of N disjoint parts (runs with index mod N = K-1)
//! into `results/<name>.shard-K-of-N/`; [`merge`] joins the parts into `results/<name>/`.
//!
//! Outputs are byte-identical whatever the thread count: every run is deterministic and the
//! summary is written in run order.
//!
//! The commands that drive batches live here too: `vehsim validate`, `vehsim run` and `vehsim merge`.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::output::write_atomic;
use crate::run::write_dir_atomic;
use vehsim_core::error::{Error, Result};
use vehsim_core::sim::Summary;
use vehsim_spec::files::read_input;
use vehsim_spec::run::{self, RunOutput};
pub use vehsim_spec::sweep::{batch_digest, Batch, BatchRun, RunStatus, MAX_RUNS};
use vehsim_spec::sweep::{from_table_with, sha256_hex};
use vehsim_spec::RunConfig;

/// `Err(Interrupted)` once SIGINT or SIGTERM was received: a batch checks it before each run and
/// a single run before it writes; the temporary folder is then removed, so a results folder is
/// either complete or left as it was before.
fn check_interrupted(dir: &Path) -> Result<()> {
    crate::output::signals::check(|| crate::output::replace::kept(dir))
}

/// Read a spec and expand its sweep ([`vehsim_spec::sweep::from_table_with`]), with progress on a
/// terminal and a stop on SIGINT or SIGTERM while a large sweep validates.
pub fn load(path: &Path) -> Result<Batch> {
    let text = read_input(path)?;
    from_text(path, &text)
}

/// As [`load`], for spec text already read from `path`.
pub fn from_text(path: &Path, text: &str) -> Result<Batch> {
    from_table(path, vehsim_spec::files::parse_toml(path, text)?)
}

/// As [`load`], for a spec already parsed into a TOML table.
pub fn from_table(path: &Path, table: toml::Table) -> Result<Batch> {
    let mut checked: Option<crate::progress::Progress> = None;
    from_table_with(path, table, &mut |_, total| {
        crate::output::signals::check(|| format!("stopped while validating {}; nothing written", path.display()))?;
        checked.get_or_insert_with(|| crate::progress::Progress::new(total, "combinations checked")).inc();
        Ok(())
    })
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

/// What happened to one run of a batch.
#[derive(Debug, Clone)]
pub struct RunRecord {
    pub index: usize,
    pub params: Vec<(String, String)>,
    pub status: RunStatus,
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
        "plausible",
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
            f.push(s.plausible.to_string());
        }
        None => f.extend(std::iter::repeat_n(String::new(), 12)),
    }
    f.push(csv_field(&r.message));
    f.join(",")
}

/// Most integration steps (summed over the runs) a call may ask for without `--force`: about
/// half an hour of one core at the engine's roughly 0.5-1 million steps per second.
pub const MAX_STEPS: f64 = 1e9;

/// Most bytes of output a call may write without `--force` (also never more than the free space).
pub const MAX_OUTPUT_BYTES: f64 = 10e9;

/// Most integration steps one run may take without `--force`. A car manoeuvre at the default
/// step needs well under 1e6 (the longest allowed, 3600 s at 5 ms, 7.2e5); above 1e7 (about 10 s
/// to a minute of one core, more for the 4-DOF model) the step has been driven down by an input
/// (a stiffness, an inertia, a tiny `step_s`) and the run would take minutes.
pub const MAX_RUN_STEPS: f64 = 1e7;

/// Bytes of one timeseries.csv row (32 columns of shortest round-trip decimals), for estimates.
const ROW_BYTES: f64 = 600.0;

/// Bytes of one set of standard plots (PNG and SVG of each chart; 1.7 MB measured for one run)
/// and what each further overlaid run adds to it.
const PLOT_SET_BYTES: f64 = 1.8e6;
const PLOT_BYTES_PER_RUN: f64 = 50e3;

/// Estimated work and output of the runs of `batch` selected by `shard`: (steps, bytes), plots
/// included.
pub fn estimate(batch: &Batch, shard: Option<Shard>) -> (f64, f64) {
    let mut steps = 0.0;
    let mut bytes = 0.0;
    let mut plotted = 0.0_f64;
    for cfg in
        batch.runs.iter().filter(|r| shard.is_none_or(|s| s.contains(r.index))).filter_map(|r| r.config.as_ref().ok())
    {
        let s = &cfg.settings;
        steps += (s.duration_s / s.step_s).ceil();
        bytes += 4096.0;
        if cfg.output.timeseries {
            bytes += ROW_BYTES * ((s.duration_s / s.output_interval_s).floor() + 1.0);
            if cfg.output.plots {
                plotted += 1.0;
            }
        }
    }
    if plotted > 0.0 && shard.is_none() {
        bytes += PLOT_SET_BYTES + PLOT_BYTES_PER_RUN * (plotted - 1.0).min(crate::plot::runs::MAX_OVERLAID_RUNS as f64);
    }
    (steps, bytes)
}

/// A byte count in the unit that suits it: `512 B`, `12.3 kB`, `1.7 MB`, `2.40 GB` (SI units).
pub fn human_bytes(b: f64) -> String {
    if b < 1e3 {
        format!("{b:.0} B")
    } else if b < 1e6 {
        format!("{:.1} kB", b / 1e3)
    } else if b < 1e9 {
        format!("{:.1} MB", b / 1e6)
    } else {
        format!("{:.2} GB", b / 1e9)
    }
}

/// Free bytes on the file system holding `dir` (or its nearest existing ancestor).
pub fn free_bytes(dir: &Path) -> Option<f64> {
    use std::os::unix::ffi::OsStrExt;
    let mut d = dir.to_path_buf();
    while !d.exists() {
        d = d.parent().filter(|p| !p.as_os_str().is_empty()).map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    }
    let c = std::ffi::CString::new(d.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs writes into the zeroed struct we own; the path is NUL-terminated.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::statvfs(c.as_ptr(), &mut st) };
    (r == 0).then_some(st.f_bavail as f64 * st.f_frsize as f64)
}

/// Unless `force`, refuse a workload above [`MAX_STEPS`] or [`MAX_OUTPUT_BYTES`], or a run above
/// [`MAX_RUN_STEPS`] (exit 2), or one whose output would not fit the free space under `out_root`
/// (exit 3), with the estimate.
pub fn check_limits(batch: &Batch, shard: Option<Shard>, out_root: &Path, force: bool) -> Result<()> {
    if !force {
        let longest = batch
            .runs
            .iter()
            .filter(|r| shard.is_none_or(|s| s.contains(r.index)))
            .filter_map(|r| r.config.as_ref().ok().map(|c| (r, c)))
            .map(|(r, c)| (r, c, (c.settings.duration_s / c.settings.step_s).ceil()))
            .fold(None, |m: Option<(&BatchRun, &RunConfig, f64)>, x| match m {
                Some(m) if m.2 >= x.2 => Some(m),
                _ => Some(x),
            });
        if let Some((run, cfg, steps)) = longest.filter(|l| l.2 > MAX_RUN_STEPS) {
            let which = if batch.is_sweep() { format!("{}: ", run_folder(run.index)) } else { String::new() };
            return Err(Error::input(
                &batch.spec_file,
                format!(
                    "{which}estimated {} integration steps in one run (step {} s over {} s), above the {} a run may \
                     take without --force: it would run for minutes. A car manoeuvre needs under 1e6; a step this \
                     short comes from integrator.step_s or from the vehicle's fastest mode (its tyre stiffnesses \
                     and wheel inertia in {}). Use --force to run it anyway",
                    vehsim_core::error::short_num(steps),
                    vehsim_core::error::short_num(cfg.settings.step_s),
                    crate::output::num::Sig(cfg.settings.duration_s),
                    vehsim_core::error::short_num(MAX_RUN_STEPS),
                    cfg.vehicle_file.display()
                ),
            ));
        }
    }
    let (steps, bytes) = estimate(batch, shard);
    let what = format!(
        "estimated {} integration steps and {} of output",
        vehsim_core::error::short_num(steps),
        human_bytes(bytes)
    );
    if !force && (steps > MAX_STEPS || bytes > MAX_OUTPUT_BYTES) {
        return Err(Error::input(
            &batch.spec_file,
            format!(
                "{what}; above the limits of {MAX_STEPS:.0e} steps and {} (a larger step_s, fewer runs, \
                 --shard, or --force to run it anyway)",
                human_bytes(MAX_OUTPUT_BYTES)
            ),
        ));
    }
    if let Some(free) = free_bytes(out_root).filter(|f| !force && bytes > *f) {
        return Err(Error::Io {
            path: out_root.to_path_buf(),
            source: std::io::Error::other(format!("{what}, but only {} free there", human_bytes(free))),
        });
    }
    Ok(())
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
        Err(msg) => (RunStatus::Invalid, None, msg.clone()),
        Ok(cfg) => {
            let out: RunOutput = run::execute(cfg);
            if let Some(d) = dir {
                let rd = d.join(run_folder(run.index));
                crate::output::create_dir(&rd)?;
                crate::run::write_run_files(&rd, cfg, &out, &run.params)?;
            }
            (RunStatus::of(&out.summary), Some(out.summary), String::new())
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
        // Named for the signal handler's one line while the run itself (no check point) goes on.
        let _pending = crate::output::signals::Temp::register(&crate::output::temp_path(&dir), &dir);
        let out = run::execute(cfg);
        check_interrupted(&dir)?;
        write_dir_atomic(&dir, |tmp| {
            crate::run::write_run_files(tmp, cfg, &out, &[])?;
            if cfg.output.plots {
                crate::plot::runs::plot_results(tmp, tmp)?;
            }
            Ok(())
        })?;
        bar.inc();
        records.push(RunRecord {
            index: 0,
            params: Vec::new(),
            status: RunStatus::of(&out.summary),
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
                let mut files = serde_json::Map::new();
                for r in &records {
                    digest_files(tmp, &run_folder(r.index), &mut files)?;
                }
                let meta = serde_json::json!({
                    "name": batch.name,
                    "k": s.k,
                    "n": s.n,
                    "runs": batch.runs.len(),
                    "plots": plots,
                    "vehsim": env!("CARGO_PKG_VERSION"),
                    "batch_digest": batch_digest(batch)?,
                    "files": files,
                });
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

/// Add the SHA-256 of every file under `root/rel` to `out`, keyed by its path relative to `root`
/// (with `/`), in name order.
fn digest_files(root: &Path, rel: &str, out: &mut serde_json::Map<String, serde_json::Value>) -> Result<()> {
    let dir = root.join(rel);
    if !dir.is_dir() {
        return Ok(());
    }
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .map_err(io_err(&dir))?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()).map_err(io_err(&dir)))
        .collect::<Result<_>>()?;
    names.sort();
    for n in names {
        let (p, key) = (dir.join(&n), format!("{rel}/{n}"));
        let m = std::fs::symlink_metadata(&p).map_err(io_err(&p))?;
        if m.is_dir() {
            digest_files(root, &key, out)?;
        } else {
            let bytes = std::fs::read(&p).map_err(io_err(&p))?;
            out.insert(key, serde_json::Value::String(sha256_hex(&bytes)));
        }
    }
    Ok(())
}

/// One shard folder as read and checked by [`merge`].
struct ShardPart {
    dir: PathBuf,
    name: String,
    /// k, n and the batch's number of runs, from shard.json.
    k_n_runs: (u64, u64, u64),
    /// The batch's digest ([`batch_digest`]) and the vehsim version that wrote the shard.
    digest: String,
    version: String,
    plots: bool,
    /// summary.csv header.
    header: String,
    /// (run index, summary.csv row, has a run folder)
    rows: Vec<(usize, String, bool)>,
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::Io { path: path.to_path_buf(), source: e }
}

/// Read and check one shard folder: its shard.json (name validated as a spec name, the folder
/// named after it), its summary.csv rows (each of this shard, each ok/failed run with its folder,
/// no run folder the summary does not list).
fn read_shard(d: &Path) -> Result<ShardPart> {
    let meta_path = d.join("shard.json");
    if !std::fs::metadata(d).is_ok_and(|m| m.is_dir()) {
        return Err(Error::input(
            d,
            "not a shard folder: no such folder (shards are written by `vehsim run --shard K/N`)",
        ));
    }
    if !meta_path.exists() {
        return Err(Error::input(
            d,
            "not a shard folder: it has no shard.json (`vehsim run --shard K/N` writes each part into \
             <name>.shard-K-of-N/, and merge takes those folders)",
        ));
    }
    let meta: serde_json::Value = serde_json::from_str(&read_input(&meta_path)?)
        .map_err(|e| Error::input(&meta_path, format!("not a shard description: {e}")))?;
    let get = |k: &str| meta.get(k).cloned().unwrap_or(serde_json::Value::Null);
    let (nm, k, n, runs) = (get("name"), get("k").as_u64(), get("n").as_u64(), get("runs").as_u64());
    let (Some(name), Some(k), Some(n), Some(runs)) = (nm.as_str().map(str::to_string), k, n, runs) else {
        return Err(Error::input(&meta_path, "expected name, k, n and runs"));
    };
    if !vehsim_spec::maneuver::valid_name(&name) {
        return Err(Error::key(
            &meta_path,
            "name",
            "not a usable folder name; use 1-100 letters, digits, '_', '-', '.', not starting with '.'",
        ));
    }
    if n == 0 || k == 0 || k > n || runs > MAX_RUNS as u64 {
        return Err(Error::input(
            &meta_path,
            format!("k = {k}, n = {n}, runs = {runs}: expected 1 <= k <= n, runs <= {MAX_RUNS}"),
        ));
    }
    let expected = Shard { k: k as usize, n: n as usize }.folder(&name);
    if d.file_name().map(|f| f.to_string_lossy() != expected).unwrap_or(true) {
        return Err(Error::input(d, format!("folder name does not match its shard.json (expected '{expected}')")));
    }
    let plots = meta.get("plots").and_then(|p| p.as_bool()).unwrap_or(true);
    let (Some(digest), Some(version), Some(files)) = (
        meta.get("batch_digest").and_then(|v| v.as_str()),
        meta.get("vehsim").and_then(|v| v.as_str()),
        meta.get("files").and_then(|v| v.as_object()),
    ) else {
        return Err(Error::input(
            &meta_path,
            "no batch_digest, vehsim version or file digests: written by an older vehsim, which merge cannot \
             check; run the shard again",
        ));
    };
    let csv_path = d.join("summary.csv");
    let text = read_input(&csv_path)?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default().to_string();
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        let malformed = || Error::input(&csv_path, format!("line {}: not a summary row", i + 2));
        let mut fields = l.splitn(3, ',');
        let idx = fields
            .next()
            .and_then(|f| f.strip_prefix("run_"))
            .and_then(|f| f.parse::<usize>().ok())
            .ok_or_else(malformed)?;
        let status = fields.next().ok_or_else(malformed)?;
        if idx as u64 >= runs || idx % n as usize != k as usize - 1 {
            return Err(Error::input(
                &csv_path,
                format!("line {}: run {idx} does not belong to shard {k} of {n}", i + 2),
            ));
        }
        let has_folder = RunStatus::parse(status).is_some_and(RunStatus::ran);
        if has_folder {
            let rd = d.join(run_folder(idx));
            let real_dir = std::fs::symlink_metadata(&rd).is_ok_and(|m| m.is_dir());
            if !real_dir || !rd.join("summary.json").is_file() {
                return Err(Error::input(
                    d,
                    format!("incomplete shard: {} is missing or has no summary.json", run_folder(idx)),
                ));
            }
        }
        if has_folder {
            // Every file of the run as the shard wrote it: none missing, none added, none changed.
            let mut found = serde_json::Map::new();
            digest_files(d, &run_folder(idx), &mut found)?;
            let prefix = format!("{}/", run_folder(idx));
            let listed = files.iter().filter(|(k, _)| k.starts_with(&prefix));
            for (f, want) in listed.clone() {
                match found.get(f) {
                    None => {
                        return Err(Error::input(d, format!("incomplete shard: {f} is missing (listed in shard.json)")))
                    }
                    Some(got) if got != want => {
                        return Err(Error::input(
                            d,
                            format!(
                                "{f} is truncated or changed since the shard was written (its SHA-256 differs \
                                 from shard.json's); run the shard again"
                            ),
                        ))
                    }
                    Some(_) => {}
                }
            }
            if let Some(extra) = found.keys().find(|f| !files.contains_key(*f)) {
                return Err(Error::input(d, format!("{extra} was not written by the shard (not in shard.json)")));
            }
            if listed.count() == 0 {
                return Err(Error::input(d, format!("shard.json lists no files of {}", run_folder(idx))));
            }
        }
        rows.push((idx, l.to_string(), has_folder));
    }
    for e in std::fs::read_dir(d).map_err(io_err(d))? {
        let f = e.map_err(io_err(d))?.file_name().to_string_lossy().into_owned();
        if f.starts_with("run_") && !rows.iter().any(|r| r.2 && run_folder(r.0) == f) {
            return Err(Error::input(d, format!("{f} is not listed in summary.csv")));
        }
    }
    Ok(ShardPart {
        dir: d.to_path_buf(),
        name,
        k_n_runs: (k, n, runs),
        digest: digest.to_string(),
        version: version.to_string(),
        plots,
        header,
        rows,
    })
}

/// Copy the folder `src` to `dst` (which must not exist), refusing symlinks; every file's length
/// is checked after the copy, and with `verify` its bytes too.
fn copy_tree(src: &Path, dst: &Path, verify: bool) -> Result<()> {
    std::fs::create_dir(dst).map_err(io_err(dst))?;
    for e in std::fs::read_dir(src).map_err(io_err(src))? {
        let e = e.map_err(io_err(src))?;
        let (from, to) = (e.path(), dst.join(e.file_name()));
        let m = std::fs::symlink_metadata(&from).map_err(io_err(&from))?;
        if m.is_dir() {
            copy_tree(&from, &to, verify)?;
        } else if m.is_file() {
            let n = std::fs::copy(&from, &to).map_err(io_err(&to))?;
            let same = n == m.len()
                && (!verify
                    || std::fs::read(&from).map_err(io_err(&from))? == std::fs::read(&to).map_err(io_err(&to))?);
            if !same {
                return Err(Error::Io { path: to, source: std::io::Error::other("copy differs from its source") });
            }
        } else {
            return Err(Error::input(&from, "not a plain file or folder (a symlink?); shards hold only files"));
        }
        crate::output::signals::check(|| "the merged folder was not written".to_string())?;
    }
    Ok(())
}

/// Join shard folders (`<name>.shard-K-of-N`) into `<name>/` beside the first, checking that they
/// are the complete, disjoint parts of one batch, each complete. Run folders are copied (so the
/// shards may sit on other file systems) and the merged folder replaces `<name>/` atomically, with
/// its plots. The shards are kept unless `remove_shards`, in which case every copied file is
/// compared byte for byte with its source before the shards are removed. The merged summary.csv
/// is identical to the one an unsharded run writes.
pub fn merge(shards: &[PathBuf], remove_shards: bool) -> Result<PathBuf> {
    let first = shards.first().ok_or_else(|| Error::Run("no shard folders given".into()))?;
    let mut batch = None;
    let mut header = None;
    let mut seen_k = std::collections::BTreeSet::new();
    let mut parts = Vec::new();
    let mut plots = true;
    let mut identity: Option<(PathBuf, String, String)> = None;
    for d in shards {
        let part = read_shard(d)?;
        let (name, (k, n, runs), p, h) = (part.name.clone(), part.k_n_runs, part.plots, part.header.clone());
        let meta_path = d.join("shard.json");
        if *batch.get_or_insert((name.clone(), n, runs)) != (name, n, runs) {
            return Err(Error::input(&meta_path, "shards of different batches cannot be merged"));
        }
        let (first_dir, first_digest, first_version) =
            identity.get_or_insert((d.clone(), part.digest.clone(), part.version.clone()));
        if *first_digest != part.digest {
            let why = if *first_version != part.version {
                format!("written by vehsim {} and {}", first_version, part.version)
            } else {
                "their spec, or the vehicle, tyre or .tir files it names, differ".to_string()
            };
            return Err(Error::input(
                d,
                format!(
                    "this shard and {} belong to different batches ({why}: batch_digest differs in shard.json); \
                     a merged batch would mix them",
                    first_dir.display()
                ),
            ));
        }
        if !seen_k.insert(k) {
            return Err(Error::input(&meta_path, format!("shard {k} of {n} given twice")));
        }
        if header.get_or_insert(h.clone()) != &h {
            return Err(Error::input(&d.join("summary.csv"), "summary columns differ between shards"));
        }
        plots &= p;
        parts.push(part);
    }
    let (name, n, total) = batch.unwrap_or_default();
    let total = total as usize;
    if seen_k.len() as u64 != n {
        let missing: Vec<String> = (1..=n).filter(|k| !seen_k.contains(k)).map(|k| k.to_string()).collect();
        return Err(Error::input(first, format!("incomplete: shard(s) {} of {n} missing", missing.join(", "))));
    }
    let mut rows: Vec<(usize, &str, &Path, bool)> =
        parts.iter().flat_map(|p| p.rows.iter().map(|r| (r.0, r.1.as_str(), p.dir.as_path(), r.2))).collect();
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
        for (idx, _, dir, has_folder) in &rows {
            if *has_folder {
                copy_tree(&dir.join(run_folder(*idx)), &tmp.join(run_folder(*idx)), remove_shards)?;
            }
        }
        let mut csv = header.clone().unwrap_or_default();
        csv.push('\n');
        for (_, r, _, _) in &rows {
            csv.push_str(r);
            csv.push('\n');
        }
        write_atomic(&tmp.join("summary.csv"), csv.as_bytes())?;
        if plots && total <= crate::plot::runs::MAX_OVERLAID_RUNS && rows.iter().any(|r| r.3) {
            crate::plot::runs::plot_results(tmp, tmp)?;
        }
        Ok(())
    })?;
    if remove_shards {
        for d in shards {
            std::fs::remove_dir_all(d).map_err(io_err(d))?;
        }
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
        "plausible".into(),
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
                if s.plausible { "yes".into() } else { "NO".into() },
            ]),
            None => l.extend(std::iter::repeat_n("-".to_string(), 7)),
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

// ---- Command line: `vehsim validate`, `vehsim run`, `vehsim merge` ----

/// `vehsim validate`: check every file (each error printed as it is found, the next file still
/// checked); exit 2 when any file or combination is invalid.
pub(crate) fn cli_validate(files: &[PathBuf], quiet: bool) -> Result<std::process::ExitCode> {
    use crate::output::num::Sig;
    use std::process::ExitCode;
    crate::progress::set_quiet(quiet);
    let mut code = ExitCode::SUCCESS;
    for f in files {
        let b = match load(f) {
            Ok(b) => b,
            Err(e) => {
                code = crate::output::signals::report(&e);
                continue;
            }
        };
        let mut invalid = 0;
        let mut long_warned = false;
        for r in &b.runs {
            match &r.config {
                Ok(cfg) => {
                    for w in &cfg.vehicle.tyre_warnings {
                        eprintln!("warning: {w}");
                    }
                    let steps = (cfg.settings.duration_s / cfg.settings.step_s).ceil();
                    if steps > MAX_RUN_STEPS && !long_warned {
                        long_warned = true;
                        let which = if b.is_sweep() {
                            format!(" {} (the first such run)", run_folder(r.index))
                        } else {
                            String::new()
                        };
                        eprintln!(
                            "warning: {}{which}: {} integration steps (step {} s): minutes of work; `vehsim run` \
                             refuses it without --force",
                            f.display(),
                            vehsim_core::error::short_num(steps),
                            vehsim_core::error::short_num(cfg.settings.step_s)
                        );
                    }
                }
                Err(msg) => {
                    invalid += 1;
                    eprintln!("error: {} {}: {msg}", f.display(), run_folder(r.index));
                }
            }
        }
        if invalid > 0 {
            code = ExitCode::from(2);
        } else if let Some(Ok(cfg)) = b.runs.first().map(|r| &r.config) {
            println!(
                "{}: ok ({} run{}; {} with {} on mu {}, tyre model {}, vehicle model {})",
                f.display(),
                b.runs.len(),
                if b.runs.len() == 1 { "" } else { "s" },
                cfg.kind,
                cfg.vehicle.name,
                Sig(cfg.env.mu),
                cfg.tyre_model.as_str(),
                cfg.vehicle_model.as_str()
            );
        }
    }
    Ok(code)
}

/// `--jobs`: at least 1 thread, and without `force` at most 4 per core.
pub(crate) fn check_jobs(jobs: Option<usize>, force: bool) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    match jobs {
        Some(0) => Err(Error::usage("--jobs", "expected at least 1 thread")),
        Some(j) if j > 4 * cores && !force => {
            Err(Error::usage("--jobs", format!("{j} threads; at most 4 x {cores} cores = {} (or --force)", 4 * cores)))
        }
        _ => Ok(()),
    }
}

/// The `vehsim run` flags besides the spec files.
#[derive(Debug, Clone)]
pub(crate) struct RunFlags {
    pub out: PathBuf,
    pub jobs: Option<usize>,
    pub shard: Option<Shard>,
    pub quiet: bool,
    pub force: bool,
}

/// `vehsim run`: load every spec and check names, threads and limits before anything runs; then run
/// each batch and print its table (or the single run's line). Exit 2 when a combination is
/// invalid, else 1 when a run failed.
pub(crate) fn cli_run(files: &[PathBuf], flags: &RunFlags) -> Result<std::process::ExitCode> {
    use std::process::ExitCode;
    let RunFlags { ref out, jobs, shard, quiet, force } = *flags;
    crate::progress::set_quiet(quiet);
    let batches = files.iter().map(|f| load(f)).collect::<Result<Vec<_>>>()?;
    let mut warned = std::collections::BTreeSet::new();
    for w in batches
        .iter()
        .flat_map(|b| &b.runs)
        .filter_map(|r| r.config.as_ref().ok())
        .flat_map(|c| &c.vehicle.tyre_warnings)
    {
        if warned.insert(w.clone()) {
            eprintln!("warning: {w}");
        }
    }
    let mut names = std::collections::BTreeSet::new();
    for b in &batches {
        if !names.insert(b.name.clone()) {
            return Err(Error::key(
                &b.spec_file,
                "name",
                format!("'{}' is used by more than one spec in this call; results would overwrite each other", b.name),
            ));
        }
    }
    check_jobs(jobs, force)?;
    for b in &batches {
        check_limits(b, shard, out, force)?;
    }
    let mut code = ExitCode::SUCCESS;
    for b in &batches {
        let result = execute(b, out, Options { jobs, shard, progress: !quiet })?;
        if result.records.iter().any(|r| r.status == RunStatus::Invalid) {
            code = ExitCode::from(2);
        } else if result.records.iter().any(|r| r.status != RunStatus::Ok) && code == ExitCode::SUCCESS {
            code = ExitCode::from(1);
        }
        for r in result.records.iter().filter(|r| r.status == RunStatus::Invalid) {
            eprintln!("error: {} {}: invalid: {}", b.name, run_folder(r.index), r.message);
        }
        if quiet {
            for r in result.records.iter().filter(|r| r.status == RunStatus::Failed) {
                eprintln!("{} {}: {} {}", b.name, run_folder(r.index), r.status, r.message);
            }
        } else if b.is_sweep() {
            println!("{}: {} runs -> {}", b.name, result.records.len(), result.dir.display());
            print!("{}", table(&b.keys, &result.records, 40));
        } else if let Some(s) = result.records.first().and_then(|r| r.summary.as_ref()) {
            println!("{}", crate::run::summary_line(&b.name, s, &result.dir));
            for r in &s.implausible {
                println!("  implausible: {r}");
            }
        }
    }
    Ok(code)
}

/// `vehsim merge`: join the shard folders and print where the batch went.
pub(crate) fn cli_merge(shards: &[PathBuf], remove_shards: bool) -> Result<std::process::ExitCode> {
    let d = merge(shards, remove_shards)?;
    println!("merged {} shards -> {}", shards.len(), d.display());
    Ok(std::process::ExitCode::SUCCESS)
}
