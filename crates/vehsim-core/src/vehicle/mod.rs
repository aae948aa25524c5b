//! Vehicle models as pure equations: `derivatives(state, inputs, environment) -> dstate`.
//!
//! A model owns no time, no controller and no I/O; the engine ([`crate::sim`]) integrates it.
//! States are fixed-size `SVector`s. By convention every model's state starts with the rigid-body
//! states X, Y (m), yaw (rad), vx, vy (m/s, body frame) and yaw rate r (rad/s), in that order;
//! `rigid_body` reads them, so drivers, manoeuvres and output work with any model.

pub mod bicycle;
pub mod condition;
pub mod ground;
pub mod lateral;
pub mod params;
pub mod powertrain;
pub mod roll4dof;
pub mod sensors;
pub mod single_track;
pub mod wheel;

use nalgebra::SVector;

use crate::contact::TyreContact;

pub use bicycle::Bicycle;
pub use condition::Condition;
pub use params::{lateral_bounds, sensor_bounds, DriveLayout, Lateral, Roll, Sensors, Vehicle, AIR_DENSITY, GRAVITY};
pub use roll4dof::Roll4Dof;

/// Inputs at one instant of a step (the controllers' ramps, and an open-loop steer, evaluated at
/// the integration stage's time).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inputs {
    /// Time at which these inputs hold, s: the integration stage's time. Models whose inputs
    /// include prescribed channels (the discovery replay's measured speed) read them by it; the
    /// engine's own vehicle models ignore it.
    pub t_s: f64,
    /// Road-wheel steer angle of the front wheels, rad, positive left (ISO 8855).
    pub steer_rad: f64,
    /// Total drive torque at the driven wheels, N m (>= 0), split by the drive layout.
    pub drive_torque_nm: f64,
    /// Total brake torque command, N m (>= 0), split by the brake balance.
    pub brake_torque_nm: f64,
    /// Contact-patch temperature per tyre, degC (bicycle: [front, rear, -, -]; four wheels: FL, FR, RL, RR).
    pub contact_temp_c: [f64; 4],
    /// Traction control's cap on the total drive torque at the wheels, N m (>= 0; infinite: no
    /// intervention, [`crate::control::tcs`]).
    pub drive_cap_nm: f64,
    /// ABS's cap on each wheel's brake torque, N m (bicycle: per axle [front, rear, -, -]; four
    /// wheels: FL, FR, RL, RR; infinite: no intervention, [`crate::control::abs`]).
    pub brake_cap_nm: [f64; 4],
}

impl Default for Inputs {
    /// Everything zero, no traction-control or ABS cap.
    fn default() -> Self {
        Inputs {
            t_s: 0.0,
            steer_rad: 0.0,
            drive_torque_nm: 0.0,
            brake_torque_nm: 0.0,
            contact_temp_c: [0.0; 4],
            drive_cap_nm: f64::INFINITY,
            brake_cap_nm: [f64::INFINITY; 4],
        }
    }
}

/// What the wheel-speed sensors and the brake layout tell the slip controllers about one wheel
/// ([`VehicleModel::wheel_sensors`]; the bicycle's "wheel" is an axle).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelSensor {
    /// Wheel spin speed times the rolling radius, m/s.
    pub omega_r_mps: f64,
    /// Forward speed of the wheel centre in wheel axes, m/s (the ideal reference speed).
    pub v_mps: f64,
    /// Whether the powertrain drives this wheel.
    pub driven: bool,
    /// Largest brake torque of this wheel (full pedal), N m.
    pub brake_max_nm: f64,
}

/// The surface the vehicle drives on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Environment {
    /// Peak friction coefficient of the surface.
    pub mu: f64,
    /// Bulk surface (ice) temperature, degC.
    pub surface_temp_c: f64,
    /// Friction regions on the ground (none by default; the bicycle model applies them per axle).
    pub regions: ground::GroundRegions,
}

/// Rigid-body kinematics of the vehicle in the ground frame (ISO 8855).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kinematics {
    /// CG position, m.
    pub x_m: f64,
    /// CG position Y, m (ground frame, positive left of the start heading).
    pub y_m: f64,
    /// Yaw angle, rad, counter-clockwise from the ground x axis.
    pub yaw_rad: f64,
    /// Body-frame velocity of the CG, m/s (vx forward, vy left).
    pub vx_mps: f64,
    /// Body-frame lateral velocity of the CG, m/s (positive left).
    pub vy_mps: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_radps: f64,
}

impl Kinematics {
    /// Speed of the CG, m/s.
    pub fn speed_mps(&self) -> f64 {
        // Speeds are far from overflow, so the plain root serves (hypot is several times slower).
        (self.vx_mps * self.vx_mps + self.vy_mps * self.vy_mps).sqrt()
    }

