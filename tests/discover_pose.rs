//! The logged pose as evidence (`discover::pose`): a run that logs its heading and position is
//! scored on their increments over windows as well as on yaw rate and a_y.
//!
//! Known answer: on a gentle sine steer (the tyres' linear range) an equal latency of both inertial
//! channels (yaw rate and a_y arrive 0.05 s late) and a first-order steering lag of 0.05 s delay
//! the logged yaw rate and a_y almost alike, and yaw rate and a_y alone rank the steering lag
//! first. The logged heading and position are not delayed by the instruments, but are by a
//! steering lag (the car itself turns later), so with them discovery names the latency. The
//! converse set (a steering lag hidden) stays a steering lag; a set with nothing hidden stays
//! `nothing_missing` with the pose's windows at the noise, whose level is estimated to within
//! 15 % of the generator's (`synth::POSE_NOISE`).

mod common;

use vehsim::discover::model::{EffectParams, ReplayModel};
use vehsim::discover::select::pose_noise_limit;
use vehsim::discover::{discover, load_vehicle, synth, tyre_kind, Dataset, Discovery, Effect};

fn model() -> ReplayModel {
    ReplayModel::new(
        load_vehicle(&common::root().join("vehicles/sedan.toml"), None, tyre_kind("pacejka").unwrap()).unwrap(),
    )
}

/// Runs of the manoeuvres `ids` with `e` at `values` hidden, logging the pose, noise `seed`.
fn posed_runs(
    m: &ReplayModel,
    e: Option<(Effect, &[f64])>,
    ids: &[&str],
    seed: u64,
) -> Vec<vehsim::discover::measured::MeasuredRun> {
    let mut p = EffectParams::default();
    if let Some((e, v)) = e {
        e.apply(&mut p, v);
    }
    let ids: Vec<String> = ids.iter().map(|s| s.to_string()).collect();
    synth::generate_plan_posed(m, &p, seed, &synth::select(&ids).unwrap()).into_iter().map(|r| r.0).collect()
}

fn value(d: &Discovery, e: Effect, i: usize) -> (f64, f64, f64) {
    let f = d.final_effects.iter().find(|f| f.effect == e).unwrap_or_else(|| panic!("{} not named", e.label()));
    (f.params[i].1, f.intervals[i].lo, f.intervals[i].hi)
}

/// Every fold scored the pose, and left each pose channel within its limit.
fn assert_pose_at_noise(d: &Discovery) {
    for (i, f) in d.folds.iter().enumerate() {
        for c in 0..2 {
            let r = f.final_pose_noise_ratio[c].unwrap_or_else(|| panic!("fold {} scored no pose channel {c}", i + 1));
            let lim = pose_noise_limit(f.pose_windows[c]);
            assert!(r <= lim, "fold {} pose channel {c}: RMS / noise {r:.2} above its limit {lim:.2}", i + 1);
        }
    }
}

#[test]
fn the_logged_heading_tells_a_sensor_latency_from_a_steering_lag() {
    let m = model();
    let runs = posed_runs(&m, Some((Effect::SensorLatency, &[0.05, 0.05])), &["gentle_sine_dry"], 1);
    assert!(runs[0].channel("psi").is_some() && runs[0].channel("x").is_some() && runs[0].channel("y").is_some());

    // The premise: without the pose, yaw rate and a_y rank the steering lag first.
    let mut bare = runs.clone();
    bare.iter_mut().for_each(|r| r.optional.clear());
    let d = discover(&m, &Dataset::new(bare), &Effect::TRIED);
    assert_eq!(d.named.first(), Some(&Effect::SteerLag), "without the pose: {:?}", d.named);

    let d = discover(&m, &Dataset::new(runs), &Effect::TRIED);
    assert_eq!(d.named, vec![Effect::SensorLatency], "with the pose; rejected {:?}", d.rejected.len());
    assert!(d.verdict.at_noise(), "verdict {}", d.verdict.as_str());
    let (yaw, lo, hi) = value(&d, Effect::SensorLatency, 0);
    eprintln!("yaw-rate latency {yaw:.5} s ({lo:.5} to {hi:.5})");
    assert!(lo <= 0.05 && 0.05 <= hi, "yaw-rate latency {yaw} ({lo} to {hi}), hidden 0.05");
    // The a_y latency's interval is too narrow on this gentle steer (docs/discover.md, "The logged
    // pose": the linear interpolation of the delay smooths the steer noise in the replayed a_y,
    // pulling the fit half a sample off); its value is within 10 %.
    let (ay, lo, hi) = value(&d, Effect::SensorLatency, 1);
    eprintln!("a_y latency {ay:.5} s ({lo:.5} to {hi:.5})");
    assert!((ay - 0.05).abs() <= 0.005, "a_y latency {ay}, hidden 0.05");
    assert_pose_at_noise(&d);
}

