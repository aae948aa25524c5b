//! Nonlinear bicycle (single-track) model with wheel spin and transient longitudinal slip.
//!
//! State (13): X, Y (m, ground frame), yaw psi (rad), body-frame vx, vy (m/s), yaw rate r (rad/s),
//! front and rear wheel spin omega_f, omega_r (rad/s), front and rear relaxed slip ratios, front
//! and rear relaxed axle lateral forces (N; used only with a lateral relaxation length) and the
//! lagged road-wheel angle (rad; used only with a steering lag).
//! Each axle carries two tyres at half the axle load, one mounted on the left and one on the
//! right ([`crate::tyre::Tyre::on`]), both at the axle's slip: the axle force is their sum,
//! twice the tyre force for a tyre that is its own mirror image; for a `.tir` tyre with
//! side-dependent coefficients the mirrored pair cancels conicity and ply steer (docs/tyres.md). Normal loads are static (the classic bicycle model has no load transfer; the 4-DOF model
//! adds it). Equations, body frame, ISO 8855 (Newton–Euler, equivalent to the dissertation's
//! Lagrange form eq. 6.1–6.78 written in the inertial frame):
//!
//!   m (dvx/dt - r vy) = Fx_f cos(delta) - Fy_f sin(delta) + Fx_r - F_drag
//!   m (dvy/dt + r vx) = Fx_f sin(delta) + Fy_f cos(delta) + Fy_r
//!   I_z dr/dt         = a (Fx_f sin(delta) + Fy_f cos(delta)) - b Fy_r + Mz_f + Mz_r
//!   dX/dt = vx cos(psi) - vy sin(psi),  dY/dt = vx sin(psi) + vy cos(psi),  dpsi/dt = r
//!   2 I_w domega/dt   = T_drive - T_brake - T_roll - R_e Fx        (per axle)
//!
//! with the slips from [`super::wheel`]; the lateral pair is [`super::single_track`]'s, shared
//! with `vehsim discover`'s replay model. Optional `[lateral]` extensions of the vehicle spec
//! (the effects `vehsim discover` names; the same equations as its replay model, shared through
//! [`super::lateral`]); every default leaves the model exactly as above:
//! - steering lag: d(delta_l)/dt = (delta - delta_l) / tau, and delta_l replaces delta;
//! - steer compliance: delta_e = delta_l - c Fy_f (c in rad/kN; Fy_f the acting front force: the
//!   relaxed state, else the steady-state force at delta_e, [`lateral::compliant_steer`]);
//! - lateral relaxation: dFy/dt = (max(|vx|, 1 m/s) / sigma_y) (Fy_ss - Fy) per axle, and the
//!   relaxed Fy acts on the body (the longitudinal force is relaxed through the slip ratio);
//! - lateral load transfer: each axle's tyres carry Fz/2 +- m vx r h / track x (axle share of the
//!   weight), so the tyre's load sensitivity lowers the axle force;
//! - friction: mu_e = mu s_mu max(1 + k_T (T_contact - T_surface), 0.1) s_i, where T_contact comes
//!   from the contact-temperature estimator (isothermal unless the manoeuvre sets
//!   `[contact] model = "atiim"`) and s_i is axle i's friction factor;
//! - friction regions of the manoeuvre's ground (`[[surface.patch]]`, `[[surface.band]]`): axle
//!   i's friction times the regions' factor at its own ground position ([`super::ground`]);
//! - per-axle cornering stiffness: axle i's tyres see c_i alpha (slope at 0 scaled by c_i, peak
//!   unchanged);
//! - load sensitivities (with load transfer): each tyre's friction and slip angle scaled by
//!   max(1 - k z, 0.05), z = Fz / Fz0 - 1 ([`lateral::load_factor`]);
//! - transient slip: the tyres carry lagged slip angles alpha_i (states in the relaxed-force
//!   slots), d(alpha_i)/dt = (max(|vx|, 1 m/s) / sigma_i) (alpha_kin,i - alpha_i), sigma_i
//!   optionally shortened by the tyre's local slope ([`lateral::saturating_relaxation_length`]);
//!   the steer compliance then acts through the force at the lagged front slip angle.
//! - longitudinal load transfer (`longitudinal_transfer_height_m` h > 0): each front tyre's
//!   load falls and each rear tyre's rises by h S / (2 L), with S = Fx_f cos(delta) + Fx_r -
//!   Fy_f sin(delta) the tyres' force along the body (positive driving), L the wheelbase
//!   ([`lateral::longitudinal_transfer_n`]); S depends on the loads through the tyres, so the
//!   balance is solved per evaluation (two fixed-point passes and a secant step, then the forces
//!   at its root: three tyre evaluations per axle instead of one);
//! - the road's bank and grade (a manoeuvre's `[road]`, [`super::road`]): gravity's in-plane
//!   components g_x, g_y added to dvx/dt and (as the force m g_y at the CG) to the lateral
//!   balance, and each tyre's static load that of its axle on the road (scaled by the normal
//!   component, shifted rearwards uphill at the CG height); the observed accelerations stay the
//!   contact forces over the mass (what an accelerometer logs).

