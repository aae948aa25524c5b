//! The tread state (`[lateral] tread_*`) in `vehsim run`: the engine's contact-temperature estimate
//! of the thermal form `vehsim discover` names. Checked against the heat balance's steady state
//! computed from the run's own logged forces and slips, against the melting cap, and for the
//! combinations the spec refuses.

mod common;

use common::Case;

/// A 40 m circle on ice at `ice_c`, nominal a_y 1 m/s^2, bicycle + Pacejka, 25 s.
fn circle(ice_c: f64) -> String {
    format!(
        "name = \"cr\"\nvehicle = \"sedan.toml\"\ntyre_model = \"pacejka\"\n[surface]\nmu = 0.15\n\
         temperature_c = {ice_c}\n[maneuver]\nkind = \"constant_radius\"\nradius_m = 40.0\ndirection = \"left\"\n\
         speed_mode = \"steps\"\nay_first_mps2 = 1.0\nay_step_mps2 = 0.25\nay_max_mps2 = 1.0\nsettle_s = 20.0\n\
         window_s = 5.0\nspeed_ramp_mps2 = 0.5\n[driver]\npreview_time_s = 0.5\n"
    )
}

/// A scratch case with the sedan (its Pacejka file copied too) and `lateral` appended to it.
fn case(tag: &str, spec: &str, lateral: &str) -> Case {
    Case::with_sedan_tail(tag, "cr.toml", spec, lateral)
}

/// The time series of run `cr` as (header, rows).
fn series(c: &Case) -> (Vec<String>, Vec<Vec<f64>>) {
    c.series("cr")
}

const TREAD: &str =
    "[lateral]\ntread_mu_per_kj = -0.1\ntread_heat_capacity_j_per_k = 300.0\ntread_cooling_time_s = 3.0\n";

/// In steady cornering the rise is the lag's steady state P tau_c / C, with P the axle's sliding
/// power |V| sqrt(kappa^2 + tan^2 alpha) |F| computed here from the logged columns (body speed for
/// the wheel's, so within 1 %): the engine's estimate carries the axle's heat, as discovery fits it.
#[test]
fn steady_cornering_rise_is_the_heat_balance() {
    let c = case("tread_steady", &circle(-10.0), TREAD);
    let (code, out, err) = c.run(&["run", "--quiet", "--out", "res", "cr.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let (head, rows) = series(&c);
    let col = |name: &str| head.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
    let last = rows.last().unwrap();
    assert!((last[col("t_s")] - 25.0).abs() < 1e-9);
    for axle in ["front", "rear"] {
        let g = |k: &str| last[col(&format!("{k}_{axle}{}", if k.starts_with("alpha") { "_rad" } else { "" }))];
        let (alpha, kappa) = (g("alpha"), g("kappa"));
        let force = last[col(&format!("fx_{axle}_n"))].hypot(last[col(&format!("fy_{axle}_n"))]);
        let slide = last[col("vx_mps")] * (kappa * kappa + alpha.tan().powi(2)).sqrt();
        let want = slide * force * 3.0 / 300.0;
        let got = last[col(&format!("contact_temp_{axle}_c"))] + 10.0;
        assert!(want > 0.3, "{axle}: the tyres slide enough to warm ({want} K)");
        assert!((got - want).abs() < 0.01 * want, "{axle}: rise {got} K, heat balance {want} K");
    }
}

/// With heating far beyond the room to melting, every contact temperature stays at or below 0 degC
/// and the friction change acts (the car needs more steer than without the tread state).
#[test]
fn the_rise_stops_at_melting_and_lowers_the_grip() {
    let hot = "[lateral]\ntread_mu_per_kj = -20.0\ntread_heat_capacity_j_per_k = 20.0\ntread_cooling_time_s = 10.0\n";
    let c = case("tread_cap", &circle(-0.5), hot);
    let (code, out, err) = c.run(&["run", "--quiet", "--out", "res", "cr.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let (head, rows) = series(&c);
    let front = head.iter().position(|h| h == "contact_temp_front_c").unwrap();
    let top = rows.iter().map(|r| r[front]).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(top, 0.0, "the front tread reaches melting and stops there");
    let plain = case("tread_cap_off", &circle(-0.5), "");
    let (code, out, err) = plain.run(&["run", "--quiet", "--out", "res", "cr.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let (h2, r2) = series(&plain);
    let steer = |h: &[String], r: &[Vec<f64>]| {
        let i = h.iter().position(|x| x == "steer_rad").unwrap();
        r.last().unwrap()[i]
    };
    let (with, without) = (steer(&head, &rows), steer(&h2, &r2));
    assert!(with > without * 1.01, "warmer tread, less grip, more steer: {with} rad against {without} rad");
}

/// The tread state is the run's contact-temperature estimate: beside the thermal form or the ATIIM
/// estimate it is refused, exit 2 naming the file and the key, nothing written.
#[test]
fn tread_state_beside_another_contact_estimate_is_refused() {
    let c = case("tread_thermal", &circle(-10.0), &format!("{TREAD}thermal_mu_per_k = -0.05\n"));
    let (code, _, err) = c.run(&["run", "--quiet", "--out", "res", "cr.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("sedan.toml") && err.contains("lateral.thermal_mu_per_k"), "{err}");
    assert!(!c.dir.join("res/cr").exists());
    let c = case("tread_atiim", &format!("{}[contact]\nmodel = \"atiim\"\n", circle(-10.0)), TREAD);
    let (code, _, err) = c.run(&["run", "--quiet", "--out", "res", "cr.toml"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cr.toml") && err.contains("contact.model") && err.contains("isothermal"), "{err}");
    assert!(!c.dir.join("res/cr").exists());
}
