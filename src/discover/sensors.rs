//! The measurement chain of the replay: the run's logged channels from the replayed yaw rate and
//! lateral acceleration at the CG, through the engine's instrument model
//! ([`vehsim_core::vehicle::sensors`]: accelerometer position and orientation, scale per channel,
//! clock skew and latency per channel). The constant offsets of `sensor_bias` are added after it
//! (by the replay), as [`vehsim_core::vehicle::sensors::logged`] does for `vehsim run`.

use super::measured::MeasuredRun;
use super::model::EffectParams;
use vehsim_core::vehicle::sensors::longitudinal_acceleration;
use vehsim_core::vehicle::Sensors;

/// Turn the replayed yaw rate `r` and CG lateral acceleration `ay` of `run` (at its sample times)
/// into the logged channels with the instruments of `p`. The longitudinal acceleration that a
/// turned accelerometer mixes in (m/s^2) is the run's logged `ax` when it has one, else the slope
/// of its measured speed over ±0.5 s ([`longitudinal_acceleration`], as `vehsim run` takes it
/// from its own speed).
pub fn measure(r: &mut [f64], ay: &mut [f64], run: &MeasuredRun, p: &EffectParams) {
    let s = Sensors {
        latency_s: p.latency_s,
        bias: [0.0; 2],
        accel_position_m: p.accel_position_m,
        scale: p.sensor_scale,
        clock_skew_ppm: p.clock_skew_ppm,
        accel_yaw_misalignment_rad: p.accel_yaw_misalignment_rad,
    };
    let ax = match (p.accel_yaw_misalignment_rad != 0.0, run.channel("ax")) {
        (false, _) => Vec::new(),
        (true, Some(ax)) => ax.to_vec(),
        (true, None) => longitudinal_acceleration(&run.vx, &run.t),
    };
    vehsim_core::vehicle::sensors::measure(r, ay, &run.t, &s, &ax);
}
