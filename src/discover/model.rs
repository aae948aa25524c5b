//! The replay model: a lateral single-track (bicycle) model driven by the measured steer and the
//! measured forward speed, with the candidate effects as optional extensions.
//!
//! The forward speed is prescribed exactly (interpolated measured vx), not tracked by a PID: the
//! discrepancy workflow must compare lateral dynamics, and a speed-tracking error would show up as a
//! spurious residual. Tyre forces come from the vehicle's tyre provider (`vehsim_core::tyre`), each axle
//! carrying two tyres mounted left and right as on the engine's bicycle, free rolling (zero slip
//! ratio) unless the longitudinal coupling is on. State (12): vy (m/s), r (rad/s), the front and rear axle lateral
//! forces Fy_f, Fy_r (N) used when the tyre relaxation effect is on, the effective road-wheel
//! angle delta_e (rad) used when the steering lag is on, the pose X, Y (m), psi (rad) in the
//! ground frame (used by the closed-loop lane change of `vehsim synth` and by friction changes
//! placed on the ground), the lagged slip angles alpha_f, alpha_r (rad) of transient slip, the
//! tread-temperature rises dT_f, dT_r (K) of the tread-state thermal form and the forward speed vx
//! (m/s, index 12: the measured one, which the replay on the engine sets after every step for the
//! kinematics; the equations read vx from their inputs). A replay runs on the engine
//! ([`super::replay`], which wraps this model and a run's channels as an engine model), whatever
//! the run's sampling: this module has the equations, not a time loop.
//!
//! Equations (body frame, ISO 8855): the engine's bicycle's lateral pair, from
//! [`vehsim_core::vehicle::single_track`],
//!
//!   m (dvy/dt + r vx) = Fx_f sin(delta_e) + Fy_f cos(delta_e) + Fy_r
//!   I_z dr/dt         = a (Fx_f sin(delta_e) + Fy_f cos(delta_e)) - b Fy_r + Mz_f + Mz_r
//!   alpha_f = delta_e - atan((vy + a r) / vx),  alpha_r = -atan((vy - b r) / vx)
//!
//! with the axle forces of the free-rolling tyres: Fx_f is the tyre's longitudinal force at zero
//! slip ratio (0 for a tyre without longitudinal shifts) and Mz its aligning moment (0 unless the
//! provider models it), so these terms are the engine's own for wheels that neither drive nor
//! brake. The slip angles are the wheel-axis ones of the engine ([`vehsim_core::vehicle::wheel`])
//! written with the body velocities (the same angles while vx >= 1 m/s and the wheels roll forward
//! at >= 0.5 m/s, above both models' speed floors).
//!
//! Effects (all off by default; each default gives the baseline exactly; the relaxation rate, load
//! transfer and thermal factor are the engine's own, from [`vehsim_core::vehicle::lateral`]):
//! - `tyre_relaxation`: dFy/dt = (|vx| / sigma_y) (Fy_ss(alpha) - Fy), relaxation length sigma_y (m);
//!   sigma_y = 0 uses the steady-state force directly.
//! - `steer_compliance`, force form: delta_e = delta - c_s Fy_f, c_s in rad/kN of front axle lateral
//!   force (the damped fixed point of [`vehsim_core::vehicle::lateral::compliant_steer`] when relaxation
//!   is off, the force acting being the one at the converged delta_e; from the lagged force
//!   otherwise); lag form: d(delta_e)/dt = (delta - delta_e) / tau_s, a first-order steering lag
//!   with time constant tau_s (s).
//! - `friction_change`, global form: surface friction mu_e = s_mu mu on the whole run; stretch form:
//!   mu_e = mu (1 + (s_mu - 1) w(d)) where d is the distance travelled since the first sample
//!   (integral of the measured vx, m) and w is a window of 1 over [d0, d0 + L] with 1 m logistic
//!   edges (so the fit sees a continuous objective).
//!   Patch form: mu_e,i = mu (1 + (s_mu - 1) w_i), w_i a disc of radius R at (X0, Y0) on the
//!   ground (1 m logistic edge) evaluated at axle i's own position X + l_i cos psi,
//!   Y + l_i sin psi (l_f = a, l_r = -b), from the logged pose (columns x, y, psi) when the run
//!   has it, else from the replay's own integrated pose (starting at the origin heading +X).
//!   Band form: the same with w_i a band across the ground, 1 over [X0, X0 + L] of axle i's own
//!   abscissa X + l_i cos psi (any Y), 1 m logistic edges.
//! - `thermal_friction`: on runs on ice (sidecar `ice_temp_c`), the ATIIM per-step estimator
//!   ([`vehsim_core::contact::estimator::AtiimEstimator`], default `[contact]` tyre) tracks each axle's
//!   contact temperature from its load, rolling speed, sliding speed vx |tan alpha| and lateral
//!   force, and the friction falls with the rise above the ice temperature:
//!   mu_e = mu max(1 + k_T (T_contact - T_ice), 0.1), k_T in 1/K (negative). The contact
//!   temperature also feeds the tyre input, so temperature-dependent providers see it.
//!   Tread-state form: on ice, each axle's tread-temperature rise dT_i (K) is a state,
//!   d(dT_i)/dt = P_i / C - dT_i / tau_c with P_i = vx |tan alpha_i| |Fy_i| the axle's frictional
//!   power (W), C its tread heat capacity (J/K) and tau_c the cooling time (s); it is a
//!   first-order lag towards P_i tau_c / C, updated like the other lags, and capped at melting
//!   (0 <= dT_i <= 0 degC - T_ice, the cap applied after every step: heat beyond it melts ice).
//!   mu_e,i = mu max(1 + k_T dT_i, 0.1); the tyre's contact temperature is T_ice + dT_i.
//! - `load_transfer`: lateral load transfer dFz = m ay_ss h_lt / track per axle in proportion to its
//!   static load, with ay_ss = vx r; each tyre of an axle is evaluated at its own load, so the tyre's
//!   load sensitivity lowers the axle force. h_lt is the effective transfer height (m).
//!   Sensitive form: besides, each tyre's friction and cornering stiffness change with its
//!   relative load z = Fz / Fz0 - 1 (Fz0 the static tyre load): mu x max(1 - k_mu z, 0.05) and
//!   alpha x max(1 - k_c z, 0.05), so that the fit does not rest on the tyre file's own load
//!   sensitivity alone.
//! - `axle_cornering_stiffness`: each axle's tyres are evaluated at slip angle c_i alpha_i
//!   (i = front, rear), which scales the cornering stiffness dFy/dalpha at alpha = 0 by c_i and
//!   leaves the peak force unchanged (it is reached at a slip angle 1/c_i times the tyre's).
//! - `axle_peak_friction`: each axle's tyres see the surface friction s_i mu_e, so the peak force
//!   scales by s_i (for providers whose force saturates at mu Fz).
//! - vehicle parameters ([`super::vehicle_params`]: `yaw_inertia`, `mass`, the CG position): the
//!   replay runs the vehicle with the key scaled by its factor ([`ReplayModel::simulate`]).
//! - `sensor_latency`, `accelerometer_position`, `sensor_scale`, `clock_skew`,
//!   `accelerometer_orientation`: the measurement chain ([`super::sensors`]).
//! - `sensor_bias`: constant offsets added to the simulated yaw-rate and lateral-acceleration
//!   sensors, b_r (rad/s) and b_ay (m/s^2).
//! - `longitudinal_coupling`: the measured speed change is driven and braked through the tyres
//!   ([`super::coupling`]): each axle's share of the force along the body, from the speed's slope,
//!   is given by the slip ratio solved for it (the lateral force is then the tyre's combined-slip
//!   one), and each tyre's load moves by -+h S / (2 L) at the fitted height h.
//!
//! The run's road (sidecar `[road]`, [`vehsim_core::vehicle::road`]; part of the baseline, flat
//! by default): gravity's lateral component in the road plane m g_y acts on the body at the CG,
//!   m (dvy/dt + r vx) = Fx_f sin(delta_e) + Fy_f cos(delta_e) + Fy_r + m g_y,
//! while the simulated accelerometer logs the tyre forces over the mass (specific force), and each
//! tyre carries its axle's normal load on the bank and grade at the vehicle's CG height. The
//! prescribed vx needs no longitudinal balance, so g_x acts only through the axle loads.

