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
//! - **Mounting orientation** (θ, rad): the accelerometer's y axis turned θ towards +x (a yaw
//!   misalignment) senses a_y,log = a_y cos θ + a_x sin θ, with a_x the longitudinal
//!   acceleration (the caller's: a logged `ax`, or [`longitudinal_acceleration`], the speed's
//!   slope over ±0.5 s). A roll misalignment φ
//!   would add g sin φ (gravity seen by the tilted axis), a constant: the offset below stands for
//!   it, so it has no key of its own.
//! - **Scale per channel** (s_r, s_a, dimensionless): each channel multiplied by its factor.
//! - **Clock skew** (ε, ppm): the inertial unit (yaw rate and a_y) stamps its samples with its own
//!   clock, running fast by ε·1e-6 against the logger's that stamps steer and speed, the two
//!   aligned at the first sample t₀: the value logged at t is the true one at
//!   t₀ + (t − t₀)/(1 + ε·1e-6), then each channel's latency before it (linear between samples,
//!   held at the ends).
//! - **Offsets** (rad/s, m/s^2): added last.
//!
//! They change only the outputs, never the vehicle's state. Each step is skipped when its
//! parameter has its no-effect value, so instruments without them log the same bits as before.

use super::params::Sensors;

/// The logged yaw rate (rad/s) and lateral acceleration (m/s^2) of instruments `s` for the true
/// yaw rate `r`, CG lateral acceleration `ay` and forward speed `vx` (m/s; its derivative is the
/// longitudinal acceleration a misaligned accelerometer mixes in) at increasing times `t` (s):
/// [`measure`], then the constant offsets.
pub fn logged(t: &[f64], r: &[f64], ay: &[f64], vx: &[f64], s: &Sensors) -> (Vec<f64>, Vec<f64>) {
    let (mut r, mut ay) = (r.to_vec(), ay.to_vec());
    let ax = if s.accel_yaw_misalignment_rad != 0.0 { longitudinal_acceleration(vx, t) } else { Vec::new() };
    measure(&mut r, &mut ay, t, s, &ax);
    r.iter_mut().for_each(|v| *v += s.bias[0]);
    ay.iter_mut().for_each(|v| *v += s.bias[1]);
    (r, ay)
}

/// Turn the yaw rate `r` and CG lateral acceleration `ay`, sampled at `t` (increasing), into the
/// logged channels of instruments `s` in place, offsets aside: the accelerometer at its position
/// (it needs the true r), its mounting orientation (mixing in the longitudinal acceleration `ax`,
/// m/s^2 at the same samples; read only when the misalignment is not 0), each channel's scale,
/// then the clock skew and each channel's latency.
pub fn measure(r: &mut [f64], ay: &mut [f64], t: &[f64], s: &Sensors, ax: &[f64]) {
    let [x_s, y_s] = s.accel_position_m;
    if x_s != 0.0 || y_s != 0.0 {
        let r_dot = derivative(r, t);
        for ((a, &w), &w_dot) in ay.iter_mut().zip(r.iter()).zip(&r_dot) {
            *a += w_dot * x_s - w * w * y_s;
        }
    }
    let theta = s.accel_yaw_misalignment_rad;
    if theta != 0.0 {
        let (sin_t, cos_t) = theta.sin_cos();
        for (a, &x) in ay.iter_mut().zip(ax) {
            *a = *a * cos_t + x * sin_t;
        }
    }
    for (c, k) in [(&mut *r, s.scale[0]), (&mut *ay, s.scale[1])] {
        if k != 1.0 {
            c.iter_mut().for_each(|v| *v *= k);
        }
    }
    let [tau_r, tau_a] = s.latency_s;
    if s.clock_skew_ppm != 0.0 {
        let rate = 1.0 / (1.0 + s.clock_skew_ppm * 1e-6);
        skewed(r, t, rate, tau_r);
        skewed(ay, t, rate, tau_a);
        return;
    }
    if tau_r > 0.0 {
        delay(r, t, tau_r);
    }
    if tau_a > 0.0 {
        delay(ay, t, tau_a);
    }
}

/// Replace `v` (sampled at increasing `t`) by its values at t₀ + (t − t₀)·`rate` − `tau`: linear
/// between samples, held at the first and last sample outside them.
fn skewed(v: &mut [f64], t: &[f64], rate: f64, tau: f64) {
    let src = v.to_vec();
    let n = src.len().min(t.len());
    if n < 2 {
        return;
    }
    for k in 0..n {
        let tk = t[0] + (t[k] - t[0]) * rate - tau;
        let j = t[..n].partition_point(|&x| x <= tk).saturating_sub(1).min(n - 2);
        let u = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
        v[k] = src[j] + u * (src[j + 1] - src[j]);
    }
}

/// Half width of the window over which [`longitudinal_acceleration`] takes the speed's slope, s. A
/// measured speed of white noise σ_v gives a slope of noise σ_v·√2/(2w): 0.028 m/s^2 for
/// σ_v = 0.02 m/s (the synthetic runs'), where central differences at 100 Hz would give 1.4 m/s^2;
/// the price is that a_x is averaged over 1 s (its changes within a second are smoothed).
const AX_HALF_WINDOW_S: f64 = 0.5;

/// The longitudinal acceleration (m/s^2) at every sample time from the forward speed `vx` (m/s)
/// at increasing times `t` (s): (v(t + w) − v(t − w)) / (2w), w = 0.5 s, v linear
/// between samples, the window cut to the run's span at its ends; zeros for fewer than two samples.
pub fn longitudinal_acceleration(vx: &[f64], t: &[f64]) -> Vec<f64> {
    longitudinal_acceleration_over(vx, t, AX_HALF_WINDOW_S)
}

