//! `vehsim envelope`: bad input exits 2 with the file and key, writing nothing; a real ISO 3888-2
//! envelope brackets the limit (the run at the reported speed passes, the one at the bracket's
//! upper end fails, within the tolerance) and is byte-identical with 1 and 2 threads; the
//! constant-radius envelope reports the highest steady a_y of the run.

mod common;

use common::Case;

/// A scratch case whose tyre folder also holds the `.tir` file the Pacejka section names.
fn case(tag: &str, name: &str, spec: &str) -> Case {
    let c = Case::new(tag, name, spec);
    let tir = "vehicles/tyres/srtt_p225_60r16.tir";
    std::fs::copy(common::root().join(tir), c.dir.join("tyres/srtt_p225_60r16.tir")).unwrap();
    c
}

const DLC: &str = r#"name = "env"
vehicle = "sedan.toml"
tyre_model = "pacejka"

[surface]
mu = 0.15

[maneuver]
kind = "iso3888_2"
speed_mps = 7.0
speed_mode = "coast"

[integrator]
method = "rk4"
step_s = 0.002

[envelope]
speed_min_mps = 5.0
speed_max_mps = 12.0
scan_step_mps = 1.0
tolerance_mps = 0.1

[sweep]
"surface.mu" = [0.15, 0.3]
"#;