use std::path::Path;

use nalgebra::SVector;

use super::measured::MeasuredRun;
use vehsim_core::contact::estimator::AtiimEstimator;
use vehsim_core::contact::thermal::MELT_C;
use vehsim_core::contact::TyreContact;
use vehsim_core::control::driver::Driver;
use vehsim_core::path::RefPath;
use vehsim_core::tyre::{TyreForces, TyreInput, TyreModel};
use vehsim_core::vehicle::road::Road;
use vehsim_core::vehicle::wheel::slide_speed;
use vehsim_core::vehicle::Vehicle;
use vehsim_core::vehicle::{ground, lateral, single_track};
use vehsim_spec::contact::ContactSpec;

/// Parameters of every candidate effect; the default is the baseline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EffectParams {
    /// Lateral relaxation length, m (0 = off; typical 0.3-1.5 m).
    pub sigma_y_m: f64,
    /// Steer compliance, rad per kN of front axle lateral force (0 = off; typical 0.001-0.01).
    pub steer_compliance_rad_per_kn: f64,
    /// Steering lag time constant, s (0 = off; typical 0.03-0.3).
    pub steer_lag_s: f64,
    /// Friction scale on the nominal surface mu over the whole run (1 = off; typical 0.3-1.5).
    pub mu_scale: f64,
    /// Friction scale over the stretch below (1 = off), on top of `mu_scale`.
    pub stretch_scale: f64,
    /// Start of the friction stretch, m of distance travelled from the first sample.
    pub stretch_start_m: f64,
    /// Length of the friction stretch, m (0 = the scale applies to the whole run).
    pub stretch_length_m: f64,
    /// Friction change per kelvin of contact-temperature rise on ice, 1/K (0 = off; negative).
    pub thermal_mu_per_k: f64,
    /// Effective lateral load-transfer height, m (0 = off; typical 0.3-0.8).
    pub load_transfer_height_m: f64,
    /// Yaw-rate sensor offset, rad/s (typical |b| < 0.05).
    pub bias_yaw_rate_radps: f64,
    /// Lateral-acceleration sensor offset, m/s^2 (typical |b| < 0.5).
    pub bias_ay_mps2: f64,
    /// Latency of the logged yaw-rate and lateral-acceleration channels, s (0 = none;
    /// [`super::sensors`]).
    pub latency_s: [f64; 2],
    /// Accelerometer position relative to the CG: x ahead, y to the left, m (0 = at the CG;
    /// [`super::sensors`]).
    pub accel_position_m: [f64; 2],
    /// Cornering-stiffness factor per axle (front, rear), 1 (1 = off; typical 0.5-2).
    pub stiffness_scale: [f64; 2],
    /// Peak-friction factor per axle (front, rear), 1 (1 = off; typical 0.5-1.5).
    pub mu_axle_scale: [f64; 2],
    /// Factors on the vehicle's physical parameters, in the order of
    /// [`super::vehicle_params::TABLE`] (1 = the spec's value).
    pub body_scale: [f64; super::vehicle_params::N],
    /// Scale factors of the logged yaw rate and lateral acceleration, 1 (1 = off).
    pub sensor_scale: [f64; 2],
    /// The inertial unit's clock runs fast against the logger's by this much, ppm (0 = off).
    pub clock_skew_ppm: f64,
    /// The accelerometer's y axis turned towards +x by this angle, rad (0 = off).
    pub accel_yaw_misalignment_rad: f64,
    /// Transient-slip relaxation length per axle (front, rear), m (0 = off; typical 0.3-1.5).
    pub slip_relaxation_m: [f64; 2],
    /// Whether the transient-slip relaxation length shortens with the tyre's local slope.
    pub slip_relaxation_saturating: bool,
    /// Load sensitivity of each tyre's friction and cornering stiffness under load transfer,
    /// [k_mu, k_c], per unit of relative load change (Fz - Fz0) / Fz0 (0 = only the tyre's own).
    pub load_sensitivity: [f64; 2],
    /// Friction patch on the ground: [friction scale, centre X (m), centre Y (m), radius (m)]
    /// in the run's ground frame (radius 0 = off).
    pub patch: [f64; 4],
    /// Friction band across the ground: [friction scale, start X (m), length along X (m)] in the
    /// run's ground frame (length 0 = off).
    pub band: [f64; 3],
    /// Friction change per kelvin of the tread-temperature state's rise on ice, 1/K (0 = off;
    /// negative).
    pub tread_mu_per_k: f64,
    /// Heat capacity of one axle's tread/contact layer, J/K (> 0).
    pub tread_heat_capacity_j_per_k: f64,
    /// Cooling time constant of the tread temperature towards the ice temperature, s (> 0).
    pub tread_cooling_s: f64,
    /// The road's bank and grade on every run, replacing each run's own (its sidecar's `[road]`)
    /// while the road effect is fitted (None: each run's own).
    pub road: Option<Road>,
    /// Longitudinal–lateral coupling: the height at which the tyres' longitudinal forces move
    /// load between the axles, m (0 = off: the tyres roll free on static loads; [`super::coupling`]).
    pub longitudinal_transfer_height_m: f64,
}

