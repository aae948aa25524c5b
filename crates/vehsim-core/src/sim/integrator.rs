//! Integrators for one step of `dx/dt = f(t, x)`: the engine's right-hand side sees the time of
//! every stage, so inputs that are functions of time (open-loop steer) are evaluated per stage
//! while the controllers' outputs are held between their samples.
//!
//! - [`Method::Rk4`]: classical fixed-step fourth-order Runge–Kutta, hand-written on `SVector`
//!   (no allocation); returns the stages k1 = f(t_k, x_k) (the derivative at the start of the step)
//!   and k4 = f(t_k + h, x_k + h k3) (the derivative at the end, to O(h^3); the engine's predictor
//!   uses it).
//! - [`Method::Rk4Exp`]: RK4 with the stiff wheel-spin / transient-slip pairs integrated by their
//!   exact exponential (a Lawson, or integrating-factor, RK4; `rk4_exp_step_t`): the pairs'
//!   2 x 2 linearisation L, taken at the step's start, is carried exactly by exp(h L / 2) and
//!   exp(h L), and RK4 integrates only the remainder f(x) - L (x - x_k). Fourth order for smooth
//!   right-hand sides (any fixed L leaves a consistent fourth-order method), the steady state of
//!   the pairs is kept exactly (the remainder vanishes there), and the step is no longer bounded by
//!   the pairs' own rate but by the fastest remaining mode.
//! - [`Method::Rk4Lag`], [`rk4_lag_step`]: RK4 with chosen components that are first-order lags
//!   dy/dt = k (u - y) relaxed exactly over the step towards a linear input ([`relax`]), stable
//!   for any lag rate (the model declares its lags; the discovery replay's step).
//! - [`Method::Dopri5`] / [`Method::Dop853`]: ode_solvers' adaptive embedded Runge–Kutta pairs,
//!   integrating from one controller sample to the next with relative and absolute tolerances.
//!   ode_solvers has no public single-step API, so a solver is created per interval and its last
//!   output taken. The output is sparse (one entry per accepted step, the last one exactly at the
//!   interval's end): with dense output and an output increment equal to the interval, ode_solvers
//!   0.6.2 appends an end point extrapolated from the first accepted step whenever that step is
//!   shorter than the interval.

use nalgebra::{DVector, SVector};
use ode_solvers::{Dop853, Dopri5, OutputType, System};

use crate::vehicle::capability::{SpinSlip, MAX_LAGS};

/// Integration method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical fixed-step fourth-order Runge–Kutta.
    Rk4,
    /// RK4 with the wheel-spin / transient-slip pairs integrated exponentially (see the module docs).
    Rk4Exp,
    /// RK4 with the model's first-order lag components relaxed exactly ([`rk4_lag_step`];
    /// `crate::vehicle::capability::Lagged`): the discovery replay's method.
    Rk4Lag,
    /// Adaptive Dormand–Prince 5(4) of ode_solvers, between controller samples.
    Dopri5 {
        /// Relative tolerance, in (0, 1) (spec default 1e-8).
        rtol: f64,
        /// Absolute tolerance, in state units, in (0, 1) (spec default 1e-10).
        atol: f64,
    },
    /// Adaptive Dormand–Prince 8(5,3) of ode_solvers, between controller samples.
    Dop853 {
        /// Relative tolerance, in (0, 1) (spec default 1e-8).
        rtol: f64,
        /// Absolute tolerance, in state units, in (0, 1) (spec default 1e-10).
        atol: f64,
    },
}

impl Method {
    /// The method's name in spec and result files (`rk4`, `rk4_exp`, `rk4_lag`, `dopri5`, `dop853`).
    pub fn name(&self) -> &'static str {
        match self {
            Method::Rk4 => "rk4",
            Method::Rk4Exp => "rk4_exp",
            Method::Rk4Lag => "rk4_lag",
            Method::Dopri5 { .. } => "dopri5",
            Method::Dop853 { .. } => "dop853",
        }
    }
}

