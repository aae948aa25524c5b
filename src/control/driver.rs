//! Path-following driver: single-point predictive preview (MacAdam-type), with steering angle and
//! rate limits applied by the engine.
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

use serde::{Deserialize, Serialize};

use crate::maneuver::path::RefPath;
use crate::vehicle::Kinematics;

/// Driver tuning.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriverParams {
    /// Preview time, s (0.2–1.0; shorter tracks tighter but oscillates more; default 0.3).
    #[serde(default = "default_preview_time")]
    pub preview_time_s: f64,
    /// Smallest preview distance, m (2–10), used at low speed (default 3).
    #[serde(default = "default_preview_min")]
    pub preview_min_m: f64,
    /// Gain on the preview correction, dimensionless (0.5–1.5).
    #[serde(default = "one")]
    pub gain: f64,
    /// The driver's internal understeer gradient K, rad per m/s^2 (0–0.01; default 0).
    #[serde(default)]
    pub understeer_gradient_rad_per_mps2: f64,
}

fn default_preview_time() -> f64 {
    0.3
}
fn default_preview_min() -> f64 {
    3.0
}
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
    pub fn new(params: DriverParams, wheelbase_m: f64) -> Self {
        Self { params, wheelbase_m, cursor: None, preview: 0, lateral_error_m: 0.0 }
    }

    /// Desired road-wheel steer angle (before limits) for the vehicle at `kin`.
    pub fn steer(&mut self, path: &RefPath, kin: &Kinematics) -> f64 {
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
        let (sy, cy) = kin.yaw_rad.sin_cos();
        let e = -(tx - px) * sy + (ty - py) * cy;
        let lk = self.wheelbase_m + p.understeer_gradient_rad_per_mps2 * v * v;
        r * lk / v + p.gain * 2.0 * lk * e / (v * v * tp * tp)
    }
}

/// Move `current` toward `target` by at most `rate_max * h`, then clamp to +-`lock`.
pub fn limit_steer(current: f64, target: f64, lock: f64, rate_max: f64, h: f64) -> f64 {
    let target = target.clamp(-lock, lock);
    let step = rate_max * h;
    (current + (target - current).clamp(-step, step)).clamp(-lock, lock)
}
