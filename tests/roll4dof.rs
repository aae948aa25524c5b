//! Physics of the 4-DOF roll model against closed forms, limits and symmetries, and the
//! constant-radius manoeuvre (ISO 4138 method 1) built on it.
//!
//! Closed forms (docs/roll4dof.md; every quantity recomputed here from the raw spec files):
//! - m_s = m - m_uf - m_ur, h_s = (m h - (m_uf + m_ur) h_u) / m_s, x_s = (m_ur b - m_uf a) / m_s,
//!   a_s = a - x_s, b_s = b + x_s, roll-axis height h_ra = (h_rf b_s + h_rr a_s) / L, h' = h_s - h_ra;
//! - steady roll phi = m_s h' a_y / (K_f + K_r - m_s g h');
//! - steady lateral transfer per axle dF_f = (K_f phi + (m_s h_rf b_s / L + m_uf h_u) a_y) / t,
//!   dF_r likewise with h_rr, a_s / L, m_ur; their sum obeys the overturning-moment balance
//!   (dF_f + dF_r) t = m h a_y + m_s g h' phi.

mod common;

use std::path::{Path, PathBuf};

use vehsim_core::maneuver::constant_radius::{ConstantRadiusParams, Direction};
use vehsim_core::maneuver::open_loop::{SpeedSchedule, SteerProfile};
use vehsim_core::sim::Method;
use vehsim_core::vehicle::VehicleModelKind;
use vehsim_core::vehicle::GRAVITY;
use vehsim_spec::maneuver::ManeuverConfig;
use vehsim_spec::run::{execute, RunOutput};
use vehsim_spec::tyre::TyreFileSpec;
use vehsim_spec::{RunConfig, VehicleFile};

/// A scratch copy of the sedan and its tyre with edits, plus a spec written next to them.
fn scratch(tag: &str, vehicle_edits: &[(&str, &str)], tyre_edits: &[(&str, &str)], spec: &str) -> RunConfig {
    let dir = common::temp_dir(tag);
    std::fs::create_dir_all(dir.join("tyres")).unwrap();
    let root = common::root();
    let mut v = std::fs::read_to_string(root.join("vehicles/sedan_rwd.toml")).unwrap();
    for (from, to) in vehicle_edits {
        assert!(v.contains(from), "sedan_rwd.toml has no '{from}'");
        v = v.replacen(from, to, 1);
    }
    std::fs::write(dir.join("car.toml"), v).unwrap();
    let mut t = std::fs::read_to_string(root.join("vehicles/tyres/srtt_p225_60r16.toml")).unwrap();
    for (from, to) in tyre_edits {
        assert!(t.contains(from), "tyre file has no '{from}'");
        t = t.replacen(from, to, 1);
    }
    std::fs::write(dir.join("tyres/srtt_p225_60r16.toml"), t).unwrap();
    let p = dir.join("spec.toml");
    std::fs::write(&p, spec).unwrap();
    match vehsim_spec::run::load(&p) {
        Ok(c) => c,
        Err(e) => panic!("{tag}: {e}"),
    }
}

/// A spec text: `vehicle_model`, surface mu and a `[maneuver]` table body.
fn spec(model: &str, mu: f64, maneuver: &str, extra: &str) -> String {
    format!(
        "name = \"t\"\nvehicle = \"car.toml\"\ntyre_model = \"linear\"\nvehicle_model = \"{model}\"\n{extra}\n\
         [surface]\nmu = {mu}\n[maneuver]\n{maneuver}\n[driver]\npreview_time_s = 0.5\n"
    )
}

/// The raw numbers the closed forms need.
struct Raw {
    m: f64,
    h: f64,
    a: f64,
    b: f64,
    t: f64,
    m_uf: f64,
    m_ur: f64,
    h_u: f64,
    k_f: f64,
    k_r: f64,
    h_rf: f64,
    h_rr: f64,
}

