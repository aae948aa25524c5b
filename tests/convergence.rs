//! Step-size convergence of the engine for every vehicle model (bicycle, 4-DOF roll) and every
//! tyre provider (`TyreModelKind::ALL`), on a short open-loop manoeuvre where the solution is
//! smooth: the shipped sine steer on ice (`maneuvers/sine_steer.toml`, 10 m/s, mu 0.15, period
//! 10 s), cut to its first [`DURATION_S`] seconds (the steer rises to its peak and half way back).
//!
//! - RK4: the step halves, h = 4, 2, 1, 0.5 ms, while the controller period stays 4 ms (the PID is
//!   sampled at the same instants in every run and the steer is a function of time, so only the integration error
//!   changes). The error is the largest |yaw-rate difference| against a Dop853 reference over the
//!   output rows (every 20 ms). Fourth order means the error falls 16-fold per halving: the
//!   observed order p = log2(e_h / e_{h/2}) must lie in [3.6, 4.4] ([3.4, 4.6] for the first
//!   halving, see [`FIRST_HALVING_ORDER`]) for every halving whose finer
//!   error is well above the noise floor (30 times; see [`noise_floor`]), and at least two
//!   halvings must qualify per combination.
//! - Adaptive: Dopri5 and Dop853 at rtol = atol = tol (1e-5, 1e-7), against Dop853 at 1e-10; the
//!   largest |yaw-rate error| must stay within tol itself (see
//!   [`adaptive_methods_meet_their_tolerance`] for why the multiple is 1).
//!
//! Regimes. Four providers are smooth in slip everywhere the run goes (linear without saturation,
//! the polynomial brush whose saturation joins with zero slope and curvature, Pacejka and
//! ATIIM-Pacejka), and run the shipped 10 degree sine steer, deep into saturation (peak friction
//! use about 0.95 per axle). The Dugoff providers are not: their force is
//! F = q / (1 + kappa) f(z) with f(z) = z (2 - z) for z < 1 and 1 otherwise
//! (`crates/vehsim-core/src/tyre/dugoff.rs`), z = mu Fz (1 + kappa) / (2 q). The switch at z = 1, where the
//! force magnitude reaches half the friction limit, is only C1: f'(1) = 0 on both sides but f''
//! jumps from -2 to 0, so the second derivative of the force in the slips, and the third time
//! derivative of the state, jump at every crossing. Every RK4 step that straddles a
//! crossing makes a local error of order h^3 instead of h^5, and the sum over the crossings is of
//! order h^3 with a constant that depends on where each crossing falls within its step; the
//! observed order in the 10 degree run wanders between 0 and 4.6 (printed below as a finding, not
//! asserted). The Dugoff providers are therefore tested on the same sine steer at 1 degree, where
//! the largest friction use is 0.37 < 0.5: z > 1 throughout, the force is the smooth linear branch,
//! and the test asserts that it stays there. (Dugoff-thermal's factor H also has a kink at
//! kappa = 0, its slip S being kappa / (1 + kappa) for kappa >= 0 and -kappa below; in these runs
//! the driven front wheels keep kappa > 0 and the free rear wheels, held back by rolling
//! resistance, kappa < 0 after the first step, so the kink is not crossed.)

mod common;

use vehsim_core::sim::Method;
use vehsim_core::tyre::TyreModelKind;
use vehsim_spec::run::{execute, RunOutput};
use vehsim_spec::{ManeuverFile, RunConfig};

/// Simulated time per run, s.
const DURATION_S: f64 = 4.0;
/// Controller period held fixed in every run, s.
const CONTROL_S: f64 = 0.004;
/// RK4 steps, s: successive halvings.
const STEPS: [f64; 4] = [0.004, 0.002, 0.001, 0.0005];
/// Accepted observed orders.
const ORDER: (f64, f64) = (3.6, 4.4);
/// Accepted observed orders of the first halving (4 ms to 2 ms). There h |lambda| = 0.62 for the
/// wheel-spin mode (|lambda| about 156 1/s on ice), short of RK4's asymptotic range, and with the
/// open-loop steer evaluated at every stage (no longer held over the 4 ms control period) the
/// observed order there ranges from 3.55 to 4.51 over the combinations.
const FIRST_HALVING_ORDER: (f64, f64) = (3.4, 4.6);
/// Road-wheel steer amplitude of the smooth regime of the Dugoff providers, deg.
const DUGOFF_AMPLITUDE_DEG: f64 = 1.0;

