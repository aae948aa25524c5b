//! The tread-temperature state and the friction band of `vehsim discover` against closed forms
//! and a fine-step reference, their recovery from data synthesized with them (each form against
//! its sibling forms), and the dropping of a proxy made redundant by the true effect.
//!
//! Expected values come from the generating parameters (`synth::default_params`) or from closed
//! forms written here, never from the code under test.

mod common;

use vehsim::discover::measured::MeasuredRun;
use vehsim::discover::model::{melt_cap_k, EffectParams, ReplayModel};
use vehsim::discover::{discover, load_vehicle, synth, tyre_kind, Dataset, Discovery, Effect};

fn model() -> ReplayModel {
    let v = load_vehicle(&common::root().join("vehicles/sedan.toml"), None, tyre_kind("pacejka").unwrap()).unwrap();
    ReplayModel::new(v)
}

/// A run on ice at constant steer and speed (no noise), `secs` long at 100 Hz.
fn steady_run(steer: f64, vx: f64, ice_c: f64, secs: f64) -> MeasuredRun {
    let n = (secs * 100.0) as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
    MeasuredRun {
        path: "steady.csv".into(),
        name: "steady".into(),
        steer: vec![steer; n],
        vx: vec![vx; n],
        yaw_rate: vec![0.0; n],
        ay: vec![0.0; n],
        t,
        optional: Vec::new(),
        mu: 0.15,
        ice_temp_c: ice_c,
        on_ice: true,
        initial_vx: vx,
        regions: Default::default(),
        road: Default::default(),
        notices: Vec::new(),
    }
}

/// The tread state with friction change k (1/K), heat capacity c (J/K) and cooling time tau (s).
fn tread(k: f64, c: f64, tau: f64) -> EffectParams {
    let mut p = EffectParams::default();
    // Fitted as the change per kJ of tread heat: k / (c / 1000 kJ/K).
    Effect::ThermalState.apply(&mut p, &[k / (c * 1e-3), c, tau]);
    assert!((p.tread_mu_per_k - k).abs() < 1e-15);
    p
}

/// In a steady turn the front tread rise settles at P_f tau_c / C, with P_f = vx |tan alpha_f|
/// |Fy_f| the front axle's frictional power. Fy_f follows from the yaw-moment balance
/// (a Fy_f cos delta = b Fy_r) and the lateral one (m ay = Fy_f cos delta + Fy_r):
/// Fy_f = m ay b / (L cos delta). The closed form takes ay and alpha_f from the replay.
#[test]
fn tread_rise_settles_at_frictional_power_times_cooling_time_over_heat_capacity() {
    let m = model();
    let v = &m.vehicle;
    let (steer, vx, tau, c) = (0.02, 10.0, 2.0, 400.0);
    let run = steady_run(steer, vx, -10.0, 30.0);
    let s = m.simulate(&run, &tread(-0.05, c, tau));
    assert!(s.ok);
    let k = run.t.len() - 1;
    let fyf = v.mass_kg * s.ay[k] * v.b_m / (v.wheelbase_m() * steer.cos());
    let power = vx * s.alpha_f[k].tan().abs() * fyf.abs();
    let expect = power * tau / c;
    let got = s.contact_rise_k[k];
    eprintln!("steady front rise {got:.6} K; closed form {expect:.6} K (P_f = {power:.1} W)");
    assert!(expect > 0.2 && expect < 10.0, "the case must heat without reaching melting: {expect}");
    assert!((got - expect).abs() < 1e-4 * expect, "{got} vs {expect}");
    // Off on dry ground.
    let dry = MeasuredRun { on_ice: false, ..run.clone() };
    let (a, b) = (m.simulate(&dry, &tread(-0.05, c, tau)), m.simulate(&dry, &EffectParams::default()));
    assert_eq!(a.yaw_rate, b.yaw_rate);
}

/// The contact cannot exceed melting: on ice at -1 degC the rise stops at 1 K however strong the
/// heating, and the friction then stays at (1 + k_T x 1 K) of the nominal.
#[test]
fn tread_rise_is_capped_at_melting() {
    let m = model();
    assert_eq!(melt_cap_k(-1.0), 1.0);
    assert_eq!(melt_cap_k(2.0), 0.0);
    let run = steady_run(0.03, 10.0, -1.0, 10.0);
    let s = m.simulate(&run, &tread(-0.2, 20.0, 5.0));
    let mx = s.contact_rise_k.iter().cloned().fold(0.0, f64::max);
    let at_cap = s.contact_rise_k.iter().filter(|r| **r == 1.0).count();
    eprintln!("largest rise {mx} K; {at_cap} samples at the cap");
    assert_eq!(mx, 1.0);
    assert!(at_cap > 500, "{at_cap}");
    // At the cap the tread state acts as a fixed friction factor 1 - 0.2 x 1 = 0.8 (axle-wise
    // peak friction scale 0.8 on both axles), so the end of the run replays identically.
    let mut fixed = EffectParams::default();
    Effect::AxleFriction.apply(&mut fixed, &[0.8, 0.8]);
    let f = m.simulate(&run, &fixed);
    let k = run.t.len() - 1;
    assert!((s.yaw_rate[k] - f.yaw_rate[k]).abs() < 1e-6, "{} vs {}", s.yaw_rate[k], f.yaw_rate[k]);
}

