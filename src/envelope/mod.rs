//! `vehsim envelope SPEC`: the limit a manoeuvre spec's vehicle reaches, for every combination of
//! the spec's `[sweep]` (and for each `[[envelope.reference]]`), in parallel; writes
//! `<out>/<name>/envelope.csv` and the plot `plots/envelope.png/.svg` atomically.
//!
//! - ISO 3888-2: the highest entry speed (`maneuver.speed_mps`, m/s) at which the course is cleared.
//!   A run passes when it completes the course (no spin-out or divergence) with no cone boundary
//!   struck. The speeds from `speed_min_mps` to `speed_max_mps` in steps of `scan_step_mps` are all
//!   run (the bracketing); between the highest passing scan speed and the failing one above it the
//!   limit is bisected until the bracket is no wider than `tolerance_mps` (default 0.05 m/s). The
//!   reported speed is the bracket's passing end. A failure below the highest pass (a non-monotone
//!   outcome) is reported with the lowest such speed; bisection assumes one change inside a scan
//!   step.
//! - Constant radius: one stepped run; the highest mean |a_y| (m/s^2) over the steady windows
//!   ([`vehsim_core::sim::steady_state`]) and, as the bracket's upper end, the nominal v^2 / R of the
//!   first step that was not steady (or not reached): the resolution is the spec's a_y step. Its
//!   `plausible` is false only when a tyre force or a_y passed the friction bound (leaving the
//!   circle and unsteady steps above the limit are how such a run ends).
//!
//! Each combination is searched on one thread; the combinations run on a pool of `--jobs` threads
//! and are written in sweep order, so the output is the same whatever the thread count.
//!
//! Spec keys (`[envelope]`): `speed_min_mps`, `speed_max_mps` (required for ISO 3888-2, 0 < min <
//! max), `scan_step_mps` (default 1, > 0), `tolerance_mps` (default 0.05, > 0); each
//! `[[envelope.reference]]` has a `label` and a `set` table of dotted spec keys to values applied to
//! the spec without its sweep (drawn as a horizontal line).

mod chart;

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Deserialize;

use crate::batch;
use crate::output::write_atomic;
use crate::run::write_dir_atomic;
use vehsim_core::error::{Error, Result};
use vehsim_core::event::EndReason;
use vehsim_spec::files::{parse_toml, read_input};
use vehsim_spec::maneuver::{ManeuverConfig, ManeuverKind};
use vehsim_spec::run;
use vehsim_spec::sweep::{self, set_path};
use vehsim_spec::RunConfig;

/// The swept key the ISO 3888-2 search sets.
pub const SPEED_KEY: &str = "maneuver.speed_mps";

/// `[envelope]` as written.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSettings {
    speed_min_mps: Option<f64>,
    speed_max_mps: Option<f64>,
    scan_step_mps: Option<f64>,
    tolerance_mps: Option<f64>,
    #[serde(default)]
    reference: Vec<RawReference>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawReference {
    label: String,
    set: toml::Table,
}

/// What the envelope measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// ISO 3888-2: highest passing entry speed, m/s.
    Speed,
    /// Constant radius: highest steady lateral acceleration, m/s^2.
    LateralAcceleration,
}

/// Validated search settings of the speed envelope, m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedSearch {
    pub min_mps: f64,
    pub max_mps: f64,
    pub scan_step_mps: f64,
    pub tolerance_mps: f64,
}

/// One trial's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Trial {
    pub pass: bool,
    pub plausible: bool,
}

/// The limit of one combination (or reference).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Limit {
    /// Highest value found to pass (speed, m/s; or steady a_y, m/s^2); `None`: nothing passed.
    pub value: Option<f64>,
    /// Lowest value found to fail above it (`None`: no failure up to the search's top).
    pub fail_above: Option<f64>,
    /// Lowest value found to fail below `value` (a non-monotone outcome).
    pub fail_below: Option<f64>,
    /// Runs used.
    pub runs: usize,
    /// Whether the run at `value` was plausible.
    pub plausible: Option<bool>,
    /// Why there is no value, or what is special about it.
    pub note: String,
}

