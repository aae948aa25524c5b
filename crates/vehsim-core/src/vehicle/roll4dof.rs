//! Four-wheel vehicle model with body roll (4-DOF: longitudinal, lateral, yaw, roll), wheel spin
//! and transient longitudinal slip per wheel. Derivation and definitions: `docs/roll4dof.md`.
//!
//! Frame: body axes that yaw with the vehicle but do not roll (ISO 8855, x forward, y left, z up).
//! Reference point O: the whole vehicle's CG in the unrolled position. The sprung mass m_s rolls by
//! phi about the roll axis (the line through the front and rear roll centres); its CG lies h' above
//! that axis and x_s ahead of O. Unsprung masses move with the yaw frame and do not roll. Roll is
//! small: the sprung CG moves sideways by -h' phi (positive phi, the body leaning to the right, is
//! what a left turn produces); second-order terms (phi^2, phi r, vertical motion of the sprung CG)
//! are dropped, so the normal loads carry the whole weight at every instant.
//!
//! Equations of motion (Fx, Fy, Mz: sums of the tyre forces in body axes and their yaw moment
//! about O; K = K_f + K_r, C = C_f + C_r; I_xa = I_xs + m_s h'^2 the roll inertia about the axis):
//!
//!   m (dvx/dt - r vy)                             = Fx - F_drag
//!   m (dvy/dt + r vx) - m_s h' dp/dt              = Fy
//!   I_z dr/dt - m_s x_s h' dp/dt                  = Mz
//!   I_xa dp/dt - m_s h' (dvy/dt + r vx + x_s dr/dt) = -K phi - C p + m_s g h' phi
//!   dphi/dt = p,  dX/dt = vx cos psi - vy sin psi,  dY/dt = vx sin psi + vy cos psi,  dpsi/dt = r
//!   I_w domega_i/dt = T_drive,i - T_resist,i - R_e Fx_i      (per wheel)
//!
//! The (vy, r, p) equations share a constant symmetric mass matrix, inverted once in [`Roll4Dof::new`].
//!
//! Normal loads (per axle i with track t, static axle load F_i0, left wheel L, right wheel R):
//!
//!   longitudinal transfer  dX = m h a_x' / L           (front loses, rear gains)
//!   lateral transfer       dY_i = (K_i phi + C_i p + (m_s h_ri l_i + m_ui h_u) a_y') / t
//!   Fz_iL = (F_i0 -+ dX) / 2 - dY_i,   Fz_iR = (F_i0 -+ dX) / 2 + dY_i
//!
//! with l_f = b_s / L, l_r = a_s / L the sprung-mass shares per axle. a_x', a_y' are the body-frame
//! accelerations of O passed through a first-order lag of time constant tau (two extra states):
//! the loads depend on the forces, which depend on the loads, and the lag breaks that algebraic
//! loop; in steady state a_x' = a_x and a_y' = a_y exactly. Each transfer is clamped so that no
//! wheel load goes negative (a lifted wheel carries 0 and its partner the whole axle load), so the
//! four loads sum to m g exactly at every evaluation.
//!
//! Watched conditions ([`Monitored::conditions`], reported by the engine at step resolution;
//! the tyres' departures from their published laws are notes, [`Monitored::notes`]):
//! - `wheel_lift` / `wheel_contact`, per wheel: its load is 0 after clamping (the lateral transfer
//!   reaches half its axle's load, or the axle itself is unloaded), and when it carries load again.
//!   The value is the wheel's load before clamping, N: (F_i0 -+ dX)/2 -+ dY_i, negative when
//!   lifted. Beyond lift the model's roll balance no longer holds (the suspension of a lifted
//!   wheel does not carry K_i phi), so the results after a `wheel_lift` are outside the model.
//! - `negative_normal_load` / `normal_load_restored`, per axle: the longitudinal transfer makes the
//!   axle's computed load F_i0 -+ dX negative (it is clamped to 0, both its wheels lift); the value
//!   is that load before clamping, N.
//!
//! Tyres: the left wheels (FL, RL) carry the tyre mounted on the left, the right wheels its
//! mounting on the right ([`crate::tyre::Tyre::on`]: a `.tir` tyre is mirrored on the side
//! opposite its TYRESIDE, so an axle's conicity and ply-steer offsets cancel; docs/tyres.md).
//!
//! Drive: the drive torque is split between the axles by the layout and within an axle equally
//! between its wheels (open differential, gear inertia neglected); brakes by the brake balance,
//! equally left and right. Front steering: the input is the mean road-wheel angle delta; with an
//! Ackermann fraction A each front wheel gets delta + A (delta_ideal - delta), where
//! tan(delta_ideal) = L tan(delta) / (L -+ (t/2) tan(delta)) (left wheel minus, right wheel plus).

