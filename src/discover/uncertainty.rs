//! Confidence intervals of fitted effect parameters, from the Jacobian of the residuals at the
//! optimum.
//!
//! r(theta) is the vector of the fitted samples' residuals (yaw rate and ay, and the fitted
//! increment windows of a run that logs a heading, position or lateral velocity,
//! [`super::increments`]), each divided by its noise estimate. J = dr/dtheta by central
//! differences (step 1 % of each parameter's typical scale; one-sided when the step would cross a
//! bound). The Gauss–Newton covariance is
//!
//!   C = s^2 (J^T J)^-1 * f,   s^2 = RSS / (N - p),   f = max((1 + rho) / (1 - rho), tau),
//!
//! with N residuals and p parameters. s^2 absorbs a misestimated noise or a remaining model
//! error (both widen the interval); rho is the lag-1 autocorrelation of the residuals (pooled over
//! runs and channels, clamped to [0, 0.99]), and the AR(1) factor (1 + rho) / (1 - rho) accounts
//! for correlated residuals carrying fewer independent samples than they count. Input noise
//! filtered by the vehicle's dynamics leaves residuals correlated over tenths of a second, which
//! an AR(1) model under-counts, so the factor is the larger of it and the integrated
//! autocorrelation time tau = 1 + 2 sum_L rho_L (lags L of one sample to [`MAX_LAG`], summed up to
//! the first lag whose rho_L is not positive): N / tau is the effective sample count. The 95 % interval
//! of parameter i is theta_i +- 1.96 sqrt(C_ii), with C_ii the larger of the above and of the
//! block sandwich estimate (J^T J)^-1 (sum_b g_b g_b^T) (J^T J)^-1, g_b = J_b^T r_b summed over
//! blocks of 1 s of residuals: correlation within a block that the lag-1 coefficient misses
//! (a slow error in the inputs or the model) then widens the interval. A singular J^T J (a parameter the data do not
//! determine) gives an infinite interval. Before the interval is built, the fitted value is
//! polished by a few Gauss–Newton steps with the same J (see [`refine`]).
//!
//! Errors in the inputs (noise on the measured steer and vx, which the replay takes as exact)
//! bias the fit through the tyre's nonlinearity; the residual-based interval does not see that.
//! One SIMEX step estimates it: white noise at each run's own input noise level (estimated from
//! second differences like the outputs') is added to the inputs again, the shift of the optimum
//! is estimated by one Gauss–Newton step with the same J, and theta - shift (the estimate
//! extrapolated to noise-free inputs) is taken into the interval: [min(theta, theta - shift) -
//! 1.96 se, max(theta, theta - shift) + 1.96 se].

use nalgebra::DMatrix;
use serde::Serialize;

use super::effects::{Effect, ParamDef};
use super::increments;
use super::model::{EffectParams, ReplayModel};
use super::select::{apply_all, noise_sigma, simulate_fitted, Dataset};
use super::synth::Rng;

/// Two-sided 95 % normal quantile.
pub const Z95: f64 = 1.959_964;

/// Relative finite-difference step (fraction of a parameter's typical scale).
const STEP: f64 = 0.01;

/// Residuals per block of the sandwich estimate (1 s of both channels at 100 Hz).
const BLOCK: usize = 200;

/// Longest lag of the integrated autocorrelation time, samples (0.5 s at 100 Hz).
pub const MAX_LAG: usize = 50;

/// Largest number of Gauss–Newton polishing steps.
pub const GN_STEPS: usize = 3;

/// The uncertainty of one fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    /// Standard error (same unit as the parameter).
    pub std_error: f64,
    /// 95 % confidence interval.
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    /// An interval that says nothing (the parameter is not determined by the data).
    pub const UNKNOWN: Interval = Interval { std_error: f64::INFINITY, lo: f64::NEG_INFINITY, hi: f64::INFINITY };

    pub fn contains(&self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }
}

