//! Steady-state analysis of a run: averages of the recorded rows over a manoeuvre's steady-state
//! windows, and the understeer gradient as the least-squares slope of road-wheel steer angle on
//! lateral acceleration with its 95 % confidence interval (slope standard error times the Student
//! t quantile for n - 2 degrees of freedom).
//!
//! On a constant radius R the Ackermann steer L / R does not change between steps, so the slope of
//! delta on a_y is the understeer gradient (ISO 4138 method 1). The slope of delta - L r / v_x on
//! a_y is reported as well: by the single-track kinematics tan(delta - alpha_f) + tan(alpha_r) =
//! L r / v_x, so delta - L r / v_x ~ alpha_f - alpha_r, the tyre part that linear theory's
//! K_us = (m / L) (b / C_f - a / C_r) describes. It excludes the driver's small radius error and the
//! change of the kinematic angles with speed (sideslip), which on a small circle at low speed make
//! the two slopes differ by a few per cent.
//!
//! A window counts as steady when all of these hold (else it is left out of the gradient and the
//! run's plausibility says why): the run reached the window's end; max |v_x - target| <=
//! max(`SPEED_TOL_MPS`, `SPEED_TOL_FRACTION` x target); max a_y - min a_y <=
//! max(`AY_RANGE_TOL_MPS2`, `AY_RANGE_TOL_FRACTION` x |nominal a_y|); and max |path error| <=
//! the manoeuvre's path tolerance (constant radius: max(1 m, 5 % of R)). With fewer than three
//! steady windows no gradient is reported.

use crate::maneuver::SteadyWindow;
use crate::sim::Row;
use crate::vehicle::GRAVITY;

/// Speed error a steady window allows: the larger of this (m/s) and the fraction of the target.
pub(crate) const SPEED_TOL_MPS: f64 = 0.2;
pub(crate) const SPEED_TOL_FRACTION: f64 = 0.03;
/// Spread of a_y a steady window allows: the larger of this (m/s^2) and the fraction of |nominal a_y|.
pub(crate) const AY_RANGE_TOL_MPS2: f64 = 0.1;
pub(crate) const AY_RANGE_TOL_FRACTION: f64 = 0.1;

/// Means of one steady-state window (signed quantities: left turns positive).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SteadyState {
    /// Step number of the window, from 1.
    pub step: usize,
    /// Window start, s.
    pub t0_s: f64,
    /// Window end, s.
    pub t1_s: f64,
    /// Number of recorded rows averaged.
    pub samples: usize,
    /// Speed target of the step, m/s.
    pub speed_target_mps: f64,
    /// Nominal lateral acceleration v^2 / R of the step, m/s^2 (positive left).
    pub nominal_ay_mps2: f64,
    /// Mean body-frame forward speed v_x, m/s.
    pub vx_mps: f64,
    /// Mean body-frame lateral acceleration a_y, m/s^2 (positive left).
    pub ay_mps2: f64,
    /// Mean road-wheel steer angle (the input), rad.
    pub steer_rad: f64,
    /// Mean yaw rate, rad/s (positive turning left).
    pub yaw_rate_radps: f64,
    /// Mean vehicle sideslip angle atan2(v_y, v_x), rad.
    pub sideslip_rad: f64,
    /// Mean roll angle, rad (positive: body leans right; 0 for models without roll).
    pub roll_rad: f64,
    /// Normal loads FL, FR, RL, RR, N.
    pub fz_fl_n: f64,
    /// Mean normal load on the front-right wheel, N.
    pub fz_fr_n: f64,
    /// Mean normal load on the rear-left wheel, N.
    pub fz_rl_n: f64,
    /// Mean normal load on the rear-right wheel, N.
    pub fz_rr_n: f64,
    /// Path curvature r / v_x, 1/m.
    pub curvature_1pm: f64,
    /// Mean lateral deviation of the CG from the circle, m (NaN when open loop).
    pub path_error_m: f64,
    /// Largest |v_x - target| in the window, m/s.
    pub max_speed_error_mps: f64,
    /// Largest |lateral deviation| from the path in the window, m (NaN when open loop).
    pub max_path_error_m: f64,
    /// max a_y - min a_y in the window, m/s^2.
    pub ay_range_mps2: f64,
    /// True when the window meets the criteria in the module docs.
    pub steady: bool,
    /// Why the window is not steady (empty when it is).
    pub not_steady: String,
}

