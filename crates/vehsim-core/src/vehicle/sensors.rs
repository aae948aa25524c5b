//! The instruments on the car: what turns the simulated yaw rate r (rad/s) and the lateral
//! acceleration at the centre of gravity a_y (m/s^2, ISO 8855: x forward, y left, positive
//! counter-clockwise yaw), sampled at increasing times, into the logged channels
//! ([`Sensors`]: a vehicle spec's `[sensors]` section). `vehsim run` logs them beside the true
//! channels; `vehsim discover`'s replay fits them as its measurement-chain effects.
//!
//! - **Accelerometer position** (x_s ahead of the CG, y_s to its left, m): a point P of the rigid
//!   body at r_P = (x_s, y_s) accelerates by a_P = a_CG + dω/dt × r_P + ω × (ω × r_P); with
//!   ω = r z, its lateral component is a_y,P = a_y + (dr/dt) x_s − r² y_s. dr/dt comes from the
//!   yaw rate by central differences on the sample times (one-sided at the ends).
//! - **Latency per channel** (τ_r, τ_a, s): the logged value at t is the true one at t − τ,
//!   interpolated linearly between samples, held at the first sample before the run starts (a
//!   logger that delays a channel has no earlier value to show).
//! - **Offsets** (rad/s, m/s^2): added last.
//!
//! They change only the outputs, never the vehicle's state.

use super::params::Sensors;

/// The logged yaw rate (rad/s) and lateral acceleration (m/s^2) of instruments `s` for the true
/// yaw rate `r` and CG lateral acceleration `ay` at increasing times `t` (s): [`measure`], then
/// the constant offsets.
pub fn logged(t: &[f64], r: &[f64], ay: &[f64], s: &Sensors) -> (Vec<f64>, Vec<f64>) {
    let (mut r, mut ay) = (r.to_vec(), ay.to_vec());
    measure(&mut r, &mut ay, t, s.latency_s, s.accel_position_m);
    r.iter_mut().for_each(|v| *v += s.bias[0]);
    ay.iter_mut().for_each(|v| *v += s.bias[1]);
    (r, ay)
}

/// Turn the yaw rate `r` and CG lateral acceleration `ay`, sampled at `t` (increasing), into the
/// logged channels in place, offsets aside: the accelerometer at `accel_position_m` [x, y] (m)
/// first (it needs the true r), then each channel's latency `latency_s` [yaw rate, ay] (s).
pub fn measure(r: &mut [f64], ay: &mut [f64], t: &[f64], latency_s: [f64; 2], accel_position_m: [f64; 2]) {
    let [x_s, y_s] = accel_position_m;
    if x_s != 0.0 || y_s != 0.0 {
        let r_dot = derivative(r, t);
        for ((a, &w), &w_dot) in ay.iter_mut().zip(r.iter()).zip(&r_dot) {
            *a += w_dot * x_s - w * w * y_s;
        }
    }
    let [tau_r, tau_a] = latency_s;
    if tau_r > 0.0 {
        delay(r, t, tau_r);
    }
    if tau_a > 0.0 {
        delay(ay, t, tau_a);
    }
}

/// dv/dt at every sample time: central differences (second order on a uniform grid), one-sided
/// at the ends; zeros for fewer than two samples.
fn derivative(v: &[f64], t: &[f64]) -> Vec<f64> {
    let n = v.len().min(t.len());
    if n < 2 {
        return vec![0.0; v.len()];
    }
    (0..n)
        .map(|k| {
            let (i, j) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (v[j] - v[i]) / (t[j] - t[i])
        })
        .collect()
}

/// Replace `v` (sampled at increasing `t`) by its values `tau` earlier: linear between samples,
/// the first sample before the run starts.
fn delay(v: &mut [f64], t: &[f64], tau: f64) {
    let src = v.to_vec();
    let n = src.len().min(t.len());
    let mut j = 0;
    for k in 0..n {
        let tk = t[k] - tau;
        while j + 1 < n && t[j + 1] <= tk {
            j += 1;
        }
        v[k] = if tk <= t[0] {
            src[0]
        } else if j + 1 >= n {
            src[n - 1]
        } else {
            let u = (tk - t[j]) / (t[j + 1] - t[j]);
            src[j] + u * (src[j + 1] - src[j])
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * dt).collect()
    }

    #[test]
    fn lever_arm_adds_the_rigid_body_terms_of_a_sine_yaw_rate() {
        // r = A sin(w t): a_y,P - a_y = A w cos(w t) x_s - A^2 sin^2(w t) y_s.
        let (a, w, x_s, y_s) = (0.3, 2.0, 1.2, -0.4);
        let t = grid(2001, 1e-3);
        let mut r: Vec<f64> = t.iter().map(|t| a * (w * t).sin()).collect();
        let mut ay = vec![0.0; t.len()];
        measure(&mut r, &mut ay, &t, [0.0; 2], [x_s, y_s]);
        for k in 1..t.len() - 1 {
            let want = a * w * (w * t[k]).cos() * x_s - (a * (w * t[k]).sin()).powi(2) * y_s;
            // Central differences at 1 ms: error A w^3 h^2 / 6 x_s, about 2.4e-7.
            assert!((ay[k] - want).abs() < 1e-6, "t {}: {} vs {}", t[k], ay[k], want);
        }
    }

    #[test]
    fn latency_shifts_each_channel_by_its_own_delay() {
        let t = grid(1001, 0.01);
        let f = |t: f64| (1.3 * t).sin() + 0.2 * t;
        let mut r: Vec<f64> = t.iter().map(|&t| f(t)).collect();
        let mut ay: Vec<f64> = r.clone();
        measure(&mut r, &mut ay, &t, [0.05, 0.125], [0.0; 2]);
        for k in 0..t.len() {
            let held = |tau: f64| if t[k] < tau { f(0.0) } else { f(t[k] - tau) };
            // Linear interpolation of a smooth signal: error below h^2 max|f''| / 8 = 2.2e-5.
            assert!((r[k] - held(0.05)).abs() < 3e-5, "yaw rate at {}", t[k]);
            assert!((ay[k] - held(0.125)).abs() < 3e-5, "ay at {}", t[k]);
        }
    }

    #[test]
    fn no_sensor_effect_leaves_the_channels_bit_identical() {
        let t = grid(50, 0.01);
        let r0: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let (mut r, mut ay) = (r0.clone(), r0.clone());
        measure(&mut r, &mut ay, &t, [0.0; 2], [0.0; 2]);
        assert_eq!(r, r0);
        assert_eq!(ay, r0);
    }
}