impl Raw {
    fn of(vehicle_file: &Path) -> Raw {
        let v = VehicleFile::load(vehicle_file).unwrap();
        let r = v.roll.clone().expect("[roll] section");
        let tyre = TyreFileSpec::load(&vehicle_file.parent().unwrap().join(&v.tyre)).unwrap();
        Raw {
            m: v.mass_kg,
            h: v.cg_height_m,
            a: v.cg_to_front_axle_m,
            b: v.cg_to_rear_axle_m,
            t: v.track_m,
            m_uf: r.unsprung_mass_front_kg,
            m_ur: r.unsprung_mass_rear_kg,
            h_u: r.unsprung_cg_height_m.unwrap_or(tyre.unloaded_radius_m),
            k_f: r.roll_stiffness_front_nm_per_rad,
            k_r: r.roll_stiffness_rear_nm_per_rad,
            h_rf: r.roll_centre_height_front_m,
            h_rr: r.roll_centre_height_rear_m,
        }
    }
    fn l(&self) -> f64 {
        self.a + self.b
    }
    fn m_s(&self) -> f64 {
        self.m - self.m_uf - self.m_ur
    }
    fn x_s(&self) -> f64 {
        (self.m_ur * self.b - self.m_uf * self.a) / self.m_s()
    }
    fn h_prime(&self) -> f64 {
        let h_s = (self.m * self.h - (self.m_uf + self.m_ur) * self.h_u) / self.m_s();
        let (a_s, b_s) = (self.a - self.x_s(), self.b + self.x_s());
        h_s - (self.h_rf * b_s + self.h_rr * a_s) / self.l()
    }
    fn roll(&self, ay: f64) -> f64 {
        let ms = self.m_s();
        ms * self.h_prime() * ay / (self.k_f + self.k_r - ms * GRAVITY * self.h_prime())
    }
    /// Steady lateral load transfer (front, rear), N: load gained by each right wheel.
    fn transfer(&self, ay: f64) -> (f64, f64) {
        let phi = self.roll(ay);
        let (a_s, b_s) = (self.a - self.x_s(), self.b + self.x_s());
        let l = self.l();
        let f = (self.k_f * phi + (self.m_s() * self.h_rf * b_s / l + self.m_uf * self.h_u) * ay) / self.t;
        let r = (self.k_r * phi + (self.m_s() * self.h_rr * a_s / l + self.m_ur * self.h_u) * ay) / self.t;
        (f, r)
    }
}

fn vehicle_path(cfg: &RunConfig) -> PathBuf {
    cfg.vehicle_file.clone()
}

/// The dissertation's constant-radius run (8 m/s held on 40 m, rear drive, 4-DOF).
fn dissertation_run() -> (RunConfig, RunOutput) {
    let cfg = common::load("maneuvers/dissertation/constant_radius_8mps_linear.toml");
    assert_eq!(cfg.vehicle_model, VehicleModelKind::Roll4Dof);
    let out = execute(&cfg);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Completed, "{:?}", out.summary.events);
    (cfg, out)
}