/// A straight-line least-squares fit y = intercept + slope x.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LinearFit {
    /// Slope of the fit, in units of y per unit of x.
    pub slope: f64,
    /// Value of the fit at x = 0.
    pub intercept: f64,
    /// Standard error of the slope.
    pub slope_std_error: f64,
    /// 95 % confidence interval of the slope.
    pub slope_ci95: [f64; 2],
    /// Coefficient of determination R^2 of the fit, in [0, 1].
    pub r_squared: f64,
    /// Number of points fitted.
    pub n: usize,
}

/// Two-sided 95 % quantile of Student's t distribution (t_0.975) for `df` degrees of freedom:
/// tabulated to three decimals for df <= 30, the Cornish–Fisher expansion about the normal
/// quantile above (error < 1e-4 there).
pub fn t975(df: usize) -> f64 {
    const TABLE: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
    ];
    match df {
        0 => f64::INFINITY,
        1..=30 => TABLE[df - 1],
        _ => {
            let z: f64 = 1.959_963_984_540_054;
            let v = df as f64;
            let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
            z + (z3 + z) / (4.0 * v)
                + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v)
                + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * v * v * v)
        }
    }
}

/// Least-squares line through (x, y); `None` with fewer than three points or no spread in x.
pub fn linear_fit(x: &[f64], y: &[f64]) -> Option<LinearFit> {
    let n = x.len().min(y.len());
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mx = x[..n].iter().sum::<f64>() / nf;
    let my = y[..n].iter().sum::<f64>() / nf;
    let sxx: f64 = x[..n].iter().map(|v| (v - mx).powi(2)).sum();
    let sxy: f64 = x[..n].iter().zip(&y[..n]).map(|(a, b)| (a - mx) * (b - my)).sum();
    let syy: f64 = y[..n].iter().map(|v| (v - my).powi(2)).sum();
    if sxx.is_nan() || sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let sse: f64 = x[..n].iter().zip(&y[..n]).map(|(a, b)| (b - intercept - slope * a).powi(2)).sum();
    let se = (sse / (nf - 2.0) / sxx).sqrt();
    let half = t975(n - 2) * se;
    let r_squared = if syy > 0.0 { 1.0 - sse / syy } else { 1.0 };
    Some(LinearFit { slope, intercept, slope_std_error: se, slope_ci95: [slope - half, slope + half], r_squared, n })
}

/// Average the rows inside each window (rows with t in [t0, t1]); windows without rows are skipped.
/// Each window is judged steady or not (module docs) with path tolerance `path_tol_m` (m; `None`:
/// no path criterion).
pub fn steady_states(windows: &[SteadyWindow], rows: &[Row], path_tol_m: Option<f64>) -> Vec<SteadyState> {
    let mut out = Vec::new();
    let t_last = rows.last().map_or(f64::NEG_INFINITY, |r| r.t_s);
    for w in windows {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.t_s >= w.t0_s - 1e-9 && r.t_s <= w.t1_s + 1e-9).collect();
        if sel.is_empty() {
            continue;
        }
        let n = sel.len() as f64;
        let mean = |f: &dyn Fn(&Row) -> f64| sel.iter().map(|r| f(r)).sum::<f64>() / n;
        out.push(SteadyState {
            step: w.step,
            t0_s: w.t0_s,
            t1_s: w.t1_s,
            samples: sel.len(),
            speed_target_mps: w.speed_target_mps,
            nominal_ay_mps2: w.nominal_ay_mps2,
            vx_mps: mean(&|r| r.obs.kin.vx_mps),
            ay_mps2: mean(&|r| r.obs.ay_mps2),
            steer_rad: mean(&|r| r.inputs.steer_rad),
            yaw_rate_radps: mean(&|r| r.obs.kin.yaw_rate_radps),
            sideslip_rad: mean(&|r| r.obs.kin.sideslip_rad()),
            roll_rad: mean(&|r| r.obs.roll_rad),
            fz_fl_n: mean(&|r| r.obs.fz_n[0]),
            fz_fr_n: mean(&|r| r.obs.fz_n[1]),
            fz_rl_n: mean(&|r| r.obs.fz_n[2]),
            fz_rr_n: mean(&|r| r.obs.fz_n[3]),
            curvature_1pm: mean(&|r| r.obs.kin.yaw_rate_radps / r.obs.kin.vx_mps.abs().max(0.5)),
            path_error_m: mean(&|r| r.path_error_m),
            max_speed_error_mps: sel.iter().map(|r| (r.obs.kin.vx_mps - w.speed_target_mps).abs()).fold(0.0, f64::max),
            max_path_error_m: sel.iter().map(|r| r.path_error_m.abs()).fold(f64::NAN, f64::max),
            ay_range_mps2: sel.iter().map(|r| r.obs.ay_mps2).fold(f64::NEG_INFINITY, f64::max)
                - sel.iter().map(|r| r.obs.ay_mps2).fold(f64::INFINITY, f64::min),
            steady: true,
            not_steady: String::new(),
        });
        if let Some(q) = out.last_mut() {
            judge(q, t_last, path_tol_m);
        }
    }
    out
}