use nalgebra::{Matrix3, SVector, Vector3};

use super::capability::{Monitored, SpinSlip, WheelSpeeds};
use super::wheel::{
    relaxed_slip_rate, resisting_omega1, resisting_torque_at, slide_speed, slip_angle, to_wheel_axes, V_LOW,
};
use super::{Condition, Environment, Extras, Inputs, Observation, VehicleModel};
use crate::contact::TyreContact;
use crate::event::EventKind;
use crate::tyre::{fastmath, Prepared, TyreForces, TyreInput};
use crate::vehicle::{Roll, Vehicle, GRAVITY};

/// State dimension of the 4-DOF model.
pub const N: usize = 18;
/// State indices. Wheels are ordered FL, FR, RL, RR.
pub mod ix {
    /// Ground-frame X position of O (the unrolled CG), m.
    pub const X: usize = 0;
    /// Ground-frame Y position of O, m (positive left of the start heading).
    pub const Y: usize = 1;
    /// Yaw angle psi, rad (positive counter-clockwise seen from above).
    pub const YAW: usize = 2;
    /// Longitudinal velocity of O in the yaw frame, m/s (positive forward).
    pub const VX: usize = 3;
    /// Lateral velocity of O in the yaw frame, m/s (positive left).
    pub const VY: usize = 4;
    /// Yaw rate r, rad/s (positive turning left).
    pub const R: usize = 5;
    /// Roll angle phi, rad (positive: body leans to the right, as in a left turn).
    pub const PHI: usize = 6;
    /// Roll rate p = dphi/dt, rad/s.
    pub const P: usize = 7;
    /// Lagged body-frame longitudinal and lateral acceleration of O, m/s^2 (drive load transfer).
    pub const AX_LAG: usize = 8;
    /// Lagged body-frame lateral acceleration of O, m/s^2 (positive left; the lateral load transfer).
    pub const AY_LAG: usize = 9;
    /// Wheel spin speeds FL, FR, RL, RR, rad/s.
    pub const OMEGA: usize = 10;
    /// Relaxed slip ratios FL, FR, RL, RR.
    pub const KAPPA: usize = 14;
}

/// Wheel names in state order.
pub const WHEELS: [&str; 4] = ["front-left", "front-right", "rear-left", "rear-right"];

/// Subjects of the watched conditions: wheels in state order, then the axles.
const WHEEL_SUBJECTS: [&str; 4] = ["front-left wheel", "front-right wheel", "rear-left wheel", "rear-right wheel"];
const AXLE_SUBJECTS: [&str; 2] = ["front axle", "rear axle"];

/// The 4-DOF roll model: a validated vehicle with roll data plus precomputed constants.
#[derive(Debug, Clone)]
pub struct Roll4Dof {
    /// The validated vehicle the model reads.
    pub vehicle: Vehicle,
    /// The vehicle's roll data (the `[roll]` section), with the derived sprung-mass geometry.
    pub roll: Roll,
    /// Static axle loads (front, rear), N.
    axle_load0: [f64; 2],
    /// Longitudinal transfer per unit a_x: m h / L, kg.
    long_gain: f64,
    /// Lateral transfer per unit a_y per axle, N per m/s^2: (m_s h_ri l_i + m_ui h_u) / t.
    lat_gain: [f64; 2],
    /// Wheel positions from O (x, y), m, FL, FR, RL, RR.
    pos: [(f64, f64); 4],
    /// Inverse of the (vy, r, p) mass matrix.
    m_inv: Matrix3<f64>,
    /// Roll-equation constants: total roll stiffness K (N m/rad) and damping C (N m s/rad),
    /// m_s g h' (N m) and m_s h' (kg m); and m_s h' / m (m), the CG's share of the roll.
    roll_k: f64,
    roll_c: f64,
    roll_gravity: f64,
    roll_ms_hp: f64,
    roll_shift: f64,
    /// Regularisation speed of each axle's wheel resisting torque ([`resisting_omega1`]), rad/s.
    resist_omega1: [f64; 2],
    /// Regularisation speed of each axle's limited-slip differential, rad/s
    /// ([`super::powertrain::Powertrain::lsd_omega_eps`]; 1 when unused).
    lsd_omega_eps: [f64; 2],
    /// Tyre coefficients prepared per wheel (FL, FR, RL, RR) for its static load on a surface
    /// ([`Roll4Dof::prepared_for`]); `None` until prepared.
    prepared: [Option<Prepared>; 4],
}