    /// Vehicle sideslip angle atan2(vy, vx), rad (0 at standstill).
    pub fn sideslip_rad(&self) -> f64 {
        if self.vx_mps == 0.0 && self.vy_mps == 0.0 {
            0.0
        } else {
            self.vy_mps.atan2(self.vx_mps)
        }
    }

    /// Ground-frame position of a point at body coordinates (px forward, py left) from the CG.
    pub fn body_point(&self, px: f64, py: f64) -> (f64, f64) {
        let (s, c) = self.yaw_rad.sin_cos();
        (self.x_m + px * c - py * s, self.y_m + px * s + py * c)
    }
}

/// The rigid-body kinematics from the six leading states (see the module docs).
pub(crate) fn rigid_body(x: &[f64]) -> Kinematics {
    Kinematics { x_m: x[0], y_m: x[1], yaw_rad: x[2], vx_mps: x[3], vy_mps: x[4], yaw_rate_radps: x[5] }
}

/// Write a pose and forward speed into the six leading states (the rest is left as it is).
pub(crate) fn set_rigid_body(x: &mut [f64], x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) {
    x[..6].copy_from_slice(&[x_m, y_m, yaw_rad, speed_mps, 0.0, 0.0]);
}

/// Everything an output row or a summary needs from one instant, common to every model.
/// Axle quantities are sums over the axle's wheels; for four-wheel models the per-wheel arrays
/// hold FL, FR, RL, RR.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Observation {
    /// Rigid-body pose and velocities of the CG.
    pub kin: Kinematics,
    /// Body-frame accelerations of the CG (including the centripetal part), m/s^2.
    pub ax_mps2: f64,
    /// Body-frame lateral acceleration of the CG, m/s^2 (positive left).
    pub ay_mps2: f64,
    /// Slip angle per axle (front, rear), rad (mean over an axle's wheels).
    pub alpha_rad: [f64; 2],
    /// Slip ratio per axle (front, rear) seen by the tyre force (mean over an axle's wheels).
    pub kappa: [f64; 2],
    /// Longitudinal and lateral tyre force per axle in wheel axes, N (sum over the axle).
    pub fx_n: [f64; 2],
    /// Lateral tyre force per axle (front, rear) in wheel axes, N (positive left; sum over the axle).
    pub fy_n: [f64; 2],
    /// Wheel spin speed per axle (front, rear), rad/s (mean over the axle).
    pub omega_radps: [f64; 2],
    /// Normal load per wheel FL, FR, RL, RR, N (bicycle: each axle's static load split equally
    /// between its two tyres, plus the quasi-static lateral transfer when `[lateral]` sets one).
    pub fz_n: [f64; 4],
    /// Roll angle, rad (0 for models without roll).
    pub roll_rad: f64,
    /// Contact temperature per axle (front, rear), degC: the input's per-tyre values, averaged
    /// over an axle's tyres for four-wheel models.
    pub contact_temp_axle_c: [f64; 2],
}

/// Most first-order lag components a model can declare for [`crate::sim::Method::Rk4Lag`].
pub const MAX_LAGS: usize = 8;

/// A vehicle model with an N-dimensional state.
pub trait VehicleModel<const N: usize>: Sync {
    /// Number of tyres whose contact temperature the model uses (2 for the bicycle, 4 for 4-DOF).
    const TYRES: usize;

    /// Whether the engine ends a run whose sideslip exceeds 60 degrees (spin-out). Default true; a
    /// model whose forward speed is prescribed (the discovery replay, which follows a measured
    /// run to its end whatever its sideslip) sets it false.
    const SPIN_OUT: bool = true;

