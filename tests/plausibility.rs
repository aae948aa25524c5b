//! Plausibility checks on real runs: the shipped physical examples are plausible, the linear tyre's
//! runs are flagged at the row where the force first passes 1.05 mu Fz (found here independently
//! from the rows), the constant-radius guard ends a run that leaves the circle and keeps its
//! unmeasured steps out of the understeer gradient, and every friction-limited provider's section
//! reaches the spec's mu, so mu changes the result.

mod common;

use vehsim_core::maneuver::constant_radius::ConstantRadiusParams;
use vehsim_core::tyre::{TyreInput, TyreModelKind};
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_spec::maneuver::ManeuverConfig;
use vehsim_spec::run::execute;
use vehsim_spec::tyre::TyreFileSpec;
use vehsim_spec::RunConfig;

#[test]
fn shipped_physical_examples_are_plausible() {
    for spec in [
        "maneuvers/quickstart_dlc_ice.toml",
        "maneuvers/constant_radius_40m_left_ice.toml",
        "maneuvers/constant_radius_100m_right_dry.toml",
    ] {
        let out = execute(&common::load(spec));
        assert!(out.summary.plausible, "{spec}: {:?}", out.summary.implausible);
        assert!(
            !out.summary
                .events
                .iter()
                .any(|e| e.kind.beyond_friction() || e.kind == vehsim_core::event::EventKind::PathExit),
            "{spec}"
        );
    }
    let out = execute(&common::load("maneuvers/quickstart_dlc_ice.toml"));
    assert_eq!(out.summary.passed, Some(true));
    for spec in ["maneuvers/constant_radius_40m_left_ice.toml", "maneuvers/constant_radius_100m_right_dry.toml"] {
        let out = execute(&common::load(spec));
        assert!(out.steady_states.iter().all(|s| s.steady), "{spec}");
        assert!(out.understeer_gradient.is_some() && out.understeer_gradient_note.is_none(), "{spec}");
    }
    // The sweep example: every run that clears the course is plausible.
    let b = vehsim::batch::load(&common::root().join("maneuvers/dlc_sweep.toml")).unwrap();
    for r in &b.runs {
        let out = execute(r.config.as_ref().unwrap());
        if out.summary.passed == Some(true) {
            assert!(out.summary.plausible, "{:?}: {:?}", r.params, out.summary.implausible);
        }
    }
}

/// The dissertation's lane change with the unsaturated linear tyre (maneuvers/dlc.toml): flagged,
/// with the onset event at the first recorded row whose axle force exceeds 1.05 mu Fz.
#[test]
fn linear_tyre_lane_change_is_flagged_at_the_right_row() {
    let cfg = common::load("maneuvers/dlc.toml");
    let out = execute(&cfg);
    assert!(!out.summary.plausible);
    assert!(out.summary.implausible.iter().any(|r| r.starts_with("tyre force beyond the friction bound")));
    assert!(out.summary.implausible.iter().any(|r| r.starts_with("lateral acceleration beyond")));
    let mu = cfg.env.mu;
    let first = out
        .rows
        .iter()
        .find(|r| {
            let o = &r.obs;
            (0..2).any(|a| o.fx_n[a].hypot(o.fy_n[a]) > 1.05 * mu * (o.fz_n[2 * a] + o.fz_n[2 * a + 1]))
        })
        .expect("a row beyond the bound");
    let ev =
        out.summary.events.iter().find(|e| e.kind == vehsim_core::event::EventKind::TyreForceBeyondFriction).unwrap();
    assert_eq!(ev.t_s, first.t_s);
    // The same manoeuvre with a friction-limited tyre never exceeds its bound.
    for kind in [TyreModelKind::Pacejka, TyreModelKind::Polynomial, TyreModelKind::Dugoff] {
        let cfg = with_tyre(&cfg, kind);
        let out = execute(&cfg);
        assert!(!out.summary.events.iter().any(|e| e.kind.beyond_friction()), "{}", kind.as_str());
    }
}

fn with_tyre(cfg: &RunConfig, kind: TyreModelKind) -> RunConfig {
    let mut c = cfg.clone();
    let p = c.vehicle_file.parent().unwrap().join("tyres/srtt_p225_60r16.toml");
    c.vehicle.tyre = TyreFileSpec::load(&p).unwrap().build(&p, kind).unwrap();
    c.tyre_model = kind;
    c
}

