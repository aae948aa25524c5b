//! One run from a manoeuvre spec: build the model and manoeuvre from a validated [`RunConfig`],
//! simulate (no I/O), and write `results/<name>/timeseries.csv` and `summary.json` atomically
//! (into a temporary folder renamed into place).

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::contact::{ContactTemperature, Isothermal};
use crate::error::{Error, Result};
use crate::maneuver::constant_radius::ConstantRadius;
use crate::maneuver::iso3888_2::{Body, Iso3888_2};
use crate::maneuver::longitudinal::Longitudinal;
use crate::maneuver::open_loop::OpenLoop;
use crate::maneuver::steady_state::{self, SteadyState, UndersteerGradient};
use crate::maneuver::{Event, EventKind, Maneuver};
use crate::output::write_atomic;
use crate::sim::observer::NoOutput;
use crate::sim::plausibility::{self, Plausibility};
use crate::sim::{Controls, EndReason, Observer, Recorder, Row, Simulation, Summary};
use crate::spec::maneuver::{ManeuverConfig, VehicleModelKind};
use crate::spec::vehicle::{Vehicle, AIR_DENSITY, GRAVITY};
use crate::spec::{ManeuverFile, RunConfig};
use crate::vehicle::{Bicycle, Roll4Dof, VehicleModel};

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    pub summary: Summary,
    /// Recorded rows (empty when the spec switches the time series off).
    pub rows: Vec<Row>,
    /// The manoeuvre's course for plots (`layout.json`), if it has one.
    pub layout: Option<serde_json::Value>,
    /// Means over the manoeuvre's steady-state windows (empty unless it defines any).
    pub steady_states: Vec<SteadyState>,
    /// Understeer gradient fitted to the steady windows (needs at least three).
    pub understeer_gradient: Option<UndersteerGradient>,
    /// Why there is no understeer gradient, for a manoeuvre with steady-state windows.
    pub understeer_gradient_note: Option<String>,
    /// The manoeuvre's own result figures ([`Maneuver::results`]), if it has any.
    pub results: Option<serde_json::Value>,
}

/// Load and validate a manoeuvre spec (with its vehicle and tyre files).
pub fn load(path: &Path) -> Result<RunConfig> {
    ManeuverFile::load(path)?.build(path)
}

/// Torque at the wheels that holds `speed` against drag and rolling resistance, N m.
pub fn cruise_torque_nm(v: &Vehicle, speed: f64) -> f64 {
    let f = 0.5 * AIR_DENSITY * v.drag_area_m2 * speed * speed + v.rolling_resistance * v.mass_kg * GRAVITY;
    f * v.tyre.rolling_radius_m
}

/// Actuator limits and controller gains of a run.
pub fn controls(cfg: &RunConfig, start_speed: f64) -> Controls {
    let v = &cfg.vehicle;
    Controls {
        pid: cfg.pid,
        drive_max_nm: v.drive_torque_max_nm,
        brake_max_nm: v.brake_torque_max_nm,
        preload_nm: cruise_torque_nm(v, start_speed),
        steer_max_rad: v.steer_max_rad,
        steer_rate_max_radps: v.steer_rate_max_radps,
    }
}

/// The manoeuvre of a run, ready to drive.
pub fn build_maneuver(cfg: &RunConfig) -> Box<dyn Maneuver> {
    let v = &cfg.vehicle;
    match &cfg.maneuver {
        ManeuverConfig::Iso3888_2(p) => {
            let body = Body {
                width_m: v.body_width_m,
                front_m: v.a_m + v.front_overhang_m,
                rear_m: v.b_m + v.rear_overhang_m(),
                wheelbase_m: v.wheelbase_m(),
            };
            Box::new(Iso3888_2::new(*p, body, cfg.driver))
        }
        ManeuverConfig::OpenLoop { steer, speed } => {
            Box::new(OpenLoop::new(steer.clone(), speed.clone(), v.steer_rate_max_radps))
        }
        ManeuverConfig::ConstantRadius(p) => Box::new(ConstantRadius::new(p.clone(), cfg.driver, v.wheelbase_m())),
        ManeuverConfig::Braking(p) => Box::new(Longitudinal::braking(*p)),
        ManeuverConfig::Launch(p) => Box::new(Longitudinal::launch(*p)),
        ManeuverConfig::BrakingInTurn(p) => {
            Box::new(crate::maneuver::brake_in_turn::BrakeInTurn::new(p.clone(), cfg.driver, v.wheelbase_m()))
        }
    }
}