impl Default for EffectParams {
    fn default() -> Self {
        Self {
            sigma_y_m: 0.0,
            steer_compliance_rad_per_kn: 0.0,
            steer_lag_s: 0.0,
            mu_scale: 1.0,
            stretch_scale: 1.0,
            stretch_start_m: 0.0,
            stretch_length_m: 0.0,
            thermal_mu_per_k: 0.0,
            load_transfer_height_m: 0.0,
            bias_yaw_rate_radps: 0.0,
            bias_ay_mps2: 0.0,
            latency_s: [0.0; 2],
            accel_position_m: [0.0; 2],
            stiffness_scale: [1.0; 2],
            mu_axle_scale: [1.0; 2],
            body_scale: [1.0; super::vehicle_params::N],
            sensor_scale: [1.0; 2],
            clock_skew_ppm: 0.0,
            accel_yaw_misalignment_rad: 0.0,
            slip_relaxation_m: [0.0; 2],
            slip_relaxation_saturating: false,
            patch: [1.0, 0.0, 0.0, 0.0],
            load_sensitivity: [0.0; 2],
            band: [1.0, 0.0, 0.0],
            tread_mu_per_k: 0.0,
            tread_heat_capacity_j_per_k: 300.0,
            tread_cooling_s: 3.0,
            road: None,
            longitudinal_transfer_height_m: 0.0,
        }
    }
}

impl EffectParams {
    /// The effects a vehicle spec switches on: its `[lateral]` keys and its `[sensors]` section
    /// (the baseline of a discovery that starts from an improved vehicle.toml, which thus
    /// replays exactly as the discovery's final model did).
    pub fn of_vehicle(v: &Vehicle) -> Self {
        let l = &v.lateral;
        let s = v.sensors.unwrap_or_default();
        Self {
            sigma_y_m: l.relaxation_length_y_m,
            steer_compliance_rad_per_kn: l.steer_compliance_rad_per_kn,
            steer_lag_s: l.steer_lag_s,
            mu_scale: l.mu_scale,
            thermal_mu_per_k: l.thermal_mu_per_k,
            load_transfer_height_m: l.load_transfer_height_m,
            bias_yaw_rate_radps: s.bias[0],
            bias_ay_mps2: s.bias[1],
            latency_s: s.latency_s,
            accel_position_m: s.accel_position_m,
            sensor_scale: s.scale,
            clock_skew_ppm: s.clock_skew_ppm,
            accel_yaw_misalignment_rad: s.accel_yaw_misalignment_rad,
            stiffness_scale: l.stiffness_scale,
            mu_axle_scale: l.mu_axle_scale,
            slip_relaxation_m: l.slip_relaxation_m,
            slip_relaxation_saturating: l.slip_relaxation_saturating,
            load_sensitivity: l.load_sensitivity,
            tread_mu_per_k: l.tread_mu_per_k(),
            tread_heat_capacity_j_per_k: l.tread_heat_capacity_j_per_k,
            tread_cooling_s: l.tread_cooling_time_s,
            longitudinal_transfer_height_m: l.longitudinal_transfer_height_m,
            ..Self::default()
        }
    }

    /// Friction factor of the ground patch at ground point (X, Y), m: 1 + (s - 1) w with w a disc
    /// of the patch radius with logistic edges of [`STRETCH_EDGE_M`].
    pub fn patch_factor(&self, x_m: f64, y_m: f64) -> f64 {
        ground::patch_factor(self.patch, x_m, y_m)
    }

    /// Friction factor of the ground band at ground abscissa X, m: 1 + (s - 1) w with w a window
    /// of 1 over [X0, X0 + L] with logistic edges of [`STRETCH_EDGE_M`] (any Y).
    pub fn band_factor(&self, x_m: f64) -> f64 {
        ground::band_factor(self.band, x_m)
    }

    /// True when a friction change placed on the ground (patch or band) is on.
    pub fn on_ground(&self) -> bool {
        self.patch[3] > 0.0 || self.band[2] > 0.0
    }

