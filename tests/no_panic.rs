//! Robustness: mutated versions of every kind of input file (manoeuvre, vehicle and tyre specs,
//! `.tir` property files, ATIIM scenarios and pressure-grid CSVs) go through the loaders, and the
//! manoeuvre specs that still validate are simulated for a short time. Nothing may panic: a bad
//! input is an `Err`, a bad simulation an event. The mutations are deterministic (a fixed-seed
//! xorshift generator), so a failure reproduces exactly; the failing input is printed.
//!
//! This is a property test over a few thousand inputs, not coverage-guided fuzzing; that is in
//! `fuzz/` (docs/fuzzing.md), and `tests/fuzz_corpus.rs` replays its corpus.

mod common;

use std::path::{Path, PathBuf};

use vehsim_spec::tyre::TyreFileSpec;

use vehsim_core::tyre::TyreModelKind;

/// xorshift64*: small, deterministic, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Values that break naive parsers and naive physics.
const NASTY: &[&str] = &[
    "nan",
    "inf",
    "-inf",
    "0",
    "-0.0",
    "-1",
    "1e308",
    "-1e308",
    "1e-320",
    "3",
    "\"\"",
    "\"x\"",
    "[]",
    "{}",
    "true",
    "99999999999999999999",
    "0.0000001",
    "[1.0, 2.0]",
    "NaN",
    "= =",
    "'",
    "$",
    "[UNITS]",
];

/// One mutation of `text`: replace a number, delete, duplicate or swap a line, truncate, or flip
/// a byte (kept valid UTF-8).
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return NASTY[rng.below(NASTY.len())].to_string();
    }
    match rng.below(6) {
        0 => {
            // Replace the value of a `key = value` line (or the whole line) by a nasty value.
            let i = rng.below(lines.len());
            let nasty = NASTY[rng.below(NASTY.len())];
            lines[i] = match lines[i].split_once('=') {
                Some((k, _)) => format!("{k}= {nasty}"),
                None => nasty.to_string(),
            };
        }
        1 => {
            let i = rng.below(lines.len());
            lines.remove(i);
        }
        2 => {
            let i = rng.below(lines.len());
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        3 => {
            let (i, j) = (rng.below(lines.len()), rng.below(lines.len()));
            lines.swap(i, j);
        }
        4 => {
            let all = lines.join("\n");
            let cut = rng.below(all.len() + 1);
            return all.get(..cut).unwrap_or(&all).to_string();
        }
        _ => {
            // Replace one character by a printable ASCII one.
            let i = rng.below(lines.len());
            let mut chars: Vec<char> = lines[i].chars().collect();
            if !chars.is_empty() {
                let c = rng.below(chars.len());
                chars[c] = (b' ' + rng.below(95) as u8) as char;
            }
            lines[i] = chars.into_iter().collect();
        }
    }
    lines.join("\n") + "\n"
}

/// A scratch copy of the sedan and its tyre files next to which mutated specs are written.
fn scratch(tag: &str) -> PathBuf {
    let dir = common::temp_dir(tag);
    let root = common::root();
    std::fs::create_dir_all(dir.join("tyres")).unwrap();
    std::fs::copy(root.join("vehicles/sedan.toml"), dir.join("sedan.toml")).unwrap();
    for f in ["srtt_p225_60r16.toml", "srtt_p225_60r16.tir"] {
        std::fs::copy(root.join("vehicles/tyres").join(f), dir.join("tyres").join(f)).unwrap();
    }
    dir
}

fn check<T>(what: &str, input: &str, f: impl FnOnce() -> T) -> T {
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    match r {
        Ok(v) => v,
        Err(_) => panic!("{what} panicked on this input:\n{input}"),
    }
}