/// The case: a 20 m circle on ice with a_y steps to 5 m/s^2 (3.4 x mu g). The run ends when
/// the car leaves the circle (end reason `left_path`, no `completed`), the steps it reached were
/// steady and give the gradient, and nothing is reported for the steps it never drove. A 0.5 m
/// circle (below the car's turning radius) ends at once with no gradient and the reason.
#[test]
fn constant_radius_guard_ends_the_run_and_drops_steps() {
    let base = common::load("maneuvers/constant_radius_40m_left_ice.toml");
    let circle = |r: f64, ay_max: f64| {
        let mut c = base.clone();
        c.vehicle_model = VehicleModelKind::Bicycle;
        let ManeuverConfig::ConstantRadius(p) = &mut c.maneuver else { panic!("not a circle") };
        p.radius_m = r;
        p.step_speeds_mps = ConstantRadiusParams::stepped_speeds(r, 0.25, 0.25, ay_max);
        p.settle_s = 10.0;
        p.window_s = 3.0;
        c.settings.duration_s = p.total_s() + 1.0;
        c
    };
    let out = execute(&circle(20.0, 5.0));
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::LeftPath, "{:?}", out.summary.events);
    assert!(!out.summary.plausible);
    assert_eq!(out.summary.events.last().unwrap().kind, vehsim_core::event::EventKind::LeftPath);
    let end = out.summary.end_time_s;
    assert!(end < 20.0 * 13.0, "ended at {end}");
    // A window the run did not reach to its end is not steady; a steady one is within friction.
    for s in &out.steady_states {
        if s.t1_s > end + 1e-9 {
            assert!(!s.steady && s.not_steady.contains("the run ended"), "{s:?}");
        }
        if s.steady {
            assert!(s.ay_mps2.abs() <= 1.05 * 0.18 * 9.81, "{s:?}");
        }
    }
    let steady = out.steady_states.iter().filter(|s| s.steady).count();
    match &out.understeer_gradient {
        Some(g) => assert_eq!(g.steps, steady),
        None => assert!(steady < 3 && out.understeer_gradient_note.is_some()),
    }

    let out = execute(&circle(0.5, 1.0));
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::LeftPath);
    assert!(out.understeer_gradient.is_none());
    assert!(
        out.understeer_gradient_note.as_deref().unwrap().contains("at least 3"),
        "{:?}",
        out.understeer_gradient_note
    );
}

/// The polynomial and Dugoff sections reach the spec's mu (mu_scale 1.0): their peak friction is
/// mu, and |F| / Fz at full sliding approaches it; so a mu sweep changes the lane change.
#[test]
fn friction_limited_sections_reach_the_specs_mu_and_mu_matters() {
    let p = common::root().join("vehicles/tyres/srtt_p225_60r16.toml");
    for kind in [TyreModelKind::Polynomial, TyreModelKind::Dugoff] {
        let m = TyreFileSpec::load(&p).unwrap().build(&p, kind).unwrap().model;
        for mu in [0.15, 0.3, 1.0] {
            let i = TyreInput::new(4000.0, 0.0, 1.0, mu);
            assert!((m.peak_friction(&i) - mu).abs() < 1e-12, "{}", kind.as_str());
            let f = m.forces(&i);
            let r = f.fx_n.hypot(f.fy_n) / (mu * 4000.0);
            assert!((0.9..=1.0 + 1e-9).contains(&r), "{} at mu {mu}: |F|/(mu Fz) = {r}", kind.as_str());
        }
    }
    let b = vehsim::batch::load(&common::root().join("maneuvers/dlc_sweep.toml")).unwrap();
    let peak = |speed: &str, mu: &str| {
        let r = b.runs.iter().find(|r| r.params[0].1 == speed && r.params[1].1 == mu).unwrap();
        execute(r.config.as_ref().unwrap()).summary.peak_ay_mps2
    };
    let (lo, hi) = (peak("8.0", "0.15"), peak("8.0", "0.3"));
    assert!(hi > 1.1 * lo, "mu 0.15 -> {lo}, mu 0.3 -> {hi}");
}
