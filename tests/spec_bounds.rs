//! One source of truth per bound: README's key tables state the ranges the code declares
//! (`spec::maneuver::bounds`, `vehicle::lateral_bounds`), each bound's message keeps its
//! wording, a `[lateral]` section on a 4-DOF run is refused, and bad flags are usage errors.

mod common;

use vehsim_core::error::Bound;
use vehsim_core::vehicle::lateral_bounds;
use vehsim_spec::maneuver::bounds;

fn readme() -> String {
    std::fs::read_to_string(common::root().join("README.md")).unwrap().replace('\u{2212}', "-")
}

/// Each `[lateral]` and `[sensors]` key of README gives the declared unit and range: `(unit, lo–hi, ...`.
#[test]
fn readme_lateral_keys_give_the_declared_ranges() {
    let text = readme();
    for b in lateral_bounds::ALL.iter().chain(&vehsim_core::vehicle::sensor_bounds::ALL) {
        let name = b.key.split_once('.').unwrap().1;
        // The key's first mention in the [lateral] and [sensors] sections, up to the end of its
        // bullet; the first parenthesis after it gives the unit and range.
        let from = text.find("Optional `[lateral]` section").unwrap();
        let at = from + text[from..].find(&format!("`{name}`")).unwrap_or_else(|| panic!("README has no {name}"));
        let end = text[at..].find("\n- ").map_or(text.len(), |e| at + e);
        let after = &text[at..end];
        let bullet = after[after.find('(').unwrap_or(0)..].split_whitespace().collect::<Vec<_>>().join(" ");
        let range = format!("{}\u{2013}{}", b.lo, b.hi);
        let want = if b.unit.is_empty() { format!("({range}") } else { format!("({}, {range}", b.unit) };
        assert!(bullet.starts_with(&want), "README's {name} should say {want}: {bullet}");
    }
}

/// The manoeuvre table rows that give a range give the declared interval.
#[test]
fn readme_manoeuvre_rows_give_the_declared_intervals() {
    let text = readme();
    for (row, b) in [
        ("`[surface] mu`", bounds::MU),
        ("`[integrator] step_s`", bounds::STEP_S),
        ("`[integrator] control_period_s`", bounds::CONTROL_PERIOD_S),
        ("`[road] bank_deg`", vehsim_core::vehicle::road::road_bounds::BANK_DEG),
        ("`[road] grade_deg`", vehsim_core::vehicle::road::road_bounds::GRADE_DEG),
    ] {
        let line = text.lines().find(|l| l.starts_with(&format!("| {row} |"))).unwrap_or_else(|| panic!("{row}"));
        assert!(line.contains(&b.interval()), "README row {row} should give {}: {line}", b.interval());
    }
}

/// The messages read the same as before the bounds were declared (tests and users match them).
#[test]
fn bound_messages_keep_their_wording() {
    let cases: [(Bound, &str); 6] = [
        (bounds::MU, "expected 0 < mu <= 2"),
        (bounds::SPEED_MPS, "expected 0 < speed_mps <= 100 (m/s)"),
        (bounds::RTOL, "expected 0 < rtol < 1"),
        (bounds::SPEED_RAMP_MPS2, "expected 0 < speed_ramp_mps2 <= 20 (m/s^2)"),
        (bounds::APPROACH_M, "expected a finite number in [5, 1000]"),
        (lateral_bounds::THERMAL_MU, "expected a finite number in [-2, 0]"),
    ];
    for (b, msg) in cases {
        assert_eq!(b.allowed(), msg, "{}", b.key);
        // Both ends: inside, at and just beyond.
        assert!(b.contains(0.5 * (b.lo + b.hi)), "{}", b.key);
        assert!(b.contains(b.hi) == (b.ends != vehsim_core::error::Ends::Open), "{}", b.key);
        assert!(b.contains(b.lo) == (b.ends == vehsim_core::error::Ends::Closed), "{}", b.key);
        assert!(!b.contains(b.hi + 1e-9 * b.hi.abs().max(1.0)) && !b.contains(f64::NAN), "{}", b.key);
    }
}

const DLC: &str = r#"name = "d"
vehicle = "sedan.toml"
tyre_model = "linear"
vehicle_model = "roll4dof"
[surface]
mu = 0.15
[maneuver]
kind = "iso3888_2"
speed_mps = 10.0
"#;

