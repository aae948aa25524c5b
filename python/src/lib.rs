//! `vehsim._vehsim`: the native half of the Python package, a thin layer over the library's
//! high-level entry points (the ones the command line uses): spec loading and validation
//! (`sweep::from_table`), run execution (`run::execute`), tyre files (`TyreFileSpec`), ATIIM
//! scenarios (`ScenarioSpec`, `solve_patch_at`, `drawbar_curve`) and discovery (`run_discover`).
//!
//! Every simulation and every tyre loop runs with the GIL released; runs and sweeps go on a
//! worker thread while the calling thread polls for signals, so Ctrl-C stops them within a second
//! ([`interruptible`]). Library errors become Python exceptions carrying the command line's
//! message: bad input or a bad option `ValueError`, I/O `OSError`, an interruption
//! `KeyboardInterrupt`, anything else `RuntimeError`. Spec values from Python nest at most
//! [`MAX_DEPTH`] levels. `simulation.rs` holds the stepped run (`vehsim.Simulation`). The
//! pure-Python half (`vehsim/`) turns these raw values into result objects and reads broadcast
//! arrays chunk by chunk.
//!
//! Units and sign conventions are the library's: SI, angles in rad, ISO 8855 axes (see the
//! README's Python section and `crates/vehsim-core/src/tyre/mod.rs`).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use rayon::prelude::*;
use vehsim_core::contact::model::{drawbar_curve, solve_patch_at};
use vehsim_core::error::Checker;
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::tyre::{TyreInput, TyreModel};
use vehsim_core::Error;
use vehsim_spec::contact::ScenarioSpec;
use vehsim_spec::files::{parse_toml, read_input};
use vehsim_spec::run::{self, RunOutput};
use vehsim_spec::sweep::{self, BatchRun};
use vehsim_spec::tyre::TyreFileSpec;
use vehsim_spec::RunConfig;

mod simulation;
use simulation::NativeSimulation;

/// Name standing for a spec given as a dict (relative paths inside it resolve against the
/// current directory).
const DICT_SPEC: &str = "<spec dict>";

/// A library error as the matching Python exception, with the command line's message.
fn py_err(e: Error) -> PyErr {
    let msg = e.to_string();
    match e {
        Error::Input { .. } | Error::Usage { .. } => PyValueError::new_err(msg),
        Error::Io { .. } => PyOSError::new_err(msg),
        Error::Interrupted { .. } => PyKeyboardInterrupt::new_err(msg),
        _ => PyRuntimeError::new_err(msg),
    }
}

/// Deepest nesting of dicts and lists a spec given from Python may have (a spec file nests a few
/// levels; a deeper value, or a dict that contains itself, is refused before the conversion's
/// recursion could exhaust the stack).
const MAX_DEPTH: usize = 32;

/// A Python value as a TOML value (bool, int, float, str, os.PathLike, list/tuple, dict with str
/// keys); `key` names it in the message of a value that has no TOML form. `depth`: how many dicts
/// and lists enclose it (at most [`MAX_DEPTH`]).
fn to_toml(file: &Path, key: &str, v: &Bound<'_, PyAny>, depth: usize) -> Result<toml::Value, Error> {
    let bad = || {
        let ty = v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
        Error::key(file, key, format!("a Python {ty} has no spec form; use bool, int, float, str, list or dict"))
    };
    if depth > MAX_DEPTH {
        return Err(Error::key(
            file,
            key.split('.').take(4).collect::<Vec<_>>().join(".").as_str(),
            format!(
                "nested more than {MAX_DEPTH} levels deep (a dict or list that contains itself?); \
                 spec values nest a few levels at most"
            ),
        ));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract::<bool>().map_err(|_| bad())?));
    }
    if v.is_instance_of::<PyInt>() {
        return v.extract::<i64>().map(toml::Value::Integer).map_err(|_| {
            let text = v.str().map(|s| s.to_string()).unwrap_or_default();
            let text = if text.len() > 24 { format!("{}...({} digits)", &text[..12], text.len()) } else { text };
            Error::key(
                file,
                key,
                format!(
                    "integer {text} does not fit a spec integer (-2^63 to 2^63 - 1); give a float for large values"
                ),
            )
        });
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract::<f64>().map_err(|_| bad())?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract::<String>().map_err(|_| bad())?));
    }
    if let Ok(d) = v.downcast::<PyDict>() {
        return dict_to_table(file, key, d, depth + 1).map(toml::Value::Table);
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, item) in v.try_iter().map_err(|_| bad())?.enumerate() {
            out.push(to_toml(file, &format!("{key}[{i}]"), &item.map_err(|_| bad())?, depth + 1)?);
        }
        return Ok(toml::Value::Array(out));
    }
    // os.PathLike, then NumPy arrays and scalars through their plain-Python `tolist()`.
    if let Ok(p) = v.extract::<PathBuf>() {
        return Ok(toml::Value::String(p.to_string_lossy().into_owned()));
    }
    if let Ok(plain) = v.call_method0("tolist") {
        let is_plain =
            [plain.is_instance_of::<PyList>(), plain.is_instance_of::<PyInt>(), plain.is_instance_of::<PyFloat>()];
        if is_plain.iter().any(|&b| b) {
            return to_toml(file, key, &plain, depth + 1);
        }
    }
    Err(bad())
}