    /// True when the tread-temperature state is on (it acts on runs on ice only).
    pub fn tread(&self) -> bool {
        self.tread_mu_per_k != 0.0
    }

    /// True when the longitudinal–lateral coupling is on (the measured speed change loads the
    /// tyres, [`super::coupling`]).
    pub fn coupled(&self) -> bool {
        self.longitudinal_transfer_height_m > 0.0
    }

    /// True when the transient-slip form of tyre relaxation is on.
    pub fn transient_slip(&self) -> bool {
        self.slip_relaxation_m[0] > 0.0
    }

    /// Friction scale at distance `d_m` travelled (the friction_change effect): the global scale,
    /// times 1 + (s - 1) w(d) over a stretch.
    pub fn mu_factor(&self, d_m: f64) -> f64 {
        if self.stretch_length_m <= 0.0 {
            return self.mu_scale;
        }
        let w = ground::window(d_m - self.stretch_start_m, self.stretch_start_m + self.stretch_length_m - d_m);
        self.mu_scale * (1.0 + (self.stretch_scale - 1.0) * w)
    }

    /// These parameters with the friction regions of a run's ground (its sidecar's
    /// `[[surface.patch]]`, `[[surface.band]]`, `[[surface.stretch]]`: part of the baseline) set
    /// where given, unless the same kind is already on here (a candidate being fitted replaces
    /// the sidecar's region of its kind).
    pub fn with_regions(&self, g: &super::measured::Regions) -> Self {
        let mut p = *self;
        if let (Some(v), false) = (g.patch, self.patch[3] > 0.0) {
            p.patch = v;
        }
        if let (Some(v), false) = (g.band, self.band[2] > 0.0) {
            p.band = v;
        }
        if let (Some([s, start, len]), false) = (g.stretch, self.stretch_length_m > 0.0) {
            (p.stretch_scale, p.stretch_start_m, p.stretch_length_m) = (s, start, len);
        }
        p
    }
}

/// Largest tread-temperature rise above an ice at `ice_c` (degC), K: the contact cannot exceed
/// melting (frictional heat beyond it melts ice instead of warming the contact).
pub fn melt_cap_k(ice_c: f64) -> f64 {
    (MELT_C - ice_c).max(0.0)
}

/// Width of the logistic edges of a friction stretch, m.
pub const STRETCH_EDGE_M: f64 = ground::EDGE_M;

/// Simulated channels at the measured sample times.
#[derive(Debug, Clone, Default)]
pub struct Simulated {
    pub yaw_rate: Vec<f64>,
    pub ay: Vec<f64>,
    pub vy: Vec<f64>,
    /// Front axle slip angle, rad.
    pub alpha_f: Vec<f64>,
    /// Front contact-temperature rise above the ice, K (0 unless thermal_friction is on).
    pub contact_rise_k: Vec<f64>,
    /// The replay's own pose, untouched by the instruments: X, Y (m) and heading psi (rad) in
    /// the engine's ground frame (its start need not be the run's; [`super::increments`] compares
    /// increments only).
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub psi: Vec<f64>,
    /// False when the state went non-finite (the rest of the run is then held at the last value).
    pub ok: bool,
}

/// Floor on |vx| in slip denominators, m/s.
pub(super) const V_FLOOR: f64 = 1.0;
/// Largest integration step of the engine's replay, s: one step per sample at 100 Hz. The lateral
/// modes decay at 5-30 1/s, so lambda h <= 0.3 and the RK4 error per step is ~(lambda h)^5 / 120
/// < 2e-5 relative, far below sensor noise. The first-order lags (force relaxation, steering lag,
/// transient slip) are integrated exactly over the step
/// ([`vehsim_core::sim::integrator::rk4_lag_step`]), so however fast they are they do not shorten it.
pub(super) const H_MAX: f64 = 0.01;
/// Indices of the replay state (the module docs give each state's meaning and unit).
pub(super) mod ix {
    /// Lateral velocity vy, m/s.
    pub const VY: usize = 0;
    /// Yaw rate r, rad/s.
    pub const R: usize = 1;
    /// Relaxed front and rear axle lateral forces Fy_f, Fy_r, N.
    pub const FY_F: usize = 2;
    pub const FY_R: usize = 3;
    /// Lagged effective road-wheel angle delta_e, rad.
    pub const DELTA_E: usize = 4;
    /// Pose in the ground frame: X, Y (m), heading psi (rad).
    pub const X: usize = 5;
    pub const Y: usize = 6;
    pub const PSI: usize = 7;
    /// Lagged front and rear slip angles alpha_f, alpha_r (transient slip), rad.
    pub const ALPHA_F: usize = 8;
    pub const ALPHA_R: usize = 9;
    /// Tread-temperature rises front and rear, K.
    pub const DT_F: usize = 10;
    pub const DT_R: usize = 11;
    /// Prescribed forward speed vx (the measured one), m/s.
    pub const VX: usize = 12;
}

/// The first-order lag states: the relaxed axle forces Fy_f, Fy_r, the lagged steer delta_e and the
/// lagged slip angles alpha_f, alpha_r.
pub(super) const LAGS: [usize; NL] = [ix::FY_F, ix::FY_R, ix::DELTA_E, ix::ALPHA_F, ix::ALPHA_R, ix::DT_F, ix::DT_R];
/// Number of lag states (the tread-temperature rises front and rear are lags too: see
/// [`ReplayModel::body`]).
const NL: usize = 7;
/// State dimension: the 12 states of the module docs and the prescribed forward speed vx (m/s,
/// index 12; read by the replay on the engine, [`super::replay`]).
pub(super) const NS: usize = 13;
pub(super) type State = SVector<f64, NS>;