/// Steady roll angle on the 8 m/s, 40 m circle equals m_s h' a_y / (K - m_s g h') within 1 %, and
/// the steady lateral load transfer of each axle its closed form within 1 %; the sum obeys the
/// overturning-moment balance. The PID holds 8 m/s within 1 % (dissertation Fig. 6.12).
#[test]
fn steady_roll_and_lateral_transfer_match_closed_forms() {
    let (cfg, out) = dissertation_run();
    let raw = Raw::of(&vehicle_path(&cfg));
    let ss = &out.steady_states;
    assert_eq!(ss.len(), 1);
    let s = ss[0].clone();
    assert!((s.ay_mps2 - 1.6).abs() < 0.05, "a_y = {} (8^2 / 40 = 1.6)", s.ay_mps2);
    let phi = raw.roll(s.ay_mps2);
    let err = (s.roll_rad - phi).abs() / phi;
    eprintln!("roll {:.6} rad, closed form {phi:.6} rad, relative error {err:.2e}", s.roll_rad);
    assert!(err < 0.01, "roll {} vs closed form {phi}", s.roll_rad);
    let (df, dr) = raw.transfer(s.ay_mps2);
    let mf = 0.5 * (s.fz_fr_n - s.fz_fl_n);
    let mr = 0.5 * (s.fz_rr_n - s.fz_rl_n);
    eprintln!("transfer front {mf:.1} N (closed form {df:.1}), rear {mr:.1} N (closed form {dr:.1})");
    assert!((mf - df).abs() < 0.01 * df, "front transfer {mf} vs {df}");
    assert!((mr - dr).abs() < 0.01 * dr, "rear transfer {mr} vs {dr}");
    let moment = (mf + mr) * raw.t;
    let expected = raw.m * raw.h * s.ay_mps2 + raw.m_s() * GRAVITY * raw.h_prime() * phi;
    assert!((moment - expected).abs() < 0.01 * expected, "overturning moment {moment} vs {expected}");
    // Left turn: the body leans right (phi > 0 in ISO 8855), the right (outer) wheels gain load.
    assert!(s.roll_rad > 0.0 && mf > 0.0 && mr > 0.0);
    // Speed held within 1 % once the run is under way.
    let worst = out.rows.iter().map(|r| (r.obs.kin.vx_mps - 8.0).abs()).fold(0.0, f64::max);
    assert!(worst < 0.08, "speed left the 1 % band: {worst}");
}

/// The four normal loads sum to the weight within 0.1 % at every step of the ice DLC with the
/// 4-DOF model (rows recorded at every step), while the lateral transfer is substantial.
#[test]
fn normal_loads_sum_to_the_weight_at_every_step_of_the_dlc() {
    let mut cfg = common::load("maneuvers/dlc_roll4dof.toml");
    cfg.settings.output_interval_s = cfg.settings.step_s;
    let out = execute(&cfg);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Completed);
    assert_eq!(out.summary.passed, Some(true), "{:?}", out.summary.events);
    let w = cfg.vehicle.mass_kg * GRAVITY;
    assert!(out.rows.len() as u64 >= out.summary.steps);
    let mut max_shift = 0.0_f64;
    for r in &out.rows {
        let sum: f64 = r.obs.fz_n.iter().sum();
        assert!((sum - w).abs() < 1e-3 * w, "t = {}: loads {:?} sum {sum} vs weight {w}", r.t_s, r.obs.fz_n);
        assert!(r.obs.fz_n.iter().all(|f| *f >= 0.0));
        max_shift = max_shift.max((r.obs.fz_n[1] - r.obs.fz_n[0]).abs());
    }
    assert!(max_shift > 500.0, "the lane change must transfer load (max front left/right difference {max_shift} N)");
}