#[test]
fn mutated_manoeuvre_specs_never_panic_and_short_runs_of_valid_ones_finish() {
    let dir = scratch("nopanic-maneuver");
    let seeds =
        ["maneuvers/dlc.toml", "maneuvers/sine_steer.toml", "maneuvers/dlc_sweep.toml", "maneuvers/dlc_roll4dof.toml"];
    let mut rng = Rng(0x5eed_0001);
    let mut simulated = 0;
    for seed in seeds {
        let text =
            std::fs::read_to_string(common::root().join(seed)).unwrap().replace("../vehicles/sedan.toml", "sedan.toml");
        for _ in 0..150 {
            let m = mutate(&text, &mut rng);
            let p = dir.join("m.toml");
            std::fs::write(&p, &m).unwrap();
            if let Ok(b) = check("batch::load", &m, || vehsim::batch::load(&p)) {
                if let Some(Ok(cfg)) = b.runs.first().map(|r| r.config.clone()) {
                    let mut cfg = cfg;
                    cfg.settings.duration_s = cfg.settings.duration_s.min(0.5);
                    let out = check("run::execute", &m, || vehsim_spec::run::execute(&cfg));
                    assert!(
                        out.summary.steps > 0 || out.summary.end_reason != vehsim_core::event::EndReason::Duration,
                        "{m}"
                    );
                    simulated += 1;
                }
            }
        }
    }
    assert!(simulated > 20, "too few mutated specs validated ({simulated}) for the run check to mean anything");
}

#[test]
fn mutated_vehicle_and_tyre_files_never_panic() {
    let dir = scratch("nopanic-vehicle");
    let root = common::root();
    let vehicle = std::fs::read_to_string(root.join("vehicles/sedan.toml")).unwrap();
    let tyre = std::fs::read_to_string(root.join("vehicles/tyres/srtt_p225_60r16.toml")).unwrap();
    let mut rng = Rng(0x5eed_0002);
    for _ in 0..300 {
        let m = mutate(&vehicle, &mut rng);
        let p = dir.join("v.toml");
        std::fs::write(&p, &m).unwrap();
        check("VehicleFile", &m, || {
            vehsim_spec::VehicleFile::load(&p).and_then(|v| v.build(&p, TyreModelKind::Linear)).map(|_| ())
        })
        .ok();
    }
    for _ in 0..300 {
        let m = mutate(&tyre, &mut rng);
        let p = dir.join("tyres/t.toml");
        std::fs::write(&p, &m).unwrap();
        for &kind in TyreModelKind::ALL {
            check("TyreFileSpec", &m, || TyreFileSpec::load(&p).and_then(|t| t.build(&p, kind)).map(|_| ())).ok();
        }
    }
}

#[test]
fn mutated_tir_files_never_panic() {
    let root = common::root();
    // The shipped SRTT file and the public PAC2002 file (tests/data/tir/README.md).
    let seeds = ["vehicles/tyres/srtt_p225_60r16.tir", "tests/data/tir/Sedan_Pac02Tire.tir"]
        .map(|f| std::fs::read_to_string(root.join(f)).unwrap_or_else(|e| panic!("{f}: {e}")));
    let mut rng = Rng(0x5eed_0003);
    let p = Path::new("mutated.tir");
    for seed in &seeds {
        for _ in 0..400 {
            let m = mutate(seed, &mut rng);
            check("parse_tir", &m, || vehsim_spec::tir::parse_tir(p, &m).map(|_| ())).ok();
        }
    }
}

#[test]
fn mutated_pressure_grids_and_atiim_scenarios_never_panic() {
    let root = common::root();
    let csv = std::fs::read_to_string(root.join("tests/data/atiim/valid.csv")).unwrap();
    let mut rng = Rng(0x5eed_0004);
    let p = Path::new("grid.csv");
    for _ in 0..400 {
        let m = mutate(&csv, &mut rng);
        check("parse_csv", &m, || vehsim_spec::patch_file::parse_csv(p, &m, 0.01, 0.01).map(|_| ())).ok();
    }
    let dir = common::temp_dir("nopanic-atiim");
    for f in ["valid.csv", "negative.csv"] {
        std::fs::copy(root.join("tests/data/atiim").join(f), dir.join(f)).unwrap();
    }
    let scenario = std::fs::read_to_string(root.join("tests/data/atiim/valid_csv.toml")).unwrap();
    for _ in 0..150 {
        let m = mutate(&scenario, &mut rng);
        let sp = dir.join("s.toml");
        std::fs::write(&sp, &m).unwrap();
        check("ScenarioSpec::load", &m, || vehsim_spec::contact::ScenarioSpec::load(&sp).map(|_| ())).ok();
    }
}