/// Simulate a validated run (no I/O), with the vehicle model the spec selects.
pub fn execute(cfg: &RunConfig) -> RunOutput {
    execute_until(cfg, &|| false).0
}

/// [`execute`], asking `stop` after every step whether to stop early (an interruption from the
/// caller): true in the second value when it did; the output then covers the steps taken.
pub fn execute_until(cfg: &RunConfig, stop: &dyn Fn() -> bool) -> (RunOutput, bool) {
    match cfg.vehicle_model {
        VehicleModelKind::Bicycle => {
            execute_with_stop(&Bicycle::new(cfg.vehicle.clone()).prepared_for(&cfg.env), cfg, stop)
        }
        VehicleModelKind::Roll4Dof => match &cfg.vehicle.roll {
            Some(roll) => {
                execute_with_stop(&Roll4Dof::new(cfg.vehicle.clone(), roll.clone()).prepared_for(&cfg.env), cfg, stop)
            }
            // Spec validation rejects this; a hand-built config gets a result that says why.
            None => (
                RunOutput {
                    summary: Summary {
                        passed: None,
                        cones_hit: 0,
                        peak_yaw_rate_radps: 0.0,
                        peak_sideslip_rad: 0.0,
                        peak_ay_mps2: 0.0,
                        max_path_deviation_m: None,
                        min_speed_mps: 0.0,
                        max_speed_mps: 0.0,
                        max_speed_error_mps: None,
                        steps: 0,
                        end_time_s: 0.0,
                        end_reason: EndReason::Diverged,
                        events: vec![Event {
                            t_s: 0.0,
                            kind: EventKind::Diverged,
                            detail: "the 4-DOF model needs the vehicle's [roll] data; nothing was simulated".into(),
                        }],
                        plausible: true,
                        implausible: Vec::new(),
                    },
                    rows: Vec::new(),
                    layout: None,
                    steady_states: Vec::new(),
                    understeer_gradient: None,
                    understeer_gradient_note: None,
                    results: None,
                },
                false,
            ),
        },
    }
}

/// Simulate a validated run with a given model.
pub fn execute_with<const N: usize, M: VehicleModel<N>>(model: &M, cfg: &RunConfig) -> RunOutput {
    execute_with_stop(model, cfg, &|| false).0
}

/// [`execute_with`], asking `stop` after every step whether to stop early (see [`execute_until`]).
pub fn execute_with_stop<const N: usize, M: VehicleModel<N>>(
    model: &M,
    cfg: &RunConfig,
    stop: &dyn Fn() -> bool,
) -> (RunOutput, bool) {
    let mut maneuver = build_maneuver(cfg);
    let ctl = controls(cfg, maneuver.start().speed_mps);
    let mut recorder = Recorder::default();
    // The contact table was validated when the spec was built; should building fail here after
    // all, the run goes on isothermal and says so in its events.
    let (mut contact, note): (Box<dyn ContactTemperature>, _) =
        match cfg.contact.build(&cfg.spec_file, M::TYRES, cfg.env.surface_temp_c) {
            Ok(c) => (c, None),
            Err(e) => (Box::new(Isothermal), Some(e.to_string())),
        };
    let windows = maneuver.steady_state_windows();
    let mut plausibility = Plausibility::for_run(cfg);
    // Rows are kept only when someone reads them (the time series or the steady-state means); the
    // plausibility checks see every recorded row either way.
    let keep: &mut dyn Observer = if cfg.output.timeseries || !windows.is_empty() {
        // Room for every row the run can record (its longest duration), capped at a million.
        let s = &cfg.settings;
        let rows = (s.duration_s / s.output_interval_s.max(s.step_s)).ceil().clamp(0.0, 1e6) as usize + 2;
        recorder = Recorder::with_capacity(rows);
        &mut recorder
    } else {
        &mut NoOutput
    };
    let mut observer = Checked { plausibility: &mut plausibility, keep };
    let mut sim =
        Simulation::new(model, cfg.env, maneuver.as_mut(), contact.as_mut(), &ctl, &cfg.settings, &mut observer)
            .with_slip_control(&cfg.slip);
    let mut stopped = false;
    while sim.step().is_none() {
        if stop() {
            stopped = true;
            break;
        }
    }
    let mut summary = sim.finish();
    if let Some(n) = note {
        summary.events.insert(0, Event { t_s: 0.0, kind: EventKind::ContactModelUnavailable, detail: n });
    }
    if summary.end_reason == EndReason::Completed {
        if let Some(r) = maneuver.end_reason() {
            summary.end_reason = r;
        }
    }
    let tol = plausibility::path_tolerance_m(cfg);
    let steady_states = steady_state::steady_states(&windows, &recorder.rows, tol);
    plausibility.finish(&mut summary, &steady_states);
    let (understeer_gradient, understeer_gradient_note) = if windows.is_empty() {
        (None, None)
    } else {
        match steady_state::understeer_gradient(&steady_states, cfg.vehicle.wheelbase_m()) {
            Ok(g) => (Some(g), None),
            Err(e) => {
                (None, Some(format!("{e} ({} of {} steps reached their window)", steady_states.len(), windows.len())))
            }
        }
    };
    let mut rows = recorder.rows;
    if !cfg.output.timeseries {
        rows = Vec::new();
    }
    let out = RunOutput {
        summary,
        rows,
        layout: maneuver.layout(),
        steady_states,
        understeer_gradient,
        understeer_gradient_note,
        results: maneuver.results(),
    };
    (out, stopped)
}

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