/// The replay model for one vehicle.
#[derive(Debug, Clone)]
pub struct ReplayModel {
    pub vehicle: Vehicle,
    fz_axle: [f64; 2],
    /// When set, the replay integrates every state, lags included, by plain RK4 with steps no
    /// longer than this (s) and no longer than a twentieth of any lag's time constant: the
    /// fine-step reference the exponential lag update is checked against.
    pub reference_step_s: Option<f64>,
}

/// The inputs of one evaluation of the replay's equations.
#[derive(Debug, Clone, Copy)]
pub(super) struct Drive {
    pub(super) steer: f64,
    pub(super) vx: f64,
    /// Surface friction with the friction_change factor applied.
    pub(super) mu: f64,
    /// Friction factor per axle from a ground patch (1 without one).
    pub(super) mu_axle: [f64; 2],
    /// Logged pose (X, Y, psi) when the run has the x, y and psi columns.
    pub(super) pose: Option<[f64; 3]>,
    /// Bulk ice temperature, degC.
    pub(super) ice_c: f64,
    /// Contact temperature per axle, degC.
    pub(super) contact_c: [f64; 2],
    /// Whether the run is on ice (the thermal effects act on ice only).
    pub(super) on_ice: bool,
    /// Tread-temperature rise per axle above the ice, K, capped at melting (0 unless the
    /// tread-temperature state is on).
    pub(super) tread_rise_k: [f64; 2],
    /// The run's road: bank and grade (flat unless its sidecar gives `[road]`).
    pub(super) road: Road,
    /// The forward acceleration the coupling takes (the logged `ax` or the speed's slope; a zero
    /// slope unless the coupling is on).
    pub(super) ax: super::coupling::Accel,
    /// What the speed change asks of the axles (the coupling on; set per state by
    /// [`ReplayModel::forces`]).
    pub(super) long: Option<super::coupling::Demand>,
}

/// Steady-state axle forces, effective steer and slip angles of one state.
pub(super) struct Forces {
    /// Steady-state axle forces (two tyres, wheel axes), front and rear.
    pub(super) axle: [TyreForces; 2],
    delta_e: f64,
    /// Slip angles the tyres carry (the lagged ones under transient slip), rad.
    alpha: [f64; 2],
    /// Kinematic slip angles (what the lagged ones relax towards), rad.
    alpha_kin: [f64; 2],
}

/// Floor on the ratio of the local to the initial tyre slope in the saturating transient-slip
/// form (the relaxation length never falls below this fraction of its nominal value).
pub const SLIP_SLOPE_FLOOR: f64 = lateral::SLIP_SLOPE_FLOOR;

impl ReplayModel {
    pub fn new(vehicle: Vehicle) -> Self {
        let (ff, fr) = vehicle.static_axle_loads_n();
        Self { vehicle, fz_axle: [ff, fr], reference_step_s: None }
    }

    /// Steady-state axle force (two tyres, wheel axes) at slip angle `alpha`, with load transfer
    /// `dfz` across the axle (N, added to the right tyre, taken from the left:
    /// [`lateral::axle_forces`]): free rolling (zero slip ratio), or under the longitudinal
    /// coupling (`d.long`) at the slip ratio that gives the axle's share of the speed change's
    /// force, on loads moved by its transfer.
    fn axle_force(&self, axle: usize, alpha: f64, dfz: f64, d: &Drive, p: &EffectParams) -> TyreForces {
        // The level road's static tyre load (the load sensitivities' reference) and the tyre's
        // load on the run's road.
        let half = 0.5 * self.fz_axle[axle];
        let mut on_road = self.tyre_load(axle, &d.road);
        if let Some(long) = &d.long {
            on_road = (on_road + long.dfz_n[axle]).max(0.0);
        }
        let mut thermal = if p.thermal_mu_per_k == 0.0 {
            1.0
        } else {
            lateral::thermal_friction_factor(p.thermal_mu_per_k, d.contact_c[axle] - d.ice_c)
        };
        let mut contact_c = d.contact_c[axle];
        if p.tread() {
            thermal *= lateral::thermal_friction_factor(p.tread_mu_per_k, d.tread_rise_k[axle]);
            contact_c = d.ice_c + d.tread_rise_k[axle];
        }
        let eval = |tyre: &dyn TyreModel, fz: f64, kappa: f64| {
            // The fitted load sensitivities at this tyre's relative load change (the engine's own
            // factors, lateral::load_sensitive_input).
            let input = TyreInput {
                fz_n: fz.max(0.0),
                kappa,
                alpha_rad: alpha * p.stiffness_scale[axle],
                camber_rad: 0.0,
                vx_mps: d.vx.abs().max(V_FLOOR),
                mu_surface: d.mu * thermal * p.mu_axle_scale[axle] * d.mu_axle[axle],
                surface_temp_c: d.ice_c,
                contact_temp_c: contact_c,
            };
            let input = lateral::load_sensitive_input(input, half, p.load_sensitivity);
            if input.fz_n <= 0.0 {
                TyreForces::default()
            } else {
                tyre.forces(&input)
            }
        };
        let tyre = &self.vehicle.tyre;
        let at_slip = |kappa: f64| {
            if dfz == 0.0 && tyre.same_on_both_sides() {
                let t = eval(&*tyre.mounted[0], on_road, kappa);
                TyreForces { fx_n: 2.0 * t.fx_n, fy_n: 2.0 * t.fy_n, mz_nm: 2.0 * t.mz_nm }
            } else {
                lateral::axle_forces(on_road, dfz, |side, fz| eval(&**tyre.on(side), fz, kappa))
            }
        };
        match &d.long {
            // The slip ratio at which the axle gives its share of the speed change's force.
            Some(long) => super::coupling::axle_slip(long.fx_n[axle], 2.0 * on_road, at_slip).1,
            None => at_slip(0.0),
        }
    }

