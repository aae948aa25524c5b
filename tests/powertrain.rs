//! The powertrain, differentials, ABS and traction control (docs/powertrain.md): the launch and
//! the ABS stop on mu 0.15 ice against their closed-form limits, the locked-wheel stop, the range
//! checks, the old single torque limit as a special case of the powertrain, and bad input.
//!
//! Bounds that involve ice friction are relative to the tyre's own peak friction computed at run
//! time (the ice friction law may move), never to fixed numbers.

mod common;

use vehsim_core::sim::Row;
use vehsim_core::tyre::{TyreInput, TyreModelKind};
use vehsim_core::vehicle::wheel::V_LOW;
use vehsim_core::vehicle::GRAVITY;
use vehsim_spec::run::{execute, RunOutput};
use vehsim_spec::RunConfig;

const LAUNCH: &str = "maneuvers/traction/launch_ice_tcs.toml";
const BRAKING: &str = "maneuvers/traction/braking_50kmh_ice_abs.toml";

fn load_with(spec: &str, tyre: TyreModelKind, edit: impl FnOnce(&mut vehsim_spec::ManeuverFile)) -> RunConfig {
    let path = common::root().join(spec);
    let mut f = vehsim_spec::ManeuverFile::load(&path).unwrap();
    f.tyre_model = tyre.as_str().to_string();
    edit(&mut f);
    f.build(&path).unwrap()
}

fn result(out: &RunOutput, key: &str) -> f64 {
    out.results.as_ref().and_then(|r| r[key].as_f64()).unwrap_or_else(|| panic!("no {key} in {:?}", out.results))
}

/// The kinematic slip of an axle in a row, kappa = (omega R - v) / max(|v|, V_LOW) (the
/// bicycle's rear axle is not steered; the front runs straight in these manoeuvres).
fn kinematic_slip(row: &Row, axle: usize, radius: f64) -> f64 {
    let v = row.obs.kin.vx_mps;
    (row.obs.omega_radps[axle] * radius - v) / v.abs().max(V_LOW)
}

/// An axle's peak |F_x| (N) over slip of sign `sign` (+1 driving, -1 braking) in 0.001 steps
/// to 1, its two tyres at half the axle load `fz_axle` (N), at speed `v` (m/s), contact at the
/// surface temperature.
fn axle_peak_force(cfg: &RunConfig, fz_axle: f64, v: f64, sign: f64) -> f64 {
    let tyre = &cfg.vehicle.tyre.model;
    let peak = (1..=1000)
        .map(|k| {
            let input = TyreInput {
                fz_n: 0.5 * fz_axle,
                kappa: sign * k as f64 * 1e-3,
                alpha_rad: 0.0,
                camber_rad: 0.0,
                vx_mps: v,
                mu_surface: cfg.env.mu,
                surface_temp_c: cfg.env.surface_temp_c,
                contact_temp_c: cfg.env.surface_temp_c,
            };
            tyre.forces(&input).fx_n.abs()
        })
        .fold(0.0, f64::max);
    2.0 * peak
}

/// The largest longitudinal deceleration (m/s^2) the tyres allow the vehicle at its static
/// loads on the run's surface: each axle's peak |F_x| over braking slip (its tyres at half the
/// static axle load, contact at the surface temperature), summed, over the mass; plus the
/// rolling resistance and the drag at the start speed, which also decelerate the car.
fn peak_deceleration(cfg: &RunConfig, v0: f64) -> (f64, f64) {
    let v = &cfg.vehicle;
    let (ff, fr) = v.static_axle_loads_n();
    let force = axle_peak_force(cfg, ff, v0, -1.0) + axle_peak_force(cfg, fr, v0, -1.0);
    let mu_x_peak = force / (v.mass_kg * GRAVITY);
    let resist = v.rolling_resistance * GRAVITY + 0.5 * 1.225 * v.drag_area_m2 * v0 * v0 / v.mass_kg;
    (mu_x_peak, mu_x_peak * GRAVITY + resist)
}

