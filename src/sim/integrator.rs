//! Integrators for one step of `dx/dt = f(t, x)`: the engine's right-hand side sees the time of
//! every stage, so inputs that are functions of time (open-loop steer) are evaluated per stage
//! while the controllers' outputs are held between their samples.
//!
//! - [`Method::Rk4`]: classical fixed-step fourth-order Runge–Kutta, hand-written on `SVector`
//!   (no allocation); returns the stages k1 = f(t_k, x_k) (the derivative at the start of the step)
//!   and k4 = f(t_k + h, x_k + h k3) (the derivative at the end, to O(h^3); the engine's predictor
//!   uses it).
//! - [`Method::Dopri5`] / [`Method::Dop853`]: ode_solvers' adaptive embedded Runge–Kutta pairs,
//!   integrating from one controller sample to the next with relative and absolute tolerances.
//!   ode_solvers has no public single-step API, so a solver is created per interval and its last
//!   output taken. The output is sparse (one entry per accepted step, the last one exactly at the
//!   interval's end): with dense output and an output increment equal to the interval, ode_solvers
//!   0.6.2 appends an end point extrapolated from the first accepted step whenever that step is
//!   shorter than the interval.

use nalgebra::{DVector, SVector};
use ode_solvers::{Dop853, Dopri5, OutputType, System};

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    Rk4,
    Dopri5 { rtol: f64, atol: f64 },
    Dop853 { rtol: f64, atol: f64 },
}

impl Method {
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 => "rk4",
            Method::Dopri5 { .. } => "dopri5",
            Method::Dop853 { .. } => "dop853",
        }
    }
}

/// One classical RK4 step of size `h`; returns (x_{k+1}, f(x_k)).
#[inline]
pub fn rk4_step<const N: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
    x: &SVector<f64, N>,
    h: f64,
) -> (SVector<f64, N>, SVector<f64, N>) {
    let (next, k1, _) = rk4_step_t(|_, s| f(s), 0.0, x, h);
    (next, k1)
}

