//! Anti-lock braking (ABS): per-wheel brake-pressure modulation by wheel-slip thresholds with
//! hysteresis, sampled on its own clock (a whole number of integration steps).
//!
//! The logic is the three-phase "dump / hold / build" modulator of the classic ABS descriptions
//! (e.g. Bosch, Automotive Handbook, chapter on ABS; Burton et al., "Anti-lock braking systems: a
//! review", 2003): at each sample the controller reads each wheel's slip ratio
//!
//!   kappa = (omega R_e - V_x) / max(|V_x|, V_LOW)   (negative when braking, [`crate::vehicle::wheel`])
//!
//! with V_x the wheel centre's true forward speed (an ideal vehicle-speed reference: real ABS
//! estimates it from the wheel speeds; not modelled) and
//! - **dump** (pressure falls at `dump_rate_per_s`) when kappa < -`slip_dump`,
//! - **build** (pressure rises at `build_rate_per_s`, up to the driver's demand) when
//!   kappa > -`slip_build`,
//! - **hold** in between (the hysteresis band).
//!
//! The output is each wheel's pressure as a fraction p in [0, 1] of the largest brake torque of
//! that wheel (the vehicle's `brake_torque_max_nm` times its balance share); the wheel's brake
//! torque is the smaller of the driver's demand and p times that largest torque. The pressure
//! ramps linearly across the ABS period to its new value (the valves' rate limits are the
//! actuator limits). Below `cutout_speed_mps` the ABS lets the demand through (p = 1; the wheels
//! may lock in the last metres, as on production systems). Without a brake demand the pressure
//! returns to p = 1 at once.

use crate::vehicle::wheel::V_LOW;
use crate::vehicle::WheelSensor;

/// The `[abs]` parameters of a manoeuvre (validated by the spec layer).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AbsParams {
    /// Sample period, s (a whole multiple of the integration step).
    pub period_s: f64,
    /// Slip beyond which the pressure is dumped (magnitude, in (0, 1)).
    pub slip_dump: f64,
    /// Slip below which the pressure builds again (magnitude, in (0, slip_dump)).
    pub slip_build: f64,
    /// Pressure fall rate while dumping, fraction of full pressure per s.
    pub dump_rate_per_s: f64,
    /// Pressure rise rate while building, fraction of full pressure per s.
    pub build_rate_per_s: f64,
    /// Speed below which the ABS stops modulating, m/s.
    pub cutout_speed_mps: f64,
}

impl Default for AbsParams {
    fn default() -> Self {
        Self {
            period_s: 0.01,
            slip_dump: 0.15,
            slip_build: 0.06,
            dump_rate_per_s: 20.0,
            build_rate_per_s: 6.0,
            cutout_speed_mps: 1.5,
        }
    }
}

/// The phase a wheel's modulator is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Pressure rises at `build_rate_per_s` up to the driver's demand (slip above -`slip_build`).
    Build,
    /// Pressure held (slip within the hysteresis band).
    Hold,
    /// Pressure falls at `dump_rate_per_s` (slip below -`slip_dump`).
    Dump,
}

/// ABS state: per wheel the pressure fraction and the phase of the last sample.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Abs {
    pub params: AbsParams,
    pub pressure: [f64; 4],
    pub phase: [Phase; 4],
}

impl Abs {
    pub fn new(params: AbsParams) -> Self {
        Self { params, pressure: [1.0; 4], phase: [Phase::Build; 4] }
    }

    /// One sample: the wheels' sensors `wheels` and whether the driver brakes; returns the
    /// pressure fractions at the end of the coming period (the engine ramps to them).
    pub fn update(&mut self, wheels: &[WheelSensor], braking: bool) -> [f64; 4] {
        let p = self.params;
        for (i, w) in wheels.iter().enumerate().take(4) {
            if !braking || w.v_mps.abs() < p.cutout_speed_mps {
                self.pressure[i] = 1.0;
                self.phase[i] = Phase::Build;
                continue;
            }
            let kappa = (w.omega_r_mps - w.v_mps) / w.v_mps.abs().max(V_LOW);
            let phase = if kappa < -p.slip_dump {
                Phase::Dump
            } else if kappa > -p.slip_build {
                Phase::Build
            } else {
                Phase::Hold
            };
            let dp = match phase {
                Phase::Dump => -p.dump_rate_per_s * p.period_s,
                Phase::Build => p.build_rate_per_s * p.period_s,
                Phase::Hold => 0.0,
            };
            self.pressure[i] = (self.pressure[i] + dp).clamp(0.0, 1.0);
            self.phase[i] = phase;
        }
        self.pressure
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wheel(kappa: f64) -> WheelSensor {
        WheelSensor { omega_r_mps: 10.0 * (1.0 + kappa), v_mps: 10.0, driven: false, brake_max_nm: 1000.0 }
    }

    #[test]
    fn dump_hold_build_with_hysteresis() {
        let mut a = Abs::new(AbsParams::default());
        // deep slip: dump by 20 %/s x 10 ms = 0.2 per sample
        let p = a.update(&[wheel(-0.3)], true);
        assert!((p[0] - 0.8).abs() < 1e-12 && a.phase[0] == Phase::Dump);
        // inside the band: hold
        let p = a.update(&[wheel(-0.1)], true);
        assert!((p[0] - 0.8).abs() < 1e-12 && a.phase[0] == Phase::Hold);
        // recovered: build by 0.06 per sample
        let p = a.update(&[wheel(-0.02)], true);
        assert!((p[0] - 0.86).abs() < 1e-12 && a.phase[0] == Phase::Build);
        // the pressure never leaves [0, 1]
        for _ in 0..10 {
            a.update(&[wheel(-0.9)], true);
        }
        assert_eq!(a.pressure[0], 0.0);
        // no demand, or below the cut-out speed: full pressure passes
        assert_eq!(a.update(&[wheel(-0.9)], false)[0], 1.0);
        a.update(&[wheel(-0.9)], true);
        let slow = WheelSensor { omega_r_mps: 0.0, v_mps: 1.0, driven: false, brake_max_nm: 1000.0 };
        assert_eq!(a.update(&[slow], true)[0], 1.0);
    }
}