/// The launch on mu 0.15 ice: with traction control the driven wheels' slip (what the tyre sees
/// and the kinematic one) stays under 0.3 at every recorded row and the car reaches the speed no
/// later than without it; without it the wheels spin up and the range check flags the run.
#[test]
fn launch_on_ice_with_and_without_traction_control() {
    for tyre in [TyreModelKind::Pacejka, TyreModelKind::AtiimPacejka] {
        let on = execute(&load_with(LAUNCH, tyre, |_| {}));
        let off_cfg = load_with(LAUNCH, tyre, |f| f.tcs = None);
        let off = execute(&off_cfg);
        let radius = off_cfg.vehicle.tyre.rolling_radius_m;
        // the slip the tyre sees (the model's relaxed slip, the `kappa_front` channel), at every row
        let worst = on.rows.iter().map(|r| r.obs.kappa[0]).fold(f64::NEG_INFINITY, f64::max);
        assert!(worst < 0.3, "{tyre:?}: driven-wheel slip up to {worst} with TCS");
        // the kinematic slip of the wheel speed, once the speed is above the slip's floor V_LOW
        // (below it, in the first tens of milliseconds, a tread speed of 0.15 m/s is a slip of 0.3)
        let worst = on
            .rows
            .iter()
            .filter(|r| r.obs.kin.vx_mps >= V_LOW)
            .map(|r| kinematic_slip(r, 0, radius))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(worst < 0.3, "{tyre:?}: driven-wheel kinematic slip up to {worst} with TCS");
        let (t_on, t_off) = (result(&on, "time_to_speed_s"), result(&off, "time_to_speed_s"));
        assert!(t_on <= t_off, "{tyre:?}: TCS {t_on} s, without {t_off} s");
        // the friction limit: no faster than the driven (front) axle's peak traction allows
        let (ff, _) = off_cfg.vehicle.static_axle_loads_n();
        let a_max = axle_peak_force(&off_cfg, ff, 1.0, 1.0) / off_cfg.vehicle.mass_kg;
        let t_min = result(&on, "target_speed_mps") / a_max;
        assert!(t_on >= t_min, "{tyre:?}: {t_on} s beats the friction limit {t_min} s");
        eprintln!("{tyre:?}: launch to 30 km/h: TCS {t_on:.2} s, without {t_off:.2} s, friction limit {t_min:.2} s");
        assert!(on.summary.plausible, "{tyre:?}: {:?}", on.summary.implausible);
        assert!(!off.summary.plausible, "{tyre:?}: the spinning launch passed the range check");
        assert!(
            off.summary
                .events
                .iter()
                .any(|e| e.kind.as_str() == "slip_ratio_beyond_range" && e.detail.contains("front")),
            "{:?}",
            off.summary.events
        );
    }
}

