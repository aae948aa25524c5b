//! Parameter fitting: a bounded Nelder–Mead simplex search on a handful of parameters.
//!
//! Parameters are searched in a scaled space (each coordinate divided by its typical scale) and
//! clamped to their bounds before every evaluation. Deterministic: no random restarts.

/// The search stops when the simplex spans less than this in the scaled space (0.2 % of each
/// parameter's typical scale: far finer than the data can resolve).
pub const SPREAD_TOL: f64 = 2e-3;

/// Minimise `f` from `x0` (each coordinate with its `scale` and bounds `lo..=hi`); at most
/// `max_evals` evaluations. Returns the best point and its value.
pub fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    scale: &[f64],
    lo: &[f64],
    hi: &[f64],
    max_evals: usize,
) -> (Vec<f64>, f64) {
    let n = x0.len();
    let to_x = |z: &[f64]| -> Vec<f64> { (0..n).map(|i| (z[i] * scale[i]).clamp(lo[i], hi[i])).collect() };
    let mut eval = |z: &[f64], count: &mut usize| {
        *count += 1;
        let v = f(&to_x(z));
        if v.is_finite() {
            v
        } else {
            f64::MAX
        }
    };
    let mut count = 0;
    let z0: Vec<f64> = (0..n).map(|i| x0[i] / scale[i]).collect();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    let v0 = eval(&z0, &mut count);
    simplex.push((z0.clone(), v0));
    for i in 0..n {
        let mut z = z0.clone();
        z[i] += 0.5;
        let v = eval(&z, &mut count);
        simplex.push((z, v));
    }
    while count < max_evals {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (simplex[0].1, simplex[n].1);
        let spread: f64 =
            (0..n).map(|i| simplex.iter().map(|s| (s.0[i] - simplex[0].0[i]).abs()).fold(0.0, f64::max)).sum();
        if spread < SPREAD_TOL || (worst - best).abs() <= 1e-9 * best.abs().max(1e-12) {
            break;
        }
        let centroid: Vec<f64> = (0..n).map(|i| simplex[..n].iter().map(|s| s.0[i]).sum::<f64>() / n as f64).collect();
        let along =
            |t: f64| -> Vec<f64> { (0..n).map(|i| centroid[i] + t * (simplex[n].0[i] - centroid[i])).collect() };
        let zr = along(-1.0);
        let vr = eval(&zr, &mut count);
        if vr < simplex[0].1 {
            let ze = along(-2.0);
            let ve = eval(&ze, &mut count);
            simplex[n] = if ve < vr { (ze, ve) } else { (zr, vr) };
        } else if vr < simplex[n - 1].1 {
            simplex[n] = (zr, vr);
        } else {
            let (zc, vc) = if vr < simplex[n].1 {
                let z = along(-0.5);
                let v = eval(&z, &mut count);
                (z, v)
            } else {
                let z = along(0.5);
                let v = eval(&z, &mut count);
                (z, v)
            };
            if vc < simplex[n].1.min(vr) {
                simplex[n] = (zc, vc);
            } else {
                for j in 1..=n {
                    let z: Vec<f64> =
                        (0..n).map(|i| simplex[0].0[i] + 0.5 * (simplex[j].0[i] - simplex[0].0[i])).collect();
                    let v = eval(&z, &mut count);
                    simplex[j] = (z, v);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    (to_x(&simplex[0].0), simplex[0].1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_shifted_quadratic() {
        let mut f = |x: &[f64]| (x[0] - 1.5).powi(2) + 10.0 * (x[1] + 0.25).powi(2);
        let (x, v) = nelder_mead(&mut f, &[0.0, 0.0], &[1.0, 1.0], &[-5.0, -5.0], &[5.0, 5.0], 400);
        assert!((x[0] - 1.5).abs() < 1e-3 && (x[1] + 0.25).abs() < 1e-3 && v < 1e-5, "{x:?} {v}");
    }

    #[test]
    fn respects_bounds() {
        let mut f = |x: &[f64]| (x[0] - 3.0).powi(2);
        let (x, _) = nelder_mead(&mut f, &[0.5], &[1.0], &[0.0], &[1.0], 200);
        assert!((x[0] - 1.0).abs() < 1e-3, "{x:?}");
    }
}