/// Normalized residuals of the fitted samples (per run: yaw rate then ay, sample by sample, then
/// the run's fitted increment windows, [`super::increments`]), the residuals' sum of squares and
/// their autocorrelation variance factor (the larger of the AR(1) factor and the integrated
/// autocorrelation time, pooled over runs and channels; see the module header).
fn residuals(model: &ReplayModel, data: &Dataset, p: &EffectParams) -> (Vec<f64>, f64, f64) {
    let sims = simulate_fitted(model, data, p);
    let mut r = Vec::new();
    let mut sq = 0.0;
    let mut inc_sq = 0.0;
    // Sums of lagged products (lag 1..=MAX_LAG) over pairs of fitted samples of one run.
    let mut lagged = [0.0; MAX_LAG + 1];
    for (i, (run, sim)) in data.runs.iter().zip(&sims).enumerate() {
        let Some(sim) = sim else { continue };
        let nz = data.noise[i];
        let fitted = |k: usize| !data.held[i][k];
        let e = |k: usize| [(run.yaw_rate[k] - sim.yaw_rate[k]) / nz.yaw_rate, (run.ay[k] - sim.ay[k]) / nz.ay];
        let n = run.t.len();
        for k in (0..n).filter(|&k| fitted(k)) {
            let [ey, ea] = e(k);
            r.push(ey);
            r.push(ea);
            sq += ey * ey + ea * ea;
            for (l, s) in lagged.iter_mut().enumerate().skip(1) {
                if k + l < n && fitted(k + l) {
                    let [fy, fa] = e(k + l);
                    *s += ey * fy + ea * fa;
                }
            }
        }
        // The fitted increment windows after the run's samples (not in the autocorrelation sums:
        // windows do not overlap).
        for w in increments::residuals(run, &nz, sim, &data.held[i]).iter().filter(|w| !w.held) {
            r.push(w.z);
            inc_sq += w.z * w.z;
        }
    }
    if !(sq > 0.0) {
        return (r, sq + inc_sq, 1.0);
    }
    let rho1 = (lagged[1] / sq).clamp(0.0, 0.99);
    let mut tau = 1.0;
    for s in &lagged[1..] {
        let rho = s / sq;
        if !(rho > 0.0) {
            break;
        }
        tau += 2.0 * rho;
    }
    (r, sq + inc_sq, tau.max((1.0 + rho1) / (1.0 - rho1)))
}

/// The data with white noise added again to the inputs (steer and vx) at each run's own noise
/// level (estimated like the outputs'), from a fixed seed.
fn with_more_input_noise(data: &Dataset) -> Dataset {
    let mut out = data.clone();
    let mut rng = Rng::new(0x51_4E_E5);
    for r in &mut out.runs {
        let (ss, sv) = (noise_sigma(&r.steer), noise_sigma(&r.vx));
        r.steer.iter_mut().for_each(|v| *v += ss * rng.normal());
        r.vx.iter_mut().for_each(|v| *v += sv * rng.normal());
    }
    out
}

/// Jacobian of the residuals at `x` by central differences (one-sided at a bound); None when a
/// parameter cannot be stepped (its bounds coincide).
fn jacobian(at: &dyn Fn(&[f64]) -> Vec<f64>, defs: &[&ParamDef], x: &[f64], n: usize) -> Option<DMatrix<f64>> {
    let mut jac = DMatrix::<f64>::zeros(n, x.len());
    for (i, d) in defs.iter().enumerate() {
        let h = STEP * d.scale;
        let (up, down) = ((x[i] + h).min(d.hi), (x[i] - h).max(d.lo));
        if up <= down {
            return None;
        }
        let mut xu = x.to_vec();
        xu[i] = up;
        let mut xd = x.to_vec();
        xd[i] = down;
        let (ru, rd) = (at(&xu), at(&xd));
        for j in 0..n {
            jac[(j, i)] = (ru[j] - rd[j]) / (up - down);
        }
    }
    Some(jac)
}

