//! The discovery on the real Stanford race lap: the first 90 s of the measured lap shipped in
//! tests/data/stanford (README there: source, trim and licence). There is no ground truth: the
//! test checks that conversion and discovery run end to end, that an accepted effect lowers the
//! held-out error, and that it also explains the logged lateral velocity (an independent
//! measurement the fit barely weighs). It fails when the data are missing.

mod common;

use std::path::Path;

use vehsim::discover::model::ReplayModel;
use vehsim::discover::{discover, load_vehicle, measured, stanford, tyre_kind, Dataset, Effect};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/stanford/20140222_01_01_03_250lm");

#[test]
fn stanford_lap_converts_and_discovery_runs() {
    assert!(
        Path::new(DATA).join("t.txt").exists(),
        "the Stanford excerpt is missing at {DATA}: it ships with the project"
    );
    let dir = common::temp_dir("stanford");
    let files = stanford::convert(Path::new(DATA), &dir, 15.0, 6).unwrap();
    assert_eq!(files.len(), 6);
    let runs: Vec<_> = files.iter().map(|f| measured::read_run(f).unwrap()).collect();
    // yawRate is in rad/s (|r| < 0.7 over the lap) and matches ay / vx to within the README's 0.974 correlation.
    assert!(runs.iter().all(|r| r.yaw_rate.iter().all(|v| v.abs() < 0.7)));
    assert_eq!(runs[0].t.len(), 1500);
    let car = common::root().join("tests/data/discover/stanford/car.toml");
    let m = ReplayModel::new(load_vehicle(&car, None, tyre_kind("linear").unwrap()).unwrap());
    let data = Dataset::new(runs);
    let d = discover(&m, &data, &Effect::TRIED);
    println!(
        "Stanford, 6 x 15 s: named {:?}, verdict {}, held-out yaw-rate RMS {:.4} -> {:.4} rad/s",
        d.named,
        d.verdict,
        d.baseline.rmse(true).yaw_rate_radps,
        d.final_scores.rmse(true).yaw_rate_radps
    );
    assert!(d.final_scores.rmse(true).yaw_rate_radps <= d.baseline.rmse(true).yaw_rate_radps);
    // The lap logs the INS's lateral velocity, scored on its increments over 1 s windows (a few
    // dozen windows beside 18 000 samples of yaw rate and a_y, so it barely steers the fit): the
    // effects named from yaw rate and a_y must bring the measured sideslip's increments most of
    // the way to its noise in both folds (measured 16.9 -> 0.93 and 40.8 -> 1.59).
    for (i, f) in d.folds.iter().enumerate() {
        let (Some(b), Some(a)) = (f.baseline_increment_noise_ratio[2], f.final_increment_noise_ratio[2]) else {
            panic!("fold {}: the logged vy was not scored", i + 1)
        };
        println!("fold {}: lateral velocity increments, RMS / noise {b:.2} -> {a:.2}", i + 1);
        assert!(a <= 0.1 * b, "fold {}: lateral velocity {b:.2} -> {a:.2}", i + 1);
        assert!(f.final_increment_noise_ratio[0].is_none(), "no heading is logged");
    }
    for s in &d.steps {
        eprintln!(
            "step {}: {:?}; held-out yaw {:.5} -> {:.5}, ay {:.5} -> {:.5}; {}",
            s.effect.label(),
            s.params,
            s.heldout_rmse_before.yaw_rate_radps,
            s.heldout_rmse_after.yaw_rate_radps,
            s.heldout_rmse_before.ay_mps2,
            s.heldout_rmse_after.ay_mps2,
            s.evidence
        );
    }
    for s in &d.steps {
        assert!(s.heldout_rmse_after.yaw_rate_radps < s.heldout_rmse_before.yaw_rate_radps);
    }
    // Every effect named is significant in the final joint fit (on this lap the sensitive load
    // transfer was accepted in round 3 and loses its interval in the final fit: it is dropped).
    let finals: Vec<_> = d.final_effects.iter().map(|f| f.effect).collect();
    assert_eq!(finals, d.named);
    assert!(d.final_effects.iter().all(|f| f.significant), "{:?}", d.final_effects);
    assert!(!d.named.is_empty());
}
