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
