//! Discovery closes its loop: every effect it names is written as spec keys (`[lateral]` and
//! `[sensors]` of the improved vehicle.toml), and that spec, replayed as a new baseline over the
//! same measured runs, reproduces the discovery's final gap to 1e-9; `vehsim run` accepts it.
//!
//! Each case hides one effect in synthetic runs (`synth::generate_plan`, the replay model with the
//! generating parameters), lets the discovery fit only that candidate (cheap), writes the improved
//! spec with the function `vehsim discover` writes it with, loads it back through the spec layer
//! and replays. The expected gap is the discovery's own final RMSE; what is checked is that the
//! spec carries every fitted value (a key dropped, renamed, rounded or not read back moves the
//! RMSE by far more than 1e-9).

mod common;

use std::path::{Path, PathBuf};

use vehsim::discover::model::{EffectParams, ReplayModel};
use vehsim::discover::report::improved_vehicle_toml;
use vehsim::discover::search::discover_from;
use vehsim::discover::{baseline_for, load_vehicle, synth, tyre_kind, Dataset, DiscoverOptions, Discovery, Effect};
use vehsim_core::vehicle::VehicleModelKind;

fn sedan() -> PathBuf {
    common::root().join("vehicles/sedan.toml")
}

fn opts(vehicle: &Path) -> DiscoverOptions {
    DiscoverOptions {
        vehicle: vehicle.to_path_buf(),
        tyre: None,
        tyre_model: tyre_kind("pacejka").unwrap(),
        model: VehicleModelKind::Bicycle,
        out: PathBuf::from("unused"),
        runs: Vec::new(),
        progress: false,
        jackknife: false,
    }
}

fn model_of(vehicle: &Path) -> ReplayModel {
    ReplayModel::new(load_vehicle(vehicle, None, tyre_kind("pacejka").unwrap()).unwrap())
}

/// Synthesize `plan` with `effect` hidden at its synth defaults and discover over that candidate
/// only; returns the runs and the discovery.
fn discover_hidden(
    effect: Effect,
    plan: &[&str],
    seed: u64,
) -> (Vec<vehsim::discover::measured::MeasuredRun>, Discovery) {
    let model = model_of(&sedan());
    let mut p = EffectParams::default();
    effect.apply(&mut p, &synth::default_params(effect));
    let ids: Vec<String> = plan.iter().map(|s| s.to_string()).collect();
    let runs: Vec<_> =
        synth::generate_plan(&model, &p, seed, &synth::select(&ids).unwrap()).into_iter().map(|r| r.0).collect();
    let d = discover_from(&model, &Dataset::new(runs.clone()), EffectParams::default(), &[effect]);
    (runs, d)
}

