//! Bad measured runs: each gives one clear message naming the file and the row or column, exit
//! code 2, and nothing is written. A valid run with an extra column is read with a notice.

mod common;

use std::path::PathBuf;
use std::process::Command;

use vehsim::discover::measured::parse_run;

use common::BIN;

/// A valid 2 s run at 100 Hz (rows from line 2), with `edit` applied to the data lines.
fn csv(edit: impl Fn(usize, String) -> String) -> String {
    let mut s = String::from("t,steer,vx,yaw_rate,ay\n");
    for k in 0..201 {
        let t = k as f64 * 0.01;
        s.push_str(&edit(k, format!("{t},{},10,{},{}\n", 0.01 * t, 0.03 * t, 0.3 * t)));
    }
    s
}

fn discover_on(tag: &str, text: &str) -> (i32, String, PathBuf, PathBuf) {
    let dir = common::temp_dir(tag);
    let run = dir.join("run1.csv");
    std::fs::write(&run, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(BIN)
        .arg("discover")
        .arg("--vehicle")
        .arg(common::root().join("vehicles/sedan.toml"))
        .arg("--out")
        .arg(&out)
        .arg(&run)
        .output()
        .unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).to_string(), run, out)
}

fn expect_bad(tag: &str, text: &str, needles: &[&str]) {
    let (code, err, run, out) = discover_on(tag, text);
    assert_eq!(code, 2, "stderr: {err}");
    assert!(err.contains(&run.display().to_string()), "message does not name the file: {err}");
    for n in needles {
        assert!(err.contains(n), "message lacks '{n}': {err}");
    }
    assert_eq!(err.lines().count(), 1, "one message expected: {err}");
    assert!(!out.exists(), "nothing may be written on bad input");
}

#[test]
fn missing_required_column_is_named() {
    let text = csv(|_, l| l).replace("t,steer,vx,yaw_rate,ay", "t,steer,vx,yaw_rate,lat_acc");
    expect_bad("missing-col", &text, &["missing required column 'ay'"]);
}

#[test]
fn non_monotonic_time_names_the_line() {
    let text = csv(|k, l| if k == 50 { l.replacen("0.5,", "0.48,", 1) } else { l });
    expect_bad("time", &text, &["line 52", "column 't'", "strictly increasing"]);
}

#[test]
fn nan_sample_names_line_and_column() {
    let text = csv(|k, l| {
        if k == 10 {
            let mut f: Vec<&str> = l.trim_end().split(',').collect();
            f[3] = "NaN";
            f.join(",") + "\n"
        } else {
            l
        }
    });
    expect_bad("nan", &text, &["line 12", "column 'yaw_rate'", "NaN"]);
}

#[test]
fn run_shorter_than_a_second_is_rejected() {
    let text: String = csv(|k, l| if k <= 50 { l } else { String::new() });
    expect_bad("short", &text, &["0.500 s", "at least 1 s"]);
}

#[test]
fn steer_in_degrees_is_rejected() {
    let text = csv(|k, l| {
        if k == 100 {
            let mut f: Vec<String> = l.trim_end().split(',').map(String::from).collect();
            f[1] = "5.7".into();
            f.join(",") + "\n"
        } else {
            l
        }
    });
    expect_bad("steer", &text, &["line 102", "column 'steer'", "1.2 rad"]);
}

#[test]
fn a_pose_or_lateral_velocity_out_of_range_names_the_line_and_column() {
    // A heading of 1e6 rad (beyond any unwrapped heading) on line 42; the pose columns x, y, psi.
    let text = csv(|k, l| {
        let psi = if k == 40 { "1e6" } else { "0.1" };
        format!("{},{},{},{psi}\n", l.trim_end(), 0.1 * k as f64, 0.0)
    })
    .replace("ay\n", "ay,x,y,psi\n");
    expect_bad("pose", &text, &["line 42", "column 'psi'", "at most 1e5 rad"]);
    let text = csv(|k, l| format!("{},{},0,0\n", l.trim_end(), if k == 7 { "-3e8" } else { "1" }))
        .replace("ay\n", "ay,x,y,psi\n");
    expect_bad("pose-x", &text, &["line 9", "column 'x'", "at most 1e8 m"]);
    let text =
        csv(|k, l| format!("{},{}\n", l.trim_end(), if k == 3 { "250" } else { "0.1" })).replace("ay\n", "ay,vy\n");
    expect_bad("vy", &text, &["line 5", "column 'vy'", "at most 1e2 m/s"]);
}

#[test]
fn extra_column_is_ignored_with_a_notice_and_optional_columns_are_read() {
    let text = csv(|_, l| l.trim_end().to_string() + ",1,0.1\n").replace("ay\n", "ay,brake,vy\n");
    let r = parse_run(&PathBuf::from("/nonexistent/run.csv"), &text).unwrap();
    assert!(r.notices.iter().any(|n| n.contains("column 'brake' ignored")), "{:?}", r.notices);
    assert_eq!(r.channel("vy").unwrap()[0], 0.1);
    assert_eq!(r.t.len(), 201);
    assert_eq!(r.mu, 1.0);
}

