//! The measurement chain of the replay: the run's logged channels from the replayed yaw rate and
//! lateral acceleration at the CG, through the engine's instrument model
//! ([`vehsim_core::vehicle::sensors`]: accelerometer position, then latency per channel). The
//! constant offsets of `sensor_bias` are added after it (by the replay), as
//! [`vehsim_core::vehicle::sensors::logged`] does for `vehsim run`.

use super::model::EffectParams;

/// Turn the replayed yaw rate `r` and CG lateral acceleration `ay`, sampled at `t` (increasing),
/// into the logged channels with the latencies and the accelerometer position of `p`.
pub fn measure(r: &mut [f64], ay: &mut [f64], t: &[f64], p: &EffectParams) {
    vehsim_core::vehicle::sensors::measure(r, ay, t, p.latency_s, p.accel_position_m);
}