/// Set `steady` and `not_steady` of a window from the criteria in the module docs; the run's last
/// recorded row is at `t_last`.
pub(crate) fn judge(q: &mut SteadyState, t_last: f64, path_tol_m: Option<f64>) {
    let mut why = Vec::new();
    if t_last < q.t1_s - 1e-9 {
        why.push(format!("the run ended at t = {t_last:.2} s, before the window's end at {:.2} s", q.t1_s));
    }
    let v_tol = SPEED_TOL_MPS.max(SPEED_TOL_FRACTION * q.speed_target_mps.abs());
    if q.max_speed_error_mps.is_nan() || q.max_speed_error_mps > v_tol {
        why.push(format!("speed off its target by up to {:.2} m/s (allowed {v_tol:.2})", q.max_speed_error_mps));
    }
    let ay_tol = AY_RANGE_TOL_MPS2.max(AY_RANGE_TOL_FRACTION * q.nominal_ay_mps2.abs());
    if q.ay_range_mps2.is_nan() || q.ay_range_mps2 > ay_tol {
        why.push(format!("a_y varies by {:.2} m/s^2 (allowed {ay_tol:.2})", q.ay_range_mps2));
    }
    if let Some(tol) = path_tol_m {
        if q.max_path_error_m > tol {
            why.push(format!("off the circle by up to {:.2} m (tolerance {tol:.2} m)", q.max_path_error_m));
        }
    }
    q.steady = why.is_empty();
    q.not_steady = why.join("; ");
}

/// The understeer gradient of a constant-radius run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct UndersteerGradient {
    /// d(delta)/d(a_y), rad per m/s^2 (positive: understeer).
    pub rad_per_mps2: f64,
    /// The same in degrees of road-wheel angle per g.
    pub deg_per_g: f64,
    /// Standard error of the gradient, rad per m/s^2.
    pub std_error_rad_per_mps2: f64,
    /// 95 % confidence interval, rad per m/s^2.
    pub ci95_rad_per_mps2: [f64; 2],
    /// Fitted steer at zero lateral acceleration, rad (about L / R).
    pub intercept_rad: f64,
    /// Coefficient of determination R^2 of the fit.
    pub r_squared: f64,
    /// Number of steady states fitted.
    pub steps: usize,
    /// Slope of delta - L r / v_x on a_y (~ slope of alpha_f - alpha_r), rad per m/s^2.
    pub slip_angle_gradient_rad_per_mps2: f64,
    /// 95 % confidence interval of that slope, rad per m/s^2.
    pub slip_angle_gradient_ci95_rad_per_mps2: [f64; 2],
    /// How the gradient was computed, in words (for the summary).
    pub method: &'static str,
}