/// What an integrator steps: the right-hand side dx/dt = f(t, x) and the structure that the
/// exponential and lag methods use beside it (a plain problem has neither).
pub trait Problem<const N: usize> {
    /// f(t_s, x).
    fn rhs(&self, t_s: f64, x: &SVector<f64, N>) -> SVector<f64, N>;

    /// The stiff wheel-spin / transient-slip pairs ([`Method::Rk4Exp`]). Default: none.
    fn spin_slip(&self) -> Option<SpinSlip> {
        None
    }

    /// The first-order lag components ([`Method::Rk4Lag`]). Default: none.
    fn lag_states(&self) -> &[usize] {
        &[]
    }

    /// At time `t_s` and state `x`: the derivative with the lag components' entries left out and
    /// the lags' inputs (see [`crate::vehicle::capability::Lagged::lag_split`]). Default: f and
    /// no lags.
    fn lag_split(&self, t_s: f64, x: &SVector<f64, N>) -> (SVector<f64, N>, [f64; MAX_LAGS]) {
        (self.rhs(t_s, x), [0.0; MAX_LAGS])
    }
}

/// The first stage of a step, evaluated by the caller at the step's start (the engine takes its
/// output row and its prediction from that evaluation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FirstStage<const N: usize> {
    /// k1 = f(t, x): every method but [`Method::Rk4Lag`].
    Derivative(SVector<f64, N>),
    /// [`Method::Rk4Lag`]: [`Problem::lag_split`] at the start and the lags' rates k_j (1/s).
    Lag {
        /// The derivative with the lag components' entries left out.
        body: SVector<f64, N>,
        /// The lags' inputs.
        inputs: [f64; MAX_LAGS],
        /// The lags' rates, taken at the step's start.
        rates: [f64; MAX_LAGS],
    },
}

impl Method {
    /// One step of `h` of `problem` from time `t` and state `x`, whose first stage `first` the
    /// caller evaluated (a [`FirstStage::Lag`] for [`Method::Rk4Lag`], a derivative otherwise;
    /// the other kind is an error). The one entry to every integrator; an error names why the
    /// adaptive solver gave up.
    #[inline]
    pub fn step<const N: usize>(
        &self,
        problem: &impl Problem<N>,
        t: f64,
        x: &SVector<f64, N>,
        h: f64,
        first: &FirstStage<N>,
    ) -> Result<SVector<f64, N>, String> {
        let f = |ts: f64, s: &SVector<f64, N>| problem.rhs(ts, s);
        match (*self, first) {
            (Method::Rk4Lag, FirstStage::Lag { body, inputs, rates }) => {
                let split = |s: &SVector<f64, N>, c: f64| problem.lag_split(t + c * h, s);
                Ok(rk4_lag_step_k1(split, x, h, problem.lag_states(), rates, (*body, *inputs)))
            }
            (Method::Rk4Lag, FirstStage::Derivative(_)) | (_, FirstStage::Lag { .. }) => {
                Err(format!("{}: first stage of the wrong kind", self.name()))
            }
            (Method::Rk4, FirstStage::Derivative(k1)) => Ok(rk4_step_k1(f, t, x, h, *k1).0),
            (Method::Rk4Exp, FirstStage::Derivative(k1)) => {
                let mut pairs = [ExpPair::new(0, 0, [[0.0; 2]; 2], h); 4];
                let n = spin_slip_linearisation(problem.spin_slip(), &f, t, x, k1, h, &mut pairs);
                Ok(rk4_exp_step_t(f, t, x, h, *k1, &pairs[..n]))
            }
            (m, FirstStage::Derivative(_)) => step_t(m, f, t, x, h),
        }
    }
}

/// Relative-slip perturbation of the finite difference in [`spin_slip_linearisation`].
const SLIP_DIFF: f64 = 1e-6;