/// Per-wheel intermediate quantities of one evaluation.
struct Wheels {
    fz: [f64; 4],
    vxw: [f64; 4],
    alpha: [f64; 4],
    /// Tyre forces in wheel axes.
    f: [TyreForces; 4],
    /// (sin, cos) of the road-wheel steer angle per wheel.
    steer_sc: [(f64, f64); 4],
    /// Wheel torque balance (drive - resist - R Fx), N m.
    torque: [f64; 4],
}

/// Road-wheel angles (left, right) of the front wheels for a mean angle `delta`, Ackermann fraction
/// `ackermann`, wheelbase `l` and track `t`.
pub fn front_steer_angles(delta: f64, ackermann: f64, l: f64, t: f64) -> (f64, f64) {
    if ackermann == 0.0 || delta == 0.0 {
        return (delta, delta);
    }
    let tan_d = fastmath::tan(delta);
    let q = 0.5 * t * tan_d;
    // L - q and L + q stay positive for |delta| below atan(2 L / t) (~74 deg for a car); beyond
    // that ideal Ackermann is undefined and the wheels stay parallel.
    if l - q.abs() <= 0.05 * l {
        return (delta, delta);
    }
    let left = fastmath::atan(l * tan_d / (l - q));
    let right = fastmath::atan(l * tan_d / (l + q));
    (delta + ackermann * (left - delta), delta + ackermann * (right - delta))
}

impl Roll4Dof {
    /// Build the model; `roll` is the vehicle's validated `[roll]` data.
    pub fn new(vehicle: Vehicle, roll: Roll) -> Self {
        let (ff, fr) = vehicle.static_axle_loads_n();
        let (a, b, t) = (vehicle.a_m, vehicle.b_m, vehicle.track_m);
        let l = a + b;
        let m = vehicle.mass_kg;
        let (a_s, b_s) = roll.sprung_axle_distances(a, b);
        let m_s = roll.sprung_mass_kg;
        let h_u = roll.unsprung_cg_height_m;
        let lat_gain = [
            (m_s * roll.rc_height_m[0] * b_s / l + roll.unsprung_mass_kg[0] * h_u) / t,
            (m_s * roll.rc_height_m[1] * a_s / l + roll.unsprung_mass_kg[1] * h_u) / t,
        ];
        let hp = roll.h_prime_m;
        let xs = roll.sprung_cg_ahead_m;
        let i_xa = roll.roll_inertia_kgm2 + m_s * hp * hp;
        let mass = Matrix3::new(
            m,
            0.0,
            -m_s * hp,
            0.0,
            vehicle.yaw_inertia_kgm2,
            -m_s * xs * hp,
            -m_s * hp,
            -m_s * xs * hp,
            i_xa,
        );
        // Positive definite for m, I_z, I_xs > 0 (validated), so the inverse exists; the fallback
        // (decoupled diagonal) is never taken for a validated vehicle.
        let m_inv = mass.try_inverse().unwrap_or_else(|| {
            Matrix3::from_diagonal(&Vector3::new(1.0 / m, 1.0 / vehicle.yaw_inertia_kgm2, 1.0 / i_xa))
        });
        let bmax = vehicle.brake_torque_max_nm;
        let brake_max = [0.5 * bmax * vehicle.brake_front_share, 0.5 * bmax * (1.0 - vehicle.brake_front_share)];
        let pos = [(a, 0.5 * t), (a, -0.5 * t), (-b, 0.5 * t), (-b, -0.5 * t)];
        let (roll_k, roll_c) = (roll.total_stiffness(), roll.damping_nms_per_rad[0] + roll.damping_nms_per_rad[1]);
        let radius = vehicle.tyre.rolling_radius_m;
        let resist_omega1 = [0, 1].map(|axle| {
            let resist_max = brake_max[axle] + vehicle.rolling_resistance * 0.5 * [ff, fr][axle] * radius;
            resisting_omega1(resist_max.max(0.5), vehicle.wheel_inertia_kgm2)
        });
        let lsd_omega_eps = [0, 1].map(|a| {
            vehicle.powertrain.as_ref().map_or(1.0, |pt| {
                let share = if a == 0 { vehicle.drive_front_share() } else { 1.0 - vehicle.drive_front_share() };
                pt.lsd_omega_eps(share * pt.wheel_torque_max_nm(), vehicle.wheel_inertia_kgm2)
            })
        });
        Self {
            long_gain: m * vehicle.cg_height_m / l,
            vehicle,
            roll,
            axle_load0: [ff, fr],
            lat_gain,
            pos,
            m_inv,
            resist_omega1,
            roll_k,
            roll_c,
            roll_gravity: m_s * GRAVITY * hp,
            roll_ms_hp: m_s * hp,
            roll_shift: m_s * hp / m,
            lsd_omega_eps,
            prepared: [None; 4],
        }
    }