fn dict_to_table(file: &Path, prefix: &str, d: &Bound<'_, PyDict>, depth: usize) -> Result<toml::Table, Error> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let k: String = k.extract().map_err(|_| Error::key(file, prefix, "keys must be strings"))?;
        let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
        t.insert(k, to_toml(file, &key, &v, depth)?);
    }
    Ok(t)
}

/// Set `value` at the dotted `key` of `table`, creating intermediate tables.
fn set_dotted(file: &Path, table: &mut toml::Table, key: &str, value: toml::Value) -> Result<(), Error> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap_or_default();
    let mut t = table;
    for p in parts {
        let entry = t.entry(p.to_string()).or_insert_with(|| toml::Value::Table(toml::Table::new()));
        t = entry.as_table_mut().ok_or_else(|| Error::key(file, key, format!("'{p}' is not a table")))?;
    }
    t.insert(last.to_string(), value);
    Ok(())
}

/// The spec as a TOML table and the path that names it: read from `path`, or converted from
/// `table`; then each override (dotted key = value) applied on top.
fn spec_table(
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> Result<(PathBuf, toml::Table), Error> {
    let (file, mut t) = match (path, table) {
        (Some(p), _) => {
            let t: toml::Table = parse_toml(&p, &read_input(&p)?)?;
            (p, t)
        }
        (None, Some(d)) => {
            let file = PathBuf::from(DICT_SPEC);
            let t = dict_to_table(&file, "", d, 0)?;
            (file, t)
        }
        (None, None) => (PathBuf::from(DICT_SPEC), toml::Table::new()),
    };
    if let Some(o) = overrides {
        for (k, v) in o.iter() {
            let k: String = k.extract().map_err(|_| Error::input(&file, "override keys must be strings"))?;
            let value = to_toml(&file, &k, &v, 0)?;
            set_dotted(&file, &mut t, &k, value)?;
        }
    }
    Ok((file, t))
}

/// A run's summary as JSON text, the keys and values of the summary.json `vehsim run` writes
/// (`params`: the swept values; the tests compare the two in full).
fn summary_json(cfg: &RunConfig, out: &RunOutput, params: &[(String, String)]) -> Result<String, Error> {
    let params: serde_json::Map<String, serde_json::Value> =
        params.iter().map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone()))).collect();
    let mut v = serde_json::json!({
        "name": cfg.name,
        "spec": cfg.spec_file.display().to_string(),
        "params": params,
        "vehicle": cfg.vehicle.name,
        "tyre": cfg.vehicle.tyre.name,
        "tyre_model": cfg.tyre_model.as_str(),
        "maneuver": cfg.kind.as_str(),
        "mu": cfg.env.mu,
        "surface_temperature_c": cfg.env.surface_temp_c,
        "integrator": cfg.settings.method.name(),
        "step_s": cfg.settings.step_s,
        "vehicle_model": cfg.vehicle_model.as_str(),
    });
    let extra = serde_json::json!({
        "summary": out.summary,
        "steady_states": out.steady_states,
        "understeer_gradient": out.understeer_gradient,
    });
    let json = |e: serde_json::Error| Error::Run(format!("summary: {e}"));
    if let (Some(m), serde_json::Value::Object(x)) = (v.as_object_mut(), extra) {
        for (k, val) in x {
            match (k.as_str(), val) {
                ("summary", serde_json::Value::Object(s)) => m.extend(s),
                ("steady_states", serde_json::Value::Array(a)) if a.is_empty() => {}
                ("understeer_gradient", serde_json::Value::Null) => {}
                (_, val) => {
                    m.insert(k, val);
                }
            }
        }
    }
    serde_json::to_string(&v).map_err(json)
}

