//! The command line with the 4-DOF model and the constant-radius manoeuvre: bad input in the
//! `[roll]` section or the `[maneuver]` table gives one message naming the file and the key, exit
//! code 2 and no results; a good run writes the steady-state outputs.

mod common;

const SPEC: &str = r#"name = "cr"
vehicle = "sedan.toml"
tyre_model = "linear"
vehicle_model = "roll4dof"

[surface]
mu = 0.15

[maneuver]
kind = "constant_radius"
radius_m = 40.0
direction = "right"
speed_mode = "steps"
ay_first_mps2 = 0.25
ay_step_mps2 = 0.25
ay_max_mps2 = 0.75
settle_s = 6.0
window_s = 1.0
"#;

use common::Case;

/// A scratch folder with the sedan, its tyre and the constant-radius spec as `cr.toml`.
fn cr_case(tag: &str) -> Case {
    Case::new(tag, "cr.toml", SPEC)
}

/// Each edit must give exit 2 with one message naming the file and the key, saying what is
/// allowed, and write nothing (also through `validate`).
#[test]
fn bad_roll_and_radius_input_is_rejected_with_file_and_key() {
    let cases: &[(&str, &str, &str, &str)] = &[
        (
            "sedan.toml",
            "roll_stiffness_front_nm_per_rad = 46000.0",
            "roll_stiffness_front_nm_per_rad = 0.0",
            "roll.roll_stiffness_front_nm_per_rad",
        ),
        (
            "sedan.toml",
            "roll_stiffness_rear_nm_per_rad = 30800.0",
            "roll_stiffness_rear_nm_per_rad = -100.0",
            "roll.roll_stiffness_rear_nm_per_rad",
        ),
        (
            "sedan.toml",
            "roll_centre_height_front_m = 0.08",
            "roll_centre_height_front_m = 0.9",
            "roll.roll_centre_height_front_m",
        ),
        (
            "sedan.toml",
            "roll_centre_height_rear_m = 0.12",
            "roll_centre_height_rear_m = 0.6",
            "roll.roll_centre_height_rear_m",
        ),
        ("sedan.toml", "roll_inertia_kgm2 = 480.0", "roll_inertia_kgm2 = nan", "roll.roll_inertia_kgm2"),
        (
            "sedan.toml",
            "unsprung_mass_front_kg = 90.0",
            "unsprung_mass_front_kg = 1000.0",
            "roll.unsprung_mass_rear_kg",
        ),
        ("sedan.toml", "ackermann = 0.5", "ackermann = 1.5", "roll.ackermann"),
        ("cr.toml", "radius_m = 40.0", "radius_m = 0.0", "maneuver.radius_m"),
        ("cr.toml", "radius_m = 40.0", "radius_m = -40.0", "maneuver.radius_m"),
        ("cr.toml", "ay_step_mps2 = 0.25", "ay_step_mps2 = 0.8", "maneuver.ay_step_mps2"),
        ("cr.toml", "ay_max_mps2 = 0.75", "ay_max_mps2 = 0.1", "maneuver.ay_max_mps2"),
        ("cr.toml", "window_s = 1.0", "window_s = 0.0", "maneuver.window_s"),
    ];
    for (i, (file, from, to, key)) in cases.iter().enumerate() {
        let c = cr_case(&format!("roll-bad{i}"));
        c.edit(file, from, to);
        let (code, _, err) = c.run(&["run", "cr.toml"]);
        assert_eq!(code, 2, "{to}: {err}");
        assert!(err.contains(file) && err.contains(key), "{to}: {err}");
        assert!(err.contains("expected"), "{to}: message does not say what is allowed: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{to}: not one message: {err}");
        assert!(!c.dir.join("results").exists(), "{to}: results written");
        let (vcode, _, _) = c.run(&["validate", "cr.toml"]);
        assert_eq!(vcode, 2, "{to}: validate");
    }
}