/// Write the improved vehicle.toml of `d` into `dir` and return its path.
fn write_improved(dir: &Path, d: &Discovery) -> PathBuf {
    let text = improved_vehicle_toml(&opts(&sedan()), d).unwrap();
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("vehicle.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The improved spec as a new baseline replays the runs with the discovery's final RMSE (fitted
/// and held-out samples, both channels) to 1e-9.
fn assert_gap_reproduced(label: &str, runs: &[vehsim::discover::measured::MeasuredRun], d: &Discovery, spec: &Path) {
    let model = model_of(spec);
    let (base, _) = baseline_for(VehicleModelKind::Bicycle, &model.vehicle);
    let largest = common::assert_final_gap_replayed(label, &model, runs.to_vec(), d, &base);
    eprintln!("{label}: largest RMSE difference, improved spec against the discovery's final model: {largest:.1e}");
    // The gap was closed at all (else the check above is the baseline against itself).
    let (fin, base) = (d.final_scores.rss_fit, d.baseline.rss_fit);
    assert!(fin < 0.5 * base, "{label}: final normalised RSS {fin:e} against the baseline's {base:e}");
}

/// `vehsim run` of a sine steer on ice with the improved vehicle: exit 0. With the tread state on
/// (`tread`), the run's contact temperature is the tread's: it rises above the ice while the tyres
/// slide and never passes melting.
fn run_maneuver(dir: &Path, spec: &Path, tread: bool) {
    let m = format!(
        "name = \"wb\"\nvehicle = \"{}\"\ntyre_model = \"pacejka\"\nduration_s = 3.0\n[surface]\nmu = 0.15\n\
         temperature_c = -3.0\n[maneuver]\nkind = \"sine_steer\"\nspeed_mps = 10.0\nsteer_amplitude_deg = 2.0\n\
         period_s = 3.0\n",
        spec.display()
    );
    std::fs::write(dir.join("wb.toml"), m).unwrap();
    let (code, out, err) = common::vehsim(dir, &["run", "--quiet", "--out", "res", "wb.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let ts = std::fs::read_to_string(dir.join("res/wb/timeseries.csv")).unwrap();
    let mut lines = ts.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = head.iter().position(|h| *h == "contact_temp_front_c").unwrap();
    let temps: Vec<f64> = lines.map(|l| l.split(',').nth(col).unwrap().parse().unwrap()).collect();
    let top = temps.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    assert!(temps.iter().all(|t| (-3.0..=0.0).contains(t)), "between the ice and melting");
    if tread {
        assert!(top > -3.0 + 1e-3, "the tread warms while the front tyres slide: highest {top} degC");
    } else {
        assert_eq!(top, -3.0, "no contact heating without the tread state");
    }
}

fn close_loop(effect: Effect, plan: &[&str], seed: u64) -> String {
    let (runs, d) = discover_hidden(effect, plan, seed);
    assert_eq!(
        d.named,
        vec![effect],
        "{}: {:?}",
        effect.label(),
        d.rejected.iter().map(|t| &t.reason).collect::<Vec<_>>()
    );
    let dir = std::env::temp_dir().join(format!(
        "vehsim_wb_{}_{}",
        effect.label().replace([' ', '(', ')'], "_"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let spec = write_improved(&dir, &d);
    let text = std::fs::read_to_string(&spec).unwrap();
    // Every fitted parameter is a key of the spec (no header-only list); a vehicle parameter's
    // is its own body key.
    for (k, _, _) in &d.final_effects[0].params {
        let key = match effect {
            Effect::VehicleParam(i) => vehsim::discover::vehicle_params::TABLE[i].bound.key,
            _ => k.as_str(),
        };
        assert!(text.contains(&format!("{key} = ")), "{}: {key} missing from\n{text}", effect.label());
    }
    assert!(!text.contains("no key for yet"), "{text}");
    assert_gap_reproduced(&effect.label(), &runs, &d, &spec);
    run_maneuver(&dir, &spec, effect == Effect::ThermalState);
    let _ = std::fs::remove_dir_all(&dir);
    text
}

#[test]
fn per_axle_stiffness_scales_close_the_loop() {
    close_loop(Effect::AxleStiffness, &["step_dry", "sine_ice"], 1);
}

#[test]
fn per_axle_friction_scales_close_the_loop() {
    close_loop(Effect::AxleFriction, &["ramp_dry", "ramp_ice"], 2);
}

#[test]
fn transient_slip_closes_the_loop_in_both_forms() {
    let t = close_loop(Effect::TransientSlip, &["sine_dry", "step_ice"], 3);
    assert!(t.contains("slip_relaxation_saturating = false"), "{t}");
    let t = close_loop(Effect::TransientSlipSaturating, &["sine_dry", "step_ice"], 3);
    assert!(t.contains("slip_relaxation_saturating = true"), "{t}");
}

/// The longitudinal coupling writes `longitudinal_transfer_height_m`, which switches the form on
/// in the replay (and the transfer in `vehsim run`'s bicycle).
#[test]
fn longitudinal_coupling_closes_the_loop() {
    let t = close_loop(Effect::LongitudinalCoupling, &["brake_sine_dry", "sine_dry", "brake_sine_ice", "sine_ice"], 5);
    assert!(t.contains("longitudinal_transfer_height_m = "), "{t}");
}

#[test]
fn load_sensitivities_close_the_loop() {
    close_loop(Effect::LoadTransferSensitive, &["ramp_dry", "step_dry"], 4);
}

#[test]
fn sensor_effects_close_the_loop_through_the_sensors_section() {
    for (e, seed) in [(Effect::SensorLatency, 5), (Effect::SensorBias, 6), (Effect::AccelPosition, 7)] {
        let t = close_loop(e, &["sine_dry", "step_ice"], seed);
        assert!(t.contains("[sensors]"), "{t}");
    }
}

/// The vehicle parameters generated from the table: the improved spec sets the key itself to the
/// fitted value (the spec's times the factor), e.g. `mass_kg = 2000` for mass x 1.25.
#[test]
fn vehicle_parameters_close_the_loop_through_their_own_keys() {
    use vehsim::discover::vehicle_params::TABLE;
    for (i, row) in TABLE.iter().enumerate() {
        let e = Effect::VehicleParam(i);
        let (runs, d) = discover_hidden(e, &["sine_dry", "step_ice"], 9);
        assert_eq!(d.named, vec![e], "{}", e.label());
        let dir = std::env::temp_dir().join(format!("vehsim_wb_{}_{}", row.effect, std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let spec = write_improved(&dir, &d);
        let text = std::fs::read_to_string(&spec).unwrap();
        let fitted = d.final_effects[0].params[0].1;
        let mut v = model_of(&sedan()).vehicle;
        let want = *(row.field)(&mut v) * fitted;
        let line = text.lines().find(|l| l.starts_with(&format!("{} = ", row.bound.key))).unwrap();
        let got: f64 = line.split(" = ").nth(1).unwrap().parse().unwrap();
        eprintln!("{}: factor {fitted:.5}, written {line}", row.effect);
        assert_eq!(got, want, "{line}");
        assert!((fitted - row.synth).abs() < 0.02 * row.synth, "{fitted}");
        assert_gap_reproduced(row.effect, &runs, &d, &spec);
        run_maneuver(&dir, &spec, false);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn new_sensor_forms_close_the_loop_through_the_sensors_section() {
    // A clock skew shows where the signal changes all along the run (a delay growing from 0 at the
    // start): two sine steers; the step's signal changes only near its start.
    for (e, plan, seed) in [
        (Effect::SensorScale, ["sine_dry", "step_ice"], 10),
        (Effect::ClockSkew, ["sine_dry", "sine_ice"], 11),
        (Effect::AccelOrientation, ["sine_dry", "step_ice"], 12),
    ] {
        let t = close_loop(e, &plan, seed);
        assert!(t.contains("[sensors]"), "{t}");
    }
}

#[test]
fn tread_state_closes_the_loop_in_the_replay_and_runs_in_vehsim_run() {
    close_loop(Effect::ThermalState, &["step_ice", "ramp_ice"], 8);
}

/// A `[lateral]` or `[sensors]` key outside its declared bound, an unknown `[sensors]` key and two
/// forms of tyre relaxation at once are refused by `vehsim run` with exit 2, one message naming
/// the vehicle file, the key and what is allowed, and nothing written.
#[test]
fn keys_outside_their_bounds_are_exit_2_naming_file_and_key() {
    let spec = common::sine_steer_spec("b", "sedan.toml", 1.0);
    for (section, key, allowed) in [
        ("[lateral]\nstiffness_scale_rear = 6.0\n", "lateral.stiffness_scale_rear", "[0.2, 5]"),
        ("[lateral]\nmu_scale_front = 0.0\n", "lateral.mu_scale_front", "[0.05, 3]"),
        ("[lateral]\nload_sensitivity_mu = -1.5\n", "lateral.load_sensitivity_mu", "[-1, 1]"),
        (
            "[lateral]\nrelaxation_length_front_m = 11.0\nrelaxation_length_rear_m = 1.0\n",
            "lateral.relaxation_length_front_m",
            "[0, 10]",
        ),
        ("[lateral]\nrelaxation_length_front_m = 1.0\n", "lateral.relaxation_length_rear_m", "both > 0"),
        (
            "[lateral]\nrelaxation_length_front_m = 1.0\nrelaxation_length_rear_m = 1.0\nrelaxation_length_y_m = 1.0\n",
            "lateral.relaxation_length_front_m",
            "set one",
        ),
        ("[lateral]\nslip_relaxation_saturating = true\n", "lateral.slip_relaxation_saturating", "expected false"),
        ("[lateral]\ntread_mu_per_kj = 1.0\n", "lateral.tread_mu_per_kj", "[-20, 0]"),
        ("[lateral]\ntread_heat_capacity_j_per_k = 5.0\n", "lateral.tread_heat_capacity_j_per_k", "[10, 100000]"),
        ("[lateral]\ntread_cooling_time_s = 0.0\n", "lateral.tread_cooling_time_s", "[0.1, 100]"),
        ("[sensors]\nlatency_ay_s = 0.6\n", "sensors.latency_ay_s", "[0, 0.5]"),
        ("[sensors]\nbias_yaw_rate_radps = -0.7\n", "sensors.bias_yaw_rate_radps", "[-0.5, 0.5]"),
        ("[sensors]\naccel_y_m = 2.0\n", "sensors.accel_y_m", "[-1.5, 1.5]"),
        ("[sensors]\nscale_ay = 2.5\n", "sensors.scale_ay", "[0.5, 2]"),
        ("[sensors]\nclock_skew_ppm = 30000.0\n", "sensors.clock_skew_ppm", "[-20000, 20000]"),
        ("[sensors]\naccel_yaw_misalignment_rad = -0.4\n", "sensors.accel_yaw_misalignment_rad", "[-0.35, 0.35]"),
        ("[sensors]\ngain_ay = 1.0\n", "gain_ay", "latency_yaw_rate_s"),
    ] {
        let case = common::Case::new("wb-bounds", "b.toml", &spec);
        let text = std::fs::read_to_string(case.dir.join("sedan.toml")).unwrap();
        std::fs::write(case.dir.join("sedan.toml"), format!("{text}\n{section}")).unwrap();
        let (code, out, err) = case.run(&["run", "--quiet", "b.toml"]);
        assert_eq!(code, 2, "{key}: {out}{err}");
        assert!(err.contains("sedan.toml") && err.contains(key) && err.contains(allowed), "{key}: {err}");
        assert!(!case.results().join("b").exists(), "{key}: something was written");
    }
}

/// With `[sensors]`, `vehsim run` adds the logged channels after the usual columns: the yaw rate
/// τ later (linear between rows, the first row before the start) plus its offset, and the lateral
/// acceleration at the accelerometer, a_y + (dr/dt) x_s - r^2 y_s (central differences of the
/// logged yaw rate), plus its offset; written here from the true columns. Without `[sensors]` the
/// columns are the usual ones and equal the run's with `[sensors]`.
#[test]
fn sensors_section_adds_the_measured_channels_to_the_time_series() {
    let spec = common::sine_steer_spec("s", "sedan.toml", 3.0);
    let plain = common::Case::new("wb-sensors-plain", "s.toml", &spec);
    assert_eq!(plain.run(&["run", "--quiet", "s.toml"]).0, 0);
    let case = common::Case::new("wb-sensors", "s.toml", &spec);
    let text = std::fs::read_to_string(case.dir.join("sedan.toml")).unwrap();
    let (tau, b_r, b_a, x_s, y_s) = (0.037, 0.01, -0.2, 1.1, 0.3);
    let sensors = format!(
        "[sensors]\nlatency_yaw_rate_s = {tau}\nbias_yaw_rate_radps = {b_r}\nbias_ay_mps2 = {b_a}\naccel_x_m = {x_s}\naccel_y_m = {y_s}\n"
    );
    std::fs::write(case.dir.join("sedan.toml"), format!("{text}\n{sensors}")).unwrap();
    let (code, out, err) = case.run(&["run", "--quiet", "s.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let read = |c: &common::Case| std::fs::read_to_string(c.results().join("s/timeseries.csv")).unwrap();
    let (with, without) = (read(&case), read(&plain));
    let header = with.lines().next().unwrap();
    assert!(header.ends_with(",yaw_rate_meas_radps,ay_meas_mps2"), "{header}");
    assert!(!without.lines().next().unwrap().contains("meas"));
    let cols: Vec<&str> = header.split(',').collect();
    let rows: Vec<Vec<f64>> =
        with.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect();
    // The true columns are those of the run without [sensors], row for row.
    for (a, b) in with.lines().skip(1).zip(without.lines().skip(1)) {
        assert!(a.starts_with(&format!("{b},")), "{a}\n{b}");
    }
    let col = |name: &str| -> Vec<f64> {
        let i = cols.iter().position(|c| *c == name).unwrap();
        rows.iter().map(|r| r[i]).collect()
    };
    let (t, r, ay, r_meas, ay_meas) =
        (col("t_s"), col("yaw_rate_radps"), col("ay_mps2"), col("yaw_rate_meas_radps"), col("ay_meas_mps2"));
    let n = t.len();
    assert!(n > 100);
    let mut largest: f64 = 0.0;
    for k in 0..n {
        let tk = t[k] - tau;
        let delayed = if tk <= t[0] {
            r[0]
        } else {
            let j = t.iter().rposition(|&s| s <= tk).unwrap();
            r[j] + (tk - t[j]) / (t[j + 1] - t[j]) * (r[j + 1] - r[j])
        };
        assert!((r_meas[k] - (delayed + b_r)).abs() < 1e-12, "yaw rate at {}", t[k]);
        let (i, j) = (k.saturating_sub(1), (k + 1).min(n - 1));
        let r_dot = (r[j] - r[i]) / (t[j] - t[i]);
        let want = ay[k] + r_dot * x_s - r[k] * r[k] * y_s + b_a;
        assert!((ay_meas[k] - want).abs() < 1e-12, "ay at {}", t[k]);
        largest = largest.max((ay_meas[k] - ay[k]).abs());
    }
    assert!(largest > 0.1, "the accelerometer terms never showed: {largest}");
}

/// The friction regions named on the road go to surface.toml; added to every run's sidecar, they
/// make the baseline replay with the discovery's final gap to 1e-9 (the vehicle unchanged).
#[test]
fn friction_regions_close_the_loop_through_the_sidecar() {
    use vehsim::discover::measured::apply_sidecar;
    use vehsim::discover::report::surface_toml;
    for (e, plan, seed) in [
        (Effect::FrictionPatch, ["step_ice", "sine_ice"], 9),
        (Effect::FrictionBand, ["step_ice", "sine_ice"], 10),
        (Effect::FrictionStretch, ["step_ice", "sine_ice"], 11),
    ] {
        let (mut runs, d) = discover_hidden(e, &plan, seed);
        assert_eq!(d.named, vec![e], "{}", e.label());
        let text = surface_toml(&d).unwrap();
        assert!(text.contains(&format!("[[surface.{}]]", e.form())), "{text}");
        assert!(improved_vehicle_toml(&opts(&sedan()), &d).unwrap().contains("so in surface.toml"));
        for r in &mut runs {
            apply_sidecar(r, Path::new("RUN.toml"), &text).unwrap();
            assert!(r.regions != Default::default());
        }
        assert_gap_reproduced(&e.label(), &runs, &d, &sedan());
    }
}

/// A sidecar region outside its declared bound, or two of a kind, is bad input naming the key.
#[test]
fn sidecar_regions_outside_their_bounds_are_refused_naming_the_key() {
    use vehsim::discover::measured::apply_sidecar;
    let (runs, _) = (
        synth::generate_plan(
            &model_of(&sedan()),
            &EffectParams::default(),
            1,
            &synth::select(&["sine_ice".into()]).unwrap(),
        ),
        (),
    );
    for (text, key) in [
        ("[[surface.patch]]\nmu_scale = 0.5\nx_m = 10.0\ny_m = 0.0\nradius_m = 0.5\n", "surface.patch.radius_m"),
        ("[[surface.band]]\nmu_scale = 4.0\nstart_x_m = 10.0\nlength_m = 20.0\n", "surface.band.mu_scale"),
        ("[[surface.stretch]]\nmu_scale = 0.5\nstart_m = 10.0\nlength_m = 1.0\n", "surface.stretch.length_m"),
        ("[[surface.stretch]]\nmu_scale = 0.5\nstart_m = 10.0\nlength_m = 5.0\n[[surface.stretch]]\nmu_scale = 0.5\nstart_m = 30.0\nlength_m = 5.0\n", "surface.stretch"),
        ("[[surface.patch]]\nmu_scale = 0.5\nx_m = 10.0\nradius_m = 5.0\n", "y_m"),
    ] {
        let mut r = runs[0].0.clone();
        let err = apply_sidecar(&mut r, Path::new("RUN.toml"), text).unwrap_err().to_string();
        assert!(err.contains("RUN.toml") && err.contains(key), "{key}: {err}");
    }
}

/// A manoeuvre spec's `[[surface.patch]]` and `[[surface.band]]` act in the engine's bicycle at
/// each axle's ground position: a patch covering the whole course at scale 0.5 on mu 0.3 runs
/// bit for bit as mu 0.15 without it (the logistic weight is exactly 1 there); a band starting
/// at X = 40 m leaves the run as it was while both axles are more than 20 m before it (weight
/// below 2e-9) and changes it after. Out-of-bounds keys are exit 2 naming the key, and the 4-DOF
/// model refuses regions.
#[test]
fn manoeuvre_regions_act_per_axle_in_the_bicycle() {
    let spec = |mu: f64, extra: &str| {
        format!(
            "name = \"g\"\nvehicle = \"{}\"\ntyre_model = \"pacejka\"\nduration_s = 8.0\n[integrator]\nstep_s = 0.005\n\
             [surface]\nmu = {mu}\nfriction_law = \"fixed\"\n{extra}[maneuver]\nkind = \"sine_steer\"\nspeed_mps = 10.0\n\
             steer_amplitude_deg = 3.0\nperiod_s = 2.0\n",
            sedan().display()
        )
    };
    let run = |text: String| -> String {
        let case = common::Case::new("wb-regions", "g.toml", &text);
        let (code, out, err) = case.run(&["run", "--quiet", "g.toml"]);
        assert_eq!(code, 0, "{out}{err}");
        std::fs::read_to_string(case.results().join("g/timeseries.csv")).unwrap()
    };
    let patch = "[[surface.patch]]\nmu_scale = 0.5\nx_m = 0.0\ny_m = 0.0\nradius_m = 1000.0\n";
    assert_eq!(run(spec(0.3, patch)), run(spec(0.15, "")));
    assert_ne!(run(spec(0.3, "")), run(spec(0.15, "")), "the friction must matter in this run");
    let plain = run(spec(0.15, ""));
    let band = run(spec(0.15, "[[surface.band]]\nmu_scale = 0.3\nstart_x_m = 40.0\nlength_m = 1000.0\n"));
    let rows = |t: &str| -> Vec<Vec<f64>> {
        t.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect()
    };
    let (p, b) = (rows(&plain), rows(&band));
    let (mut before, mut after) = (0, 0);
    for (rp, rb) in p.iter().zip(&b) {
        // Columns 1 (x_m) and 6 (yaw_rate_radps); the front axle is 1.2 m ahead of the CG.
        if rp[1] + 1.5 < 20.0 {
            assert!((rp[6] - rb[6]).abs() < 1e-9, "x {}: {} vs {}", rp[1], rp[6], rb[6]);
            before += 1;
        }
        if rp[1] > 60.0 && (rp[6] - rb[6]).abs() > 1e-3 {
            after += 1;
        }
    }
    assert!(before > 100 && after > 20, "{before} rows before the band, {after} changed after");
    for (extra, key) in [
        ("[[surface.patch]]\nmu_scale = 0.5\nx_m = 0.0\ny_m = 0.0\nradius_m = 0.5\n", "surface.patch.radius_m"),
        ("[[surface.band]]\nmu_scale = 3.5\nstart_x_m = 0.0\nlength_m = 10.0\n", "surface.band.mu_scale"),
        ("[[surface.stretch]]\nmu_scale = 0.5\nstart_m = -1.0\nlength_m = 10.0\n", "surface.stretch.start_m"),
    ] {
        let case = common::Case::new("wb-regions-bad", "g.toml", &spec(0.15, extra));
        let (code, out, err) = case.run(&["run", "--quiet", "g.toml"]);
        assert_eq!(code, 2, "{key}: {out}{err}");
        assert!(err.contains("g.toml") && err.contains(key), "{key}: {err}");
    }
}

/// A manoeuvre's `[[surface.stretch]]` acts along the distance the CG has travelled: against the
/// same run without it, the yaw rate is unchanged (1e-9) while the distance (the trapezoid of the
/// logged vx, computed here) is more than 20 m before the stretch's start at 40 m, first departs
/// within 15 m of the start, and differs beyond 60 m. The 4-DOF model refuses it.
#[test]
fn manoeuvre_stretch_acts_along_the_distance_travelled() {
    let spec = |extra: &str, model: &str| {
        format!(
            "name = \"g\"\nvehicle = \"{}\"\ntyre_model = \"pacejka\"\nvehicle_model = \"{model}\"\nduration_s = 8.0\n\
             [surface]\nmu = 0.15\nfriction_law = \"fixed\"\n{extra}[maneuver]\nkind = \"sine_steer\"\nspeed_mps = 10.0\n\
             steer_amplitude_deg = 3.0\nperiod_s = 2.0\n",
            sedan().display()
        )
    };
    let run = |text: String| -> Vec<Vec<f64>> {
        let case = common::Case::new("wb-stretch", "g.toml", &text);
        let (code, out, err) = case.run(&["run", "--quiet", "g.toml"]);
        assert_eq!(code, 0, "{out}{err}");
        let t = std::fs::read_to_string(case.results().join("g/timeseries.csv")).unwrap();
        t.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect()
    };
    let stretch = "[[surface.stretch]]\nmu_scale = 0.3\nstart_m = 40.0\nlength_m = 1000.0\n";
    let (p, s) = (run(spec("", "bicycle")), run(spec(stretch, "bicycle")));
    // Columns 0 (t_s), 4 (vx_mps) and 6 (yaw_rate_radps).
    let (mut d, mut first_departure, mut after) = (0.0, None, 0);
    for (k, (rp, rs)) in p.iter().zip(&s).enumerate() {
        if k > 0 {
            d += 0.5 * (rp[0] - p[k - 1][0]) * (rp[4] + p[k - 1][4]);
        }
        let diff = (rp[6] - rs[6]).abs();
        if d < 20.0 {
            assert!(diff < 1e-9, "distance {d} m: {} vs {}", rp[6], rs[6]);
        }
        if diff > 1e-6 && first_departure.is_none() {
            first_departure = Some(d);
        }
        if d > 60.0 && diff > 1e-3 {
            after += 1;
        }
    }
    let at = first_departure.expect("the stretch changes the run");
    eprintln!("the stretch at 40 m first moves the yaw rate by 1e-6 rad/s at {at:.2} m travelled");
    assert!((25.0..=41.0).contains(&at), "first departs at {at} m of distance travelled");
    assert!(after > 20, "{after} rows changed beyond 60 m");
    let case = common::Case::new("wb-stretch-4dof", "g.toml", &spec(stretch, "roll4dof"));
    let (code, _, err) = case.run(&["run", "--quiet", "g.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("g.toml") && err.contains("surface.patch") && err.contains("[[surface.stretch]]"), "{err}");
}
