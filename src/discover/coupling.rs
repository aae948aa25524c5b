//! Longitudinal–lateral coupling in the replay (the `longitudinal_coupling` effect): the measured
//! speed change becomes the tyres' longitudinal forces, which load the axles longitudinally and
//! take friction from their lateral capacity through the tyre's own combined slip.
//!
//! Without it the replay's tyres roll free (slip ratio 0) on static loads, whatever the speed
//! does. With it, at every evaluation (body frame, ISO 8855; forces in N, positive driving):
//!
//! - **The force the tyres must give along the body**: from the run's logged `ax` when it has one
//!   (the accelerometer's specific force, the contact and aerodynamic forces over the mass),
//!   S = m a_x,logged + F_drag(v_x); else from the prescribed speed's slope a_x (m/s^2; the
//!   measured v_x's slope over ±0.25 s, `AX_HALF_WINDOW_S`), S = m (a_x − r v_y) + F_drag(v_x) −
//!   m g_x, with g_x the road's grade component (`vehsim_core::vehicle::road`) and
//!   F_drag = ½ ρ C_d A v_x |v_x|. The wheels' spin-up takes dv_x/dt (the slope, or
//!   a_x,logged + r v_y + g_x).
//! - **Its split between the axles** as the engine's bicycle drives and brakes them: both axles'
//!   wheel torques come from one torque Q R shared by the drive shares (s_f, s_r) when Q > 0
//!   and by the brake shares otherwise; each axle's torque also turns its wheels
//!   (J_i a_x / R, J_i the axle's two wheel inertias) and overcomes its rolling resistance
//!   (c_rr F_z,i R), so axle i's tyres give F_i = s_i Q − e_i, e_i = c_rr F_z,i + J_i a_x / R^2.
//!   The body balance F_f cos δ − F_yf sin δ + F_r = S then gives
//!   Q = (S + F_yf sin δ + e_f cos δ + e_r) / (s_f cos δ + s_r), with the front lateral force's
//!   component along the body taken at its steady-turn value F_yf ≈ m (b / L) v_x r (a small term:
//!   sin δ ≲ 0.1). Powertrain inertia and engine braking are not modelled (the engine's PID
//!   without a `[powertrain]` has neither).
//! - **The longitudinal load transfer**: each front tyre's load falls and each rear tyre's rises
//!   by h S / (2 L) ([`vehsim_core::vehicle::lateral::longitudinal_transfer_n`], the engine's
//!   own), h the fitted transfer height (m).
//! - **The slip ratio** κ_i of each axle at which its tyres, at their slip angle and loads, give
//!   F_i (`axle_slip`); their lateral force is then the tyre's combined-slip one at κ_i. An axle
//!   asked for more than its tyres can give stays at its largest force (the κ of the peak found).
//!
//! The contact heat of the thermal forms still takes the slip angle's sliding speed only (the
//! slip ratio's share of the sliding is left out there).
//!
//! The engine's bicycle has the same forces through its wheel-spin states (the speed comes from
//! its PID's torque), and the same transfer at `[lateral] longitudinal_transfer_height_m`, which is
//! where discovery writes h.

use vehsim_core::tyre::TyreForces;
use vehsim_core::vehicle::road::Road;
use vehsim_core::vehicle::{lateral, Vehicle};

/// Half width of the window over which the coupling takes the measured speed's slope, s
/// ([`vehsim_core::vehicle::sensors::longitudinal_acceleration_over`]). A speed of white noise σ_v
/// gives a slope of noise σ_v·√2/(2w) (0.057 m/s² for the synthetic runs' 0.02 m/s), and a brake
/// onset is spread over 2w. On the engine's braking runs of `tests/discover_coupling.rs` (a brake
/// step, generated h = 0.55 m) the fitted height was 0.599 m at w = 0.5 s, 0.575 at 0.25 s, 0.562
/// at 0.12 s, and at 0.06 s the slope's noise left the set unexplained: 0.25 s keeps a margin of
/// four in noise from that.
pub(super) const AX_HALF_WINDOW_S: f64 = 0.25;

/// What the measured speed change asks of the axles at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Demand {
    /// Longitudinal force of each axle's two tyres (front, rear), wheel axes, N.
    pub(super) fx_n: [f64; 2],
    /// Load change of each tyre (front, rear), N.
    pub(super) dfz_n: [f64; 2],
}

/// The forward acceleration the coupling is given, m/s^2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Accel {
    /// The measured speed's slope dv_x/dt (over ±[`AX_HALF_WINDOW_S`]).
    Slope(f64),
    /// The run's logged `ax`: the accelerometer's specific force along the body, the contact and
    /// aerodynamic forces over the mass, (S − F_drag)/m.
    Logged(f64),
}