/// [`longitudinal_acceleration`] over ±`half_window_s` (s, > 0) instead of ±0.5 s.
pub fn longitudinal_acceleration_over(vx: &[f64], t: &[f64], half_window_s: f64) -> Vec<f64> {
    let n = vx.len().min(t.len());
    if n < 2 {
        return vec![0.0; vx.len()];
    }
    let at = |tk: f64| {
        let j = t[..n].partition_point(|&x| x <= tk).saturating_sub(1).min(n - 2);
        let u = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
        vx[j] + u * (vx[j + 1] - vx[j])
    };
    (0..n)
        .map(|k| {
            let (a, b) = ((t[k] - half_window_s).max(t[0]), (t[k] + half_window_s).min(t[n - 1]));
            (at(b) - at(a)) / (b - a)
        })
        .collect()
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
        measure(&mut r, &mut ay, &t, &Sensors { accel_position_m: [x_s, y_s], ..Sensors::default() }, &[]);
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
        measure(&mut r, &mut ay, &t, &Sensors { latency_s: [0.05, 0.125], ..Sensors::default() }, &[]);
        for k in 0..t.len() {
            let held = |tau: f64| if t[k] < tau { f(0.0) } else { f(t[k] - tau) };
            // Linear interpolation of a smooth signal: error below h^2 max|f''| / 8 = 2.2e-5.
            assert!((r[k] - held(0.05)).abs() < 3e-5, "yaw rate at {}", t[k]);
            assert!((ay[k] - held(0.125)).abs() < 3e-5, "ay at {}", t[k]);
        }
    }

    /// The mounting orientation, scale and clock skew against their closed forms: a_y cos θ +
    /// a_x sin θ times the scale; a channel stamped by a clock fast by ε is the true one at
    /// t/(1 + ε), here a line (exact under linear interpolation) and a sine.
    #[test]
    fn orientation_scale_and_skew_follow_their_closed_forms() {
        let t = grid(1001, 0.01);
        let (theta, k) = (0.2_f64, 1.1);
        let ax: Vec<f64> = t.iter().map(|t| (0.7 * t).cos()).collect();
        let mut ay: Vec<f64> = t.iter().map(|t| 2.0 + t).collect();
        let mut r: Vec<f64> = t.iter().map(|t| 0.1 * t).collect();
        let s = Sensors { accel_yaw_misalignment_rad: theta, scale: [1.0, k], ..Sensors::default() };
        measure(&mut r, &mut ay, &t, &s, &ax);
        for i in 0..t.len() {
            let want = k * ((2.0 + t[i]) * theta.cos() + ax[i] * theta.sin());
            assert!((ay[i] - want).abs() < 1e-12, "{} vs {want}", ay[i]);
        }
        let eps = 0.01;
        let mut r: Vec<f64> = t.iter().map(|t| 0.1 * t).collect();
        let mut ay: Vec<f64> = t.iter().map(|t| (1.3 * t).sin()).collect();
        let s = Sensors { clock_skew_ppm: eps * 1e6, ..Sensors::default() };
        measure(&mut r, &mut ay, &t, &s, &[]);
        for i in 0..t.len() {
            let tt = t[i] / (1.0 + eps);
            assert!((r[i] - 0.1 * tt).abs() < 1e-12, "{} vs {}", r[i], 0.1 * tt);
            // Linear interpolation of the sine: below h^2 max|f''| / 8 = 2.2e-5.
            assert!((ay[i] - (1.3 * tt).sin()).abs() < 3e-5);
        }
    }

    /// `logged` mixes in the speed's slope: a speed ramp of 2 m/s^2 seen by an axis turned by θ
    /// adds 2 sin θ (the offset after it), at every sample, the ends included.
    #[test]
    fn logged_takes_the_longitudinal_acceleration_from_the_speed() {
        let t = grid(101, 0.01);
        let vx: Vec<f64> = t.iter().map(|t| 10.0 + 2.0 * t).collect();
        let zero = vec![0.0; t.len()];
        let s = Sensors { accel_yaw_misalignment_rad: 0.1, bias: [0.0, 0.5], ..Sensors::default() };
        let (_, ay) = logged(&t, &zero, &zero, &vx, &s);
        assert!(ay.iter().all(|a| (a - (2.0 * 0.1_f64.sin() + 0.5)).abs() < 1e-9), "{ay:?}");
    }

    #[test]
    fn longitudinal_acceleration_is_the_slope_over_the_window() {
        // v = sin(t): the slope over ±w is sin(w) cos(t) / w inside the run, the chord at the ends.
        let t = grid(1001, 0.01);
        let v: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let a = longitudinal_acceleration(&v, &t);
        let w = AX_HALF_WINDOW_S;
        for k in 0..t.len() {
            let (lo, hi) = ((t[k] - w).max(0.0), (t[k] + w).min(10.0));
            let want = (hi.sin() - lo.sin()) / (hi - lo);
            assert!((a[k] - want).abs() < 1e-12, "{} vs {want}", a[k]);
        }
        assert!((a[500] - w.sin() / w * 5.0_f64.cos()).abs() < 1e-12);
    }

    #[test]
    fn no_sensor_effect_leaves_the_channels_bit_identical() {
        let t = grid(50, 0.01);
        let r0: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let (mut r, mut ay) = (r0.clone(), r0.clone());
        measure(&mut r, &mut ay, &t, &Sensors::default(), &[]);
        assert_eq!(r, r0);
        assert_eq!(ay, r0);
    }
}