/// Understeer gradient from the steady windows among `states`; with fewer than three, or no
/// spread of a_y among them, the error says why.
pub fn understeer_gradient(states: &[SteadyState], wheelbase_m: f64) -> Result<UndersteerGradient, String> {
    let all = states.len();
    let states: Vec<&SteadyState> = states.iter().filter(|s| s.steady).collect();
    if states.len() < 3 {
        return Err(format!(
            "no understeer gradient: {} of {all} steady-state windows are steady, at least 3 are needed",
            states.len()
        ));
    }
    let none = || "no understeer gradient: the steady windows have no spread of a_y".to_string();
    let ay: Vec<f64> = states.iter().map(|s| s.ay_mps2).collect();
    let steer: Vec<f64> = states.iter().map(|s| s.steer_rad).collect();
    let corrected: Vec<f64> = states.iter().map(|s| s.steer_rad - wheelbase_m * s.curvature_1pm).collect();
    let f = linear_fit(&ay, &steer).ok_or_else(none)?;
    let c = linear_fit(&ay, &corrected).ok_or_else(none)?;
    Ok(UndersteerGradient {
        rad_per_mps2: f.slope,
        deg_per_g: f.slope.to_degrees() * GRAVITY,
        std_error_rad_per_mps2: f.slope_std_error,
        ci95_rad_per_mps2: f.slope_ci95,
        intercept_rad: f.intercept,
        r_squared: f.r_squared,
        steps: f.n,
        slip_angle_gradient_rad_per_mps2: c.slope,
        slip_angle_gradient_ci95_rad_per_mps2: c.slope_ci95,
        method: "least squares of the mean road-wheel steer angle on the mean lateral acceleration over the \
                 steady-state windows; 95 % interval = slope +- t(0.975, n-2) x standard error",
    })
}