/// ABS braking from 50 km/h on mu 0.15 ice stops between the friction limit and 1.25 times it
/// (using at least 80 % of the tyres' peak), shorter than the locked-wheel stop, and no wheel
/// stays locked longer than one ABS cycle (above the ABS cut-out speed).
#[test]
fn abs_stop_on_ice_against_the_friction_limit() {
    for tyre in [TyreModelKind::Pacejka, TyreModelKind::AtiimPacejka] {
        let cfg = load_with(BRAKING, tyre, |_| {});
        let abs = execute(&cfg);
        let locked = execute(&load_with(BRAKING, tyre, |f| f.abs = None));
        let v0 = result(&abs, "speed_at_onset_mps");
        let v_end = result(&abs, "end_speed_mps");
        let (mu_x, a_limit) = peak_deceleration(&cfg, v0);
        let d_min = (v0 * v0 - v_end * v_end) / (2.0 * a_limit);
        let d_friction = (v0 * v0 - v_end * v_end) / (2.0 * mu_x * GRAVITY);
        let d = result(&abs, "braking_distance_m");
        assert!(d >= d_min, "{tyre:?}: {d} m is shorter than the limit {d_min} m");
        assert!(d <= 1.25 * d_friction, "{tyre:?}: {d} m is beyond 1.25 x v^2/(2 mu_x,peak g) = {d_friction} m");
        let d_locked = result(&locked, "braking_distance_m");
        assert!(d < d_locked, "{tyre:?}: ABS {d} m, locked {d_locked} m");
        assert!(abs.summary.plausible, "{:?}", abs.summary.implausible);
        // lock episodes (kinematic slip below -0.9) against the ABS cycle (the interval between
        // successive crossings of the dump threshold), above the cut-out speed
        let p = cfg.slip.abs.unwrap();
        let radius = cfg.vehicle.tyre.rolling_radius_m;
        for axle in 0..2 {
            let (mut start, mut longest, mut crossings) = (None, 0.0_f64, Vec::new());
            let mut prev = 0.0;
            for r in abs.rows.iter().filter(|r| r.obs.kin.vx_mps > p.cutout_speed_mps) {
                let k = kinematic_slip(r, axle, radius);
                match (k < -0.9, start) {
                    (true, None) => start = Some(r.t_s),
                    (false, Some(t0)) => {
                        longest = longest.max(r.t_s - t0);
                        start = None;
                    }
                    _ => {}
                }
                if k < -p.slip_dump && prev >= -p.slip_dump {
                    crossings.push(r.t_s);
                }
                prev = k;
            }
            assert!(crossings.len() >= 3, "{tyre:?}: axle {axle}: the ABS never cycled");
            let cycle = crossings.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
            assert!(longest < cycle.max(p.period_s), "{tyre:?}: axle {axle} locked for {longest} s (cycle {cycle} s)");
        }
        // the locked stop itself: every wheel slides, at the sliding friction
        let worst = locked
            .rows
            .iter()
            .filter(|r| r.obs.kin.vx_mps > 2.0 && r.t_s > 1.0)
            .map(|r| kinematic_slip(r, 0, radius))
            .fold(f64::INFINITY, f64::min);
        assert!(worst < -0.9, "{tyre:?}: the stop without ABS did not lock ({worst})");
    }
}

/// The old single torque limit is the powertrain's special case: a motor with one ratio of 1,
/// no power cap to speak of, no inertia and an open differential, of torque drive_torque_max_nm,
/// gives the run without a powertrain (the same equations up to rounding).
#[test]
fn single_torque_limit_is_the_special_case() {
    use vehsim_core::vehicle::powertrain::{Differential, GearMode, Powertrain, TorqueSource};
    let base = common::load("maneuvers/quickstart_dlc_ice.toml");
    let mut cfg = base.clone();
    cfg.vehicle.powertrain = Some(Powertrain::new(
        TorqueSource::Motor { torque_max_nm: cfg.vehicle.drive_torque_max_nm, power_max_w: 1e12, speed_max_radps: 1e9 },
        vec![1.0],
        1.0,
        1.0,
        0.0,
        GearMode::Auto,
        Differential::Open,
    ));
    let (a, b) = (execute(&base), execute(&cfg));
    assert_eq!(a.rows.len(), b.rows.len());
    let worst = a
        .rows
        .iter()
        .zip(&b.rows)
        .map(|(p, q)| (p.obs.kin.x_m - q.obs.kin.x_m).abs().max((p.obs.omega_radps[0] - q.obs.omega_radps[0]).abs()))
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst}");
    // and the shipped vehicle with a powertrain: the same car otherwise
    let read =
        |f: &str| -> toml::Table { toml::from_str(&std::fs::read_to_string(common::root().join(f)).unwrap()).unwrap() };
    for (plain, with) in [
        ("vehicles/sedan.toml", "vehicles/sedan_powertrain.toml"),
        ("vehicles/sedan_rwd.toml", "vehicles/sedan_rwd_powertrain.toml"),
    ] {
        let (mut p, mut w) = (read(plain), read(with));
        assert!(w.remove("powertrain").is_some());
        for k in ["name", "tyre"] {
            p.remove(k);
            w.remove(k);
        }
        assert_eq!(p, w, "{with} differs from {plain} beyond its [powertrain] and tyre");
    }
    // the tyre with declared ranges: the same tyre, its .tir the same file plus the range sections
    let (mut p, mut w) =
        (read("vehicles/tyres/srtt_p225_60r16.toml"), read("vehicles/tyres/srtt_p225_60r16_ranged.toml"));
    for t in [&mut p, &mut w] {
        t.remove("name");
        t["pacejka"].as_table_mut().unwrap().remove("tir_file");
    }
    assert_eq!(p, w);
    let data = |f: &str| -> Vec<String> {
        std::fs::read_to_string(common::root().join(f))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('!') && !l.starts_with('$') && !l.trim().is_empty())
            .map(String::from)
            .collect()
    };
    let (plain, ranged) =
        (data("vehicles/tyres/srtt_p225_60r16.tir"), data("vehicles/tyres/srtt_p225_60r16_ranged.tir"));
    let extra: Vec<&String> = ranged.iter().filter(|l| !plain.contains(l)).collect();
    assert_eq!(ranged.len(), plain.len() + extra.len());
    assert_eq!(extra.len(), 6, "{extra:?}");
    assert!(
        extra.iter().all(|l| ["[LONG_SLIP", "KPU", "[VERTICAL_FORCE", "FZM"].iter().any(|k| l.starts_with(k))),
        "{extra:?}"
    );
}

