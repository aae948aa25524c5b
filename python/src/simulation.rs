//! `NativeSimulation`: one run of a manoeuvre spec stepped from Python (the native half of
//! `vehsim.Simulation`), over the library's [`StepRun`].
//!
//! The spec's driver and speed controller act unless the caller drives a channel itself: steer
//! (front road-wheel angle, rad, positive left) and torque (total drive and brake torque at the
//! wheels, N m, both >= 0). Inputs are checked against the vehicle's limits (ValueError naming
//! the input and the range); stepping a finished run is a RuntimeError. Stepping holds the GIL
//! (a step takes microseconds) and looks for Ctrl-C every [`SIGNAL_EVERY`] steps of a long call.

use std::sync::{Mutex, MutexGuard, PoisonError};

use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vehsim_core::sim::external::{ExternalInputs, SteerRate, Torque};
use vehsim_core::Error;
use vehsim_spec::step::StepRun;
use vehsim_spec::step::OBSERVATION;
use vehsim_spec::RunConfig;

use crate::{load_batch, py_err};

/// Steps between two looks for a pending signal within one `step(n)` call (a few ms of work).
const SIGNAL_EVERY: u64 = 2048;

/// A stepped run (see the module docs).
#[pyclass(module = "vehsim._vehsim")]
pub struct NativeSimulation {
    cfg: RunConfig,
    /// Behind a lock only because a Python class must be shareable between threads (the
    /// engine's parts are Send, not Sync); `&mut self` methods reach it without locking.
    run: Mutex<StepRun>,
    steer_external: bool,
    steer_rate_external: bool,
    torque_external: bool,
}

fn build(cfg: &RunConfig, steer: bool, steer_rate: bool, torque: bool) -> PyResult<StepRun> {
    let mut run = StepRun::new(cfg).map_err(py_err)?;
    // external channels start at zero steer (rate) and zero torque until the first inputs
    let e = ExternalInputs {
        steer_rad: steer.then_some(0.0),
        steer_rate: steer_rate.then(SteerRate::default),
        torque_nm: torque.then_some(Torque { drive_nm: 0.0, brake_nm: 0.0 }),
    };
    run.set_inputs(e).map_err(PyValueError::new_err)?;
    Ok(run)
}

impl NativeSimulation {
    fn lock(&self) -> MutexGuard<'_, StepRun> {
        self.run.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

#[pymethods]
impl NativeSimulation {
    /// Load and validate a single-run spec (path or dict, with overrides); `steer_external` and
    /// `torque_external` say which channels the caller drives.
    #[new]
    #[pyo3(signature = (path=None, table=None, overrides=None, steer_external=false, torque_external=false, steer_rate_external=false))]
    fn new(
        path: Option<std::path::PathBuf>,
        table: Option<&Bound<'_, PyDict>>,
        overrides: Option<&Bound<'_, PyDict>>,
        steer_external: bool,
        torque_external: bool,
        steer_rate_external: bool,
    ) -> PyResult<Self> {
        if steer_external && steer_rate_external {
            return Err(PyValueError::new_err("external: 'steer' and 'steer_rate' exclude each other; give one"));
        }
        let b = load_batch(path, table, overrides).map_err(py_err)?;
        if b.is_sweep() {
            return Err(py_err(Error::key(
                &b.spec_file,
                "sweep",
                format!("the spec sweeps {}; a Simulation steps one run: drop [sweep]", b.keys.join(", ")),
            )));
        }
        let Some(first) = b.runs.into_iter().next() else {
            return Err(py_err(Error::input(&b.spec_file, "the spec has no run")));
        };
        let cfg = first.config.map_err(|m| py_err(Error::input(&b.spec_file, m)))?;
        let run = build(&cfg, steer_external, steer_rate_external, torque_external)?;
        Ok(Self { cfg, run: Mutex::new(run), steer_external, steer_rate_external, torque_external })
    }

    /// Start over from the manoeuvre's start (the engine is deterministic: the same inputs give
    /// the same run).
    fn reset(&mut self) -> PyResult<()> {
        self.run = Mutex::new(build(&self.cfg, self.steer_external, self.steer_rate_external, self.torque_external)?);
        Ok(())
    }