#[test]
fn sidecar_sets_surface_and_rejects_unknown_keys() {
    let dir = common::temp_dir("sidecar");
    let p = dir.join("r.csv");
    std::fs::write(&p, csv(|_, l| l)).unwrap();
    std::fs::write(dir.join("r.toml"), "[surface]\nmu = 0.15\nice_temp_c = -8.0\n[initial]\nvx = 9.5\n").unwrap();
    let r = vehsim::discover::measured::read_run(&p).unwrap();
    assert_eq!((r.mu, r.ice_temp_c, r.initial_vx), (0.15, -8.0, 9.5));
    std::fs::write(dir.join("r.toml"), "[surface]\nfriction = 0.15\n").unwrap();
    let e = vehsim::discover::measured::read_run(&p).unwrap_err().to_string();
    assert!(e.contains("r.toml") && e.contains("friction"), "{e}");
    std::fs::write(dir.join("r.toml"), "[surface]\nmu = 15.0\n").unwrap();
    let e = vehsim::discover::measured::read_run(&p).unwrap_err().to_string();
    assert!(e.contains("surface.mu"), "{e}");
}

/// A run in degrees per second, degrees and g, said so in its header cells or in its sidecar's
/// `[units]`, reads as the SI run (to round-off).
#[test]
fn columns_in_other_units_are_converted_when_the_header_or_sidecar_says_so() {
    let si = parse_run(&PathBuf::from("/nonexistent/si.csv"), &csv(|_, l| l)).unwrap();
    let deg = std::f64::consts::PI / 180.0;
    let converted = |l: String| {
        let f: Vec<f64> = l.trim().split(',').map(|v| v.parse().unwrap()).collect();
        format!("{},{},{},{},{}\n", f[0], f[1] / deg, f[2] * 3.6, f[3] / deg, f[4] / 9.80665)
    };
    let dir = common::temp_dir("units");
    let header = csv(|_, l| converted(l)).replacen(
        "t,steer,vx,yaw_rate,ay",
        "t [s],steer [deg],vx [km/h],yaw_rate [deg/s],ay [g]",
        1,
    );
    let p = dir.join("h.csv");
    std::fs::write(&p, &header).unwrap();
    let by_header = vehsim::discover::measured::read_run(&p).unwrap();
    let p = dir.join("s.csv");
    std::fs::write(&p, csv(|_, l| converted(l))).unwrap();
    std::fs::write(dir.join("s.toml"), "[units]\nsteer = \"deg\"\nvx = \"km/h\"\nyaw_rate = \"deg/s\"\nay = \"g\"\n")
        .unwrap();
    let by_sidecar = vehsim::discover::measured::read_run(&p).unwrap();
    for r in [&by_header, &by_sidecar] {
        for (a, b) in [(&r.steer, &si.steer), (&r.vx, &si.vx), (&r.yaw_rate, &si.yaw_rate), (&r.ay, &si.ay)] {
            assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + y.abs())));
        }
    }
}

/// A unit not listed for its column, a sidecar unit for a column the run lacks, and a header and a
/// sidecar that disagree: exit 2 naming the file, the column or key and what is allowed.
#[test]
fn bad_units_are_named() {
    let text = csv(|_, l| l).replacen("ay\n", "ay [ft/s^2]\n", 1);
    expect_bad("unit-header", &text, &["header", "unit 'ft/s^2' of column 'ay'", "allowed: m/s^2, g"]);
    let dir = common::temp_dir("units-bad");
    let p = dir.join("r.csv");
    for (csv_text, side, needles) in [
        (csv(|_, l| l), "[units]\nx = \"m\"\n", vec!["r.toml", "units.x", "has no column 'x'"]),
        (csv(|_, l| l), "[units]\nbrake = \"bar\"\n", vec!["units.brake", "not a column of the run format"]),
        (csv(|_, l| l), "[units]\nyaw_rate = \"rpm\"\n", vec!["units.yaw_rate", "allowed: rad/s, deg/s"]),
        (
            csv(|_, l| l).replacen("yaw_rate", "yaw_rate [rad/s]", 1),
            "[units]\nyaw_rate = \"deg/s\"\n",
            vec!["units.yaw_rate", "header", "'rad/s'", "give one unit"],
        ),
    ] {
        std::fs::write(&p, csv_text).unwrap();
        std::fs::write(dir.join("r.toml"), side).unwrap();
        let e = vehsim::discover::measured::read_run(&p).unwrap_err();
        let msg = e.to_string();
        assert_eq!(e.exit_code(), 2, "{msg}");
        for n in needles {
            assert!(msg.contains(n), "lacks '{n}': {msg}");
        }
    }
}

/// The provider and baseline-model flags take the spec files' names: anything else is a usage
/// error (exit 2) that lists them, before any file is read.
#[test]
fn unknown_tyre_model_or_baseline_model_lists_the_allowed_names() {
    let discover = ["discover", "--vehicle", "nope.toml", "--out", "unused", "nope.csv"];
    let synth = ["synth", "--effect", "none", "--out", "unused"];
    let tyres: &[&str] = &["pacejka", "atiim_pacejka", "dugoff_thermal"];
    let cases: [(&[&str], &str, &str, &[&str]); 3] = [
        (&discover, "--tyre-model", "magic", tyres),
        (&discover, "--model", "roll6dof", &["bicycle", "roll4dof"]),
        (&synth, "--tyre-model", "magic", tyres),
    ];
    for (command, flag, value, needles) in cases {
        let o = Command::new(BIN).args(command).args([flag, value]).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{flag} {value}: {err}");
        assert!(err.contains(value), "{err}");
        for n in needles {
            assert!(err.contains(n), "{flag}: {err} does not list {n}");
        }
        assert!(!std::path::Path::new("unused").exists());
    }
}
