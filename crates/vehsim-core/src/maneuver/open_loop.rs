//! Open-loop manoeuvres: a prescribed road-wheel steer angle versus time with the PID holding a
//! speed (or following a speed schedule). Sine steer reproduces the dissertation's Fig. 6.3 input
//! (10 degree amplitude over a 10 s run); step steer gives steady-state cornering; straight
//! running with a speed schedule covers standstill starts and stops.

use super::{Command, Maneuver, Outcome, Start};

use crate::event::Event;
use crate::vehicle::Kinematics;

/// Road-wheel steer angle versus time, rad.
#[derive(Debug, Clone, PartialEq)]
pub enum SteerProfile {
    /// No steering.
    Zero,
    /// A sin(2 pi (t - start) / period) after `start_s`, 0 before.
    Sine {
        /// Amplitude A, rad (positive: the first half-period steers left).
        amplitude_rad: f64,
        /// Period, s (> 0).
        period_s: f64,
        /// Start time, s.
        start_s: f64,
    },
    /// Linear ramp from 0 at `start_s` to `amplitude_rad` at `start_s + ramp_s`, then held.
    Step {
        /// Final steer angle, rad (positive left).
        amplitude_rad: f64,
        /// Time the ramp starts, s.
        start_s: f64,
        /// Ramp duration, s (0: an ideal step).
        ramp_s: f64,
    },
}

impl SteerProfile {
    /// The profile as the steering rate limiter `rate_max` (rad/s) delivers it, where that is
    /// again a profile: a step whose ramp is too steep is stretched to the limited rate (what the
    /// limiter does to a ramp from rest); a sine must stay within the limit. `None` when the
    /// limiter would reshape the profile into something else (then the engine samples and limits it).
    pub fn rate_limited(&self, rate_max: f64) -> Option<SteerProfile> {
        match *self {
            SteerProfile::Zero => Some(SteerProfile::Zero),
            SteerProfile::Sine { amplitude_rad, period_s, .. } => {
                let peak_rate = amplitude_rad.abs() * 2.0 * std::f64::consts::PI / period_s;
                (peak_rate <= rate_max).then(|| self.clone())
            }
            SteerProfile::Step { amplitude_rad, start_s, ramp_s } => {
                if rate_max <= 0.0 {
                    return None;
                }
                Some(SteerProfile::Step { amplitude_rad, start_s, ramp_s: ramp_s.max(amplitude_rad.abs() / rate_max) })
            }
        }
    }

    /// Road-wheel steer angle at time `t` (s), rad (positive left).
    pub fn at(&self, t: f64) -> f64 {
        match *self {
            SteerProfile::Zero => 0.0,
            SteerProfile::Sine { amplitude_rad, period_s, start_s } => {
                if t < start_s {
                    0.0
                } else {
                    amplitude_rad * (2.0 * std::f64::consts::PI * (t - start_s) / period_s).sin()
                }
            }
            SteerProfile::Step { amplitude_rad, start_s, ramp_s } => {
                if ramp_s <= 0.0 {
                    if t >= start_s {
                        amplitude_rad
                    } else {
                        0.0
                    }
                } else {
                    amplitude_rad * ((t - start_s) / ramp_s).clamp(0.0, 1.0)
                }
            }
        }
    }
}

/// Speed target versus time: piecewise linear through (t, v) points, held beyond the ends.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedSchedule {
    /// (time s, speed m/s) points, times strictly increasing.
    pub points: Vec<(f64, f64)>,
}

impl SpeedSchedule {
    /// A single speed `v` (m/s) at all times.
    pub fn constant(v: f64) -> Self {
        Self { points: vec![(0.0, v)] }
    }

