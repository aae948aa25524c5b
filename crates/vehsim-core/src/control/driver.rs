//! Path-following driver: single-point predictive preview (MacAdam-type), with steering angle and
//! rate limits applied by the engine (`limit_steer` over one step, `rate_limited_steer` over a
//! control period with the command interpolated across it).
//!
//! The driver predicts where the CG will be one preview time T_p ahead if speed v and yaw rate r
//! stay as they are (an arc along the current course angle psi + beta), takes the path point one
//! preview distance ahead of the CG's closest path point, and measures the lateral error e between
//! them, perpendicular to the heading. From the steady-state single-track relation a steer change
//! d(delta) changes the yaw rate by v d(delta) / (L + K v^2) and so the lateral position after T_p by
//! v^2 T_p^2 d(delta) / (2 (L + K v^2)). The command is the steer that sustains the present yaw rate
//! plus the correction that cancels e:
//!
//!   delta = r (L + K v^2) / v + gain * 2 (L + K v^2) e / (v^2 T_p^2)
//!
//! K is the driver's internal understeer gradient (rad per m/s^2; 0 by default: the feedback
//! absorbs the vehicle's own understeer).

use crate::path::RefPath;
use crate::vehicle::Kinematics;

/// Driver tuning.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct DriverParams {
    /// Preview time, s (0.2–1.0; shorter tracks tighter but oscillates more; default 0.3).
    #[cfg_attr(feature = "serde", serde(default = "default_preview_time"))]
    pub preview_time_s: f64,
    /// Smallest preview distance, m (2–10), used at low speed (default 3).
    #[cfg_attr(feature = "serde", serde(default = "default_preview_min"))]
    pub preview_min_m: f64,
    /// Gain on the preview correction, dimensionless (0.5–1.5).
    #[cfg_attr(feature = "serde", serde(default = "one"))]
    pub gain: f64,
    /// The driver's internal understeer gradient K, rad per m/s^2 (0–0.01; default 0).
    #[cfg_attr(feature = "serde", serde(default))]
    pub understeer_gradient_rad_per_mps2: f64,
}

fn default_preview_time() -> f64 {
    0.3
}
fn default_preview_min() -> f64 {
    3.0
}
#[cfg(feature = "serde")]
fn one() -> f64 {
    1.0
}

impl Default for DriverParams {
    fn default() -> Self {
        Self {
            preview_time_s: default_preview_time(),
            preview_min_m: default_preview_min(),
            gain: 1.0,
            understeer_gradient_rad_per_mps2: 0.0,
        }
    }
}

/// Driver state: where on the path it is, and the applied steer angle.
#[derive(Debug, Clone)]
pub struct Driver {
    /// The driver's gains, preview and understeer compensation.
    pub params: DriverParams,
    /// Wheelbase L, m.
    pub wheelbase_m: f64,
    /// Segment index of the closest path point found last (`None` before the first sample).
    cursor: Option<usize>,
    /// Segment index of the preview point found last (0 before the first sample).
    preview: usize,
    /// Signed lateral error of the CG from the path (left positive), m, at the last sample.
    pub lateral_error_m: f64,
}

impl Driver {
    /// A driver at the start of its path, for a vehicle of wheelbase `wheelbase_m` (m).
    pub fn new(params: DriverParams, wheelbase_m: f64) -> Self {
        Self { params, wheelbase_m, cursor: None, preview: 0, lateral_error_m: 0.0 }
    }

    /// Desired road-wheel steer angle (before limits) for the vehicle at `kin`.
    pub fn steer(&mut self, path: &RefPath, kin: &Kinematics) -> f64 {
        self.steer_with(path, kin, kin.yaw_rad.sin_cos())
    }

    /// [`Driver::steer`] given `kin.yaw_rad.sin_cos()` (for a caller that needs it too).
    pub fn steer_with(&mut self, path: &RefPath, kin: &Kinematics, (sy, cy): (f64, f64)) -> f64 {
        let p = &self.params;
        let (s, e_cg, idx) = match self.cursor {
            Some(i) => path.closest_from(kin.x_m, kin.y_m, i),
            None => {
                let (s, e) = path.closest_global(kin.x_m, kin.y_m);
                (s, e, path.segment_at(s))
            }
        };
        self.cursor = Some(idx);
        self.lateral_error_m = e_cg;
        let v = kin.speed_mps().max(1.0);
        let dist = (p.preview_time_s * v).max(p.preview_min_m);
        let tp = dist / v;
        let r = kin.yaw_rate_radps;
        let course = kin.yaw_rad + if kin.speed_mps() > 0.5 { kin.sideslip_rad() } else { 0.0 };
        let mid = course + 0.5 * r * tp;
        let (px, py) = (kin.x_m + dist * mid.cos(), kin.y_m + dist * mid.sin());
        let ((tx, ty), preview) = path.point_at_from(s + dist, idx, self.preview);
        self.preview = preview;
        let e = -(tx - px) * sy + (ty - py) * cy;
        let lk = self.wheelbase_m + p.understeer_gradient_rad_per_mps2 * v * v;
        r * lk / v + p.gain * 2.0 * lk * e / (v * v * tp * tp)
    }
}