/// The 4-DOF model has no `[lateral]` extensions: a vehicle that switches one on is refused for
/// it, naming the vehicle file and the key; the bicycle model takes it; an all-default section
/// changes nothing and passes.
#[test]
fn lateral_section_is_refused_for_the_4dof_model() {
    let case = common::Case::new("bounds_lateral", "d.toml", DLC);
    let sedan = std::fs::read_to_string(case.dir.join("sedan.toml")).unwrap();
    std::fs::write(case.dir.join("sedan.toml"), format!("{sedan}\n[lateral]\nmu_scale = 1.0\n")).unwrap();
    let (code, out, err) = case.run(&["validate", "d.toml"]);
    assert_eq!(code, 0, "an all-default [lateral] changes nothing: {out}{err}");
    case.edit("sedan.toml", "mu_scale = 1.0", "mu_scale = 1.0\nsteer_lag_s = 0.05");
    let (code, _, err) = case.run(&["validate", "d.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("sedan.toml") && err.contains("key 'lateral.steer_lag_s'"), "{err}");
    assert!(err.contains("roll4dof") && err.contains("d.toml") && err.lines().count() == 1, "{err}");
    case.edit("d.toml", "vehicle_model = \"roll4dof\"", "vehicle_model = \"bicycle\"");
    let (code, _, err) = case.run(&["validate", "d.toml"]);
    assert_eq!(code, 0, "{err}");
}

/// A bad flag is a usage error: exit 2, one line naming the flag and what is allowed; a spec
/// choice given as a flag lists the names the spec files use.
#[test]
fn bad_flags_are_usage_errors() {
    let case = common::Case::new("bounds_flags", "d.toml", DLC);
    let (code, _, err) = case.run(&["run", "--jobs", "0", "d.toml"]);
    assert_eq!((code, err.as_str()), (2, "error: --jobs: expected at least 1 thread\n"));
    let (code, _, err) = case.run(&["bench", "d.toml", "--runs", "1", "--contact", "warm"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--contact") && err.contains("isothermal, atiim"), "{err}");
    let (code, _, err) = case.run(&["bench", "d.toml", "--runs", "1", "--tyre-model", "dugoff-thermal"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("dugoff_thermal") && err.contains("atiim_pacejka"), "{err}");
    let (code, _, err) = case.run(&["bench", "d.toml", "--runs", "1", "--model", "roll4dof", "--tsv"]);
    assert_eq!(code, 0, "{err}");
}

/// Every choice's names, as users write them: the spelling is the file format (spec keywords,
/// summary.csv values), so a renamed variant must not rename its string. Each name parses back to
/// its value, and `allowed` lists them in order.
#[test]
fn choice_names_are_the_file_format() {
    use vehsim_core::contact::estimator::Statistic;
    use vehsim_core::tyre::TyreModelKind;
    use vehsim_core::vehicle::VehicleModelKind;
    use vehsim_spec::contact::{ContactModelKind, PressureSource};
    use vehsim_spec::maneuver::ManeuverKind;
    macro_rules! names {
        ($t:ty, $expected:expr) => {{
            let names: Vec<&str> = <$t>::ALL.iter().map(|k| k.as_str()).collect();
            assert_eq!(names, $expected, stringify!($t));
            for k in <$t>::ALL {
                assert_eq!(<$t>::parse(k.as_str()), Some(*k));
            }
            assert_eq!(<$t>::parse("no_such_name"), None);
            assert_eq!(<$t>::allowed(), $expected.join(", "));
        }};
    }
    names!(TyreModelKind, ["linear", "polynomial", "pacejka", "dugoff", "dugoff_thermal", "atiim_pacejka"]);
    names!(VehicleModelKind, ["bicycle", "roll4dof"]);
    names!(
        ManeuverKind,
        [
            "iso3888_2",
            "sine_steer",
            "step_steer",
            "straight",
            "constant_radius",
            "braking",
            "launch",
            "braking_in_turn"
        ]
    );
    names!(vehsim::batch::RunStatus, ["ok", "failed", "invalid"]);
    names!(ContactModelKind, ["isothermal", "atiim"]);
    names!(PressureSource, ["synth", "csv", "image"]);
    names!(Statistic, ["max", "mean"]);
}