    /// Set the external inputs (only the channels the caller drives; None keeps a channel's
    /// value); checked against the vehicle's limits.
    #[pyo3(signature = (steer_rad=None, drive_torque_nm=None, brake_torque_nm=None, steer_rate_radps=None))]
    fn set_inputs(
        &mut self,
        steer_rad: Option<f64>,
        drive_torque_nm: Option<f64>,
        brake_torque_nm: Option<f64>,
        steer_rate_radps: Option<f64>,
    ) -> PyResult<()> {
        let run = self.run.get_mut().unwrap_or_else(PoisonError::into_inner);
        let mut e = run.inputs();
        if let Some(s) = steer_rad {
            if !self.steer_external {
                return Err(PyValueError::new_err(
                    "steer_rad: the spec's driver steers this simulation; create it with external=['steer'] to steer",
                ));
            }
            e.steer_rad = Some(s);
        }
        if let Some(r) = steer_rate_radps {
            if !self.steer_rate_external {
                return Err(PyValueError::new_err(
                    "steer_rate_radps: this simulation does not take a steer rate; create it with external=['steer_rate']",
                ));
            }
            e.steer_rate = Some(SteerRate { rate_radps: r, ..SteerRate::default() });
        }
        if drive_torque_nm.is_some() || brake_torque_nm.is_some() {
            if !self.torque_external {
                return Err(PyValueError::new_err(
                    "drive/brake torque: the spec's speed controller sets the torque of this simulation; \
                     create it with external=['torque'] to set it",
                ));
            }
            let t = e.torque_nm.unwrap_or_default();
            e.torque_nm = Some(Torque {
                drive_nm: drive_torque_nm.unwrap_or(t.drive_nm),
                brake_nm: brake_torque_nm.unwrap_or(t.brake_nm),
            });
        }
        run.set_inputs(e).map_err(PyValueError::new_err)
    }

    /// Take up to `n` steps (stopping at the run's end); returns the end reason once the run
    /// has ended, else None. A finished run raises RuntimeError.
    fn step(&mut self, py: Python<'_>, n: u64) -> PyResult<Option<&'static str>> {
        let run = self.run.get_mut().unwrap_or_else(PoisonError::into_inner);
        if let Some(r) = run.end_reason() {
            return Err(PyRuntimeError::new_err(format!(
                "the simulation has ended ({} at t = {} s); call reset() to start again",
                r.as_str(),
                run.time_s()
            )));
        }
        for i in 0..n {
            if i > 0 && i % SIGNAL_EVERY == 0 {
                py.check_signals()?;
            }
            if run.step().is_some() {
                break;
            }
        }
        Ok(run.end_reason().map(|r| r.as_str()))
    }

    /// The observation now (values in the order of OBSERVATION).
    fn observation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.lock().observation().to_vec().into_pyarray(py)
    }

    /// The model's state vector now (names in `state_names`).
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.lock().state().to_vec().into_pyarray(py)
    }

    #[getter]
    fn state_names(&self) -> Vec<&'static str> {
        self.lock().state_names()
    }

    #[getter]
    fn t_s(&self) -> f64 {
        self.lock().time_s()
    }

    #[getter]
    fn steps(&self) -> u64 {
        self.lock().steps()
    }

    #[getter]
    fn max_steps(&self) -> u64 {
        self.lock().max_steps()
    }

    #[getter]
    fn step_s(&self) -> f64 {
        self.lock().step_s()
    }

    #[getter]
    fn control_period_s(&self) -> f64 {
        self.lock().control_period_s()
    }

    #[getter]
    fn duration_s(&self) -> f64 {
        self.lock().duration_s()
    }

    #[getter]
    fn end_reason(&self) -> Option<&'static str> {
        self.lock().end_reason().map(|r| r.as_str())
    }

    #[getter]
    fn cones_hit(&self) -> usize {
        self.lock().outcome().cones_hit
    }

    #[getter]
    fn passed(&self) -> Option<bool> {
        self.lock().outcome().passed
    }

    #[getter]
    fn name(&self) -> &str {
        &self.cfg.name
    }

    #[getter]
    fn maneuver(&self) -> &'static str {
        self.cfg.kind.as_str()
    }

    #[getter]
    fn mu(&self) -> f64 {
        self.cfg.env.mu
    }

    #[getter]
    fn surface_temperature_c(&self) -> f64 {
        self.cfg.env.surface_temp_c
    }

    #[getter]
    fn wheelbase_m(&self) -> f64 {
        self.cfg.vehicle.wheelbase_m()
    }

    /// (steer lock rad, largest drive torque N m, largest brake torque N m, steer rate limit rad/s).
    #[getter]
    fn limits(&self) -> (f64, f64, f64, f64) {
        let l = self.lock().limits();
        (l.steer_max_rad, l.drive_max_nm, l.brake_max_nm, l.steer_rate_max_radps)
    }

    /// The external inputs in force: (steer rad, drive N m, brake N m, steer rate rad/s), None
    /// where the channel is not external.
    #[getter]
    fn inputs(&self) -> (Option<f64>, Option<f64>, Option<f64>, Option<f64>) {
        let e = self.lock().inputs();
        let t = e.torque_nm;
        (e.steer_rad, t.map(|t| t.drive_nm), t.map(|t| t.brake_nm), e.steer_rate.map(|r| r.rate_radps))
    }

    /// Events so far: dicts with t_s, kind and detail.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for e in self.lock().events() {
            let d = PyDict::new(py);
            d.set_item("t_s", e.t_s)?;
            d.set_item("kind", e.kind.as_str())?;
            d.set_item("detail", &e.detail)?;
            out.append(d)?;
        }
        Ok(out)
    }
}

/// Names of the observation's values (the columns of timeseries.csv).
pub fn observation_names() -> Vec<&'static str> {
    OBSERVATION.to_vec()
}
