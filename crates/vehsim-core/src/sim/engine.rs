//! The engine: owns time and advances a run one integration step at a time.
//!
//! [`Simulation`] is the steppable engine: [`Simulation::new`] sets up the initial state,
//! [`Simulation::step`] advances one step and says whether the run has ended, the state, time and
//! inputs can be read between steps, and [`Simulation::finish`] records the final state and
//! returns the [`Summary`]. [`simulate`] is the loop over it. Each step has three named phases:
//!
//! 1. `Simulation::sample_controls`, at every controller sample (every `control_period_s`, a
//!    whole number of steps, on its own clock: the period does not follow the step): the
//!    manoeuvre (steer and speed commands) and the PID see the state *predicted at the end of the
//!    coming control period*, t + T_c, along the tangent at t (x_k + T_c f(x_k); the slope is the
//!    coming step's first RK4 stage, so the prediction costs no model evaluation; under
//!    [`Method::Rk4Lag`] the lag states follow their exact relaxation instead). Their outputs
//!    ramp linearly across the period from their values at t to the new ones at t + T_c (a
//!    predicted first-order hold: the inputs are continuous, the sampled loop converges to the
//!    continuous-time one at second order in T_c, and the sharply saturating tyres no longer
//!    see a staircase steer; errors per provider: `super::stability`). The steer at the ramp's
//!    end is that of a continuous rate limiter following the driver's command interpolated
//!    linearly across the period (from the last sample's command to the new one) and clamped to
//!    the lock (`rate_limited_steer`: it leaves the lock when the command does, not up to a
//!    period early); the PID integrates its error by the trapezoidal rule. The
//!    contact-temperature estimate comes first: it is advanced over the period behind (none at
//!    the first sample) to the tyres' operating conditions at t, taken at the contact
//!    temperatures it returns (the friction force depends on them:
//!    [`ContactTemperature::update_coupled`] solves for the consistent estimate). Each trial
//!    evaluates the whole model ([`VehicleModel::evaluate`] with the contact conditions); the last one, at the
//!    accepted temperatures, is the coming step's first stage, so an estimate that converges at
//!    its first trial costs no model evaluation of its own. Its ramp runs from the estimate at t
//!    to the estimate carried on by its change over the period behind (second order in T_c like
//!    the other ramps; held at the first sample, never past melting), and the next sample
//!    replaces that end by the estimate at the state reached.
//! 2. `Simulation::advance`: one step of the chosen integrator (RK4, or RK4 with the
//!    wheel-spin / transient-slip pairs integrated exponentially, linearised by one forward
//!    difference at the step's start, or RK4 with the model's first-order lag states relaxed
//!    exactly, [`Method::Rk4Lag`]). Inputs that are known functions of time (an open-loop steer
//!    profile, [`Maneuver::steer_at`]) are evaluated at every stage, and every stage's inputs carry
//!    its time ([`Inputs::t_s`]: a model with prescribed channels reads them by it). An output
//!    row, when one is due, is recorded from the first stage's model evaluation (no evaluation of
//!    its own; under [`Method::Rk4Lag`] the observation is the model's own call). Every method is
//!    entered through [`Method::step`]: the engine hands it the step's stages as a
//!    [`Problem`] (the model's derivative at the inputs of the stage's time, and the model's
//!    capabilities the method uses).
//! 3. `Simulation::check_end`: the model's projection of the new state
//!    ([`crate::vehicle::capability::Prescribed`]: bounds, prescribed components), divergence (non-finite state),
//!    the onset and recovery of the model's unphysical conditions (wheel lift, negative normal
//!    load; [`super::watch`]), spin-out (|sideslip| > 60 deg above 1 m/s, for models that keep
//!    the rule: not those with prescribed components; its event carries the crossing time interpolated
//!    within the step), the manoeuvre's rules, the summary's running figures, and observers.
//!
//! Slip controllers (ABS, traction control; [`super::slip_control`], switched on by
//! [`Simulation::with_slip_control`]) sample the wheels at the start of every step that is due on
//! their own periods, before phase 1, and their caps ramp across their periods; a manoeuvre that
//! asks for the pedal itself ([`Maneuver::pedal`]: launch, braking) sets the torque ramp's end to
//! full drive or full brake instead of the PID's output. Without them nothing of this runs.
//!
//! Divergence and spin-out end the run with an event; they are results, not errors. The model's
//! conditions are also checked once for the initial state, at t = 0. Time is t_k = k h, from the
//! step index, never accumulated.

use crate::event::EndReason;
use nalgebra::SVector;

use super::external::ExternalInputs;
use super::integrator::{relax, FirstStage, Method, Problem};
use super::observer::{Observer, Row};
use super::watch::Watch;
use crate::contact::thermal::MELT_C;
use crate::contact::{ContactTemperature, TyreContact};
use crate::control::driver::rate_limited_steer;
use crate::control::{Pid, PidParams};
use crate::event::{Event, EventKind};
use crate::maneuver::Maneuver;
use crate::vehicle::{Environment, Extras, Inputs, Kinematics, Observation, VehicleModel, MAX_LAGS};