/// One classical RK4 step of size `h` from time `t` for a time-dependent right-hand side;
/// returns (x_{k+1}, k1, k4).
#[inline]
pub fn rk4_step_t<const N: usize>(
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> (SVector<f64, N>, SVector<f64, N>, SVector<f64, N>) {
    let th = t + 0.5 * h;
    let k1 = f(t, x);
    let k2 = f(th, &(x + k1 * (0.5 * h)));
    let k3 = f(th, &(x + k2 * (0.5 * h)));
    let k4 = f(t + h, &(x + k3 * h));
    (x + (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0), k1, k4)
}

/// The system made autonomous for ode_solvers: the state carries the time as an extra last
/// component (derivative 1), and the right-hand side reads the stage time from it. ode_solvers
/// 0.6.2's DOP853 tableau has c_12 = 0 instead of 1, so the time it passes to the twelfth stage
/// is wrong; time carried in the state is advanced by the tableau's `a` rows, which are right.
struct Autonomous<F, const N: usize> {
    f: F,
}

impl<const N: usize, F: Fn(f64, &SVector<f64, N>) -> SVector<f64, N>> System<f64, DVector<f64>> for Autonomous<F, N> {
    fn system(&self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let x = SVector::<f64, N>::from_iterator(y.iter().take(N).copied());
        let d = (self.f)(y[N], &x);
        dy.rows_mut(0, N).copy_from(&d);
        dy[N] = 1.0;
    }
}

/// Advance `x` by `h` with `method` (autonomous right-hand side); an error names why the adaptive
/// solver gave up.
pub fn step<const N: usize>(
    method: Method,
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
    x: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, String> {
    step_t(method, |_, s| f(s), 0.0, x, h)
}

/// Advance `x` from time `t` by `h` with `method`; an error names why the adaptive solver gave up.
pub fn step_t<const N: usize>(
    method: Method,
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, String> {
    match method {
        Method::Rk4 => Ok(rk4_step_t(f, t, x, h).0),
        Method::Dopri5 { rtol, atol } | Method::Dop853 { rtol, atol } => {
            let y0 = DVector::from_iterator(N + 1, x.iter().copied().chain([t]));
            let sys = Autonomous { f };
            // Hairer's default parameters, as ode_solvers' `new` sets them, except that the
            // stiffness test is off (the engine detects divergence itself). Sparse output records
            // each accepted step's own solution, the last at exactly h (dense output would
            // interpolate the end point).
            let (name, out) = if matches!(method, Method::Dopri5 { .. }) {
                let mut s = Dopri5::from_param(
                    sys,
                    0.0,
                    h,
                    h,
                    y0,
                    rtol,
                    atol,
                    0.9,
                    0.04,
                    0.2,
                    10.0,
                    h,
                    0.0,
                    100_000,
                    u32::MAX,
                    OutputType::Sparse,
                );
                ("dopri5", s.integrate().map(|_| s.y_out().last().cloned()))
            } else {
                let mut s = Dop853::from_param(
                    sys,
                    0.0,
                    h,
                    h,
                    y0,
                    rtol,
                    atol,
                    0.9,
                    0.0,
                    0.333,
                    6.0,
                    h,
                    0.0,
                    100_000,
                    u32::MAX,
                    OutputType::Sparse,
                );
                ("dop853", s.integrate().map(|_| s.y_out().last().cloned()))
            };
            match out {
                Err(e) => Err(format!("{name}: {e}")),
                Ok(None) => Err(format!("{name} produced no output")),
                Ok(Some(y)) => Ok(SVector::<f64, N>::from_iterator(y.iter().take(N).copied())),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// Harmonic oscillator x'' = -x: RK4's global error falls 16-fold when the step halves, and the
    /// adaptive methods meet tight tolerances against the closed form cos(t).
    #[test]
    fn methods_against_closed_form() {
        let f = |x: &Vector2<f64>| Vector2::new(x[1], -x[0]);
        let run = |m: Method, h: f64| {
            let mut x = Vector2::new(1.0, 0.0);
            let n = (2.0 / h).round() as usize;
            for _ in 0..n {
                x = step(m, f, &x, h).unwrap();
            }
            (x[0] - 2.0_f64.cos()).abs()
        };
        let (e1, e2) = (run(Method::Rk4, 0.1), run(Method::Rk4, 0.05));
        let order = (e1 / e2).log2();
        assert!((order - 4.0).abs() < 0.15, "observed order {order}");
        assert!(run(Method::Dopri5 { rtol: 1e-10, atol: 1e-12 }, 0.5) < 1e-9);
        assert!(run(Method::Dop853 { rtol: 1e-12, atol: 1e-14 }, 0.5) < 1e-11);
    }

    const METHODS: [Method; 3] =
        [Method::Rk4, Method::Dopri5 { rtol: 1e-10, atol: 1e-12 }, Method::Dop853 { rtol: 1e-12, atol: 1e-14 }];

    /// Integrate `f` from `x0` over [0, t_end] in steps of `h` with `method`.
    fn solve<const N: usize>(
        method: Method,
        f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
        x0: SVector<f64, N>,
        t_end: f64,
        h: f64,
    ) -> SVector<f64, N> {
        let n = (t_end / h).round() as usize;
        (0..n).fold(x0, |x, k| step_t(method, &f, k as f64 * h, &x, h).unwrap())
    }

    /// Forced oscillator x'' + x = sin(2 t), x(0) = x'(0) = 0, a right-hand side that depends on
    /// time (as open-loop inputs do): x(t) = (2 sin t - sin 2t) / 3. RK4 converges at fourth
    /// order with the forcing evaluated at every stage; the adaptive methods meet their tolerance.
    #[test]
    fn forced_oscillator_every_method() {
        let f = |t: f64, x: &Vector2<f64>| Vector2::new(x[1], -x[0] + (2.0 * t).sin());
        let exact = |t: f64| (2.0 * t.sin() - (2.0 * t).sin()) / 3.0;
        let err = |m: Method, h: f64| (solve(m, f, Vector2::zeros(), 3.0, h)[0] - exact(3.0)).abs();
        let order = (err(Method::Rk4, 0.04) / err(Method::Rk4, 0.02)).log2();
        assert!((order - 4.0).abs() < 0.15, "observed order {order}");
        assert!(err(METHODS[1], 0.5) < 1e-8);
        assert!(err(METHODS[2], 0.5) < 1e-10);
    }

    /// Linear single-track model (lateral velocity v and yaw rate r at speed u, cornering
    /// stiffnesses per axle) under a constant steer: the steady state is the closed form
    /// r = u delta / (L + K u^2) with K = m (b C_r - a C_f) / (L C_f C_r), and
    /// v = r (b - m a u^2 / (L C_r)); every method reaches it.
    #[test]
    fn linear_bicycle_steady_state_every_method() {
        let (m, iz, a, b, cf, cr, u, delta) = (1500.0, 2500.0, 1.1, 1.6, 80_000.0, 90_000.0, 15.0, 0.02);
        let l = a + b;
        let f = |_t: f64, x: &Vector2<f64>| {
            let (v, r) = (x[0], x[1]);
            let fyf = cf * (delta - (v + a * r) / u);
            let fyr = cr * (-(v - b * r) / u);
            Vector2::new((fyf + fyr) / m - u * r, (a * fyf - b * fyr) / iz)
        };
        let k = m * (b * cr - a * cf) / (l * cf * cr);
        let r_ss = u * delta / (l + k * u * u);
        let v_ss = r_ss * (b - m * a * u * u / (l * cr));
        for method in METHODS {
            let x = solve(method, f, Vector2::zeros(), 20.0, 0.01);
            assert!((x[1] - r_ss).abs() < 1e-9 * r_ss.abs(), "{method:?}: r {} vs {r_ss}", x[1]);
            assert!((x[0] - v_ss).abs() < 1e-9 * v_ss.abs().max(1e-3), "{method:?}: v {} vs {v_ss}", x[0]);
        }
    }
}