/// The demand of the measured forward acceleration `ax` on the vehicle `v` at forward speed `vx`
/// (m/s), lateral velocity `vy` (m/s), yaw rate `r` (rad/s), road-wheel angle `steer` (rad) and
/// road `road`, with transfer height `h_m` (m).
pub(super) fn demand(
    v: &Vehicle,
    h_m: f64,
    ax: Accel,
    (vx, vy, r): (f64, f64, f64),
    steer: f64,
    road: &Road,
) -> Demand {
    let m = v.mass_kg;
    let l = v.wheelbase_m();
    let drag = v.drag_n(vx);
    let gx = if road.is_flat() { 0.0 } else { road.gravity_in_plane().0 };
    // The tyres' force along the body S and the speed's rate dv_x/dt, from m(dv_x/dt − r v_y) =
    // S − F_drag + m g_x.
    let (s, dvx_dt) = match ax {
        Accel::Slope(a) => (m * (a - r * vy) + drag - m * gx, a),
        Accel::Logged(a) => (m * a + drag, a + r * vy + gx),
    };
    let (ff, fr) = v.static_axle_loads_n();
    let radius = v.tyre.rolling_radius_m;
    let spin = 2.0 * v.wheel_inertia_kgm2 * dvx_dt / (radius * radius);
    let e = [v.rolling_resistance * ff + spin, v.rolling_resistance * fr + spin];
    let (sin_d, cos_d) = steer.sin_cos();
    let fy_front = m * v.b_m / l * vx * r;
    let n = s + fy_front * sin_d + e[0] * cos_d + e[1];
    let share = if n >= 0.0 { v.drive_front_share() } else { v.brake_front_share };
    let q = n / (share * cos_d + (1.0 - share));
    let [df, dr] = lateral::longitudinal_transfer_n(h_m, s, l);
    Demand { fx_n: [share * q - e[0], (1.0 - share) * q - e[1]], dfz_n: [0.5 * df, 0.5 * dr] }
}

/// Slip ratios of the bracket search from free rolling, in order of magnitude.
const BRACKET: [f64; 6] = [0.002, 0.01, 0.04, 0.15, 0.5, 1.0];
/// Most regula-falsi iterations inside a bracket.
const MAX_ITER: usize = 40;
/// Force tolerance of the slip solve, relative to the axle load.
const TOL: f64 = 1e-7;