/// Sideslip beyond which a run is declared a spin-out, rad (60 degrees).
pub(crate) const SPIN_OUT_SIDESLIP_RAD: f64 = std::f64::consts::PI / 3.0;
/// Speed below which sideslip is not judged, m/s.
pub(crate) const SPIN_OUT_MIN_SPEED_MPS: f64 = 1.0;

/// Time-stepping settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimSettings {
    /// Integration method.
    pub method: Method,
    /// Integration step, s.
    pub step_s: f64,
    /// Controller sample period, s, on its own clock: a whole number of steps (rounded, at least
    /// one; the spec layer refuses any other value).
    pub control_period_s: f64,
    /// Longest simulated time, s.
    pub duration_s: f64,
    /// Interval between recorded rows, s (rounded to a whole number of steps, at least one).
    pub output_interval_s: f64,
}

/// Controller settings and actuator limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controls {
    /// Gains of the speed PID.
    pub pid: PidParams,
    /// Largest total drive and brake torque, N m.
    pub drive_max_nm: f64,
    /// Largest total brake torque, N m.
    pub brake_max_nm: f64,
    /// Torque that holds the start speed (drag and rolling resistance), N m; preloads the PID.
    pub preload_nm: f64,
    /// Steering lock, rad, and rate limit, rad/s.
    pub steer_max_rad: f64,
    /// Steering rate limit, rad/s.
    pub steer_rate_max_radps: f64,
}

/// Figures of one run (the engine's part of `summary.json`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Summary {
    /// Pass/fail where the manoeuvre has a rule, else null.
    pub passed: Option<bool>,
    /// Number of distinct gate boundaries struck (ISO 3888-2; 0 otherwise).
    pub cones_hit: usize,
    /// Largest |yaw rate| over every step, rad/s.
    pub peak_yaw_rate_radps: f64,
    /// Largest |sideslip| atan2(|v_y|, v_x) over every step, rad (beyond pi/2 when sliding backwards).
    pub peak_sideslip_rad: f64,
    /// Largest |body-frame lateral acceleration| over every step, m/s^2.
    pub peak_ay_mps2: f64,
    /// Largest |lateral deviation| of the CG from the reference path, m (null when open loop).
    pub max_path_deviation_m: Option<f64>,
    /// Lowest CG speed over every step, m/s.
    pub min_speed_mps: f64,
    /// Highest CG speed over every step, m/s.
    pub max_speed_mps: f64,
    /// Largest |speed target - vx| while the PID was active, m/s (null if never active).
    pub max_speed_error_mps: Option<f64>,
    /// Number of integration steps taken.
    pub steps: u64,
    /// When the run ended, s: for a completed manoeuvre or a spin-out the instant of the end
    /// condition, interpolated within the last step; otherwise the end of the last step.
    pub end_time_s: f64,
    /// Why the run ended (serialised as `completed`, `duration`, `spin_out`, `diverged`, `left_path`).
    pub end_reason: EndReason,
    /// Events in time order (gate strikes, condition changes, plausibility flags).
    pub events: Vec<Event>,
    /// False when a plausibility check failed ([`super::plausibility`]); the reasons follow.
    pub plausible: bool,
    /// Why the run is implausible, one sentence per failed check (empty when plausible).
    pub implausible: Vec<String>,
}

