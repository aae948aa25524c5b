//! The discovery replay on the engine: a measured run's channels as inputs prescribed by time, the
//! replay model ([`ReplayModel`]) as a [`VehicleModel`], the manoeuvre that steers it (the
//! measured steer open loop, or a driver closed loop) and the observer that keeps the rows at the
//! measured sample times. [`ReplayModel::simulate`] and [`ReplayModel::simulate_closed_loop`] run
//! here, on [`Simulation`] with [`Method::Rk4Lag`] (the lag states relaxed exactly), or with plain
//! RK4 on every state for the fine-step reference ([`ReplayModel::reference_step_s`]).
//!
//! - Time: the engine's time t is the run's time less its first sample's. A run sampled
//!   uniformly ([`uniform_interval`]: every sample within 1e-6 of an interval of the grid through
//!   the first and last) takes the step h = dt / m, the sample interval dt divided into the fewest
//!   m steps no longer than 10 ms (`H_MAX`), so every sample time is a step boundary (to
//!   round-off) and a row is recorded every m steps from the step's first stage. A run sampled
//!   unevenly (e.g. logger jitter) takes a uniform grid of steps across it, h = T / ceil(T / 10
//!   ms) with T its span, records a row every step, and the simulated channels are interpolated
//!   to its sample times by the cubic through the four rows around each (two either side; the
//!   first and last intervals take the first or last four), streamed as the steps pass them.
//!   The step does not shrink with the shortest sample interval: the inputs are read at every
//!   stage's time wherever the samples fall (a 1 us logger glitch would otherwise cost a million
//!   steps a second). One step is taken beyond the last sample so that its row, too, comes from
//!   a step (a run ending there is not judged).
//! - Prescribed inputs, read at every stage's time ([`Inputs::t_s`]; the samples around it found
//!   by arithmetic on a uniform run, by binary search on an uneven one): the measured vx, the
//!   distance travelled (trapezoidal integral of vx at the samples) for the friction stretch and
//!   the logged pose, each linear between samples; the steer open loop is the measured steer,
//!   linear between samples ([`Maneuver::steer_at`], no lock: the measured steer is what the car
//!   did). Closed loop, the driver sees the state predicted one sample interval ahead (the
//!   control period is dt) with the measured vx there, and the engine's continuous rate limiter
//!   and lock set the steer ramped across the interval (so the steer at the samples, linear in
//!   between, replays the run exactly). `vehsim synth`, the closed loop's user, writes uniform
//!   runs; on an uneven run the driver would sample every step (control period h), and the steer
//!   returned is interpolated to the samples like the other channels.
//! - State: the replay model's 12 states and the measured vx at index 12, which the model's
//!   projection ([`Prescribed::project`]) sets at every step's end (its derivative, the measured
//!   vx's slope, serves the controller's prediction); the kinematics report it. The projection
//!   also caps the tread-temperature rises at melting.
//! - Rules: the engine's divergence (a non-finite state) and the replay's own (|vy| > 1e3 m/s or
//!   |r| > 1e2 rad/s: the manoeuvre ends the run); the samples after the last one recorded (or,
//!   uneven, interpolated up to the last row) then hold its values and [`Simulated::ok`] is
//!   false. No spin-out: the replay follows the run to its end whatever its sideslip.
//! - Contact temperature (thermal_friction on ice): the engine's estimator update at every step
//!   (control period h, or dt closed loop on a uniform run), from the tyres' conditions at the
//!   state predicted at the step's end, its output ramped across the step.
//!
//! Discovery has no time loop of its own: every replay, whatever its sampling, open or closed
//! loop, is this one on the engine. Uneven sampling is tested against the same inputs sampled at
//! 1 kHz (within 3.0e-5 rad/s, the 10 ms step's own error; linear interpolation to the samples
//! would add up to 3.0e-5, the cubic 1.7e-6).

use nalgebra::SVector;

use super::coupling::Accel;
use super::measured::MeasuredRun;
use super::model::{ix, Drive, EffectParams, ReplayModel, Simulated, State, H_MAX, LAGS, NS, SLIP_SLOPE_FLOOR};
use vehsim_core::contact::{ContactTemperature, Isothermal, TyreContact};
use vehsim_core::control::driver::Driver;
use vehsim_core::control::PidParams;
use vehsim_core::event::Event;
use vehsim_core::maneuver::{Command, Maneuver, Outcome, Start};
use vehsim_core::path::RefPath;
use vehsim_core::sim::{Controls, Method, Observer, Row, SimSettings, Simulation};
use vehsim_core::vehicle::capability::{Lagged, Prescribed};
use vehsim_core::vehicle::sensors::longitudinal_acceleration_over;
use vehsim_core::vehicle::{Environment, Extras, Inputs, Kinematics, Observation, VehicleModel, MAX_LAGS};

/// Largest |vy| (m/s) and |r| (rad/s) of a replay that has not diverged.
const VY_LIMIT: f64 = 1e3;
const R_LIMIT: f64 = 1e2;