/// The 4-DOF model launches the rear-drive sedan through its limited-slip differential (the
/// differentials' closed forms on split friction are unit tests of crates/vehsim-core/src/vehicle/powertrain.rs).
#[test]
fn four_wheel_launch_through_the_limited_slip_differential() {
    let path = common::root().join(LAUNCH);
    let mut f = vehsim_spec::ManeuverFile::load(&path).unwrap();
    f.vehicle = "../../vehicles/sedan_rwd_powertrain.toml".into();
    f.vehicle_model = Some("roll4dof".into());
    f.tcs = None;
    let cfg = f.build(&path).unwrap();
    assert!(cfg.vehicle.powertrain.is_some());
    let out = execute(&cfg);
    assert!(!out.summary.failed(), "{:?}", out.summary.events);
    assert!(result(&out, "time_to_speed_s") > 0.0);
}

/// Bad input: exit 2, naming the file, the key and what is allowed.
#[test]
fn bad_powertrain_and_slip_control_input() {
    let spec = std::fs::read_to_string(common::root().join(LAUNCH))
        .unwrap()
        .replace("../../vehicles/sedan_powertrain.toml", "sedan.toml");
    let pt = "\n[powertrain]\nkind = \"engine\"\ntorque_curve = [[1000.0, 180.0], [4100.0, 231.0], [6300.0, 200.0]]\n\
              gear_ratios = [3.3, 1.9]\nfinal_drive_ratio = 4.356\n";
    let cases: &[(&str, &str, &str, &str)] = &[
        ("sedan.toml", "[4100.0, 231.0]", "[900.0, 231.0]", "powertrain.torque_curve[1]"),
        ("sedan.toml", "gear_ratios = [3.3, 1.9]", "gear_ratios = [3.3, 0.0]", "powertrain.gear_ratios[1]"),
        ("sedan.toml", "final_drive_ratio = 4.356", "final_drive_ratio = -1.0", "powertrain.final_drive_ratio"),
        (
            "sedan.toml",
            "final_drive_ratio = 4.356",
            "final_drive_ratio = 4.356\ndifferential = \"limited_slip\"\ntorque_bias_ratio = 0.8",
            "powertrain.torque_bias_ratio",
        ),
        ("spec.toml", "\n[tcs]", "\n[tcs]\nperiod_s = 0.0075", "tcs.period_s"),
        ("spec.toml", "\n[tcs]", "\n[tcs]\nslip_high = 1.2", "tcs.slip_high"),
        ("spec.toml", "\n[tcs]", "\n[abs]\nslip_dump = 0.0\n[tcs]", "abs.slip_dump"),
        ("spec.toml", "\n[tcs]", "\n[abs]\nslip_dump = 0.1\nslip_build = 0.2\n[tcs]", "abs.slip_build"),
    ];
    for (n, (file, from, to, key)) in cases.iter().enumerate() {
        let case = common::Case::new(&format!("pt_bad_{n}"), "spec.toml", &spec);
        let tir = "vehicles/tyres/srtt_p225_60r16.tir";
        std::fs::copy(common::root().join(tir), case.dir.join("tyres/srtt_p225_60r16.tir")).unwrap();
        let v = std::fs::read_to_string(case.dir.join("sedan.toml")).unwrap();
        std::fs::write(case.dir.join("sedan.toml"), v + pt).unwrap();
        case.edit(file, from, to);
        let (code, _, err) = case.run(&["validate", "spec.toml"]);
        assert_eq!(code, 2, "{key}: {err}");
        assert!(err.contains(key) && err.contains(file), "{key}: {err}");
        assert!(err.contains("expected") || err.contains("allowed"), "{key}: {err}");
    }
}

