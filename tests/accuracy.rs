//! Accuracy guard of the default time-stepping settings.
//!
//! The defaults (controllers sampled every 10 ms with the predicted first-order hold, the RK4 step
//! from the vehicle's fastest mode; `crates/vehsim-core/src/sim/stability.rs`) must stay close to a run with
//! step = control period = 0.25 ms, which is within about 2e-6 rad/s of its own step-halved
//! run:
//!
//! - every vehicle model x tyre provider on an ISO 3888-2 lane change on ice (10 m/s held,
//!   mu 0.15; the ATIIM-Pacejka provider with the ATIIM contact estimate): largest |yaw-rate
//!   difference| <= 5e-4 rad/s (every combination at the one 10 ms period; measured at most
//!   3.7e-4, the 4-DOF model with Dugoff tyres; 1.6e-4 / 2.0e-4 bicycle / 4-DOF with ATIIM) and
//!   largest |lateral position difference| <= 2 cm over the common output rows (every 10 ms),
//!   same cone count, same verdict;
//! - the lane change with ATIIM converges at second order in the control period (the contact
//!   estimate consistent with the friction force, the continuous steering rate limit);
//! - the exponential RK4 on dry asphalt with the step equal to the control period (20 ms bicycle,
//!   10 ms 4-DOF), against a 0.25 ms step at the same period;
//! - a grid of 40 lane changes from the shipped 1000-run sweep's ranges (8 speeds x 5 frictions):
//!   no pass/fail flip and no change in the cone count against the reference
//!   (the whole 1000-run grid: `cargo test --release --test accuracy -- --ignored`);
//! - a small-amplitude (1 degree) open-loop sine steer on the linear tyre, controllers at a fixed
//!   4 ms: the yaw-rate error against a 0.125 ms run falls at fourth order as the step halves
//!   from 2 ms to 0.5 ms (the steer is evaluated at every RK4 stage, not held over the step).
//!   From 4 ms to 2 ms the observed order is 3.0: there h |lambda| = 0.62 for the wheel-spin mode,
//!   outside RK4's asymptotic range.
//!
//! The specs are written here, in code; only the sedan and its tyre file are shipped data.

mod common;

use vehsim_spec::run::{execute, RunOutput};
use vehsim_spec::{ManeuverFile, RunConfig};

/// A spec for the shipped sedan with the given tyre provider, vehicle model, friction and
/// `[maneuver]` body, validated with the default integrator settings.
fn config(tag: &str, tyre: &str, model: &str, mu: f64, maneuver: &str, extra: &str) -> RunConfig {
    let dir = common::temp_dir(&format!("accuracy-{tag}"));
    let contact = if tyre == "atiim_pacejka" { "[contact]\nmodel = \"atiim\"\n" } else { "" };
    let vehicle = common::root().join("vehicles/sedan.toml");
    let spec = format!(
        "name = \"{tag}\"\nvehicle = \"{}\"\ntyre_model = \"{tyre}\"\nvehicle_model = \"{model}\"\n{extra}\
         [surface]\nmu = {mu}\ntemperature_c = -3.0\n[maneuver]\n{maneuver}\n{contact}",
        vehicle.display()
    );
    let path = dir.join("spec.toml");
    std::fs::write(&path, spec).unwrap();
    ManeuverFile::load(&path).and_then(|f| f.build(&path)).unwrap_or_else(|e| panic!("{tag}: {e}"))
}

fn dlc(tag: &str, tyre: &str, model: &str, speed: f64, mu: f64) -> RunConfig {
    config(tag, tyre, model, mu, &format!("kind = \"iso3888_2\"\nspeed_mps = {speed}\nspeed_mode = \"hold\""), "")
}

/// The run with step and control period replaced, rows every 10 ms.
fn run(base: &RunConfig, h: Option<f64>, tc: Option<f64>) -> RunOutput {
    let mut c = base.clone();
    if let Some(h) = h {
        c.settings.step_s = h;
    }
    if let Some(tc) = tc {
        c.settings.control_period_s = tc;
    }
    c.settings.output_interval_s = 0.01;
    execute(&c)
}

/// The reference: step = control period = 0.25 ms.
fn reference(base: &RunConfig) -> RunOutput {
    run(base, Some(0.00025), Some(0.00025))
}