/// With very stiff roll, the CG and the roll centres on the ground, no unsprung mass, a
/// vanishing track and parallel steer, the 4-DOF model is the bicycle model: yaw rate through the
/// closed-loop DLC agrees within 1e-3 rad/s.
#[test]
fn degenerate_4dof_reproduces_the_bicycle_through_the_dlc() {
    let edits = [
        ("cg_height_m = 0.55", "cg_height_m = 0.0"),
        ("track_m = 1.58", "track_m = 0.001"),
        ("roll_centre_height_front_m = 0.08", "roll_centre_height_front_m = 0.0"),
        ("roll_centre_height_rear_m = 0.12", "roll_centre_height_rear_m = 0.0"),
        ("roll_stiffness_front_nm_per_rad = 46000.0", "roll_stiffness_front_nm_per_rad = 1.0e7"),
        ("roll_stiffness_rear_nm_per_rad = 30800.0", "roll_stiffness_rear_nm_per_rad = 1.0e7"),
        ("unsprung_mass_front_kg = 90.0", "unsprung_mass_front_kg = 0.0"),
        ("unsprung_mass_rear_kg = 80.0", "unsprung_mass_rear_kg = 0.0"),
        ("ackermann = 0.5", "ackermann = 0.0"),
        ("drive = \"rear\"", "drive = \"front\""),
    ];
    let man = "kind = \"iso3888_2\"\nspeed_mps = 10.0\nspeed_mode = \"hold\"";
    let four = scratch("degenerate4", &edits, &[], &spec("roll4dof", 0.15, man, ""));
    let two = scratch("degenerate2", &edits, &[], &spec("bicycle", 0.15, man, ""));
    let (a, b) = (execute(&four), execute(&two));
    assert_eq!(a.summary.end_reason, vehsim_core::event::EndReason::Completed);
    assert_eq!(b.summary.end_reason, vehsim_core::event::EndReason::Completed);
    let mut worst = 0.0_f64;
    for (p, q) in a.rows.iter().zip(&b.rows) {
        assert!((p.t_s - q.t_s).abs() < 1e-12);
        worst = worst.max((p.obs.kin.yaw_rate_radps - q.obs.kin.yaw_rate_radps).abs());
        assert!(p.obs.roll_rad.abs() < 1e-12);
    }
    eprintln!("max |r_4dof - r_bicycle| = {worst:.3e} rad/s");
    assert!(worst < 1e-3, "yaw rates differ by {worst} rad/s");
    assert!(b.summary.peak_yaw_rate_radps > 0.2, "the DLC must actually yaw");
}

fn stepped(radius: f64, dir: Direction, ay_max: f64, settle: f64, window: f64) -> ManeuverConfig {
    ManeuverConfig::ConstantRadius(ConstantRadiusParams {
        radius_m: radius,
        direction: dir,
        step_speeds_mps: ConstantRadiusParams::stepped_speeds(radius, 0.5, 0.5, ay_max),
        settle_s: settle,
        window_s: window,
        speed_ramp_mps2: 0.5,
    })
}

fn with_maneuver(base: &RunConfig, m: ManeuverConfig) -> RunConfig {
    let mut c = base.clone();
    if let ManeuverConfig::ConstantRadius(p) = &m {
        c.settings.duration_s = p.total_s() + 0.5;
    }
    c.maneuver = m;
    c
}

/// Left and right constant-radius turns mirror each other: same x, negated y, yaw, yaw rate and
/// roll, and the left and right wheel loads swapped.
#[test]
fn left_and_right_turns_mirror_each_other() {
    let base = common::load("maneuvers/dissertation/constant_radius_8mps_linear.toml");
    let l = execute(&with_maneuver(&base, stepped(40.0, Direction::Left, 1.0, 4.0, 1.0)));
    let r = execute(&with_maneuver(&base, stepped(40.0, Direction::Right, 1.0, 4.0, 1.0)));
    assert_eq!(l.summary.end_reason, vehsim_core::event::EndReason::Completed);
    assert_eq!(l.rows.len(), r.rows.len());
    let mut max_roll = 0.0_f64;
    for (p, q) in l.rows.iter().zip(&r.rows) {
        let (a, b) = (&p.obs, &q.obs);
        assert!((a.kin.x_m - b.kin.x_m).abs() < 1e-9, "t = {}", p.t_s);
        assert!((a.kin.y_m + b.kin.y_m).abs() < 1e-9, "t = {}: y {} vs {}", p.t_s, a.kin.y_m, b.kin.y_m);
        assert!((a.kin.yaw_rad + b.kin.yaw_rad).abs() < 1e-9);
        assert!((a.kin.yaw_rate_radps + b.kin.yaw_rate_radps).abs() < 1e-9);
        assert!((a.roll_rad + b.roll_rad).abs() < 1e-9);
        assert!((a.fz_n[0] - b.fz_n[1]).abs() < 1e-6 && (a.fz_n[2] - b.fz_n[3]).abs() < 1e-6);
        assert!((p.inputs.steer_rad + q.inputs.steer_rad).abs() < 1e-9);
        max_roll = max_roll.max(a.roll_rad.abs());
    }
    assert!(max_roll > 0.005, "the turn must roll the body ({max_roll} rad)");
    let (gl, gr) = (l.steady_states.len(), r.steady_states.len());
    assert_eq!((gl, gr), (2, 2));
    for (p, q) in l.steady_states.iter().zip(&r.steady_states) {
        assert!(p.ay_mps2 > 0.4 && (p.ay_mps2 + q.ay_mps2).abs() < 1e-9);
    }
}