/// The tread rise is a first-order lag updated exactly over the replay's step (with the cap
/// applied at the step's end): against plain RK4 at 1 ms it agrees within 1e-4 rad/s of yaw rate
/// and 2 % of what the effect changes, on the ice sine and the ice step (which reaches melting).
#[test]
fn tread_state_matches_a_fine_step_reference() {
    let m = model();
    let mut fine = model();
    fine.reference_step_s = Some(1e-3);
    let p = tread(-0.15, 200.0, 0.3);
    let runs = synth::generate(&m, &EffectParams::default(), 5);
    for run in [&runs[0].0, &runs[3].0] {
        let none = m.simulate(run, &EffectParams::default());
        let (a, b) = (m.simulate(run, &p), fine.simulate(run, &p));
        let max_abs = |u: &[f64], w: &[f64]| u.iter().zip(w).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let (diff, effect) = (max_abs(&a.yaw_rate, &b.yaw_rate), max_abs(&b.yaw_rate, &none.yaw_rate));
        eprintln!("tread state, {}: max |r - r_fine| = {diff:.2e} rad/s; the effect moves r by {effect:.2e}", run.name);
        assert!(diff < 1e-4 && diff < 0.02 * effect, "{}: {diff} against {effect}", run.name);
    }
}

/// The band's friction factor against its closed form 1 + (s - 1) w, w = 1 / (1 + e^-(X - X0))
/// x 1 / (1 + e^-(X0 + L - X)) (edges of 1 m).
#[test]
fn band_factor_follows_its_closed_form() {
    let p = EffectParams { band: [0.4, 20.0, 30.0], ..Default::default() };
    let logistic = |z: f64| 1.0 / (1.0 + (-z).exp());
    for x in [-5.0, 19.0, 20.0, 21.5, 35.0, 49.0, 50.0, 80.0] {
        let expect = 1.0 - 0.6 * logistic(x - 20.0) * logistic(50.0 - x);
        assert!((p.band_factor(x) - expect).abs() < 1e-12, "X = {x}");
    }
    assert_eq!(EffectParams::default().band_factor(30.0), 1.0);
}

/// Discovery over the candidates `cands` on data synthesized with `truth` on.
fn discover_on(truth: Effect, cands: &[Effect], seed: u64) -> Discovery {
    let m = model();
    let mut p = EffectParams::default();
    truth.apply(&mut p, &synth::default_params(truth));
    let runs = synth::generate(&m, &p, seed);
    discover(&m, &Dataset::new(runs.into_iter().map(|r| r.0).collect()), cands)
}

/// Every generating value inside the final 95 % interval (widened to the blind suite's
/// family-wise level, 3.09 standard errors, as discover_blind.rs does).
fn check_recovered(d: &Discovery, e: Effect) {
    let truth = synth::default_params(e);
    assert_eq!(d.named_names(), vec![e.name()], "{:?}", d.rejected);
    let fe = &d.final_effects[0];
    assert_eq!(fe.effect, e, "wrong form");
    assert!(fe.significant);
    let rows: Vec<_> = e.params().iter().zip(&truth).zip(fe.params.iter().zip(&fe.intervals)).collect();
    for ((def, t), ((_, v, _), iv)) in &rows {
        eprintln!("  {}: {v:.5} (95 %: {:.5} to {:.5}), generated {t}", def.name, iv.lo, iv.hi);
    }
    for ((def, t), ((_, _, _), iv)) in rows {
        let widen = (3.09 - vehsim::discover::uncertainty::Z95) * iv.std_error;
        assert!(iv.lo - widen <= *t && *t <= iv.hi + widen, "{}: {t} outside [{}, {}]", def.name, iv.lo, iv.hi);
    }
}

/// Discovery over `cands` on `truth`'s data (seed 11): `truth` is named, in its form, every
/// generating value inside its interval; the candidates' held-out scores are printed.
fn named_among(truth: Effect, cands: &[Effect]) -> Discovery {
    let d = discover_on(truth, cands, 11);
    for t in &d.rejected {
        eprintln!("rejected {}: dBIC {:.1}, {}; {:?}", t.effect.label(), t.delta_bic, t.reason, t.params);
    }
    eprintln!("accepted: {:?} ({}), verdict {}", d.steps[0].params, d.steps[0].evidence, d.verdict);
    check_recovered(&d, truth);
    d
}

