//! The fuzzing corpus as regression inputs (runs on stable, in `cargo test --release`): every file
//! of `fuzz/corpus/<target>/` (the seeds and what fuzzing added) and of `fuzz/regressions/<target>/`
//! (minimised inputs that once crashed the program) goes through the same
//! `vehsim::fuzz_entry::<target>` function as in the fuzzer, and must return without panicking.
//! A failure names the target and the file. The fuzzing itself is in `fuzz/` (docs/fuzzing.md).

use std::path::{Path, PathBuf};

use vehsim::fuzz_entry::{run_target, TARGETS};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

/// Files of `dir`, sorted (none when the folder does not exist).
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut v: Vec<PathBuf> = rd.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.is_file()).collect();
    v.sort();
    v
}

/// Feed every file of `fuzz/<kind>/<target>/` to its target; returns (inputs run, failures).
fn run_folder(kind: &str) -> (usize, Vec<String>) {
    let mut n = 0;
    let mut failures = Vec::new();
    for t in TARGETS {
        for f in files(&fuzz_dir().join(kind).join(t)) {
            let data = std::fs::read(&f).unwrap();
            n += 1;
            let r = std::panic::catch_unwind(|| run_target(t, &data));
            match r {
                Ok(true) => {}
                Ok(false) => failures.push(format!("{t}: no such target")),
                Err(_) => failures.push(format!("target {t} panicked on {}", f.display())),
            }
        }
    }
    (n, failures)
}

#[test]
fn every_target_has_a_fuzz_target_file_and_a_seed_corpus() {
    for t in TARGETS {
        let src = fuzz_dir().join("fuzz_targets").join(format!("{t}.rs"));
        let text = std::fs::read_to_string(&src).unwrap_or_else(|e| panic!("{}: {e}", src.display()));
        assert!(text.contains(&format!("vehsim::fuzz_entry::{t}(")), "{} must call fuzz_entry::{t}", src.display());
        assert!(!files(&fuzz_dir().join("corpus").join(t)).is_empty(), "fuzz/corpus/{t}/ has no seeds");
    }
    // No stray folders: every corpus or regression folder belongs to a target.
    for kind in ["corpus", "regressions"] {
        let Ok(rd) = std::fs::read_dir(fuzz_dir().join(kind)) else { continue };
        for e in rd.filter_map(|e| e.ok()) {
            let name = e.file_name().to_string_lossy().into_owned();
            assert!(TARGETS.contains(&name.as_str()), "fuzz/{kind}/{name} is not a fuzz target");
        }
    }
}

#[test]
fn corpus_inputs_never_panic() {
    let (n, failures) = run_folder("corpus");
    assert!(n >= TARGETS.len(), "only {n} corpus inputs");
    assert!(failures.is_empty(), "{} of {n} corpus inputs failed:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn regression_inputs_never_panic() {
    let (n, failures) = run_folder("regressions");
    assert!(failures.is_empty(), "{} of {n} regression inputs failed:\n{}", failures.len(), failures.join("\n"));
}

/// Is this a seed written from the project's own files (a readable name) rather than an input
/// the fuzzer added (named by the SHA-1 of its content)?
fn is_seed(p: &Path) -> bool {
    let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    !(name.len() == 40 && name.chars().all(|c| c.is_ascii_hexdigit()))
}

/// The seeds taken from the project's own spec files are valid inputs, so fuzzing starts on the
/// accepting paths (the relative paths inside them resolve from where the entry functions pretend
/// the bytes come from).
#[test]
fn spec_seeds_are_accepted_inputs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let corpus = fuzz_dir().join("corpus");
    let text = |p: &Path| std::fs::read_to_string(p).unwrap();
    let files = |d: &Path| files(d).into_iter().filter(|p| is_seed(p)).collect::<Vec<_>>();
    for f in files(&corpus.join("vehicle_toml")) {
        let path = root.join("vehicles/fuzz_input.toml");
        let v: vehsim_spec::VehicleFile = vehsim_spec::files::parse_toml(&path, &text(&f)).unwrap();
        v.build(&path, vehsim_core::tyre::TyreModelKind::Linear).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
    for f in files(&corpus.join("maneuver_toml")) {
        let b = vehsim::batch::from_text(&root.join("maneuvers/fuzz_input.toml"), &text(&f));
        let b = b.unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(b.runs.iter().all(|r| r.config.is_ok()), "{}", f.display());
    }
    for f in files(&corpus.join("tyre_toml")) {
        let path = root.join("vehicles/tyres/fuzz_input.toml");
        let t: vehsim_spec::tyre::TyreFileSpec = vehsim_spec::files::parse_toml(&path, &text(&f)).unwrap();
        assert!(
            vehsim_core::tyre::TyreModelKind::ALL.iter().any(|k| t.build(&path, *k).is_ok()),
            "{}: no provider builds",
            f.display()
        );
    }
    for f in files(&corpus.join("atiim_scenario_toml")) {
        let path = root.join("tests/data/atiim/fuzz_input.toml");
        let s: vehsim_spec::contact::ScenarioSpec = vehsim_spec::files::parse_toml(&path, &text(&f)).unwrap();
        s.validate(&path).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
    }
}

/// Crash found by `pressure_png` (2026-11-21): a 573-byte indexed PNG whose header claims 24 x
/// 620757056 pixels made the reader allocate a 60 GB frame buffer before decoding (an abort).
/// Now the decoded size is checked against the limit first.
#[test]
fn png_claiming_a_huge_image_is_an_input_error_before_any_allocation() {
    let f = fuzz_dir().join("regressions/pressure_png/huge_dimensions.png");
    let bytes = std::fs::read(&f).unwrap();
    let lay = vehsim_spec::patch_file::ImageLayout {
        footprint: [0, 0, 10, 8],
        colour_bar: [20, 0, 24, 64],
        bar_min_pa: 0.0,
        bar_max_pa: 630e3,
        tolerance: 40.0,
        dx_m: 0.005,
        dy_m: 0.005,
    };
    match vehsim_spec::patch_file::read_png_map(Path::new("map.png"), &bytes, &lay) {
        Err(e @ vehsim_core::Error::Input { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains("map.png") && msg.contains("too large") && msg.contains("MiB"), "{msg}");
        }
        other => panic!("expected an input error, got {other:?}"),
    }
}