/// Other bad input: the 4-DOF model on a vehicle without `[roll]`, an unknown model, a misspelt
/// `[roll]` key, a hold-mode key in steps mode, a bad direction.
#[test]
fn missing_roll_section_and_misspelt_keys_are_rejected() {
    let c = cr_case("roll-missing");
    let text = std::fs::read_to_string(c.dir.join("sedan.toml")).unwrap();
    let cut = text.find("\n[roll]").unwrap();
    std::fs::write(c.dir.join("sedan.toml"), &text[..cut]).unwrap();
    let (code, _, err) = c.run(&["run", "cr.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cr.toml") && err.contains("vehicle_model") && err.contains("[roll]"), "{err}");
    assert!(err.contains("sedan.toml"), "the message must name the vehicle file: {err}");
    assert!(!c.dir.join("results").exists());
    // The bicycle still runs on that vehicle.
    c.edit("cr.toml", "vehicle_model = \"roll4dof\"", "vehicle_model = \"bicycle\"");
    let (code, _, err) = c.run(&["validate", "cr.toml"]);
    assert_eq!(code, 0, "{err}");

    let edits: &[(&str, &str, &str, &str)] = &[
        ("cr.toml", "vehicle_model = \"roll4dof\"", "vehicle_model = \"unicycle\"", "vehicle_model"),
        ("sedan.toml", "ackermann = 0.5", "ackerman = 0.5", "ackerman"),
        ("cr.toml", "ay_max_mps2 = 0.75", "ay_max_mps2 = 0.75\nspeed_mps = 8.0", "maneuver.speed_mps"),
        ("cr.toml", "direction = \"right\"", "direction = \"up\"", "direction"),
    ];
    for (i, (file, from, to, key)) in edits.iter().enumerate() {
        let c = cr_case(&format!("roll-key{i}"));
        c.edit(file, from, to);
        let (code, _, err) = c.run(&["run", "cr.toml"]);
        assert_eq!(code, 2, "{to}: {err}");
        assert!(err.contains(file) && err.contains(key), "{to}: {err}");
        assert!(!c.dir.join("results").exists(), "{to}: results written");
    }
}

/// A stepped right-hand constant-radius run writes timeseries.csv with the roll and per-wheel load
/// columns, steady_states.csv with one row per step, and summary.json with the steady states and
/// the understeer gradient with its confidence interval.
#[test]
fn constant_radius_run_writes_steady_state_outputs() {
    let c = cr_case("roll-good");
    let (code, out, err) = c.run(&["run", "cr.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let dir = c.dir.join("results/cr");
    let csv = std::fs::read_to_string(dir.join("timeseries.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for col in ["roll_rad", "fz_fl_n", "fz_fr_n", "fz_rl_n", "fz_rr_n"] {
        assert!(header.contains(&col), "missing column {col}");
    }
    let ss = std::fs::read_to_string(dir.join("steady_states.csv")).unwrap();
    assert_eq!(ss.lines().count(), 4, "{ss}");
    for col in ["steer_rad", "yaw_rate_radps", "sideslip_rad", "roll_rad", "fz_fl_n", "fz_rr_n", "ay_mps2"] {
        assert!(ss.lines().next().unwrap().split(',').any(|h| h == col), "steady_states.csv lacks {col}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["vehicle_model"], "roll4dof");
    assert_eq!(json["steady_states"].as_array().unwrap().len(), 3);
    let g = &json["understeer_gradient"];
    let k = g["rad_per_mps2"].as_f64().unwrap();
    let ci = g["ci95_rad_per_mps2"].as_array().unwrap();
    assert!(ci[0].as_f64().unwrap() < k && k < ci[1].as_f64().unwrap(), "{g}");
    // Right turn: negative lateral acceleration, negative roll, outer (left) wheels loaded.
    let s0 = &json["steady_states"][0];
    assert!(s0["ay_mps2"].as_f64().unwrap() < 0.0 && s0["roll_rad"].as_f64().unwrap() < 0.0);
    assert!(s0["fz_fl_n"].as_f64().unwrap() > s0["fz_fr_n"].as_f64().unwrap());
}