/// Column names of timeseries.csv, units in the names.
pub const COLUMNS: &[&str] = &[
    "t_s",
    "x_m",
    "y_m",
    "yaw_rad",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "sideslip_rad",
    "ax_mps2",
    "ay_mps2",
    "steer_rad",
    "alpha_front_rad",
    "alpha_rear_rad",
    "kappa_front",
    "kappa_rear",
    "fx_front_n",
    "fy_front_n",
    "fx_rear_n",
    "fy_rear_n",
    "omega_front_radps",
    "omega_rear_radps",
    "drive_torque_nm",
    "brake_torque_nm",
    "speed_target_mps",
    "path_error_m",
    "contact_temp_front_c",
    "contact_temp_rear_c",
    "roll_rad",
    "fz_fl_n",
    "fz_fr_n",
    "fz_rl_n",
    "fz_rr_n",
];

/// One row's values in the order of [`COLUMNS`] (the units are in the names).
pub fn row_values(r: &Row) -> [f64; 32] {
    let o = &r.obs;
    let k = &o.kin;
    [
        r.t_s,
        k.x_m,
        k.y_m,
        k.yaw_rad,
        k.vx_mps,
        k.vy_mps,
        k.yaw_rate_radps,
        k.sideslip_rad(),
        o.ax_mps2,
        o.ay_mps2,
        r.inputs.steer_rad,
        o.alpha_rad[0],
        o.alpha_rad[1],
        o.kappa[0],
        o.kappa[1],
        o.fx_n[0],
        o.fy_n[0],
        o.fx_n[1],
        o.fy_n[1],
        o.omega_radps[0],
        o.omega_radps[1],
        r.inputs.drive_torque_nm,
        r.inputs.brake_torque_nm,
        r.speed_target_mps,
        r.path_error_m,
        o.contact_temp_axle_c[0],
        o.contact_temp_axle_c[1],
        o.roll_rad,
        o.fz_n[0],
        o.fz_n[1],
        o.fz_n[2],
        o.fz_n[3],
    ]
}

/// The CSV text of a run's rows (non-finite values, e.g. no speed target while coasting, are empty).
pub fn timeseries_csv(rows: &[Row]) -> String {
    let mut s = String::with_capacity(rows.len() * 400);
    s.push_str(&COLUMNS.join(","));
    s.push('\n');
    for r in rows {
        for (i, v) in row_values(r).iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            if v.is_finite() {
                let _ = write!(s, "{v}");
            }
        }
        s.push('\n');
    }
    s
}

/// Write a run's files into the existing folder `dir`: timeseries.csv (unless switched off),
/// summary.json and, for manoeuvres with a course, layout.json. `params` are the swept values.
pub fn write_run_files(dir: &Path, cfg: &RunConfig, out: &RunOutput, params: &[(String, String)]) -> Result<()> {
    if cfg.output.timeseries {
        write_atomic(&dir.join("timeseries.csv"), timeseries_csv(&out.rows).as_bytes())?;
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

pub use crate::output::write_dir_atomic;

/// The run's observer: every recorded row goes to the plausibility checks and to `keep`.
struct Checked<'a> {
    plausibility: &'a mut Plausibility,
    keep: &'a mut dyn Observer,
}

impl Observer for Checked<'_> {
    fn record(&mut self, row: &Row) {
        self.plausibility.check(row);
        self.keep.record(row);
    }
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
