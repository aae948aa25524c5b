//! Manoeuvres: what the driver is asked to do (steer and speed commands), when the run is over,
//! and the manoeuvre's own pass/fail rule. A manoeuvre sees the vehicle's kinematics only.

pub mod brake_in_turn;
pub mod constant_radius;
pub mod iso3888_2;
pub mod longitudinal;
pub mod open_loop;
pub mod path;
pub mod steady_state;

use serde::Serialize;

use crate::vehicle::Kinematics;

/// What the manoeuvre asks of the vehicle for the next step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Desired road-wheel steer angle, rad (the engine applies the steering limits).
    pub steer_rad: f64,
    /// Speed target for the PID, m/s; `None` releases the throttle and brake (coasting).
    pub speed_target_mps: Option<f64>,
}

/// Something that happened during a run, with its time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Time, s.
    pub t_s: f64,
    /// What happened (serialised in snake case: `cone_strike`, `spin_out`, ...).
    pub kind: EventKind,
    /// Human-readable detail (which gate and side, which state went non-finite, ...).
    pub detail: String,
}

/// The kinds of [`Event`], serialised (summary.json) as their snake-case names ([`EventKind::as_str`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EventKind {
    /// ISO 3888-2: the car left the course's exit (the manoeuvre's end).
    CourseComplete,
    /// ISO 3888-2: a gate boundary (cone line) was struck.
    ConeStrike,
    /// Constant radius: one more lap of the circle.
    LapComplete,
    /// Constant radius: the car left the circle beyond the path tolerance.
    LeftPath,
    /// The state became non-finite or the adaptive solver gave up.
    Diverged,
    /// |sideslip| exceeded the spin-out limit.
    SpinOut,
    /// A watched condition flapped too often; its further events are not reported.
    EventsSuppressed,
    /// 4-DOF model: a wheel's normal load reached zero, and its return.
    WheelLift,
    WheelContact,
    /// 4-DOF model: a normal load went negative before clamping, and its return.
    NegativeNormalLoad,
    NormalLoadRestored,
    /// Plausibility: a tyre force beyond the friction limit, and its return.
    TyreForceBeyondFriction,
    TyreForceWithinFriction,
    /// Plausibility: lateral acceleration beyond mu g, and its return.
    AyBeyondFriction,
    AyWithinFriction,
    /// Plausibility: the car beyond the path tolerance, and its return.
    PathExit,
    PathReturn,
    /// The contact-temperature model could not be built; the run went on isothermal.
    ContactModelUnavailable,
    /// Thermal Dugoff: the published temperature factor would reverse F_x; it was clamped.
    ThermalFactorClamped,
    /// Plausibility by the tyre's range: an axle's slip ratio left the tyre file's declared
    /// range, and its return; likewise the slip angle and a wheel's normal load.
    SlipRatioBeyondRange,
    SlipRatioWithinRange,
    SlipAngleBeyondRange,
    SlipAngleWithinRange,
    LoadBeyondRange,
    LoadWithinRange,
}

impl EventKind {
    /// The serialised name.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::CourseComplete => "course_complete",
            EventKind::ConeStrike => "cone_strike",
            EventKind::LapComplete => "lap_complete",
            EventKind::LeftPath => "left_path",
            EventKind::Diverged => "diverged",
            EventKind::SpinOut => "spin_out",
            EventKind::EventsSuppressed => "events_suppressed",
            EventKind::WheelLift => "wheel_lift",
            EventKind::WheelContact => "wheel_contact",
            EventKind::NegativeNormalLoad => "negative_normal_load",
            EventKind::NormalLoadRestored => "normal_load_restored",
            EventKind::TyreForceBeyondFriction => "tyre_force_beyond_friction",
            EventKind::TyreForceWithinFriction => "tyre_force_within_friction",
            EventKind::AyBeyondFriction => "ay_beyond_friction",
            EventKind::AyWithinFriction => "ay_within_friction",
            EventKind::PathExit => "path_exit",
            EventKind::PathReturn => "path_return",
            EventKind::ContactModelUnavailable => "contact_model_unavailable",
            EventKind::ThermalFactorClamped => "thermal_factor_clamped",
            EventKind::SlipRatioBeyondRange => "slip_ratio_beyond_range",
            EventKind::SlipRatioWithinRange => "slip_ratio_within_range",
            EventKind::SlipAngleBeyondRange => "slip_angle_beyond_range",
            EventKind::SlipAngleWithinRange => "slip_angle_within_range",
            EventKind::LoadBeyondRange => "load_beyond_range",
            EventKind::LoadWithinRange => "load_within_range",
        }
    }

    /// The onsets of the friction checks: a result beyond what the surface can carry.
    pub fn beyond_friction(self) -> bool {
        matches!(self, EventKind::TyreForceBeyondFriction | EventKind::AyBeyondFriction)
    }
}

