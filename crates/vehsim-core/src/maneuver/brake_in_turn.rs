//! Braking in a turn (after ISO 7975): steady driving on a circle at a held speed with the
//! path-following driver, then, at `brake_at_s`, the steering held at its last command and the
//! brake pedal applied at a fixed fraction of its stop until the car stops (or `after_s` has
//! passed). The yaw response to the braking is the result.
//!
//! ISO 7975 brakes from steady-state circular driving with the steering wheel held fixed and
//! reports the yaw rate and the lateral acceleration at fixed times after the brake onset
//! relative to their values at the onset; here, in `summary.json`'s `results`: the yaw rate,
//! the sideslip and the speed at the onset, and at 1 s after it (ISO 7975's main instant) the
//! yaw rate, its ratio to the onset's, the sideslip, the heading change since the onset (rad,
//! signs ISO 8855: positive left) and the CG's deviation from the circle (m, positive outside).
//! The circle phase is [`ConstantRadius`] with one held speed; its own end rule (the car leaving
//! the circle) applies only before the onset.

#[cfg(feature = "serde")]
use serde_json::json;

use super::constant_radius::{ConstantRadius, ConstantRadiusParams};
use super::{Command, Maneuver, Outcome, Start};
use crate::control::DriverParams;
use crate::event::Event;
use crate::vehicle::Kinematics;

/// Parameters (validated by the spec layer).
#[derive(Debug, Clone, PartialEq)]
pub struct BrakeInTurnParams {
    /// The circle phase: radius, direction, one held speed (settle_s is the time on the circle).
    pub circle: ConstantRadiusParams,
    /// Brake onset, s.
    pub brake_at_s: f64,
    /// Pedal fraction of its stop, (0, 1].
    pub brake_fraction: f64,
    /// Longest time after the onset, s.
    pub after_s: f64,
}

/// What the result needs at an instant (read by `results`, which comes with the `serde` feature).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
struct Snap {
    t: f64,
    yaw_rate: f64,
    sideslip: f64,
    speed: f64,
    yaw: f64,
    radial: f64,
}

/// The manoeuvre.
pub struct BrakeInTurn {
    params: BrakeInTurnParams,
    circle: ConstantRadius,
    /// The driver's last steer command, rad (held after the onset).
    last_steer: f64,
    held: Option<f64>,
    onset: Option<Snap>,
    at_1s: Option<Snap>,
    ended_on_circle: bool,
}

impl BrakeInTurn {
    /// The manoeuvre: the circle of `params.circle` driven by a driver for a car of wheelbase
    /// `wheelbase_m` (m), braked at `brake_at_s`.
    pub fn new(params: BrakeInTurnParams, driver: DriverParams, wheelbase_m: f64) -> Self {
        let circle = ConstantRadius::new(params.circle.clone(), driver, wheelbase_m);
        Self { params, circle, last_steer: 0.0, held: None, onset: None, at_1s: None, ended_on_circle: false }
    }

    fn snap(&self, t: f64, kin: &Kinematics) -> Snap {
        Snap {
            t,
            yaw_rate: kin.yaw_rate_radps,
            sideslip: kin.sideslip_rad(),
            speed: kin.speed_mps(),
            yaw: kin.yaw_rad,
            radial: self.circle.radial_error_m(kin),
        }
    }
}

impl Maneuver for BrakeInTurn {
    fn start(&self) -> Start {
        self.circle.start()
    }

    fn command(&mut self, t: f64, kin: &Kinematics) -> Command {
        let c = self.circle.command(t, kin);
        if self.held.is_none() {
            self.last_steer = c.steer_rad;
        }
        c
    }

    fn steer_at(&self, _t: f64) -> Option<f64> {
        self.held
    }

    fn pedal(&self, t: f64) -> Option<f64> {
        (t > self.params.brake_at_s + 1e-9).then_some(-self.params.brake_fraction)
    }

    fn path_error_m(&self) -> Option<f64> {
        self.circle.path_error_m()
    }

    fn after_step(&mut self, t: f64, kin: &Kinematics, events: &mut Vec<Event>) -> bool {
        let p = &self.params;
        match self.onset {
            None => {
                if t >= p.brake_at_s - 1e-9 {
                    self.onset = Some(self.snap(t, kin));
                    self.held = Some(self.last_steer);
                    return false;
                }
                if self.circle.after_step(t, kin, events) {
                    self.ended_on_circle = true;
                    return true;
                }
                false
            }
            Some(o) => {
                if self.at_1s.is_none() && t >= o.t + 1.0 - 1e-9 {
                    self.at_1s = Some(self.snap(t, kin));
                }
                kin.speed_mps() < super::longitudinal::STOP_SPEED_MPS || t >= o.t + p.after_s - 1e-9
            }
        }
    }

    fn end_reason(&self) -> Option<crate::event::EndReason> {
        if self.ended_on_circle {
            self.circle.end_reason()
        } else {
            None
        }
    }

    fn outcome(&self) -> Outcome {
        Outcome::default()
    }

    #[cfg(feature = "serde")]
    fn layout(&self) -> Option<serde_json::Value> {
        self.circle.layout()
    }

    #[cfg(feature = "serde")]
    fn results(&self) -> Option<serde_json::Value> {
        let o = self.onset;
        let a = self.at_1s;
        Some(json!({
            "kind": "braking_in_turn",
            "brake_onset_s": o.map(|o| o.t),
            "held_steer_rad": self.held,
            "speed_at_onset_mps": o.map(|o| o.speed),
            "yaw_rate_at_onset_radps": o.map(|o| o.yaw_rate),
            "sideslip_at_onset_rad": o.map(|o| o.sideslip),
            "speed_at_1s_mps": a.map(|a| a.speed),
            "yaw_rate_at_1s_radps": a.map(|a| a.yaw_rate),
            "yaw_rate_ratio_at_1s": o.zip(a).map(|(o, a)| a.yaw_rate / o.yaw_rate),
            "sideslip_at_1s_rad": a.map(|a| a.sideslip),
            "heading_change_at_1s_rad": o.zip(a).map(|(o, a)| a.yaw - o.yaw),
            "circle_deviation_at_1s_m": a.map(|a| a.radial),
        }))
    }
}