/// The sample interval of a run whose samples are uniform (each within 1e-6 of an interval of
/// the grid from the first sample to the last), s; `None` otherwise or with fewer than 2 samples.
pub fn uniform_interval(t: &[f64]) -> Option<f64> {
    let n = t.len();
    if n < 2 {
        return None;
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let tol = 1e-6 * dt;
    (dt > 0.0 && t.iter().enumerate().all(|(i, &ti)| (ti - (t[0] + i as f64 * dt)).abs() <= tol)).then_some(dt)
}

/// A run's channels, read at the engine's time.
struct Channels<'a> {
    run: &'a MeasuredRun,
    /// Sample interval of a uniformly sampled run, s (the samples around a time found by
    /// arithmetic); `None` when the sampling is uneven (found by binary search over `tau`).
    dt: Option<f64>,
    /// Sample times less the first's, s (uneven sampling only; empty otherwise).
    tau: Vec<f64>,
    /// Distance travelled at every sample, m.
    dist: Vec<f64>,
    /// The logged pose (x, y, psi) when a friction change placed on the ground needs it.
    logged: Option<[&'a [f64]; 3]>,
    /// The forward acceleration at every sample, m/s^2, when the longitudinal coupling needs it
    /// (empty otherwise; [`super::coupling`]): the logged `ax` when the run has it, else the
    /// measured speed's slope; `ax_as` says which.
    ax: Vec<f64>,
    ax_as: fn(f64) -> Accel,
}

impl<'a> Channels<'a> {
    /// The channels of `run` (at least 2 samples), sampled uniformly at `dt` or unevenly (`None`).
    fn new(run: &'a MeasuredRun, dt: Option<f64>, p: &EffectParams) -> Self {
        let n = run.t.len();
        let mut dist = Vec::with_capacity(n);
        dist.push(0.0);
        for k in 1..n {
            dist.push(dist[k - 1] + 0.5 * (run.vx[k] + run.vx[k - 1]) * (run.t[k] - run.t[k - 1]));
        }
        let logged = match (run.channel("x"), run.channel("y"), run.channel("psi")) {
            (Some(x), Some(y), Some(psi)) if p.on_ground() => Some([x, y, psi]),
            _ => None,
        };
        let tau = if dt.is_some() { Vec::new() } else { run.t.iter().map(|t| t - run.t[0]).collect() };
        let (ax, ax_as): (Vec<f64>, fn(f64) -> Accel) = match (p.coupled(), run.channel("ax")) {
            (false, _) => (Vec::new(), Accel::Slope),
            (true, Some(ax)) => (ax.to_vec(), Accel::Logged),
            (true, None) => {
                (longitudinal_acceleration_over(&run.vx, &run.t, super::coupling::AX_HALF_WINDOW_S), Accel::Slope)
            }
        };
        Self { run, dt, tau, dist, logged, ax, ax_as }
    }

    /// The samples around engine time `t_s` and the fraction of the way between them (held at
    /// the ends).
    fn at(&self, t_s: f64) -> (usize, f64) {
        let last = self.run.t.len() - 2;
        match self.dt {
            Some(dt) => {
                let s = t_s / dt;
                let i = if s > 0.0 { (s.floor() as usize).min(last) } else { 0 };
                (i, (s - i as f64).clamp(0.0, 1.0))
            }
            None => {
                let tau = &self.tau;
                let i = tau.partition_point(|&x| x <= t_s).saturating_sub(1).min(last);
                (i, ((t_s - tau[i]) / (tau[i + 1] - tau[i])).clamp(0.0, 1.0))
            }
        }
    }

    /// Length of sample interval `i` (from sample i to i + 1), s.
    fn interval(&self, i: usize) -> f64 {
        match self.dt {
            Some(dt) => dt,
            None => self.tau[i + 1] - self.tau[i],
        }
    }

    fn lerp(c: &[f64], (i, w): (usize, f64)) -> f64 {
        c[i] + w * (c[i + 1] - c[i])
    }

    fn vx(&self, t_s: f64) -> f64 {
        Self::lerp(&self.run.vx, self.at(t_s))
    }

    fn steer(&self, t_s: f64) -> f64 {
        Self::lerp(&self.run.steer, self.at(t_s))
    }
}

/// The replay model on one run with one set of effect parameters, as an engine model.
struct RunModel<'a> {
    model: &'a ReplayModel,
    p: &'a EffectParams,
    ch: &'a Channels<'a>,
    /// Tread-temperature state on (the effect on a run on ice) and its melting cap, K.
    tread: bool,
    tread_cap: f64,
}

impl RunModel<'_> {
    /// The replay's inputs at the stage of `u`: its steer and contact temperatures, and the
    /// prescribed channels at its time.
    fn drive(&self, u: &Inputs) -> Drive {
        let (run, at) = (self.ch.run, self.ch.at(u.t_s));
        let lerp = |c: &[f64]| Channels::lerp(c, at);
        Drive {
            steer: u.steer_rad,
            vx: lerp(&run.vx),
            mu: run.mu * self.p.mu_factor(lerp(&self.ch.dist)),
            mu_axle: [1.0; 2],
            pose: self.ch.logged.map(|[x, y, psi]| [lerp(x), lerp(y), lerp(psi)]),
            ice_c: run.ice_temp_c,
            contact_c: [u.contact_temp_c[0], u.contact_temp_c[1]],
            on_ice: run.on_ice,
            tread_rise_k: [0.0; 2],
            road: self.p.road.unwrap_or(run.road),
            ax: if self.ch.ax.is_empty() { Accel::Slope(0.0) } else { (self.ch.ax_as)(lerp(&self.ch.ax)) },
            long: None,
        }
    }

    /// Slope of the measured vx at engine time `t_s`, m/s^2.
    fn vx_slope(&self, t_s: f64) -> f64 {
        let (i, _) = self.ch.at(t_s);
        (self.ch.run.vx[i + 1] - self.ch.run.vx[i]) / self.ch.interval(i)
    }
}