const MODELS: [&str; 2] = ["bicycle", "roll4dof"];

/// The sine-steer spec with the given provider, vehicle model and (optionally) steer amplitude.
fn config(tyre: TyreModelKind, model: &str, amplitude_deg: Option<f64>) -> RunConfig {
    let path = common::root().join("maneuvers/sine_steer.toml");
    let mut file = ManeuverFile::load(&path).unwrap();
    file.tyre_model = tyre.as_str().to_string();
    file.vehicle_model = Some(model.to_string());
    file.duration_s = Some(DURATION_S);
    if let Some(a) = amplitude_deg {
        file.maneuver.insert("steer_amplitude_deg".into(), toml::Value::Float(a));
    }
    file.build(&path).unwrap()
}

/// Whether a provider has the Dugoff z = 1 switch (see the module docs).
fn is_dugoff(tyre: TyreModelKind) -> bool {
    matches!(tyre, TyreModelKind::Dugoff | TyreModelKind::DugoffThermal)
}

/// The smooth regime of a provider (see the module docs).
fn smooth_config(tyre: TyreModelKind, model: &str) -> RunConfig {
    config(tyre, model, is_dugoff(tyre).then_some(DUGOFF_AMPLITUDE_DEG))
}

fn run(base: &RunConfig, method: Method, step: f64) -> RunOutput {
    let mut c = base.clone();
    c.settings.method = method;
    c.settings.step_s = step;
    c.settings.control_period_s = CONTROL_S;
    c.settings.output_interval_s = 0.02;
    execute(&c)
}

fn dop853(base: &RunConfig, tol: f64) -> RunOutput {
    run(base, Method::Dop853 { rtol: tol, atol: tol }, CONTROL_S)
}

/// Largest |yaw-rate difference| over the common output rows (all 201 rows of a 4 s run).
fn err(a: &RunOutput, b: &RunOutput) -> f64 {
    assert_eq!(a.summary.end_reason, vehsim_core::event::EndReason::Duration, "{:?}", a.summary.events);
    assert_eq!(b.summary.end_reason, vehsim_core::event::EndReason::Duration, "{:?}", b.summary.events);
    let mut worst = 0.0_f64;
    let mut n = 0;
    for (p, q) in a.rows.iter().zip(&b.rows) {
        assert!((p.t_s - q.t_s).abs() < 1e-9, "output grids differ");
        worst = worst.max((p.obs.kin.yaw_rate_radps - q.obs.kin.yaw_rate_radps).abs());
        n += 1;
    }
    assert!(n > 200, "only {n} common rows");
    worst
}

/// Noise floor of an error measurement, rad/s: the larger of the disagreement of the references at
/// rtol = atol = 1e-12 and 1e-13 (what is left of the reference's own error) and an estimate of
/// the round-off accumulated by RK4 over its longest run, sqrt(8000 steps) x machine epsilon x
/// the peak yaw rate (a random walk of one rounding per step). A halving counts only when its
/// finer error exceeds [`ABOVE_FLOOR`] times this floor.
fn noise_floor(r12: &RunOutput, r13: &RunOutput) -> f64 {
    let steps = DURATION_S / STEPS[STEPS.len() - 1];
    let round_off = steps.sqrt() * f64::EPSILON * r12.summary.peak_yaw_rate_radps;
    err(r12, r13).max(round_off)
}

/// How far above the noise floor an error must be for its halving to count.
const ABOVE_FLOOR: f64 = 30.0;

/// Largest friction use |F| / (mu_tyre Fz) per axle over a run (axle sums; mu_tyre = mu, the
/// Dugoff sections' `mu_scale` being 1).
fn friction_use(out: &RunOutput, mu_tyre: f64) -> f64 {
    let mut worst = 0.0_f64;
    for r in &out.rows {
        let o = &r.obs;
        for a in 0..2 {
            let fz = o.fz_n[2 * a] + o.fz_n[2 * a + 1];
            worst = worst.max(o.fx_n[a].hypot(o.fy_n[a]) / (mu_tyre * fz));
        }
    }
    worst
}

/// RK4 errors against `reference` at every step of [`STEPS`] and the observed orders.
fn rk4_errors(base: &RunConfig, reference: &RunOutput) -> (Vec<f64>, Vec<f64>) {
    method_errors(base, Method::Rk4, reference)
}