/// (largest |yaw-rate difference| rad/s, largest |y difference| m, rows compared) over the rows
/// at common times.
fn diff(a: &RunOutput, b: &RunOutput) -> (f64, f64, usize) {
    let (mut r, mut y, mut n, mut j) = (0.0_f64, 0.0_f64, 0, 0);
    for p in &a.rows {
        while j < b.rows.len() && b.rows[j].t_s < p.t_s - 1e-9 {
            j += 1;
        }
        if j < b.rows.len() && (b.rows[j].t_s - p.t_s).abs() < 1e-9 {
            let q = &b.rows[j];
            r = r.max((p.obs.kin.yaw_rate_radps - q.obs.kin.yaw_rate_radps).abs());
            y = y.max((p.obs.kin.y_m - q.obs.kin.y_m).abs());
            n += 1;
        }
    }
    (r, y, n)
}

#[test]
fn defaults_match_the_fine_reference_for_every_model_and_provider() {
    for model in ["bicycle", "roll4dof"] {
        for tyre in vehsim_core::tyre::TyreModelKind::ALL.iter().map(|k| k.as_str()) {
            let base = dlc(&format!("{model}-{tyre}"), tyre, model, 10.0, 0.15);
            let (h, tc) = (base.settings.step_s, base.settings.control_period_s);
            let d = run(&base, None, None);
            let r = reference(&base);
            let (er, ey, n) = diff(&d, &r);
            println!("{model} + {tyre}: step {h} s, period {tc} s: yaw rate {er:.2e} rad/s, y {ey:.2e} m");
            assert!(n > 1000, "{model} + {tyre}: {n} rows compared");
            assert_eq!(tc, 0.01, "{model} + {tyre}: default period");
            assert!(er <= 5e-4 && ey <= 0.02, "{model} + {tyre}: yaw rate {er:.2e} rad/s, y {ey:.2e} m");
            assert_eq!(d.summary.cones_hit, r.summary.cones_hit, "{model} + {tyre}");
            assert_eq!(d.summary.passed, r.summary.passed, "{model} + {tyre}");
            assert_eq!(d.summary.end_reason, r.summary.end_reason, "{model} + {tyre}");
        }
    }
}

/// The sampled loop converges to the continuous-time one: at a fixed 0.25 ms step, the yaw-rate
/// error of the lane change (bicycle, linear tyre: smooth, so the order is clean; measured 2.09
/// and 1.93) against the step = period = 0.25 ms reference falls at second order as the control
/// period halves from 10 ms to 2.5 ms (predicted first-order hold, `vehsim_core::sim::engine`). With
/// saturating tyres the observed order varies (Pacejka: 2.5e-4, 4.8e-5, 1.9e-5 rad/s) but the
/// error stays below 1e-4 rad/s.
#[test]
fn sampled_control_converges_at_second_order_in_the_period() {
    for tyre in ["linear", "pacejka"] {
        let smooth = tyre == "linear";
        let base = dlc(&format!("period-{tyre}"), tyre, "bicycle", 10.0, 0.15);
        let r = reference(&base);
        let errs: Vec<f64> =
            [0.01, 0.005, 0.0025].iter().map(|&tc| diff(&run(&base, Some(0.00025), Some(tc)), &r).0).collect();
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            println!("{tyre}: errors {:.3e} -> {:.3e}: order {order:.2}", w[0], w[1]);
            assert!(!smooth || order >= 1.7, "{tyre}: observed order {order:.2} ({errs:?})");
            assert!(w[1] < 1e-4, "{tyre}: {errs:?}");
        }
    }
}