fn pad(a: [f64; LAGS.len()]) -> [f64; MAX_LAGS] {
    let mut out = [0.0; MAX_LAGS];
    out[..a.len()].copy_from_slice(&a);
    out
}

impl RunModel<'_> {
    /// The observation of state `x` under inputs `u` (drive `d`): the replay's channels.
    fn observation_of(&self, x: &State, u: &Inputs, d: &Drive) -> Observation {
        let (ay, alpha_f) = self.model.ay(x, d, self.p);
        let ice = self.ch.run.ice_temp_c;
        let contact = if self.tread {
            [ice + x[ix::DT_F], ice + x[ix::DT_R]]
        } else {
            [u.contact_temp_c[0], u.contact_temp_c[1]]
        };
        Observation {
            kin: self.kinematics(x),
            ay_mps2: ay,
            alpha_rad: [alpha_f, 0.0],
            contact_temp_axle_c: contact,
            ..Observation::default()
        }
    }
}

impl VehicleModel<NS> for RunModel<'_> {
    const TYRES: usize = 2;

    fn state_names(&self) -> [&'static str; NS] {
        ["vy", "r", "fy_f", "fy_r", "delta_e", "x", "y", "psi", "alpha_f", "alpha_r", "dT_f", "dT_r", "vx"]
    }

    /// The run's state at its first sample (the pose and speed given are the run's own).
    fn initial_state(&self, _x_m: f64, _y_m: f64, _yaw_rad: f64, _speed_mps: f64) -> State {
        let run = self.ch.run;
        let u = Inputs { steer_rad: run.steer[0], contact_temp_c: [run.ice_temp_c; 4], ..Inputs::default() };
        self.model.initial_state(run, self.p, &self.drive(&u))
    }

    fn body_acceleration(&self, x: &State, dx: &State) -> (f64, f64) {
        (dx[ix::VX], dx[ix::VY] + x[ix::R] * x[ix::VX])
    }

    fn evaluate(&self, x: &State, u: &Inputs, _env: &Environment, extras: Extras<'_>) -> State {
        let d = self.drive(u);
        if let Some(out) = extras.contacts {
            out[..2].copy_from_slice(&self.model.contacts(x, &d, self.p));
        }
        if let Some(o) = extras.observation {
            *o = self.observation_of(x, u, &d);
        }
        let mut dx = self.model.derivatives(x, &d, self.p);
        dx[ix::VX] = self.vx_slope(u.t_s);
        dx
    }

    fn kinematics(&self, x: &State) -> Kinematics {
        Kinematics {
            x_m: x[ix::X],
            y_m: x[ix::Y],
            yaw_rad: x[ix::PSI],
            vx_mps: x[ix::VX],
            vy_mps: x[ix::VY],
            yaw_rate_radps: x[ix::R],
        }
    }

    fn lags(&self) -> Option<&dyn Lagged<NS>> {
        Some(self)
    }

    /// Prescribed: the measured speed, and the tread rise's melting cap. So a spin-out does not
    /// end the replay, which follows a measured run to its end whatever its sideslip.
    fn prescribed(&self) -> Option<&dyn Prescribed<NS>> {
        Some(self)
    }
}

impl Lagged<NS> for RunModel<'_> {
    fn lag_states(&self) -> &[usize] {
        &LAGS
    }

    fn lag_split(
        &self,
        x: &State,
        u: &Inputs,
        _env: &Environment,
        contacts: Option<&mut [TyreContact]>,
    ) -> (State, [f64; MAX_LAGS]) {
        let d = self.drive(u);
        if let Some(out) = contacts {
            out[..2].copy_from_slice(&self.model.contacts(x, &d, self.p));
        }
        let (mut dx, target) = self.model.body(x, &d, self.p);
        dx[ix::VX] = self.vx_slope(u.t_s);
        (dx, pad(target))
    }

    fn lag_rates(&self, x: &State, u: &Inputs, _env: &Environment) -> [f64; MAX_LAGS] {
        pad(self.model.lag_rates(x, &self.drive(u), self.p))
    }
}

impl Prescribed<NS> for RunModel<'_> {
    fn project(&self, t_s: f64, x: &mut SVector<f64, NS>) {
        if self.tread {
            // The melting cap: heat beyond it melts ice, the contact stays at 0 degC.
            x[ix::DT_F] = x[ix::DT_F].clamp(0.0, self.tread_cap);
            x[ix::DT_R] = x[ix::DT_R].clamp(0.0, self.tread_cap);
        }
        x[ix::VX] = self.ch.vx(t_s);
    }
}

/// The replay's manoeuvre: the measured steer (open loop) or a driver on a path (closed loop);
/// ends the run when the state leaves the replay's bounds.
struct ReplayDrive<'a, 'b> {
    ch: &'a Channels<'a>,
    closed: Option<(&'b RefPath, &'b mut Driver)>,
}

impl Maneuver for ReplayDrive<'_, '_> {
    fn start(&self) -> Start {
        Start { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0, speed_mps: self.ch.run.vx[0] }
    }

    fn command(&mut self, t: f64, kin: &Kinematics) -> Command {
        let steer_rad = match &mut self.closed {
            Some((path, driver)) => driver.steer(path, &Kinematics { vx_mps: self.ch.vx(t), ..*kin }),
            None => 0.0,
        };
        Command { steer_rad, speed_target_mps: None }
    }

    fn steer_at(&self, t: f64) -> Option<f64> {
        self.closed.is_none().then(|| self.ch.steer(t))
    }

    fn path_error_m(&self) -> Option<f64> {
        None
    }