/// Search the highest passing speed with `trial` (see the module docs for the procedure).
pub fn search_speed(s: &SpeedSearch, mut trial: impl FnMut(f64) -> Result<Trial>) -> Result<Limit> {
    let n = ((s.max_mps - s.min_mps) / s.scan_step_mps - 1e-9).ceil().max(0.0) as usize;
    let grid: Vec<f64> = (0..=n).map(|i| (s.min_mps + i as f64 * s.scan_step_mps).min(s.max_mps)).collect();
    let mut out = Limit::default();
    let mut results = Vec::with_capacity(grid.len());
    for &v in &grid {
        results.push(trial(v)?);
    }
    out.runs = grid.len();
    let Some(ip) = results.iter().rposition(|t| t.pass) else {
        out.fail_above = Some(grid[0]);
        out.note = format!("fails at every speed from {} to {} m/s", s.min_mps, s.max_mps);
        return Ok(out);
    };
    out.fail_below = grid[..ip].iter().zip(&results).find(|(_, t)| !t.pass).map(|(v, _)| *v);
    let (mut lo, mut lo_trial) = (grid[ip], results[ip]);
    if ip + 1 < grid.len() {
        let mut hi = grid[ip + 1];
        while hi - lo > s.tolerance_mps {
            let mid = 0.5 * (lo + hi);
            let t = trial(mid)?;
            out.runs += 1;
            if t.pass {
                (lo, lo_trial) = (mid, t);
            } else {
                hi = mid;
            }
        }
        out.fail_above = Some(hi);
    } else {
        out.note = format!("passes at the top of the search ({} m/s): the limit is higher", s.max_mps);
    }
    if let Some(fb) = out.fail_below {
        let sep = if out.note.is_empty() { "" } else { "; " };
        out.note = format!("{}{sep}non-monotone: fails at {fb} m/s, below the highest pass", out.note);
    }
    out.value = Some(lo);
    out.plausible = Some(lo_trial.plausible);
    Ok(out)
}

/// The steady lateral-acceleration limit of one constant-radius run.
fn steady_limit(cfg: &RunConfig) -> Limit {
    let out = run::execute(cfg);
    let ManeuverConfig::ConstantRadius(p) = &cfg.maneuver else { return Limit::default() };
    let nominal: Vec<f64> = p.step_speeds_mps.iter().map(|v| v * v / p.radius_m).collect();
    let steady_at = |step: usize| out.steady_states.iter().any(|s| s.step == step && s.steady);
    // The run ends by leaving the circle or with unsteady steps by design; what makes its limit
    // implausible is a tyre force or a_y beyond friction.
    let beyond = out.summary.events.iter().any(|e| e.kind.beyond_friction());
    let mut limit = Limit { runs: 1, plausible: Some(!beyond), ..Limit::default() };
    limit.value = out.steady_states.iter().filter(|s| s.steady).map(|s| s.ay_mps2.abs()).reduce(f64::max);
    let top_step = out.steady_states.iter().filter(|s| s.steady).map(|s| s.step).max().unwrap_or(0);
    limit.fail_above = (top_step + 1..=nominal.len()).find(|&k| !steady_at(k)).map(|k| nominal[k - 1]);
    limit.fail_below = (1..top_step).find(|&k| !steady_at(k)).map(|k| nominal[k - 1]);
    limit.note = match (limit.value, limit.fail_below) {
        (None, _) => "no steady window".into(),
        (Some(_), Some(f)) => format!("non-monotone: the step at nominal a_y {f:.3} m/s^2 is not steady"),
        _ if limit.fail_above.is_none() => "every step steady: the limit is higher".into(),
        _ => String::new(),
    };
    limit
}

/// One job: a sweep combination or a reference, as a spec table without a sweep.
#[derive(Debug, Clone)]
struct Job {
    label: String,
    params: Vec<String>,
    table: toml::Table,
}

/// A loaded envelope spec.
#[derive(Debug, Clone)]
pub struct Envelope {
    pub name: String,
    pub spec_file: PathBuf,
    pub kind: Kind,
    pub search: Option<SpeedSearch>,
    /// Swept keys in nesting order.
    pub keys: Vec<String>,
    jobs: Vec<Job>,
}

/// One row of envelope.csv.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Reference label (empty for a sweep combination).
    pub label: String,
    /// Swept values as text (empty for a reference).
    pub params: Vec<String>,
    pub limit: Limit,
}

