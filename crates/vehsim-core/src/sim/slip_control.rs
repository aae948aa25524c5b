//! The slip controllers on the engine's control clock: ABS ([`crate::control::abs`]) and traction
//! control ([`crate::control::tcs`]), each sampled every whole number of integration steps (its
//! own period), their outputs ramped linearly across the period (the actuators' rate limits) and
//! applied to the inputs at every integration stage as caps: ABS on each wheel's brake torque,
//! TCS on the total drive torque. Without either controller nothing here runs and the inputs keep
//! their infinite caps (no change to a run, bit for bit).

use crate::control::abs::{Abs, AbsParams};
use crate::control::tcs::{Tcs, TcsParams};
use crate::vehicle::{Inputs, WheelSensor};

/// Which slip controllers a run has (the manoeuvre's `[abs]` and `[tcs]` sections).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlipControlParams {
    /// ABS parameters (`None`: no ABS).
    pub abs: Option<AbsParams>,
    /// Traction-control parameters (`None`: no TCS).
    pub tcs: Option<TcsParams>,
}

impl SlipControlParams {
    /// Neither controller.
    pub fn is_off(&self) -> bool {
        self.abs.is_none() && self.tcs.is_none()
    }
}

/// A linear ramp across one controller period.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Ramp<T: Copy> {
    t0: f64,
    period: f64,
    from: T,
    to: T,
}

impl<T: Copy> Ramp<T> {
    fn weight(&self, ts: f64) -> f64 {
        ((ts - self.t0) / self.period).clamp(0.0, 1.0)
    }
}

/// The controllers' state in a run.
#[derive(Debug, Clone)]
pub(crate) struct SlipControl {
    abs: Option<(Abs, u64, Ramp<[f64; 4]>)>,
    tcs: Option<(Tcs, u64, Ramp<f64>)>,
    /// The wheels' largest brake torques, N m (from the last sample's sensors).
    brake_max: [f64; 4],
}

impl SlipControl {
    /// The controllers of `params` for integration step `h` (s; each period is rounded to a whole
    /// number of steps, at least one: the spec layer refuses any other) and the vehicle's largest
    /// drive torque `drive_max_nm` (N m; the scale of the TCS rates).
    pub fn new(params: &SlipControlParams, h: f64, drive_max_nm: f64) -> Self {
        let every = |p: f64| ((p / h).round() as u64).max(1);
        Self {
            abs: params.abs.map(|p| {
                let n = every(p.period_s);
                (Abs::new(p), n, Ramp { t0: 0.0, period: n as f64 * h, from: [1.0; 4], to: [1.0; 4] })
            }),
            tcs: params.tcs.map(|p| {
                let n = every(p.period_s);
                let cap = drive_max_nm;
                (Tcs::new(p, drive_max_nm), n, Ramp { t0: 0.0, period: n as f64 * h, from: cap, to: cap })
            }),
            brake_max: [0.0; 4],
        }
    }

    /// At step `k` (time `t`, s): sample each controller that is due from the wheels' sensors and
    /// the inputs `u` at t (the driver's brake demand and drive request).
    pub fn sample(&mut self, k: u64, t: f64, wheels: &[WheelSensor], u: &Inputs) {
        for (o, w) in self.brake_max.iter_mut().zip(wheels) {
            *o = w.brake_max_nm;
        }
        if let Some((abs, n, ramp)) = &mut self.abs {
            if k % *n == 0 {
                let from = ramp.to;
                let to = abs.update(wheels, u.brake_torque_nm > 0.0);
                *ramp = Ramp { t0: t, from, to, ..*ramp };
            }
        }
        if let Some((tcs, n, ramp)) = &mut self.tcs {
            if k % *n == 0 {
                // from the torque in effect at t (the cap or the smaller request)
                let from = ramp.to.min(u.drive_torque_nm.max(0.0));
                let to = tcs.update(wheels, u.drive_torque_nm);
                *ramp = Ramp { t0: t, from, to, ..*ramp };
            }
        }
    }

    /// Apply the caps at time `ts` (s) to the inputs `u`.
    pub fn apply(&self, ts: f64, u: &mut Inputs) {
        if let Some((_, _, r)) = &self.abs {
            let w = r.weight(ts);
            for i in 0..4 {
                let p = r.from[i] + w * (r.to[i] - r.from[i]);
                u.brake_cap_nm[i] = if p >= 1.0 { f64::INFINITY } else { p * self.brake_max[i] };
            }
        }
        if let Some((_, _, r)) = &self.tcs {
            u.drive_cap_nm = r.from + r.weight(ts) * (r.to - r.from);
        }
    }
}