    fn after_step(&mut self, _t: f64, kin: &Kinematics, _events: &mut Vec<Event>) -> bool {
        kin.vy_mps.abs() > VY_LIMIT || kin.yaw_rate_radps.abs() > R_LIMIT
    }

    fn outcome(&self) -> Outcome {
        Outcome::default()
    }
}

/// The simulated channels of one row: yaw rate (rad/s), lateral acceleration (m/s^2), lateral
/// velocity (m/s), front slip angle (rad), front contact temperature (degC), steer (rad) and the
/// pose X, Y (m), psi (rad).
#[derive(Debug, Clone, Copy, Default)]
struct Sample {
    r: f64,
    ay: f64,
    vy: f64,
    alpha_f: f64,
    contact_c: f64,
    steer: f64,
    x: f64,
    y: f64,
    psi: f64,
}

impl Sample {
    fn of(row: &Row) -> Self {
        Self {
            r: row.obs.kin.yaw_rate_radps,
            ay: row.obs.ay_mps2,
            vy: row.obs.kin.vy_mps,
            alpha_f: row.obs.alpha_rad[0],
            contact_c: row.obs.contact_temp_axle_c[0],
            steer: row.inputs.steer_rad,
            x: row.obs.kin.x_m,
            y: row.obs.kin.y_m,
            psi: row.obs.kin.yaw_rad,
        }
    }

    /// `self + c b`, channel by channel.
    fn add_scaled(&self, c: f64, b: &Self) -> Self {
        Self {
            r: self.r + c * b.r,
            ay: self.ay + c * b.ay,
            vy: self.vy + c * b.vy,
            alpha_f: self.alpha_f + c * b.alpha_f,
            contact_c: self.contact_c + c * b.contact_c,
            steer: self.steer + c * b.steer,
            x: self.x + c * b.x,
            y: self.y + c * b.y,
            psi: self.psi + c * b.psi,
        }
    }
}

/// Uniform sampling: keeps the rows recorded at the first `n` sample times, in order (every
/// sample time is a step boundary).
struct Samples {
    dt: f64,
    n: usize,
    rows: Vec<Sample>,
}

impl Observer for Samples {
    fn record(&mut self, row: &Row) {
        let i = self.rows.len();
        if i < self.n && (row.t_s - i as f64 * self.dt).abs() <= 1e-6 * self.dt {
            self.rows.push(Sample::of(row));
        }
    }
}

/// Uneven sampling: the rows, recorded at every step, interpolated to the measured sample times
/// `tau` (engine time) as the steps pass them, by the cubic through the four rows around each
/// sample (two either side; the first and last intervals take the first or last four). Streamed:
/// only the last four rows are kept.
struct Resampled<'a> {
    tau: &'a [f64],
    /// Tolerance on a sample time reached by a row (round-off of the engine's clock), s.
    tol: f64,
    /// The last rows (at most four), oldest first: engine time (s) and channels.
    window: Vec<(f64, Sample)>,
    rows: Vec<Sample>,
}

impl Resampled<'_> {
    /// Emits the samples pending at or before `until` (s), interpolated on the window's rows.
    fn emit(&mut self, until: f64) {
        while let Some(&tk) = self.tau.get(self.rows.len()) {
            if tk > until + self.tol {
                break;
            }
            let v = lagrange(&self.window, tk, self.tol);
            self.rows.push(v);
        }
    }

    /// After the last step: the samples up to the last row (a replay ended early leaves the
    /// rest).
    fn flush(&mut self) {
        if let Some(&(t, _)) = self.window.last() {
            self.emit(t);
        }
    }
}

impl Observer for Resampled<'_> {
    fn record(&mut self, row: &Row) {
        if self.window.len() == 4 {
            self.window.remove(0);
        }
        self.window.push((row.t_s, Sample::of(row)));
        match self.window.len() {
            // The first row: the first sample (engine time 0).
            1 => self.emit(row.t_s),
            // Rows j - 2 .. j + 1: the samples up to row j (the first time, from row 0 on).
            4 => self.emit(self.window[2].0),
            _ => {}
        }
    }
}

/// The polynomial through the rows `pts` (time, channels) at time `t`; a row's own channels
/// when `t` is within `tol` of its time.
fn lagrange(pts: &[(f64, Sample)], t: f64, tol: f64) -> Sample {
    if let Some((_, s)) = pts.iter().find(|(ti, _)| (t - ti).abs() <= tol) {
        return *s;
    }
    let mut out = Sample::default();
    for (i, (ti, si)) in pts.iter().enumerate() {
        let w = pts.iter().enumerate().filter(|&(m, _)| m != i).map(|(_, (tm, _))| (t - tm) / (ti - tm)).product();
        out = out.add_scaled(w, si);
    }
    out
}

/// Most steps of an unevenly sampled replay (beyond it the step grows).
const MAX_STEPS: usize = 100_000_000;