/// A run's time series as (column names, columns), read from the CSV text the command line writes
/// (the same numbers to the bit: Rust prints the shortest text that parses back to the same f64;
/// an empty cell, a value the run does not define, becomes NaN); with the vehicle's `[sensors]`,
/// the logged channels too, as in timeseries.csv.
fn timeseries(cfg: &RunConfig, out: &RunOutput) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = vehsim_spec::run::timeseries_csv_with(&out.rows, cfg.vehicle.sensors.as_ref());
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap_or_default().split(',').map(str::to_string).collect();
    let mut cols: Vec<Vec<f64>> = names.iter().map(|_| Vec::with_capacity(out.rows.len())).collect();
    for l in lines {
        for (c, cell) in cols.iter_mut().zip(l.split(',')) {
            c.push(cell.parse().unwrap_or(f64::NAN));
        }
    }
    (names, cols)
}

/// One executed run: (status, summary JSON or None, message, time series or None).
type RunRecord = (&'static str, Option<String>, String, Option<(Vec<String>, Vec<Vec<f64>>)>);

/// Status of a run a sweep did not finish because it was interrupted.
const INTERRUPTED: &str = "interrupted";

/// Execute one run unless `stop` is set before or during it (then the record says `interrupted`).
fn execute(run: &BatchRun, keep_timeseries: bool, stop: &AtomicBool) -> Result<RunRecord, Error> {
    let stopped = || stop.load(Ordering::Relaxed);
    let interrupted = || (INTERRUPTED, None, "interrupted before it finished".to_string(), None);
    match &run.config {
        _ if stopped() => Ok(interrupted()),
        Err(msg) => Ok((sweep::RunStatus::Invalid.as_str(), None, msg.clone(), None)),
        Ok(cfg) => {
            let (out, halted) = run::execute_until(cfg, &stopped);
            if halted {
                return Ok(interrupted());
            }
            let status = sweep::RunStatus::of(&out.summary).as_str();
            let ts = keep_timeseries.then(|| timeseries(cfg, &out));
            Ok((status, Some(summary_json(cfg, &out, &run.params)?), String::new(), ts))
        }
    }
}

/// How often the waiting thread looks for a signal (Ctrl-C) while work runs without the GIL.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Run `work` on a worker thread while this (the calling, usually main) thread waits without the
/// GIL and checks for signals every [`SIGNAL_POLL`]: on Ctrl-C (a Python exception from the
/// signal handlers, normally KeyboardInterrupt) `stop` is set, the work is told to wind up and
/// its (partial) result is returned with the exception. The work checks `stop` between runs and
/// after every step, so control returns well within a second.
fn interruptible<T: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> T + Send) -> PyResult<(T, Option<PyErr>)> {
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        let stop = &stop;
        std::thread::Builder::new()
            .stack_size(WORKER_STACK)
            .spawn_scoped(scope, move || {
                // a send fails only when the receiver is gone, which the scope rules out
                let _ = tx.send(work(stop));
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
        let mut signal: Option<PyErr> = None;
        let mut rx = rx;
        loop {
            // the receiver goes to the GIL-free closure and comes back (it is Send, not Sync)
            let (got, back) = py.allow_threads(move || (rx.recv_timeout(SIGNAL_POLL), rx));
            rx = back;
            match got {
                Ok(v) => return Ok((v, signal)),
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if signal.is_none() {
                        if let Err(e) = py.check_signals() {
                            stop.store(true, Ordering::Relaxed);
                            signal = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err("the worker thread ended without a result"));
                }
            }
        }
    })
}

