//! Traction control (TCS): the drive torque reduced when a driven wheel spins, by slip thresholds
//! with hysteresis, sampled on its own clock (a whole number of integration steps).
//!
//! At each sample the controller reads the largest slip ratio of the driven wheels,
//! kappa = (omega R_e - V_x) / max(|V_x|, V_LOW) (positive when driving; V_x the wheel centre's
//! true forward speed, an ideal reference), and moves its cap on the total drive torque at the
//! wheels:
//! - **reduce** at `reduction_rate_per_s` (fraction of the vehicle's largest drive torque per s:
//!   the engine's torque-reduction rate by spark retard and fuel cut) when kappa > `slip_high`;
//! - **restore** at `restore_rate_per_s` when kappa < `slip_low`;
//! - **hold** in between.
//!
//! A reduction starts from the torque actually requested (not from a cap above it), so the first
//! reduction acts at once. The cap ramps linearly across the TCS period. This is the engine-torque
//! part of a production traction control; the brake intervention on a single spinning wheel (the
//! "electronic differential lock") and an ESC yaw-rate intervention are not modelled
//! (docs/powertrain.md).

use crate::vehicle::wheel::V_LOW;
use crate::vehicle::WheelSensor;

/// The `[tcs]` parameters of a manoeuvre (validated by the spec layer).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TcsParams {
    /// Sample period, s (a whole multiple of the integration step).
    pub period_s: f64,
    /// Slip above which the torque is reduced, in (0, 1).
    pub slip_high: f64,
    /// Slip below which the torque is restored, in (0, slip_high).
    pub slip_low: f64,
    /// Reduction rate, fraction of the largest drive torque per s.
    pub reduction_rate_per_s: f64,
    /// Restore rate, fraction of the largest drive torque per s.
    pub restore_rate_per_s: f64,
}

impl Default for TcsParams {
    fn default() -> Self {
        Self { period_s: 0.01, slip_high: 0.15, slip_low: 0.10, reduction_rate_per_s: 30.0, restore_rate_per_s: 5.0 }
    }
}

/// TCS state: the cap on the total drive torque, N m.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tcs {
    pub params: TcsParams,
    /// Largest drive torque of the vehicle, N m (the scale of the rates).
    pub torque_max_nm: f64,
    pub cap_nm: f64,
}

impl Tcs {
    pub fn new(params: TcsParams, torque_max_nm: f64) -> Self {
        Self { params, torque_max_nm, cap_nm: torque_max_nm }
    }

    /// The largest driven-wheel slip among `wheels` (0 if none is driven).
    pub fn driven_slip(wheels: &[WheelSensor]) -> f64 {
        wheels
            .iter()
            .filter(|w| w.driven)
            .map(|w| (w.omega_r_mps - w.v_mps) / w.v_mps.abs().max(V_LOW))
            .fold(0.0, f64::max)
    }

    /// One sample: the wheels' sensors and the drive torque requested now (N m); returns the cap
    /// at the end of the coming period (the engine ramps to it).
    pub fn update(&mut self, wheels: &[WheelSensor], request_nm: f64) -> f64 {
        let p = self.params;
        let kappa = Self::driven_slip(wheels);
        let step = self.torque_max_nm * p.period_s;
        if kappa > p.slip_high {
            self.cap_nm = (self.cap_nm.min(request_nm.max(0.0)) - p.reduction_rate_per_s * step).max(0.0);
        } else if kappa < p.slip_low {
            self.cap_nm = (self.cap_nm + p.restore_rate_per_s * step).min(self.torque_max_nm);
        }
        self.cap_nm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn driven(kappa: f64) -> WheelSensor {
        WheelSensor { omega_r_mps: 5.0 * (1.0 + kappa), v_mps: 5.0, driven: true, brake_max_nm: 0.0 }
    }

    #[test]
    fn reduce_hold_restore() {
        let mut t = Tcs::new(TcsParams::default(), 3000.0);
        // spinning: reduce from the request (2000) by 30 /s x 3000 x 0.01 = 900
        assert!((t.update(&[driven(0.3)], 2000.0) - 1100.0).abs() < 1e-9);
        // in the band: hold
        assert!((t.update(&[driven(0.12)], 2000.0) - 1100.0).abs() < 1e-9);
        // gripping: restore by 5 x 3000 x 0.01 = 150 per sample
        assert!((t.update(&[driven(0.01)], 2000.0) - 1250.0).abs() < 1e-9);
        // an undriven wheel's slip is not the TCS's business
        let free = WheelSensor { driven: false, ..driven(0.9) };
        assert!((Tcs::driven_slip(&[free, driven(0.02)]) - 0.02).abs() < 1e-12);
        for _ in 0..10 {
            t.update(&[driven(0.5)], 2000.0);
        }
        assert_eq!(t.cap_nm, 0.0);
    }
}