/// The lane change on ice with the ATIIM estimate, where the front wheels spin at the melting
/// point and recover, converges at second order in the control period (step = period, from 10 ms
/// to 1.25 ms): the least-squares slope of log error against log period is at least 1.7, the
/// error falls at every halving, and on the 4-DOF model no halving gains less than order 1.2 (a
/// first-order scheme gains 1). Measured with the ice friction law (the tyre's friction follows
/// the contact temperature everywhere, so the bulk tread state is advanced with the mean of the
/// forcing at both ends of the period: holding the end's made the 4-DOF run first order, 0.9):
/// 4-DOF 8.1e-5, 2.7e-5, 6.2e-6, 1.4e-6 rad/s (slope 1.96), bicycle 1.16e-4, 1.05e-4, 4.1e-5,
/// 1.5e-6 (slope 2.0; every largest error at the onset of a front wheel-spin episode at 6.65 s,
/// so the ratio of one halving varies, 1.11 then 2.53 then 28, and the slope is the measure).
/// Before the law: 4-DOF 1.75e-4, 4.0e-5, 1.1e-5, 2.8e-6, bicycle 9.8e-5, 1.7e-5, 6.3e-6, 1.8e-6. Before the estimate was
/// solved for the temperature consistent with the friction force it allows, it alternated
/// between a melting and a cooler contact from sample to sample, and the sampled steering rate
/// limit left the lock up to a period early: 7.4e-4, 1.3e-4, 1.5e-4 rad/s (4-DOF), no order.
#[test]
fn thermal_lane_change_converges_at_second_order_in_the_period() {
    for model in ["roll4dof", "bicycle"] {
        let base = dlc(&format!("period-atiim-{model}"), "atiim_pacejka", model, 10.0, 0.15);
        let r = reference(&base);
        let periods = [0.01, 0.005, 0.0025, 0.00125];
        let errs: Vec<f64> = periods.iter().map(|&tc| diff(&run(&base, Some(tc), Some(tc)), &r).0).collect();
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            println!("{model} + ATIIM: errors {:.3e} -> {:.3e}: order {order:.2}", w[0], w[1]);
            // the bicycle's largest error sits at the onset of a front wheel-spin episode
            // (6.65 s), whose timing moves little between 10 and 5 ms: there only a falling error
            // is asserted, and the slope over the four periods is the measure
            let floor = if model == "bicycle" { 0.1 } else { 1.2 };
            assert!(order >= floor, "{model}: observed order {order:.2} over one halving ({errs:?})");
        }
        let (lx, ly): (Vec<f64>, Vec<f64>) = periods.iter().zip(&errs).map(|(t, e)| (t.ln(), e.ln())).unzip();
        let (mx, my) = (lx.iter().sum::<f64>() / 4.0, ly.iter().sum::<f64>() / 4.0);
        let slope = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum::<f64>()
            / lx.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
        println!("{model} + ATIIM: least-squares order {slope:.2}");
        assert!(slope >= 1.7, "{model}: least-squares order {slope:.2} ({errs:?})");
    }
}

/// A run that brakes to a stop reaches the regularised brake torque's stiff range (up to
/// `TORQUE_RATE_MAX` = 400 1/s below the regularisation wheel speed), which the linearisation at
/// free rolling does not see: the spec layer then divides the 10 ms period into two 5 ms steps
/// (h x 400 = 2), and the car stops. (At 10 ms a steered stop creeps on at 0.14 m/s:
/// tests/bicycle_physics.rs, `standstill_start_and_brake_to_standstill`.) A run that keeps its
/// speed keeps the 10 ms step.
#[test]
fn a_stop_takes_the_brake_torque_rate_into_the_default_step() {
    let stop = "kind = \"straight\"\nspeed_schedule = [[0.0, 10.0], [2.0, 10.0], [6.0, 0.0]]";
    // (14 s: with locked wheels the ice friction law's fall at 5-10 m/s of sliding lowers the
    // deceleration, so the car stops after about 10 s, where it stopped by 10 s with mu fixed)
    let base = config("stop", "pacejka", "bicycle", 0.15, stop, "duration_s = 14.0\n");
    assert_eq!((base.settings.step_s, base.settings.control_period_s), (0.005, 0.01));
    let out = run(&base, None, None);
    let end = out.rows.last().unwrap();
    assert!(end.obs.kin.speed_mps() < 0.05, "v = {}", end.obs.kin.speed_mps());
    let cruise = dlc("no-stop", "pacejka", "bicycle", 10.0, 0.15);
    assert_eq!((cruise.settings.step_s, cruise.settings.control_period_s), (0.01, 0.01));
}

/// Speeds and frictions of `maneuvers/bench/dlc_sweep_1000.toml`.
fn sweep_grid() -> (Vec<f64>, Vec<f64>) {
    ((0..40).map(|i| 8.0 + 0.2 * i as f64).collect(), (0..25).map(|i| 0.10 + 0.02 * i as f64).collect())
}