impl Summary {
    /// True when the run ended in divergence or spin-out.
    pub fn failed(&self) -> bool {
        self.end_reason.failed()
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

/// The controller outputs that ramp across a control period (first-order hold).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ramped {
    steer_rad: f64,
    /// Drive (positive) or brake (negative) torque, N m.
    torque_nm: f64,
    contact_temp_c: [f64; 4],
    /// Distance the CG has travelled, m.
    distance_m: f64,
}

impl Ramped {
    /// The inputs at fraction `w` (0 at `from`, 1 at `to`) of the ramp.
    fn lerp(from: &Ramped, to: &Ramped, w: f64) -> Inputs {
        let l = |a: f64, b: f64| a + w * (b - a);
        let tq = l(from.torque_nm, to.torque_nm);
        let mut c = from.contact_temp_c;
        for (c, b) in c.iter_mut().zip(to.contact_temp_c) {
            *c = l(*c, b);
        }
        Inputs {
            steer_rad: l(from.steer_rad, to.steer_rad),
            drive_torque_nm: tq.max(0.0),
            brake_torque_nm: (-tq).max(0.0),
            contact_temp_c: c,
            distance_m: l(from.distance_m, to.distance_m),
            ..Inputs::default()
        }
    }
}

/// The coming step's first stage, evaluated ahead of the step (by the controller sample, for its
/// prediction): what the integrator takes, the derivative it amounts to (under
/// [`Method::Rk4Lag`], assembled from the lag parts) and the observation when a row is due.
struct Pending<const N: usize> {
    first: FirstStage<N>,
    k1: SVector<f64, N>,
    /// The output row when one is due: its observation from this evaluation, the rest filled in
    /// when the step records it (the row is built where the observation lands, not copied).
    row: Option<Row>,
}

/// A row to be filled: the observation `obs`, the rest blank (time 0, default inputs, no speed
/// target or path error).
fn blank_row(obs: Observation) -> Row {
    Row { t_s: 0.0, obs, inputs: Inputs::default(), speed_target_mps: f64::NAN, path_error_m: f64::NAN }
}

/// The first stage of a step of `model` at state `x` under inputs `u` (see [`Pending`]), with
/// the observation when `record` and the tyres' contact conditions into `contacts` when given:
/// one evaluation of the model (plus its lag rates, and an observation of its own, under
/// [`Method::Rk4Lag`] with a model that has lags). Written into `slot` in place (the observation
/// is evaluated where it is kept, not built and then moved: a memory copy less per step).
#[allow(clippy::too_many_arguments)]
fn first_stage<'p, const N: usize, M: VehicleModel<N>>(
    slot: &'p mut Option<Pending<N>>,
    model: &M,
    env: &Environment,
    lag: bool,
    x: &SVector<f64, N>,
    u: &Inputs,
    record: bool,
    contacts: Option<&mut [TyreContact]>,
) -> &'p mut Pending<N> {
    if let Some(l) = model.lags().filter(|_| lag) {
        let (body, inputs) = l.lag_split(x, u, env, contacts);
        let rates = l.lag_rates(x, u, env);
        let mut k1 = body;
        for (j, &i) in l.lag_states().iter().enumerate() {
            if rates[j] > 0.0 {
                k1[i] = rates[j] * (inputs[j] - x[i]);
            }
        }
        let row = record.then(|| blank_row(model.observe(x, u, env)));
        return slot.insert(Pending { first: FirstStage::Lag { body, inputs, rates }, k1, row });
    }
    let p = slot.insert(Pending {
        first: FirstStage::Derivative(SVector::zeros()),
        k1: SVector::zeros(),
        row: record.then(|| blank_row(Observation::default())),
    });
    let k1 = model.evaluate(x, u, env, Extras { observation: p.row.as_mut().map(|r| &mut r.obs), contacts });
    p.first = if lag {
        FirstStage::Lag { body: k1, inputs: [0.0; MAX_LAGS], rates: [0.0; MAX_LAGS] }
    } else {
        FirstStage::Derivative(k1)
    };
    p.k1 = k1;
    p
}

/// The stages of one step as the integrator sees them ([`Problem`]): the model's derivative under
/// the inputs at each stage's time (those at the step's middle computed once, for RK4's k2 and
/// k3), and the model's spin-slip pairs and lags.
struct Stages<'s, 'a, const N: usize, M: VehicleModel<N>> {
    sim: &'s Simulation<'a, N, M>,
    mid: (f64, Inputs),
}

impl<const N: usize, M: VehicleModel<N>> Stages<'_, '_, N, M> {
    #[inline]
    fn inputs(&self, ts: f64) -> Inputs {
        if ts == self.mid.0 {
            self.mid.1
        } else {
            self.sim.inputs_at(ts)
        }
    }
}

impl<const N: usize, M: VehicleModel<N>> Problem<N> for Stages<'_, '_, N, M> {
    #[inline(always)]
    fn rhs(&self, ts: f64, x: &SVector<f64, N>) -> SVector<f64, N> {
        self.sim.model.derivatives(x, &self.inputs(ts), &self.sim.env)
    }

    fn spin_slip(&self) -> Option<crate::vehicle::capability::SpinSlip> {
        self.sim.model.spin_slip()
    }

    fn lag_states(&self) -> &[usize] {
        self.sim.model.lags().map_or(&[], |l| l.lag_states())
    }

    fn lag_split(&self, ts: f64, x: &SVector<f64, N>) -> (SVector<f64, N>, [f64; MAX_LAGS]) {
        match self.sim.model.lags() {
            Some(l) => l.lag_split(x, &self.inputs(ts), &self.sim.env, None),
            None => (self.rhs(ts, x), [0.0; MAX_LAGS]),
        }
    }
}

