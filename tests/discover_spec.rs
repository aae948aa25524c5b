//! The improved vehicle spec written by `vehsim discover` runs with `vehsim run`, and the
//! engine's `[lateral]` extensions behave as their equations say.

mod common;

use std::process::Command;

use common::BIN;

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
    let vf = vehsim::spec::vehicle::VehicleFile::load(&out.join("vehicle.toml")).unwrap();
    let v = vf.build(&out.join("vehicle.toml"), vehsim::tyre::spec::TyreModelKind::Pacejka).unwrap();
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
    let a = vehsim::run::execute(&scaled);
    let b = vehsim::run::execute(&lowered);
    assert_eq!(a.rows.len(), b.rows.len());
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        assert!((ra.obs.kin.yaw_rate_radps - rb.obs.kin.yaw_rate_radps).abs() < 1e-9);
    }
    let mut compliant = base.clone();
    compliant.vehicle.lateral.steer_compliance_rad_per_kn = 0.01;
    let c = vehsim::run::execute(&compliant);
    let o = vehsim::run::execute(&base);
    let peak =
        |rows: &[vehsim::sim::observer::Row]| rows.iter().map(|r| r.obs.kin.yaw_rate_radps.abs()).fold(0.0, f64::max);
    assert!(peak(&c.rows) < 0.98 * peak(&o.rows), "{} vs {}", peak(&c.rows), peak(&o.rows));
}

/// Every vehicle effect that `vehsim discover` can write into `[lateral]` is the same extension
/// in the engine's bicycle model and in the discovery's replay model: an engine run with the
/// effect on is reproduced by the replay with the same parameter much better than by the replay
/// without it (the remaining gap is the engine's longitudinal dynamics and PID speed control,
/// which the replay does not have).
#[test]
fn engine_and_replay_run_the_same_effect_extensions() {
    use vehsim::discover::model::{EffectParams, ReplayModel};
    use vehsim::discover::Effect;
    let dir = common::temp_dir("discover-engine-replay");
    let sedan = common::root().join("vehicles/sedan.toml");
    // Each effect on a surface where it shows: load transfer needs a dry road's lateral
    // acceleration, the others act on ice (mu 0.15, 10 m/s) as well.
    let spec = |mu: f64, speed: f64| {
        let text = format!(
            "name = \"cmp\"\nvehicle = {:?}\ntyre_model = \"pacejka\"\nduration_s = 8.0\n\
             [surface]\nmu = {mu}\ntemperature_c = -3.0\n[maneuver]\nkind = \"sine_steer\"\nspeed_mps = {speed}\n\
             steer_amplitude_deg = 2.5\nperiod_s = 3.0\n[output]\ninterval_s = 0.01\n",
            sedan.to_string_lossy()
        );
        let path = dir.join(format!("cmp_{mu}_{speed}.toml"));
        std::fs::write(&path, text).unwrap();
        vehsim::run::load(&path).unwrap()
    };
    let (ice, dry) = (spec(0.15, 10.0), spec(1.0, 20.0));
    let cases: [(Effect, f64); 6] = [
        (Effect::SteerCompliance, 0.004),
        (Effect::SteerLag, 0.12),
        (Effect::TyreRelaxation, 1.2),
        (Effect::LoadTransfer, 0.6),
        (Effect::FrictionChange, 0.7),
        (Effect::ThermalFriction, -0.6),
    ];
    for (e, value) in cases {
        let mut cfg = if e == Effect::LoadTransfer { dry.clone() } else { ice.clone() };
        let l = &mut cfg.vehicle.lateral;
        match e {
            Effect::SteerCompliance => l.steer_compliance_rad_per_kn = value,
            Effect::SteerLag => l.steer_lag_s = value,
            Effect::TyreRelaxation => l.relaxation_length_y_m = value,
            Effect::LoadTransfer => l.load_transfer_height_m = value,
            Effect::FrictionChange => l.mu_scale = value,
            _ => {
                l.thermal_mu_per_k = value;
                cfg.contact.model = "atiim".into();
            }
        }
        let run = vehsim::discover::synth::engine_run(&cfg, &cfg.spec_file).unwrap();
        let replay = ReplayModel::new(cfg.vehicle.clone());
        let mut p = EffectParams::default();
        e.apply(&mut p, &[value]);
        let rms = |sim: &[f64]| {
            (sim.iter().zip(&run.yaw_rate).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / sim.len() as f64).sqrt()
        };
        let with = rms(&replay.simulate(&run, &p).yaw_rate);
        let without = rms(&replay.simulate(&run, &EffectParams::default()).yaw_rate);
        eprintln!("{}: yaw-rate RMS engine vs replay {with:.2e} with the effect, {without:.2e} without", e.label());
        assert!(with < 0.2 * without, "{}: {with:.3e} with vs {without:.3e} without", e.label());
    }
}