use nalgebra::SVector;

use super::capability::{Monitored, SpinSlip, WheelSpeeds};
use super::wheel::{
    relaxed_slip_rate, resisting_omega1, resisting_torque_at, slide_speed, slip_angle, to_wheel_axes, V_LOW,
};
use super::{lateral, single_track, Condition, Environment, Extras, Inputs, Observation, VehicleModel};
use crate::contact::TyreContact;
use crate::tyre::{Prepared, TyreForces, TyreInput};
use crate::vehicle::Vehicle;

/// State dimension of the bicycle model.
pub const N: usize = 13;
/// State indices.
pub mod ix {
    /// Ground-frame X position of the CG, m.
    pub const X: usize = 0;
    /// Ground-frame Y position of the CG, m (positive left of the start heading).
    pub const Y: usize = 1;
    /// Yaw angle psi, rad (positive counter-clockwise seen from above).
    pub const YAW: usize = 2;
    /// Body-frame longitudinal velocity vx, m/s (positive forward).
    pub const VX: usize = 3;
    /// Body-frame lateral velocity vy, m/s (positive left).
    pub const VY: usize = 4;
    /// Yaw rate r, rad/s (positive turning left).
    pub const R: usize = 5;
    /// Front wheel spin omega_f, rad/s (positive rolling forward).
    pub const OMEGA_F: usize = 6;
    /// Rear wheel spin omega_r, rad/s (positive rolling forward).
    pub const OMEGA_R: usize = 7;
    /// Front relaxed slip ratio, dimensionless (positive driving).
    pub const KAPPA_F: usize = 8;
    /// Rear relaxed slip ratio, dimensionless (positive driving).
    pub const KAPPA_R: usize = 9;
    /// Front relaxed axle lateral force, N (positive left; used only with a lateral relaxation
    /// length); under transient slip (`lateral.relaxation_length_front_m`) the lagged front slip
    /// angle, rad, instead.
    pub const FY_F: usize = 10;
    /// Rear relaxed axle lateral force, N (as [`FY_F`]; the lagged rear slip angle under
    /// transient slip).
    pub const FY_R: usize = 11;
    /// Lagged road-wheel angle delta_l, rad (positive left; used only with a steering lag).
    pub const DELTA_L: usize = 12;
}

/// The bicycle model: a validated vehicle plus precomputed constants.
#[derive(Debug, Clone)]
pub struct Bicycle {
    /// The validated vehicle the model reads.
    pub vehicle: Vehicle,
    /// Static load per tyre (front, rear), N.
    fz_tyre: [f64; 2],
    /// Spin inertia per axle (two wheels), kg m^2.
    axle_inertia: f64,
    /// Rolling-resistance torque per axle at the static loads, N m, and the regularisation
    /// speed of the axle's resisting torque ([`resisting_omega1`]), rad/s (vehicle constants).
    roll_torque: [f64; 2],
    resist_omega1: [f64; 2],
    /// Tyre coefficients prepared for each axle's static load on a surface
    /// ([`Bicycle::prepared_for`]); used for the inputs they match, `None` until prepared.
    prepared: [Option<Prepared>; 2],
}

/// Per-axle intermediate quantities of one evaluation.
struct Axles {
    vxw: [f64; 2],
    /// Slip angles the tyres carry (the lagged ones under transient slip), rad.
    alpha: [f64; 2],
    /// Kinematic slip angles (what the lagged ones relax towards under transient slip), rad.
    alpha_kin: [f64; 2],
    /// Transient-slip rates |vx| / sigma_i per axle, 1/s (0 without transient slip).
    slip_rate: [f64; 2],
    /// Force per axle (two tyres).
    f: [TyreForces; 2],
    /// Wheel torque balance per axle: drive - brake - rolling resistance, N m.
    torque: [f64; 2],
    cos_d: f64,
    sin_d: f64,
    /// Longitudinal load change of each tyre (front, rear), N: half its axle's
    /// [`lateral::longitudinal_transfer_n`] (0 without `longitudinal_transfer_height_m`).
    long: [f64; 2],
}

