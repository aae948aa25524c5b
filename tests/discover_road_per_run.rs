//! A road per run: each run of a set driven on its own constant bank and grade, hidden from the
//! sidecars. Discovery's road-per-run step (after the search) must name `road (per_run)`, recover
//! every run's pair within its interval, explain the set, and write `roads.toml`, whose `[road]`
//! tables added to the sidecars replay the discovery's final gap to 1e-9; a set with a second,
//! shared effect keeps that effect; `vehsim synth --roads` refuses bad pairs. (One road shared by
//! every run, and no road at all, stay as they were: tests/discover_road.rs checks that the step
//! adopts no per-run roads there.)

mod common;

use std::path::Path;

use vehsim::discover::measured::{apply_sidecar, MeasuredRun};
use vehsim::discover::model::{EffectParams, ReplayModel};
use vehsim::discover::road_per_run::RoadForm;
use vehsim::discover::search::discover_from;
use vehsim::discover::select::Verdict;
use vehsim::discover::uncertainty::Z95;
use vehsim::discover::{load_vehicle, synth, tyre_kind, Dataset, Discovery, Effect};
use vehsim_core::vehicle::road::Road;

fn model() -> ReplayModel {
    ReplayModel::new(
        load_vehicle(&common::root().join("vehicles/sedan.toml"), None, tyre_kind("pacejka").unwrap()).unwrap(),
    )
}

/// The six manoeuvres of the benchmark set (both surfaces; sine, step and ramp steer).
const SIX: [&str; 6] = ["sine_ice", "sine_dry", "step_dry", "step_ice", "ramp_ice", "ramp_dry"];

/// Each run's road (bank, grade in deg), in the order of [`SIX`]: mild, both signs, one run
/// level in bank, one in grade.
const ROADS: [(f64, f64); 6] = [(3.0, 0.0), (-2.0, 2.0), (0.0, -3.0), (4.0, 1.0), (-3.0, -1.0), (1.0, 3.0)];

/// The runs of [`SIX`], run i on road `ROADS[i]`, with `p` (the hidden shared effects), seed `seed`.
fn runs_on_roads(p: &EffectParams, seed: u64) -> Vec<MeasuredRun> {
    let ids: Vec<String> = SIX.iter().map(|s| s.to_string()).collect();
    let roads: Vec<Road> = ROADS.iter().map(|&(b, g)| Road::from_deg(b, g)).collect();
    synth::generate_plan_roads(&model(), p, seed, &synth::select(&ids).unwrap(), &roads, &[])
        .into_iter()
        .map(|r| r.0)
        .collect()
}

fn discover_all(runs: &[MeasuredRun]) -> Discovery {
    discover_from(&model(), &Dataset::new(runs.to_vec()), EffectParams::default(), &Effect::TRIED)
}

/// Every run's fitted pair holds its generated one within the interval widened to 3.09 standard
/// errors (the blind suite's family-wise level, as tests/discover_road.rs).
fn assert_roads_recovered(d: &Discovery) {
    let roads = d.run_roads().expect("a road per run");
    assert_eq!(roads.len(), ROADS.len());
    for (r, &(bank, grade)) in roads.iter().zip(&ROADS) {
        for (what, v, iv, truth) in
            [("bank", r.bank_deg, r.intervals[0], bank), ("grade", r.grade_deg, r.intervals[1], grade)]
        {
            eprintln!("{} {what}: {v:.4} (95 %: {:.4} to {:.4}), generated {truth}", r.run, iv.lo, iv.hi);
            let widen = (3.09 - Z95) * iv.std_error;
            assert!(iv.lo - widen <= truth && truth <= iv.hi + widen, "{} {what}: {truth} outside {iv:?}", r.run);
        }
    }
}