#[test]
fn bad_input_exits_2_naming_the_file_and_key() {
    let cases: [(&str, &str, &str); 8] = [
        ("speed_min_mps = 5.0", "speed_min_mps = 0.0", "envelope.speed_min_mps"),
        ("speed_min_mps = 5.0", "speed_min_mps = -1.0", "envelope.speed_min_mps"),
        ("speed_max_mps = 12.0", "speed_max_mps = 4.0", "envelope.speed_max_mps"),
        ("tolerance_mps = 0.1", "tolerance_mps = 0.0", "envelope.tolerance_mps"),
        ("tolerance_mps = 0.1", "tolerance_mps = -0.05", "envelope.tolerance_mps"),
        ("speed_max_mps = 12.0\n", "", "envelope.speed_max_mps"),
        ("tolerance_mps = 0.1", "tolerance_mps = 0.1\nbisect = 3", "bisect"),
        ("\"surface.mu\" = [0.15, 0.3]", "\"maneuver.speed_mps\" = [5.0, 6.0]", "sweep.maneuver.speed_mps"),
    ];
    for (i, (from, to, key)) in cases.iter().enumerate() {
        let c = case(&format!("env-bad-{i}"), "env.toml", DLC);
        c.edit("env.toml", from, to);
        let (code, out, err) = c.run(&["envelope", "env.toml"]);
        assert_eq!(code, 2, "{to}: {out}{err}");
        assert!(err.contains("env.toml") && err.contains(key), "{to}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{to}: not one message: {err}");
        assert!(!c.results().exists(), "{to}: results written");
    }
    // A manoeuvre with neither a pass rule nor a steady-state measure.
    let open_loop = "name = \"ol\"\nvehicle = \"sedan.toml\"\n[maneuver]\nkind = \"sine_steer\"\nspeed_mps = 10.0\n\
                     amplitude_deg = 2.0\nfrequency_hz = 0.5\n";
    let c = Case::new("env-bad-kind", "ol.toml", open_loop);
    let (code, _, err) = c.run(&["envelope", "ol.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("ol.toml") && err.contains("maneuver.kind") && err.contains("iso3888_2"), "{err}");
}

#[test]
fn speed_envelope_brackets_the_limit_and_is_deterministic() {
    let c = case("env-dlc", "env.toml", DLC);
    let (code, out, err) = c.run(&["envelope", "env.toml", "--jobs", "1", "--out", "one"]);
    assert_eq!(code, 0, "{out}{err}");
    let (code, out, err) = c.run(&["envelope", "env.toml", "--jobs", "2", "--out", "two"]);
    assert_eq!(code, 0, "{out}{err}");
    let one = std::fs::read(c.dir.join("one/env/envelope.csv")).unwrap();
    assert_eq!(one, std::fs::read(c.dir.join("two/env/envelope.csv")).unwrap());
    assert!(c.dir.join("one/env/plots/envelope.png").exists() && c.dir.join("one/env/plots/envelope.svg").exists());

    let env = vehsim::envelope::load(&c.dir.join("env.toml")).unwrap();
    let rows = vehsim::envelope::execute(&env, Some(2)).unwrap();
    assert_eq!(String::from_utf8(one).unwrap(), vehsim::envelope::csv(&env, &rows));
    // Check each bracket with independent runs at its two ends.
    let cfg_at = |mu: &str, v: f64| {
        let text = std::fs::read_to_string(c.dir.join("env.toml")).unwrap();
        let text = text.split("[envelope]").next().unwrap().to_string();
        let text =
            text.replace("mu = 0.15", &format!("mu = {mu}")).replace("speed_mps = 7.0", &format!("speed_mps = {v:?}"));
        let p = c.dir.join("check.toml");
        std::fs::write(&p, text).unwrap();
        vehsim_spec::run::load(&p).unwrap()
    };
    let mut limits = Vec::new();
    for r in &rows {
        let l = &r.limit;
        let pass = |v| {
            let s = vehsim_spec::run::execute(&cfg_at(&r.params[0], v)).summary;
            s.passed == Some(true) && s.end_reason == vehsim_core::event::EndReason::Completed
        };
        let (v, hi) = (l.value.expect("a passing speed"), l.fail_above.expect("a failing speed"));
        assert!(hi > v && hi - v <= 0.1 + 1e-12 && (5.0..=12.0).contains(&v), "{l:?}");
        assert!(pass(v) && !pass(hi), "{:?}: {l:?}", r.params);
        // A failure below the limit (mu 0.3: at 5 m/s the rear corner clips lane 1's last cone
        // as the path turns) is reported as non-monotone, and is one.
        if let Some(fb) = l.fail_below {
            assert!(fb < v && !pass(fb) && l.note.contains("non-monotone"), "{l:?}");
        } else {
            assert!(l.note.is_empty(), "{l:?}");
        }
        limits.push(v);
    }
    // More friction, a higher passing speed.
    assert!(limits[1] > limits[0], "{limits:?}");
}

#[test]
fn constant_radius_envelope_is_the_highest_steady_lateral_acceleration() {
    let spec = r#"name = "cr_env"
vehicle = "sedan.toml"
tyre_model = "pacejka"
[surface]
mu = 0.15
[maneuver]
kind = "constant_radius"
radius_m = 20.0
direction = "left"
speed_mode = "steps"
ay_first_mps2 = 0.5
ay_step_mps2 = 0.5
ay_max_mps2 = 3.0
settle_s = 10.0
window_s = 2.0
speed_ramp_mps2 = 0.3
[driver]
preview_time_s = 0.5
"#;
    let c = case("env-cr", "cr.toml", spec);
    let (code, out, err) = c.run(&["envelope", "cr.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let csv = std::fs::read_to_string(c.results().join("cr_env/envelope.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "reference,highest_steady_ay_mps2,next_step_nominal_ay_mps2,unsteady_step_below_nominal_ay_mps2,runs,plausible,note"
    );
    let f: Vec<&str> = lines.next().unwrap().split(',').collect();
    // The same run through `vehsim run`: the envelope is its highest steady a_y, and the bracket's
    // upper end is the nominal a_y of the first step that was not steady.
    let out = vehsim_spec::run::execute(&vehsim_spec::run::load(&c.dir.join("cr.toml")).unwrap());
    let best = out.steady_states.iter().filter(|s| s.steady).map(|s| s.ay_mps2.abs()).fold(f64::NAN, f64::max);
    assert_eq!(f[1].parse::<f64>().unwrap(), best);
    let next = out.steady_states.iter().find(|s| !s.steady).map(|s| s.nominal_ay_mps2);
    let next = next.unwrap_or_else(|| (out.steady_states.len() + 1) as f64 * 0.5);
    assert!((f[2].parse::<f64>().unwrap() - next).abs() < 1e-9, "{csv}");
    // mu 0.15: no steady a_y above the friction the tyre realises, and not every step was steady.
    assert!(best > 0.9 && best < 0.19 * 9.81, "{best}");
    assert_eq!(f[4], "1");
    // The run ends by leaving the circle, yet no tyre force passed its bound: plausible.
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::LeftPath);
    assert_eq!(f[5], "true");
}