/// The understeer gradient measured on a 100 m circle with lateral-acceleration steps of 0.5 m/s^2
/// (0.5 to 3 m/s^2) matches linear theory within 5 % (and the slip-angle gradient, the slope of
/// delta - L r / v_x, within 1 %), for the sedan as shipped and with ten times its front roll stiffness
/// (where load transfer moves the gradient by more than 5 %).
///
/// Theory: each tyre's cornering stiffness is C0 (Fz / Fz0)^p at the loads Fz = F_axle / 2 -+ dF(a_y)
/// of the closed-form lateral transfer, so load transfer (p = 0.8 < 1) softens an axle as a_y grows;
/// C_f, C_r are the axle sums and s_f, s_r = (C_outer - C_inner) / C_axle. The steady force and
/// yaw-moment balances, with the front lateral forces split in proportion to stiffness (the split
/// makes a yaw moment (t/2) sin(delta) (Fy_inner - Fy_outer)), give
/// Fy_f = m a_y b / (L cos delta - (t/2) s_f sin delta) and Fy_r = m a_y - Fy_f cos delta. On a path
/// of curvature rho = r / v_x the inner wheel's forward speed is lower by the fraction eps = t rho / 2, so
/// the rear slip angles are alpha_r (1 +- eps) and the front ones delta - theta (1 +- eps), theta
/// the front wheels' kinematic angle; weighting by the stiffnesses gives the axle mean slip angles
/// alpha_r = Fy_r / (C_r (1 - eps s_r)) and alpha_f = Fy_f / C_f - eps theta s_f. Then
/// delta - L rho = alpha_f - alpha_r. (The understeer
/// gradient is a small difference of two nearly equal slip angles, so effects of a few tenths of a
/// per cent on either show up as several per cent on the gradient.) The test fits a line to the
/// theory's delta - L rho at the measured lateral accelerations and compares its slope with the
/// slope the manoeuvre reports for delta - L r / v_x, and with the plain slope of delta (on a
/// 100 m circle both agree within 1 %). Drag and rolling resistance are off so that the front tyres
/// carry no longitudinal force, and the steering is parallel (Ackermann 0), as the theory assumes.
#[test]
fn understeer_gradient_matches_linear_theory_with_load_transfer() {
    let circle = "kind = \"constant_radius\"\nradius_m = 100.0\nspeed_mode = \"steps\"\nay_first_mps2 = 0.5\n\
                  ay_step_mps2 = 0.5\nay_max_mps2 = 3.0\nsettle_s = 8.0\nwindow_s = 2.0";
    let common_edits = [
        ("drag_area_m2 = 0.67", "drag_area_m2 = 0.0"),
        ("rolling_resistance = 0.010", "rolling_resistance = 0.0"),
        ("ackermann = 0.5", "ackermann = 0.0"),
    ];
    for (tag, front_k, transfer_matters) in [("us-shipped", "46000.0", false), ("us-stiff-front", "460000.0", true)] {
        let mut edits = common_edits.to_vec();
        let k_edit = format!("roll_stiffness_front_nm_per_rad = {front_k}");
        edits.push(("roll_stiffness_front_nm_per_rad = 46000.0", &k_edit));
        let cfg = scratch(tag, &edits, &[], &spec("roll4dof", 1.0, circle, ""));
        let out = execute(&cfg);
        assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Completed, "{tag}: {:?}", out.summary.events);
        let g = out.understeer_gradient.expect("an understeer gradient");
        assert_eq!(g.steps, 6);
        let raw = Raw::of(&cfg.vehicle_file);
        let tyre = TyreFileSpec::load(&cfg.vehicle_file.parent().unwrap().join("tyres/srtt_p225_60r16.toml")).unwrap();
        let lin = tyre.linear.unwrap();
        let c_tyre =
            |fz: f64| lin.cornering_stiffness_n_per_rad * (fz.max(0.0) / tyre.nominal_load_n).powf(lin.load_exponent);
        let l = raw.l();
        let w = raw.m * GRAVITY;
        let (f0, r0) = (w * raw.b / l, w * raw.a / l);
        let mut ays = Vec::new();
        let mut theory = Vec::new();
        for s in &out.steady_states {
            let ay = s.ay_mps2;
            let (dff, dfr) = raw.transfer(ay);
            let (cfl, cfr) = (c_tyre(0.5 * f0 - dff), c_tyre(0.5 * f0 + dff));
            let (crl, crr) = (c_tyre(0.5 * r0 - dfr), c_tyre(0.5 * r0 + dfr));
            let (cf, cr) = (cfl + cfr, crl + crr);
            // Outer-minus-inner stiffness shares and the inner/outer slip-angle split t rho / 2.
            let (sf, sr) = ((cfr - cfl) / cf, (crr - crl) / cr);
            let eps = 0.5 * raw.t * s.curvature_1pm;
            let (sd, cd) = s.steer_rad.sin_cos();
            // Yaw-moment balance with the front lateral forces split in proportion to stiffness.
            let fyf = raw.m * ay * raw.b / (l * cd - 0.5 * raw.t * sf * sd);
            let fyr = raw.m * ay - fyf * cd;
            // Front: alpha = delta - theta (1 +- eps) with theta = delta - alpha_f the kinematic
            // angle of the front wheels (inner wheel +); rear: alpha = alpha_r (1 +- eps).
            let alpha_f = fyf / cf - eps * (s.steer_rad - fyf / cf) * sf;
            let alpha_r = fyr / (cr * (1.0 - eps * sr));
            ays.push(ay);
            theory.push(alpha_f - alpha_r);
            assert!((s.vx_mps - s.speed_target_mps).abs() < 0.01 * s.speed_target_mps, "{tag}: speed not held");
        }
        let fit = vehsim_core::sim::steady_state::linear_fit(&ays, &theory).unwrap();
        let k0 = raw.m / l * (raw.b / (2.0 * c_tyre(0.5 * f0)) - raw.a / (2.0 * c_tyre(0.5 * r0)));
        eprintln!(
            "{tag}: K_us measured {:.4e} (slip-angle {:.4e}, 95 % CI {:.4e}..{:.4e}), theory {:.4e}, \
             theory without load transfer {:.4e} rad/(m/s^2)",
            g.rad_per_mps2,
            g.slip_angle_gradient_rad_per_mps2,
            g.ci95_rad_per_mps2[0],
            g.ci95_rad_per_mps2[1],
            fit.slope,
            k0
        );
        let err = (g.slip_angle_gradient_rad_per_mps2 - fit.slope).abs() / fit.slope;
        assert!(err < 0.05, "{tag}: slip-angle K_us {} vs theory {}", g.slip_angle_gradient_rad_per_mps2, fit.slope);
        let err = (g.rad_per_mps2 - fit.slope).abs() / fit.slope;
        assert!(err < 0.05, "{tag}: K_us {} vs theory {} ({err})", g.rad_per_mps2, fit.slope);
        // 5 % is a meaningful tolerance: neutral steer (0) lies far outside it.
        assert!(k0 > 2e-4 && fit.slope > 2e-4, "{tag}: the sedan must understeer: {k0}, {}", fit.slope);
        if transfer_matters {
            assert!((fit.slope - k0).abs() > 0.05 * fit.slope, "{tag}: load transfer changes too little to be tested");
        }
        assert!(g.ci95_rad_per_mps2[0] < g.rad_per_mps2 && g.rad_per_mps2 < g.ci95_rad_per_mps2[1]);
    }
}

