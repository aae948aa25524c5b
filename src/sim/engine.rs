//! The engine: owns time and runs the step loop.
//!
//! Per step k (t_k = k h, from the step index, never accumulated):
//! 1. at every controller sample (every `control_period / h` steps; by default every step) sample
//!    the manoeuvre (steer and speed commands) and the PID from the current kinematics, apply the
//!    steering angle and rate limits, and hold the inputs until the next sample;
//! 2. at the same instants update the contact-temperature estimate from every tyre's operating
//!    conditions;
//! 3. advance the state by one step with the chosen integrator;
//! 4. check for divergence (non-finite state), report the onset and recovery of the model's
//!    unphysical conditions (wheel lift, negative normal load; [`super::watch`]) at the new state,
//!    check for spin-out (|sideslip| > 60 deg above 1 m/s), let the manoeuvre check its rules,
//!    update the summary and notify observers.
//!
//! Divergence and spin-out end the run with an event; they are results, not errors. The model's
//! conditions are also checked once for the initial state, at t = 0.

use nalgebra::SVector;
use serde::Serialize;

use super::integrator::{rk4_step, step, Method};
use super::observer::{Observer, Row};
use super::watch::Watch;
use crate::contact::{ContactTemperature, TyreContact};
use crate::control::driver::limit_steer;
use crate::control::{Pid, PidParams};
use crate::maneuver::{Event, Maneuver};
use crate::vehicle::{Environment, Inputs, VehicleModel};

/// Sideslip beyond which a run is declared a spin-out, rad (60 degrees).
pub const SPIN_OUT_SIDESLIP_RAD: f64 = std::f64::consts::PI / 3.0;
/// Speed below which sideslip is not judged, m/s.
pub const SPIN_OUT_MIN_SPEED_MPS: f64 = 1.0;

/// Time-stepping settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimSettings {
    pub method: Method,
    /// Integration step, s.
    pub step_s: f64,
    /// Controller sample period, s: a whole number of steps (rounded, at least one).
    pub control_period_s: f64,
    /// Longest simulated time, s.
    pub duration_s: f64,
    /// Interval between recorded rows, s (rounded to a whole number of steps, at least one).
    pub output_interval_s: f64,
}

/// Controller settings and actuator limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controls {
    pub pid: PidParams,
    /// Largest total drive and brake torque, N m.
    pub drive_max_nm: f64,
    pub brake_max_nm: f64,
    /// Torque that holds the start speed (drag and rolling resistance), N m; preloads the PID.
    pub preload_nm: f64,
    /// Steering lock, rad, and rate limit, rad/s.
    pub steer_max_rad: f64,
    pub steer_rate_max_radps: f64,
}

/// Figures of one run (the engine's part of `summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Pass/fail where the manoeuvre has a rule, else null.
    pub passed: Option<bool>,
    pub cones_hit: usize,
    pub peak_yaw_rate_radps: f64,
    pub peak_sideslip_rad: f64,
    pub peak_ay_mps2: f64,
    /// Largest |lateral deviation| of the CG from the reference path, m (null when open loop).
    pub max_path_deviation_m: Option<f64>,
    pub min_speed_mps: f64,
    pub max_speed_mps: f64,
    /// Largest |speed target - vx| while the PID was active, m/s (null if never active).
    pub max_speed_error_mps: Option<f64>,
    pub steps: u64,
    pub end_time_s: f64,
    /// `completed` (manoeuvre finished), `duration` (time limit reached), `spin_out`, `diverged`.
    pub end_reason: String,
    pub events: Vec<Event>,
    /// False when a plausibility check failed ([`super::plausibility`]); the reasons follow.
    pub plausible: bool,
    pub implausible: Vec<String>,
}

impl Summary {
    /// True when the run ended in divergence or spin-out.
    pub fn failed(&self) -> bool {
        self.end_reason == "diverged" || self.end_reason == "spin_out"
    }
}

/// Is the angle of (vx, |vy|) from the x axis, in [0, pi], larger than that of (cx, sy) (a unit
/// vector in the same half plane)? Cross-product test: no trigonometry per step.
fn wider(vx: f64, vy_abs: f64, cx: f64, sy: f64) -> bool {
    cx * vy_abs - sy * vx > 0.0
}