/// One run in progress: the steppable engine (see the module docs).
pub struct Simulation<'a, const N: usize, M: VehicleModel<N>> {
    model: &'a M,
    env: Environment,
    maneuver: &'a mut dyn Maneuver,
    contact: &'a mut dyn ContactTemperature,
    controls: &'a Controls,
    observer: &'a mut dyn Observer,
    method: Method,
    /// Step and control period, s.
    h: f64,
    hc: f64,
    n_steps: u64,
    out_every: u64,
    ctrl_every: u64,
    x: SVector<f64, N>,
    /// Inputs at the current instant (the ramps' values at the last step's start).
    u: Inputs,
    /// The control period's ramps: time of its start, s, and the inputs at its start and end
    /// (steer, signed wheel torque: drive positive, and the contact temperatures).
    ramp_t0: f64,
    ramp_from: Ramped,
    ramp_to: Ramped,
    /// The coming step's first stage, computed by the controller sample for its prediction.
    pending: Option<Pending<N>>,
    /// Whether a spin-out ends the run: not for a model with prescribed components (the
    /// discovery replay follows a measured run to its end whatever its sideslip).
    spin_out: bool,
    pid: Pid,
    pid_active: bool,
    contacts: [TyreContact; 4],
    temps: [f64; 4],
    events: Vec<Event>,
    watch: Watch,
    st: Stats,
    spin_dir: (f64, f64),
    k: u64,
    /// The distance travelled at the last control sample, m, and the forward speed then, m/s.
    travelled: (f64, f64),
    /// Time and speed target of the last row recorded, s and m/s.
    last_row: Option<(f64, f64)>,
    speed_target: f64,
    /// The driver's steer command at the last sample (for the end of the period ahead), rad.
    steer_cmd: Option<f64>,
    path_error: Option<f64>,
    end: Option<EndReason>,
    /// Inputs set from outside the engine ([`Self::set_external`]); none by default.
    external: ExternalInputs,
    /// ABS and traction control, when the run has them ([`super::slip_control`]).
    slip: Option<super::slip_control::SlipControl>,
}

impl<'a, const N: usize, M: VehicleModel<N>> Simulation<'a, N, M> {
    /// Set up a run of `model` through `maneuver` from the manoeuvre's start (no step taken yet).
    pub fn new(
        model: &'a M,
        env: Environment,
        maneuver: &'a mut dyn Maneuver,
        contact: &'a mut dyn ContactTemperature,
        controls: &'a Controls,
        settings: &SimSettings,
        observer: &'a mut dyn Observer,
    ) -> Self {
        let h = settings.step_s;
        let n_steps = ((settings.duration_s / h) - 1e-9).ceil().max(0.0) as u64;
        let out_every = ((settings.output_interval_s / h).round() as u64).max(1);
        let ctrl_every = ((settings.control_period_s / h).round() as u64).max(1);
        let start = maneuver.start();
        let x = model.initial_state(start.x_m, start.y_m, start.yaw_rad, start.speed_mps);
        let mut pid = Pid::new(controls.pid, -controls.brake_max_nm, controls.drive_max_nm);
        pid.preload(controls.preload_nm);
        let u = Inputs { contact_temp_c: [env.surface_temp_c; 4], ..Inputs::default() };
        let mut events = Vec::new();
        let mut watch = Watch::default();
        watch.check(model, &x, &u, &env, 0.0, &mut events);
        let (spin_sin, spin_cos) = SPIN_OUT_SIDESLIP_RAD.sin_cos();
        // The PID starts preloaded: its output at zero error is the preload torque.
        let preload = controls.preload_nm.clamp(-controls.brake_max_nm, controls.drive_max_nm);
        let start_inputs =
            Ramped { steer_rad: 0.0, torque_nm: preload, contact_temp_c: [env.surface_temp_c; 4], distance_m: 0.0 };
        Self {
            model,
            env,
            maneuver,
            contact,
            controls,
            observer,
            method: settings.method,
            h,
            hc: ctrl_every as f64 * h,
            n_steps,
            out_every,
            ctrl_every,
            x,
            u,
            ramp_t0: 0.0,
            ramp_from: start_inputs,
            ramp_to: start_inputs,
            pending: None,
            spin_out: model.prescribed().is_none(),
            pid,
            pid_active: true,
            contacts: [TyreContact { surface_temp_c: env.surface_temp_c, ..TyreContact::default() }; 4],
            temps: [env.surface_temp_c; 4],
            events,
            watch,
            travelled: (0.0, 0.0),
            st: Stats {
                peak_r: 0.0,
                peak_beta_dir: (1.0, 0.0),
                peak_ay: 0.0,
                max_dev: None,
                vmin: f64::INFINITY,
                vmax: 0.0,
                max_verr: None,
            },
            spin_dir: (spin_cos, spin_sin),
            k: 0,
            last_row: None,
            speed_target: f64::NAN,
            steer_cmd: None,
            path_error: None,
            end: None,
            external: ExternalInputs::default(),
            slip: None,
        }
    }

    /// Give the run ABS and/or traction control ([`super::slip_control`]), before the first step.
    pub fn with_slip_control(mut self, params: &super::slip_control::SlipControlParams) -> Self {
        if !params.is_off() {
            self.slip = Some(super::slip_control::SlipControl::new(params, self.h, self.controls.drive_max_nm));
        }
        self
    }

    /// Current time, s.
    pub fn time_s(&self) -> f64 {
        self.k as f64 * self.h
    }

    /// Current state.
    pub fn state(&self) -> &SVector<f64, N> {
        &self.x
    }

