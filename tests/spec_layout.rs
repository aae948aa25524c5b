//! Spec layout: `maneuvers/` holds run specs only (so `vehsim run maneuvers/*.toml` can work), and
//! a spec given to the wrong command is refused (exit 2) with one line naming the right command.

mod common;

use common::vehsim;

#[test]
fn every_top_level_maneuvers_file_is_a_run_spec() {
    let dir = common::root().join("maneuvers");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let table: toml::Table = toml::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
            assert_eq!(
                vehsim_spec::kind::detect(&table),
                Some(vehsim_spec::kind::SpecKind::Run),
                "{} is not a run spec",
                p.display()
            );
            n += 1;
        }
    }
    assert!(n >= 5, "only {n} specs in maneuvers/");
}

/// (exit code, stderr) of `vehsim <args>` run in the repository root.
fn refused(args: &[&str]) -> String {
    let (code, out, err) = vehsim(&common::root(), args);
    assert_eq!(code, 2, "{args:?}: {out}{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
    err
}

#[test]
fn a_spec_of_the_wrong_kind_names_the_right_command() {
    let tyre = "scenarios/tyre/tyre_curves.toml";
    for cmd in ["run", "validate", "bench"] {
        let err = refused(&[cmd, tyre]);
        assert!(err.contains(&format!("vehsim tyre {tyre}")), "{cmd}: {err}");
    }
    for cmd in ["tyre", "atiim"] {
        let err = refused(&[cmd, "maneuvers/dlc.toml"]);
        assert!(err.contains("vehsim run maneuvers/dlc.toml"), "{cmd}: {err}");
    }
    // An ATIIM scenario (its keys, not a shipped file: those move between folders).
    let dir = common::temp_dir("spec-kind-atiim");
    std::fs::write(
        dir.join("scenario.toml"),
        "name = \"s\"\ntitle = \"t\"\n[pressure]\nsource = \"synth\"\nload_n = 4000.0\n[operating]\nspeed_mps = 25.0\n",
    )
    .unwrap();
    for cmd in ["run", "validate", "tyre"] {
        let (code, out, err) = vehsim(&dir, &[cmd, "scenario.toml"]);
        assert_eq!(code, 2, "{cmd}: {out}{err}");
        assert!(err.contains("vehsim atiim scenario.toml"), "{cmd}: {err}");
        assert!(!dir.join("results").exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