/// The linear parts of the wheel-spin / transient-slip pairs at state `x` (derivative `k1`) and
/// their propagators over a step `h`, into `out`; returns how many. The pairs are (omega index,
/// kappa index) per wheel and d(dkappa/dt)/d(omega) = R_e / sigma (exact: the slip equation is
/// linear in omega). The kappa column, d(domega/dt)/d(kappa) (the tyre's slip stiffness through
/// R_e / I_w) and d(dkappa/dt)/d(kappa) = -max(|V_x|, V_low) / sigma, comes from one forward
/// difference with every wheel's kappa moved at once (a wheel's spin and slip depend on no other
/// wheel's slip). d(domega/dt)/d(omega) (the regularised brake and rolling-resistance torque,
/// non-zero only near standstill and at most `TORQUE_RATE_MAX`) is left to the explicit part.
fn spin_slip_linearisation<const N: usize>(
    spin_slip: Option<SpinSlip>,
    f: &impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    k1: &SVector<f64, N>,
    h: f64,
    out: &mut [ExpPair; 4],
) -> usize {
    let Some(SpinSlip { pairs, kappa_per_omega }) = spin_slip.filter(|s| !s.pairs.is_empty()) else {
        return 0;
    };
    let mut xp = *x;
    for &(_, k) in pairs {
        xp[k] += SLIP_DIFF;
    }
    let dp = f(t, &xp);
    let n = pairs.len().min(out.len());
    for (o, &(w, k)) in out.iter_mut().zip(pairs) {
        let l = [[0.0, (dp[w] - k1[w]) / SLIP_DIFF], [kappa_per_omega, (dp[k] - k1[k]) / SLIP_DIFF]];
        *o = ExpPair::new(w, k, l, h);
    }
    n
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
    let k1 = f(t, x);
    rk4_step_k1(f, t, x, h, k1)
}

/// [`rk4_step_t`] with the first stage k1 = f(t, x) already evaluated (the engine takes the
/// output row from that evaluation). Always inlined: the engine's per-step cost depends on it
/// (callgrind, one lane change: 0.3 % more instructions as a call).
#[inline(always)]
pub(crate) fn rk4_step_k1<const N: usize>(
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
    k1: SVector<f64, N>,
) -> (SVector<f64, N>, SVector<f64, N>, SVector<f64, N>) {
    let th = t + 0.5 * h;
    let k2 = f(th, &(x + k1 * (0.5 * h)));
    let k3 = f(th, &(x + k2 * (0.5 * h)));
    let k4 = f(t + h, &(x + k3 * h));
    (x + (k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0), k1, k4)
}

/// Response after a time t of the first-order lag dy/dt = k (u - y), from y0, when its input u moves
/// linearly from u0 to u1 over t; z = k t >= 0. Exact for that input:
/// y = u1 + (y0 - u0) e^-z - (u1 - u0) (1 - e^-z) / z. It gives y0 at z = 0 and u1 as z -> inf
/// (an infinitely fast lag), and the trapezoidal rule y0 + z ((u0 + u1) / 2 - y0) for small z.
pub fn relax(y0: f64, u0: f64, u1: f64, z: f64) -> f64 {
    if !(z > 0.0) {
        return y0;
    }
    let e = (-z).exp();
    let phi = if z < 1e-8 { 1.0 - 0.5 * z } else { -(-z).exp_m1() / z };
    u1 + (y0 - u0) * e - (u1 - u0) * phi
}

/// One step of size `h` for a state whose components `lags[j]` are first-order lags
/// dy_j/dt = k_j (u_j - y_j), the rest integrated by classical RK4. `body(y, c)` gives the
/// derivative of the other components at `y` (its entries at the lag indices are not used) and
/// the lags' inputs u_j at `y` and fraction `c` of the step (0, 1/2 or 1: an input that is a
/// known function of time over the step is set from `c`). `k[j]` (1/s) is lag j's rate, taken at
/// the step's start; a lag with k_j = 0 is left to `body` like any other component. Each lag relaxes
/// exactly ([`relax`]) towards an input taken as linear between its value at the step's start and
/// its value at each stage's state (an input that depends on a lag is first taken at the lag
/// relaxed towards the best estimate of that input so far: the start's for the first midpoint
/// stage, the first midpoint's for the second, their linear extrapolation for the end stage and
/// the end stage's for the result; with the start's everywhere, a lag-dependent input such as a
/// slip angle behind a compliant steer lags by up to 6 times more). The step is stable for any lag rate; with every k_j = 0
/// it is RK4 on `body`. `lags` may be shorter than `L` (the rest of `k` is then unused).
/// ([`Method::Rk4Lag`]: the engine's step for models that declare lag states.)
pub fn rk4_lag_step<const N: usize, const L: usize>(
    body: impl Fn(&SVector<f64, N>, f64) -> (SVector<f64, N>, [f64; L]),
    x0: &SVector<f64, N>,
    h: f64,
    lags: &[usize],
    k: &[f64; L],
) -> SVector<f64, N> {
    let first = body(x0, 0.0);
    rk4_lag_step_k1(body, x0, h, lags, k, first)
}