    /// Inputs at the start of the last step taken (the controller ramps' values then; the steer
    /// of an open-loop profile is the profile's value then).
    pub fn inputs(&self) -> &Inputs {
        &self.u
    }

    /// Events so far.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// Why the run ended, once it has.
    pub fn end_reason(&self) -> Option<EndReason> {
        self.end
    }

    /// Replace the manoeuvre's steer and the speed controller's torque, from the next step on,
    /// by the values set in `e` (held over every step until set again; see
    /// the spec layer's step API). The controllers keep sampling; their outputs are not applied.
    pub fn set_external(&mut self, e: ExternalInputs) {
        self.external = e;
    }

    /// The inputs the next step starts from (the ramps' values now, with the external inputs).
    pub fn inputs_now(&self) -> Inputs {
        self.inputs_at(self.time_s())
    }

    /// The manoeuvre being driven (its verdict so far, its path error).
    pub fn maneuver(&self) -> &dyn Maneuver {
        &*self.maneuver
    }

    /// The speed controller's target at its last sample, m/s (NaN while it is off).
    pub fn speed_target_mps(&self) -> f64 {
        self.speed_target
    }

    /// Advance one step; returns why the run ended if it did (then further calls do nothing and
    /// return the same reason).
    pub fn step(&mut self) -> Option<EndReason> {
        if self.end.is_some() {
            return self.end;
        }
        if self.k >= self.n_steps {
            self.end = Some(EndReason::Duration);
            return self.end;
        }
        let t = self.time_s();
        let kin = self.model.kinematics(&self.x);
        let record = self.k % self.out_every == 0;
        if self.slip.is_some() {
            self.sample_slip_control(t);
        }
        if self.k % self.ctrl_every == 0 {
            self.sample_controls(t, record);
        }
        let next = self.advance(t, &kin, record);
        self.k += 1;
        self.end = self.check_end(next, &kin);
        self.end
    }

    /// The inputs at time `ts` within the current control period: the ramps, and an open-loop
    /// steer profile's value at `ts` where the manoeuvre prescribes one, and the slip
    /// controllers' caps.
    #[inline]
    fn inputs_at(&self, ts: f64) -> Inputs {
        let mut u = Ramped::lerp(&self.ramp_from, &self.ramp_to, (ts - self.ramp_t0) / self.hc);
        u.t_s = ts;
        if let Some(d) = self.maneuver.steer_at(ts) {
            let lock = self.controls.steer_max_rad;
            u.steer_rad = d.clamp(-lock, lock);
        }
        self.external.apply(&mut u);
        if let Some(s) = &self.slip {
            s.apply(ts, &mut u);
        }
        u
    }

    /// The slip controllers due at this step sample the wheels at time `t`.
    fn sample_slip_control(&mut self, t: f64) {
        let u = self.inputs_at(t);
        let mut wheels = [crate::vehicle::WheelSensor::default(); 4];
        let n = self.model.wheel_speeds().map_or(0, |w| w.wheel_sensors(&self.x, u.steer_rad, &mut wheels));
        if let Some(s) = &mut self.slip {
            s.sample(self.k, t, &wheels[..n], &u);
        }
    }

    /// Phase 1: the contact-temperature estimate at time `t`, then the manoeuvre and the PID
    /// from the state predicted one control period ahead; ramp their outputs across the period
    /// (see the module docs). The derivative at `t` the prediction needs is the coming step's
    /// first stage: it is kept for [`Self::advance`] (with the observation when `record`).
    fn sample_controls(&mut self, t: f64, record: bool) {
        let hc = self.hc;
        let mut u0 = self.commanded_inputs(t);
        let vx_now = self.model.kinematics(&self.x).vx_mps;
        u0.distance_m = self.distance_at_sample(vx_now);
        let previous = self.temps;
        let evaluated = self.estimate_contact(&u0, &previous, record);
        u0.contact_temp_c = self.temps;
        let x_end = self.state_one_period_ahead(&u0, evaluated, record);
        let kin = self.model.kinematics(&x_end);
        let cmd = self.maneuver.command(t + hc, &kin);
        let from = Ramped { contact_temp_c: u0.contact_temp_c, distance_m: u0.distance_m, ..self.ramp_to };
        let steer = self.steer_command(t + hc, from.steer_rad, cmd.steer_rad);
        let torque = self.torque_command(t + hc, cmd.speed_target_mps, kin.vx_mps);
        let ahead = self.contact_ahead(from.contact_temp_c, &previous);
        let to = Ramped {
            steer_rad: steer,
            torque_nm: torque,
            contact_temp_c: ahead,
            distance_m: u0.distance_m + hc * vx_now,
        };
        (self.ramp_t0, self.ramp_from, self.ramp_to) = (t, from, to);
        self.path_error = self.maneuver.path_error_m();
        if let Some(e) = self.path_error {
            self.st.max_dev = max_opt(self.st.max_dev, e.abs());
        }
    }

