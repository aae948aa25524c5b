//! Helpers shared by the integration tests: load the shipped specs from the repository.
#![allow(dead_code)]

use std::path::PathBuf;

use vehsim::spec::RunConfig;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Load and validate a shipped manoeuvre spec (path relative to the repository root).
pub fn load(spec: &str) -> RunConfig {
    match vehsim::run::load(&root().join(spec)) {
        Ok(c) => c,
        Err(e) => panic!("{spec}: {e}"),
    }
}

/// A fresh, empty temporary folder for one test.
pub fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vehsim-test-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}