    /// Static load of one tyre of `axle` on `road`, N: the level one on a flat road, else half the
    /// axle's normal load on the bank and grade at the vehicle's CG height (the engine's bicycle's
    /// own, [`Road::axle_loads_n`]).
    fn tyre_load(&self, axle: usize, road: &Road) -> f64 {
        if road.is_flat() {
            return 0.5 * self.fz_axle[axle];
        }
        let v = &self.vehicle;
        0.5 * road.axle_loads_n(v.mass_kg, v.a_m, v.b_m, v.cg_height_m)[axle]
    }

    fn load_transfer(&self, axle: usize, vx: f64, r: f64, p: &EffectParams) -> f64 {
        if p.load_transfer_height_m == 0.0 {
            return 0.0;
        }
        let v = &self.vehicle;
        let share = self.fz_axle[axle] / (self.fz_axle[0] + self.fz_axle[1]);
        lateral::load_transfer_n(v.mass_kg, vx, r, p.load_transfer_height_m, v.track_m, share)
    }

    /// Steady-state axle forces, the effective steer and the slip angles for a state.
    pub(super) fn forces(&self, x: &State, d: &Drive, p: &EffectParams) -> Forces {
        let v = &self.vehicle;
        let mut local;
        let tread = p.tread() && d.on_ice;
        let d = if p.on_ground() || tread || p.coupled() {
            local = *d;
            if p.coupled() {
                let state = (d.vx, x[ix::VY], x[ix::R]);
                let h = p.longitudinal_transfer_height_m;
                local.long = Some(super::coupling::demand(v, h, d.ax, state, d.steer, &d.road));
            }
            if p.on_ground() {
                // Each axle at its own ground position: the logged pose, else the replay's own.
                let [px, py, psi] = d.pose.unwrap_or([x[ix::X], x[ix::Y], x[ix::PSI]]);
                for (i, l) in [v.a_m, -v.b_m].into_iter().enumerate() {
                    let (xa, ya) = ground::axle_position(px, py, psi, l);
                    local.mu_axle[i] = p.patch_factor(xa, ya) * p.band_factor(xa);
                }
            }
            if tread {
                let cap = melt_cap_k(d.ice_c);
                local.tread_rise_k = [x[ix::DT_F].clamp(0.0, cap), x[ix::DT_R].clamp(0.0, cap)];
            }
            &local
        } else {
            d
        };
        let (vy, r) = (x[ix::VY], x[ix::R]);
        let vxs = d.vx.abs().max(V_FLOOR);
        let beta_f = ((vy + v.a_m * r) / vxs).atan();
        let alpha_r = -((vy - v.b_m * r) / vxs).atan();
        let dfz = [self.load_transfer(0, d.vx, r, p), self.load_transfer(1, d.vx, r, p)];
        let rear = self.axle_force(1, alpha_r, dfz[1], d, p);
        let steer = if p.steer_lag_s > 0.0 { x[ix::DELTA_E] } else { d.steer };
        let c = p.steer_compliance_rad_per_kn * 1e-3;
        if p.transient_slip() {
            // The forces follow the lagged slip angles; the compliance acts through them.
            let axle =
                [self.axle_force(0, x[ix::ALPHA_F], dfz[0], d, p), self.axle_force(1, x[ix::ALPHA_R], dfz[1], d, p)];
            let delta_e = lateral::effective_steer(steer, c, axle[0].fy_n);
            return Forces {
                axle,
                delta_e,
                alpha: [x[ix::ALPHA_F], x[ix::ALPHA_R]],
                alpha_kin: [delta_e - beta_f, alpha_r],
            };
        }
        let front_at = |delta: f64| self.axle_force(0, delta - beta_f, dfz[0], d, p);
        let (delta_e, front) = if c != 0.0 && p.sigma_y_m > 0.0 {
            // The acting front force is the relaxed state: no iteration needed.
            let delta_e = lateral::effective_steer(steer, c, x[ix::FY_F]);
            (delta_e, front_at(delta_e))
        } else {
            // The fixed point delta_e = delta - c Fy_f(delta_e) (delta_e = delta without compliance).
            lateral::compliant_steer(steer, c, front_at, |f| f.fy_n)
        };
        let alpha = [delta_e - beta_f, alpha_r];
        Forces { axle: [front, rear], delta_e, alpha, alpha_kin: alpha }
    }

    /// Transient-slip relaxation length of an axle at slip angle `alpha`, m: the nominal one, or
    /// in the saturating form the nominal one times the tyre's local slope dFy/dalpha over its
    /// slope at alpha = 0 (floored at [`SLIP_SLOPE_FLOOR`]), as a string model whose relaxation
    /// length is the cornering stiffness over the lateral carcass stiffness predicts.
    fn slip_sigma(&self, axle: usize, alpha: f64, dfz: f64, d: &Drive, p: &EffectParams) -> f64 {
        let s0 = p.slip_relaxation_m[axle];
        if !p.slip_relaxation_saturating {
            return s0;
        }
        const EPS: f64 = lateral::SLIP_SLOPE_STEP_RAD;
        let slope =
            |a: f64| self.axle_force(axle, a + EPS, dfz, d, p).fy_n - self.axle_force(axle, a - EPS, dfz, d, p).fy_n;
        lateral::saturating_relaxation_length(s0, slope(alpha) / slope(0.0))
    }

    /// Axle forces acting on the body: the steady-state ones, with the lateral forces replaced by
    /// the relaxed states when the tyre relaxation effect is on.
    fn acting(x: &State, f: &Forces, p: &EffectParams) -> [TyreForces; 2] {
        let mut a = f.axle;
        if p.sigma_y_m > 0.0 {
            a[0].fy_n = x[ix::FY_F];
            a[1].fy_n = x[ix::FY_R];
        }
        a
    }