/// Six runs each on its own road (nothing else hidden, seed 1): the search alone names nothing
/// (no shared cause fits; verdict unexplained, held-out yaw rate 11.9x and 5.5x the noise in its
/// two folds), the step names `road (per_run)` and the set is explained; each run's pair is
/// recovered (measured: the largest miss 0.022 deg of bank, 02_sine_dry, 2.3 standard errors);
/// the `[road]` of roads.toml in each sidecar replays the final gap to 1e-9.
#[test]
fn each_run_on_its_own_road_is_named_and_recovered() {
    let mut runs = runs_on_roads(&EffectParams::default(), 1);
    let d = discover_all(&runs);
    assert_eq!(d.named_names(), vec!["road (per_run)"], "{}", d.named_text());
    assert!(d.named.is_empty() && d.final_effects.is_empty());
    assert_eq!(d.verdict, Verdict::Explained);
    let o = d.road_per_run.as_ref().unwrap();
    assert_eq!(o.chosen, RoadForm::PerRun);
    assert!(o.named_before.is_empty(), "{:?}", o.named_before);
    for f in &o.comparison.as_ref().unwrap().folds {
        let [none, shared, per_run] = f.bic();
        eprintln!("held-out BIC: none {none:.1}, one road {shared:.1}, a road per run {per_run:.1}");
        assert!(per_run < shared && per_run < none);
    }
    assert_roads_recovered(&d);
    // The write-back: each run's [road] from roads.toml added to its sidecar.
    let text = o.comparison.as_ref().unwrap().roads_toml();
    for (r, fitted) in runs.iter_mut().zip(d.run_roads().unwrap()) {
        let snippet = fitted.sidecar_toml();
        assert!(text.contains(&format!("# {}.toml\n{snippet}", r.name)), "{text}");
        apply_sidecar(r, Path::new("RUN.toml"), &format!("[surface]\nmu = {}\n{snippet}", r.mu)).unwrap();
    }
    common::assert_final_gap_replayed("road per run", &model(), runs, &d, &EffectParams::default());
    assert!(d.final_scores.rss_held < 0.05 * d.baseline.rss_held);
}

/// The same roads with a shared effect hidden as well (a lateral-accelerometer latency of
/// 0.05 s, seed 3): the search before the roads names nothing (the roads' residuals hide the
/// latency's gain); the search run again with each run on its road names the latency, which
/// stays significant with the roads refitted; the set is explained. Measured: 0.04911 s
/// (0.04867 to 0.04957), 4 standard errors low, as the same latency without roads (same seed and
/// manoeuvres, every run fitted or held out whole) is 0.04960 s (0.04929 to 0.04996), 2.4 low:
/// the replay is driven by the noisy measured steer and speed, which biases the lag slightly; the
/// blocks fit on half of every run. So the bound is 3 % of the generated value.
#[test]
#[ignore = "long (two searches and two comparisons, about 45 s); run by scripts/test-long.sh"]
fn a_shared_effect_on_top_of_the_roads_stays_named() {
    let mut p = EffectParams::default();
    Effect::SensorLatency.apply(&mut p, &[0.0, 0.05]);
    let d = discover_all(&runs_on_roads(&p, 3));
    assert_eq!(d.named_names(), vec![Effect::SensorLatency.name(), "road (per_run)"], "{}", d.named_text());
    eprintln!("named before the roads: {:?}", d.road_per_run.as_ref().unwrap().named_before);
    let fe = &d.final_effects[0];
    assert!(fe.significant);
    let (v, iv) = (fe.params[1].1, fe.intervals[1]);
    eprintln!("latency_ay_s {v:.5} (95 %: {:.5} to {:.5}), generated 0.05", iv.lo, iv.hi);
    assert!((v - 0.05).abs() <= 0.0015, "{v} {iv:?}");
    assert_eq!(d.verdict, Verdict::Explained);
    assert_roads_recovered(&d);
}

/// `vehsim synth --roads`: one bank_deg:grade_deg pair per manoeuvre, with `--effect road` and no
/// `--params`; anything else is a usage error (exit 2) naming `--roads` and what is allowed, and
/// writes nothing.
#[test]
fn bad_roads_are_refused() {
    let dir = common::temp_dir("road-per-run-bad");
    let sedan = common::root().join("vehicles/sedan.toml");
    let out = dir.join("runs");
    let base = ["synth", "--vehicle", sedan.to_str().unwrap(), "--out", out.to_str().unwrap()];
    for (extra, needle) in [
        (
            &["--effect", "road", "--maneuvers", "sine_ice,sine_dry", "--roads", "1:1"][..],
            "give one pair per manoeuvre",
        ),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "1"][..], "is not bank_deg:grade_deg"),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "x:1"][..], "is not a finite number"),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "nan:1"][..], "is not a finite number"),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "36:0"][..], "[-35, 35]"),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "0:-21"][..], "[-20, 20]"),
        (&["--effect", "road", "--maneuvers", "sine_ice", "--roads", "0:10"][..], "mu 0.15"),
        (&["--effect", "sensor_bias", "--maneuvers", "sine_ice", "--roads", "1:1"][..], "go with --effect road"),
        (
            &["--effect", "road", "--params", "bank_deg=1", "--maneuvers", "sine_ice", "--roads", "1:1"][..],
            "no --params",
        ),
    ] {
        let args: Vec<&str> = base.iter().copied().chain(extra.iter().copied()).collect();
        let (code, _, err) = common::vehsim(&dir, &args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("--roads") && err.contains(needle), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?}");
    }
}