/// Move `current` toward `target` by at most `rate_max * h`, then clamp to +-`lock`.
pub(crate) fn limit_steer(current: f64, target: f64, lock: f64, rate_max: f64, h: f64) -> f64 {
    let target = target.clamp(-lock, lock);
    let step = rate_max * h;
    (current + (target - current).clamp(-step, step)).clamp(-lock, lock)
}

/// The steer at the end of a control period of `h` seconds that starts at `y0`: a continuous
/// rate limiter (|d steer/dt| <= `rate`, rad/s) tracking the command clamped to +-`lock`, the
/// command linear across the period from `c0` (at its start) to `c1` (at its end). Exact for
/// that command: piecewise on the pieces between the command's crossings of the lock; on each,
/// the steer closes its gap to the clamped command at the rate limit, then follows it where it
/// moves slower than the limit. (The sampled limiter, which moves the steer by at most `rate h`
/// toward the clamped `c1`, leaves the lock up to a period early when the command crosses it
/// within the period: an error first order in the period.)
pub(crate) fn rate_limited_steer(y0: f64, c0: f64, c1: f64, lock: f64, rate: f64, h: f64) -> f64 {
    let lock = lock.abs();
    let mut y = y0.clamp(-lock, lock);
    if !(h > 0.0 && rate >= 0.0 && c0.is_finite() && c1.is_finite()) {
        return limit_steer(y, c1, lock, rate.max(0.0), h.max(0.0));
    }
    let g = |s: f64| (c0 + (c1 - c0) * (s / h)).clamp(-lock, lock);
    let mut knots = [0.0, h, h, h];
    let mut n = 1;
    for edge in [-lock, lock] {
        let s = h * (edge - c0) / (c1 - c0);
        if s > 0.0 && s < h {
            knots[n] = s;
            n += 1;
        }
    }
    knots[1..n].sort_by(f64::total_cmp);
    knots[n] = h;
    for w in knots[..=n].windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let (ga, gb) = (g(a), g(b));
        let m = (gb - ga) / (b - a);
        let d = ga - y;
        let mut s = a;
        if d.abs() > 1e-12 {
            // closing the gap at the rate limit: does the steer reach the command within the piece?
            let close = rate - d.signum() * m;
            if close > 0.0 && d.abs() < close * (b - a) {
                s = a + d.abs() / close;
                y = g(s);
            } else {
                y += d.signum() * rate * (b - a);
                continue;
            }
        }
        // on the command from s: follow it, or fall behind at the limit where it moves faster
        y = if m.abs() <= rate { gb } else { y + m.signum() * rate * (b - s) };
    }
    y.clamp(-lock, lock)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The continuous limiter by brute force: [`limit_steer`] over `n` sub-steps of the command
    /// interpolated linearly from `c0` to `c1` (converges to the continuous limiter at first order
    /// in h / n).
    fn substepped(y0: f64, c0: f64, c1: f64, lock: f64, rate: f64, h: f64, n: usize) -> f64 {
        let mut y = y0;
        for j in 1..=n {
            let s = j as f64 / n as f64;
            y = limit_steer(y, c0 + (c1 - c0) * s, lock, rate, h / n as f64);
        }
        y
    }

    #[test]
    fn rate_limited_steer_matches_the_substepped_limiter() {
        let (lock, rate, h) = (0.6, 1.0, 0.01);
        let cases = [
            (0.6, 0.65, 0.55),   // leaves the lock within the period, command faster than the limit
            (0.6, 0.62, 0.598),  // leaves it, command slower than the limit
            (-0.6, -0.7, -0.5),  // the same at the other lock
            (0.58, 0.57, 0.7),   // reaches the lock within the period
            (0.0, 0.0, 0.005),   // tracks a slow command
            (0.0, 0.0, 0.05),    // falls behind a fast one
            (0.01, -0.02, 0.03), // above the command, which reverses faster than the limit
            (0.01, 0.0, 0.008),  // catches up with a slow command within the period
            (0.3, 0.3, 0.3),     // still
            (0.59, 2.0, -2.0),   // crosses both locks within the period
        ];
        for (y0, c0, c1) in cases {
            let exact = rate_limited_steer(y0, c0, c1, lock, rate, h);
            let brute = substepped(y0, c0, c1, lock, rate, h, 200_000);
            assert!((exact - brute).abs() <= 2.0 * rate * h / 200_000.0, "{y0} {c0} {c1}: {exact} vs {brute}");
        }
        // closed form: at the lock, the command crossing it at s* = h (c0 - lock) / (c0 - c1) and
        // falling faster than the limit, the steer leaves the lock at s* and falls at the limit
        let (c0, c1) = (0.65, 0.55);
        let s_star = h * (c0 - lock) / (c0 - c1);
        let y = rate_limited_steer(lock, c0, c1, lock, rate, h);
        assert!((y - (lock - rate * (h - s_star))).abs() < 1e-15, "{y}");
        // a command constant across the period: the sampled limiter
        for (y0, c) in [(0.0, 0.3), (0.0, 0.005), (0.59, 0.7), (-0.2, -0.9)] {
            assert_eq!(rate_limited_steer(y0, c, c, lock, rate, h), limit_steer(y0, c, lock, rate, h));
        }
        // non-finite commands and a non-positive period fall back to the sampled limiter: finite
        assert!(rate_limited_steer(0.1, f64::NAN, 0.2, lock, rate, h).is_finite());
        assert!(rate_limited_steer(0.1, 0.0, 0.2, lock, rate, 0.0).is_finite());
    }
}