impl Bicycle {
    /// The model for `vehicle`, with its static tyre loads, axle inertia and rolling-resistance torques precomputed.
    pub fn new(vehicle: Vehicle) -> Self {
        let (ff, fr) = vehicle.static_axle_loads_n();
        let fz_tyre = [ff / 2.0, fr / 2.0];
        let axle_inertia = 2.0 * vehicle.wheel_inertia_kgm2;
        let bmax = vehicle.brake_torque_max_nm;
        let brake_max = [bmax * vehicle.brake_front_share, bmax * (1.0 - vehicle.brake_front_share)];
        let radius = vehicle.tyre.rolling_radius_m;
        let roll_torque = fz_tyre.map(|fz| vehicle.rolling_resistance * 2.0 * fz * radius);
        let resist_omega1 = [0, 1].map(|i| resisting_omega1((brake_max[i] + roll_torque[i]).max(1.0), axle_inertia));
        Self { vehicle, fz_tyre, axle_inertia, roll_torque, resist_omega1, prepared: [None; 2] }
    }

    /// Whether both axles hold a prepared Magic Formula curve (the fast path of
    /// [`Self::prepared_for`] is taken); for tests across crates.
    #[doc(hidden)]
    pub fn has_prepared_curves(&self) -> bool {
        self.prepared.iter().all(|p| p.is_some_and(|p| p.pacejka.is_some()))
    }

    /// The model with its tyres' coefficients prepared for the static loads on `env` at the
    /// surface temperature (the explicit prepare step of [`crate::tyre::TyreModel::prepare`]):
    /// evaluations at those conditions skip the load-dependent part; any other (a contact-heated
    /// tyre, load transfer) is evaluated in full. The forces are the same bit for bit.
    pub fn prepared_for(mut self, env: &Environment) -> Self {
        for i in 0..2 {
            let input = TyreInput {
                fz_n: self.fz_tyre[i],
                kappa: 0.0,
                alpha_rad: 0.0,
                camber_rad: 0.0,
                vx_mps: 0.0,
                mu_surface: env.mu * self.vehicle.lateral.mu_scale * self.vehicle.lateral.mu_axle_scale[i],
                surface_temp_c: env.surface_temp_c,
                contact_temp_c: env.surface_temp_c,
            };
            self.prepared[i] = Some(self.vehicle.tyre.mounted[0].prepare(&input));
        }
        self
    }