    /// Lateral force (N) and yaw moment (N m) on the body of the acting axle forces `acting` at
    /// the effective steer of `f` ([`single_track::lateral_loads`]).
    fn lateral_loads(&self, f: &Forces, acting: &[TyreForces; 2]) -> (f64, f64) {
        let v = &self.vehicle;
        let (sin_d, cos_d) = f.delta_e.sin_cos();
        single_track::lateral_loads(&acting[0], &acting[1], cos_d, sin_d, v.a_m, v.b_m)
    }

    /// Derivatives of the body states (the lag states' entries left 0) and the inputs the lag
    /// states relax towards ([`LAGS`] order: steady-state forces, the steer, kinematic slip angles).
    pub(super) fn body(&self, x: &State, d: &Drive, p: &EffectParams) -> (State, [f64; NL]) {
        let v = &self.vehicle;
        let f = self.forces(x, d, p);
        let acting = Self::acting(x, &f, p);
        let [fyf, fyr] = acting.map(|a| a.fy_n);
        // The tread-temperature rise of axle i relaxes at 1 / tau_c towards P_i tau_c / C, with
        // P_i = v_slide,i |Fy_i| the frictional power of the axle (W): dT/dt = P_i / C - T / tau_c.
        let mut rise = [0.0; 2];
        if p.tread() && d.on_ice {
            let vx = d.vx.abs().max(V_FLOOR);
            for (i, fy) in [fyf, fyr].into_iter().enumerate() {
                let power_w = slide_speed(0.0, f.alpha[i], vx) * fy.abs();
                rise[i] = power_w * p.tread_cooling_s / p.tread_heat_capacity_j_per_k;
            }
        }
        let (fy, mz) = self.lateral_loads(&f, &acting);
        // The road's lateral gravity acts on the body at the CG, not on the accelerometer
        // (which logs fy / m: see [`Self::ay`]).
        let fy = if d.road.is_flat() { fy } else { fy + v.mass_kg * d.road.gravity_in_plane().1 };
        let mut dx = State::zeros();
        (dx[ix::VY], dx[ix::R]) = single_track::lateral_rates(v.mass_kg, v.yaw_inertia_kgm2, d.vx, x[ix::R], fy, mz);
        let (sp, cp) = x[ix::PSI].sin_cos();
        dx[ix::X] = d.vx * cp - x[ix::VY] * sp;
        dx[ix::Y] = d.vx * sp + x[ix::VY] * cp;
        dx[ix::PSI] = x[ix::R];
        (dx, [f.axle[0].fy_n, f.axle[1].fy_n, d.steer, f.alpha_kin[0], f.alpha_kin[1], rise[0], rise[1]])
    }

    /// Rates k (1/s) of the lag states ([`LAGS`] order; 0 = the state is unused) at state `x`:
    /// |vx| / sigma_y, 1 / tau_s and |vx| / sigma_i (the saturating form's sigma_i at x's lagged
    /// slip angle).
    pub(super) fn lag_rates(&self, x: &State, d: &Drive, p: &EffectParams) -> [f64; NL] {
        let mut k = [0.0; NL];
        if p.sigma_y_m > 0.0 {
            k[0] = lateral::relaxation_rate(d.vx, p.sigma_y_m);
            k[1] = k[0];
        }
        if p.steer_lag_s > 0.0 {
            k[2] = 1.0 / p.steer_lag_s;
        }
        if p.transient_slip() {
            let dfz = [self.load_transfer(0, d.vx, x[ix::R], p), self.load_transfer(1, d.vx, x[ix::R], p)];
            for i in 0..2 {
                let sigma = self.slip_sigma(i, x[8 + i], dfz[i], d, p);
                k[3 + i] = lateral::relaxation_rate(d.vx, sigma);
            }
        }
        if p.tread() && d.on_ice {
            k[5] = 1.0 / p.tread_cooling_s;
            k[6] = k[5];
        }
        k
    }

    /// The derivatives of the lateral states [vy (m/s), r (rad/s), Fy_f, Fy_r (N, the relaxed
    /// axle forces), delta_e (rad, the lagged steer)] at those states `lateral`, under the steer
    /// `steer_rad` (rad), the forward speed `vx_mps` (m/s), the surface friction `mu` (before the
    /// effects' scale) and the road `road` (bank and grade), with `(ice_c, contact_c)` the ice and the axles' contact temperatures (degC): the
    /// equations the replay integrates, at one instant, lags included (their entries are 0 when
    /// the effect that uses them is off). Under transient slip the third and fourth entries are
    /// the lagged slip angles alpha_f, alpha_r (rad) and their rates instead, as in the engine's
    /// bicycle. For checks against the engine's bicycle model.
    pub fn lateral_derivatives(
        &self,
        p: &EffectParams,
        lateral: [f64; 5],
        steer_rad: f64,
        vx_mps: f64,
        (mu, road): (f64, Road),
        (ice_c, contact_c): (f64, [f64; 2]),
    ) -> [f64; 5] {
        let d = Drive {
            steer: steer_rad,
            vx: vx_mps,
            mu: mu * p.mu_factor(0.0),
            mu_axle: [1.0; 2],
            pose: None,
            ice_c,
            contact_c,
            on_ice: true,
            tread_rise_k: [0.0; 2],
            road,
            ax: super::coupling::Accel::Slope(0.0),
            long: None,
        };
        let mut x = State::zeros();
        x.as_mut_slice()[..5].copy_from_slice(&lateral);
        if p.transient_slip() {
            // The engine's bicycle keeps the lagged slip angles in its relaxed-force slots.
            (x[ix::ALPHA_F], x[ix::ALPHA_R]) = (lateral[2], lateral[3]);
        }
        let dx = self.derivatives(&x, &d, p);
        let mut out: [f64; 5] = std::array::from_fn(|i| dx[i]);
        if p.transient_slip() {
            (out[2], out[3]) = (dx[ix::ALPHA_F], dx[ix::ALPHA_R]);
        }
        out
    }

