//! Integrators for one step of `dx/dt = f(x)` with the inputs held over the step.
//!
//! - [`Method::Rk4`]: classical fixed-step fourth-order Runge–Kutta, hand-written on `SVector`
//!   (no allocation); returns the stage k1 = f(x_k), the derivative at the start of the step.
//! - [`Method::Dopri5`] / [`Method::Dop853`]: ode_solvers' adaptive embedded Runge–Kutta pairs,
//!   integrating from one controller sample to the next with relative and absolute tolerances.
//!   ode_solvers has no public single-step API, so a solver is created per interval and its last
//!   output taken. The output is sparse (one entry per accepted step, the last one exactly at the
//!   interval's end): with dense output and an output increment equal to the interval, ode_solvers
//!   0.6.2 appends an end point extrapolated from the first accepted step whenever that step is
//!   shorter than the interval.

use nalgebra::SVector;
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
    let k1 = f(x);
    let k2 = f(&(x + k1 * (0.5 * h)));
    let k3 = f(&(x + k2 * (0.5 * h)));
    let k4 = f(&(x + k3 * h));
    (x + (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0), k1)
}

struct Sys<F>(F);

impl<const N: usize, F: Fn(&SVector<f64, N>) -> SVector<f64, N>> System<f64, SVector<f64, N>> for Sys<F> {
    fn system(&self, _t: f64, y: &SVector<f64, N>, dy: &mut SVector<f64, N>) {
        *dy = (self.0)(y);
    }
}

/// Advance `x` by `h` with `method`; an error names why the adaptive solver gave up.
pub fn step<const N: usize>(
    method: Method,
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
    x: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, String> {
    match method {
        Method::Rk4 => Ok(rk4_step(f, x, h).0),
        Method::Dopri5 { rtol, atol } => {
            let mut s = Dopri5::new(Sys(f), 0.0, h, h, *x, rtol, atol);
            // Sparse output records each accepted step's own solution, the last at exactly h
            // (dense output would interpolate the end point).
            s.set_output(OutputType::Sparse);
            s.integrate().map_err(|e| format!("dopri5: {e}"))?;
            s.y_out().last().copied().ok_or_else(|| "dopri5 produced no output".to_string())
        }
        Method::Dop853 { rtol, atol } => {
            let mut s = Dop853::new(Sys(f), 0.0, h, h, *x, rtol, atol);
            s.set_output(OutputType::Sparse);
            s.integrate().map_err(|e| format!("dop853: {e}"))?;
            s.y_out().last().copied().ok_or_else(|| "dop853 produced no output".to_string())
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
}
