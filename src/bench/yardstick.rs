//! The yardstick of the benchmark tables: a deliberately naive single-track (bicycle) model
//! integrated with classical RK4 at a fixed 1 ms step for 10 s of simulated time, written the
//! straightforward way (a plain derivative function of a state array, everything recomputed at
//! every stage, the C library's `atan`, `sin` and `sin_cos`), and independent of vehsim's models.
//!
//! It exists so that wall times measured on different machines can be compared: a table row's
//! median divided by the yardstick's median timed the same hour on the same machine
//! (`vehsim yardstick`, `scripts/perf_table.sh`) is a figure a reader can scale to their machine.
//! Its own cost is fixed by construction: 10 000 steps, 40 000 evaluations of the derivative,
//! 80 000 tyre evaluations.
//!
//! Model (SI units; x forward, y left, yaw counter-clockwise positive): states
//! [x, y, psi, vx, vy, r] in the ground frame (position, yaw) and the body frame (velocities,
//! yaw rate). Per axle a simple Magic Formula lateral tyre, Fy = -D sin(C atan(B alpha)) with
//! D = mu Fz (static axle loads), alpha the axle's slip angle; the front wheel is steered by
//! delta(t) = 2 deg sin(2 pi 0.5 Hz t); a proportional drive force holds vx near 10 m/s against an
//! aerodynamic drag. The vehicle is the shipped sedan's size (1600 kg, 3130 kg m^2, a = 1.09 m,
//! b = 1.71 m) on ice (mu 0.15).

use std::f64::consts::PI;

/// Fixed step, s.
pub const STEP_S: f64 = 1e-3;
/// Simulated time, s.
pub const DURATION_S: f64 = 10.0;
/// Number of steps of one run.
pub const STEPS: usize = 10_000;

const MASS_KG: f64 = 1600.0;
const YAW_INERTIA_KGM2: f64 = 3130.0;
const A_M: f64 = 1.09;
const B_M: f64 = 1.71;
const G: f64 = 9.81;
const MU: f64 = 0.15;
/// Magic Formula stiffness and shape factors (dimensionless).
const MF_B: f64 = 10.0;
const MF_C: f64 = 1.9;
/// Speed target, m/s, and the drive force per m/s of speed error, N s/m.
const V_TARGET: f64 = 10.0;
const DRIVE_GAIN: f64 = 2000.0;
/// Drag force per (m/s)^2, N s^2/m^2 (0.5 rho Cd A).
const DRAG: f64 = 0.4;
/// Steer amplitude, rad, and frequency, Hz.
const STEER_AMP_RAD: f64 = 2.0 * PI / 180.0;
const STEER_HZ: f64 = 0.5;

/// [x, y, psi, vx, vy, r].
pub type State = [f64; 6];

/// Steer angle at time t, rad.
pub fn steer(t: f64) -> f64 {
    STEER_AMP_RAD * (2.0 * PI * STEER_HZ * t).sin()
}

/// Lateral tyre force of an axle with load `fz`, N, at slip angle `alpha`, rad.
pub fn tyre_fy(fz: f64, alpha: f64) -> f64 {
    -MU * fz * (MF_C * (MF_B * alpha).atan()).sin()
}

/// The state's time derivative with steer angle `delta`, rad.
pub fn derivative(s: &State, delta: f64) -> State {
    let [_, _, psi, vx, vy, r] = *s;
    let l = A_M + B_M;
    let fz_front = MASS_KG * G * B_M / l;
    let fz_rear = MASS_KG * G * A_M / l;
    let alpha_front = (vy + A_M * r).atan2(vx) - delta;
    let alpha_rear = (vy - B_M * r).atan2(vx);
    let fy_front = tyre_fy(fz_front, alpha_front);
    let fy_rear = tyre_fy(fz_rear, alpha_rear);
    let drive = DRIVE_GAIN * (V_TARGET - vx) - DRAG * vx * vx;
    let (sin_d, cos_d) = delta.sin_cos();
    let fx_body = drive - fy_front * sin_d;
    let fy_body = fy_front * cos_d + fy_rear;
    let (sin_p, cos_p) = psi.sin_cos();
    [
        vx * cos_p - vy * sin_p,
        vx * sin_p + vy * cos_p,
        r,
        fx_body / MASS_KG + vy * r,
        fy_body / MASS_KG - vx * r,
        (A_M * fy_front * cos_d - B_M * fy_rear) / YAW_INERTIA_KGM2,
    ]
}

/// `s + h k`.
fn add(s: &State, k: &State, h: f64) -> State {
    let mut out = *s;
    for (o, d) in out.iter_mut().zip(k) {
        *o += h * d;
    }
    out
}

/// One classical RK4 step of size `h` from time `t` (the steer evaluated at every stage).
pub fn rk4_step(s: &State, t: f64, h: f64) -> State {
    let k1 = derivative(s, steer(t));
    let k2 = derivative(&add(s, &k1, 0.5 * h), steer(t + 0.5 * h));
    let k3 = derivative(&add(s, &k2, 0.5 * h), steer(t + 0.5 * h));
    let k4 = derivative(&add(s, &k3, h), steer(t + h));
    let mut out = *s;
    for i in 0..6 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// One run: 10 s at 1 ms from straight running at the target speed; the final state.
pub fn run() -> State {
    let mut s: State = [0.0, 0.0, 0.0, V_TARGET, 0.0, 0.0];
    for k in 0..STEPS {
        s = rk4_step(&s, k as f64 * STEP_S, STEP_S);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With a small steer held, the yaw rate settles at the linear single track's closed form
    /// r = v delta / (L + K v^2), K = m (b / C_f - a / C_r) / L, C = B C D (the tyre's slope at 0).
    #[test]
    fn steady_yaw_rate_matches_the_linear_single_track() {
        let delta = 0.002;
        let l = A_M + B_M;
        let cf = MF_B * MF_C * MU * MASS_KG * G * B_M / l;
        let cr = MF_B * MF_C * MU * MASS_KG * G * A_M / l;
        let mut s: State = [0.0, 0.0, 0.0, V_TARGET, 0.0, 0.0];
        for _ in 0..20_000 {
            let k1 = derivative(&s, delta);
            let k2 = derivative(&add(&s, &k1, 0.5 * STEP_S), delta);
            let k3 = derivative(&add(&s, &k2, 0.5 * STEP_S), delta);
            let k4 = derivative(&add(&s, &k3, STEP_S), delta);
            for i in 0..6 {
                s[i] += STEP_S / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        let v = s[3];
        let k_us = MASS_KG * (B_M / cf - A_M / cr) / l;
        let want = v * delta / (l + k_us * v * v);
        assert!(((s[5] - want) / want).abs() < 2e-3, "r {} vs {want}", s[5]);
    }

    /// The run is deterministic, finite, and stays a mild manoeuvre (speed held, no spin).
    #[test]
    fn run_is_deterministic_and_mild() {
        let (a, b) = (run(), run());
        assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        assert!(a.iter().all(|v| v.is_finite()));
        assert!((a[3] - V_TARGET).abs() < 0.1, "vx {}", a[3]);
        assert!(a[0] > 90.0 && a[0] < 101.0, "x {}", a[0]);
        assert!(a[5].abs() < 0.5, "r {}", a[5]);
    }
}
