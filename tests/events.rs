//! Unphysical conditions are reported as events with time and cause, at step resolution, once at
//! onset and once at recovery: wheel lift and touch-down of the 4-DOF model (a high-CG car in hard
//! steering on a dry road), a negative axle load from longitudinal transfer (the same car braking
//! hard on high friction), and nothing for runs that stay physical or for the bicycle, whose loads
//! are static.

mod common;

use vehsim_core::event::{Event, EventKind};
use vehsim_spec::run::{execute, RunOutput};
use vehsim_spec::RunConfig;

const WHEELS: [&str; 4] = ["front-left wheel", "front-right wheel", "rear-left wheel", "rear-right wheel"];

/// The sedan (front drive) with `vehicle_edits` and a spec for it; every step recorded.
fn case(tag: &str, vehicle_edits: &[(&str, &str)], model: &str, mu: f64, maneuver: &str, duration: f64) -> RunConfig {
    let spec = format!(
        "name = \"{tag}\"\nvehicle = \"sedan.toml\"\ntyre_model = \"polynomial\"\nvehicle_model = \"{model}\"\n\
         duration_s = {duration}\n[surface]\nmu = {mu}\n[maneuver]\n{maneuver}\n"
    );
    let c = common::Case::new(tag, "spec.toml", &spec);
    for (from, to) in vehicle_edits {
        c.edit("sedan.toml", from, to);
    }
    let mut cfg = vehsim_spec::run::load(&c.dir.join("spec.toml")).unwrap_or_else(|e| panic!("{tag}: {e}"));
    cfg.settings.output_interval_s = cfg.settings.step_s;
    cfg
}

const HIGH_CG: [(&str, &str); 1] = [("cg_height_m = 0.55", "cg_height_m = 1.1")];

fn of_kind<'a>(out: &'a RunOutput, kinds: &[EventKind]) -> Vec<&'a Event> {
    out.summary.events.iter().filter(|e| kinds.contains(&e.kind)).collect()
}

/// The recorded row at time `t` (every step is recorded).
fn row_at(out: &RunOutput, t: f64) -> &vehsim_core::sim::Row {
    out.rows.iter().find(|r| (r.t_s - t).abs() < 1e-9).unwrap_or_else(|| panic!("no row at {t}"))
}

/// The value at the end of a detail, `... -523.4 N`.
fn value_of(detail: &str) -> f64 {
    let mut it = detail.rsplit(' ');
    assert_eq!(it.next(), Some("N"), "{detail}");
    it.next().unwrap().parse().unwrap()
}

/// A high-CG 4-DOF car in a large sine steer on a dry road lifts its inner wheels in each half of the
/// sine and sets them down in between. Each lift and each touch-down is one event at the first step
/// that shows it (the load at that step is 0 after a positive load one step earlier, and the other
/// way round), naming the wheel and its load before clamping (negative at lift, positive at
/// touch-down); per wheel the events alternate, lift first; left wheels lift in the left turn.
#[test]
fn wheel_lift_and_contact_are_reported_at_the_step_with_wheel_and_load() {
    let sine = "kind = \"sine_steer\"\nspeed_mps = 15.0\nsteer_amplitude_deg = 8.0\nperiod_s = 4.0\nstart_s = 0.5";
    let cfg = case("lift", &HIGH_CG, "roll4dof", 1.0, sine, 4.5);
    let h = cfg.settings.step_s;
    let out = execute(&cfg);
    assert!(!out.summary.failed(), "{:?}", out.summary.events);
    let ev = of_kind(&out, &[EventKind::WheelLift, EventKind::WheelContact]);
    eprintln!("{:#?}", ev);
    assert!(ev.len() >= 4, "expected lifts and touch-downs on both sides: {ev:?}");
    assert!(ev.len() <= 16, "events flood: {ev:?}");
    for (i, name) in WHEELS.iter().enumerate() {
        let mine: Vec<&&Event> = ev.iter().filter(|e| e.detail.starts_with(name)).collect();
        for (k, e) in mine.iter().enumerate() {
            let lift = k % 2 == 0;
            assert_eq!(e.kind, if lift { EventKind::WheelLift } else { EventKind::WheelContact }, "{name}: {mine:?}");
            let fz_now = row_at(&out, e.t_s).obs.fz_n[i];
            let fz_before = row_at(&out, e.t_s - h).obs.fz_n[i];
            let v = value_of(&e.detail);
            if lift {
                assert!(fz_now == 0.0 && fz_before > 0.0, "{e:?}: load {fz_before} then {fz_now}");
                assert!(v <= 0.0, "{e:?}");
            } else {
                assert!(fz_now > 0.0 && fz_before == 0.0, "{e:?}: load {fz_before} then {fz_now}");
                assert!(v > 0.0 && (v - fz_now).abs() < 0.1, "{e:?}: {fz_now}");
            }
        }
    }
    // Left turn first (positive steer): a left wheel lifts first, during the first half period.
    let first = ev[0];
    assert!(first.kind == EventKind::WheelLift && first.detail.contains("-left wheel"), "{first:?}");
    assert!(first.t_s > 0.5 && first.t_s < 2.5, "{first:?}");
    assert!(
        ev.iter().any(|e| e.kind == EventKind::WheelLift && e.detail.contains("-right wheel") && e.t_s > 2.5),
        "{ev:?}"
    );
    // Events are in time order.
    assert!(out.summary.events.windows(2).all(|w| w[0].t_s <= w[1].t_s));
}