/// Braking in a turn on ice: with ABS the steered car keeps its circle (the yaw rate falls with
/// the speed, a kinematic closed form r = v / R for a car on the circle, and the CG stays near
/// it); with the wheels locked it runs wide of where the ABS car is.
#[test]
fn braking_in_a_turn_keeps_the_circle_with_abs() {
    const SPEC: &str = "maneuvers/traction/braking_in_turn_40m_ice_abs.toml";
    let with = execute(&load_with(SPEC, TyreModelKind::Pacejka, |_| {}));
    let without = execute(&load_with(SPEC, TyreModelKind::Pacejka, |f| f.abs = None));
    let r = |o: &RunOutput, k: &str| result(o, k);
    let speed_ratio = r(&with, "speed_at_1s_mps") / r(&with, "speed_at_onset_mps");
    let yaw_ratio = r(&with, "yaw_rate_ratio_at_1s");
    assert!((yaw_ratio / speed_ratio - 1.0).abs() < 0.1, "yaw ratio {yaw_ratio}, speed ratio {speed_ratio}");
    let (dev_abs, dev_locked) = (r(&with, "circle_deviation_at_1s_m"), r(&without, "circle_deviation_at_1s_m"));
    assert!(dev_abs.abs() < 0.2 && dev_locked > dev_abs, "deviation at 1 s: ABS {dev_abs} m, locked {dev_locked} m");
    // on the circle at the onset: r = v / R within 5 %
    let onset = r(&with, "yaw_rate_at_onset_radps") * 40.0 / r(&with, "speed_at_onset_mps");
    assert!((onset - 1.0).abs() < 0.05, "{onset}");
}

/// The shipped braking-distance-versus-ice-temperature sweep: every combination validates; at
/// the coldest, a middle and the warmest ice, for both tyre models, the ABS stop is no shorter
/// than the friction limit of the tyre's own isothermal peak (contact heating only lowers it),
/// shorter than the locked-wheel stop, and with the Pacejka tyre within 1.25 x that limit.
#[test]
fn braking_versus_ice_temperature_sweep() {
    let batch =
        vehsim::batch::load(&common::root().join("maneuvers/traction/braking_50kmh_ice_temperature.toml")).unwrap();
    assert_eq!(batch.runs.len(), 36);
    let param = |r: &vehsim::batch::BatchRun, k: &str| r.params.iter().find(|p| p.0 == k).unwrap().1.clone();
    let mut distances = std::collections::BTreeMap::new();
    for run in &batch.runs {
        let cfg = run.config.as_ref().unwrap();
        let t = param(run, "surface.temperature_c");
        if !["-25.0", "-3.0", "-1.0"].contains(&t.as_str()) {
            continue;
        }
        let out = execute(cfg);
        let d = result(&out, "braking_distance_m");
        let v0 = result(&out, "speed_at_onset_mps");
        let v_end = result(&out, "end_speed_mps");
        let (mu_x, a_limit) = peak_deceleration(cfg, v0);
        assert!(d >= (v0 * v0 - v_end * v_end) / (2.0 * a_limit), "{:?}: {d} m", run.params);
        let abs = param(run, "abs.enabled") == "true";
        if abs && cfg.tyre_model == TyreModelKind::Pacejka {
            assert!(d <= 1.25 * (v0 * v0 - v_end * v_end) / (2.0 * mu_x * GRAVITY), "{:?}: {d} m", run.params);
        }
        distances.insert((param(run, "tyre_model"), t, abs), d);
    }
    assert_eq!(distances.len(), 12);
    for ((tyre, t, abs), d) in &distances {
        if *abs {
            let locked = distances[&(tyre.clone(), t.clone(), false)];
            assert!(*d < locked, "{tyre} at {t} degC: ABS {d} m, locked {locked} m");
        }
    }
}
