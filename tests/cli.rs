//! The command line: exit codes, messages for bad input, and the files a run writes.

mod common;

use std::path::Path;

use common::Case;

/// A scratch folder with the sedan and the shipped ice DLC spec as `dlc.toml`.
fn dlc_case(tag: &str) -> Case {
    let spec = std::fs::read_to_string(common::root().join("maneuvers/dlc.toml"))
        .unwrap()
        .replace("../vehicles/sedan.toml", "sedan.toml");
    Case::new(tag, "dlc.toml", &spec)
}

/// Expect exit 2, a one-line message naming `file` and containing every piece of `needles`,
/// and no results folder.
fn expect_bad_input(case: &Case, file: &str, needles: &[&str]) {
    let (code, _out, err) = case.run(&["run", "dlc.toml"]);
    assert_eq!(code, 2, "stderr: {err}");
    assert!(err.contains(file), "message does not name {file}: {err}");
    for n in needles {
        assert!(err.contains(n), "message lacks '{n}': {err}");
    }
    assert!(!case.results().exists(), "results/ was written despite bad input");
    let (vcode, _, verr) = case.run(&["validate", "dlc.toml"]);
    assert_eq!(vcode, 2, "validate: {verr}");
}

#[test]
fn missing_file_is_bad_input() {
    let c = dlc_case("missing");
    let (code, _, err) = c.run(&["run", "nope.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("nope.toml") && err.contains("not found"), "{err}");
    assert!(!c.results().exists());
}

#[test]
fn malformed_toml_names_the_line() {
    let c = dlc_case("malformed");
    c.edit("dlc.toml", "name = \"dlc_ice\"", "name = \"dlc_ice");
    expect_bad_input(&c, "dlc.toml", &["line"]);
}

#[test]
fn unknown_key_is_rejected_with_its_name() {
    let c = dlc_case("unknown");
    c.edit("sedan.toml", "mass_kg = 1600.0", "mass_kg = 1600.0\ncolour = \"red\"");
    expect_bad_input(&c, "sedan.toml", &["colour"]);
}

#[test]
fn unknown_key_inside_the_maneuver_table_is_rejected() {
    let c = dlc_case("unknown-man");
    c.edit("dlc.toml", "speed_mps = 10.0", "speed_mps = 10.0\nspeeed_mode = \"hold\"");
    expect_bad_input(&c, "dlc.toml", &["speeed_mode"]);
}

#[test]
fn wrong_type_names_the_key() {
    let c = dlc_case("wrongtype");
    c.edit("dlc.toml", "speed_mps = 10.0", "speed_mps = \"fast\"");
    expect_bad_input(&c, "dlc.toml", &["speed_mps"]);
    let c = dlc_case("wrongtype2");
    c.edit("sedan.toml", "mass_kg = 1600.0", "mass_kg = \"heavy\"");
    expect_bad_input(&c, "sedan.toml", &["mass_kg"]);
}

#[test]
fn non_physical_values_name_key_and_allowed_range() {
    let cases: &[(&str, &str, &str, &str)] = &[
        ("sedan.toml", "mass_kg = 1600.0", "mass_kg = -5.0", "mass_kg"),
        ("sedan.toml", "mass_kg = 1600.0", "mass_kg = 0.0", "mass_kg"),
        ("sedan.toml", "cg_to_front_axle_m = 1.09", "cg_to_front_axle_m = 0.0", "cg_to_front_axle_m"),
        ("sedan.toml", "cg_to_rear_axle_m = 1.71", "cg_to_rear_axle_m = -1.0", "cg_to_rear_axle_m"),
        ("dlc.toml", "method = \"rk4\"", "method = \"rk4\"\nstep_s = 0.0", "step_s"),
        ("dlc.toml", "method = \"rk4\"", "method = \"rk4\"\nstep_s = -0.001", "step_s"),
        ("dlc.toml", "method = \"rk4\"", "method = \"rk4\"\nstep_s = 0.03", "step_s"),
        (
            "dlc.toml",
            "method = \"rk4\"",
            "method = \"rk4\"\nstep_s = 0.004\ncontrol_period_s = 0.01",
            "control_period_s",
        ),
        ("dlc.toml", "method = \"rk4\"", "method = \"rk4\"\ncontrol_period_s = 0.0", "control_period_s"),
        ("dlc.toml", "mu = 0.15", "mu = 0.0", "mu"),
        ("dlc.toml", "mu = 0.15", "mu = -0.2", "mu"),
        ("dlc.toml", "mu = 0.15", "mu = nan", "mu"),
        ("sedan.toml", "mass_kg = 1600.0", "mass_kg = nan", "mass_kg"),
        ("dlc.toml", "speed_mps = 10.0", "speed_mps = inf", "speed_mps"),
        (
            "tyres/srtt_p225_60r16.toml",
            "cornering_stiffness_n_per_rad = 69000.0",
            "cornering_stiffness_n_per_rad = nan",
            "cornering_stiffness_n_per_rad",
        ),
    ];
    for (i, (file, from, to, key)) in cases.iter().enumerate() {
        let c = dlc_case(&format!("nonphys{i}"));
        c.edit(file, from, to);
        let (code, _, err) = c.run(&["run", "dlc.toml"]);
        assert_eq!(code, 2, "{to}: {err}");
        let name = Path::new(file).file_name().unwrap().to_str().unwrap();
        assert!(err.contains(name) && err.contains(key), "{to}: {err}");
        assert!(err.contains("expected"), "{to}: message does not say what is allowed: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{to}: not one message: {err}");
        assert!(!c.results().exists(), "{to}: results written");
    }
}

#[test]
fn unknown_tyre_model_lists_the_allowed_ones() {
    let c = dlc_case("tyremodel");
    c.edit("dlc.toml", "tyre_model = \"linear\"", "tyre_model = \"magic\"");
    expect_bad_input(&c, "dlc.toml", &["tyre_model", "magic", "linear"]);
}

#[test]
fn one_bad_spec_stops_the_whole_call_before_anything_runs() {
    let c = dlc_case("onebad");
    std::fs::write(c.dir.join("bad.toml"), "name = 3\n").unwrap();
    let (code, _, err) = c.run(&["run", "dlc.toml", "bad.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(!c.results().exists());
}

#[test]
fn a_run_writes_the_documented_files_and_columns() {
    let c = dlc_case("good");
    let (code, out, err) = c.run(&["run", "dlc.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let dir = c.results().join("dlc_ice");
    let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for col in [
        "t_s",
        "x_m",
        "y_m",
        "yaw_rad",
        "vx_mps",
        "vy_mps",
        "yaw_rate_radps",
        "sideslip_rad",
        "ay_mps2",
        "steer_rad",
        "alpha_front_rad",
        "alpha_rear_rad",
        "kappa_front",
        "kappa_rear",
        "fx_front_n",
        "fy_front_n",
        "fx_rear_n",
        "fy_rear_n",
        "drive_torque_nm",
        "speed_target_mps",
    ] {
        assert!(header.contains(&col), "missing column {col}");
    }
    assert!(csv.lines().count() > 1000);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    for key in [
        "passed",
        "cones_hit",
        "peak_yaw_rate_radps",
        "peak_sideslip_rad",
        "peak_ay_mps2",
        "max_path_deviation_m",
        "min_speed_mps",
        "max_speed_mps",
        "steps",
        "events",
    ] {
        assert!(json.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(json["passed"], serde_json::Value::Bool(true));
    // Nothing temporary is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(c.results())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn help_is_available_on_every_subcommand() {
    let c = dlc_case("help");
    for args in [&["--help"][..], &["run", "--help"], &["validate", "--help"], &["bench", "--help"]] {
        let (code, out, _) = c.run(args);
        assert_eq!(code, 0);
        assert!(out.contains("Usage"), "{args:?}: {out}");
    }
    let (code, _, _) = c.run(&["frobnicate"]);
    assert_eq!(code, 2);
}