/// Load and check an envelope spec (every bad input is an [`Error::Input`] naming the key).
pub fn load(path: &Path) -> Result<Envelope> {
    let mut table: toml::Table = parse_toml(path, &read_input(path)?)?;
    let raw: RawSettings = match table.remove("envelope") {
        None => RawSettings::default(),
        Some(v) => serde_path_to_error::deserialize::<_, RawSettings>(v).map_err(|e| {
            let at = e.path().to_string();
            let key = if at.is_empty() || at == "." { "envelope".to_string() } else { format!("envelope.{at}") };
            Error::key(path, &key, e.into_inner().to_string().trim_end())
        })?,
    };
    let kind_name = table.get("maneuver").and_then(|m| m.get("kind")).and_then(|k| k.as_str()).unwrap_or("");
    let kind = match ManeuverKind::parse(kind_name) {
        Some(ManeuverKind::Iso3888_2) => Kind::Speed,
        Some(ManeuverKind::ConstantRadius) => Kind::LateralAcceleration,
        _ => {
            return Err(Error::key(
                path,
                "maneuver.kind",
                format!(
                    "'{kind_name}' has neither a pass rule nor a steady-state measure; envelope needs iso3888_2 \
                     (highest passing speed) or constant_radius (highest steady lateral acceleration)"
                ),
            ))
        }
    };
    let search = match kind {
        Kind::Speed => Some(speed_search(path, &raw)?),
        Kind::LateralAcceleration => {
            for (k, v) in [("speed_min_mps", raw.speed_min_mps), ("speed_max_mps", raw.speed_max_mps)] {
                if v.is_some() {
                    return Err(Error::key(path, &format!("envelope.{k}"), "only for iso3888_2; remove it"));
                }
            }
            None
        }
    };
    let sweep = match table.remove("sweep") {
        None => toml::Table::new(),
        Some(toml::Value::Table(t)) => t,
        Some(_) => return Err(Error::key(path, "sweep", "expected a table of key = [values]")),
    };
    let refuse = |k: &str| {
        (k == SPEED_KEY && kind == Kind::Speed).then(|| "is what the envelope searches; it cannot be swept".into())
    };
    let (keys, lists) = sweep::swept_lists(path, &sweep, &refuse)?;
    let total: usize = lists.iter().map(|l| l.len()).product();
    if total > 10_000 {
        return Err(Error::key(path, "sweep", format!("{total} combinations; at most 10000 allowed")));
    }
    let mut jobs = Vec::with_capacity(total + raw.reference.len());
    for index in 0..total {
        let choice = sweep::combination(index, &lists);
        let mut t = table.clone();
        let mut params = Vec::new();
        for ((k, l), c) in keys.iter().zip(&lists).zip(&choice) {
            set_path(&mut t, k, l[*c].clone()).map_err(|e| Error::key(path, &format!("sweep.{k}"), e))?;
            params.push(sweep::value_text(&l[*c]));
        }
        jobs.push(Job { label: String::new(), params, table: t });
    }
    for (i, r) in raw.reference.iter().enumerate() {
        let mut t = table.clone();
        for (k, v) in &r.set {
            set_path(&mut t, k, v.clone())
                .map_err(|e| Error::key(path, &format!("envelope.reference[{i}].set.{k}"), e))?;
        }
        jobs.push(Job { label: r.label.clone(), params: Vec::new(), table: t });
    }
    // Check every job's spec now (at the lowest search speed), so bad input stops before any run.
    for (i, j) in jobs.iter().enumerate() {
        let what = if !j.label.is_empty() {
            format!("reference '{}'", j.label)
        } else if keys.is_empty() {
            "the spec".to_string()
        } else {
            format!("sweep combination {} ({})", i + 1, describe(&keys, &j.params))
        };
        job_config(path, j, search.map(|s| s.min_mps))
            .map_err(|e| Error::input(path, format!("{what}: {}", strip_file(path, &e.to_string()))))?;
    }
    let name = match table.get("name") {
        Some(toml::Value::String(s)) => s.clone(),
        _ => return Err(Error::key(path, "name", "expected a string")),
    };
    Ok(Envelope { name, spec_file: path.to_path_buf(), kind, search, keys, jobs })
}

fn speed_search(path: &Path, raw: &RawSettings) -> Result<SpeedSearch> {
    let need = |k: &str, v: Option<f64>| {
        v.ok_or_else(|| Error::key(path, &format!("envelope.{k}"), "required for iso3888_2 (m/s, > 0)"))
    };
    let (lo, hi) = (need("speed_min_mps", raw.speed_min_mps)?, need("speed_max_mps", raw.speed_max_mps)?);
    let step = raw.scan_step_mps.unwrap_or(1.0);
    let tol = raw.tolerance_mps.unwrap_or(0.05);
    let bad = |k: &str, v: f64, allowed: &str| Error::key(path, &format!("envelope.{k}"), format!("{v}: {allowed}"));
    if !(lo.is_finite() && lo > 0.0) {
        return Err(bad("speed_min_mps", lo, "expected a speed > 0 (m/s)"));
    }
    if !(hi.is_finite() && hi > lo) {
        return Err(bad("speed_max_mps", hi, &format!("expected a finite speed above speed_min_mps = {lo} (m/s)")));
    }
    if !(step.is_finite() && step > 0.0) {
        return Err(bad("scan_step_mps", step, "expected > 0 (m/s)"));
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(bad("tolerance_mps", tol, "expected > 0 (m/s)"));
    }
    if (hi - lo) / step > 1000.0 {
        return Err(bad("scan_step_mps", step, "at most 1000 scan speeds between the bounds"));
    }
    Ok(SpeedSearch { min_mps: lo, max_mps: hi, scan_step_mps: step, tolerance_mps: tol })
}