    /// All derivatives, lags included (the plain-RK4 reference).
    pub(super) fn derivatives(&self, x: &State, d: &Drive, p: &EffectParams) -> State {
        let (mut dx, target) = self.body(x, d, p);
        for ((i, k), u) in LAGS.into_iter().zip(self.lag_rates(x, d, p)).zip(target) {
            if k > 0.0 {
                dx[i] = k * (u - x[i]);
            }
        }
        dx
    }

    /// Lateral acceleration (body frame, at the CG, m/s^2) and front slip angle (rad) of a state.
    pub(super) fn ay(&self, x: &State, d: &Drive, p: &EffectParams) -> (f64, f64) {
        let f = self.forces(x, d, p);
        let (fy, _) = self.lateral_loads(&f, &Self::acting(x, &f, p));
        (fy / self.vehicle.mass_kg, f.alpha[0])
    }

    /// Operating conditions of one tyre per axle, for the contact-temperature estimator.
    pub(super) fn contacts(&self, x: &State, d: &Drive, p: &EffectParams) -> [TyreContact; 2] {
        let f = self.forces(x, d, p);
        let fy = Self::acting(x, &f, p).map(|a| a.fy_n);
        let vx = d.vx.abs().max(V_FLOOR);
        std::array::from_fn(|i| TyreContact {
            fz_n: self.tyre_load(i, &d.road),
            roll_speed_mps: vx,
            slide_speed_mps: slide_speed(0.0, f.alpha[i], vx),
            friction_force_n: 0.5 * fy[i].abs(),
            surface_temp_c: d.ice_c,
        })
    }

    /// The contact-temperature estimator of a run when thermal_friction is on (on ice only).
    pub(super) fn estimator(run: &MeasuredRun, p: &EffectParams) -> Option<AtiimEstimator> {
        if p.thermal_mu_per_k == 0.0 || !run.on_ice {
            return None;
        }
        // The default [contact] table (the SRTT P225/60R16 interface); built once per process
        // and ice temperature. A build failure (it cannot fail for a validated ice temperature)
        // leaves the run isothermal.
        ContactSpec::default().build_atiim(Path::new("thermal_friction"), 2, run.ice_temp_c).ok()
    }

    /// The state at a run's first sample under its inputs `d0` there: vy from the optional
    /// channel (else 0), the measured yaw rate less its sensor bias, the steer lag at the steer,
    /// relaxed forces and lagged slip angles at their steady values, the pose at the origin and
    /// the measured forward speed.
    pub(super) fn initial_state(&self, run: &MeasuredRun, p: &EffectParams, d0: &Drive) -> State {
        let mut x = State::zeros();
        x[ix::VY] = run.channel("vy").map_or(0.0, |v| v[0]);
        x[ix::R] = (run.yaw_rate[0] - p.bias_yaw_rate_radps) / p.sensor_scale[0];
        x[ix::DELTA_E] = d0.steer;
        x[ix::VX] = d0.vx;
        if p.sigma_y_m > 0.0 {
            let f = self.forces(&x, d0, p);
            x[ix::FY_F] = f.axle[0].fy_n;
            x[ix::FY_R] = f.axle[1].fy_n;
        }
        if p.transient_slip() {
            // Start relaxed: the lagged slip angles at their kinematic values (a fixed point,
            // since the compliance acts through the lagged force).
            for _ in 0..8 {
                let f = self.forces(&x, d0, p);
                x[ix::ALPHA_F] = f.alpha_kin[0];
                x[ix::ALPHA_R] = f.alpha_kin[1];
            }
        }
        x
    }

    /// Replay a measured run on the engine ([`super::replay`]): steer and vx interpolated
    /// linearly between samples and read at every integration stage's time, starting from the
    /// first sample's measured yaw rate and lateral velocity (vy from the optional channel, else
    /// 0). A run sampled uniformly (every run `vehsim synth` and the Stanford conversion write)
    /// is integrated with the samples on step boundaries; any other on a uniform grid of steps
    /// across it, the simulated channels interpolated to its samples.
    pub fn simulate(&self, run: &MeasuredRun, p: &EffectParams) -> Simulated {
        let (m, p) = self.for_params(p);
        super::replay::replay(m.as_ref().unwrap_or(self), run, &p.with_regions(&run.regions), None).0
    }

    /// The model of the vehicle with the factors of `p.body_scale` applied to its parameters
    /// ([`super::vehicle_params::scaled_vehicle`]; None when all are 1: this model), and `p`
    /// with those factors reset to 1.
    fn for_params(&self, p: &EffectParams) -> (Option<ReplayModel>, EffectParams) {
        let scaled = super::vehicle_params::scaled_vehicle(&self.vehicle, &p.body_scale)
            .map(|v| ReplayModel { reference_step_s: self.reference_step_s, ..ReplayModel::new(v) });
        (scaled, EffectParams { body_scale: [1.0; super::vehicle_params::N], ..*p })
    }

    /// Drive a run closed loop on the engine ([`super::replay`]): `driver` follows `path` from
    /// the origin heading along +X, at the run's measured speed profile. The driver samples
    /// every sample interval (a run sampled uniformly, as every run `vehsim synth` drives) or
    /// every step (uneven sampling), seeing the state predicted one control period ahead; the
    /// engine's continuous rate limiter and the vehicle's steering lock set the steer, ramped
    /// across the period, so on a uniform run the recorded steer replays exactly as the
    /// measured-run replay interpolates it. Returns the steer samples and the simulated channels.
    pub fn simulate_closed_loop(
        &self,
        run: &MeasuredRun,
        p: &EffectParams,
        path: &RefPath,
        driver: &mut Driver,
    ) -> (Vec<f64>, Simulated) {
        let (m, p) = self.for_params(p);
        let model = m.as_ref().unwrap_or(self);
        let (sim, steer) = super::replay::replay(model, run, &p.with_regions(&run.regions), Some((path, driver)));
        (steer, sim)
    }
}