/// Stack of a worker thread, bytes (the main thread's usual size; rayon's workers get the same).
const WORKER_STACK: usize = 8 << 20;

fn record_to_py(py: Python<'_>, params: &[(String, String)], index: usize, r: RunRecord) -> PyResult<PyObject> {
    let d = PyDict::new(py);
    d.set_item("index", index)?;
    let p = PyDict::new(py);
    for (k, v) in params {
        p.set_item(k, v)?;
    }
    d.set_item("params", p)?;
    d.set_item("status", r.0)?;
    d.set_item("summary_json", r.1)?;
    d.set_item("message", r.2)?;
    match r.3 {
        Some((names, cols)) => {
            let ts = PyDict::new(py);
            for (n, c) in names.iter().zip(cols) {
                ts.set_item(n, c.into_pyarray(py))?;
            }
            d.set_item("timeseries", ts)?;
        }
        None => d.set_item("timeseries", py.None())?,
    }
    Ok(d.into_any().unbind())
}

/// Load (with overrides) and validate a manoeuvre spec into its batch of runs.
fn load_batch(
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> Result<sweep::Batch, Error> {
    let (file, t) = spec_table(path, table, overrides)?;
    sweep::from_table(&file, t)
}

/// Run one manoeuvre spec (no files written); a spec with a sweep is refused.
#[pyfunction]
#[pyo3(signature = (path=None, table=None, overrides=None))]
fn run_spec(
    py: Python<'_>,
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyObject> {
    let b = load_batch(path, table, overrides).map_err(py_err)?;
    if b.is_sweep() {
        return Err(py_err(Error::key(
            &b.spec_file,
            "sweep",
            format!("the spec sweeps {}; use vehsim.sweep for it", b.keys.join(", ")),
        )));
    }
    let first = &b.runs[0];
    if let Err(m) = &first.config {
        return Err(py_err(Error::input(&b.spec_file, m.clone())));
    }
    let (rec, signal) = interruptible(py, |stop| execute(first, true, stop))?;
    if let Some(e) = signal {
        return Err(e);
    }
    // a signal that arrived as the run finished is raised now, before any array is made
    py.check_signals()?;
    record_to_py(py, &first.params, 0, rec.map_err(py_err)?)
}

/// The most worker threads a sweep may use: 4 per core, as `vehsim run --jobs` allows.
#[pyfunction]
fn max_jobs() -> usize {
    4 * std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Run every combination of a spec's sweep on `jobs` threads (all cores when None; 1 to
/// [`max_jobs`]) with the GIL released; records in run order whatever the thread count. With
/// `shard` = (K, N) only the runs of the K-th of N parts run (index mod N = K - 1, as
/// `vehsim run --shard K/N`) and only their records are returned.
/// Returns (records, interrupted, digest): on Ctrl-C the runs not finished are recorded as
/// `interrupted` and the second value is the exception to raise (the caller keeps the finished
/// records with it); `digest` is the batch's [`batch_identity`] digest when `shard` is given
/// (computed from the files this process read), else None.
#[pyfunction]
#[pyo3(signature = (path=None, table=None, overrides=None, jobs=None, keep_timeseries=false, shard=None))]
fn sweep_spec(
    py: Python<'_>,
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
    jobs: Option<&Bound<'_, PyAny>>,
    keep_timeseries: bool,
    shard: Option<(usize, usize)>,
) -> PyResult<(Vec<PyObject>, Option<PyObject>, Option<String>)> {
    let jobs = check_jobs(jobs)?;
    let b = load_batch(path, table, overrides).map_err(py_err)?;
    let part = check_shard(shard)?;
    let digest = part.map(|_| sweep::batch_digest(&b)).transpose().map_err(py_err)?;
    let runs: Vec<&BatchRun> = b.runs.iter().filter(|r| part.is_none_or(|(k, n)| r.index % n == k - 1)).collect();
    let (records, signal) = interruptible(py, |stop| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(jobs.unwrap_or(0))
            .stack_size(WORKER_STACK)
            .build()
            .map_err(|e| Error::Run(format!("thread pool: {e}")))?;
        Ok::<Vec<Result<RunRecord, Error>>, Error>(
            pool.install(|| runs.par_iter().map(|r| execute(r, keep_timeseries, stop)).collect()),
        )
    })?;
    let records = records.map_err(py_err)?;
    let signal = match signal {
        Some(e) => Some(e),
        None => py.check_signals().err(),
    };
    let mut out = Vec::with_capacity(records.len());
    for (run, rec) in runs.iter().zip(records) {
        out.push(record_to_py(py, &run.params, run.index, rec.map_err(py_err)?)?);
    }
    Ok((out, signal.map(|e| e.into_value(py).into_any()), digest))
}

/// `shard` as (K, N) with 1 <= K <= N, or a ValueError in `--shard`'s words.
fn check_shard(shard: Option<(usize, usize)>) -> PyResult<Option<(usize, usize)>> {
    match shard {
        Some((k, n)) if n == 0 || k == 0 || k > n => {
            Err(PyValueError::new_err(format!("shard: {k}/{n} is not a shard; expected K/N with 1 <= K <= N")))
        }
        s => Ok(s),
    }
}

/// What identifies a spec's batch, computed where it is loaded: (SHA-256 digest over the vehsim
/// version, the spec as parsed with its overrides and the vehicle, tyre and `.tir` files its runs
/// read, the digest `vehsim merge` compares; the number of runs; the spec's name). A sweep split
/// over machines compares the digest every part reports with the caller's.
#[pyfunction]
#[pyo3(signature = (path=None, table=None, overrides=None))]
fn batch_identity(
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<(String, usize, String)> {
    let b = load_batch(path, table, overrides).map_err(py_err)?;
    let digest = sweep::batch_digest(&b).map_err(py_err)?;
    Ok((digest, b.runs.len(), b.name))
}

/// `jobs` as the command line bounds `--jobs`: None (all cores) or a whole number from 1 to
/// [`max_jobs`]; anything else is a ValueError naming the allowed range.
fn check_jobs(jobs: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(j) = jobs.filter(|j| !j.is_none()) else { return Ok(None) };
    let max = max_jobs();
    let cores = max / 4;
    let text = j.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
    let text = if text.len() > 40 { format!("{}...", &text.chars().take(40).collect::<String>()) } else { text };
    let n = if j.is_instance_of::<PyBool>() { None } else { j.extract::<i128>().ok() };
    match n {
        Some(n) if n >= 1 && n <= max as i128 => Ok(Some(n as usize)),
        _ => Err(PyValueError::new_err(format!(
            "jobs: {text} threads is not allowed; expected a whole number from 1 to {max} \
             (4 x {cores} cores, as vehsim run --jobs allows), or None for one per core"
        ))),
    }
}

/// A tyre file's provider, ready to evaluate.
#[pyclass(module = "vehsim._vehsim", frozen)]
struct NativeTyre {
    model: std::sync::Arc<dyn TyreModel>,
    #[pyo3(get)]
    name: String,
    #[pyo3(get)]
    provider: &'static str,
    #[pyo3(get)]
    path: String,
    #[pyo3(get)]
    rolling_radius_m: f64,
    #[pyo3(get)]
    unloaded_radius_m: f64,
    #[pyo3(get)]
    nominal_load_n: f64,
    #[pyo3(get)]
    warnings: Vec<String>,
}

/// The validated input columns of one vectorised call, all of one length.
struct Inputs<'a> {
    fz: &'a [f64],
    kappa: &'a [f64],
    alpha: &'a [f64],
    camber: &'a [f64],
    vx: &'a [f64],
    mu: &'a [f64],
    surface_temp: &'a [f64],
    contact_temp: &'a [f64],
}

impl Inputs<'_> {
    /// The first value outside the providers' domain, as a bad-input error naming the argument
    /// and its flat index (`offset` + the index within these columns). The bounds are checked
    /// inline; the message is built only on failure.
    fn check(&self, offset: usize) -> Result<(), Error> {
        use std::f64::consts::FRAC_PI_2;
        let c = Checker::new(Path::new("Tyre.forces"));
        let args: [(&str, &[f64], f64, f64); 8] = [
            ("fz", self.fz, 0.0, f64::INFINITY),
            ("kappa", self.kappa, -1.0, 10.0),
            ("alpha", self.alpha, -FRAC_PI_2, FRAC_PI_2),
            ("camber", self.camber, -0.5, 0.5),
            ("vx", self.vx, 0.0, f64::INFINITY),
            ("mu", self.mu, 0.0, 3.0),
            ("surface_temp", self.surface_temp, -80.0, 80.0),
            ("contact_temp", self.contact_temp, -80.0, 120.0),
        ];
        for (name, v, lo, hi) in args {
            // NaN fails the comparison too
            if let Some(i) = v.iter().position(|x| !(x.is_finite() && *x >= lo && *x <= hi)) {
                let key = format!("{name}[{}]", offset + i);
                return Err(if hi.is_infinite() { c.non_negative(&key, v[i]) } else { c.range(&key, v[i], lo, hi) }
                    .err()
                    .unwrap_or_else(|| Error::key(Path::new("Tyre.forces"), &key, "out of range")));
            }
        }
        Ok(())
    }

    fn input(&self, i: usize) -> TyreInput {
        TyreInput {
            fz_n: self.fz[i],
            kappa: self.kappa[i],
            alpha_rad: self.alpha[i],
            camber_rad: self.camber[i],
            vx_mps: self.vx[i],
            mu_surface: self.mu[i],
            surface_temp_c: self.surface_temp[i],
            contact_temp_c: self.contact_temp[i],
        }
    }
}

/// The data of a 1-D array (the Python wrapper passes contiguous copies).
fn contiguous<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|_| PyValueError::new_err(format!("Tyre.forces: '{name}' must be contiguous")))
}

