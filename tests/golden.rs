//! Golden trajectories: a small matrix of (manoeuvre x tyre model x vehicle model) runs compared
//! channel by channel with the files in tests/data/golden/, with the tolerances below.
//!
//! Re-bless after an intended change of the physics or numerics (then review the new files by eye,
//! e.g. `cargo run --release -- run SPEC` and look at results/<name>/plots/):
//!
//!     VEHSIM_BLESS=1 cargo test --release --test golden

mod common;

use std::collections::BTreeMap;
use std::path::PathBuf;

use vehsim::compare::compare;
use vehsim::output::table::Table;
use vehsim::run::timeseries_csv;
use vehsim_spec::run::execute;

/// Absolute tolerances per channel. They allow for last-bit differences of libm between machines
/// amplified through the closed loop, and are far below any physically meaningful change.
fn tolerances() -> BTreeMap<String, f64> {
    let mut t = BTreeMap::new();
    for (k, v) in [
        ("t_s", 1e-9),
        ("x_m", 1e-6),
        ("y_m", 1e-6),
        ("yaw_rad", 1e-7),
        ("vx_mps", 1e-6),
        ("vy_mps", 1e-6),
        ("yaw_rate_radps", 1e-7),
        ("sideslip_rad", 1e-7),
        ("ax_mps2", 1e-5),
        ("ay_mps2", 1e-5),
        ("steer_rad", 1e-7),
        ("alpha_front_rad", 1e-7),
        ("alpha_rear_rad", 1e-7),
        ("kappa_front", 1e-7),
        ("kappa_rear", 1e-7),
        ("omega_front_radps", 1e-5),
        ("omega_rear_radps", 1e-5),
        ("path_error_m", 1e-6),
    ] {
        t.insert(k.to_string(), v);
    }
    t
}

/// Default tolerance for forces (N), torques (N m), speeds and temperatures.
const DEFAULT_TOL: f64 = 1e-3;

fn golden_path(stem: &str) -> PathBuf {
    common::root().join("tests/data/golden").join(format!("{stem}.csv"))
}

fn simulate(spec: &str, tyre_model: &str, vehicle_model: &str, contact: &str) -> String {
    let path = common::root().join(spec);
    let mut file = vehsim_spec::ManeuverFile::load(&path).unwrap();
    file.tyre_model = tyre_model.to_string();
    file.vehicle_model = Some(vehicle_model.to_string());
    file.contact.model = contact.to_string();
    let mut cfg = file.build(&path).unwrap();
    cfg.settings.output_interval_s = 0.05;
    timeseries_csv(&execute(&cfg).rows)
}

#[test]
fn trajectories_match_the_golden_files() {
    let bless = std::env::var("VEHSIM_BLESS").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    for &(stem, spec, tyre, model, contact) in common::GOLDEN_CASES {
        let csv = simulate(spec, tyre, model, contact);
        let path = golden_path(stem);
        if bless {
            std::fs::write(&path, &csv).unwrap();
            eprintln!("blessed {}", path.display());
            continue;
        }
        let golden = match Table::read(&path) {
            Ok(t) => t,
            Err(e) => panic!("{e}\nbless the golden files with: VEHSIM_BLESS=1 cargo test --release --test golden"),
        };
        let now = Table::parse(&path, &csv).unwrap();
        let r = compare(&path, &golden, &path, &now, &tolerances(), DEFAULT_TOL).unwrap();
        assert!(r.only_in_one.is_empty(), "{stem}: channels added or removed: {:?} (re-bless)", r.only_in_one);
        if !r.within() {
            let w = r.worst().unwrap();
            failures.push(format!(
                "{stem}: {} off by {:.3e} at t = {} s (tolerance {:.1e})",
                w.channel, w.max_abs_error, w.at_t_s, w.tolerance
            ));
        }
    }
    assert!(failures.is_empty(), "golden trajectories differ:\n{}", failures.join("\n"));
}

/// The comparison is not vacuous: a yaw-rate change of 1e-5 rad/s in one row of a golden file is
/// detected.
#[test]
fn a_perturbed_trajectory_fails_the_golden_comparison() {
    if std::env::var("VEHSIM_BLESS").is_ok_and(|v| v == "1") {
        return; // the golden files are being rewritten by the other test
    }
    let (stem, ..) = common::GOLDEN_CASES[0];
    let path = golden_path(stem);
    let golden = Table::read(&path).expect("golden file (bless with VEHSIM_BLESS=1)");
    let mut perturbed = golden.clone();
    let c = perturbed.columns.iter().position(|c| c == "yaw_rate_radps").unwrap();
    let mid = perturbed.data[c].len() / 2;
    perturbed.data[c][mid] += 1e-5;
    let r = compare(&path, &golden, &path, &perturbed, &tolerances(), DEFAULT_TOL).unwrap();
    assert!(!r.within());
    assert_eq!(r.worst().unwrap().channel, "yaw_rate_radps");
}