/// The slip ratio at which an axle's tyres give the longitudinal force `target_n` (N) and their
/// forces there: `axle(kappa)` evaluates the axle's two tyres at slip ratio kappa; `fz_axle_n`
/// (N) scales the tolerance. The force is searched from free rolling outwards in the target's
/// direction over [`BRACKET`] and refined by the Illinois form of regula falsi to within
/// 1e-7 of the axle load; a target beyond the tyres' reach returns the bracket point of the
/// largest force in its direction.
pub(super) fn axle_slip(target_n: f64, fz_axle_n: f64, axle: impl Fn(f64) -> TyreForces) -> (f64, TyreForces) {
    let tol = TOL * fz_axle_n.max(1.0);
    let f0 = axle(0.0);
    let g = |t: &TyreForces| t.fx_n - target_n;
    let (mut a, mut fa, mut ta) = (0.0, g(&f0), f0);
    if fa.abs() <= tol {
        return (0.0, f0);
    }
    let dir = -fa.signum();
    // The bracket: the first point whose residual changes sign; else the best in its direction.
    let mut bracket = None;
    for k in BRACKET.map(|k| dir * k) {
        let t = axle(k);
        let fk = g(&t);
        if fk.signum() != fa.signum() {
            bracket = Some((k, fk, t));
            break;
        }
        if fk * dir > fa * dir {
            (a, fa, ta) = (k, fk, t);
        }
    }
    let Some((mut b, mut fb, mut tb)) = bracket else { return (a, ta) };
    // Illinois: regula falsi that halves the retained end's residual when an end is kept twice.
    let mut side = 0;
    for _ in 0..MAX_ITER {
        let c = b - fb * (b - a) / (fb - fa);
        let t = axle(c);
        let fc = g(&t);
        if fc.abs() <= tol {
            return (c, t);
        }
        if fc.signum() == fb.signum() {
            (b, fb, tb) = (c, fc, t);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            (a, fa, ta) = (c, fc, t);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    if fa.abs() < fb.abs() {
        (a, ta)
    } else {
        (b, tb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vehsim_core::vehicle::AIR_DENSITY;

    /// A saturating axle: Fx = 3000 tanh(20 kappa) N.
    fn axle(k: f64) -> TyreForces {
        TyreForces { fx_n: 3000.0 * (20.0 * k).tanh(), fy_n: 0.0, mz_nm: 0.0 }
    }

    /// The solve meets the closed-form inverse within its tolerance in both directions, returns
    /// free rolling for a zero target, and a target beyond the peak returns the largest force.
    #[test]
    fn slip_solve_inverts_a_saturating_axle() {
        for target in [-2500.0, -300.0, 1.0, 800.0, 2900.0] {
            let (k, t) = axle_slip(target, 10_000.0, axle);
            let want = (target / 3000.0f64).atanh() / 20.0;
            assert!((t.fx_n - target).abs() <= 1e-3, "{target}: {}", t.fx_n);
            assert!((k - want).abs() < 1e-6, "{target}: kappa {k} against {want}");
        }
        assert_eq!(axle_slip(0.0, 10_000.0, axle).0, 0.0);
        let (k, t) = axle_slip(3500.0, 10_000.0, axle);
        assert_eq!(k, 1.0);
        assert!(t.fx_n > 2999.0);
    }

    /// The demand's split closes the body balance: F_f cos(delta) - F_yf sin(delta) + F_r plus
    /// each axle's wheel-spin and rolling terms equals S, with F_yf at its steady-turn estimate;
    /// braking goes by the brake shares, driving by the drive shares, and the transfer loads the
    /// front under braking.
    #[test]
    fn demand_closes_the_body_balance() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let kind = crate::discover::tyre_kind("pacejka").unwrap();
        let v = crate::discover::load_vehicle(&root.join("vehicles/sedan.toml"), None, kind).unwrap();
        for (ax, r, steer) in [(-3.0, 0.3, 0.05), (2.0, -0.2, -0.03), (0.0, 0.0, 0.0)] {
            let (vx, vy) = (15.0, 0.4);
            let d = demand(&v, 0.55, Accel::Slope(ax), (vx, vy, r), steer, &Road::default());
            let drag = 0.5 * AIR_DENSITY * v.drag_area_m2 * vx * vx;
            let s = v.mass_kg * (ax - r * vy) + drag;
            let fyf = v.mass_kg * v.b_m / v.wheelbase_m() * vx * r;
            let body = d.fx_n[0] * steer.cos() - fyf * steer.sin() + d.fx_n[1];
            assert!((body - s).abs() < 1e-9 * s.abs().max(1.0), "{ax}: {body} against {s}");
            assert!((d.dfz_n[0] + 0.55 * s / (2.0 * v.wheelbase_m())).abs() < 1e-9);
            assert_eq!(d.dfz_n[0], -d.dfz_n[1]);
        }
        // The sedan is front-driven: driving leaves the rear only its rolling and spin terms.
        let d = demand(&v, 0.55, Accel::Slope(2.0), (15.0, 0.0, 0.0), 0.0, &Road::default());
        let (_, fr) = v.static_axle_loads_n();
        let spin = 2.0 * v.wheel_inertia_kgm2 * 2.0 / v.tyre.rolling_radius_m.powi(2);
        assert!((d.fx_n[1] + v.rolling_resistance * fr + spin).abs() < 1e-9);
        // Braking shares the torque by the brake balance.
        let d = demand(&v, 0.55, Accel::Slope(-3.0), (15.0, 0.0, 0.0), 0.0, &Road::default());
        let (ff, _) = v.static_axle_loads_n();
        let spin = 2.0 * v.wheel_inertia_kgm2 * -3.0 / v.tyre.rolling_radius_m.powi(2);
        let q = (d.fx_n[0] + v.rolling_resistance * ff + spin) / v.brake_front_share;
        let rear = d.fx_n[1] + v.rolling_resistance * (v.mass_kg * 9.80665 - ff) + spin;
        assert!((rear - (1.0 - v.brake_front_share) * q).abs() < 1e-6);
        assert!(d.dfz_n[0] > 0.0);
    }

    /// A logged ax (specific force) is the speed's slope less r v_y and the grade's g_x: on a
    /// graded, banked road the two inputs give the same demand.
    #[test]
    fn a_logged_ax_is_the_slope_without_the_kinematic_and_gravity_terms() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let kind = crate::discover::tyre_kind("pacejka").unwrap();
        let v = crate::discover::load_vehicle(&root.join("vehicles/sedan.toml"), None, kind).unwrap();
        let road = Road::from_deg(3.0, 4.0);
        let (vx, vy, r, steer) = (15.0, 0.4, 0.3, 0.05);
        for slope in [-3.0, 0.0, 2.0] {
            let logged = slope - r * vy - road.gravity_in_plane().0;
            let a = demand(&v, 0.55, Accel::Slope(slope), (vx, vy, r), steer, &road);
            let b = demand(&v, 0.55, Accel::Logged(logged), (vx, vy, r), steer, &road);
            for k in 0..2 {
                assert!((a.fx_n[k] - b.fx_n[k]).abs() < 1e-9 * a.fx_n[k].abs().max(1.0), "{a:?} {b:?}");
                assert!((a.dfz_n[k] - b.dfz_n[k]).abs() < 1e-9 * a.dfz_n[k].abs().max(1.0), "{a:?} {b:?}");
            }
        }
    }
}
