//! The files of one run: `timeseries.csv`, `summary.json`, `steady_states.csv`, `layout.json`,
//! and the line `vehsim run` prints for it.

use std::path::Path;

use serde::Serialize;

use crate::output::write_atomic;
use vehsim_core::error::{Error, Result};
use vehsim_core::sim::steady_state::{self, SteadyState, UndersteerGradient};
use vehsim_core::sim::Summary;
use vehsim_spec::run::RunOutput;
use vehsim_spec::RunConfig;

pub use crate::output::write_dir_atomic;
pub use vehsim_spec::run::{timeseries_csv, timeseries_csv_with};

/// `summary.json`: the run's identity plus the engine's figures.
#[derive(Debug, Serialize)]
struct SummaryFile<'a> {
    name: &'a str,
    spec: String,
    /// Swept parameters of this run within its batch (empty for a single run).
    params: serde_json::Map<String, serde_json::Value>,
    vehicle: &'a str,
    tyre: &'a str,
    tyre_model: &'static str,
    maneuver: &'static str,
    mu: f64,
    surface_temperature_c: f64,
    integrator: &'static str,
    step_s: f64,
    vehicle_model: &'static str,
    #[serde(flatten)]
    summary: &'a Summary,
    #[serde(skip_serializing_if = "<[SteadyState]>::is_empty")]
    steady_states: &'a [SteadyState],
    #[serde(skip_serializing_if = "Option::is_none")]
    understeer_gradient: Option<&'a UndersteerGradient>,
    #[serde(skip_serializing_if = "Option::is_none")]
    understeer_gradient_note: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    results: Option<&'a serde_json::Value>,
}

/// Write a run's files into the existing folder `dir`: timeseries.csv (unless switched off),
/// summary.json and, for manoeuvres with a course, layout.json. `params` are the swept values.
pub fn write_run_files(dir: &Path, cfg: &RunConfig, out: &RunOutput, params: &[(String, String)]) -> Result<()> {
    if cfg.output.timeseries {
        write_atomic(
            &dir.join("timeseries.csv"),
            timeseries_csv_with(&out.rows, cfg.vehicle.sensors.as_ref()).as_bytes(),
        )?;
    }
    let sf = SummaryFile {
        name: &cfg.name,
        spec: cfg.spec_file.display().to_string(),
        params: params.iter().map(|(k, v)| (k.clone(), serde_json::Value::String(v.clone()))).collect(),
        vehicle: &cfg.vehicle.name,
        tyre: &cfg.vehicle.tyre.name,
        tyre_model: cfg.tyre_model.as_str(),
        maneuver: cfg.kind.as_str(),
        mu: cfg.env.mu,
        surface_temperature_c: cfg.env.surface_temp_c,
        integrator: cfg.settings.method.name(),
        step_s: cfg.settings.step_s,
        vehicle_model: cfg.vehicle_model.as_str(),
        summary: &out.summary,
        steady_states: &out.steady_states,
        understeer_gradient: out.understeer_gradient.as_ref(),
        understeer_gradient_note: out.understeer_gradient_note.as_deref(),
        results: out.results.as_ref(),
    };
    let json = serde_json::to_string_pretty(&sf).map_err(|e| Error::Run(format!("summary.json: {e}")))?;
    write_atomic(&dir.join("summary.json"), (json + "\n").as_bytes())?;
    if !out.steady_states.is_empty() {
        write_atomic(&dir.join("steady_states.csv"), steady_state::steady_states_csv(&out.steady_states).as_bytes())?;
    }
    if let Some(layout) = &out.layout {
        let json = serde_json::to_string_pretty(layout).map_err(|e| Error::Run(format!("layout.json: {e}")))?;
        write_atomic(&dir.join("layout.json"), (json + "\n").as_bytes())?;
    }
    Ok(())
}

/// The line `vehsim run` prints for a single run `name` written to `dir`: why and when it ended,
/// the pass verdict (and plausibility), the peaks and the folder.
pub(crate) fn summary_line(name: &str, s: &Summary, dir: &Path) -> String {
    use crate::output::num::Sig;
    let verdict = match s.passed {
        Some(true) => "passed".to_string(),
        Some(false) => format!("FAILED ({} cone boundaries hit)", s.cones_hit),
        None => "no pass rule".to_string(),
    };
    let verdict = if s.plausible { verdict } else { format!("{verdict}, IMPLAUSIBLE") };
    format!(
        "{name}: {} at t = {} s, {verdict}; peak yaw rate {} rad/s, peak sideslip {} deg, peak ay {} m/s^2 -> {}",
        s.end_reason,
        Sig(s.end_time_s),
        Sig(s.peak_yaw_rate_radps),
        Sig(s.peak_sideslip_rad.to_degrees()),
        Sig(s.peak_ay_mps2),
        dir.display()
    )
}