/// Standstill start and stop, steered and straight, with the 4-DOF model: no NaN, no event.
#[test]
fn standstill_start_and_stop_with_the_4dof_model() {
    let straight =
        "kind = \"straight\"\nspeed_schedule = [[0.0, 0.0], [1.0, 0.0], [5.0, 10.0], [8.0, 10.0], [11.0, 0.0]]";
    let cfg = scratch("standstill", &[], &[], &spec("roll4dof", 0.15, straight, "duration_s = 16.0"));
    let out = execute(&cfg);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Duration, "{:?}", out.summary.events);
    assert!(out.summary.max_speed_mps > 9.5);
    let end = out.rows.last().unwrap();
    assert!(end.obs.kin.speed_mps() < 0.05);
    assert!(out.rows.iter().all(|r| r.obs.fz_n.iter().chain(&r.obs.kappa).all(|v| v.is_finite())));
    // The same schedule with the wheels steered 0.15 rad from the start.
    let mut steered = cfg.clone();
    steered.maneuver = ManeuverConfig::OpenLoop {
        steer: SteerProfile::Step { amplitude_rad: 0.15, start_s: 0.0, ramp_s: 0.0 },
        speed: SpeedSchedule { points: vec![(0.0, 0.0), (1.0, 0.0), (5.0, 10.0), (8.0, 10.0), (11.0, 0.0)] },
    };
    let out = execute(&steered);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Duration, "{:?}", out.summary.events);
    assert!(out.summary.max_speed_mps > 9.5);
    assert!(out.rows.last().unwrap().obs.kin.speed_mps() < 0.05);
    assert!(out.rows.iter().all(|r| r.obs.fz_n.iter().chain(&r.obs.kappa).all(|v| v.is_finite())));
}