/// The loop through the CLI: `vehsim synth --roads` writes runs on their own roads, `vehsim
/// discover` names `road (per_run)` and writes roads.toml; each run's `[road]` from it appended
/// to its sidecar, a second `vehsim discover` finds nothing missing.
#[test]
fn the_cli_writes_roads_toml_and_the_sidecars_close_the_loop() {
    let dir = common::temp_dir("road-per-run-cli");
    let sedan = common::root().join("vehicles/sedan.toml");
    let sedan = sedan.to_str().unwrap();
    let roads: Vec<String> = ROADS.iter().map(|(b, g)| format!("{b}:{g}")).collect();
    let csvs = common::synth_runs_with(
        &dir,
        &["--effect", "road", "--maneuvers", &SIX.join(","), "--roads", &roads.join(",")],
    );
    assert_eq!(csvs.len(), SIX.len());
    let discover = |out: &str| {
        let mut args = vec!["discover", "--quiet", "--vehicle", sedan, "--out", out];
        args.extend(csvs.iter().map(|p| p.to_str().unwrap()));
        let (code, _, err) = common::vehsim(&dir, &args);
        assert_eq!(code, 0, "{err}");
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("report.json")).unwrap()).unwrap();
        report
    };
    let report = discover("d1");
    assert_eq!(report["named_effects"], serde_json::json!(["road (per_run)"]), "{}", report["named_effects"]);
    assert_eq!(report["verdict"], "explained");
    assert_eq!(report["road_per_run"]["chosen"], "road (per_run)");
    let text = std::fs::read_to_string(dir.join("d1/roads.toml")).unwrap();
    // Each `# NAME.toml` section of roads.toml appended to that run's sidecar.
    let mut appended = 0;
    for section in text.split("\n# ") {
        let Some((file, table)) = section.split_once('\n').filter(|(f, _)| f.ends_with(".toml")) else {
            continue; // the header's comment lines
        };
        appended += 1;
        let side = dir.join("runs").join(file.trim());
        let mut s = std::fs::read_to_string(&side).unwrap();
        s.push('\n');
        s.push_str(table);
        std::fs::write(&side, s).unwrap();
    }
    assert_eq!(appended, SIX.len(), "{text}");
    let again = discover("d2");
    assert_eq!(again["verdict"], "nothing_missing", "{}", again["named_effects"]);
    assert!(!dir.join("d2/roads.toml").exists());
}

/// The per-run intervals' calibration: the roads of [`ROADS`] over seeds 1 to 6, the `road`
/// candidate alone (then the step), 72 intervals (a bank and a grade per run and seed). With
/// calibrated 95 % intervals fewer than 63 would cover their truth with probability 0.3 %
/// (binomial, 72, 0.95). Measured: 68 of 72 (bank 34, grade 34 of 36); the errors over their
/// standard errors have sd 1.05 (bank) and 0.86 (grade), mean -0.03 and -0.06, largest |z| 2.41.
#[test]
#[ignore = "long (six discoveries, about 60 s); run by scripts/test-long.sh"]
fn per_run_intervals_cover_the_truth() {
    let mut covered = [0usize; 2];
    let mut total = 0;
    for seed in 1..7 {
        let runs = runs_on_roads(&EffectParams::default(), seed);
        let d = discover_from(&model(), &Dataset::new(runs), EffectParams::default(), &[Effect::Road]);
        let roads = d.run_roads().unwrap_or_else(|| panic!("seed {seed}: {}", d.named_text()));
        for (r, &(bank, grade)) in roads.iter().zip(&ROADS) {
            for (k, (v, iv, truth)) in
                [(r.bank_deg, r.intervals[0], bank), (r.grade_deg, r.intervals[1], grade)].into_iter().enumerate()
            {
                let z = (v - truth) / iv.std_error;
                eprintln!("seed {seed} {} {}: {v:.4} (se {:.4}), z {z:+.2}", r.run, ["bank", "grade"][k], iv.std_error);
                covered[k] += usize::from(iv.lo <= truth && truth <= iv.hi);
            }
            total += 1;
        }
    }
    eprintln!("covered: bank {} of {total}, grade {} of {total}", covered[0], covered[1]);
    assert!(covered[0] + covered[1] >= 63, "{covered:?} of {total} each");
}