    /// The distance travelled at this sample, m: the last sample's plus the trapezoid of the
    /// forward speed over the period behind (0 at the first sample); `vx_now` the speed now, m/s.
    fn distance_at_sample(&mut self, vx_now: f64) -> f64 {
        let d = if self.k == 0 { 0.0 } else { self.travelled.0 + 0.5 * self.hc * (self.travelled.1 + vx_now) };
        self.travelled = (d, vx_now);
        d
    }

    /// The inputs at sample time `t`: the end of the previous ramps (the start's values at the
    /// first sample), the manoeuvre's prescribed steer, the external inputs and the slip
    /// controllers' torque changes.
    fn commanded_inputs(&self, t: f64) -> Inputs {
        let c = self.controls;
        let u0 = Inputs { t_s: t, ..Ramped::lerp(&self.ramp_from, &self.ramp_to, 1.0) };
        let mut u0 = match self.maneuver.steer_at(t) {
            Some(d) => Inputs { steer_rad: d.clamp(-c.steer_max_rad, c.steer_max_rad), ..u0 },
            None => u0,
        };
        self.external.apply(&mut u0);
        if let Some(s) = &self.slip {
            s.apply(t, &mut u0);
        }
        u0
    }

    /// The contact-temperature estimate at the sample time of `u0`, advanced over the period
    /// behind from `previous` (the estimate at the last sample; none at the first sample) and the
    /// tyres' conditions then, taken at the contact temperatures it returns (the friction force
    /// depends on them: `update_coupled` solves for the consistent estimate); left in
    /// `self.temps`. Each evaluation of the conditions is a full
    /// evaluation of the model; the last one, at the accepted temperatures, is the coming step's
    /// first stage (in `pending_k1`). Returns the temperatures of that last evaluation (`None`
    /// under [`Method::Rk4Lag`], whose conditions evaluate no derivative).
    fn estimate_contact(&mut self, u0: &Inputs, previous: &[f64; 4], record: bool) -> Option<[f64; 4]> {
        let (model, env, x) = (self.model, &self.env, &self.x);
        let lag = self.method == Method::Rk4Lag;
        let mut evaluated: Option<[f64; 4]> = None;
        let pending = &mut self.pending;
        let mut conditions = |temps: &[f64], out: &mut [TyreContact]| {
            let mut u = *u0;
            u.contact_temp_c[..temps.len()].copy_from_slice(temps);
            first_stage(pending, model, env, lag, x, &u, record, Some(out));
            evaluated = Some(u.contact_temp_c);
        };
        let n = M::TYRES;
        let h_behind = if self.k == 0 { 0.0 } else { self.hc };
        self.contact.update_coupled(
            h_behind,
            &previous[..n],
            &mut conditions,
            &mut self.contacts[..n],
            &mut self.temps[..n],
        );
        evaluated
    }

    /// x(t + T_c) along the tangent at t (second order, like the ramp), with the first stage of
    /// the coming step left in `pending_k1`. Not the quadratic through the previous sample
    /// (x_{k-1} + 2 T_c k1, third order): that leapfrog extrapolation has a parasitic mode, which
    /// the driver loop turned into a 1 m/s^2 lateral oscillation at 10 ms on the 4-DOF model's
    /// slow constant-radius runs. Under [`Method::Rk4Lag`] the lag components follow their exact
    /// relaxation towards their inputs at t instead (a tangent would overshoot a lag faster than
    /// 1 / T_c). `evaluated`: the temperatures of the contact estimate's last evaluation.
    fn state_one_period_ahead(&mut self, u0: &Inputs, evaluated: Option<[f64; 4]>, record: bool) -> SVector<f64, N> {
        let (hc, n) = (self.hc, M::TYRES);
        // the last evaluation is the first stage when it was at the estimate (bit for bit)
        let at_estimate =
            evaluated.is_some_and(|e| e[..n].iter().zip(&self.temps[..n]).all(|(p, q)| p.to_bits() == q.to_bits()));
        if !at_estimate || self.pending.is_none() {
            let lag = self.method == Method::Rk4Lag;
            first_stage(&mut self.pending, self.model, &self.env, lag, &self.x, u0, record, None);
        }
        let Some(p) = &self.pending else { return self.x };
        match &p.first {
            FirstStage::Derivative(k1) => self.x + k1 * hc,
            FirstStage::Lag { body, inputs, rates } => {
                let mut x_end = self.x + body * hc;
                let lags = self.model.lags().map_or(&[][..], |l| l.lag_states());
                for (j, &i) in lags.iter().enumerate() {
                    if rates[j] > 0.0 {
                        x_end[i] = relax(self.x[i], inputs[j], inputs[j], rates[j] * hc);
                    }
                }
                x_end
            }
        }
    }