    /// Names of the state components, for diagnostics.
    fn state_names(&self) -> [&'static str; N];

    /// Time derivative of the state; pure.
    fn derivatives(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> SVector<f64, N>;

    /// Rigid-body kinematics of a state.
    fn kinematics(&self, x: &SVector<f64, N>) -> Kinematics;

    /// Steady straight running at `speed_mps` from pose (x, y, yaw): wheels rolling, no slip.
    fn initial_state(&self, x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> SVector<f64, N>;

    /// Body-frame acceleration (ax, ay) of the CG, m/s^2, from a state and its derivative.
    fn body_acceleration(&self, x: &SVector<f64, N>, dx: &SVector<f64, N>) -> (f64, f64);

    /// Full observation (forces, slips, accelerations) of a state under inputs.
    fn observe(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> Observation;

    /// [`Self::derivatives`] and [`Self::observe`] of the same state and inputs together, the same
    /// values bit for bit; models override it to evaluate their tyres once for both (the engine
    /// takes its output rows from the first RK4 stage). Default: the two calls.
    fn derivatives_observed(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
    ) -> (SVector<f64, N>, Observation) {
        (self.derivatives(x, u, env), self.observe(x, u, env))
    }

    /// Operating conditions of every tyre (for the contact-temperature estimator), in `out[..TYRES]`.
    fn tyre_contacts(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, out: &mut [TyreContact]);

    /// [`Self::tyre_contacts`] into `out` and [`Self::derivatives`] (with [`Self::observe`] when
    /// `observe`) of the same state and inputs together, the same values bit for bit as the
    /// separate calls; models override it to evaluate their tyres once for all of them (the
    /// engine's contact-temperature estimate at a controller sample and the coming step's first
    /// stage share that evaluation). Default: the separate calls.
    fn derivatives_contacts(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        observe: bool,
        out: &mut [TyreContact],
    ) -> (SVector<f64, N>, Option<Observation>) {
        self.tyre_contacts(x, u, env, out);
        if observe {
            let (d, o) = self.derivatives_observed(x, u, env);
            (d, Some(o))
        } else {
            (self.derivatives(x, u, env), None)
        }
    }

    /// Push the unphysical conditions this model watches, evaluated at state `x` under inputs `u`,
    /// onto `out`: the same conditions in the same order at every call (the engine reports when
    /// one starts or stops holding). The default watches nothing: the bicycle's normal loads are
    /// static and positive, so it has nothing to report.
    fn conditions(&self, _x: &SVector<f64, N>, _u: &Inputs, _env: &Environment, _out: &mut Vec<Condition>) {}

    /// Push the one-off notes of state `x` under inputs `u` as (event kind, detail): the tyres'
    /// departures from their published laws ([`crate::tyre::TyreModel::departure`]), with the
    /// tyre named in the detail. The engine reports each kind once per run, at the first state
    /// that shows it (step resolution). Default: none.
    fn notes(
        &self,
        _x: &SVector<f64, N>,
        _u: &Inputs,
        _env: &Environment,
        _out: &mut Vec<(crate::event::EventKind, String)>,
    ) {
    }

    /// The wheel-speed sensors of the slip controllers (ABS, traction control) at state `x` with
    /// road-wheel angle `steer_rad`, into `out`; returns how many wheels (2 for the bicycle's
    /// axles, 4 for four wheels). Default: none (no slip control possible).
    fn wheel_sensors(&self, _x: &SVector<f64, N>, _steer_rad: f64, _out: &mut [WheelSensor; 4]) -> usize {
        0
    }

    /// The stiff wheel-spin / transient-slip pairs, (omega index, relaxed-slip index) per wheel or
    /// axle, and d(dkappa/dt)/d(omega) = R_e / sigma (see [`wheel`]); the engine's exponential RK4
    /// integrates them exactly. Default: none (plain RK4).
    fn spin_slip_pairs(&self) -> (&'static [(usize, usize)], f64) {
        (&[], 0.0)
    }

    /// The state's first-order lag components dy_j/dt = k_j (u_j - y_j) (at most [`MAX_LAGS`]),
    /// which [`crate::sim::Method::Rk4Lag`] relaxes exactly over a step. Default: none.
    fn lag_states(&self) -> &[usize] {
        &[]
    }

    /// For [`crate::sim::Method::Rk4Lag`]: the derivative of the state with the lag components'
    /// entries left out (their values are not used where the lag's rate is positive), and each
    /// lag's input u_j in [`Self::lag_states`] order. With the rates of [`Self::lag_rates`],
    /// [`Self::derivatives`] must equal it with entry j replaced by k_j (u_j - y_j) wherever
    /// k_j > 0. Default: the derivative and no lags.
    fn lag_split(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> (SVector<f64, N>, [f64; MAX_LAGS]) {
        (self.derivatives(x, u, env), [0.0; MAX_LAGS])
    }

    /// The lag rates k_j (1/s) at state `x`, in [`Self::lag_states`] order (0: the component is
    /// integrated like any other). Default: all 0.
    fn lag_rates(&self, _x: &SVector<f64, N>, _u: &Inputs, _env: &Environment) -> [f64; MAX_LAGS] {
        [0.0; MAX_LAGS]
    }

    /// Map the state at the end of every accepted step, at time `t_s`, onto the model's admissible
    /// set (bounds that the equations do not keep by themselves, prescribed components). Default:
    /// nothing.
    fn project(&self, _t_s: f64, _x: &mut SVector<f64, N>) {}
}

/// Which vehicle model a run uses (top-level `vehicle_model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VehicleModelKind {
    /// Nonlinear single-track model, static axle loads (default).
    Bicycle,
    /// Four-wheel model with body roll and load transfer; needs the vehicle's `[roll]` section.
    Roll4Dof,
}

choice_names!(VehicleModelKind {
    Bicycle => "bicycle",
    Roll4Dof => "roll4dof",
});

named_by_as_str!(VehicleModelKind);