    /// The model with its tyres' coefficients prepared for `env` (the explicit prepare step of
    /// [`crate::tyre::TyreModel::prepare`]): the load-independent part serves every load the
    /// transfer gives on that surface, the load-dependent part the static load. The forces are the
    /// same bit for bit.
    pub fn prepared_for(mut self, env: &Environment) -> Self {
        for i in 0..4 {
            let input = TyreInput {
                fz_n: 0.5 * self.axle_load0[i / 2],
                kappa: 0.0,
                alpha_rad: 0.0,
                camber_rad: 0.0,
                vx_mps: 0.0,
                mu_surface: env.mu,
                surface_temp_c: env.surface_temp_c,
                contact_temp_c: env.surface_temp_c,
            };
            self.prepared[i] = Some(self.vehicle.tyre.mounted[i % 2].prepare(&input));
        }
        self
    }

    /// Normal loads FL, FR, RL, RR, N, of a state (each >= 0; they sum to m g).
    pub fn normal_loads(&self, x: &SVector<f64, N>) -> [f64; 4] {
        self.loads(x, true).1
    }

    /// Loads before clamping, N: the axle loads (front, rear) from the longitudinal transfer,
    /// F_i0 -+ dX, and the wheel loads (FL, FR, RL, RR) (F_i0 -+ dX)/2 -+ dY_i. Where neither
    /// transfer is clamped they equal [`Self::normal_loads`].
    pub fn unclamped_loads(&self, x: &SVector<f64, N>) -> ([f64; 2], [f64; 4]) {
        self.loads(x, false)
    }

    /// Axle and wheel loads, N, with the longitudinal transfer clamped to the static axle loads
    /// and each axle's lateral transfer to half its load (`clamp`), or as the equations give them.
    fn loads(&self, x: &SVector<f64, N>, clamp: bool) -> ([f64; 2], [f64; 4]) {
        let t = self.vehicle.track_m;
        let [f0, r0] = self.axle_load0;
        let mut dx = self.long_gain * x[ix::AX_LAG];
        if clamp {
            dx = dx.clamp(-r0, f0);
        }
        let axle = [f0 - dx, r0 + dx];
        let (phi, p, ay) = (x[ix::PHI], x[ix::P], x[ix::AY_LAG]);
        let mut fz = [0.0; 4];
        for i in 0..2 {
            let k = self.roll.stiffness_nm_per_rad[i];
            let c = self.roll.damping_nms_per_rad[i];
            let half = 0.5 * axle[i];
            let mut dy = (k * phi + c * p) / t + self.lat_gain[i] * ay;
            if clamp {
                dy = dy.clamp(-half, half);
            }
            fz[2 * i] = half - dy;
            fz[2 * i + 1] = half + dy;
        }
        (axle, fz)
    }

