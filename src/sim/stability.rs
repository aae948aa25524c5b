//! The model's fastest mode and the integration step it allows.
//!
//! The fastest mode is the eigenvalue of largest magnitude |lambda| (1/s) of the Jacobian of the
//! model's derivatives, taken by central differences at steady straight running (the manoeuvre's
//! start pose, no steer, no torque, contact at the surface temperature). On the sedan it is the
//! wheel spin coupled with transient slip (about 156 1/s on ice and 250 1/s on dry asphalt at
//! 10 m/s); it grows with speed, so callers evaluate it over the manoeuvre's speed range.
//!
//! Classical RK4 is stable for h |lambda| up to [`RK4_REAL_BOUND`] on the negative real axis (the
//! wheel-spin mode is a lightly damped complex pair, |lambda| ~ sqrt(C_kappa R_e^2 / (I_w sigma)),
//! near the imaginary axis, where RK4's bound is 2.83: the real-axis one is the smaller). The
//! default step keeps h |lambda| <= [`DEFAULT_H_LAMBDA`], where RK4 still damps the mode and its
//! error in the slow (vehicle) modes is far below the controller sampling's.
//!
//! Where that would make the step shorter than the control period (dry surfaces, higher speeds),
//! the spec layer picks the exponential RK4 ([`super::integrator::Method::Rk4Exp`]) instead: it
//! carries the wheel-spin / transient-slip pairs exactly, so the step is bounded by the fastest
//! *remaining* mode, the largest |eigenvalue| of the Jacobian with the pairs' 2 x 2 blocks removed
//! ([`fastest_rates_per_s`]).

use nalgebra::{DMatrix, SVector};

use crate::vehicle::{Environment, Inputs, VehicleModel};

/// Where RK4's stability region meets the negative real axis: h lambda = -2.785.
pub const RK4_REAL_BOUND: f64 = 2.785;
/// h |lambda| of the default step.
pub const DEFAULT_H_LAMBDA: f64 = 2.0;
/// Default controller sample period, s. The sampling, not the step, dominates the error of the
/// closed-loop runs: on the ISO 3888-2 lane change on ice (sedan, 10 m/s, mu 0.15) the largest
/// yaw-rate difference from a 0.25 ms run is 0.8e-4 (Pacejka), 2.6e-4 (Dugoff) and 3.5e-4 rad/s
/// (polynomial) at 5 ms, and 1.3e-4, 5.1e-4, 7.9e-4 rad/s at 10 ms, whatever the step; 5 ms keeps
/// every provider within the 5e-4 rad/s guard of tests/accuracy.rs.
pub const DEFAULT_CONTROL_PERIOD_S: f64 = 0.005;

/// Largest |eigenvalue| (1/s) of the model's Jacobian at steady straight running at `speed_mps`:
/// (of the whole Jacobian, of the Jacobian without the wheel-spin / transient-slip pairs' 2 x 2
/// blocks, [`VehicleModel::spin_slip_pairs`]: what the exponential RK4 leaves to its explicit part).
pub fn fastest_rates_per_s<const N: usize, M: VehicleModel<N>>(
    model: &M,
    env: &Environment,
    speed_mps: f64,
) -> (f64, f64) {
    let x0: SVector<f64, N> = model.initial_state(0.0, 0.0, 0.0, speed_mps);
    let u = Inputs { contact_temp_c: [env.surface_temp_c; 4], ..Inputs::default() };
    let mut jac = DMatrix::<f64>::zeros(N, N);
    for j in 0..N {
        let d = 1e-6 * x0[j].abs().max(1e-2);
        let (mut xp, mut xm) = (x0, x0);
        xp[j] += d;
        xm[j] -= d;
        let col = (model.derivatives(&xp, &u, env) - model.derivatives(&xm, &u, env)) / (2.0 * d);
        jac.set_column(j, &col);
    }
    let largest = |m: &DMatrix<f64>| {
        m.clone().complex_eigenvalues().iter().map(|z| z.norm()).filter(|v| v.is_finite()).fold(0.0, f64::max)
    };
    let full = largest(&jac);
    for &(w, k) in model.spin_slip_pairs().0 {
        for (a, b) in [(w, w), (w, k), (k, w), (k, k)] {
            jac[(a, b)] = 0.0;
        }
    }
    (full, largest(&jac))
}

/// The default step for control period `control_period_s` and fastest rate `lambda`: the period
/// divided into the fewest whole steps with h lambda <= [`DEFAULT_H_LAMBDA`].
pub fn default_step_s(control_period_s: f64, lambda: f64) -> f64 {
    let n = (control_period_s * lambda / DEFAULT_H_LAMBDA - 1e-9).ceil().max(1.0);
    control_period_s / n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_step_divides_the_period_within_the_bound() {
        assert_eq!(default_step_s(0.01, 156.0), 0.01);
        assert_eq!(default_step_s(0.01, 250.0), 0.005);
        assert_eq!(default_step_s(0.01, 200.0), 0.01);
        let h = default_step_s(0.01, 1234.0);
        assert!(h * 1234.0 <= DEFAULT_H_LAMBDA && (0.01 / h - (0.01 / h).round()).abs() < 1e-9);
    }
}
