//! Longitudinal load transfer in `vehsim run` (`[lateral] longitudinal_transfer_height_m`, the
//! bicycle model): the form `vehsim discover` names as `longitudinal_coupling`. Checked against
//! the pitch balance computed from the run's own logged forces, against its direction (braking
//! loads the front axle, the car turns in harder under braking in a turn), and for the key's
//! default and refusal.

mod common;

use common::Case;

/// Braking in a turn on a dry road: 6 s on a 40 m circle to the left at 12 m/s (a_y 3.6 m/s^2),
/// then 40 % of the brake torque with the steer held, bicycle + Pacejka.
const BRAKE_IN_TURN: &str = "name = \"bt\"\nvehicle = \"sedan.toml\"\ntyre_model = \"pacejka\"\n\
    [surface]\nmu = 0.9\ntemperature_c = 10.0\n[maneuver]\nkind = \"braking_in_turn\"\nradius_m = 40.0\n\
    direction = \"left\"\nspeed_mps = 12.0\nbrake_at_s = 6.0\nbrake_fraction = 0.4\n";

/// Transfer height of the checks, m (the sedan's CG height).
const H: f64 = 0.55;

/// The sedan's static axle loads (front, rear), N, and wheelbase, m (vehicles/sedan.toml).
fn sedan() -> ([f64; 2], f64) {
    let (m, a, b) = (1600.0, 1.09, 1.71);
    let g = 9.80665;
    let l: f64 = a + b;
    ([m * g * b / l, m * g * a / l], l)
}

/// A scratch case of the braking-in-turn run with `lateral` appended to the sedan.
fn case(tag: &str, lateral: &str) -> Case {
    Case::with_sedan_tail(tag, "bt.toml", BRAKE_IN_TURN, lateral)
}

/// Run the case; its time series as (header, rows).
fn run(c: &Case) -> (Vec<String>, Vec<Vec<f64>>) {
    let (code, out, err) = c.run(&["run", "--quiet", "--out", "res", "bt.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    c.series("bt")
}

fn col(head: &[String], name: &str) -> usize {
    head.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"))
}

/// Each row's axle loads are the static ones moved by h S / L, S the tyres' force along the body
/// computed here from the row's logged forces and steer: the engine solves the balance its loads
/// and forces must satisfy together. Braking loads the front axle by about h m a_x / L.
#[test]
fn axle_loads_satisfy_the_pitch_balance() {
    let (head, rows) = run(&case("long_balance", &format!("[lateral]\nlongitudinal_transfer_height_m = {H}\n")));
    let ([f0, r0], l) = sedan();
    let c = |n: &str| col(&head, n);
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for row in &rows {
        let d = row[c("steer_rad")];
        let s = row[c("fx_front_n")] * d.cos() - row[c("fy_front_n")] * d.sin() + row[c("fx_rear_n")];
        let front = row[c("fz_fl_n")] + row[c("fz_fr_n")];
        let rear = row[c("fz_rl_n")] + row[c("fz_rr_n")];
        worst = worst.max((front - (f0 - H * s / l)).abs()).max((rear - (r0 + H * s / l)).abs());
        largest = largest.max((H * s / l).abs());
    }
    println!("largest transfer {largest:.1} N, worst balance residual {worst:.3e} N");
    // Braking at 40 % of the sedan's 7000 N m on a dry road moves about 1 kN.
    assert!(largest > 500.0, "largest transfer {largest} N");
    assert!(worst < 1e-3 * largest, "worst residual {worst} N against {largest} N");
    // Under braking the front axle carries more than its static load.
    let last = rows.iter().rfind(|r| r[c("t_s")] < 7.0).unwrap();
    assert!(last[c("fz_fl_n")] + last[c("fz_fr_n")] > f0 + 300.0);
}

/// Without the key (and with it at 0) the loads are static and the two runs are the same bytes;
/// with it, braking in a turn moves load onto the front tyres, which then turn the car in harder:
/// the yaw rate a second after the brake is higher than with static loads.
#[test]
fn static_by_default_and_turn_in_under_braking() {
    let base = case("long_none", "");
    let zero = case("long_zero", "[lateral]\nlongitudinal_transfer_height_m = 0.0\n");
    let with = case("long_with", &format!("[lateral]\nlongitudinal_transfer_height_m = {H}\n"));
    let (head, rows0) = run(&base);
    let _ = run(&zero);
    let (_, rows1) = run(&with);
    let read = |c: &Case| std::fs::read(c.dir.join("res/bt/timeseries.csv")).unwrap();
    assert_eq!(read(&base), read(&zero));
    let ([f0, _], _) = sedan();
    let c = |n: &str| col(&head, n);
    assert!(rows0.iter().all(|r| (r[c("fz_fl_n")] + r[c("fz_fr_n")] - f0).abs() < 1e-6));
    let at = |rows: &[Vec<f64>], t: f64| rows.iter().find(|r| r[c("t_s")] >= t).unwrap()[c("yaw_rate_radps")];
    // Before the brake the two agree closely (only the drive force moves load).
    assert!((at(&rows0, 5.9) - at(&rows1, 5.9)).abs() < 0.01 * at(&rows0, 5.9).abs());
    let (r0, r1) = (at(&rows0, 7.0), at(&rows1, 7.0));
    println!("yaw rate 1 s after the brake: static loads {r0:.4} rad/s, transfer {r1:.4} rad/s");
    assert!(r1 > 1.03 * r0, "{r1} vs {r0}");
}

/// The 4-DOF model carries its own load transfer and refuses the key (exit 2 naming it).
#[test]
fn the_roll_model_refuses_the_key() {
    let c = case("long_roll", &format!("[lateral]\nlongitudinal_transfer_height_m = {H}\n"));
    c.edit("bt.toml", "tyre_model", "vehicle_model = \"roll4dof\"\ntyre_model");
    let (code, out, err) = c.run(&["run", "--quiet", "--out", "res", "bt.toml"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("lateral.longitudinal_transfer_height_m"), "{err}");
}