    fn axles(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> Axles {
        let h = self.vehicle.lateral.longitudinal_transfer_height_m;
        if h != 0.0 {
            return self.axles_transferred(x, u, env, h);
        }
        self.axles_with::<false>(x, u, env, [0.0; 2])
    }

    /// [`Self::axles`] with longitudinal load transfer at height `h` (m): the loads depend on the
    /// tyres' longitudinal forces, which depend on the loads. The balance S = g(S) (S the tyres'
    /// force along the body's x axis, g(S) that force at the loads S moves) is solved by one
    /// secant step from two fixed-point passes ([`pitch_balance`]), then the forces are taken at
    /// its root. (Kept out of line: the static-load path is the hot one.)
    #[inline(never)]
    fn axles_transferred(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, h: f64) -> Axles {
        let l = self.vehicle.wheelbase_m();
        let long = |s: f64| lateral::longitudinal_transfer_n(h, s, l).map(|d| 0.5 * d);
        let s0 = self.tyre_fx_body(x, &self.axles_with::<true>(x, u, env, [0.0; 2]));
        let s1 = self.tyre_fx_body(x, &self.axles_with::<true>(x, u, env, long(s0)));
        self.axles_with::<true>(x, u, env, long(pitch_balance(s0, s1)))
    }

    /// The tyres' acting force along the body's x axis, N (the drag excluded).
    fn tyre_fx_body(&self, x: &SVector<f64, N>, ax: &Axles) -> f64 {
        let [f, r] = self.acting(x, ax);
        f.fx_n * ax.cos_d - f.fy_n * ax.sin_d + r.fx_n
    }

    /// [`Self::axles`] with each tyre's load changed by `long` (front, rear), N. `T`: whether
    /// `long` may be other than 0 (false: the static-load path, compiled without it).
    #[inline(always)]
    fn axles_with<const T: bool>(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, long: [f64; 2]) -> Axles {
        let lat = &self.vehicle.lateral;
        let c = lat.steer_compliance_rad_per_kn * 1e-3;
        let steer = if lat.steer_lag_s > 0.0 { x[ix::DELTA_L] } else { u.steer_rad };
        if c == 0.0 {
            // (the common case, kept out of the fixed point's closures: they cost the hot path
            // its inlining)
            return self.axles_at::<T>(x, u, env, steer, long);
        }
        if lat.relaxation_length_y_m > 0.0 {
            // With relaxation the acting front force is a state: no iteration needed.
            return self.axles_at::<T>(x, u, env, lateral::effective_steer(steer, c, x[ix::FY_F]), long);
        }
        if lat.transient_slip() {
            // Transient slip: the front force follows the lagged slip angle (a state), so the
            // compliance acts through it without iteration.
            let fy = self.axles_at::<T>(x, u, env, steer, long).f[0].fy_n;
            return self.axles_at::<T>(x, u, env, lateral::effective_steer(steer, c, fy), long);
        }
        // Steer compliance: effective steer delta - c Fy_f with the steady-state front force, a
        // fixed point (none without compliance).
        lateral::compliant_steer(steer, c, |d| self.axles_at::<T>(x, u, env, d, long), |ax| ax.f[0].fy_n).1
    }

    /// Static load of one tyre of axle `i` on the road of `env`, N: the level one on a flat road,
    /// else half the axle's normal load on the bank and grade ([`super::road::Road::axle_loads_n`],
    /// at the vehicle's CG height).
    fn tyre_load(&self, env: &Environment, i: usize) -> f64 {
        if env.road.is_flat() {
            return self.fz_tyre[i];
        }
        let v = &self.vehicle;
        0.5 * env.road.axle_loads_n(v.mass_kg, v.a_m, v.b_m, v.cg_height_m)[i]
    }

    /// [`Self::tyre_load`] changed by the longitudinal load transfer `long[i]` (N), at least 0.
    #[inline(always)]
    fn loaded<const T: bool>(&self, env: &Environment, i: usize, long: [f64; 2]) -> f64 {
        if !T || long[i] == 0.0 {
            return self.tyre_load(env, i);
        }
        (self.tyre_load(env, i) + long[i]).max(0.0)
    }

    /// Lateral load transfer per axle (added to one tyre, taken from the other), N.
    fn load_transfer(&self, x: &SVector<f64, N>, axle: usize) -> f64 {
        let v = &self.vehicle;
        let h = v.lateral.load_transfer_height_m;
        if h == 0.0 {
            return 0.0;
        }
        let share = self.fz_tyre[axle] / (self.fz_tyre[0] + self.fz_tyre[1]);
        lateral::load_transfer_n(v.mass_kg, x[ix::VX], x[ix::R], h, v.track_m, share)
    }

    /// Axle forces acting on the body: the steady-state tyre forces, with the lateral ones
    /// replaced by the relaxed states when a relaxation length is set.
    fn acting(&self, x: &SVector<f64, N>, ax: &Axles) -> [TyreForces; 2] {
        let mut f = ax.f;
        if self.vehicle.lateral.relaxation_length_y_m > 0.0 {
            f[0].fy_n = x[ix::FY_F];
            f[1].fy_n = x[ix::FY_R];
        }
        f
    }

    /// Each tyre's operating conditions (one tyre of each axle, the axle's quantities halved) for
    /// axle quantities `ax` and the forces acting `acting`.
    fn contacts_of(
        &self,
        x: &SVector<f64, N>,
        env: &Environment,
        ax: &Axles,
        acting: &[TyreForces; 2],
        out: &mut [TyreContact],
    ) {
        let radius = self.vehicle.tyre.rolling_radius_m;
        let omega = [x[ix::OMEGA_F], x[ix::OMEGA_R]];
        let kappa = [x[ix::KAPPA_F], x[ix::KAPPA_R]];
        for (i, o) in out.iter_mut().take(2).enumerate() {
            *o = TyreContact {
                fz_n: self.loaded::<true>(env, i, ax.long),
                roll_speed_mps: (omega[i] * radius).abs(),
                slide_speed_mps: slide_speed(kappa[i], ax.alpha[i], ax.vxw[i].abs().max(V_LOW)),
                friction_force_n: 0.5 * (acting[i].fx_n * acting[i].fx_n + acting[i].fy_n * acting[i].fy_n).sqrt(),
                surface_temp_c: env.surface_temp_c,
            };
        }
    }

    /// Axle quantities with the front wheels at road-wheel angle `steer` (rad).
    fn axles_at<const T: bool>(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        steer: f64,
        long: [f64; 2],
    ) -> Axles {
        let v = &self.vehicle;
        let (vx, vy, r) = (x[ix::VX], x[ix::VY], x[ix::R]);
        let (sin_d, cos_d) = crate::tyre::fastmath::sin_cos(steer);
        let radius = v.tyre.rolling_radius_m;
        // Wheel-centre velocities in wheel axes.
        let vf = (vx * cos_d + (vy + v.a_m * r) * sin_d, -vx * sin_d + (vy + v.a_m * r) * cos_d);
        let vr = (vx, vy - v.b_m * r);
        let vxw = [vf.0, vr.0];
        let alpha_kin = [slip_angle(vf.0, vf.1), slip_angle(vr.0, vr.1)];
        let lat = &v.lateral;
        // Under transient slip the tyres carry the lagged slip angles (states).
        let alpha = if lat.transient_slip() { [x[ix::FY_F], x[ix::FY_R]] } else { alpha_kin };
        let mut slip_rate = [0.0; 2];
        let omega = [x[ix::OMEGA_F], x[ix::OMEGA_R]];
        let front_share = v.drive_front_share();
        let drive = [u.drive_torque_nm * front_share, u.drive_torque_nm * (1.0 - front_share)];
        let brake_cmd = u.brake_torque_nm.min(v.brake_torque_max_nm);
        // ABS caps each axle's brake torque (infinite without ABS: the value is left as it is)
        let brake = [
            (brake_cmd * v.brake_front_share).min(u.brake_cap_nm[0]),
            (brake_cmd * (1.0 - v.brake_front_share)).min(u.brake_cap_nm[1]),
        ];
        let mut f = [TyreForces::default(); 2];
        let mut torque = [0.0; 2];
        let mut load = [0.0; 2];
        for i in 0..2 {
            f[i] = self.axle_force::<T>(x, u, env, i, alpha[i], (vxw[i], long));
            if lat.transient_slip() {
                slip_rate[i] = self.slip_rate::<T>(x, u, env, i, alpha[i], (vxw[i], long));
            }
            let resist = resisting_torque_at(brake[i] + self.roll_torque[i], self.resist_omega1[i], omega[i]);
            torque[i] = drive[i] - resist - radius * f[i].fx_n;
            load[i] = resist + radius * f[i].fx_n;
        }
        if let Some(pt) = &v.powertrain {
            // The driveline (crates/vehsim-core/src/vehicle/powertrain.rs): the request, capped by traction control
            // and by the full-load torque at the carrier speed, drives the axles through the
            // reflected engine inertia. The torque balance is expressed as the equivalent axle
            // torque I d(omega)/dt.
            let shares = [front_share, 1.0 - front_share];
            let omega_c = shares[0] * omega[0] + shares[1] * omega[1];
            let (full, j_r) = pt.at_carrier_speed(omega_c);
            let t_w = u.drive_torque_nm.min(u.drive_cap_nm).min(full);
            let i_axle = [self.axle_inertia; 2];
            let acc = super::powertrain::axle_accelerations(t_w, shares, i_axle, load, j_r);
            torque = [acc[0] * self.axle_inertia, acc[1] * self.axle_inertia];
        } else if u.drive_cap_nm < u.drive_torque_nm {
            // traction control without a powertrain model: the cap on the request
            let t = u.drive_cap_nm.max(0.0);
            for i in 0..2 {
                torque[i] += t * shares_of(front_share)[i] - drive[i];
            }
        }
        Axles { vxw, alpha, alpha_kin, slip_rate, f, torque, cos_d, sin_d, long }
    }

    /// Force of axle `i`'s two tyres at slip angle `alpha` (rad), wheel-axis forward speed `vxw`
    /// (m/s) and longitudinal load changes `long` (N per tyre, front and rear): twice one tyre's
    /// for a tyre that is its own mirror image without load transfer, else each tyre at its own
    /// load ([`lateral::axle_forces`]) and, with load sensitivities, its own friction and
    /// stiffness factor ([`lateral::load_sensitive_input`]).
    fn axle_force<const T: bool>(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        i: usize,
        alpha: f64,
        (vxw, long): (f64, [f64; 2]),
    ) -> TyreForces {
        let v = &self.vehicle;
        let input = self.tyre_input::<T>(x, u, env, i, alpha, (vxw, long));
        let dfz = self.load_transfer(x, i);
        if dfz == 0.0 && v.tyre.same_on_both_sides() {
            let left = &v.tyre.mounted[0];
            // (the prepared curves hold the level road's static loads only)
            let t = match (&self.prepared[i], env.road.is_flat() && (!T || long[i] == 0.0)) {
                (Some(p), true) => left.forces_prepared(p, &input),
                _ => left.forces(&input),
            };
            TyreForces { fx_n: 2.0 * t.fx_n, fy_n: 2.0 * t.fy_n, mz_nm: 2.0 * t.mz_nm }
        } else {
            // Each tyre at its own load (a lifted tyre carries nothing); the right one
            // (outer in a left turn) gains the transfer.
            // The load sensitivities relative to the level road's static load fz0.
            let (fz0, k) = (self.fz_tyre[i], v.lateral.load_sensitivity);
            lateral::axle_forces(self.loaded::<T>(env, i, long), dfz, |side, fz| {
                let at_load = TyreInput { fz_n: fz, ..input };
                let input = if k == [0.0; 2] { at_load } else { lateral::load_sensitive_input(at_load, fz0, k) };
                v.tyre.on(side).forces(&input)
            })
        }
    }

    /// Transient-slip rate of axle `i` at its lagged slip angle `alpha` (rad), 1/s:
    /// max(|vx|, 1 m/s) / sigma_i, with sigma_i shortened by the tyre's local slope in the
    /// saturating form ([`lateral::saturating_relaxation_length`]).
    fn slip_rate<const T: bool>(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        i: usize,
        alpha: f64,
        at: (f64, [f64; 2]),
    ) -> f64 {
        let lat = &self.vehicle.lateral;
        let mut sigma = lat.slip_relaxation_m[i];
        if lat.slip_relaxation_saturating {
            let eps = lateral::SLIP_SLOPE_STEP_RAD;
            let fy = |a: f64| self.axle_force::<T>(x, u, env, i, a, at).fy_n;
            let slope = |a: f64| fy(a + eps) - fy(a - eps);
            sigma = lateral::saturating_relaxation_length(sigma, slope(alpha) / slope(0.0));
        }
        lateral::relaxation_rate(x[ix::VX], sigma)
    }

    /// The input of axle `i`'s tyres at its static load share changed by `long` (N per tyre),
    /// slip angle `alpha` (rad) and wheel-axis forward speed `vxw` (m/s).
    fn tyre_input<const T: bool>(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        i: usize,
        alpha: f64,
        (vxw, long): (f64, [f64; 2]),
    ) -> TyreInput {
        let lat = &self.vehicle.lateral;
        let mut mu = env.mu * lat.mu_scale;
        // The contact heating's friction change per kelvin: the thermal form's, or the tread
        // state's (the spec layer allows one of them; with neither, 0 + 0 is exactly 0).
        let mu_per_k = lat.thermal_mu_per_k + lat.tread_mu_per_k();
        if mu_per_k != 0.0 {
            let rise = u.contact_temp_c[i] - env.surface_temp_c;
            mu *= lateral::thermal_friction_factor(mu_per_k, rise);
        }
        // The per-axle friction and cornering-stiffness factors (1 by default: exact).
        mu *= lat.mu_axle_scale[i];
        if !env.regions.is_empty() {
            // Friction regions on the ground, at this axle's own position.
            let l = [self.vehicle.a_m, -self.vehicle.b_m][i];
            let (xa, ya) = super::ground::axle_position(x[ix::X], x[ix::Y], x[ix::YAW], l);
            mu *= env.regions.factor(xa, ya) * env.regions.factor_along(u.distance_m);
        }
        TyreInput {
            fz_n: self.loaded::<T>(env, i, long),
            kappa: x[[ix::KAPPA_F, ix::KAPPA_R][i]],
            alpha_rad: alpha * lat.stiffness_scale[i],
            camber_rad: 0.0,
            vx_mps: vxw,
            mu_surface: mu,
            surface_temp_c: env.surface_temp_c,
            contact_temp_c: u.contact_temp_c[i],
        }
    }

    /// The derivative from the axle quantities `ax` and the body loads (x, y force, yaw moment).
    fn derivative_of(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        ax: &Axles,
        (fx, fy, mz): (f64, f64, f64),
    ) -> SVector<f64, N> {
        let v = &self.vehicle;
        let (yaw, vx, vy, r) = (x[ix::YAW], x[ix::VX], x[ix::VY], x[ix::R]);
        let (s, c) = crate::tyre::fastmath::sin_cos(yaw);
        let radius = v.tyre.rolling_radius_m;
        let sigma = v.tyre.relaxation_length_x_m;
        let mut d = SVector::<f64, N>::zeros();
        d[ix::X] = vx * c - vy * s;
        d[ix::Y] = vx * s + vy * c;
        d[ix::YAW] = r;
        d[ix::VX] = fx / v.mass_kg + r * vy;
        // The road's gravity in its plane acts at the CG (no yaw moment; none on a flat road).
        let fy = if env.road.is_flat() {
            fy
        } else {
            let (gx, gy) = env.road.gravity_in_plane();
            d[ix::VX] += gx;
            fy + v.mass_kg * gy
        };
        (d[ix::VY], d[ix::R]) = single_track::lateral_rates(v.mass_kg, v.yaw_inertia_kgm2, vx, r, fy, mz);
        d[ix::OMEGA_F] = ax.torque[0] / self.axle_inertia;
        d[ix::OMEGA_R] = ax.torque[1] / self.axle_inertia;
        d[ix::KAPPA_F] = relaxed_slip_rate(x[ix::KAPPA_F], x[ix::OMEGA_F], radius, ax.vxw[0], sigma);
        d[ix::KAPPA_R] = relaxed_slip_rate(x[ix::KAPPA_R], x[ix::OMEGA_R], radius, ax.vxw[1], sigma);
        let lat = &v.lateral;
        if lat.relaxation_length_y_m > 0.0 {
            let rate = lateral::relaxation_rate(vx, lat.relaxation_length_y_m);
            d[ix::FY_F] = rate * (ax.f[0].fy_n - x[ix::FY_F]);
            d[ix::FY_R] = rate * (ax.f[1].fy_n - x[ix::FY_R]);
        }
        if lat.steer_lag_s > 0.0 {
            d[ix::DELTA_L] = (u.steer_rad - x[ix::DELTA_L]) / lat.steer_lag_s;
        }
        if lat.transient_slip() {
            // The lagged slip angles (in the relaxed-force slots) relax towards the kinematic ones.
            d[ix::FY_F] = ax.slip_rate[0] * (ax.alpha_kin[0] - x[ix::FY_F]);
            d[ix::FY_R] = ax.slip_rate[1] * (ax.alpha_kin[1] - x[ix::FY_R]);
        }
        d
    }

    /// The observation from the axle quantities `ax`, the acting forces and the body loads.
    fn observation_of(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        ax: &Axles,
        acting: &[TyreForces; 2],
        (fx, fy, _): (f64, f64, f64),
    ) -> Observation {
        let kin = super::rigid_body(x.as_slice());
        Observation {
            kin,
            ax_mps2: fx / self.vehicle.mass_kg,
            ay_mps2: fy / self.vehicle.mass_kg,
            alpha_rad: ax.alpha,
            kappa: [x[ix::KAPPA_F], x[ix::KAPPA_R]],
            fx_n: [acting[0].fx_n, acting[1].fx_n],
            fy_n: [acting[0].fy_n, acting[1].fy_n],
            omega_radps: [x[ix::OMEGA_F], x[ix::OMEGA_R]],
            fz_n: {
                // vx r > 0 (turning left) moves load to the right (outer) tyres.
                let [[(_, fr), (_, fl)], [(_, rr), (_, rl)]] =
                    [0, 1].map(|i| lateral::tyre_loads(self.loaded::<true>(env, i, ax.long), self.load_transfer(x, i)));
                [fl, fr, rl, rr]
            },
            roll_rad: 0.0,
            contact_temp_axle_c: [u.contact_temp_c[0], u.contact_temp_c[1]],
        }
    }

    /// Body-frame force (x, y) and yaw moment of the acting tyre forces `forces`, plus drag.
    fn body_loads(&self, ax: &Axles, forces: &[TyreForces; 2], vx: f64) -> (f64, f64, f64) {
        let v = &self.vehicle;
        let [f, r] = forces;
        let fxf_b = f.fx_n * ax.cos_d - f.fy_n * ax.sin_d;
        let drag = v.drag_n(vx);
        let fx = fxf_b + r.fx_n - drag;
        let (fy, mz) = single_track::lateral_loads(f, r, ax.cos_d, ax.sin_d, v.a_m, v.b_m);
        (fx, fy, mz)
    }
}

impl VehicleModel<N> for Bicycle {
    const TYRES: usize = 2;