/// The high-CG car braking from 20 m/s to a stop on mu 1.2 decelerates beyond g a / h: the
/// longitudinal transfer exceeds the rear axle's static load, whose computed load goes negative.
/// One `negative_normal_load` names the rear axle and its load, both rear wheels lift at the same
/// step, and the load is restored (`normal_load_restored`, then `wheel_contact`) once the braking
/// eases as the car stops.
#[test]
fn negative_axle_load_under_hard_braking_is_reported_with_axle_and_load() {
    let brake = "kind = \"straight\"\nspeed_schedule = [[0.0, 20.0], [0.5, 20.0], [0.6, 0.0]]";
    let edits = [HIGH_CG[0], ("brake_torque_max_nm = 7000.0", "brake_torque_max_nm = 14000.0")];
    let cfg = case("brake", &edits, "roll4dof", 1.2, brake, 4.0);
    let out = execute(&cfg);
    eprintln!("{:#?}", out.summary.events);
    let neg = of_kind(&out, &[EventKind::NegativeNormalLoad]);
    assert_eq!(neg.len(), 1, "{:?}", out.summary.events);
    let e = neg[0];
    assert!(e.detail.starts_with("rear axle: axle load from longitudinal transfer before clamping"), "{e:?}");
    assert!(value_of(&e.detail) < 0.0 && e.t_s > 0.5, "{e:?}");
    // Both rear wheels lift at that step, and they carry nothing in its row.
    for w in ["rear-left wheel", "rear-right wheel"] {
        assert!(
            out.summary
                .events
                .iter()
                .any(|x| x.kind == EventKind::WheelLift && x.detail.starts_with(w) && x.t_s <= e.t_s),
            "{w}: {:?}",
            out.summary.events
        );
    }
    let row = row_at(&out, e.t_s);
    assert!(row.obs.fz_n[2] == 0.0 && row.obs.fz_n[3] == 0.0, "{:?}", row.obs.fz_n);
    let back = of_kind(&out, &[EventKind::NormalLoadRestored]);
    assert_eq!(back.len(), 1, "{:?}", out.summary.events);
    assert!(back[0].t_s > e.t_s && value_of(&back[0].detail) >= 0.0, "{back:?}");
}

/// Runs that stay physical gain no events: the shipped 4-DOF double lane change on ice, and the
/// bicycle (static loads) in the same hard sine steer that lifts the 4-DOF car's wheels.
#[test]
fn physical_runs_and_the_bicycle_report_nothing_new() {
    let out = execute(&common::load("maneuvers/dlc_roll4dof.toml"));
    let kinds = [
        EventKind::WheelLift,
        EventKind::WheelContact,
        EventKind::NegativeNormalLoad,
        EventKind::NormalLoadRestored,
        EventKind::EventsSuppressed,
    ];
    assert!(of_kind(&out, &kinds).is_empty(), "{:?}", out.summary.events);
    let sine = "kind = \"sine_steer\"\nspeed_mps = 15.0\nsteer_amplitude_deg = 8.0\nperiod_s = 4.0\nstart_s = 0.5";
    let out = execute(&case("bicycle", &HIGH_CG, "bicycle", 1.0, sine, 4.5));
    assert!(of_kind(&out, &kinds).is_empty(), "{:?}", out.summary.events);
}