/// An oversteering car (CG far back) above its critical speed spins: a `spin_out` event ends the
/// run; an unstable integration (RK4 at 10 ms on a 1 ms lag) ends it with `diverged`; a wheel that lifts is reported. No panic anywhere.
#[test]
fn spin_out_divergence_and_wheel_lift_are_events() {
    let sine = "kind = \"sine_steer\"\nspeed_mps = 20.0\nsteer_amplitude_deg = 3.0\nperiod_s = 4.0";
    let back = [
        ("cg_to_front_axle_m = 1.09", "cg_to_front_axle_m = 2.2"),
        ("cg_to_rear_axle_m = 1.71", "cg_to_rear_axle_m = 0.6"),
    ];
    let cfg = scratch(
        "spin",
        &back,
        &[("saturate = false", "saturate = true")],
        &spec("roll4dof", 0.15, sine, "duration_s = 20.0"),
    );
    let out = execute(&cfg);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::SpinOut, "{:?}", out.summary.events);
    assert!(out.summary.events.iter().any(|e| e.kind == vehsim_core::event::EventKind::SpinOut));

    // RK4 at 10 ms on a 1 ms load-transfer lag is unstable (h / tau = 10 > 2.8): the lag state
    // grows by a factor ~290 per step until it overflows, while the clamped load transfer and the
    // friction-limited (saturating) tyre keep the vehicle itself sane, so the run ends `diverged`
    // (not with a spin-out), naming the state. A spec asking for that step is refused (the bound is
    // in the message); the engine is given it directly.
    let lag = [("ackermann = 0.5", "ackermann = 0.5\nload_transfer_lag_s = 0.001")];
    let straight = "kind = \"straight\"\nspeed_schedule = [[0.0, 10.0]]";
    let spec_text = spec("roll4dof", 0.15, straight, "duration_s = 10.0\n[integrator]\nstep_s = 0.01");
    let mut cfg = scratch(
        "diverge",
        &lag,
        &[("saturate = false", "saturate = true")],
        &spec("roll4dof", 0.15, straight, "duration_s = 10.0"),
    );
    std::fs::write(cfg.spec_file.with_file_name("refused.toml"), &spec_text).unwrap();
    let err = vehsim_spec::run::load(&cfg.spec_file.with_file_name("refused.toml")).unwrap_err().to_string();
    assert!(
        err.contains("integrator.step_s") && err.contains("stability bound") && err.contains("expected step_s <="),
        "{err}"
    );
    cfg.settings.step_s = 0.01;
    cfg.settings.control_period_s = 0.01;
    let out = execute(&cfg);
    assert_eq!(out.summary.end_reason, vehsim_core::event::EndReason::Diverged, "{:?}", out.summary.events);
    let e = out.summary.events.iter().find(|e| e.kind == vehsim_core::event::EventKind::Diverged).unwrap();
    assert!(e.detail.contains("non-finite") && e.detail.contains("ax_lagged"), "{}", e.detail);
    assert!(out.summary.end_time_s < 5.0);

    let high = [("cg_height_m = 0.55", "cg_height_m = 1.2")];
    let circle = "kind = \"constant_radius\"\nradius_m = 40.0\nspeed_mps = 17.0\nsettle_s = 6.0\nwindow_s = 1.0";
    let cfg = scratch("lift", &high, &[], &spec("roll4dof", 1.0, circle, ""));
    let out = execute(&cfg);
    assert!(
        out.summary.events.iter().any(|e| e.kind == vehsim_core::event::EventKind::WheelLift),
        "{:?}",
        out.summary.events
    );
    let w = cfg.vehicle.mass_kg * GRAVITY;
    for r in &out.rows {
        assert!(r.obs.fz_n.iter().all(|f| *f >= 0.0));
        assert!((r.obs.fz_n.iter().sum::<f64>() - w).abs() < 1e-3 * w);
    }
}