struct Stats {
    peak_r: f64,
    /// Velocity direction (vx, |vy|) with the largest sideslip so far.
    peak_beta_dir: (f64, f64),
    peak_ay: f64,
    max_dev: Option<f64>,
    vmin: f64,
    vmax: f64,
    max_verr: Option<f64>,
}

fn max_opt(a: Option<f64>, v: f64) -> Option<f64> {
    Some(a.map_or(v, |a| a.max(v)))
}

/// Run one simulation of `model` through `maneuver`.
pub fn simulate<const N: usize, M: VehicleModel<N>>(
    model: &M,
    env: Environment,
    maneuver: &mut dyn Maneuver,
    contact: &mut dyn ContactTemperature,
    controls: &Controls,
    settings: &SimSettings,
    observer: &mut dyn Observer,
) -> Summary {
    let h = settings.step_s;
    let n_steps = ((settings.duration_s / h) - 1e-9).ceil().max(0.0) as u64;
    let out_every = ((settings.output_interval_s / h).round() as u64).max(1);
    let ctrl_every = ((settings.control_period_s / h).round() as u64).max(1);
    let hc = ctrl_every as f64 * h;
    let start = maneuver.start();
    let mut x = model.initial_state(start.x_m, start.y_m, start.yaw_rad, start.speed_mps);
    let mut pid = Pid::new(controls.pid, -controls.brake_max_nm, controls.drive_max_nm);
    pid.preload(controls.preload_nm);
    let mut pid_active = true;
    let mut u = Inputs { contact_temp_c: [env.surface_temp_c; 4], ..Inputs::default() };
    let mut contacts = [TyreContact { surface_temp_c: env.surface_temp_c, ..TyreContact::default() }; 4];
    let mut temps = [env.surface_temp_c; 4];
    let mut events = Vec::new();
    let mut watch = Watch::default();
    watch.check(model, &x, &u, &env, 0.0, &mut events);
    let mut st = Stats {
        peak_r: 0.0,
        peak_beta_dir: (1.0, 0.0),
        peak_ay: 0.0,
        max_dev: None,
        vmin: f64::INFINITY,
        vmax: 0.0,
        max_verr: None,
    };
    let (spin_sin, spin_cos) = SPIN_OUT_SIDESLIP_RAD.sin_cos();
    let mut end_reason = "duration";
    let mut k: u64 = 0;
    let mut last_row: Option<Row> = None;
    let mut speed_target = f64::NAN;
    let mut path_error = None;
    while k < n_steps {
        let t = k as f64 * h;
        let kin = model.kinematics(&x);
        if k % ctrl_every == 0 {
            // 1. Controllers, sampled and held.
            let cmd = maneuver.command(t, &kin);
            u.steer_rad =
                limit_steer(u.steer_rad, cmd.steer_rad, controls.steer_max_rad, controls.steer_rate_max_radps, hc);
            speed_target = match cmd.speed_target_mps {
                Some(v) => {
                    if !pid_active {
                        pid.reset();
                        pid_active = true;
                    }
                    let torque = pid.update(v, kin.vx_mps, hc);
                    u.drive_torque_nm = torque.max(0.0);
                    u.brake_torque_nm = (-torque).max(0.0);
                    st.max_verr = max_opt(st.max_verr, (v - kin.vx_mps).abs());
                    v
                }
                None => {
                    pid_active = false;
                    u.drive_torque_nm = 0.0;
                    u.brake_torque_nm = 0.0;
                    f64::NAN
                }
            };
            // 2. Contact temperature.
            if contact.needs_conditions() {
                model.tyre_contacts(&x, &u, &env, &mut contacts[..M::TYRES]);
            }
            contact.update(hc, &contacts[..M::TYRES], &mut temps[..M::TYRES]);
            u.contact_temp_c = temps;
            path_error = maneuver.path_error_m();
            if let Some(e) = path_error {
                st.max_dev = max_opt(st.max_dev, e.abs());
            }
        }
        if k % out_every == 0 {
            let row = Row {
                t_s: t,
                obs: model.observe(&x, &u, &env),
                inputs: u,
                speed_target_mps: speed_target,
                path_error_m: path_error.unwrap_or(f64::NAN),
            };
            observer.record(&row);
            last_row = Some(row);
        }
        // 3. Advance.
        let f = |s: &SVector<f64, N>| model.derivatives(s, &u, &env);
        let (next, k1) = match settings.method {
            Method::Rk4 => {
                let (n, k1) = rk4_step(f, &x, h);
                (Ok(n), k1)
            }
            m => (step(m, f, &x, h), f(&x)),
        };
        let (_, ay) = model.body_acceleration(&x, &k1);
        if ay.is_finite() {
            st.peak_ay = st.peak_ay.max(ay.abs());
        }
        let speed = kin.speed_mps();
        st.vmin = st.vmin.min(speed);
        st.vmax = st.vmax.max(speed);
        st.peak_r = st.peak_r.max(kin.yaw_rate_radps.abs());
        if wider(kin.vx_mps, kin.vy_mps.abs(), st.peak_beta_dir.0, st.peak_beta_dir.1) {
            st.peak_beta_dir = (kin.vx_mps, kin.vy_mps.abs());
        }
        k += 1;
        let t_next = k as f64 * h;
        // 4. Checks.
        let next = match next {
            Ok(n) if n.iter().all(|v| v.is_finite()) => n,
            Ok(n) => {
                let names = model.state_names();
                let bad: Vec<&str> =
                    n.iter().zip(names.iter()).filter(|(v, _)| !v.is_finite()).map(|(_, s)| *s).collect();
                events.push(Event {
                    t_s: t_next,
                    kind: "diverged".into(),
                    detail: format!("non-finite state: {}", bad.join(", ")),
                });
                end_reason = "diverged";
                break;
            }
            Err(msg) => {
                events.push(Event { t_s: t_next, kind: "diverged".into(), detail: msg });
                end_reason = "diverged";
                break;
            }
        };
        x = next;
        watch.check(model, &x, &u, &env, t_next, &mut events);
        let kin = model.kinematics(&x);
        if kin.speed_mps() > SPIN_OUT_MIN_SPEED_MPS && wider(kin.vx_mps, kin.vy_mps.abs(), spin_cos, spin_sin) {
            events.push(Event {
                t_s: t_next,
                kind: "spin_out".into(),
                detail: format!("sideslip {:.1} deg exceeds 60 deg", kin.sideslip_rad().to_degrees()),
            });
            end_reason = "spin_out";
            break;
        }
        if maneuver.after_step(t_next, &kin, &mut events) {
            end_reason = "completed";
            break;
        }
    }
    // Record the final state (the inputs of the last step are kept for reference).
    let t_end = k as f64 * h;
    let kin = model.kinematics(&x);
    if x.iter().all(|v| v.is_finite()) && last_row.is_none_or(|r| r.t_s < t_end) {
        let row = Row {
            t_s: t_end,
            obs: model.observe(&x, &u, &env),
            inputs: u,
            speed_target_mps: last_row.map_or(f64::NAN, |r| r.speed_target_mps),
            path_error_m: maneuver.path_error_m().unwrap_or(f64::NAN),
        };
        observer.record(&row);
        st.vmin = st.vmin.min(kin.speed_mps());
        st.vmax = st.vmax.max(kin.speed_mps());
    }
    let outcome = maneuver.outcome();
    Summary {
        passed: if end_reason == "diverged" || end_reason == "spin_out" {
            outcome.passed.map(|_| false)
        } else {
            outcome.passed
        },
        cones_hit: outcome.cones_hit,
        peak_yaw_rate_radps: st.peak_r,
        peak_sideslip_rad: st.peak_beta_dir.1.atan2(st.peak_beta_dir.0),
        peak_ay_mps2: st.peak_ay,
        max_path_deviation_m: st.max_dev,
        min_speed_mps: if st.vmin.is_finite() { st.vmin } else { 0.0 },
        max_speed_mps: st.vmax,
        max_speed_error_mps: st.max_verr,
        steps: k,
        end_time_s: t_end,
        end_reason: end_reason.to_string(),
        events,
        plausible: true,
        implausible: Vec::new(),
    }
}