fn describe(keys: &[String], params: &[String]) -> String {
    keys.iter().zip(params).map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ")
}

fn strip_file(path: &Path, msg: &str) -> String {
    let prefix = format!("{}: ", path.display());
    msg.strip_prefix(&prefix).unwrap_or(msg).to_string()
}

/// The validated run of `job` (at entry speed `speed`, when the envelope searches speed).
fn job_config(path: &Path, job: &Job, speed: Option<f64>) -> Result<RunConfig> {
    let mut t = job.table.clone();
    if let Some(v) = speed {
        set_path(&mut t, SPEED_KEY, toml::Value::Float(v)).map_err(|e| Error::key(path, SPEED_KEY, e))?;
    }
    let mut b = batch::from_table(path, t)?;
    b.runs.remove(0).config.map_err(|e| Error::input(path, e))
}

/// The limit of one job.
fn job_limit(env: &Envelope, job: &Job) -> Result<Limit> {
    let path = &env.spec_file;
    match env.search {
        Some(s) => search_speed(&s, |v| {
            crate::output::signals::check(|| "the envelope was not written (no partial results)".into())?;
            let out = run::execute(&job_config(path, job, Some(v))?);
            let pass = out.summary.passed == Some(true) && out.summary.end_reason == EndReason::Completed;
            Ok(Trial { pass, plausible: out.summary.plausible })
        }),
        None => Ok(steady_limit(&job_config(path, job, None)?)),
    }
}

/// Run every job on `jobs` threads (all cores when `None`); rows in sweep order, then references.
pub fn execute(env: &Envelope, jobs: Option<usize>) -> Result<Vec<Row>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.unwrap_or(0))
        .build()
        .map_err(|e| Error::Run(format!("thread pool: {e}")))?;
    let limits: Vec<Result<Limit>> = pool.install(|| env.jobs.par_iter().map(|j| job_limit(env, j)).collect());
    env.jobs
        .iter()
        .zip(limits)
        .map(|(j, l)| Ok(Row { label: j.label.clone(), params: j.params.clone(), limit: l? }))
        .collect()
}

/// Quote a CSV field when it needs it.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Column names of the value and its bracket for `kind`.
pub fn value_columns(kind: Kind) -> [&'static str; 3] {
    match kind {
        Kind::Speed => {
            ["highest_passing_speed_mps", "lowest_failing_speed_above_mps", "lowest_failing_speed_below_mps"]
        }
        Kind::LateralAcceleration => {
            ["highest_steady_ay_mps2", "next_step_nominal_ay_mps2", "unsteady_step_below_nominal_ay_mps2"]
        }
    }
}

/// The text of envelope.csv.
pub fn csv(env: &Envelope, rows: &[Row]) -> String {
    let mut cols = vec!["reference".to_string()];
    cols.extend(env.keys.iter().cloned());
    cols.extend(value_columns(env.kind).iter().map(|s| s.to_string()));
    cols.extend(["runs", "plausible", "note"].map(String::from));
    let mut s = cols.join(",") + "\n";
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    for r in rows {
        let mut f = vec![csv_field(&r.label)];
        if r.params.is_empty() {
            f.extend(std::iter::repeat_n(String::new(), env.keys.len()));
        } else {
            f.extend(r.params.iter().map(|p| csv_field(p)));
        }
        let l = &r.limit;
        f.extend([opt(l.value), opt(l.fail_above), opt(l.fail_below), l.runs.to_string()]);
        f.push(l.plausible.map_or(String::new(), |p| p.to_string()));
        f.push(csv_field(&l.note));
        s.push_str(&f.join(","));
        s.push('\n');
    }
    s
}

