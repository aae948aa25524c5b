//! The improved vehicle spec written by `vehsim discover` runs with `vehsim run`, and the
//! engine's `[lateral]` extensions behave as their equations say.

mod common;

use std::process::Command;

use common::BIN;
use vehsim_core::vehicle::road::Road;

#[test]
fn improved_vehicle_spec_from_discover_runs_with_vehsim_run() {
    let dir = common::temp_dir("discover-spec");
    let root = common::root();
    let runs = common::synth_runs(&dir, "friction_change", "mu_scale=0.6");
    let out = dir.join("out");
    let o = Command::new(BIN)
        .arg("discover")
        .arg("--vehicle")
        .arg(root.join("vehicles/sedan.toml"))
        .arg("--out")
        .arg(&out)
        .args(&runs)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let vf = vehsim_spec::vehicle::VehicleFile::load(&out.join("vehicle.toml")).unwrap();
    let v = vf.build(&out.join("vehicle.toml"), vehsim_core::tyre::TyreModelKind::Pacejka).unwrap();
    assert!((v.lateral.mu_scale - 0.6).abs() < 0.25 * 0.6, "mu_scale {}", v.lateral.mu_scale);
    assert_eq!(v.lateral.steer_compliance_rad_per_kn, 0.0);
    let spec = "name = \"improved\"\nvehicle = \"out/vehicle.toml\"\ntyre_model = \"pacejka\"\nduration_s = 4.0\n\
                [surface]\nmu = 0.15\n[maneuver]\nkind = \"sine_steer\"\nspeed_mps = 10.0\nsteer_amplitude_deg = 2.0\nperiod_s = 3.0\n";
    std::fs::write(dir.join("improved.toml"), spec).unwrap();
    let o = Command::new(BIN)
        .args(["run", "improved.toml", "--out", "results", "--quiet"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("results/improved/timeseries.csv").exists());
}

/// mu_scale s on surface mu is the same car as surface mu s*mu; steer compliance lowers the
/// steady yaw rate of a step steer.
#[test]
fn lateral_section_mu_scale_and_steer_compliance_act_as_documented() {
    let base = common::load("maneuvers/sine_steer.toml");
    let mut scaled = base.clone();
    scaled.vehicle.lateral.mu_scale = 0.5;
    let mut lowered = base.clone();
    lowered.env.mu = base.env.mu * 0.5;
    let a = vehsim_spec::run::execute(&scaled);
    let b = vehsim_spec::run::execute(&lowered);
    assert_eq!(a.rows.len(), b.rows.len());
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        assert!((ra.obs.kin.yaw_rate_radps - rb.obs.kin.yaw_rate_radps).abs() < 1e-9);
    }
    let mut compliant = base.clone();
    compliant.vehicle.lateral.steer_compliance_rad_per_kn = 0.01;
    let c = vehsim_spec::run::execute(&compliant);
    let o = vehsim_spec::run::execute(&base);
    let peak = |rows: &[vehsim_core::sim::observer::Row]| {
        rows.iter().map(|r| r.obs.kin.yaw_rate_radps.abs()).fold(0.0, f64::max)
    };
    assert!(peak(&c.rows) < 0.98 * peak(&o.rows), "{} vs {}", peak(&c.rows), peak(&o.rows));
}

