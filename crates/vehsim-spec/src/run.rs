//! One run from a manoeuvre spec: build the model and manoeuvre from a validated [`RunConfig`]
//! and simulate (no I/O). The files of a run are written by the application.

use std::fmt::Write as _;
use std::path::Path;

use crate::maneuver::{ManeuverConfig, ManeuverFile, RunConfig};
use vehsim_core::contact::{ContactTemperature, Isothermal};
use vehsim_core::error::Result;
use vehsim_core::event::EndReason;
use vehsim_core::event::{Event, EventKind};
use vehsim_core::maneuver::constant_radius::ConstantRadius;
use vehsim_core::maneuver::iso3888_2::{Body, Iso3888_2};
use vehsim_core::maneuver::longitudinal::Longitudinal;
use vehsim_core::maneuver::open_loop::OpenLoop;
use vehsim_core::maneuver::Maneuver;
use vehsim_core::sim::columns::{row_values, COLUMNS};
use vehsim_core::sim::observer::NoOutput;
use vehsim_core::sim::plausibility::Plausibility;
use vehsim_core::sim::steady_state::{self, SteadyState, UndersteerGradient};
use vehsim_core::sim::{Controls, Observer, Recorder, Row, Simulation, Summary};
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_core::vehicle::{Bicycle, Roll4Dof, VehicleModel};
use vehsim_core::vehicle::{Vehicle, AIR_DENSITY, GRAVITY};

/// Everything a run produced.
#[derive(Debug, Clone)]
pub struct RunOutput {
    /// The engine's figures of the run (the engine's part of `summary.json`).
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
pub(crate) fn cruise_torque_nm(v: &Vehicle, speed: f64) -> f64 {
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
            Box::new(vehsim_core::maneuver::brake_in_turn::BrakeInTurn::new(p.clone(), cfg.driver, v.wheelbase_m()))
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

/// [`execute_with`], asking `stop` after every step whether to stop early (see [`execute_until`]).
pub(crate) fn execute_with_stop<const N: usize, M: VehicleModel<N>>(
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
        match cfg.contact.build_for(&cfg.spec_file, &cfg.vehicle.lateral, M::TYRES, cfg.env.surface_temp_c) {
            Ok(c) => (c, None),
            Err(e) => (Box::new(Isothermal), Some(e.to_string())),
        };
    let windows = maneuver.steady_state_windows();
    let mut plausibility = Plausibility::new(cfg.vehicle.tyre.model.clone(), cfg.env, path_tolerance_m(cfg))
        .with_ranges(cfg.vehicle.tyre_ranges);
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
    let tol = path_tolerance_m(cfg);
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

/// The path tolerance of a run's manoeuvre, m (`None` for open-loop manoeuvres, which have no path).
pub(crate) fn path_tolerance_m(cfg: &RunConfig) -> Option<f64> {
    match &cfg.maneuver {
        ManeuverConfig::ConstantRadius(p) => {
            Some(vehsim_core::maneuver::constant_radius::circle_tolerance_m(p.radius_m))
        }
        ManeuverConfig::Iso3888_2(p) => {
            let gates = vehsim_core::maneuver::iso3888_2::layout(cfg.vehicle.body_width_m, p.lane5_min_width_m);
            Some(0.5 * gates.iter().map(|g| g.width_m()).fold(0.0, f64::max))
        }
        ManeuverConfig::OpenLoop { .. }
        | ManeuverConfig::Braking(_)
        | ManeuverConfig::Launch(_)
        | ManeuverConfig::BrakingInTurn(_) => None,
    }
}

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

/// The CSV text of a run's rows (non-finite values, e.g. no speed target while coasting, are empty).
pub fn timeseries_csv(rows: &[Row]) -> String {
    timeseries_csv_with(rows, None)
}

/// Columns of the measured channels, added after [`COLUMNS`] when the vehicle has `[sensors]`.
pub const MEASURED_COLUMNS: [&str; 2] = ["yaw_rate_meas_radps", "ay_meas_mps2"];

/// As [`timeseries_csv`]; with instruments `sensors`, two more columns: the yaw rate and lateral
/// acceleration they log ([`vehsim_core::vehicle::sensors::logged`], over the recorded rows: the
/// latency interpolates between rows, the accelerometer's yaw acceleration is a central
/// difference of the recorded yaw rate). Without, the text is [`timeseries_csv`]'s, byte for byte.
pub fn timeseries_csv_with(rows: &[Row], sensors: Option<&vehsim_core::vehicle::Sensors>) -> String {
    let measured = sensors.map(|s| {
        let t: Vec<f64> = rows.iter().map(|r| r.t_s).collect();
        let r: Vec<f64> = rows.iter().map(|r| r.obs.kin.yaw_rate_radps).collect();
        let ay: Vec<f64> = rows.iter().map(|r| r.obs.ay_mps2).collect();
        let vx: Vec<f64> = rows.iter().map(|r| r.obs.kin.vx_mps).collect();
        vehsim_core::vehicle::sensors::logged(&t, &r, &ay, &vx, s)
    });
    let mut s = String::with_capacity(rows.len() * 400);
    s.push_str(&COLUMNS.join(","));
    if measured.is_some() {
        s.push(',');
        s.push_str(&MEASURED_COLUMNS.join(","));
    }
    s.push('\n');
    for (k, r) in rows.iter().enumerate() {
        let extra = measured.as_ref().map(|(r, ay)| [r[k], ay[k]]);
        for (i, v) in row_values(r).iter().chain(extra.iter().flatten()).enumerate() {
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