/// Run the envelope and write `<out_root>/<name>/envelope.csv` and `plots/envelope.png/.svg`.
pub fn run_envelope(env: &Envelope, out_root: &Path, jobs: Option<usize>) -> Result<(PathBuf, Vec<Row>)> {
    let rows = execute(env, jobs)?;
    let dir = out_root.join(&env.name);
    write_dir_atomic(&dir, |tmp| {
        write_atomic(&tmp.join("envelope.csv"), csv(env, &rows).as_bytes())?;
        let plots = tmp.join("plots");
        crate::output::create_dir(&plots)?;
        chart::plot(&plots.join("envelope"), env, &rows)
    })?;
    Ok((dir, rows))
}

/// `vehsim envelope`: search the limit of every combination, print one line each and the folder.
pub(crate) fn cli_envelope(file: &Path, out: &Path, jobs: Option<usize>) -> Result<std::process::ExitCode> {
    batch::check_jobs(jobs, true)?; // at least 1; no upper limit here
    let (dir, rows) = run_envelope(&load(file)?, out, jobs)?;
    for r in &rows {
        let what = if r.label.is_empty() { r.params.join(", ") } else { r.label.clone() };
        let v = r.limit.value.map_or("none".into(), |v| format!("{v:.3}"));
        println!("{what}: {v} ({} runs) {}", r.limit.runs, r.limit.note);
    }
    println!("-> {}", dir.display());
    Ok(std::process::ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(tol: f64) -> SpeedSearch {
        SpeedSearch { min_mps: 4.0, max_mps: 20.0, scan_step_mps: 1.0, tolerance_mps: tol }
    }

    fn ok(pass: bool) -> Result<Trial> {
        Ok(Trial { pass, plausible: true })
    }

    /// A constructed threshold at 11.37 m/s (pass at and below): found within the tolerance, from
    /// below (the passing end), with 17 scan runs plus ceil(log2(1 / 0.05)) = 5 bisection runs.
    #[test]
    fn finds_a_constructed_threshold_within_the_tolerance() {
        let l = search_speed(&s(0.05), |v| ok(v <= 11.37)).unwrap();
        let v = l.value.unwrap();
        let hi = l.fail_above.unwrap();
        assert!(v <= 11.37 && 11.37 < hi && hi - v <= 0.05, "{l:?}");
        assert_eq!(l.runs, 17 + 5);
        assert_eq!(l.fail_below, None);
        assert!(l.note.is_empty(), "{l:?}");
        // A tighter tolerance tightens the bracket.
        let t = search_speed(&s(0.001), |v| ok(v <= 11.37)).unwrap();
        assert!(t.fail_above.unwrap() - t.value.unwrap() <= 0.001 && t.value.unwrap() <= 11.37);
    }

    /// Passes between 4 and 7.5 and again between 9.2 and 13.6: the higher limit is reported with
    /// the failure at 8 m/s below it, and the note says non-monotone.
    #[test]
    fn reports_a_non_monotone_outcome() {
        let l = search_speed(&s(0.05), |v| ok(v <= 7.5 || (9.2..=13.6).contains(&v))).unwrap();
        assert!((l.value.unwrap() - 13.6).abs() <= 0.05 && l.value.unwrap() <= 13.6, "{l:?}");
        assert_eq!(l.fail_below, Some(8.0));
        assert!(l.note.contains("non-monotone") && l.note.contains("8 m/s"), "{}", l.note);
    }

    /// Nothing passes; everything passes (the top of the search is reported, with no failure).
    #[test]
    fn edges_of_the_search() {
        let l = search_speed(&s(0.05), |_| ok(false)).unwrap();
        assert_eq!((l.value, l.fail_above, l.runs), (None, Some(4.0), 17));
        assert!(l.note.contains("fails at every speed"));
        let l = search_speed(&s(0.05), |_| ok(true)).unwrap();
        assert_eq!((l.value, l.fail_above, l.runs), (Some(20.0), None, 17));
        assert!(l.note.contains("the limit is higher"));
        // A scan step that does not divide the range still ends at the top bound.
        let l = search_speed(&SpeedSearch { scan_step_mps: 3.0, ..s(0.05) }, |v| ok(v < 19.5)).unwrap();
        assert!(l.value.unwrap() <= 19.5 && l.fail_above.unwrap() - l.value.unwrap() <= 0.05, "{l:?}");
    }

    #[test]
    fn set_key_creates_tables() {
        let mut t = toml::Table::new();
        set_path(&mut t, "a.b.c", toml::Value::Integer(3)).unwrap();
        assert_eq!(t["a"]["b"]["c"].as_integer(), Some(3));
        set_path(&mut t, "top", toml::Value::Integer(1)).unwrap();
        assert!(set_path(&mut t, "top.x", toml::Value::Integer(1)).is_err());
    }
}