    fn state_names(&self) -> [&'static str; N] {
        let slip = self.vehicle.lateral.transient_slip();
        [
            "x_m",
            "y_m",
            "yaw_rad",
            "vx_mps",
            "vy_mps",
            "yaw_rate_radps",
            "omega_front_radps",
            "omega_rear_radps",
            "kappa_front",
            "kappa_rear",
            if slip { "alpha_front_lagged_rad" } else { "fy_front_relaxed_n" },
            if slip { "alpha_rear_lagged_rad" } else { "fy_rear_relaxed_n" },
            "steer_lagged_rad",
        ]
    }

    fn initial_state(&self, x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> SVector<f64, N> {
        let mut s = SVector::<f64, N>::zeros();
        super::set_rigid_body(s.as_mut_slice(), x_m, y_m, yaw_rad, speed_mps);
        let omega = speed_mps / self.vehicle.tyre.rolling_radius_m;
        s[ix::OMEGA_F] = omega;
        s[ix::OMEGA_R] = omega;
        s
    }

    fn body_acceleration(&self, x: &SVector<f64, N>, dx: &SVector<f64, N>) -> (f64, f64) {
        (dx[ix::VX] - x[ix::R] * x[ix::VY], dx[ix::VY] + x[ix::R] * x[ix::VX])
    }

    #[inline]
    fn evaluate(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, extras: Extras<'_>) -> SVector<f64, N> {
        let ax = self.axles(x, u, env);
        let acting = self.acting(x, &ax);
        if let Some(out) = extras.contacts {
            self.contacts_of(x, env, &ax, &acting, out);
        }
        let loads = self.body_loads(&ax, &acting, x[ix::VX]);
        if let Some(o) = extras.observation {
            *o = self.observation_of(x, u, env, &ax, &acting, loads);
        }
        self.derivative_of(x, u, env, &ax, loads)
    }

    fn spin_slip(&self) -> Option<SpinSlip> {
        let t = &self.vehicle.tyre;
        Some(SpinSlip {
            pairs: &[(ix::OMEGA_F, ix::KAPPA_F), (ix::OMEGA_R, ix::KAPPA_R)],
            kappa_per_omega: t.rolling_radius_m / t.relaxation_length_x_m,
        })
    }

    fn monitor(&self) -> Option<&dyn Monitored<N>> {
        Some(self)
    }

    fn wheel_speeds(&self) -> Option<&dyn WheelSpeeds<N>> {
        Some(self)
    }
}

impl Monitored<N> for Bicycle {
    /// None: the bicycle's normal loads are static and positive.
    fn conditions(&self, _x: &SVector<f64, N>, _u: &Inputs, _env: &Environment, _out: &mut Vec<Condition>) {}