/// [`rk4_lag_step`] with the first stage `body(x0, 0)` already evaluated.
pub(crate) fn rk4_lag_step_k1<const N: usize, const L: usize>(
    body: impl Fn(&SVector<f64, N>, f64) -> (SVector<f64, N>, [f64; L]),
    x0: &SVector<f64, N>,
    h: f64,
    lags: &[usize],
    k: &[f64; L],
    (k1, u0): (SVector<f64, N>, [f64; L]),
) -> SVector<f64, N> {
    if lags.iter().zip(k).all(|(_, &k)| k == 0.0) {
        return rk4_step_k1(|ts, s| body(s, ts / h).0, 0.0, x0, h, k1).0;
    }
    let relax_to = |y: &mut SVector<f64, N>, u: &[f64; L], c: f64| {
        for (j, &i) in lags.iter().enumerate() {
            if k[j] > 0.0 {
                y[i] = relax(x0[i], u0[j], u[j], k[j] * c * h);
            }
        }
    };
    // The state at fraction c of the step with its lags relaxed: first towards `guess` (the
    // best estimate of their inputs there so far), then towards their inputs at that state.
    let stage = |mut y: SVector<f64, N>, c: f64, guess: &[f64; L]| {
        relax_to(&mut y, guess, c);
        let u = body(&y, c).1;
        relax_to(&mut y, &u, c);
        y
    };
    let (k2, u2) = body(&stage(x0 + k1 * (0.5 * h), 0.5, &u0), 0.5);
    let (k3, u3) = body(&stage(x0 + k2 * (0.5 * h), 0.5, &u2), 0.5);
    let extrapolated: [f64; L] = std::array::from_fn(|j| 2.0 * u3[j] - u0[j]);
    let (k4, u4) = body(&stage(x0 + k3 * h, 1.0, &extrapolated), 1.0);
    stage(x0 + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0), 1.0, &u4)
}

/// A 2 x 2 block of the state, components (`i`, `j`), integrated exactly over a step: its linear
/// part L (row-major, 1/s) and the propagators exp(h L / 2) and exp(h L).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ExpPair {
    pub i: usize,
    pub j: usize,
    pub l: [[f64; 2]; 2],
    pub half: [[f64; 2]; 2],
    pub full: [[f64; 2]; 2],
}

impl ExpPair {
    /// The pair (`i`, `j`) with linear part `l` (row-major, 1/s) over a step of `h` s.
    pub fn new(i: usize, j: usize, l: [[f64; 2]; 2], h: f64) -> Self {
        let k = 0.5 * h;
        let e = expm2([[l[0][0] * k, l[0][1] * k], [l[1][0] * k, l[1][1] * k]]);
        // exp(h L) = exp(h L / 2)^2.
        let full = [
            [e[0][0] * e[0][0] + e[0][1] * e[1][0], e[0][0] * e[0][1] + e[0][1] * e[1][1]],
            [e[1][0] * e[0][0] + e[1][1] * e[1][0], e[1][0] * e[0][1] + e[1][1] * e[1][1]],
        ];
        Self { i, j, l, half: e, full }
    }
}

