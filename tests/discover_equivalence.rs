//! What the data cannot tell apart (`discover::equivalence`): in the tyres' linear range a steer
//! compliance c (rad/N) acting through the front axle force is the same as a front cornering
//! stiffness lowered to C_f / (1 + c C_f): with F_f = C_f (delta - c F_f - beta_f),
//! F_f = C_f / (1 + c C_f) (delta - beta_f). One gentle sine steer on dry asphalt therefore cannot
//! tell the two apart; a manoeuvre into the non-linear range (or on a surface of other stiffness)
//! can. The expected front scale comes from that closed form and the tyre's own slope, never from
//! the code under test.

mod common;

use vehsim::discover::model::{EffectParams, ReplayModel};
use vehsim::discover::select::Verdict;
use vehsim::discover::{discover, load_vehicle, synth, tyre_kind, Dataset, Discovery, Effect};
use vehsim_core::tyre::TyreInput;

fn model() -> ReplayModel {
    let v = load_vehicle(&common::root().join("vehicles/sedan.toml"), None, tyre_kind("pacejka").unwrap()).unwrap();
    ReplayModel::new(v)
}

/// Runs of the `ids` manoeuvres with the steer compliance of `synth`'s defaults, noise `seed`.
fn runs(m: &ReplayModel, ids: &[&str], seed: u64) -> Vec<vehsim::discover::measured::MeasuredRun> {
    let mut p = EffectParams::default();
    Effect::SteerCompliance.apply(&mut p, &synth::default_params(Effect::SteerCompliance));
    let ids: Vec<String> = ids.iter().map(|s| s.to_string()).collect();
    let plan = synth::select(&ids).unwrap();
    synth::generate_plan(m, &p, seed, &plan).into_iter().map(|r| r.0).collect()
}

/// The front axle's cornering stiffness at its static load, N/rad (central difference of the
/// tyre's own lateral force at +-0.1 mrad, two tyres).
fn front_axle_stiffness(m: &ReplayModel) -> f64 {
    let v = &m.vehicle;
    let fz = 0.5 * v.static_axle_loads_n().0;
    let fy = |a: f64| v.tyre.mounted[0].forces(&TyreInput::new(fz, 0.0, a, 1.0)).fy_n;
    2.0 * ((fy(1e-4) - fy(-1e-4)) / 2e-4).abs()
}

fn discover_runs(m: &ReplayModel, runs: Vec<vehsim::discover::measured::MeasuredRun>) -> Discovery {
    discover(m, &Dataset::new(runs), &Effect::TRIED)
}

#[test]
fn compliance_and_front_stiffness_are_one_class_until_the_proposed_runs_split_it() {
    let m = model();
    let d = discover_runs(&m, runs(&m, &["gentle_sine_dry"], 1));
    assert_eq!(d.named, vec![Effect::SteerCompliance], "rejected {:?}", d.rejected);
    assert_eq!(d.verdict, Verdict::ExplainedEquivalent);
    assert_eq!(d.verdict.as_str(), "explained (equivalent forms)");
    let class = &d.classes[0];
    let stiffness = class.members.iter().find(|e| e.effect == Effect::AxleStiffness);
    let stiffness = stiffness.unwrap_or_else(|| panic!("axle_cornering_stiffness not in {}", class.text()));
    // The equivalent front scale of the closed form, from the generating compliance (rad/kN).
    let c = synth::default_params(Effect::SteerCompliance)[0] * 1e-3;
    let expected = 1.0 / (1.0 + c * front_axle_stiffness(&m));
    let (front, rear) = (stiffness.values[0], stiffness.values[1]);
    eprintln!("{}; front scale {front:.4} (closed form {expected:.4}), rear {rear:.4}", class.text());
    assert!((front - expected).abs() <= 0.05 * expected, "front scale {front}, closed form {expected}");
    assert!((rear - 1.0).abs() <= 0.05, "rear scale {rear}");
    // The equivalent is refitted jointly and carries its own intervals, around its values.
    assert_eq!(stiffness.intervals.len(), 2);
    for (v, iv) in stiffness.values.iter().zip(&stiffness.intervals) {
        eprintln!("  {v:.4} (95 %: {:.4} to {:.4})", iv.lo, iv.hi);
        assert!(iv.lo <= *v && *v <= iv.hi && iv.hi - iv.lo < 0.2, "{v} outside or loose {iv:?}");
    }
    assert!(stiffness.intervals[0].contains(expected), "closed form {expected} outside {:?}", stiffness.intervals[0]);
    // The gentle run itself separates nothing; the proposal does, well above the noise.
    let gentle = class.separations.iter().find(|s| s.maneuver == "gentle_sine_dry").unwrap();
    let proposal = class.proposal();
    eprintln!("proposed {} ({:.1} x noise); gentle_sine_dry {:.3}", proposal.maneuver, proposal.class, gentle.class);
    assert!(gentle.class < 0.1, "the gentle run separates the class by {}", gentle.class);
    assert!(proposal.class > 3.0, "proposal {} separates by {} only", proposal.maneuver, proposal.class);

    // Runs of the proposed manoeuvre (other noise) added: the class splits.
    let mut more = runs(&m, &["gentle_sine_dry"], 1);
    more.extend(runs(&m, &[proposal.maneuver], 2));
    let d2 = discover_runs(&m, more);
    assert_eq!(d2.named, vec![Effect::SteerCompliance], "rejected {:?}", d2.rejected);
    assert!(d2.classes.is_empty(), "still a class: {}", d2.classes[0].text());
    assert_eq!(d2.verdict, Verdict::Explained);
}

#[test]
fn synth_refuses_an_unknown_manoeuvre_naming_the_allowed_ones() {
    let e = synth::select(&["figure_eight".to_string()]).unwrap_err().to_string();
    assert!(e.contains("--maneuvers") && e.contains("figure_eight") && e.contains("gentle_sine_dry"), "{e}");
    // No ids: the default set, unchanged.
    let all = synth::select(&[]).unwrap();
    assert_eq!(all.len(), synth::DEFAULT_PLAN);
    assert_eq!(all[0].id, "sine_ice");
}