/// Halving the RK4 step on the 4-DOF DLC (controller sampled every 4 ms in all runs, so only the
/// integration error changes) cuts the yaw-rate error against a Dop853 reference (rtol 1e-13) about
/// 16-fold per halving: fourth order. The change between successive halvings shows the same
/// order without any reference.
#[test]
fn rk4_on_the_4dof_model_converges_at_fourth_order() {
    let base = common::load("maneuvers/dlc_roll4dof.toml");
    let with = |m: Method, h: f64| {
        let mut c = base.clone();
        c.settings.method = m;
        c.settings.step_s = h;
        c.settings.control_period_s = 0.004;
        c.settings.output_interval_s = 0.02;
        execute(&c)
    };
    let runs: Vec<RunOutput> = [0.004, 0.002, 0.001].iter().map(|&h| with(Method::Rk4, h)).collect();
    let reference = with(Method::Dop853 { rtol: 1e-13, atol: 1e-14 }, 0.004);
    assert_eq!(reference.summary.end_reason, vehsim_core::event::EndReason::Completed);
    let errs: Vec<f64> = runs.iter().map(|r| common::max_yaw_rate_diff(r, &reference)).collect();
    let diffs: Vec<f64> = runs.windows(2).map(|w| common::max_yaw_rate_diff(&w[0], &w[1])).collect();
    eprintln!("4-DOF RK4 max yaw-rate error vs Dop853 at h = 4, 2, 1 ms: {errs:?}; change per halving {diffs:?}");
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.5..4.6).contains(&order), "errors {errs:?}: observed order {order}");
    }
    let order = (diffs[0] / diffs[1]).log2();
    assert!((3.5..4.6).contains(&order), "differences {diffs:?}: observed order {order}");
    assert!(errs[2] < 1e-9, "RK4 at 1 ms vs Dop853: {} rad/s", errs[2]);
    assert!(runs[2].summary.peak_yaw_rate_radps > 0.2);
}
