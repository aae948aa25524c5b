//! Inputs set from outside the engine (the step API, the Python package, an FMI unit).
//!
//! [`ExternalInputs`] replace, from the next step on, the manoeuvre's steer command and the speed
//! controller's torque by values the caller sets; each is optional (`None`: the spec's own driver
//! or speed controller acts). They are held over every step until set again (a zero-order hold:
//! the engine's ramps across a control period do not apply to them). The controllers keep
//! sampling while they are overridden (the manoeuvre still tracks its path error, cone strikes
//! and end rules), so a run with no external input is bit for bit the run `vehsim run` makes.
//!
//! Units and signs: steer angle of the front road wheels, rad, positive left (ISO 8855); drive
//! and brake torque are the totals at the wheels, N m, both >= 0, split by the vehicle's drive
//! layout and brake balance as the speed controller's torque is. The limits are the vehicle
//! file's: |steer| <= `steer_max_rad` (the rate limit applies to the driver only: an external
//! steer is the road-wheel angle itself), drive <= `drive_torque_max_nm`, brake <=
//! `brake_torque_max_nm`.

use super::engine::Controls;
use crate::vehicle::Inputs;

/// Inputs the caller sets in place of the controllers' (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ExternalInputs {
    /// Front road-wheel steer angle, rad, positive left; `None`: the manoeuvre's driver steers.
    pub steer_rad: Option<f64>,
    /// Steer rate instead of an angle (takes precedence over `steer_rad`): see [`SteerRate`].
    pub steer_rate: Option<SteerRate>,
    /// Total drive and brake torque at the wheels, N m (each >= 0); `None`: the speed controller.
    pub torque_nm: Option<Torque>,
}

/// A steer rate held from time `t0_s`: the steer angle at time t is `from_rad + rate_radps (t -
/// t0_s)`, evaluated at every integration stage (exact for a held rate) and stopped at the lock
/// (`lock_rad`). The step API fills `from_rad`, `t0_s` and `lock_rad` from the run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SteerRate {
    /// Steer rate, rad/s, positive left; |rate| <= the vehicle's `steer_rate_max_radps`.
    pub rate_radps: f64,
    /// Steer angle at `t0_s`, rad.
    pub from_rad: f64,
    /// Time the rate was set, s.
    pub t0_s: f64,
    /// Steering lock, rad.
    pub lock_rad: f64,
}

/// Drive and brake torque set together, N m (both >= 0; both may act at once).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Torque {
    /// Total drive torque at the wheels, N m (>= 0).
    pub drive_nm: f64,
    /// Total brake torque at the wheels, N m (>= 0).
    pub brake_nm: f64,
}

/// The actuator limits external inputs are checked against (the vehicle file's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Steering lock, rad (|steer| <= this).
    pub steer_max_rad: f64,
    /// Steering rate limit, rad/s (|steer rate| <= this).
    pub steer_rate_max_radps: f64,
    /// Largest total drive and brake torque, N m.
    pub drive_max_nm: f64,
    /// Largest total brake torque, N m.
    pub brake_max_nm: f64,
}

impl From<&Controls> for Limits {
    fn from(c: &Controls) -> Self {
        Limits {
            steer_max_rad: c.steer_max_rad,
            steer_rate_max_radps: c.steer_rate_max_radps,
            drive_max_nm: c.drive_max_nm,
            brake_max_nm: c.brake_max_nm,
        }
    }
}

impl ExternalInputs {
    /// Write the inputs that are set into `u` (the others are left as the controllers made them).
    pub fn apply(&self, u: &mut Inputs) {
        if let Some(s) = self.steer_rad {
            u.steer_rad = s;
        }
        if let Some(r) = self.steer_rate {
            let lock = r.lock_rad.abs();
            u.steer_rad = (r.from_rad + r.rate_radps * (u.t_s - r.t0_s)).clamp(-lock, lock);
        }
        if let Some(t) = self.torque_nm {
            u.drive_torque_nm = t.drive_nm;
            u.brake_torque_nm = t.brake_nm;
        }
    }

    /// Ok if every input set is a finite number within `lim`; else a message naming the input,
    /// its value and the allowed range.
    pub fn check(&self, lim: &Limits) -> std::result::Result<(), String> {
        let within = |name: &str, v: f64, lo: f64, hi: f64, unit: &str| {
            if v.is_finite() && v >= lo && v <= hi {
                Ok(())
            } else {
                Err(format!(
                    "{name} = {} is not allowed; expected a finite number in [{}, {}] {unit} (the vehicle's limit)",
                    short(v),
                    short(lo),
                    short(hi)
                ))
            }
        };
        if let Some(s) = self.steer_rad {
            within("steer_rad", s, -lim.steer_max_rad, lim.steer_max_rad, "rad")?;
        }
        if let Some(r) = self.steer_rate {
            let max = lim.steer_rate_max_radps;
            within("steer_rate_radps", r.rate_radps, -max, max, "rad/s")?;
        }
        if let Some(t) = self.torque_nm {
            within("drive_torque_nm", t.drive_nm, 0.0, lim.drive_max_nm, "N m")?;
            within("brake_torque_nm", t.brake_nm, 0.0, lim.brake_max_nm, "N m")?;
        }
        Ok(())
    }
}

/// `v` for a message: the shortest text that reads back as `v` between 1e-4 and 1e6 in
/// magnitude, short scientific notation outside (no 301-digit 1e300).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}