/// Replay `run` on the engine (see the module docs), open loop when `closed` is `None`; returns
/// the simulated channels and the steer at every sample.
pub(super) fn replay(
    model: &ReplayModel,
    run: &MeasuredRun,
    p: &EffectParams,
    closed: Option<(&RefPath, &mut Driver)>,
) -> (Simulated, Vec<f64>) {
    let n = run.t.len();
    if n < 2 {
        // Not a run (a measured run has at least 2 samples): nothing to integrate.
        let out = Simulated {
            yaw_rate: run.yaw_rate.clone(),
            ay: run.ay.clone(),
            vy: vec![0.0; n],
            alpha_f: vec![0.0; n],
            contact_rise_k: vec![0.0; n],
            ok: false,
            ..Default::default()
        };
        return (out, run.steer.clone());
    }
    let uniform = uniform_interval(&run.t);
    let ch = Channels::new(run, uniform, p);
    let tread = p.tread() && run.on_ice;
    let rm = RunModel { model, p, ch: &ch, tread, tread_cap: super::model::melt_cap_k(run.ice_temp_c) };
    let hmax = match model.reference_step_s {
        None => H_MAX,
        Some(h_ref) => reference_step(run, p, h_ref, tread),
    };
    // The step h, the rows' interval (the sample interval, or every step when uneven) and the
    // run's end in engine time plus one step.
    let (h, out_dt, duration_s) = match uniform {
        Some(dt) => {
            let m = ((dt / hmax).ceil() as usize).clamp(1, 1_000_000);
            let h = dt / m as f64;
            (h, dt, (n - 1) as f64 * dt + h)
        }
        None => {
            let span = ch.tau[n - 1];
            let m = ((span / hmax).ceil() as usize).clamp(1, MAX_STEPS);
            let h = span / m as f64;
            (h, h, m as f64 * h + h)
        }
    };
    let closed_loop = closed.is_some();
    let mut est = ReplayModel::estimator(run, p);
    let thermal = est.is_some();
    let settings = SimSettings {
        method: if model.reference_step_s.is_some() { Method::Rk4 } else { Method::Rk4Lag },
        step_s: h,
        // The controller sample (driver, contact estimate) every interval closed loop (every
        // step when the sampling is uneven), every step for the contact estimate open loop;
        // otherwise once, at the start (what it would ramp, the torque 0 and the isothermal
        // contact at the surface temperature, never changes).
        control_period_s: if closed_loop {
            out_dt
        } else if thermal {
            h
        } else {
            duration_s
        },
        duration_s,
        output_interval_s: out_dt,
    };
    let v = &model.vehicle;
    let controls = Controls {
        pid: PidParams::default(),
        drive_max_nm: 0.0,
        brake_max_nm: 0.0,
        preload_nm: 0.0,
        steer_max_rad: if closed_loop { v.steer_max_rad } else { f64::INFINITY },
        steer_rate_max_radps: v.steer_rate_max_radps,
    };
    let env = Environment {
        mu: run.mu,
        surface_temp_c: run.ice_temp_c,
        regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
        road: vehsim_core::vehicle::road::Road::FLAT,
    };
    let mut maneuver = ReplayDrive { ch: &ch, closed };
    let mut isothermal = Isothermal;
    let contact: &mut dyn ContactTemperature = match est.as_mut() {
        Some(e) => e,
        None => &mut isothermal,
    };
    let mut samples = Samples { dt: out_dt, n, rows: Vec::new() };
    let mut resampled = Resampled { tau: &ch.tau, tol: 1e-6 * h, window: Vec::with_capacity(4), rows: Vec::new() };
    let observer: &mut dyn Observer = if uniform.is_some() {
        samples.rows.reserve(n);
        &mut samples
    } else {
        resampled.rows.reserve(n);
        &mut resampled
    };
    let mut sim = Simulation::new(&rm, env, &mut maneuver, contact, &controls, &settings, observer);
    while sim.step().is_none() {}
    // Not finished: `Simulation::finish` would record the final state, which after an early end
    // is the one that left the bounds (the samples from there on hold the last one within them).
    drop(sim);
    resampled.flush();
    let rows = if uniform.is_some() { samples.rows } else { resampled.rows };
    let mut out = Simulated { ok: rows.len() == n, ..Default::default() };
    let mut steer = Vec::with_capacity(n);
    let ice = run.ice_temp_c;
    // The first row is recorded before the first step, so there is always a last one to hold.
    let last = rows.last().copied().unwrap_or_default();
    for r in rows.iter().chain(std::iter::repeat_n(&last, n - rows.len())) {
        out.yaw_rate.push(r.r);
        out.ay.push(r.ay);
        out.vy.push(r.vy);
        out.alpha_f.push(r.alpha_f);
        out.contact_rise_k.push(r.contact_c - ice);
        out.x.push(r.x);
        out.y.push(r.y);
        out.psi.push(r.psi);
        steer.push(r.steer);
    }
    // What the instruments log: the accelerometer's place, the channels' latency, their offsets.
    super::sensors::measure(&mut out.yaw_rate, &mut out.ay, run, p);
    out.yaw_rate.iter_mut().for_each(|v| *v += p.bias_yaw_rate_radps);
    out.ay.iter_mut().for_each(|v| *v += p.bias_ay_mps2);
    (out, steer)
}

