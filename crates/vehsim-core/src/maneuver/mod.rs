//! Manoeuvres: what the driver is asked to do (steer and speed commands), when the run is over,
//! and the manoeuvre's own pass/fail rule. A manoeuvre sees the vehicle's kinematics only.

pub mod brake_in_turn;
pub mod constant_radius;
pub mod iso3888_2;
pub mod longitudinal;
pub mod open_loop;

use crate::event::Event;

use crate::vehicle::Kinematics;

/// What the manoeuvre asks of the vehicle for the next step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Desired road-wheel steer angle, rad (the engine applies the steering limits).
    pub steer_rad: f64,
    /// Speed target for the PID, m/s; `None` releases the throttle and brake (coasting).
    pub speed_target_mps: Option<f64>,
}

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
    /// Ground-frame X of the CG, m.
    pub x_m: f64,
    /// Ground-frame Y of the CG, m (positive left).
    pub y_m: f64,
    /// Yaw angle, rad, counter-clockwise from the ground x axis.
    pub yaw_rad: f64,
    /// Forward speed, m/s (the wheels start rolling at it).
    pub speed_mps: f64,
}

/// A time window over which a manoeuvre expects the vehicle to be in a steady state.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SteadyWindow {
    /// Step number, from 1.
    pub step: usize,
    /// Window start and end, s.
    pub t0_s: f64,
    /// Window end, s.
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
    #[cfg(feature = "serde")]
    fn layout(&self) -> Option<serde_json::Value> {
        None
    }

    /// Why the manoeuvre ended the run when that is not plain completion (e.g. `left_path`);
    /// `None` by default.
    fn end_reason(&self) -> Option<crate::event::EndReason> {
        None
    }

    /// The manoeuvre's own result figures for `summary.json`'s `results` (braking distance,
    /// launch time, ...); `None` (the default) writes nothing.
    #[cfg(feature = "serde")]
    fn results(&self) -> Option<serde_json::Value> {
        None
    }

    /// Steady-state windows the run's rows are averaged over afterwards (none by default).
    fn steady_state_windows(&self) -> Vec<SteadyWindow> {
        Vec::new()
    }
}