/// Points per parallel chunk of a vectorised call; smaller calls run on the calling thread.
const CHUNK: usize = 8192;

/// Fx, Fy and Mz arrays (N, N, N m) of a vectorised tyre evaluation.
type ForceArrays<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

#[pymethods]
impl NativeTyre {
    /// Read a tyre file and build provider `provider` (the names of the spec files' `tyre_model`).
    #[staticmethod]
    fn load(path: PathBuf, provider: &str) -> PyResult<Self> {
        let kind: TyreModelKind =
            provider.parse().map_err(|m: String| py_err(Error::input(Path::new("provider"), m)))?;
        let spec = TyreFileSpec::load(&path).map_err(py_err)?;
        let (t, warnings) = spec.build_with_warnings(&path, kind).map_err(py_err)?;
        Ok(Self {
            model: t.model,
            name: t.name,
            provider: kind.as_str(),
            path: path.display().to_string(),
            rolling_radius_m: t.rolling_radius_m,
            unloaded_radius_m: t.unloaded_radius_m,
            nominal_load_n: t.nominal_load_n,
            warnings,
        })
    }

    /// Forces (fx, fy, mz) for eight 1-D float64 arrays of one length (the Python wrapper feeds
    /// the broadcast inputs chunk by chunk; `offset` is the chunk's first flat index, for
    /// messages); checked first, then evaluated without the GIL, in parallel chunks.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (fz, kappa, alpha, camber, vx, mu, surface_temp, contact_temp, offset=0))]
    fn forces<'py>(
        &self,
        py: Python<'py>,
        fz: PyReadonlyArray1<'py, f64>,
        kappa: PyReadonlyArray1<'py, f64>,
        alpha: PyReadonlyArray1<'py, f64>,
        camber: PyReadonlyArray1<'py, f64>,
        vx: PyReadonlyArray1<'py, f64>,
        mu: PyReadonlyArray1<'py, f64>,
        surface_temp: PyReadonlyArray1<'py, f64>,
        contact_temp: PyReadonlyArray1<'py, f64>,
        offset: usize,
    ) -> PyResult<ForceArrays<'py>> {
        let inp = Inputs {
            fz: contiguous(&fz, "fz")?,
            kappa: contiguous(&kappa, "kappa")?,
            alpha: contiguous(&alpha, "alpha")?,
            camber: contiguous(&camber, "camber")?,
            vx: contiguous(&vx, "vx")?,
            mu: contiguous(&mu, "mu")?,
            surface_temp: contiguous(&surface_temp, "surface_temp")?,
            contact_temp: contiguous(&contact_temp, "contact_temp")?,
        };
        let n = inp.fz.len();
        let lens = [inp.kappa, inp.alpha, inp.camber, inp.vx, inp.mu, inp.surface_temp, inp.contact_temp];
        if lens.iter().any(|a| a.len() != n) {
            return Err(PyValueError::new_err("Tyre.forces: every argument must have the same length"));
        }
        let model = &*self.model;
        let (fx, fy, mz) = py
            .allow_threads(|| -> Result<_, Error> {
                inp.check(offset)?;
                let (mut fx, mut fy, mut mz) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                let eval = |start: usize, fx: &mut [f64], fy: &mut [f64], mz: &mut [f64]| {
                    for k in 0..fx.len() {
                        let f = model.forces(&inp.input(start + k));
                        fx[k] = f.fx_n;
                        fy[k] = f.fy_n;
                        mz[k] = f.mz_nm;
                    }
                };
                if n <= CHUNK {
                    eval(0, &mut fx, &mut fy, &mut mz);
                } else {
                    fx.par_chunks_mut(CHUNK)
                        .zip(fy.par_chunks_mut(CHUNK))
                        .zip(mz.par_chunks_mut(CHUNK))
                        .enumerate()
                        .for_each(|(c, ((x, y), z))| eval(c * CHUNK, x, y, z));
                }
                Ok((fx, fy, mz))
            })
            .map_err(py_err)?;
        Ok((fx.into_pyarray(py), fy.into_pyarray(py), mz.into_pyarray(py)))
    }
}