#[test]
fn a_steering_lag_stays_a_steering_lag_with_the_pose() {
    let m = model();
    let runs = posed_runs(&m, Some((Effect::SteerLag, &[0.05])), &["gentle_sine_dry"], 1);
    let d = discover(&m, &Dataset::new(runs), &Effect::TRIED);
    assert_eq!(d.named, vec![Effect::SteerLag]);
    let (lag, lo, hi) = value(&d, Effect::SteerLag, 0);
    eprintln!("steering lag {lag:.5} s ({lo:.5} to {hi:.5})");
    assert!(lo <= 0.05 && 0.05 <= hi, "steering lag {lag} ({lo} to {hi}), hidden 0.05");
    assert!(d.verdict.at_noise(), "verdict {}", d.verdict.as_str());
    assert_pose_at_noise(&d);
}

#[test]
fn nothing_hidden_leaves_the_pose_at_its_estimated_noise() {
    let m = model();
    let runs = posed_runs(&m, None, &["gentle_sine_dry", "step_dry", "sine_ice"], 2);
    let data = Dataset::new(runs);
    for (r, n) in data.runs.iter().zip(&data.noise) {
        let p = n.pose.unwrap_or_else(|| panic!("{}: no pose noise", r.name));
        let pos = p.position_m.unwrap_or_else(|| panic!("{}: no position noise", r.name));
        let [psi0, pos0] = synth::POSE_NOISE;
        eprintln!("{}: heading noise {:.3e} rad, position {pos:.3e} m", r.name, p.psi_rad);
        assert!((p.psi_rad / psi0 - 1.0).abs() <= 0.15, "{}: heading noise {} (generated {psi0})", r.name, p.psi_rad);
        assert!((pos / pos0 - 1.0).abs() <= 0.15, "{}: position noise {pos} (generated {pos0})", r.name);
    }
    let d = discover(&m, &data, &Effect::TRIED);
    assert!(d.named.is_empty(), "named {:?}", d.named);
    assert_eq!(d.verdict.as_str(), "nothing_missing");
    assert_pose_at_noise(&d);
}

#[test]
fn synth_writes_the_pose_and_discover_reports_it() {
    let dir = common::temp_dir("discover_pose_cli");
    let runs = common::synth_runs_with(
        &dir,
        &[
            "--effect",
            "sensor_latency",
            "--params",
            "latency_yaw_rate_s=0.05",
            "latency_ay_s=0.05",
            "--maneuvers",
            "gentle_sine_dry",
            "--pose",
        ],
    );
    assert_eq!(runs.len(), 1);
    let text = std::fs::read_to_string(&runs[0]).unwrap();
    assert_eq!(text.lines().next(), Some("t,steer,vx,yaw_rate,ay,x,y,psi"));
    // A wrapped heading: every logged value within +-pi.
    let psi: Vec<f64> = text.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect();
    assert!(psi.iter().all(|a| a.abs() <= std::f64::consts::PI), "heading beyond +-pi");
    let out = dir.join("d");
    let (code, stdout, stderr) = common::vehsim(
        &dir,
        &[
            "discover",
            "--vehicle",
            common::root().join("vehicles/sedan.toml").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            runs[0].to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("logged pose over 1 s windows: heading"), "{stdout}");
    assert!(stdout.contains("verdict: explained"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(report["named_effects"][0], "sensor_latency", "{}", report["named_effects"]);
    let psi_noise = report["noise"][0]["psi_rad"].as_f64().expect("noise.psi_rad");
    assert!((psi_noise / synth::POSE_NOISE[0] - 1.0).abs() <= 0.15, "heading noise {psi_noise}");
    for f in report["folds"].as_array().unwrap() {
        assert_eq!(f["final_pose_noise_ratio"].as_array().map(Vec::len), Some(2), "{f}");
        assert_eq!(f["pose_windows"].as_array().map(Vec::len), Some(2), "{f}");
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("The logged pose, scored on its increments"), "report.md has no pose table");
}