fn no_flips(every: usize) {
    let (speeds, mus) = sweep_grid();
    let mut n = 0;
    for v in speeds.iter().step_by(every) {
        for mu in mus.iter().step_by(every) {
            let base = dlc(&format!("sweep-{v}-{mu}"), "pacejka", "bicycle", *v, *mu);
            let (d, r) = (run(&base, None, None), reference(&base));
            let what = format!("{v} m/s, mu {mu}: {:?} vs {:?}", d.summary.events, r.summary.events);
            assert_eq!(d.summary.passed, r.summary.passed, "{what}");
            assert_eq!(d.summary.cones_hit, r.summary.cones_hit, "{what}");
            assert_eq!(d.summary.end_reason, r.summary.end_reason, "{what}");
            n += 1;
        }
    }
    assert!(n >= 40, "{n} runs");
}

#[test]
fn sweep_subset_has_no_pass_fail_flips() {
    no_flips(5);
}

/// The whole 1000-run grid (about 3 minutes on a quiet 2-core machine).
#[test]
#[ignore = "slow (about 3 min): the long suite, scripts/test-long.sh"]
fn sweep_has_no_pass_fail_flips() {
    no_flips(1);
}

#[test]
fn open_loop_sine_converges_at_fourth_order() {
    let sine = "kind = \"sine_steer\"\nspeed_mps = 10.0\nsteer_amplitude_deg = 1.0\nperiod_s = 2.0";
    let base = config("sine4", "linear", "bicycle", 0.15, sine, "duration_s = 4.0\n");
    let tc = Some(0.004);
    let reference = run(&base, Some(0.000125), tc);
    let errs: Vec<f64> = [0.002, 0.001, 0.0005].iter().map(|&h| diff(&run(&base, Some(h), tc), &reference).0).collect();
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        println!("errors {:.3e} -> {:.3e}: order {order:.2}", w[0], w[1]);
        assert!((3.5..=4.5).contains(&order), "observed order {order:.2} ({errs:?})");
    }
}

/// The exponential RK4 (the wheel-spin / transient-slip pairs carried exactly,
/// `vehsim_core::sim::Method::Rk4Exp`) on dry asphalt (mu 1.0, 15 m/s) with the step equal to the
/// control period: 20 ms for the bicycle, 10 ms for the 4-DOF model (its load-transfer lag, a
/// mode the exponential step leaves explicit, costs 3.9e-3 rad/s at 20 ms with the Magic Formula).
/// A spec asking for that step gets the exponential RK4 (h |lambda| of the pair is beyond 2), the
/// run stays within 5e-4 rad/s and 2 cm of a 0.25 ms step at the same period (same cones, same
/// verdict), and plain RK4 given the 20 ms step directly is unstable (yaw-rate error > 0.1 rad/s).
#[test]
fn exponential_rk4_runs_long_steps_on_dry() {
    let dry = "kind = \"iso3888_2\"\nspeed_mps = 15.0\nspeed_mode = \"hold\"";
    for (model, h) in [("bicycle", 0.02), ("roll4dof", 0.01)] {
        for tyre in ["linear", "pacejka"] {
            let tag = format!("dry-{model}-{tyre}");
            let integrator = format!("[integrator]\nstep_s = {h}\ncontrol_period_s = {h}\n");
            let base = config(&tag, tyre, model, 1.0, dry, &integrator);
            assert_eq!(base.settings.method, vehsim_core::sim::Method::Rk4Exp, "{tag}");
            assert_eq!((base.settings.step_s, base.settings.control_period_s), (h, h), "{tag}");
            let d = run(&base, None, None);
            let mut fine = base.clone();
            fine.settings.method = vehsim_core::sim::Method::Rk4;
            let r = run(&fine, Some(0.00025), None);
            let (er, ey, n) = diff(&d, &r);
            let plain = run(&fine, None, None);
            let (pr, py, _) = diff(&plain, &r);
            println!(
                "{tag}, step {h} s: yaw rate {er:.2e} rad/s, y {ey:.2e} m over {n} rows; plain RK4 {:?}, {pr:.2e} rad/s, {py:.2e} m",
                plain.summary.end_reason
            );
            assert!(n > 300 && er <= 5e-4 && ey <= 0.02, "{tag}: yaw rate {er:.2e} rad/s, y {ey:.2e} m, {n} rows");
            assert_eq!(d.summary.cones_hit, r.summary.cones_hit, "{tag}");
            assert_eq!(d.summary.passed, r.summary.passed, "{tag}");
            if h >= 0.02 {
                assert!(!(pr <= 0.1), "{tag}: plain RK4 at {h} s: {pr:.2e} rad/s");
            }
        }
    }
}