    /// Target speed at time `t` (s), m/s.
    pub fn at(&self, t: f64) -> f64 {
        let p = &self.points;
        match p.iter().position(|&(ti, _)| ti > t) {
            None => p.last().map_or(0.0, |q| q.1),
            Some(0) => p[0].1,
            Some(i) => {
                let (t0, v0) = p[i - 1];
                let (t1, v1) = p[i];
                v0 + (v1 - v0) * (t - t0) / (t1 - t0)
            }
        }
    }
}

/// An open-loop manoeuvre.
#[derive(Debug, Clone)]
pub struct OpenLoop {
    /// Road-wheel steer angle versus time.
    pub steer: SteerProfile,
    /// Target speed versus time, held by the PID.
    pub speed: SpeedSchedule,
    /// True when `steer` already respects the steering limits, so the engine evaluates it at every
    /// integration stage ([`Maneuver::steer_at`]); false to have it sampled and rate-limited.
    pub continuous_steer: bool,
}

impl OpenLoop {
    /// The manoeuvre for a vehicle whose steering rate is limited to `rate_max` rad/s: the profile
    /// is evaluated continuously whenever the limiter would deliver it as a profile again.
    pub fn new(steer: SteerProfile, speed: SpeedSchedule, rate_max: f64) -> Self {
        match steer.rate_limited(rate_max) {
            Some(steer) => Self { steer, speed, continuous_steer: true },
            None => Self { steer, speed, continuous_steer: false },
        }
    }
}

impl Maneuver for OpenLoop {
    fn start(&self) -> Start {
        Start { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0, speed_mps: self.speed.at(0.0) }
    }

    fn command(&mut self, t: f64, _kin: &Kinematics) -> Command {
        Command { steer_rad: self.steer.at(t), speed_target_mps: Some(self.speed.at(t)) }
    }

    fn steer_at(&self, t: f64) -> Option<f64> {
        self.continuous_steer.then(|| self.steer.at(t))
    }

    fn path_error_m(&self) -> Option<f64> {
        None
    }

    fn after_step(&mut self, _t: f64, _kin: &Kinematics, _events: &mut Vec<Event>) -> bool {
        false
    }

    fn outcome(&self) -> Outcome {
        Outcome { passed: None, cones_hit: 0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_interpolates_and_holds() {
        let s = SpeedSchedule { points: vec![(1.0, 0.0), (3.0, 10.0), (5.0, 10.0), (6.0, 0.0)] };
        assert_eq!(s.at(0.0), 0.0);
        assert_eq!(s.at(2.0), 5.0);
        assert_eq!(s.at(4.0), 10.0);
        assert_eq!(s.at(5.5), 5.0);
        assert_eq!(s.at(9.0), 0.0);
    }

    /// The limiter's ramp is the profile's ramp stretched to the rate limit; a sine within the
    /// limit passes unchanged and one beyond it is left to the sampled limiter.
    #[test]
    fn rate_limited_profiles() {
        let step = SteerProfile::Step { amplitude_rad: -0.2, start_s: 1.0, ramp_s: 0.0 };
        assert_eq!(step.rate_limited(0.5), Some(SteerProfile::Step { amplitude_rad: -0.2, start_s: 1.0, ramp_s: 0.4 }));
        let slow = SteerProfile::Step { amplitude_rad: 0.2, start_s: 1.0, ramp_s: 2.0 };
        assert_eq!(slow.rate_limited(0.5), Some(slow.clone()));
        let sine = SteerProfile::Sine { amplitude_rad: 0.1, period_s: 1.0, start_s: 0.0 };
        assert_eq!(sine.rate_limited(0.7), Some(sine.clone()));
        assert_eq!(sine.rate_limited(0.6), None);
    }

    #[test]
    fn sine_profile_is_zero_at_period_and_peaks_at_quarter() {
        let p = SteerProfile::Sine { amplitude_rad: 0.2, period_s: 4.0, start_s: 1.0 };
        assert_eq!(p.at(0.5), 0.0);
        assert!((p.at(2.0) - 0.2).abs() < 1e-15);
        assert!(p.at(5.0).abs() < 1e-12);
    }
}
