//! Every shipped vehicle builds and every shipped manoeuvre spec (a TOML file with a `[maneuver]`
//! table, sweeps included) validates, so a user's first `vehsim run` cannot fail on our files.

mod common;

use std::path::{Path, PathBuf};

use vehsim_core::tyre::TyreModelKind;
use vehsim_spec::VehicleFile;

fn toml_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "toml") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn every_shipped_vehicle_builds() {
    let files: Vec<_> = toml_files(&common::root().join("vehicles"))
        .into_iter()
        .filter(|p| !p.starts_with(common::root().join("vehicles/tyres")))
        .collect();
    assert!(files.len() >= 6, "expected the sedan and classes A-E, found {files:?}");
    for f in files {
        let v = VehicleFile::load(&f).and_then(|v| v.build(&f, TyreModelKind::Linear));
        assert!(v.is_ok(), "{}: {}", f.display(), v.unwrap_err());
    }
}

#[test]
fn every_shipped_maneuver_spec_validates() {
    use vehsim_spec::kind::{detect, SpecKind};
    let mut n = 0;
    for f in toml_files(&common::root().join("maneuvers")) {
        let text = std::fs::read_to_string(&f).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        // maneuvers/ holds run specs only, so that `vehsim run maneuvers/*.toml` runs them all.
        assert_eq!(detect(&table), Some(SpecKind::Run), "{}: not a run spec", f.display());
        let b = vehsim::batch::load(&f);
        assert!(b.is_ok(), "{}: {}", f.display(), b.unwrap_err());
        assert!(b.unwrap().runs.iter().all(|r| r.config.is_ok()), "{}: an invalid sweep combination", f.display());
        n += 1;
    }
    assert!(n >= 4, "only {n} manoeuvre specs found");
}

#[test]
fn every_shipped_envelope_spec_validates() {
    let files = toml_files(&common::root().join("scenarios/envelope"));
    assert!(files.len() >= 2, "expected the ice-temperature and constant-radius envelopes, found {files:?}");
    for f in files {
        // The envelope loader checks every combination and reference.
        let e = vehsim::envelope::load(&f);
        assert!(e.is_ok(), "{}: {}", f.display(), e.unwrap_err());
    }
}
