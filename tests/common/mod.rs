//! Helpers shared by the integration tests: load the shipped specs from the repository.
#![allow(dead_code)]

pub mod atiim;

use std::path::{Path, PathBuf};
use std::process::Command;

use vehsim_spec::run::RunOutput;
use vehsim_spec::RunConfig;

/// The vehsim binary built for the tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_vehsim");

/// Run the vehsim binary in `dir`; returns (exit code, stdout, stderr).
pub fn vehsim(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(BIN).args(args).current_dir(dir).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A scratch folder holding a copy of the sedan (`sedan.toml`), its tyre (`tyres/`) and one
/// manoeuvre spec that names `sedan.toml`; tests edit the copies and run the CLI on them.
pub struct Case {
    pub dir: PathBuf,
}

impl Case {
    /// New scratch folder `tag` with the spec text `spec` written as `spec_name`.
    pub fn new(tag: &str, spec_name: &str, spec: &str) -> Self {
        let dir = temp_dir(tag);
        std::fs::create_dir_all(dir.join("tyres")).unwrap();
        let root = root();
        std::fs::copy(root.join("vehicles/sedan.toml"), dir.join("sedan.toml")).unwrap();
        std::fs::copy(root.join("vehicles/tyres/srtt_p225_60r16.toml"), dir.join("tyres/srtt_p225_60r16.toml"))
            .unwrap();
        std::fs::write(dir.join(spec_name), spec).unwrap();
        Case { dir }
    }

    /// Replace `from` by `to` in `file` (the replacement must happen).
    pub fn edit(&self, file: &str, from: &str, to: &str) -> &Self {
        let p = self.dir.join(file);
        let s = std::fs::read_to_string(&p).unwrap();
        assert!(s.contains(from), "{file} has no '{from}'");
        std::fs::write(&p, s.replacen(from, to, 1)).unwrap();
        self
    }

    /// New scratch folder as [`Case::new`], with the sedan's Pacejka `.tir` copied beside its tyre
    /// and `tail` (e.g. a `[lateral]` section) appended to `sedan.toml`.
    pub fn with_sedan_tail(tag: &str, spec_name: &str, spec: &str, tail: &str) -> Self {
        let c = Case::new(tag, spec_name, spec);
        let tir = "tyres/srtt_p225_60r16.tir";
        std::fs::copy(root().join("vehicles").join(tir), c.dir.join(tir)).unwrap();
        let v = c.dir.join("sedan.toml");
        let text = std::fs::read_to_string(&v).unwrap();
        std::fs::write(&v, format!("{text}\n{tail}")).unwrap();
        c
    }

    /// The time series of run `name` written under `res/` (`--out res`) as (header, rows).
    pub fn series(&self, name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
        let text = std::fs::read_to_string(self.dir.join("res").join(name).join("timeseries.csv")).unwrap();
        let mut lines = text.lines();
        let head = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        (head, rows)
    }

    /// Run the CLI in the scratch folder.
    pub fn run(&self, args: &[&str]) -> (i32, String, String) {
        vehsim(&self.dir, args)
    }

    /// The default results folder of the scratch folder.
    pub fn results(&self) -> PathBuf {
        self.dir.join("results")
    }
}

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Load and validate a shipped manoeuvre spec (path relative to the repository root).
pub fn load(spec: &str) -> RunConfig {
    match vehsim_spec::run::load(&root().join(spec)) {
        Ok(c) => c,
        Err(e) => panic!("{spec}: {e}"),
    }
}

/// A run spec `name`: vehicle file `vehicle` (as written in the spec), the linear tyre, a sine
/// steer of 3 deg amplitude and 2 s period at 10 m/s on mu 0.15, `duration_s` long. Tables such
/// as [output] or [sweep] can follow.
pub fn sine_steer_spec(name: &str, vehicle: &str, duration_s: f64) -> String {
    format!(
        r#"name = "{name}"
vehicle = "{vehicle}"
tyre_model = "linear"
duration_s = {duration_s:?}
[surface]
mu = 0.15
[maneuver]
kind = "sine_steer"
speed_mps = 10.0
steer_amplitude_deg = 3.0
period_s = 2.0
"#
    )
}

/// A fresh, empty temporary folder for one test.
pub fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("vehsim-test-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Largest |yaw-rate difference| of two runs over their common output grid (the extra final row
/// of a run, whose time depends on the step, is where the grids part). Asserts that more than
/// 500 rows were compared.
pub fn max_yaw_rate_diff(a: &RunOutput, b: &RunOutput) -> f64 {
    let mut worst = 0.0_f64;
    let mut n = 0;
    for (p, q) in a.rows.iter().zip(&b.rows) {
        if (p.t_s - q.t_s).abs() > 1e-9 {
            break;
        }
        worst = worst.max((p.obs.kin.yaw_rate_radps - q.obs.kin.yaw_rate_radps).abs());
        n += 1;
    }
    assert!(n > 500, "runs too short to compare ({n} common rows)");
    worst
}

/// `vehsim synth --effect EFFECT --params PARAMS --out DIR/runs` on the shipped sedan; returns the
/// written run CSVs, sorted.
pub fn synth_runs(dir: &Path, effect: &str, params: &str) -> Vec<PathBuf> {
    synth_runs_with(dir, &["--effect", effect, "--params", params])
}

/// `vehsim synth ARGS --out DIR/runs` on the shipped sedan (it must succeed); returns the written
/// run CSVs, sorted.
pub fn synth_runs_with(dir: &Path, args: &[&str]) -> Vec<PathBuf> {
    let out = Command::new(BIN)
        .arg("synth")
        .args(args)
        .arg("--out")
        .arg(dir.join("runs"))
        .arg("--vehicle")
        .arg(root().join("vehicles/sedan.toml"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut runs: Vec<PathBuf> = std::fs::read_dir(dir.join("runs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    runs.sort();
    runs
}

/// The golden trajectories, checked by tests/golden.rs and measured against a fine step by
/// tests/accuracy.rs: (golden file stem `<run>__<tyre model>__<vehicle model>`, spec, tyre model,
/// vehicle model, contact model), the spec's own settings with those three replaced.
pub const GOLDEN_CASES: &[(&str, &str, &str, &str, &str)] = &[
    ("dlc_ice__linear__bicycle", "maneuvers/dlc.toml", "linear", "bicycle", "isothermal"),
    ("sine_steer_ice__linear__bicycle", "maneuvers/sine_steer.toml", "linear", "bicycle", "isothermal"),
    ("dlc_ice__pacejka__bicycle", "maneuvers/dlc.toml", "pacejka", "bicycle", "isothermal"),
    ("dlc_ice__atiim_pacejka__bicycle", "maneuvers/dlc.toml", "atiim_pacejka", "bicycle", "atiim"),
    ("dlc_ice__dugoff__bicycle", "maneuvers/dlc.toml", "dugoff", "bicycle", "isothermal"),
    ("dlc_ice__linear__roll4dof", "maneuvers/dlc.toml", "linear", "roll4dof", "isothermal"),
    ("dlc_ice__pacejka__roll4dof", "maneuvers/dlc.toml", "pacejka", "roll4dof", "isothermal"),
];

/// Each `(effect, param, needle)`: `vehsim synth --effect effect --params param` (the sedan, into
/// `dir/runs`) is a usage error (exit 2) whose message names `--params` and contains `needle`, and
/// writes nothing.
pub fn assert_synth_params_refused(dir: &Path, cases: &[(&str, &str, &str)]) {
    let sedan = root().join("vehicles/sedan.toml");
    let sedan = sedan.to_str().unwrap();
    for (effect, param, needle) in cases {
        let out = dir.join("runs");
        let (code, _, err) = vehsim(
            dir,
            &["synth", "--vehicle", sedan, "--effect", effect, "--params", param, "--out", out.to_str().unwrap()],
        );
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("--params") && err.contains(needle), "{err}");
        assert!(!out.exists());
    }
}

/// The runs replayed from the baseline `p` by `model` on the discovery's split give its final
/// RMSE (fitted and held-out samples, both channels) to 1e-9: what a write-back must reproduce.
/// Returns the largest difference; `label` names the case in a failure.
pub fn assert_final_gap_replayed(
    label: &str,
    model: &vehsim::discover::model::ReplayModel,
    runs: Vec<vehsim::discover::measured::MeasuredRun>,
    d: &vehsim::discover::Discovery,
    p: &vehsim::discover::model::EffectParams,
) -> f64 {
    use vehsim::discover::select::{score, simulate_all};
    let mut data = vehsim::discover::Dataset::new(runs);
    data.held = d.held.clone();
    let s = score(&data, &simulate_all(model, &data, p));
    let mut largest: f64 = 0.0;
    for held in [false, true] {
        let (got, want) = (s.rmse(held), d.final_scores.rmse(held));
        for (g, w, ch) in [(got.yaw_rate_radps, want.yaw_rate_radps, "yaw rate"), (got.ay_mps2, want.ay_mps2, "ay")] {
            largest = largest.max((g - w).abs());
            assert!((g - w).abs() <= 1e-9, "{label} {ch} (held out {held}): replayed {g:e}, discovery's final {w:e}");
        }
    }
    largest
}