/// exp(A) of a real 2 x 2 matrix in closed form: with m = tr A / 2 and q = m^2 - det A,
/// exp(A) = e^m (c I + s (A - m I)), where c = cosh(sqrt q), s = sinh(sqrt q) / sqrt q for q > 0,
/// c = cos(sqrt -q), s = sin(sqrt -q) / sqrt -q for q < 0 (a complex pair), and their series
/// near q = 0 (|q| < 1e-6, truncated after q^2: relative error below 1e-19).
pub(crate) fn expm2(a: [[f64; 2]; 2]) -> [[f64; 2]; 2] {
    let m = 0.5 * (a[0][0] + a[1][1]);
    let q = m * m - (a[0][0] * a[1][1] - a[0][1] * a[1][0]);
    let (c, s) = if q.abs() < 1e-6 {
        (1.0 + q / 2.0 + q * q / 24.0, 1.0 + q / 6.0 + q * q / 120.0)
    } else if q > 0.0 {
        let r = q.sqrt();
        (r.cosh(), r.sinh() / r)
    } else {
        let r = (-q).sqrt();
        let (sn, cs) = r.sin_cos();
        (cs, sn / r)
    };
    let e = m.exp();
    [[e * (c + s * (a[0][0] - m)), e * s * a[0][1]], [e * s * a[1][0], e * (c + s * (a[1][1] - m))]]
}

/// `v` with every pair's components multiplied by its half-step (`full` false) or whole-step
/// propagator; the other components unchanged.
#[inline]
fn propagate<const N: usize>(pairs: &[ExpPair], v: &SVector<f64, N>, full: bool) -> SVector<f64, N> {
    let mut w = *v;
    for p in pairs {
        let e = if full { &p.full } else { &p.half };
        let (a, b) = (v[p.i], v[p.j]);
        w[p.i] = e[0][0] * a + e[0][1] * b;
        w[p.j] = e[1][0] * a + e[1][1] * b;
    }
    w
}