/// Errors of a fixed-step `method` against `reference` at every step of [`STEPS`] and the
/// observed orders.
fn method_errors(base: &RunConfig, method: Method, reference: &RunOutput) -> (Vec<f64>, Vec<f64>) {
    let errs: Vec<f64> = STEPS.iter().map(|&h| err(&run(base, method, h), reference)).collect();
    let orders = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    (errs, orders)
}

fn fmt_all(v: &[f64], f: impl Fn(f64) -> String) -> String {
    v.iter().map(|x| f(*x)).collect::<Vec<_>>().join("  ")
}

/// RK4 converges at fourth order for every vehicle model and provider in its smooth regime. Prints
/// the table (`--nocapture`), and the Dugoff providers in the saturating 10 degree run as a finding.
#[test]
fn rk4_step_halving_is_fourth_order_for_every_model_and_provider() {
    let mut failures = Vec::new();
    eprintln!(
        "RK4 max |yaw-rate error| (rad/s) vs Dop853 rtol=atol=1e-12, h = 4, 2, 1, 0.5 ms, control 4 ms; \
         orders log2(e_h / e_h/2); * = finer error below 30x the noise floor, not asserted"
    );
    eprintln!("{:<24} {:>7} {:>9}  {:<43} orders", "model / provider", "amp deg", "floor", "errors at 4, 2, 1, 0.5 ms");
    for model in MODELS {
        for &tyre in TyreModelKind::ALL {
            let base = smooth_config(tyre, model);
            let (r12, r13) = (dop853(&base, 1e-12), dop853(&base, 1e-13));
            let floor = noise_floor(&r12, &r13);
            let (errs, orders) = rk4_errors(&base, &r12);
            let mut asserted = 0;
            let mut shown = Vec::new();
            for (k, p) in orders.iter().enumerate() {
                let counted = errs[k + 1] > ABOVE_FLOOR * floor;
                shown.push(format!("{p:.2}{}", if counted { "" } else { "*" }));
                if counted {
                    asserted += 1;
                    let band = if k == 0 { FIRST_HALVING_ORDER } else { ORDER };
                    if !(band.0..=band.1).contains(p) {
                        failures.push(format!("{model}/{}: order {p:.2} at halving {k} ({errs:?})", tyre.as_str()));
                    }
                }
            }
            if asserted < 2 {
                failures
                    .push(format!("{model}/{}: only {asserted} halvings above the floor {floor:.1e}", tyre.as_str()));
            }
            if is_dugoff(tyre) {
                let u = friction_use(&r12, base.env.mu);
                if u >= 0.45 {
                    failures.push(format!("{model}/{}: friction use {u:.3} reaches the z = 1 switch", tyre.as_str()));
                }
            }
            let amp = if is_dugoff(tyre) { DUGOFF_AMPLITUDE_DEG } else { 10.0 };
            eprintln!(
                "{:<24} {amp:>7.0} {floor:>9.1e}  {:<43} {}",
                format!("{model} / {}", tyre.as_str()),
                fmt_all(&errs, |e| format!("{e:.2e}")),
                shown.join("  ")
            );
        }
    }
    // The finding: the Dugoff providers through their z = 1 switch (10 degree steer).
    eprintln!("not asserted: Dugoff providers in the 10 degree run (force crosses half the friction limit, z = 1)");
    for model in MODELS {
        for tyre in [TyreModelKind::Dugoff, TyreModelKind::DugoffThermal] {
            let base = config(tyre, model, None);
            let r12 = dop853(&base, 1e-12);
            let (errs, orders) = rk4_errors(&base, &r12);
            eprintln!(
                "{:<24} {:>7} {:>9}  {:<43} {}  (friction use {:.2})",
                format!("{model} / {}", tyre.as_str()),
                10,
                "-",
                fmt_all(&errs, |e| format!("{e:.2e}")),
                fmt_all(&orders, |p| format!("{p:.2}")),
                friction_use(&r12, base.env.mu)
            );
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The exponential RK4 (`Method::Rk4Exp`: the wheel-spin / transient-slip pairs carried by their
/// exact exponential, linearised at each step's start) keeps RK4's fourth order: the split
/// f = L (x - x_k) + (f - L (x - x_k)) with any fixed L leaves a consistent fourth-order method.
/// Same runs and bands as the RK4 test, for both vehicle models with the Magic Formula and the
/// linear tyre.
#[test]
fn exponential_rk4_step_halving_is_fourth_order() {
    let mut failures = Vec::new();
    for model in MODELS {
        for tyre in [TyreModelKind::Pacejka, TyreModelKind::Linear] {
            let base = smooth_config(tyre, model);
            let (r12, r13) = (dop853(&base, 1e-12), dop853(&base, 1e-13));
            let floor = noise_floor(&r12, &r13);
            let (errs, orders) = method_errors(&base, Method::Rk4Exp, &r12);
            eprintln!(
                "{model} / {}: errors {}, orders {}, floor {floor:.1e}",
                tyre.as_str(),
                fmt_all(&errs, |e| format!("{e:.2e}")),
                fmt_all(&orders, |p| format!("{p:.2}"))
            );
            let mut asserted = 0;
            for (k, p) in orders.iter().enumerate() {
                if errs[k + 1] > ABOVE_FLOOR * floor {
                    asserted += 1;
                    let band = if k == 0 { FIRST_HALVING_ORDER } else { ORDER };
                    if !(band.0..=band.1).contains(p) {
                        failures.push(format!("{model}/{}: order {p:.2} at halving {k} ({errs:?})", tyre.as_str()));
                    }
                }
            }
            if asserted < 2 {
                failures.push(format!("{model}/{}: only {asserted} halvings above the floor", tyre.as_str()));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Dopri5 and Dop853 at rtol = atol = tol keep the largest |yaw-rate error| against Dop853 at
/// 1e-10 within tol itself, for every vehicle model and provider (smooth regimes as above).
///
/// Why a multiple of 1. The solvers keep the estimated local error of every accepted step below
/// tol (1 + |y|) per component (weighted RMS norm <= 1); the yaw rate stays below 1 rad/s, so the
/// local yaw-rate error per step is bounded by about 2 tol. The global error is the sum of these
/// local errors carried forward by the (stable, damped) yaw dynamics, so over the ~1000 controller
/// intervals of the run (each at least one step) it could in principle reach hundreds of tol.
/// It does not, because both pairs propagate the higher-order solution (local extrapolation):
/// the error actually made per step is an order of h smaller than the estimate being controlled.
/// A bound of tol itself is then safe (the table prints the margin, several orders), while a looser
/// multiple would let a solver that ignored its tolerance pass. The errors must also not grow when
/// the tolerance tightens. (On ice the dynamics are slow: Dop853 covers each 4 ms interval in one
/// step at every tolerance from 1e-5 to 1e-10 for most combinations, so its error against the
/// reference is often exactly 0.)
#[test]
fn adaptive_methods_meet_their_tolerance() {
    const TOLS: [f64; 2] = [1e-5, 1e-7];
    let mut failures = Vec::new();
    eprintln!("adaptive max |yaw-rate error| (rad/s) vs Dop853 rtol=atol=1e-10; bound: tol");
    eprintln!(
        "{:<24} {:>10} {:>10} {:>10} {:>10}",
        "model / provider", "dopri5 1e-5", "dopri5 1e-7", "dop853 1e-5", "dop853 1e-7"
    );
    for model in MODELS {
        for &tyre in TyreModelKind::ALL {
            let base = smooth_config(tyre, model);
            let reference = dop853(&base, 1e-10);
            let mut row = Vec::new();
            for (name, make) in [
                ("dopri5", (|t| Method::Dopri5 { rtol: t, atol: t }) as fn(f64) -> Method),
                ("dop853", |t| Method::Dop853 { rtol: t, atol: t }),
            ] {
                let errs: Vec<f64> = TOLS.iter().map(|&t| err(&run(&base, make(t), CONTROL_S), &reference)).collect();
                for (e, t) in errs.iter().zip(TOLS) {
                    if *e > t {
                        failures.push(format!("{model}/{} {name} tol {t:e}: error {e:.2e}", tyre.as_str()));
                    }
                }
                if errs[1] > errs[0] {
                    failures.push(format!("{model}/{} {name}: error grows as tol tightens {errs:?}", tyre.as_str()));
                }
                row.extend(errs);
            }
            eprintln!("{:<24} {}", format!("{model} / {}", tyre.as_str()), fmt_all(&row, |e| format!("{e:>10.2e}")));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