    /// The steer at the end of the coming period, rad: the manoeuvre's prescribed angle, or the
    /// driver's command `cmd_rad` rate-limited from `from_rad` (the ramp's start).
    fn steer_command(&mut self, t_end: f64, from_rad: f64, cmd_rad: f64) -> f64 {
        let c = self.controls;
        let steer = match self.maneuver.steer_at(t_end) {
            Some(d) => d.clamp(-c.steer_max_rad, c.steer_max_rad),
            None => {
                let c0 = self.steer_cmd.unwrap_or(cmd_rad);
                rate_limited_steer(from_rad, c0, cmd_rad, c.steer_max_rad, c.steer_rate_max_radps, self.hc)
            }
        };
        self.steer_cmd = Some(cmd_rad);
        steer
    }

    /// The wheel torque at the end of the coming period, N m (drive > 0, brake < 0): the
    /// manoeuvre's pedal (full throttle or brake: launch, braking), else the speed controller
    /// tracking `target_mps` from the forward speed `vx_mps` one period ahead, else none (coasting).
    fn torque_command(&mut self, t_end: f64, target_mps: Option<f64>, vx_mps: f64) -> f64 {
        let c = self.controls;
        match (self.maneuver.pedal(t_end), target_mps) {
            (Some(p), target) => {
                self.pid_active = false;
                self.speed_target = target.unwrap_or(f64::NAN);
                if p >= 0.0 {
                    p.min(1.0) * c.drive_max_nm
                } else {
                    p.max(-1.0) * c.brake_max_nm
                }
            }
            (None, Some(v)) => {
                if !self.pid_active {
                    self.pid.reset();
                    self.pid_active = true;
                }
                self.st.max_verr = max_opt(self.st.max_verr, (v - vx_mps).abs());
                self.speed_target = v;
                self.pid.update(v, vx_mps, self.hc)
            }
            (None, None) => {
                self.pid_active = false;
                self.speed_target = f64::NAN;
                0.0
            }
        }
    }

    /// The contact temperatures at t + T_c, degC: the estimate `now` carried on by its change
    /// over the period behind (from `previous`; held at the first sample), not past melting
    /// (second order in T_c, like the ramp; the next sample replaces it by the estimate at the
    /// state reached).
    fn contact_ahead(&self, now: [f64; 4], previous: &[f64; 4]) -> [f64; 4] {
        let mut ahead = now;
        if self.k > 0 {
            for (a, p) in ahead.iter_mut().zip(previous) {
                let e = *a + (*a - p);
                if e.is_finite() {
                    *a = e.min(MELT_C.max(*a));
                }
            }
        }
        ahead
    }

    /// Phase 2: one integration step from time `t` (the state's kinematics `kin`), recording the
    /// step's start as an output row first when `record` (the row's observation comes from the
    /// same model evaluation as the first stage, k1, computed by the controller sample when there
    /// was one); the inputs at every stage are the ramps' values at the stage time; updates the running figures of the step's
    /// start. Returns the new state or why the solver gave up.
    fn advance(&mut self, t: f64, kin: &Kinematics, record: bool) -> Result<SVector<f64, N>, String> {
        // The environment and the pending first stage (with its row) are read in place: moving
        // them (a few hundred bytes each) cost a memory copy each per step.
        let (model, h) = (self.model, self.h);
        let inputs = self.inputs_at(t);
        let lag = self.method == Method::Rk4Lag;
        let pending = match &mut self.pending {
            Some(p) if p.row.is_some() || !record => p,
            slot => first_stage(slot, model, &self.env, lag, &self.x, &inputs, record, None),
        };
        let k1 = pending.k1;
        if let Some(row) = &mut pending.row {
            row.t_s = t;
            row.inputs = inputs;
            row.speed_target_mps = self.speed_target;
            row.path_error_m = self.path_error.unwrap_or(f64::NAN);
            self.observer.record(row);
            self.last_row = Some((row.t_s, row.speed_target_mps));
        }
        self.u = inputs;
        let stages = Stages { sim: &*self, mid: (t + 0.5 * h, self.inputs_at(t + 0.5 * h)) };
        // (always filled above; the next step's first stage is evaluated afresh)
        let next = match &self.pending {
            Some(p) => self.method.step(&stages, t, &self.x, h, &p.first),
            None => Err("the step's first stage was not evaluated".to_string()),
        };
        self.pending = None;
        let st = &mut self.st;
        let (_, ay) = model.body_acceleration(&self.x, &k1);
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
        next
    }

