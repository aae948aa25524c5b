//! Numerics of the engine: RK4 against a tight-tolerance adaptive reference, and the order of
//! convergence under step halving, on the closed-loop ISO 3888-2 run.

mod common;

use vehsim_core::sim::Method;
use vehsim_spec::run::execute;
use vehsim_spec::RunConfig;

fn with(cfg: &RunConfig, method: Method, step: f64, control: f64) -> RunConfig {
    let mut c = cfg.clone();
    c.settings.method = method;
    c.settings.step_s = step;
    c.settings.control_period_s = control;
    c.settings.output_interval_s = 0.02;
    c
}

/// RK4 at the default 1 ms step agrees with Dopri5 at rtol 1e-10 within 1e-4 rad/s in yaw rate
/// through the whole double lane change (same 1 ms controller sampling for both).
#[test]
fn rk4_default_step_agrees_with_tight_dopri5_over_the_dlc() {
    let base = common::load("maneuvers/dlc.toml");
    let rk4 = execute(&with(&base, Method::Rk4, 0.001, 0.001));
    let dp = execute(&with(&base, Method::Dopri5 { rtol: 1e-10, atol: 1e-12 }, 0.001, 0.001));
    assert_eq!(rk4.summary.end_reason, vehsim_core::event::EndReason::Completed);
    let d = common::max_yaw_rate_diff(&rk4, &dp);
    eprintln!("max |r_rk4 - r_dopri5| over the DLC = {d:.3e} rad/s");
    assert!(d < 1e-4, "max |r_rk4 - r_dopri5| = {d} rad/s");
    assert!(rk4.summary.peak_yaw_rate_radps > 0.2, "the DLC must actually yaw");
}

/// Halving the RK4 step (controller sampled every 4 ms in all runs, so only the integration error
/// changes) reduces the yaw-rate error against a Dop853 reference about 16-fold: fourth order.
#[test]
fn rk4_step_halving_shows_fourth_order_convergence() {
    let base = common::load("maneuvers/dlc.toml");
    let reference = execute(&with(&base, Method::Dop853 { rtol: 1e-13, atol: 1e-14 }, 0.004, 0.004));
    let errs: Vec<f64> = [0.004, 0.002, 0.001]
        .iter()
        .map(|&h| common::max_yaw_rate_diff(&execute(&with(&base, Method::Rk4, h, 0.004)), &reference))
        .collect();
    eprintln!("RK4 max yaw-rate error vs Dop853 at h = 4, 2, 1 ms: {errs:?}");
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.5..4.6).contains(&order), "errors {errs:?}: observed order {order}");
    }
}
