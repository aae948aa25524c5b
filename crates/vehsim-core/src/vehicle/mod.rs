//! Vehicle models as pure equations: one evaluation `evaluate(state, inputs, environment) -> dstate`
//! ([`VehicleModel`]), with what only some models offer in [`capability`].
//!
//! A model owns no time, no controller and no I/O; the engine ([`crate::sim`]) integrates it.
//! States are fixed-size `SVector`s. By convention every model's state starts with the rigid-body
//! states X, Y (m), yaw (rad), vx, vy (m/s, body frame) and yaw rate r (rad/s), in that order;
//! `rigid_body` reads them, so drivers, manoeuvres and output work with any model.

pub mod bicycle;
pub mod capability;
pub mod condition;
pub mod ground;
pub mod lateral;
pub mod params;
pub mod powertrain;
pub mod road;
pub mod roll4dof;
pub mod sensors;
pub mod single_track;
pub mod wheel;

use nalgebra::SVector;

use crate::contact::TyreContact;

pub use bicycle::Bicycle;
pub use capability::MAX_LAGS;
pub use condition::Condition;
pub use params::{
    body_bounds, lateral_bounds, sensor_bounds, DriveLayout, Lateral, Roll, Sensors, Vehicle, AIR_DENSITY, GRAVITY,
};
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
    /// Distance the CG has travelled since the start, m: the integral of its forward speed (the
    /// engine's trapezoid over the control samples, ramped across each period). Read by a friction
    /// stretch ([`ground::GroundRegions::stretch`]).
    pub distance_m: f64,
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
            distance_m: 0.0,
        }
    }
}

/// What the wheel-speed sensors and the brake layout tell the slip controllers about one wheel
/// ([`capability::WheelSpeeds`]; the bicycle's "wheel" is an axle).
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
    /// The road's constant bank and grade (flat by default; the bicycle model applies them).
    pub road: road::Road,
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

/// What one evaluation writes besides the derivative ([`VehicleModel::evaluate`]); `None`: not
/// wanted. The default asks for nothing.
#[derive(Debug, Default)]
pub struct Extras<'a> {
    /// The observation of the state (forces, slips, accelerations).
    pub observation: Option<&'a mut Observation>,
    /// The operating conditions of every tyre, for the contact-temperature estimator, written to
    /// `[..TYRES]`.
    pub contacts: Option<&'a mut [TyreContact]>,
}

/// A vehicle model with an N-dimensional state: one evaluation of its equations
/// ([`Self::evaluate`]) and what the engine needs to start and watch a run. What only some
/// integrators or controllers use is a capability the model may offer (the accessors at the end,
/// [`capability`]); a model offers none by default.
pub trait VehicleModel<const N: usize>: Sync {
    /// Number of tyres whose contact temperature the model uses (2 for the bicycle, 4 for 4-DOF).
    const TYRES: usize;

    /// Names of the state components, for diagnostics.
    fn state_names(&self) -> [&'static str; N];

    /// Steady straight running at `speed_mps` from pose (x, y, yaw): wheels rolling, no slip.
    fn initial_state(&self, x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> SVector<f64, N>;

    /// Body-frame acceleration (ax, ay) of the CG, m/s^2, from a state and its derivative.
    fn body_acceleration(&self, x: &SVector<f64, N>, dx: &SVector<f64, N>) -> (f64, f64);

    /// One evaluation of the model at state `x` under inputs `u` on surface `env`: returns the
    /// time derivative of the state, and writes what `extras` asks for (the observation, the
    /// tyres' contact conditions) from the same tyre evaluation. Pure: the same arguments give
    /// the same values bit for bit, whatever `extras` asks for.
    fn evaluate(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, extras: Extras<'_>) -> SVector<f64, N>;

    /// Rigid-body kinematics of a state. Default: the six leading states (see the module docs).
    fn kinematics(&self, x: &SVector<f64, N>) -> Kinematics {
        rigid_body(x.as_slice())
    }

    /// Time derivative of the state: [`Self::evaluate`] asking for nothing else.
    #[inline]
    fn derivatives(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> SVector<f64, N> {
        self.evaluate(x, u, env, Extras::default())
    }

    /// Full observation (forces, slips, accelerations) of a state under inputs: [`Self::evaluate`]'s.
    fn observe(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> Observation {
        let mut o = Observation::default();
        self.evaluate(x, u, env, Extras { observation: Some(&mut o), contacts: None });
        o
    }

    /// The stiff wheel-spin / transient-slip pairs, which [`crate::sim::Method::Rk4Exp`]
    /// integrates exactly. Default: none (plain RK4).
    fn spin_slip(&self) -> Option<capability::SpinSlip> {
        None
    }

    /// The first-order lag components, which [`crate::sim::Method::Rk4Lag`] relaxes exactly.
    /// Default: none.
    fn lags(&self) -> Option<&dyn capability::Lagged<N>> {
        None
    }

    /// The unphysical conditions and one-off notes the engine reports. Default: none.
    fn monitor(&self) -> Option<&dyn capability::Monitored<N>> {
        None
    }

    /// The wheel-speed sensors the slip controllers (ABS, traction control) read. Default: none
    /// (no slip control possible).
    fn wheel_speeds(&self) -> Option<&dyn capability::WheelSpeeds<N>> {
        None
    }

    /// Components prescribed from outside the equations (the discovery replay's measured speed).
    /// Default: none.
    fn prescribed(&self) -> Option<&dyn capability::Prescribed<N>> {
        None
    }
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