/// `steady_states.csv` text.
pub fn steady_states_csv(states: &[SteadyState]) -> String {
    let mut s = String::from(
        "step,t0_s,t1_s,samples,speed_target_mps,nominal_ay_mps2,vx_mps,ay_mps2,steer_rad,yaw_rate_radps,\
         sideslip_rad,roll_rad,fz_fl_n,fz_fr_n,fz_rl_n,fz_rr_n,curvature_1pm,path_error_m,max_speed_error_mps,\
         max_path_error_m,ay_range_mps2,steady\n",
    );
    for q in states {
        let vals = [
            q.t0_s,
            q.t1_s,
            q.samples as f64,
            q.speed_target_mps,
            q.nominal_ay_mps2,
            q.vx_mps,
            q.ay_mps2,
            q.steer_rad,
            q.yaw_rate_radps,
            q.sideslip_rad,
            q.roll_rad,
            q.fz_fl_n,
            q.fz_fr_n,
            q.fz_rl_n,
            q.fz_rr_n,
            q.curvature_1pm,
            q.path_error_m,
            q.max_speed_error_mps,
            q.max_path_error_m,
            q.ay_range_mps2,
        ];
        s.push_str(&q.step.to_string());
        for v in vals {
            s.push(',');
            if v.is_finite() {
                s.push_str(&v.to_string());
            }
        }
        s.push(',');
        s.push_str(if q.steady { "true" } else { "false" });
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_recovers_an_exact_line_and_widens_with_noise() {
        let x = [0.5, 1.0, 1.5, 2.0, 2.5];
        let y: Vec<f64> = x.iter().map(|v| 0.07 + 0.004 * v).collect();
        let f = linear_fit(&x, &y).unwrap();
        assert!((f.slope - 0.004).abs() < 1e-15 && (f.intercept - 0.07).abs() < 1e-15);
        assert!(f.slope_std_error < 1e-12);
        // With scatter the interval is the slope +- t(0.975, 3) x its standard error.
        let yn: Vec<f64> = y.iter().zip([1.0, -1.0, 0.0, 1.0, -1.0]).map(|(v, e)| v + 1e-4 * e).collect();
        let g = linear_fit(&x, &yn).unwrap();
        let half = 0.5 * (g.slope_ci95[1] - g.slope_ci95[0]);
        assert!((half - 3.182 * g.slope_std_error).abs() < 1e-15);
        assert!(g.slope_ci95[0] < g.slope && g.slope < g.slope_ci95[1]);
        assert!(linear_fit(&x[..2], &y[..2]).is_none());
    }

    /// Rows at 100 Hz over 4 s-steps of a 40 m circle (a_y = 0.5 k, steer = 0.07 + 0.004 a_y);
    /// `off` lists the steps whose window drifts 3 m off the circle (tolerance 2 m).
    fn circle_rows(off: &[usize]) -> (Vec<SteadyWindow>, Vec<Row>) {
        use crate::vehicle::{Inputs, Kinematics, Observation};
        let windows: Vec<SteadyWindow> = (1..=5)
            .map(|k| SteadyWindow {
                step: k,
                t0_s: 4.0 * k as f64 - 1.0,
                t1_s: 4.0 * k as f64,
                speed_target_mps: (0.5 * k as f64 * 40.0).sqrt(),
                nominal_ay_mps2: 0.5 * k as f64,
            })
            .collect();
        let rows = (0..=2000)
            .map(|i| {
                let t = i as f64 * 0.01;
                let w = &windows[((t / 4.0 - 1e-9).ceil().max(1.0) as usize - 1).min(4)];
                let ay = w.nominal_ay_mps2;
                let drift = if off.contains(&w.step) && t >= w.t0_s - 1e-9 { 3.0 } else { 0.1 };
                Row {
                    t_s: t,
                    obs: Observation {
                        kin: Kinematics { vx_mps: w.speed_target_mps, ..Kinematics::default() },
                        ay_mps2: ay,
                        ..Observation::default()
                    },
                    inputs: Inputs { steer_rad: 0.07 + 0.004 * ay, ..Inputs::default() },
                    speed_target_mps: w.speed_target_mps,
                    path_error_m: drift,
                }
            })
            .collect();
        (windows, rows)
    }

    /// The constant-radius guard: an off-circle window is marked and left out of the gradient,
    /// which the other windows still give exactly; with fewer than three steady windows there is
    /// no gradient and the error says why; a run ended early leaves its last window unsteady.
    #[test]
    fn off_circle_windows_are_dropped_from_the_gradient() {
        let (w, rows) = circle_rows(&[]);
        let ss = steady_states(&w, &rows, Some(2.0));
        assert!(ss.iter().all(|s| s.steady), "{ss:?}");
        assert_eq!(understeer_gradient(&ss, 2.8).unwrap().steps, 5);

        let (w, rows) = circle_rows(&[2, 5]);
        let ss = steady_states(&w, &rows, Some(2.0));
        let flags: Vec<bool> = ss.iter().map(|s| s.steady).collect();
        assert_eq!(flags, [true, false, true, true, false]);
        assert!(ss[1].not_steady.contains("off the circle by up to 3.00 m"), "{}", ss[1].not_steady);
        let g = understeer_gradient(&ss, 2.8).unwrap();
        assert_eq!(g.steps, 3);
        assert!((g.rad_per_mps2 - 0.004).abs() < 1e-12 && (g.intercept_rad - 0.07).abs() < 1e-12);
        // Without a path tolerance the drift is not judged.
        assert!(steady_states(&w, &rows, None).iter().all(|s| s.steady));

        let (w, rows) = circle_rows(&[1, 3, 4]);
        let ss = steady_states(&w, &rows, Some(2.0));
        let e = understeer_gradient(&ss, 2.8).unwrap_err();
        assert!(e.contains("2 of 5"), "{e}");

        let (w, rows) = circle_rows(&[]);
        let ss = steady_states(&w, &rows[..1950], Some(2.0));
        assert_eq!(ss.len(), 5);
        assert!(!ss[4].steady && ss[4].not_steady.contains("the run ended"), "{:?}", ss[4]);
    }

    #[test]
    fn t_quantile_is_continuous_across_the_table_end() {
        assert!((t975(30) - 2.042).abs() < 1e-9);
        assert!((t975(31) - 2.0395).abs() < 2e-4, "{}", t975(31));
        assert!((t975(120) - 1.9799).abs() < 2e-4, "{}", t975(120));
        assert!(t975(1000) > 1.96 && t975(1000) < 1.963);
    }
}