/// One exponential (Lawson) RK4 step of size `h` from time `t` (see the module docs), with the
/// pairs' linear parts and propagators for this `h` in `pairs` and `k1` = f(t, x) already
/// evaluated. With d = x - x_k and the remainder g(s) = f(s) - L (s - x_k):
///
/// ```text
/// g1 = k1,                       x2 = x_k + E_1/2 (h/2 g1)
/// g2 = g(x2),                    x3 = x_k + h/2 g2
/// g3 = g(x3),                    x4 = x_k + h E_1/2 g3
/// g4 = g(x4),                    x_k+1 = x_k + h/6 (E_1 g1 + 2 E_1/2 (g2 + g3) + g4)
/// ```
///
/// with E_1/2 = exp(h L / 2), E_1 = exp(h L) on the pairs and the identity elsewhere: without
/// pairs it is exactly [`rk4_step_t`].
pub(crate) fn rk4_exp_step_t<const N: usize>(
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
    k1: SVector<f64, N>,
    pairs: &[ExpPair],
) -> SVector<f64, N> {
    // g(s) = f(t, s) - L (s - x) on the pairs' components.
    let g = |ts: f64, s: &SVector<f64, N>| {
        let mut d = f(ts, s);
        for p in pairs {
            let (l, a, b) = (&p.l, s[p.i] - x[p.i], s[p.j] - x[p.j]);
            d[p.i] -= l[0][0] * a + l[0][1] * b;
            d[p.j] -= l[1][0] * a + l[1][1] * b;
        }
        d
    };
    let th = t + 0.5 * h;
    let g2 = g(th, &(x + propagate(pairs, &(k1 * (0.5 * h)), false)));
    let g3 = g(th, &(x + g2 * (0.5 * h)));
    let g4 = g(t + h, &(x + propagate(pairs, &(g3 * h), false)));
    x + (propagate(pairs, &k1, true) + propagate(pairs, &(g2 + g3), false) * 2.0 + g4) * (h / 6.0)
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
pub(crate) fn step_t<const N: usize>(
    method: Method,
    f: impl Fn(f64, &SVector<f64, N>) -> SVector<f64, N>,
    t: f64,
    x: &SVector<f64, N>,
    h: f64,
) -> Result<SVector<f64, N>, String> {
    match method {
        // Without the model's pairs or lags the exponential and lag variants are plain RK4 (see
        // the engine).
        Method::Rk4 | Method::Rk4Exp | Method::Rk4Lag => Ok(rk4_step_t(f, t, x, h).0),
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

    /// A lag alone with an input ramp over the step: [`rk4_lag_step`] is the closed form, at any
    /// rate (k h from 1e-3 to 1e3), and a lag of rate 0 is left to the body.
    #[test]
    fn lag_step_is_exact_for_a_ramped_input() {
        let (y0, u0, u1, h) = (0.3, -1.0, 2.0, 0.01);
        for k in [0.1, 10.0, 1e3, 1e5] {
            let body = |_: &SVector<f64, 1>, c: f64| (SVector::<f64, 1>::zeros(), [u0 + c * (u1 - u0)]);
            let y = rk4_lag_step(body, &SVector::<f64, 1>::new(y0), h, &[0], &[k])[0];
            let z = k * h;
            let exact = u1 + (y0 - u0) * (-z).exp() - (u1 - u0) * (1.0 - (-z).exp()) / z;
            // (1e-12: the closed form as written here cancels in 1 - e^-z at small z)
            assert!((y - exact).abs() <= 1e-12 * exact.abs().max(1.0), "k {k}: {y} vs {exact}");
        }
        let body = |_: &SVector<f64, 1>, _: f64| (SVector::<f64, 1>::new(2.0), [5.0]);
        assert_eq!(rk4_lag_step(body, &SVector::<f64, 1>::new(1.0), 0.5, &[0], &[0.0])[0], 2.0);
    }

    /// A body state driven by a lag that follows it (x' = -x + 2 y, y' = k (x - y), k = 40 1/s):
    /// against a fine classical RK4 (h = 1e-5) over 1 s the error falls at least at second order
    /// as the step halves from 20 ms to 5 ms (observed 1.90, 1.95), and at k = 1e4 1/s, where
    /// classical RK4 at 10 ms diverges, the lag step stays bounded and close to the reduced
    /// model (y = x: x' = x, so x(1) = e).
    #[test]
    fn lag_step_converges_and_stays_stable_for_a_stiff_lag() {
        let run = |k: f64, h: f64| {
            let n = (1.0 / h).round() as usize;
            let mut x = Vector2::new(1.0, 1.0);
            for _ in 0..n {
                let body = |s: &Vector2<f64>, _: f64| (Vector2::new(-s[0] + 2.0 * s[1], 0.0), [s[0]]);
                x = rk4_lag_step(body, &x, h, &[1], &[k]);
            }
            x
        };
        let reference = |k: f64| {
            let mut x = Vector2::new(1.0, 1.0);
            for _ in 0..100_000 {
                x = rk4_step(|s: &Vector2<f64>| Vector2::new(-s[0] + 2.0 * s[1], k * (s[0] - s[1])), &x, 1e-5).0;
            }
            x
        };
        let r = reference(40.0);
        let e: Vec<f64> = [0.02, 0.01, 0.005].iter().map(|&h| (run(40.0, h) - r).norm()).collect();
        let orders = [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()];
        eprintln!("lag step errors {e:?}, orders {orders:?}");
        assert!(orders.iter().all(|&p| p > 1.8), "{e:?}: orders {orders:?}");
        let stiff = run(1e4, 0.01);
        assert!((stiff[0] - std::f64::consts::E).abs() < 1e-2 * std::f64::consts::E, "{stiff:?}");
    }

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

    /// exp of a 2 x 2 matrix against its Taylor series (scaled by 2^-12, 30 terms, squared back),
    /// for a complex pair (the wheel-spin mode), real distinct eigenvalues, a double eigenvalue
    /// (Jordan block, the series branch) and zero.
    #[test]
    fn expm2_matches_the_series() {
        let mul = |a: [[f64; 2]; 2], b: [[f64; 2]; 2]| {
            [
                [a[0][0] * b[0][0] + a[0][1] * b[1][0], a[0][0] * b[0][1] + a[0][1] * b[1][1]],
                [a[1][0] * b[0][0] + a[1][1] * b[1][0], a[1][0] * b[0][1] + a[1][1] * b[1][1]],
            ]
        };
        let series = |a: [[f64; 2]; 2]| {
            let k = 2f64.powi(-12);
            let a = [[a[0][0] * k, a[0][1] * k], [a[1][0] * k, a[1][1] * k]];
            let (mut sum, mut term) = ([[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 1.0]]);
            for n in 1..30 {
                term = mul(term, a);
                term = [[term[0][0] / n as f64, term[0][1] / n as f64], [term[1][0] / n as f64, term[1][1] / n as f64]];
                for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    sum[i][j] += term[i][j];
                }
            }
            (0..12).fold(sum, |m, _| mul(m, m))
        };
        let cases = [
            [[0.0, -20000.0 * 0.0025], [2.2 * 0.0025, -60.0 * 0.0025]],
            [[-1.5, 0.3], [0.2, -0.4]],
            [[0.7, 1.0], [0.0, 0.7]],
            [[0.0, 0.0], [0.0, 0.0]],
            [[0.0, -1.3e4 * 0.01], [2.0 * 0.01, -90.0 * 0.01]],
        ];
        for a in cases {
            let (e, r) = (expm2(a), series(a));
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                assert!((e[i][j] - r[i][j]).abs() <= 1e-11 * (1.0 + r[i][j].abs()), "{a:?}: {e:?} vs {r:?}");
            }
        }
    }

    /// A stiff oscillating pair (a, b) like the wheel spin and transient slip (|lambda| about
    /// 210 1/s, damping ratio 0.14, a saturating "tyre" tanh(b)) driven by and driving a slow forced
    /// state y. The exponential RK4 with the pair's Jacobian taken at each step's start runs where
    /// RK4 cannot (h |lambda| = 4.2), converges at fourth order, and without pairs is RK4 itself.
    #[test]
    fn exponential_rk4_on_a_stiff_pair() {
        use nalgebra::Vector3;
        let (k, c, d) = (20000.0, 2.2, 60.0);
        let f = |t: f64, x: &Vector3<f64>| {
            let (a, b, y) = (x[0], x[1], x[2]);
            Vector3::new(
                -k * b.tanh() + 50.0 * y,
                c * a - d * b - 10.0 * y,
                -y + 0.002 * a * a / (1.0 + a * a) + (3.0 * t).sin(),
            )
        };
        let exp_step = |t: f64, x: &Vector3<f64>, h: f64| {
            let l = [[0.0, -k / x[1].cosh().powi(2)], [c, -d]];
            rk4_exp_step_t(f, t, x, h, f(t, x), &[ExpPair::new(0, 1, l, h)])
        };
        let x0 = Vector3::new(0.3, 0.0, 0.1);
        let solve = |h: f64, exp: bool| {
            let n = (1.0 / h).round() as usize;
            (0..n).fold(x0, |x, i| {
                let t = i as f64 * h;
                if exp {
                    exp_step(t, &x, h)
                } else {
                    rk4_step_t(f, t, &x, h).0
                }
            })
        };
        let reference = solve(2e-5, false);
        let err = |h: f64, exp: bool| (solve(h, exp) - reference).amax();
        assert!(!(err(0.02, false) < 1.0), "RK4 at h |lambda| = 4.2: {}", err(0.02, false));
        assert!(err(0.02, true) < 2e-3, "exponential RK4 at h |lambda| = 4.2: {}", err(0.02, true));
        let errs: Vec<f64> = [0.005, 0.0025, 0.00125].iter().map(|&h| err(h, true)).collect();
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!((3.6..=4.4).contains(&order), "observed order {order} ({errs:?})");
        }
        let x = Vector3::new(0.2, 0.01, -0.3);
        assert_eq!(rk4_exp_step_t(f, 0.1, &x, 0.003, f(0.1, &x), &[]), rk4_step_t(f, 0.1, &x, 0.003).0);
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