/// Tread-state data: of the two thermal forms, the tread state is named and its three
/// parameters are recovered within their intervals; the estimator form scores lower.
#[test]
fn tread_state_data_name_the_tread_state_over_the_estimator_form() {
    let d = named_among(Effect::ThermalState, &[Effect::ThermalFriction, Effect::ThermalState]);
    assert!(d.verdict.at_noise(), "{}", d.verdict);
}

/// Friction-band data: among the friction-change forms the band is named and located.
#[test]
fn friction_band_data_name_the_band_and_locate_it() {
    let cands = [Effect::FrictionChange, Effect::FrictionStretch, Effect::FrictionPatch, Effect::FrictionBand];
    let d = named_among(Effect::FrictionBand, &cands);
    assert!(d.verdict.at_noise(), "{}", d.verdict);
}

/// The reverse: data from the ATIIM-estimator form name the estimator form, not the tread state.
#[test]
#[ignore = "slow (the estimator form): run with cargo test --release --test discover_forms -- --ignored"]
fn estimator_form_data_name_the_estimator_form_over_the_tread_state() {
    let _ = named_among(Effect::ThermalFriction, &[Effect::ThermalFriction, Effect::ThermalState]);
}

/// A proxy made redundant by the true effect: front cornering stiffness lowered by 30 % looks,
/// in the linear range, like a steer compliance (delta_e = delta - c Fy_f lowers the front axle's
/// effective stiffness). Fitted alone, the compliance is clearly significant; refitted jointly
/// with the per-axle stiffness (named after it), its interval contains 0 and it is the one
/// [`redundant`] drops, while the stiffness stays. (On this data the greedy search names the
/// stiffness first, so the proxy never gets named; the test drives the step the search takes
/// after each joint refit.)
#[test]
fn a_proxy_is_dropped_when_the_true_effect_makes_it_redundant() {
    use vehsim::discover::select::{fit_jointly, redundant};
    let m = model();
    let mut p = EffectParams::default();
    Effect::AxleStiffness.apply(&mut p, &[0.7, 1.0]);
    let runs = synth::generate(&m, &p, 11);
    let data = Dataset::new(runs.into_iter().map(|r| r.0).collect());
    let base = EffectParams::default();
    // The proxy alone: significant.
    let (v, _) = fit_jointly(&m, &data, &base, &[(Effect::SteerCompliance, vec![0.002])]);
    let alone = vec![(Effect::SteerCompliance, v[0].clone())];
    let (_, iv, _) = redundant(&m, &data, &base, &alone);
    eprintln!("compliance alone: {:?} {:?}", v[0], iv[0]);
    assert!(!iv[0][0].contains(0.0), "the proxy alone must be significant");
    // With the true effect, refitted jointly: the proxy (index 0) is redundant.
    let both = vec![(Effect::SteerCompliance, v[0].clone()), (Effect::AxleStiffness, vec![1.0, 1.0])];
    let (vals, _) = fit_jointly(&m, &data, &base, &both);
    let both: Vec<(Effect, Vec<f64>)> = both.iter().map(|b| b.0).zip(vals).collect();
    let (vals, ivs, gone) = redundant(&m, &data, &base, &both);
    eprintln!("jointly: {vals:?} {ivs:?}; dropped {gone:?}");
    assert_eq!(gone, vec![0]);
    assert!(ivs[0][0].contains(0.0));
    assert!((vals[1][0] - 0.7).abs() < 0.05 && (vals[1][1] - 1.0).abs() < 0.05, "{:?}", vals[1]);
}

/// The new forms' parameters are range-checked on the command line like the others: exit 2 with
/// `--params`, the key, the value and the allowed range; and one form at a time.
#[test]
fn new_form_parameters_out_of_range_are_usage_errors() {
    let dir = common::temp_dir("discover-forms-params");
    let sedan = common::root().join("vehicles/sedan.toml");
    let sedan = sedan.to_str().unwrap();
    common::assert_synth_params_refused(
        &dir,
        &[
            ("thermal_friction", "tread_mu_per_kj=5", "tread_mu_per_kj = 5 is outside [-20, 0] 1/kJ"),
            ("thermal_friction", "tread_heat_capacity_j_per_k=1", "outside [10, 100000] J/K"),
            ("thermal_friction", "tread_cooling_time_s=0", "outside [0.1, 100] s"),
            ("friction_change", "band_length_m=0", "band_length_m = 0 is outside [2, 2000] m"),
        ],
    );
    let (code, _, err) = common::vehsim(
        &dir,
        &[
            "synth",
            "--vehicle",
            sedan,
            "--effect",
            "thermal_friction",
            "--params",
            "tread_cooling_time_s=2",
            "thermal_mu_per_k=-1",
            "--out",
            "x",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("no form of thermal_friction has all of"), "{err}");
}