/// The engine's bicycle model and the discovery's replay model write the same lateral equations
/// (shared through `vehsim_core::vehicle::single_track` and `vehsim_core::vehicle::lateral`): for every
/// effect both have (steer compliance, steering lag, lateral relaxation, load transfer, friction
/// scale, thermal friction at a given contact temperature), alone and together, at fixed states
/// (vy, r, the relaxed axle forces, the lagged steer, the steer and vx; the bicycle's wheels free
/// rolling, omega = vx / R_e with relaxed slip ratios 0, so its tyres are at zero slip ratio as
/// the replay's), on a flat road and on two banked and graded ones (the road's gravity and axle
/// loads, `[road]` of a manoeuvre and of a run's sidecar), the two models' dvy/dt, dr/dt and
/// lag-state derivatives agree to 1e-12 relative (to the larger of the two, floored at 1e-3 of
/// that derivative's largest magnitude over the cases: a yaw acceleration of 5e-5 rad/s^2 that is
/// the difference of axle moments of 1 rad/s^2 differs by a last-bit round-off of the axle forces
/// on a banked road, 2.7e-12 of itself). Tyres: every provider on the shipped sedan, and a Magic Formula tyre edited to have
/// a longitudinal force at zero slip (PHX1, PVX1) and an aligning moment, so that the
/// Fx_f sin(delta) and Mz terms are exercised too.
#[test]
fn engine_and_replay_lateral_derivatives_agree_to_round_off() {
    use vehsim::discover::model::{EffectParams, ReplayModel};
    use vehsim_core::tyre::TyreInput;
    use vehsim_core::tyre::TyreModelKind;
    use vehsim_core::vehicle::bicycle::{ix, Bicycle};
    use vehsim_core::vehicle::{Environment, Inputs, VehicleModel};
    use vehsim_core::vehicle::{Lateral, Vehicle};
    use vehsim_spec::VehicleFile;

    // The sedan with an edited copy of its tyre: longitudinal shifts and the aligning moment on.
    let case = common::Case::new("engine-replay-derivatives", "unused.toml", "");
    let tir = common::root().join("vehicles/tyres/srtt_p225_60r16.tir");
    let text = std::fs::read_to_string(&tir).unwrap();
    let mut edited = 0;
    let mut text_out = String::new();
    for line in text.lines() {
        let line = match line.split_whitespace().next() {
            // A horizontal shift of Fx (slip ratio) and a vertical one (fraction of Fz).
            Some("PHX1") => "PHX1 = 0.004",
            Some("PVX1") => "PVX1 = 0.02",
            _ => line,
        };
        edited += usize::from(line.starts_with("PHX1 =") || line.starts_with("PVX1 ="));
        text_out.push_str(line);
        text_out.push('\n');
    }
    let text = text_out;
    assert_eq!(edited, 2, "the .tir must have PHX1 and PVX1");
    std::fs::write(case.dir.join("tyres/srtt_p225_60r16.tir"), text).unwrap();
    case.edit("tyres/srtt_p225_60r16.toml", "aligning_moment = false", "aligning_moment = true");
    let build =
        |path: &std::path::Path, kind: TyreModelKind| VehicleFile::load(path).unwrap().build(path, kind).unwrap();
    let shifted = build(&case.dir.join("sedan.toml"), TyreModelKind::Pacejka);
    let zero_slip = shifted.tyre.model.forces(&TyreInput::new(4000.0, 0.0, 0.05, 0.15));
    assert!(zero_slip.fx_n.abs() > 10.0 && zero_slip.mz_nm.abs() > 1.0, "{zero_slip:?}");
    let sedan = common::root().join("vehicles/sedan.toml");
    let mut vehicles: Vec<(String, Vehicle)> = vec![("pacejka with Fx(0) and Mz".into(), shifted)];
    for kind in ["pacejka", "linear", "polynomial", "dugoff", "dugoff_thermal", "atiim_pacejka"] {
        vehicles.push((kind.into(), build(&sedan, TyreModelKind::parse(kind).unwrap())));
    }

    let none = Lateral::default();
    let slip = Lateral { slip_relaxation_m: [0.8, 1.4], ..none };
    let effects: [(&str, Lateral); 17] = [
        ("none", none),
        ("steer compliance", Lateral { steer_compliance_rad_per_kn: 0.004, ..none }),
        ("steering lag", Lateral { steer_lag_s: 0.12, ..none }),
        ("lateral relaxation", Lateral { relaxation_length_y_m: 1.2, ..none }),
        (
            "relaxation and compliance",
            Lateral { relaxation_length_y_m: 1.2, steer_compliance_rad_per_kn: 0.004, ..none },
        ),
        ("load transfer", Lateral { load_transfer_height_m: 0.6, ..none }),
        ("friction scale", Lateral { mu_scale: 0.7, ..none }),
        ("thermal friction", Lateral { thermal_mu_per_k: -0.05, ..none }),
        ("per-axle stiffness", Lateral { stiffness_scale: [0.8, 1.3], ..none }),
        ("per-axle friction", Lateral { mu_axle_scale: [0.9, 0.7], ..none }),
        ("load sensitivities", Lateral { load_transfer_height_m: 0.6, load_sensitivity: [0.3, 0.2], ..none }),
        ("transient slip", slip),
        ("transient slip, saturating", Lateral { slip_relaxation_saturating: true, ..slip }),
        (
            "transient slip, compliance and load transfer",
            Lateral { steer_compliance_rad_per_kn: 0.004, load_transfer_height_m: 0.5, ..slip },
        ),
        (
            "all",
            Lateral {
                steer_compliance_rad_per_kn: 0.006,
                mu_scale: 0.8,
                steer_lag_s: 0.08,
                relaxation_length_y_m: 0.7,
                load_transfer_height_m: 0.5,
                thermal_mu_per_k: -0.03,
                stiffness_scale: [1.2, 0.9],
                mu_axle_scale: [0.95, 1.1],
                load_sensitivity: [0.2, -0.1],
                ..none
            },
        ),
        (
            "all with saturating transient slip",
            Lateral {
                steer_compliance_rad_per_kn: 0.006,
                mu_scale: 0.8,
                steer_lag_s: 0.08,
                load_transfer_height_m: 0.5,
                thermal_mu_per_k: -0.03,
                stiffness_scale: [1.2, 0.9],
                mu_axle_scale: [0.95, 1.1],
                load_sensitivity: [0.2, -0.1],
                slip_relaxation_m: [0.6, 1.1],
                slip_relaxation_saturating: true,
                ..none
            },
        ),
        (
            "stiffness and friction with load transfer",
            Lateral { stiffness_scale: [0.7, 1.0], mu_axle_scale: [1.0, 0.8], load_transfer_height_m: 0.6, ..none },
        ),
    ];
    // (vx, vy, r, Fy_f, Fy_r, lagged steer, steer): a mild state, a skid, a reversed turn and a
    // fast turn whose load transfer lifts the inner tyres on a dry road.
    let states: [[f64; 7]; 4] = [
        [10.0, 0.3, 0.25, 1500.0, -800.0, 0.04, 0.06],
        [6.0, -0.9, 0.6, -2500.0, 1200.0, -0.02, 0.15],
        [15.0, 0.4, -0.3, 600.0, -2000.0, -0.05, -0.03],
        [20.0, -0.5, 0.9, 6000.0, 4000.0, 0.05, 0.05],
    ];
    let (ice_c, contact_c) = (-3.0, [-1.2, -2.1]);
    let mut worst = 0.0_f64;
    let mut pairs: Vec<(usize, f64, f64, String)> = Vec::new();
    for (tyre, vehicle) in &vehicles {
        for (name, lat) in &effects {
            let mut v = vehicle.clone();
            v.lateral = *lat;
            let p = EffectParams::of_vehicle(&v);
            let bicycle = Bicycle::new(v.clone());
            let replay = ReplayModel::new(v);
            // Flat, a left-high downhill road and a right-high uphill one.
            let roads = [Road::FLAT, Road::from_deg(6.0, -5.0), Road::from_deg(-20.0, 4.0)];
            for (mu, road) in [0.15, 1.0].into_iter().flat_map(|mu| roads.map(|r| (mu, r))) {
                let env = Environment {
                    mu,
                    surface_temp_c: ice_c,
                    regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
                    road,
                };
                for [vx, vy, r, fyf, fyr, delta_l, steer] in states {
                    // Under transient slip the relaxed-force slots hold lagged slip angles, rad.
                    let (fyf, fyr) = if lat.transient_slip() { (fyf * 1e-5, fyr * 1e-5) } else { (fyf, fyr) };
                    let mut x = bicycle.initial_state(0.0, 0.0, 0.3, vx);
                    (x[ix::VY], x[ix::R], x[ix::FY_F], x[ix::FY_R], x[ix::DELTA_L]) = (vy, r, fyf, fyr, delta_l);
                    assert_eq!((x[ix::KAPPA_F], x[ix::KAPPA_R]), (0.0, 0.0));
                    let u = Inputs {
                        steer_rad: steer,
                        contact_temp_c: [contact_c[0], contact_c[1], contact_c[0], contact_c[1]],
                        ..Inputs::default()
                    };
                    let db = bicycle.derivatives(&x, &u, &env);
                    let db = [db[ix::VY], db[ix::R], db[ix::FY_F], db[ix::FY_R], db[ix::DELTA_L]];
                    let dr = replay.lateral_derivatives(
                        &p,
                        [vy, r, fyf, fyr, delta_l],
                        steer,
                        vx,
                        (mu, road),
                        (ice_c, contact_c),
                    );
                    for (k, (b, e)) in db.iter().zip(&dr).enumerate() {
                        let at = format!(
                            "{tyre}, {name}, mu {mu}, {road:?}, state {:?}",
                            [vx, vy, r, fyf, fyr, delta_l, steer]
                        );
                        pairs.push((k, *b, *e, at));
                    }
                }
            }
        }
    }
    // Each derivative's scale: its largest magnitude over the cases. A value far below it is a
    // difference of terms of that scale (dr/dt = (a F_yf - b F_yr) / I_z near balance), whose
    // round-off is relative to the terms: the comparison is relative to the larger of the two
    // values, floored at 1e-3 of the scale.
    let mut scale = [0.0_f64; 5];
    for (k, b, e, _) in &pairs {
        scale[*k] = scale[*k].max(b.abs()).max(e.abs());
    }
    for (k, b, e, at) in &pairs {
        let rel = (b - e).abs() / b.abs().max(e.abs()).max(1e-3 * scale[*k]).max(f64::MIN_POSITIVE);
        worst = worst.max(rel);
        assert!(
            rel <= 1e-12,
            "{at}: derivative {k} (vy, r, Fy_f, Fy_r, delta_l) bicycle {b:e}, replay {e:e}, relative {rel:.1e}"
        );
    }
    eprintln!("largest relative difference bicycle vs replay: {worst:.2e}");
}