    /// Phase 3: accept the new state (or end the run on divergence) and apply the end rules; `kin0`
    /// is the kinematics at the start of the step.
    fn check_end(&mut self, next: Result<SVector<f64, N>, String>, kin0: &Kinematics) -> Option<EndReason> {
        let t_next = self.time_s();
        let next = next.map(|mut n| {
            if let Some(p) = self.model.prescribed() {
                p.project(t_next, &mut n);
            }
            n
        });
        let next = match next {
            Ok(n) if n.iter().all(|v| v.is_finite()) => n,
            Ok(n) => {
                let names = self.model.state_names();
                let bad: Vec<&str> =
                    n.iter().zip(names.iter()).filter(|(v, _)| !v.is_finite()).map(|(_, s)| *s).collect();
                self.events.push(Event {
                    t_s: t_next,
                    kind: EventKind::Diverged,
                    detail: format!("non-finite state: {}", bad.join(", ")),
                });
                return Some(EndReason::Diverged);
            }
            Err(msg) => {
                self.events.push(Event { t_s: t_next, kind: EventKind::Diverged, detail: msg });
                return Some(EndReason::Diverged);
            }
        };
        self.x = next;
        self.watch.check(self.model, &self.x, &self.u, &self.env, t_next, &mut self.events);
        let kin = self.model.kinematics(&self.x);
        let (cx, sy) = self.spin_dir;
        if self.spin_out && kin.speed_mps() > SPIN_OUT_MIN_SPEED_MPS && wider(kin.vx_mps, kin.vy_mps.abs(), cx, sy) {
            // The crossing of 60 degrees, interpolated linearly in the cross product within the step.
            let g = |k: &Kinematics| cx * k.vy_mps.abs() - sy * k.vx_mps;
            let (g0, g1) = (g(kin0), g(&kin));
            let frac = if g0 < 0.0 && g1 > g0 { g0 / (g0 - g1) } else { 1.0 };
            self.events.push(Event {
                t_s: t_next - (1.0 - frac) * self.h,
                kind: EventKind::SpinOut,
                detail: format!("sideslip {:.1} deg exceeds 60 deg", kin.sideslip_rad().to_degrees()),
            });
            return Some(EndReason::SpinOut);
        }
        if self.maneuver.after_step(t_next, &kin, &mut self.events) {
            return Some(EndReason::Completed);
        }
        None
    }

    /// Record the final state (the inputs of the last step are kept for reference) and return the
    /// run's summary.
    pub fn finish(mut self) -> Summary {
        let end_reason = self.end.unwrap_or(EndReason::Duration);
        let t_end = self.time_s();
        // A completed manoeuvre's end time is interpolated within the last step; a spin-out's is
        // its event's (the state recorded is the one at the end of that step).
        let end_time_s = match end_reason {
            EndReason::Completed => self.maneuver.end_time_s().unwrap_or(t_end),
            EndReason::SpinOut => self.events.last().map_or(t_end, |e| e.t_s),
            _ => t_end,
        };
        let kin = self.model.kinematics(&self.x);
        if self.x.iter().all(|v| v.is_finite()) && self.last_row.is_none_or(|(t, _)| t < t_end) {
            let row = Row {
                t_s: t_end,
                obs: self.model.observe(&self.x, &self.u, &self.env),
                inputs: self.u,
                speed_target_mps: self.last_row.map_or(f64::NAN, |(_, v)| v),
                path_error_m: self.maneuver.path_error_m().unwrap_or(f64::NAN),
            };
            self.observer.record(&row);
            self.st.vmin = self.st.vmin.min(kin.speed_mps());
            self.st.vmax = self.st.vmax.max(kin.speed_mps());
        }
        let outcome = self.maneuver.outcome();
        let st = &self.st;
        Summary {
            passed: if end_reason.failed() { outcome.passed.map(|_| false) } else { outcome.passed },
            cones_hit: outcome.cones_hit,
            peak_yaw_rate_radps: st.peak_r,
            peak_sideslip_rad: st.peak_beta_dir.1.atan2(st.peak_beta_dir.0),
            peak_ay_mps2: st.peak_ay,
            max_path_deviation_m: st.max_dev,
            min_speed_mps: if st.vmin.is_finite() { st.vmin } else { 0.0 },
            max_speed_mps: st.vmax,
            max_speed_error_mps: st.max_verr,
            steps: self.k,
            end_time_s,
            end_reason,
            events: self.events,
            plausible: true,
            implausible: Vec::new(),
        }
    }
}

/// Run one simulation of `model` through `maneuver`: step until the run ends, then finish.
pub fn simulate<const N: usize, M: VehicleModel<N>>(
    model: &M,
    env: Environment,
    maneuver: &mut dyn Maneuver,
    contact: &mut dyn ContactTemperature,
    controls: &Controls,
    settings: &SimSettings,
    observer: &mut dyn Observer,
) -> Summary {
    simulate_with_slip_control(model, env, maneuver, contact, controls, settings, observer, &Default::default())
}

/// [`simulate`] with the slip controllers `slip` (ABS, traction control).
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate_with_slip_control<const N: usize, M: VehicleModel<N>>(
    model: &M,
    env: Environment,
    maneuver: &mut dyn Maneuver,
    contact: &mut dyn ContactTemperature,
    controls: &Controls,
    settings: &SimSettings,
    observer: &mut dyn Observer,
    slip: &super::slip_control::SlipControlParams,
) -> Summary {
    let mut sim = Simulation::new(model, env, maneuver, contact, controls, settings, observer).with_slip_control(slip);
    while sim.step().is_none() {}
    sim.finish()
}
