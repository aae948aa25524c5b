//! The model's fastest mode and the integration step it allows.
//!
//! The fastest mode is the eigenvalue of largest magnitude |lambda| (1/s) of the Jacobian of the
//! model's derivatives, taken by central differences at steady straight running (the manoeuvre's
//! start pose, no steer, no torque, contact at the surface temperature). On the sedan it is the
//! wheel spin coupled with transient slip (about 156 1/s on ice and 250 1/s on dry asphalt at
//! 10 m/s); it grows with speed, so callers evaluate it over the manoeuvre's speed range.
//!
//! Classical RK4 is stable for h |lambda| up to 2.785 on the negative real axis (the
//! wheel-spin mode is a lightly damped complex pair, |lambda| ~ sqrt(C_kappa R_e^2 / (I_w sigma)),
//! near the imaginary axis, where RK4's bound is 2.83: the real-axis one is the smaller). The
//! default step keeps h |lambda| <= [`DEFAULT_H_LAMBDA`], where RK4 still damps the mode and its
//! error in the slow (vehicle) modes is far below the controller sampling's.
//!
//! Where that would make the step shorter than the control period (dry surfaces, stiff tyres),
//! the spec layer picks the exponential RK4 ([`super::integrator::Method::Rk4Exp`]) instead: it
//! carries the wheel-spin / transient-slip pairs exactly, so the pairs' own rate no longer bounds
//! the step. What does is the stability of the whole split step (the pairs stay coupled to the
//! body through the explicit part): [`Analysis::exp_stable`] applies one exponential RK4 step, the
//! engine's own `rk4_exp_step_t`, to the linearised model and asks for a spectral radius <= 1.
//! The default takes the longest whole division of the control period that is stable with a
//! margin of [`EXP_MARGIN`] on the step.

use nalgebra::{DMatrix, SMatrix, SVector};

use super::integrator::{rk4_exp_step_t, ExpPair};
use crate::vehicle::{Environment, Inputs, VehicleModel};

/// Most QR iterations of one eigenvalue computation (a converging one of the models' 10-20 states
/// takes well under a hundred).
const SCHUR_MAX_ITER: usize = 10_000;

/// Factor by which the default exponential RK4 step must stay stable when lengthened.
pub const EXP_MARGIN: f64 = 1.3;

/// h |lambda| of the default step.
pub const DEFAULT_H_LAMBDA: f64 = 2.0;
/// Default controller sample period, s, for every model, provider and contact estimate. The
/// sampling, not the step, dominates the error of the closed-loop runs. With the engine's
/// predicted first-order hold (`super::engine`), on the ISO 3888-2 lane change on ice (sedan,
/// 10 m/s held, mu 0.15) the largest yaw-rate difference from a step = period = 0.25 ms run at
/// step = period = 10 ms is, bicycle / 4-DOF: linear 1.3e-4 / 1.4e-4, polynomial 3.6e-4 / 3.3e-4,
/// Pacejka 2.6e-4 / 1.9e-4, Dugoff 3.5e-4 / 3.7e-4, ATIIM-Pacejka with the ATIIM contact estimate
/// 9.8e-5 / 1.8e-4 rad/s, within the 5e-4 rad/s guard of tests/accuracy.rs; at 20 ms every
/// saturating provider is beyond it (9.2e-4 to 1.1e-3 rad/s; ATIIM 6.4e-4 / 7.0e-4 with a 10 ms
/// step) and the unsaturated linear tyre needs a shorter step than the period. So 10 ms.
///
/// The ATIIM case once needed 5 ms on the 4-DOF model (7.6e-4 rad/s at 10 ms, 1.3e-4 at 5 ms,
/// 1.3e-4 at 2.5 ms: no order), from two errors of the sampling that did not shrink at second
/// order: the estimate priced its heat with the friction force at the previous sample's contact
/// temperature, a loop whose gain passes -1 near melting, so the estimate alternated between a
/// melting and a cooler contact from sample to sample (at 0.25 ms as at 10 ms; now solved for
/// the consistent temperature, `crate::contact::ContactTemperature::update_coupled`); and the
/// sampled steering rate limit left the lock up to a period early (now a continuous limiter
/// across the period, `crate::control::driver::rate_limited_steer`). With both, the 4-DOF
/// lane change converges at second order: with the estimate solved at each sample's own state,
/// 1.8e-4, 4.0e-5, 1.1e-5, 2.8e-6 rad/s at 10, 5, 2.5, 1.25 ms (docs/performance.md).
pub const DEFAULT_CONTROL_PERIOD_S: f64 = 0.01;