/// The refusal of a step is honest for the exponential RK4: the unsaturated linear tyre on ice
/// (the stiffest pair, not scaled by friction) at 25 ms is refused with the bound in the message;
/// 0.95 of that bound (rounded down to 2.5 ms) runs the lane change to its end within 5e-3 rad/s of a 0.25 ms step at the
/// same period, and the refused 25 ms, given to the engine directly, leaves the course (spin-out
/// or a yaw-rate error beyond 0.1 rad/s).
#[test]
fn exponential_rk4_bound_is_honest() {
    let dlc = "kind = \"iso3888_2\"\nspeed_mps = 10.0\nspeed_mode = \"hold\"";
    let dir = common::temp_dir("accuracy-bound");
    let vehicle = common::root().join("vehicles/sedan.toml");
    let spec = format!(
        "name = \"bound\"\nvehicle = \"{}\"\ntyre_model = \"linear\"\n[integrator]\nstep_s = 0.025\n\
         control_period_s = 0.025\n[surface]\nmu = 0.15\ntemperature_c = -3.0\n[maneuver]\n{dlc}\n",
        vehicle.display()
    );
    let path = dir.join("spec.toml");
    std::fs::write(&path, spec).unwrap();
    let err = ManeuverFile::load(&path).and_then(|f| f.build(&path)).unwrap_err().to_string();
    assert!(err.contains("integrator.step_s") && err.contains("stability bound"), "{err}");
    let bound: f64 =
        err.split("expected step_s <= ").nth(1).and_then(|t| t.split(' ').next()).unwrap().parse().unwrap();
    assert!(bound > 0.005 && bound < 0.025, "{err}");
    let base = config("bound-ok", "linear", "bicycle", 0.15, dlc, "");
    let with = |h: f64, method| {
        let mut c = base.clone();
        (c.settings.method, c.settings.step_s, c.settings.control_period_s) = (method, h, h);
        c
    };
    // 0.95 of the bound, rounded down to whole 2.5 ms (rows at common times with the reference).
    let h = (0.95 * bound / 0.0025).floor() * 0.0025;
    let d = run(&with(h, vehsim_core::sim::Method::Rk4Exp), None, None);
    let r = run(&with(h, vehsim_core::sim::Method::Rk4), Some(0.00025), Some(h));
    let (er, _, n) = diff(&d, &r);
    println!("bound {bound} s; at {h:.4} s: {:?}, yaw rate {er:.2e} rad/s over {n} rows", d.summary.end_reason);
    assert_eq!(d.summary.end_reason, vehsim_core::event::EndReason::Completed, "{:?}", d.summary.events);
    assert!(n > 100 && er < 5e-3, "at {h} s: {er:.2e} rad/s over {n} rows");
    let bad = run(&with(0.025, vehsim_core::sim::Method::Rk4Exp), None, None);
    let r = run(&with(0.025, vehsim_core::sim::Method::Rk4), Some(0.00025), Some(0.025));
    let (eb, _, _) = diff(&bad, &r);
    println!("at 0.025 s: {:?}, yaw rate {eb:.2e} rad/s", bad.summary.end_reason);
    assert!(
        bad.summary.end_reason != vehsim_core::event::EndReason::Completed || !(eb <= 0.1),
        "{:?} {eb:.2e}",
        bad.summary.end_reason
    );
}