    /// The tyres' departures from their published laws, per axle and side.
    fn notes(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        out: &mut Vec<(crate::event::EventKind, String)>,
    ) {
        let tyre = &self.vehicle.tyre;
        if !tyre.model.reports_departures() {
            return;
        }
        let ax = self.axles(x, u, env);
        for i in 0..2 {
            let input = self.tyre_input::<true>(x, u, env, i, ax.alpha[i], (ax.vxw[i], ax.long));
            let [right, left] = lateral::tyre_loads(input.fz_n, self.load_transfer(x, i));
            for ((side, fz), name) in [(left, "left"), (right, "right")] {
                if let Some((kind, detail)) = tyre.on(side).departure(&TyreInput { fz_n: fz, ..input }) {
                    out.push((kind, format!("{} {name} tyre: {detail}", ["front", "rear"][i])));
                }
            }
        }
    }
}

impl WheelSpeeds<N> for Bicycle {
    /// Per axle (front, rear): omega R_e, the wheel-centre forward speed in wheel axes, whether
    /// it is driven and its largest brake torque.
    fn wheel_sensors(&self, x: &SVector<f64, N>, steer_rad: f64, out: &mut [super::WheelSensor; 4]) -> usize {
        let v = &self.vehicle;
        let radius = v.tyre.rolling_radius_m;
        let share = v.drive_front_share();
        let bmax = v.brake_torque_max_nm;
        for (axle, o) in out.iter_mut().take(2).enumerate() {
            let steer = if axle == 0 { steer_rad } else { 0.0 };
            let (vy_w, om) = if axle == 0 {
                (x[ix::VY] + v.a_m * x[ix::R], x[ix::OMEGA_F])
            } else {
                (x[ix::VY] - v.b_m * x[ix::R], x[ix::OMEGA_R])
            };
            *o = super::WheelSensor {
                omega_r_mps: om * radius,
                v_mps: to_wheel_axes(x[ix::VX], vy_w, steer).0,
                driven: if axle == 0 { share > 0.0 } else { share < 1.0 },
                brake_max_nm: bmax * if axle == 0 { v.brake_front_share } else { 1.0 - v.brake_front_share },
            };
        }
        2
    }
}

/// The root of the pitch balance S = g(S) from two fixed-point passes s0 = g(0) and s1 = g(s0),
/// N: the secant through them, S = s0^2 / (2 s0 - s1), exact when g is linear in S (the forces
/// proportional to the loads' changes) and second order otherwise; s1 when the secant's slope is
/// not below 1 (no contracting balance), 0 when s0 is.
fn pitch_balance(s0: f64, s1: f64) -> f64 {
    if s0 == 0.0 {
        return 0.0;
    }
    let den = 2.0 * s0 - s1;
    // The slope k = (s1 - s0) / s0 < 1 exactly when den / s0 > 0.
    if den / s0 > 1e-3 {
        s0 * s0 / den
    } else {
        s1
    }
}

/// The drive shares (front, rear) of a front share.
fn shares_of(front_share: f64) -> [f64; 2] {
    [front_share, 1.0 - front_share]
}

#[cfg(test)]
mod tests {
    use super::pitch_balance;

    /// The secant's root is the fixed point of a balance linear in S, g(S) = a + k S (root
    /// a / (1 - k)), for braking and driving; no balance (s0 = 0) is 0; a balance that does not
    /// contract (k >= 1) keeps the second pass.
    #[test]
    fn pitch_balance_is_exact_for_a_linear_balance() {
        for (a, k) in [(1000.0, 0.2), (-2500.0, 0.15), (300.0, -0.4)] {
            let g = |s: f64| a + k * s;
            let s0 = g(0.0);
            let root = pitch_balance(s0, g(s0));
            assert!((root - a / (1.0 - k)).abs() <= 1e-9 * a.abs(), "{a}, {k}: {root}");
        }
        assert_eq!(pitch_balance(0.0, 5.0), 0.0);
        assert_eq!(pitch_balance(100.0, 250.0), 250.0);
    }
}