named_by_as_str!(EventKind);

/// A manoeuvre's verdict at the end of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Outcome {
    /// Pass/fail where the manoeuvre has a rule (ISO 3888-2: no cone hit), else `None`.
    pub passed: Option<bool>,
    /// Number of distinct gate boundaries struck.
    pub cones_hit: usize,
}

/// Starting pose and speed: CG position (m), yaw (rad) and forward speed (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    pub x_m: f64,
    pub y_m: f64,
    pub yaw_rad: f64,
    pub speed_mps: f64,
}

/// A time window over which a manoeuvre expects the vehicle to be in a steady state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SteadyWindow {
    /// Step number, from 1.
    pub step: usize,
    /// Window start and end, s.
    pub t0_s: f64,
    pub t1_s: f64,
    /// Speed target of the step, m/s.
    pub speed_target_mps: f64,
    /// Nominal lateral acceleration v^2 / R of the step (signed: left positive), m/s^2.
    pub nominal_ay_mps2: f64,
}

/// A manoeuvre, driven by the engine: commands once per control period, checks once per step.
pub trait Maneuver: Send {
    /// Where and how fast the vehicle starts.
    fn start(&self) -> Start;
    /// Command for the end of the coming control period: the engine passes that instant as `t` and
    /// the kinematics predicted for it as `kin`, and ramps the inputs to the command across the
    /// period (see [`crate::sim::engine`]).
    fn command(&mut self, t: f64, kin: &Kinematics) -> Command;
    /// The steer angle as a known function of time, rad, where the manoeuvre prescribes one
    /// (open loop; already within the steering rate limit): the engine then evaluates it at every
    /// integration stage instead of ramping to [`Command::steer_rad`] across the control period.
    /// `None` (the default) for feedback steering.
    fn steer_at(&self, _t: f64) -> Option<f64> {
        None
    }
    /// Full throttle (+1) or full brake (-1), or a fraction of either, at time `t`, where the
    /// manoeuvre asks for the pedal itself (launch, braking) instead of a speed for the PID;
    /// `None` (the default): the PID follows [`Command::speed_target_mps`].
    fn pedal(&self, _t: f64) -> Option<f64> {
        None
    }
    /// Signed lateral deviation of the CG from the reference path at the last command, m
    /// (`None` for open-loop manoeuvres).
    fn path_error_m(&self) -> Option<f64>;
    /// Called after each step with the new kinematics; pushes events; returns true when the
    /// manoeuvre is complete and the run should stop.
    fn after_step(&mut self, t: f64, kin: &Kinematics, events: &mut Vec<Event>) -> bool;
    /// Verdict so far.
    fn outcome(&self) -> Outcome;

    /// Once [`Maneuver::after_step`] has ended the run: the time within the last step at which
    /// the end condition was met, interpolated, s (`None`: the end of the step).
    fn end_time_s(&self) -> Option<f64> {
        None
    }

    /// The course for plots (gates, reference path, body outline), as JSON; `None` if there is none.
    fn layout(&self) -> Option<serde_json::Value> {
        None
    }

    /// Why the manoeuvre ended the run when that is not plain completion (e.g. `left_path`);
    /// `None` by default.
    fn end_reason(&self) -> Option<crate::sim::EndReason> {
        None
    }

    /// The manoeuvre's own result figures for `summary.json`'s `results` (braking distance,
    /// launch time, ...); `None` (the default) writes nothing.
    fn results(&self) -> Option<serde_json::Value> {
        None
    }

    /// Steady-state windows the run's rows are averaged over afterwards (none by default).
    fn steady_state_windows(&self) -> Vec<SteadyWindow> {
        Vec::new()
    }
}