/// The fine-step reference's step bound, s: `h_ref`, and a twentieth of the fastest lag's time
/// constant at the run's largest speed (plain RK4 integrates the lags too).
fn reference_step(run: &MeasuredRun, p: &EffectParams, h_ref: f64, tread: bool) -> f64 {
    let vmax = run.vx.iter().fold(super::model::V_FLOOR, |a, v| a.max(v.abs()));
    let mut hmax = h_ref;
    if p.sigma_y_m > 0.0 {
        hmax = hmax.min(0.05 * p.sigma_y_m / vmax);
    }
    if p.transient_slip() {
        let floor = if p.slip_relaxation_saturating { SLIP_SLOPE_FLOOR } else { 1.0 };
        hmax = hmax.min(0.05 * floor * p.slip_relaxation_m[0].min(p.slip_relaxation_m[1]) / vmax);
    }
    if p.steer_lag_s > 0.0 {
        hmax = hmax.min(0.05 * p.steer_lag_s);
    }
    if tread {
        hmax = hmax.min(0.05 * p.tread_cooling_s);
    }
    hmax
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discover::{load_vehicle, synth, tyre_kind};
    use vehsim_core::sim::integrator::rk4_step_t;

    fn model() -> ReplayModel {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        ReplayModel::new(load_vehicle(&root.join("vehicles/sedan.toml"), None, tyre_kind("pacejka").unwrap()).unwrap())
    }

    /// Yaw rate and lateral acceleration at the samples of `run` from a loop written here, not the
    /// engine's: classical RK4 with step `h` (a whole fraction of the sample interval) on the
    /// replay's derivatives, the measured steer at every stage's time, the projection after
    /// every step.
    fn independent_loop(model: &ReplayModel, run: &MeasuredRun, p: &EffectParams, h: f64) -> (Vec<f64>, Vec<f64>) {
        let dt = uniform_interval(&run.t).unwrap();
        let ch = Channels::new(run, Some(dt), p);
        let rm = RunModel { model, p, ch: &ch, tread: false, tread_cap: 0.0 };
        let env = Environment {
            mu: run.mu,
            surface_temp_c: run.ice_temp_c,
            regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
            road: vehsim_core::vehicle::road::Road::FLAT,
        };
        let u = |t: f64| Inputs {
            t_s: t,
            steer_rad: ch.steer(t),
            contact_temp_c: [run.ice_temp_c; 4],
            ..Inputs::default()
        };
        let m = (dt / h).round() as usize;
        let mut x = rm.initial_state(0.0, 0.0, 0.0, 0.0);
        let (mut r, mut ay) = (Vec::new(), Vec::new());
        for i in 0..run.t.len() {
            let t = (i * m) as f64 * h;
            r.push(x[ix::R]);
            ay.push(rm.observe(&x, &u(t), &env).ay_mps2);
            for k in i * m..(i + 1) * m {
                x = rk4_step_t(|ts, s| rm.derivatives(s, &u(ts), &env), k as f64 * h, &x, h).0;
                rm.project((k + 1) as f64 * h, &mut x);
            }
        }
        (r, ay)
    }

    /// The replay on the engine against the independent loop above, for lags (saturating transient
    /// slip with a steer compliance through it), load transfer and a friction stretch, on an ice
    /// sine and a dry step: with plain RK4 at the same step on both sides (the engine's fine-step
    /// reference) they agree to round-off (measured: 0 for the yaw rate and the lateral
    /// acceleration alike); the engine's lag step at 10 ms stays within 1e-4 rad/s of them
    /// (measured 1.9e-5 and 1.7e-5).
    #[test]
    fn engine_replay_matches_an_independent_loop() {
        let m = model();
        let runs = synth::generate(&m, &EffectParams::default(), 5);
        let p = EffectParams {
            slip_relaxation_m: [0.3, 0.5],
            slip_relaxation_saturating: true,
            steer_compliance_rad_per_kn: 0.004,
            load_transfer_height_m: 0.5,
            stretch_scale: 0.8,
            stretch_start_m: 60.0,
            stretch_length_m: 40.0,
            ..EffectParams::default()
        };
        let mut fine = model();
        fine.reference_step_s = Some(1e-3);
        for (run, _) in [&runs[0], &runs[2]] {
            let mut run = run.clone();
            for c in [&mut run.t, &mut run.steer, &mut run.vx, &mut run.yaw_rate, &mut run.ay] {
                c.truncate(401);
            }
            let dt = uniform_interval(&run.t).unwrap();
            let h = dt / (dt / reference_step(&run, &p, 1e-3, false)).ceil();
            let (r, ay) = independent_loop(&m, &run, &p, h);
            let max_abs = |u: &[f64], w: &[f64]| u.iter().zip(w).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            let peak = |u: &[f64]| u.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            let engine = fine.simulate(&run, &p);
            assert!(engine.ok);
            let (dr, day) = (max_abs(&engine.yaw_rate, &r), max_abs(&engine.ay, &ay));
            let lag = m.simulate(&run, &p);
            let dlag = max_abs(&lag.yaw_rate, &r);
            eprintln!(
                "{}: h {h:.2e} s, engine RK4 vs independent loop: max |dr| {dr:.2e} rad/s (peak {:.3}), max |day| \
                 {day:.2e} m/s^2 (peak {:.3}); engine lag step at 10 ms: max |dr| {dlag:.2e} rad/s",
                run.name,
                peak(&r),
                peak(&ay)
            );
            assert!(dr <= 1e-12 * peak(&r) && day <= 1e-12 * peak(&ay), "{dr} {day}");
            assert!(dlag < 1e-4, "{dlag}");
        }
    }

    /// Uniform sampling is recognised to 1e-6 of the interval, and not beyond.
    #[test]
    fn uniform_interval_tolerates_round_off_only() {
        let t: Vec<f64> = (0..101).map(|k| 150.0 + k as f64 * 0.01).collect();
        let dt = uniform_interval(&t).unwrap();
        assert!((dt - 0.01).abs() < 1e-12, "{dt}");
        let mut jitter = t.clone();
        jitter[50] += 2e-8;
        assert!(uniform_interval(&jitter).is_none());
        jitter[50] = t[50] + 5e-9;
        assert!(uniform_interval(&jitter).is_some());
        assert!(uniform_interval(&t[..1]).is_none());
    }

    /// `run` sampled at `times` (within its span): every channel interpolated linearly between
    /// its samples, so a time set that keeps every sample of `run` describes the same inputs.
    fn resample(run: &MeasuredRun, times: &[f64]) -> MeasuredRun {
        let at = |c: &[f64]| -> Vec<f64> {
            times
                .iter()
                .map(|&t| {
                    let i = run.t.partition_point(|&x| x <= t).saturating_sub(1).min(run.t.len() - 2);
                    let w = (t - run.t[i]) / (run.t[i + 1] - run.t[i]);
                    c[i] + w * (c[i + 1] - c[i])
                })
                .collect()
        };
        MeasuredRun {
            t: times.to_vec(),
            steer: at(&run.steer),
            vx: at(&run.vx),
            yaw_rate: at(&run.yaw_rate),
            ay: at(&run.ay),
            optional: run.optional.iter().map(|(k, c)| (k.clone(), at(c))).collect(),
            ..run.clone()
        }
    }

    /// The first `n` samples of `run`.
    fn head(run: &MeasuredRun, n: usize) -> MeasuredRun {
        let mut r = run.clone();
        for c in [&mut r.t, &mut r.steer, &mut r.vx, &mut r.yaw_rate, &mut r.ay] {
            c.truncate(n);
        }
        for (_, c) in &mut r.optional {
            c.truncate(n);
        }
        r
    }

    fn max_abs(u: &[f64], w: &[f64]) -> f64 {
        u.iter().zip(w).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    }

    /// The effects the sampling tests switch on: saturating transient slip with a steer
    /// compliance through it (lags), load transfer and contact heating (on the ice run).
    fn lagged_heated() -> EffectParams {
        EffectParams {
            slip_relaxation_m: [0.3, 0.5],
            slip_relaxation_saturating: true,
            steer_compliance_rad_per_kn: 0.004,
            load_transfer_height_m: 0.5,
            thermal_mu_per_k: -1.0,
            ..EffectParams::default()
        }
    }

    /// The uneven-sampling tests' runs: the synthetic set's ice sine and dry step, cut to their
    /// first 401 samples (4 s at 100 Hz).
    fn sine_and_step(m: &ReplayModel) -> [MeasuredRun; 2] {
        let runs = synth::generate(m, &EffectParams::default(), 5);
        [head(&runs[0].0, 401), head(&runs[2].0, 401)]
    }

    /// An unevenly sampled run is integrated on a uniform grid and its channels interpolated to
    /// its samples. Here the samples of a 100 Hz run (the ice sine and the dry step) plus one
    /// more 3 ms into every other interval (on the same inputs: the extra samples lie on the
    /// measured channels' lines), lags, load transfer and contact heating on:
    /// - its rows on the grid equal the same run's replay at 100 Hz, and at the extra samples the
    ///   replay's values equal the cubic written here through those rows, both to round-off
    ///   (measured <= 7e-17 rad/s): fails if the interpolation is linear, dropped (the row before
    ///   taken) or shifted by a sample;
    /// - against the same inputs sampled at 1 kHz (replayed at 1 ms steps) it stays within 5e-5
    ///   rad/s, a thirtieth of the synthetic yaw-rate noise (measured 2.1e-5 on the sine, 1.7e-5
    ///   on the step, the same at the 100 Hz and at the extra samples: the 10 ms step's own error).
    ///   On the 1 kHz trajectory itself, linear interpolation between its 10 ms points misses by up
    ///   to 9.8e-6 and 3.0e-5 rad/s, the cubic by 5.1e-7 and 1.7e-6.
    #[test]
    fn uneven_sampling_on_the_engine_matches_a_fine_even_run() {
        let (m, p) = (model(), lagged_heated());
        let mut worst = 0.0_f64;
        for even in sine_and_step(&m) {
            let dense_t: Vec<f64> = (0..4001).map(|k| even.t[0] + k as f64 * 1e-3).collect();
            let dense = resample(&even, &dense_t);
            // Indices into the dense run: every 10 ms, and 3 ms into every other interval.
            let idx: Vec<usize> = (0..4001).filter(|k| k % 10 == 0 || k % 20 == 3).collect();
            let uneven = resample(&even, &idx.iter().map(|&k| dense_t[k]).collect::<Vec<_>>());
            assert!(uniform_interval(&dense.t).is_some() && uniform_interval(&uneven.t).is_none());
            let (fine, coarse, u) = (m.simulate(&dense, &p), m.simulate(&even, &p), m.simulate(&uneven, &p));
            assert!(fine.ok && coarse.ok && u.ok);
            assert_eq!(u.yaw_rate.len(), idx.len());
            let pick = |c: &[f64], every: &dyn Fn(usize) -> bool| -> Vec<f64> {
                idx.iter().zip(c).filter(|(&k, _)| every(k)).map(|(_, v)| *v).collect()
            };
            let reference: Vec<f64> = idx.iter().map(|&k| fine.yaw_rate[k]).collect();
            let on_grid = |k: usize| k % 10 == 0;
            let off_grid = |k: usize| k % 10 != 0;
            let (d_on, d_off) = (
                max_abs(&pick(&u.yaw_rate, &on_grid), &pick(&reference, &on_grid)),
                max_abs(&pick(&u.yaw_rate, &off_grid), &pick(&reference, &off_grid)),
            );
            // The even run on the same 10 ms steps: the uneven run's rows at the 100 Hz samples.
            let d_even = max_abs(&pick(&u.yaw_rate, &on_grid), &coarse.yaw_rate);
            // The cubic through the 10 ms points of `c` (indexed by 10 ms) two either side of
            // dense index k (one before and three after in the first interval, three before and
            // one after in the last).
            let cubic_at = |c: &dyn Fn(usize) -> f64, k: usize| -> f64 {
                let j = (k / 10).clamp(1, 398);
                let mut v = 0.0;
                for a in j - 1..j + 3 {
                    let l: f64 = (j - 1..j + 3)
                        .filter(|&b| b != a)
                        .map(|b| (k as f64 - 10.0 * b as f64) / (10.0 * a as f64 - 10.0 * b as f64))
                        .product();
                    v += l * c(a);
                }
                v
            };
            let extra: Vec<(usize, f64)> =
                idx.iter().zip(&u.yaw_rate).filter(|(&k, _)| k % 10 != 0).map(|(&k, &r)| (k, r)).collect();
            // The interpolation itself: the cubic written here through the 100 Hz run's samples
            // (the uneven run's rows on the grid) at the extra samples.
            let d_cubic =
                extra.iter().map(|&(k, r)| (cubic_at(&|a| coarse.yaw_rate[a], k) - r).abs()).fold(0.0, f64::max);
            // Interpolation error on the fine trajectory itself, linear and cubic.
            let (mut interp, mut cubic) = (0.0_f64, 0.0_f64);
            for &(k, _) in &extra {
                let k0 = k - k % 10;
                let w = (k - k0) as f64 / 10.0;
                let lin = fine.yaw_rate[k0] + w * (fine.yaw_rate[k0 + 10] - fine.yaw_rate[k0]);
                interp = interp.max((lin - fine.yaw_rate[k]).abs());
                cubic = cubic.max((cubic_at(&|a| fine.yaw_rate[10 * a], k) - fine.yaw_rate[k]).abs());
            }
            let peak = reference.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            eprintln!(
                "{}: uneven on the engine vs 1 kHz run: max |dr| {d_on:.2e} rad/s at the 100 Hz samples, {d_off:.2e} at \
                 the extra samples (peak |r| {peak:.3}); vs the 100 Hz run: {d_even:.2e}; linear interpolation of \
                 the 1 kHz trajectory at 10 ms: {interp:.2e}, cubic: {cubic:.2e}; the replay's interpolation vs a \
                 cubic written here: {d_cubic:.2e}",
                even.name
            );
            assert!(d_even <= 1e-12 * peak && d_cubic <= 1e-12 * peak, "{d_even} {d_cubic}");
            worst = worst.max(d_on).max(d_off);
        }
        assert!(worst < 5e-5, "{worst}");
    }

    /// A run whose samples are off the uniform grid by logger jitter (every other sample 20 us
    /// late, the values unchanged) replays on the same grid of 10 ms steps as the run sampled
    /// evenly and stays within 1e-5 rad/s of it, lags, load transfer and contact heating on
    /// (measured 2.6e-6 on the ice sine, 4.7e-6 on the dry step: the inputs moved by 20 us).
    /// Fails if the channels are interpolated linearly (4.2e-5), not at all (4.4e-3) or shifted
    /// by a sample (4.4e-3).
    #[test]
    fn jittered_sampling_matches_even_sampling() {
        let (m, p) = (model(), lagged_heated());
        let mut worst = 0.0_f64;
        for even in sine_and_step(&m) {
            let mut uneven = even.clone();
            for i in (1..400).step_by(2) {
                uneven.t[i] += 2e-5;
            }
            assert!(uniform_interval(&even.t).is_some() && uniform_interval(&uneven.t).is_none());
            let (a, b) = (m.simulate(&even, &p), m.simulate(&uneven, &p));
            assert!(a.ok && b.ok);
            let d = max_abs(&a.yaw_rate, &b.yaw_rate);
            let day = max_abs(&a.ay, &b.ay);
            eprintln!(
                "{}: even vs jittered, both on the engine: max |dr| {d:.2e} rad/s, max |day| {day:.2e} m/s^2",
                even.name
            );
            worst = worst.max(d);
        }
        assert!(worst < 1e-5, "{worst}");
    }

    /// A replay that leaves its bounds (here a yaw inertia 6e-5 of the car's, whose yaw mode RK4
    /// cannot follow at 10 ms: it grows from the eighth sample on) ends there: not ok, every sample
    /// finite, |r| within 1e2 rad/s, the last samples holding the last value recorded within the
    /// bounds. (At 1e-4 of the car's the saturating tyres hold the unstable mode in an oscillation
    /// peaking near 99 rad/s, just inside the bound: whether it crossed depended on the last bits
    /// of the arctangent.)
    #[test]
    fn a_diverging_replay_holds_its_last_sample_within_bounds() {
        let m = model();
        let runs = synth::generate(&m, &EffectParams::default(), 5);
        let mut p = EffectParams::default();
        p.body_scale[0] = 6e-5;
        let s = m.simulate(&runs[1].0, &p);
        assert!(!s.ok);
        assert!(s.yaw_rate.iter().chain(&s.ay).chain(&s.vy).all(|v| v.is_finite()));
        assert!(s.yaw_rate.iter().all(|r| r.abs() <= R_LIMIT) && s.vy.iter().all(|v| v.abs() <= VY_LIMIT));
        let n = s.yaw_rate.len();
        assert_eq!(n, runs[1].0.t.len());
        let held = s.yaw_rate.iter().rev().take_while(|&&r| r == s.yaw_rate[n - 1]).count();
        eprintln!("held over the last {held} of {n} samples");
        assert!(held > 1 && held < n);
    }
}