    // (inlined into its callers: the 288-byte result is then built in place, not copied)
    #[inline(always)]
    fn wheels(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> Wheels {
        let v = &self.vehicle;
        let (vx, vy, r) = (x[ix::VX], x[ix::VY], x[ix::R]);
        let radius = v.tyre.rolling_radius_m;
        let fz = self.normal_loads(x);
        let (dl, dr) = front_steer_angles(u.steer_rad, self.roll.ackermann, v.wheelbase_m(), v.track_m);
        // Rear wheels are not steered: sin 0 = 0, cos 0 = 1 exactly, no trigonometry needed; front
        // wheels at the same angle (no Ackermann) share theirs.
        let sc_left = fastmath::sin_cos(dl);
        let sc_right = if dr.to_bits() == dl.to_bits() { sc_left } else { fastmath::sin_cos(dr) };
        let steer_sc = [sc_left, sc_right, (0.0, 1.0), (0.0, 1.0)];
        let front_share = v.drive_front_share();
        let drive_axle = [u.drive_torque_nm * front_share, u.drive_torque_nm * (1.0 - front_share)];
        let brake_cmd = u.brake_torque_nm.min(v.brake_torque_max_nm);
        let brake_axle = [brake_cmd * v.brake_front_share, brake_cmd * (1.0 - v.brake_front_share)];
        let mut load = [0.0; 4];
        let mut w =
            Wheels { fz, vxw: [0.0; 4], alpha: [0.0; 4], f: [TyreForces::default(); 4], steer_sc, torque: [0.0; 4] };
        for i in 0..4 {
            let axle = i / 2;
            let (px, py) = self.pos[i];
            let (sd, cd) = steer_sc[i];
            let (vxb, vyb) = (vx - r * py, vy + r * px);
            let (vxw, vyw) = (vxb * cd + vyb * sd, -vxb * sd + vyb * cd);
            w.vxw[i] = vxw;
            w.alpha[i] = slip_angle(vxw, vyw);
            let input = tyre_input(x, u, env, i, fz[i], w.alpha[i], vxw);
            let tyre = &v.tyre.mounted[i % 2]; // FL, RL on the left, FR, RR on the right
            w.f[i] = match &self.prepared[i] {
                Some(p) => tyre.forces_prepared(p, &input),
                None => tyre.forces(&input),
            };
            let roll_res = v.rolling_resistance * fz[i] * radius;
            // ABS caps each wheel's brake torque (infinite without ABS: the value is left as it is)
            let brake = (0.5 * brake_axle[axle]).min(u.brake_cap_nm[i]);
            let resist = resisting_torque_at(brake + roll_res, self.resist_omega1[axle], x[ix::OMEGA + i]);
            w.torque[i] = 0.5 * drive_axle[axle] - resist - radius * w.f[i].fx_n;
            load[i] = resist + radius * w.f[i].fx_n;
        }
        if let Some(pt) = &v.powertrain {
            self.driveline(pt, x, u, front_share, &load, &mut w.torque);
        } else if u.drive_cap_nm < u.drive_torque_nm {
            // traction control without a powertrain model: the cap on the request
            let t = u.drive_cap_nm.max(0.0);
            for i in 0..4 {
                let share = if i < 2 { front_share } else { 1.0 - front_share };
                w.torque[i] += 0.5 * share * (t - u.drive_torque_nm);
            }
        }
        w
    }

    /// The wheels' torque balances (as I_w d(omega)/dt) through the powertrain `pt`: the request
    /// capped by traction control and the full-load torque at the carrier speed, the reflected
    /// engine inertia and the axles' differentials (crates/vehsim-core/src/vehicle/powertrain.rs), from the wheels'
    /// load torques `load` (N m: brake, rolling resistance and R_e F_x).
    fn driveline(
        &self,
        pt: &super::powertrain::Powertrain,
        x: &SVector<f64, N>,
        u: &Inputs,
        front_share: f64,
        load: &[f64; 4],
        torque: &mut [f64; 4],
    ) {
        use super::powertrain::{axle_accelerations, wheel_accelerations};
        let iw = self.vehicle.wheel_inertia_kgm2;
        let om = |i: usize| x[ix::OMEGA + i];
        let shares = [front_share, 1.0 - front_share];
        let mean = [0.5 * (om(0) + om(1)), 0.5 * (om(2) + om(3))];
        let omega_c = shares[0] * mean[0] + shares[1] * mean[1];
        let (full, j_r) = pt.at_carrier_speed(omega_c);
        let t_w = u.drive_torque_nm.min(u.drive_cap_nm).min(full);
        let axle_load = [load[0] + load[1], load[2] + load[3]];
        let acc = axle_accelerations(t_w, shares, [2.0 * iw; 2], axle_load, j_r);
        for a in 0..2 {
            let (l, r) = wheel_accelerations(
                acc[a],
                pt.differential,
                shares[a] > 0.0,
                (load[2 * a], load[2 * a + 1]),
                (om(2 * a), om(2 * a + 1)),
                iw,
                shares[a] * t_w,
                self.lsd_omega_eps[a],
            );
            torque[2 * a] = l * iw;
            torque[2 * a + 1] = r * iw;
        }
    }

    /// Body-frame force (x, y) and yaw moment about O of the tyres, plus drag.
    fn body_loads(&self, w: &Wheels, vx: f64) -> (f64, f64, f64) {
        let v = &self.vehicle;
        let (mut fx, mut fy, mut mz) = (0.0, 0.0, 0.0);
        for i in 0..4 {
            let f = w.f[i];
            let (s, c) = w.steer_sc[i];
            let fxb = f.fx_n * c - f.fy_n * s;
            let fyb = f.fx_n * s + f.fy_n * c;
            let (px, py) = self.pos[i];
            fx += fxb;
            fy += fyb;
            mz += px * fyb - py * fxb + f.mz_nm;
        }
        fx -= v.drag_n(vx);
        (fx, fy, mz)
    }

    /// Derivative together with the per-wheel quantities it used (inlined: a caller that does not
    /// read them does not copy them).
    #[inline(always)]
    /// Each tyre's operating conditions for the wheel quantities `w`.
    fn contacts_of(&self, x: &SVector<f64, N>, env: &Environment, w: &Wheels, out: &mut [TyreContact]) {
        let radius = self.vehicle.tyre.rolling_radius_m;
        for (i, o) in out.iter_mut().take(4).enumerate() {
            let kappa = x[ix::KAPPA + i];
            *o = TyreContact {
                fz_n: w.fz[i],
                roll_speed_mps: (x[ix::OMEGA + i] * radius).abs(),
                slide_speed_mps: slide_speed(kappa, w.alpha[i], w.vxw[i].abs().max(V_LOW)),
                friction_force_n: (w.f[i].fx_n * w.f[i].fx_n + w.f[i].fy_n * w.f[i].fy_n).sqrt(),
                surface_temp_c: env.surface_temp_c,
            };
        }
    }

    #[inline(always)]
    fn eval(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> (SVector<f64, N>, Wheels) {
        let v = &self.vehicle;
        let ro = &self.roll;
        let (yaw, vx, vy, r, phi, p) = (x[ix::YAW], x[ix::VX], x[ix::VY], x[ix::R], x[ix::PHI], x[ix::P]);
        let w = self.wheels(x, u, env);
        let (fx, fy, mz) = self.body_loads(&w, vx);
        let m = v.mass_kg;
        let (k, c) = (self.roll_k, self.roll_c);
        let rhs =
            Vector3::new(fy - m * r * vx, mz, -k * phi - c * p + self.roll_gravity * phi + self.roll_ms_hp * r * vx);
        let acc = self.m_inv * rhs;
        let (s, co) = fastmath::sin_cos(yaw);
        let radius = v.tyre.rolling_radius_m;
        let sigma = v.tyre.relaxation_length_x_m;
        let tau = ro.load_transfer_lag_s;
        let mut d = SVector::<f64, N>::zeros();
        d[ix::X] = vx * co - vy * s;
        d[ix::Y] = vx * s + vy * co;
        d[ix::YAW] = r;
        d[ix::VX] = fx / m + r * vy;
        d[ix::VY] = acc[0];
        d[ix::R] = acc[1];
        d[ix::PHI] = p;
        d[ix::P] = acc[2];
        // Acceleration of O (the load-transfer inputs; equal to the CG's in steady state).
        let ax = fx / m;
        let ay = acc[0] + r * vx;
        d[ix::AX_LAG] = (ax - x[ix::AX_LAG]) / tau;
        d[ix::AY_LAG] = (ay - x[ix::AY_LAG]) / tau;
        for i in 0..4 {
            d[ix::OMEGA + i] = w.torque[i] / v.wheel_inertia_kgm2;
            d[ix::KAPPA + i] = relaxed_slip_rate(x[ix::KAPPA + i], x[ix::OMEGA + i], radius, w.vxw[i], sigma);
        }
        (d, w)
    }

    /// The observation from the derivative `d` and the per-wheel quantities `w` of one evaluation.
    fn observation_of(&self, x: &SVector<f64, N>, u: &Inputs, d: &SVector<f64, N>, w: &Wheels) -> Observation {
        let kin = super::rigid_body(x.as_slice());
        let (ax, ay) = self.body_acceleration(x, d);
        let mean = |a: [f64; 4], axle: usize| 0.5 * (a[2 * axle] + a[2 * axle + 1]);
        let kappa = [x[ix::KAPPA], x[ix::KAPPA + 1], x[ix::KAPPA + 2], x[ix::KAPPA + 3]];
        let omega = [x[ix::OMEGA], x[ix::OMEGA + 1], x[ix::OMEGA + 2], x[ix::OMEGA + 3]];
        Observation {
            kin,
            ax_mps2: ax,
            ay_mps2: ay,
            alpha_rad: [mean(w.alpha, 0), mean(w.alpha, 1)],
            kappa: [mean(kappa, 0), mean(kappa, 1)],
            fx_n: [w.f[0].fx_n + w.f[1].fx_n, w.f[2].fx_n + w.f[3].fx_n],
            fy_n: [w.f[0].fy_n + w.f[1].fy_n, w.f[2].fy_n + w.f[3].fy_n],
            omega_radps: [mean(omega, 0), mean(omega, 1)],
            fz_n: w.fz,
            roll_rad: x[ix::PHI],
            contact_temp_axle_c: [mean(u.contact_temp_c, 0), mean(u.contact_temp_c, 1)],
        }
    }
}

impl VehicleModel<N> for Roll4Dof {
    const TYRES: usize = 4;

    fn state_names(&self) -> [&'static str; N] {
        [
            "x_m",
            "y_m",
            "yaw_rad",
            "vx_mps",
            "vy_mps",
            "yaw_rate_radps",
            "roll_rad",
            "roll_rate_radps",
            "ax_lagged_mps2",
            "ay_lagged_mps2",
            "omega_fl_radps",
            "omega_fr_radps",
            "omega_rl_radps",
            "omega_rr_radps",
            "kappa_fl",
            "kappa_fr",
            "kappa_rl",
            "kappa_rr",
        ]
    }

    fn initial_state(&self, x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> SVector<f64, N> {
        let mut s = SVector::<f64, N>::zeros();
        super::set_rigid_body(s.as_mut_slice(), x_m, y_m, yaw_rad, speed_mps);
        let omega = speed_mps / self.vehicle.tyre.rolling_radius_m;
        for i in 0..4 {
            s[ix::OMEGA + i] = omega;
        }
        s
    }

    /// Acceleration of the whole vehicle's CG: that of O plus the sprung mass's share of its roll
    /// acceleration, -(m_s / m) h' dp/dt sideways (equal to the tyre forces over m by Newton).
    fn body_acceleration(&self, x: &SVector<f64, N>, dx: &SVector<f64, N>) -> (f64, f64) {
        let shift = self.roll_shift;
        (dx[ix::VX] - x[ix::R] * x[ix::VY], dx[ix::VY] + x[ix::R] * x[ix::VX] - shift * dx[ix::P])
    }

    #[inline]
    fn evaluate(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, extras: Extras<'_>) -> SVector<f64, N> {
        let (d, w) = self.eval(x, u, env);
        if let Some(out) = extras.contacts {
            self.contacts_of(x, env, &w, out);
        }
        if let Some(o) = extras.observation {
            *o = self.observation_of(x, u, &d, &w);
        }
        d
    }

    fn spin_slip(&self) -> Option<SpinSlip> {
        const PAIRS: [(usize, usize); 4] = [
            (ix::OMEGA, ix::KAPPA),
            (ix::OMEGA + 1, ix::KAPPA + 1),
            (ix::OMEGA + 2, ix::KAPPA + 2),
            (ix::OMEGA + 3, ix::KAPPA + 3),
        ];
        let t = &self.vehicle.tyre;
        Some(SpinSlip { pairs: &PAIRS, kappa_per_omega: t.rolling_radius_m / t.relaxation_length_x_m })
    }

    fn monitor(&self) -> Option<&dyn Monitored<N>> {
        Some(self)
    }

    fn wheel_speeds(&self) -> Option<&dyn WheelSpeeds<N>> {
        Some(self)
    }
}

impl Monitored<N> for Roll4Dof {
    /// Wheel lift per wheel and negative axle load per axle (see the module docs).
    fn conditions(&self, x: &SVector<f64, N>, _u: &Inputs, _env: &Environment, out: &mut Vec<Condition>) {
        let (axle, wheel) = self.unclamped_loads(x);
        for (i, &fz) in wheel.iter().enumerate() {
            out.push(Condition {
                onset: EventKind::WheelLift,
                recovery: EventKind::WheelContact,
                subject: WHEEL_SUBJECTS[i],
                quantity: "normal load before clamping",
                value: fz,
                unit: "N",
                // An unloaded axle (clamped to 0) lifts both its wheels whatever their own value.
                active: fz <= 0.0 || axle[i / 2] <= 0.0,
            });
        }
        for (i, &fz) in axle.iter().enumerate() {
            out.push(Condition {
                onset: EventKind::NegativeNormalLoad,
                recovery: EventKind::NormalLoadRestored,
                subject: AXLE_SUBJECTS[i],
                quantity: "axle load from longitudinal transfer before clamping",
                value: fz,
                unit: "N",
                active: fz < 0.0,
            });
        }
    }

    /// The tyres' departures from their published laws, per wheel.
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
        let w = self.wheels(x, u, env);
        for (i, wheel) in WHEELS.iter().enumerate() {
            let input = tyre_input(x, u, env, i, w.fz[i], w.alpha[i], w.vxw[i]);
            if let Some((kind, detail)) = tyre.mounted[i % 2].departure(&input) {
                out.push((kind, format!("{wheel} tyre: {detail}")));
            }
        }
    }
}

impl WheelSpeeds<N> for Roll4Dof {
    /// Per wheel (FL, FR, RL, RR): omega R_e, the wheel-centre forward speed in wheel axes,
    /// whether it is driven and its largest brake torque.
    fn wheel_sensors(&self, x: &SVector<f64, N>, steer_rad: f64, out: &mut [super::WheelSensor; 4]) -> usize {
        let v = &self.vehicle;
        let (vx, vy, r) = (x[ix::VX], x[ix::VY], x[ix::R]);
        let (dl, dr) = front_steer_angles(steer_rad, self.roll.ackermann, v.wheelbase_m(), v.track_m);
        let share = v.drive_front_share();
        let bmax = v.brake_torque_max_nm;
        for (i, o) in out.iter_mut().enumerate() {
            let (px, py) = self.pos[i];
            let steer = [dl, dr, 0.0, 0.0][i];
            let front = i < 2;
            *o = super::WheelSensor {
                omega_r_mps: x[ix::OMEGA + i] * v.tyre.rolling_radius_m,
                v_mps: to_wheel_axes(vx - r * py, vy + r * px, steer).0,
                driven: if front { share > 0.0 } else { share < 1.0 },
                brake_max_nm: 0.5 * bmax * if front { v.brake_front_share } else { 1.0 - v.brake_front_share },
            };
        }
        4
    }
}

/// The tyre input of wheel `i` (FL, FR, RL, RR) at load `fz` (N), slip angle `alpha` (rad) and
/// wheel-axis forward speed `vxw` (m/s).
fn tyre_input(
    x: &SVector<f64, N>,
    u: &Inputs,
    env: &Environment,
    i: usize,
    fz: f64,
    alpha: f64,
    vxw: f64,
) -> TyreInput {
    TyreInput {
        fz_n: fz,
        kappa: x[ix::KAPPA + i],
        alpha_rad: alpha,
        camber_rad: 0.0,
        vx_mps: vxw,
        mu_surface: env.mu,
        surface_temp_c: env.surface_temp_c,
        contact_temp_c: u.contact_temp_c[i],
    }
}