/// Exploration, not a check: errors of step / period pairs against the reference
/// (`VEHSIM_EXPLORE` = comma-separated step:period pairs, seconds; the exponential RK4 throughout).
#[test]
#[ignore = "exploration, not a check: prints errors for VEHSIM_EXPLORE's step:period pairs"]
fn explore() {
    let pairs: Vec<(f64, f64)> = std::env::var("VEHSIM_EXPLORE")
        .unwrap_or("0.005:0.005,0.01:0.01,0.02:0.02".into())
        .split(',')
        .map(|p| {
            let (a, b) = p.split_once(':').unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect();
    let models = std::env::var("VEHSIM_EXPLORE_MODELS").unwrap_or("bicycle".into());
    for model in models.split(',') {
        for tyre in vehsim_core::tyre::TyreModelKind::ALL.iter().map(|k| k.as_str()) {
            let base = dlc(&format!("explore-{model}-{tyre}"), tyre, model, 10.0, 0.15);
            let reference = reference(&base);
            for &(h, tc) in &pairs {
                let mut c = base.clone();
                c.settings.method = vehsim_core::sim::Method::Rk4Exp;
                let o = run(&c, Some(h), Some(tc));
                let (r, y, _) = diff(&o, &reference);
                println!(
                    "{model} {tyre}: h {h} tc {tc}: yaw rate {r:.3e} rad/s, y {y:.3e} m, cones {} vs {}",
                    o.summary.cones_hit, reference.summary.cones_hit
                );
            }
        }
    }
}

/// Report, not a check: for each golden case (tests/golden.rs), the largest |yaw-rate| and |y|
/// distance of the golden file (blessed before the controllers had their own clock) and of the
/// current engine with the spec's settings from a step = control period = 0.25 ms run.
///     cargo test --release --test accuracy golden_distances -- --ignored --nocapture
#[test]
#[ignore = "a report, not a check: prints the goldens' distances from a fine-step run"]
fn golden_distances() {
    for &(stem, spec, tyre, model, contact) in common::GOLDEN_CASES {
        let path = common::root().join(spec);
        let mut file = ManeuverFile::load(&path).unwrap();
        file.tyre_model = tyre.into();
        file.vehicle_model = Some(model.into());
        file.contact.model = contact.into();
        let base = file.build(&path).unwrap();
        let now = execute(&base);
        let reference = reference(&base);
        let text = std::fs::read_to_string(common::root().join(format!("tests/data/golden/{stem}.csv"))).unwrap();
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
        let (ct, cr, cy) = (col("t_s"), col("yaw_rate_radps"), col("y_m"));
        let (mut gr, mut gy) = (0.0_f64, 0.0_f64);
        for l in lines {
            let v: Vec<&str> = l.split(',').collect();
            let t: f64 = v[ct].parse().unwrap();
            if let Some(q) = reference.rows.iter().find(|q| (q.t_s - t).abs() < 1e-9) {
                gr = gr.max((v[cr].parse::<f64>().unwrap() - q.obs.kin.yaw_rate_radps).abs());
                gy = gy.max((v[cy].parse::<f64>().unwrap() - q.obs.kin.y_m).abs());
            }
        }
        let (nr, ny, _) = diff(&now, &reference);
        println!(
            "{stem}: golden {gr:.2e} rad/s, {gy:.2e} m; now (step {} s, period {} s) {nr:.2e} rad/s, {ny:.2e} m",
            base.settings.step_s, base.settings.control_period_s
        );
    }
}

/// Events inside the step: at a fixed control period, the cone strikes (count, boundaries and
/// times) and the end time of a lane change that strikes cones do not depend on the step, since
/// strikes come from the corners' swept segments and the end from an interpolated crossing.
#[test]
fn cone_strikes_and_end_time_do_not_move_with_the_step() {
    let base = dlc("events", "pacejka", "bicycle", 12.0, 0.15);
    let runs: Vec<RunOutput> = [0.005, 0.0025, 0.001].iter().map(|&h| run(&base, Some(h), Some(0.005))).collect();
    let strikes = |o: &RunOutput| -> Vec<(f64, String)> {
        o.summary
            .events
            .iter()
            .filter(|e| e.kind == vehsim_core::event::EventKind::ConeStrike)
            .map(|e| (e.t_s, e.detail.clone()))
            .collect()
    };
    let fine = strikes(&runs[2]);
    assert!(!fine.is_empty(), "the case must strike cones: {:?}", runs[2].summary.events);
    for o in &runs[..2] {
        let s = strikes(o);
        assert_eq!(o.summary.cones_hit, runs[2].summary.cones_hit);
        assert_eq!(s.len(), fine.len(), "{s:?} vs {fine:?}");
        for ((t, d), (tf, df)) in s.iter().zip(&fine) {
            assert!((t - tf).abs() < 1e-3, "{d} at {t} s vs {df} at {tf} s");
            assert_eq!(d.split(" corner").next(), df.split(" corner").next());
        }
        assert_eq!(o.summary.end_reason, vehsim_core::event::EndReason::Completed);
        assert!(
            (o.summary.end_time_s - runs[2].summary.end_time_s).abs() < 1e-4,
            "{} vs {}",
            o.summary.end_time_s,
            runs[2].summary.end_time_s
        );
    }
}