/// Evaluate an ATIIM scenario (file or dict, with overrides): per-pixel maps, the patch summary
/// and the drawbar-pull curve, as `vehsim atiim` computes them (no files written).
#[pyfunction]
#[pyo3(signature = (path=None, table=None, overrides=None))]
fn atiim_scenario(
    py: Python<'_>,
    path: Option<PathBuf>,
    table: Option<&Bound<'_, PyDict>>,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyObject> {
    // A file as it stands is read as `vehsim atiim` reads it (the same messages, line numbers
    // included); a dict or overrides go through TOML text, so messages still name the keys.
    let as_is = path.clone().filter(|_| table.is_none() && overrides.is_none_or(|o| o.is_empty()));
    let (file, t) = spec_table(path, table, overrides).map_err(py_err)?;
    let text = toml::to_string(&t).map_err(|e| py_err(Error::input(&file, format!("cannot write as TOML: {e}"))))?;
    let (sc, res, curve) = py
        .allow_threads(|| -> Result<_, Error> {
            let sc = match as_is {
                Some(p) => ScenarioSpec::load(&p)?,
                None => parse_toml::<ScenarioSpec>(&file, &text)?.validate(&file)?,
            };
            let res = solve_patch_at(&sc.grid, &sc.operating(), &sc.params);
            let curve = drawbar_curve(
                &sc.grid,
                &sc.params,
                sc.drawbar_speed_mps,
                sc.slip_angle_rad,
                sc.ice_temp_c,
                &sc.drawbar_slips,
            );
            Ok((sc, res, curve))
        })
        .map_err(py_err)?;
    let op = sc.operating();
    let d = PyDict::new(py);
    d.set_item("name", &sc.name)?;
    d.set_item("title", &sc.title)?;
    d.set_item("pixel_length_m", sc.grid.dx_m)?;
    d.set_item("pixel_width_m", sc.grid.dy_m)?;
    let opd = PyDict::new(py);
    opd.set_item("speed_mps", sc.speed_mps)?;
    opd.set_item("slip_ratio", sc.slip_ratio)?;
    opd.set_item("slip_angle_rad", sc.slip_angle_rad)?;
    opd.set_item("ice_temp_c", sc.ice_temp_c)?;
    let (roll_speed_mps, _, _) = op.speeds();
    opd.set_item("roll_speed_mps", roll_speed_mps)?;
    opd.set_item("slide_speed_mps", op.slide_speed_mps())?;
    d.set_item("operating", opd)?;
    let summary = serde_json::to_string(&res.summary).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    d.set_item("summary_json", summary)?;
    let (rows, cols) = (res.rows, res.cols);
    let grid = |v: Vec<f64>| -> PyResult<PyObject> {
        Ok(PyArray1::from_vec(py, v).reshape([rows, cols])?.into_any().unbind())
    };
    let flags = |v: &[bool]| v.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect::<Vec<f64>>();
    let maps = PyDict::new(py);
    maps.set_item("pressure_pa", grid(sc.grid.p_pa.clone())?)?;
    maps.set_item("rise_k", grid(res.rise_k)?)?;
    maps.set_item("wet", grid(flags(&res.wet))?)?;
    maps.set_item("sliding", grid(flags(&res.sliding))?)?;
    maps.set_item("film_m", grid(res.film_m)?)?;
    maps.set_item("mu_visc", grid(res.mu_visc)?)?;
    maps.set_item("mu", grid(res.mu)?)?;
    maps.set_item("q_gen_w_m2", grid(res.q_gen)?)?;
    maps.set_item("q_tread_w_m2", grid(res.q_tread)?)?;
    maps.set_item("q_ice_w_m2", grid(res.q_ice)?)?;
    maps.set_item("q_melt_w_m2", grid(res.q_melt)?)?;
    d.set_item("maps", maps)?;
    let dp = PyDict::new(py);
    let col = |f: &dyn Fn(&(f64, vehsim_core::contact::model::PatchSummary)) -> f64| {
        curve.iter().map(f).collect::<Vec<f64>>().into_pyarray(py)
    };
    dp.set_item("slip_ratio", col(&|c| c.0))?;
    dp.set_item("drawbar_coeff", col(&|c| c.1.drawbar_coeff))?;
    dp.set_item("wet_fraction", col(&|c| c.1.wet_fraction))?;
    dp.set_item("sliding_fraction", col(&|c| c.1.sliding_fraction))?;
    dp.set_item("max_film_m", col(&|c| c.1.max_film_m))?;
    dp.set_item("mean_rise_k", col(&|c| c.1.mean_rise_k))?;
    dp.set_item("speed_mps", sc.drawbar_speed_mps)?;
    d.set_item("drawbar", dp)?;
    Ok(d.into_any().unbind())
}