/// The linearised model at steady straight running at one speed.
pub struct Analysis {
    /// Largest |eigenvalue| of the Jacobian, 1/s (the fastest mode).
    pub rate_per_s: f64,
    /// Spectral radius of one exponential RK4 step of a given size for the linearised model.
    radius: Box<dyn Fn(f64) -> f64>,
}

impl Analysis {
    /// Whether the exponential RK4 at step `h` (s) is stable for the linearised model.
    pub fn exp_stable(&self, h: f64) -> bool {
        (self.radius)(h) <= 1.0 + 1e-6
    }

    /// The longest step up to `h_max` (s), on a grid of 100 geometric steps from 0.1 ms, below
    /// which every grid step is stable for the exponential RK4 (0 if none is).
    pub fn exp_max_step(&self, h_max: f64) -> f64 {
        let grid = (0..=100).map(|i| 1e-4 * (h_max / 1e-4).powf(i as f64 / 100.0));
        grid.take_while(|&h| self.exp_stable(h)).last().unwrap_or(0.0)
    }
}

/// The Jacobian of `model` at steady straight running at `speed_mps` (the manoeuvre's start
/// pose, no steer, no torque, contact at the surface temperature), by central differences; its
/// fastest rate; and the exponential RK4's step on it, with the pairs linearised as the engine
/// does (the pair block of the Jacobian, its omega-omega entry left to the explicit part).
pub fn analyse<const N: usize, M: VehicleModel<N>>(model: &M, env: &Environment, speed_mps: f64) -> Analysis {
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
    // Bounded in time whatever the model's coefficients: a matrix with a non-finite entry, or
    // whose Schur iteration does not converge within SCHUR_MAX_ITER, counts as infinitely fast.
    let largest = |m: DMatrix<f64>| {
        if !m.iter().all(|v| v.is_finite()) {
            return f64::INFINITY;
        }
        match nalgebra::linalg::Schur::try_new(m, f64::EPSILON, SCHUR_MAX_ITER) {
            Some(s) => s.complex_eigenvalues().iter().map(|z| z.norm()).filter(|v| v.is_finite()).fold(0.0, f64::max),
            None => f64::INFINITY,
        }
    };
    let rate_per_s = largest(jac.clone());
    let jm = SMatrix::<f64, N, N>::from_iterator(jac.iter().copied());
    let pairs: Vec<(usize, usize)> = model.spin_slip().map_or(&[][..], |s| s.pairs).to_vec();
    let radius = move |h: f64| {
        let lin: Vec<ExpPair> =
            pairs.iter().map(|&(w, k)| ExpPair::new(w, k, [[0.0, jm[(w, k)]], [jm[(k, w)], jm[(k, k)]]], h)).collect();
        let mut step = DMatrix::<f64>::zeros(N, N);
        for j in 0..N {
            let x = SVector::<f64, N>::from_fn(|i, _| if i == j { 1.0 } else { 0.0 });
            let next = rk4_exp_step_t(|_, s: &SVector<f64, N>| jm * s, 0.0, &x, h, jm * x, &lin);
            step.set_column(j, &next);
        }
        largest(step)
    };
    Analysis { rate_per_s, radius: Box::new(radius) }
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