/// Polish the fitted values of `effects` (on top of `base`) by Gauss–Newton steps on the fitted
/// samples (at most [`GN_STEPS`], each kept only when it lowers the residual sum of squares,
/// clamped to the bounds), then give every parameter's 95 % interval, all estimated together so
/// that correlated parameters widen each other's interval. The simplex search stops at a spread
/// of 0.2 % of each parameter's scale, which on long clean records can be coarser than the
/// statistical uncertainty; the polish puts the value at the optimum the interval is built around.
/// Returns the polished values per effect and their intervals.
pub fn refine(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    effects: &[(Effect, Vec<f64>)],
) -> (Vec<Vec<f64>>, Vec<Vec<Interval>>) {
    let defs: Vec<&ParamDef> = effects.iter().flat_map(|(e, _)| e.params().iter()).collect();
    let mut x: Vec<f64> = effects.iter().flat_map(|(_, v)| v.iter().copied()).collect();
    let np = x.len();
    let split = |x: &[f64]| -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        let mut i = 0;
        for (e, _) in effects {
            out.push(x[i..i + e.params().len()].to_vec());
            i += e.params().len();
        }
        out
    };
    let unknown = |x: &[f64]| {
        (split(x), effects.iter().map(|(e, _)| vec![Interval::UNKNOWN; e.params().len()]).collect::<Vec<_>>())
    };
    let full = |x: &[f64]| residuals(model, data, &apply_all(base, effects, x));
    let only_r = |x: &[f64]| full(x).0;
    let (mut r, mut sq, mut corr) = full(&x);
    let n = r.len();
    if n <= np || np == 0 {
        return unknown(&x);
    }
    let Some(mut jac) = jacobian(&only_r, &defs, &x, n) else { return unknown(&x) };
    for _ in 0..GN_STEPS {
        let jtj = jac.transpose() * &jac;
        let g = jac.transpose() * nalgebra::DVector::from_vec(r.clone());
        let Some(step) = jtj.lu().solve(&(-g)) else { break };
        let xn: Vec<f64> = (0..np).map(|i| (x[i] + step[i]).clamp(defs[i].lo, defs[i].hi)).collect();
        let (rn, sqn, corrn) = full(&xn);
        if !(sqn < sq) {
            break;
        }
        (x, r, sq, corr) = (xn, rn, sqn, corrn);
        match jacobian(&only_r, &defs, &x, n) {
            Some(j) => jac = j,
            None => return unknown(&x),
        }
    }
    let s2 = sq / (n - np) as f64;
    let factor = s2 * corr;
    let Some(inv) = (jac.transpose() * &jac).try_inverse() else { return unknown(&x) };
    // Block sandwich: the scores J^T r summed over blocks of BLOCK residuals (1 s of two channels
    // at 100 Hz), so that residuals correlated within a block (a slow model or input error the
    // lag-1 correlation misses) count once per block.
    let mut meat = DMatrix::<f64>::zeros(np, np);
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let g = jac.rows(start, end - start).transpose() * nalgebra::DVector::from_column_slice(&r[start..end]);
        meat += &g * g.transpose();
    }
    let sandwich = &inv * meat * &inv;
    // Errors in the inputs: one SIMEX step. Doubling the input noise variance moves the optimum
    // by about the bias the input noise already causes; one Gauss-Newton step with the same J
    // estimates that move, and the interval is widened to cover the corrected value.
    let noisier = with_more_input_noise(data);
    let rj = residuals(model, &noisier, &apply_all(base, effects, &x)).0;
    let shift = if rj.len() == n {
        let dr = nalgebra::DVector::from_iterator(n, rj.iter().zip(&r).map(|(a, b)| a - b));
        -(&inv * (jac.transpose() * dr))
    } else {
        nalgebra::DVector::zeros(np)
    };
    let ivs: Vec<Interval> = (0..np)
        .map(|i| {
            let var = (inv[(i, i)] * factor).max(sandwich[(i, i)]);
            let corrected = x[i] - shift[i];
            if var.is_finite() && var >= 0.0 && corrected.is_finite() {
                let se = var.sqrt();
                Interval { std_error: se, lo: x[i].min(corrected) - Z95 * se, hi: x[i].max(corrected) + Z95 * se }
            } else {
                Interval::UNKNOWN
            }
        })
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    for (e, _) in effects {
        out.push(ivs[i..i + e.params().len()].to_vec());
        i += e.params().len();
    }
    (split(&x), out)
}

/// True when the interval of at least one of `e`'s parameters excludes its no-effect value, or
/// when `e` is a structural form ([`Effect::structural`]: no parameter value switches it off).
pub fn significant(e: Effect, iv: &[Interval]) -> bool {
    e.structural() || e.params().iter().zip(iv).any(|(d, i)| d.null.is_some_and(|z| !i.contains(z)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_interval_contains_its_ends_and_nothing_outside() {
        let i = Interval { std_error: 0.5, lo: 1.0, hi: 2.0 };
        assert!(i.contains(1.0) && i.contains(2.0) && !i.contains(0.999) && !i.contains(2.001));
        assert!(Interval::UNKNOWN.contains(0.0));
    }

    #[test]
    fn significance_looks_only_at_parameters_with_a_no_effect_value() {
        // The stretch's position parameters have no no-effect value: only mu_scale counts.
        let e = Effect::FrictionStretch;
        let ok = Interval { std_error: 0.01, lo: 0.5, hi: 0.6 };
        let wide = Interval { std_error: 1.0, lo: 0.0, hi: 2.0 };
        assert!(significant(e, &[ok, wide, wide]));
        assert!(!significant(e, &[wide, ok, ok]));
    }
}