/// Run discovery on measured runs and write its folder `out` (report.json and the rest, as
/// `vehsim discover`); returns the notices about the input.
#[pyfunction]
#[pyo3(signature = (vehicle, runs, out, tyre=None, tyre_model="pacejka", model="bicycle"))]
fn discover_runs(
    py: Python<'_>,
    vehicle: PathBuf,
    runs: Vec<PathBuf>,
    out: PathBuf,
    tyre: Option<PathBuf>,
    tyre_model: &str,
    model: &str,
) -> PyResult<Vec<String>> {
    let kind = vehsim::discover::tyre_kind(tyre_model).map_err(py_err)?;
    let opts = vehsim::discover::DiscoverOptions {
        vehicle,
        tyre,
        tyre_model: kind,
        model: vehsim::discover::model_kind(model).map_err(py_err)?,
        out,
        runs,
        progress: false,
        jackknife: false,
    };
    py.allow_threads(|| vehsim::discover::run_discover(&opts)).map(|(_, notices)| notices).map_err(py_err)
}

#[pymodule]
fn _vehsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Load NumPy's C API now, at import: loading it lazily at the first array a call returns
    // could run Python code (the import) with a KeyboardInterrupt pending, and the numpy crate
    // panics when that import fails.
    let _ = PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add_class::<NativeSimulation>()?;
    m.add("OBSERVATION", simulation::observation_names())?;
    m.add_function(wrap_pyfunction!(run_spec, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_spec, m)?)?;
    m.add_function(wrap_pyfunction!(max_jobs, m)?)?;
    m.add_function(wrap_pyfunction!(batch_identity, m)?)?;
    m.add_function(wrap_pyfunction!(atiim_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(discover_runs, m)?)?;
    m.add_class::<NativeTyre>()?;
    m.add("TYRE_MODELS", TyreModelKind::ALL.iter().map(|k| k.as_str()).collect::<Vec<_>>())?;
    m.add("TIMESERIES_COLUMNS", vehsim_core::sim::columns::COLUMNS.to_vec())?;
    Ok(())
}
