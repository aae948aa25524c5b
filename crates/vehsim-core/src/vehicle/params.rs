//! The validated vehicle: the parameters the vehicle models read, with their units.
//!
//! Geometry follows ISO 8855: x forward, y left, z up; `a` and `b` are the horizontal distances from
//! the centre of gravity to the front and rear axle. The spec layer builds a [`Vehicle`] from a
//! vehicle file; nothing here reads files.

use crate::tyre::Tyre;

/// Which axle(s) the engine drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum DriveLayout {
    /// Front-wheel drive: all drive torque to the front axle.
    Front,
    /// Rear-wheel drive: all drive torque to the rear axle.
    Rear,
    /// All-wheel drive: split by [`Vehicle::front_drive_share`].
    All,
}

/// The allowed ranges of the `[lateral]` keys, each declared once (README's vehicle section lists
/// the same; `tests/spec_bounds.rs` holds the two together).
pub mod lateral_bounds {
    use crate::error::Bound;

    /// `lateral.steer_compliance_rad_per_kn`: [0, 0.1] rad/kN.
    pub const STEER_COMPLIANCE: Bound = Bound::closed("lateral.steer_compliance_rad_per_kn", 0.0, 0.1, "rad/kN");
    /// `lateral.mu_scale`: [0.05, 3], dimensionless.
    pub const MU_SCALE: Bound = Bound::closed("lateral.mu_scale", 0.05, 3.0, "");
    /// `lateral.steer_lag_s`: [0, 2] s.
    pub const STEER_LAG: Bound = Bound::closed("lateral.steer_lag_s", 0.0, 2.0, "s");
    /// `lateral.relaxation_length_y_m`: [0, 10] m.
    pub const RELAXATION_LENGTH: Bound = Bound::closed("lateral.relaxation_length_y_m", 0.0, 10.0, "m");
    /// `lateral.load_transfer_height_m`: [0, 2] m.
    pub const LOAD_TRANSFER_HEIGHT: Bound = Bound::closed("lateral.load_transfer_height_m", 0.0, 2.0, "m");
    /// `lateral.thermal_mu_per_k`: [-2, 0] 1/K (friction may only fall as the contact warms).
    pub const THERMAL_MU: Bound = Bound::closed("lateral.thermal_mu_per_k", -2.0, 0.0, "1/K");
    /// `lateral.stiffness_scale_front`: [0.2, 5], dimensionless (the front tyres see c_f alpha).
    pub const STIFFNESS_SCALE_FRONT: Bound = Bound::closed("lateral.stiffness_scale_front", 0.2, 5.0, "");
    /// `lateral.stiffness_scale_rear`: [0.2, 5], dimensionless.
    pub const STIFFNESS_SCALE_REAR: Bound = Bound::closed("lateral.stiffness_scale_rear", 0.2, 5.0, "");
    /// `lateral.mu_scale_front`: [0.05, 3], dimensionless (the front tyres' friction factor).
    pub const MU_SCALE_FRONT: Bound = Bound::closed("lateral.mu_scale_front", 0.05, 3.0, "");
    /// `lateral.mu_scale_rear`: [0.05, 3], dimensionless.
    pub const MU_SCALE_REAR: Bound = Bound::closed("lateral.mu_scale_rear", 0.05, 3.0, "");
    /// `lateral.load_sensitivity_mu`: [-1, 1] per unit of relative load change.
    pub const LOAD_SENSITIVITY_MU: Bound = Bound::closed("lateral.load_sensitivity_mu", -1.0, 1.0, "");
    /// `lateral.load_sensitivity_stiffness`: [-1, 1] per unit of relative load change.
    pub const LOAD_SENSITIVITY_STIFFNESS: Bound = Bound::closed("lateral.load_sensitivity_stiffness", -1.0, 1.0, "");
    /// `lateral.relaxation_length_front_m`: [0, 10] m (transient slip of the front axle; 0 = off).
    pub const RELAXATION_FRONT: Bound = Bound::closed("lateral.relaxation_length_front_m", 0.0, 10.0, "m");
    /// `lateral.relaxation_length_rear_m`: [0, 10] m (transient slip of the rear axle; 0 = off).
    pub const RELAXATION_REAR: Bound = Bound::closed("lateral.relaxation_length_rear_m", 0.0, 10.0, "m");
    /// `lateral.tread_mu_per_kj`: [-20, 0] 1/kJ (friction change per kJ of tread heat; 0 = off).
    pub const TREAD_MU_PER_KJ: Bound = Bound::closed("lateral.tread_mu_per_kj", -20.0, 0.0, "1/kJ");
    /// `lateral.tread_heat_capacity_j_per_k`: [10, 1e5] J/K (one axle's tread layer).
    pub const TREAD_HEAT_CAPACITY: Bound = Bound::closed("lateral.tread_heat_capacity_j_per_k", 10.0, 1e5, "J/K");
    /// `lateral.tread_cooling_time_s`: [0.1, 100] s.
    pub const TREAD_COOLING_TIME: Bound = Bound::closed("lateral.tread_cooling_time_s", 0.1, 100.0, "s");
    /// `lateral.longitudinal_transfer_height_m`: [0, 2] m (the height at which the tyres'
    /// longitudinal forces pitch load between the axles: a car's CG height, 0.45-0.65 m for
    /// passenger cars and up to about 1 m for vans and light trucks; 0 = static loads).
    pub const LONGITUDINAL_TRANSFER_HEIGHT: Bound =
        Bound::closed("lateral.longitudinal_transfer_height_m", 0.0, 2.0, "m");

    /// Every bound above, in the order of [`super::Lateral::values`].
    pub const ALL: [Bound; 18] = [
        STEER_COMPLIANCE,
        MU_SCALE,
        STEER_LAG,
        RELAXATION_LENGTH,
        LOAD_TRANSFER_HEIGHT,
        THERMAL_MU,
        STIFFNESS_SCALE_FRONT,
        STIFFNESS_SCALE_REAR,
        MU_SCALE_FRONT,
        MU_SCALE_REAR,
        LOAD_SENSITIVITY_MU,
        LOAD_SENSITIVITY_STIFFNESS,
        RELAXATION_FRONT,
        RELAXATION_REAR,
        TREAD_MU_PER_KJ,
        TREAD_HEAT_CAPACITY,
        TREAD_COOLING_TIME,
        LONGITUDINAL_TRANSFER_HEIGHT,
    ];
}

/// Validated lateral extensions (the spec layer reads them from a vehicle file's `[lateral]` section); the default changes nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lateral {
    /// rad per kN of front axle lateral force.
    pub steer_compliance_rad_per_kn: f64,
    /// Friction scale.
    pub mu_scale: f64,
    /// Steering lag, s.
    pub steer_lag_s: f64,
    /// Lateral relaxation length, m.
    pub relaxation_length_y_m: f64,
    /// Lateral load-transfer height, m.
    pub load_transfer_height_m: f64,
    /// Friction change per kelvin of contact-temperature rise, 1/K.
    pub thermal_mu_per_k: f64,
    /// Cornering-stiffness factor per axle (front, rear): the axle's tyres see factor x alpha.
    pub stiffness_scale: [f64; 2],
    /// Peak-friction factor per axle (front, rear): the axle's tyres see factor x mu.
    pub mu_axle_scale: [f64; 2],
    /// Load sensitivity of each tyre's friction and cornering stiffness under load transfer,
    /// [k_mu, k_c], per unit of relative load change Fz / Fz0 - 1 ([`super::lateral::load_factor`]).
    pub load_sensitivity: [f64; 2],
    /// Transient-slip relaxation length per axle (front, rear), m (0 = off).
    pub slip_relaxation_m: [f64; 2],
    /// Whether the transient-slip relaxation length shortens with the tyre's local slope.
    pub slip_relaxation_saturating: bool,
    /// Tread state: friction change per kJ of heat stored in one axle's tread, 1/kJ (0 = off).
    pub tread_mu_per_kj: f64,
    /// Tread state: heat capacity of one axle's tread layer, J/K.
    pub tread_heat_capacity_j_per_k: f64,
    /// Tread state: cooling time constant towards the surface temperature, s.
    pub tread_cooling_time_s: f64,
    /// Height at which the tyres' longitudinal forces move load between the axles, m (0 = static
    /// loads): the front axle's load falls by h S / L, S the tyres' force along the body's x axis
    /// (positive driving), L the wheelbase ([`super::lateral::longitudinal_transfer_n`]).
    pub longitudinal_transfer_height_m: f64,
}

impl Lateral {
    /// The values in the order of [`lateral_bounds::ALL`].
    pub fn values(&self) -> [f64; 18] {
        [
            self.steer_compliance_rad_per_kn,
            self.mu_scale,
            self.steer_lag_s,
            self.relaxation_length_y_m,
            self.load_transfer_height_m,
            self.thermal_mu_per_k,
            self.stiffness_scale[0],
            self.stiffness_scale[1],
            self.mu_axle_scale[0],
            self.mu_axle_scale[1],
            self.load_sensitivity[0],
            self.load_sensitivity[1],
            self.slip_relaxation_m[0],
            self.slip_relaxation_m[1],
            self.tread_mu_per_kj,
            self.tread_heat_capacity_j_per_k,
            self.tread_cooling_time_s,
            self.longitudinal_transfer_height_m,
        ]
    }

    /// The key (e.g. `lateral.steer_lag_s`) of the first extension switched on, if any.
    pub fn first_active_key(&self) -> Option<&'static str> {
        let off = Lateral::default().values();
        lateral_bounds::ALL.iter().zip(self.values().iter().zip(off)).find(|(_, (v, d))| **v != *d).map(|(b, _)| b.key)
    }

    /// True when transient slip is on (either axle's relaxation length above 0).
    pub fn transient_slip(&self) -> bool {
        self.slip_relaxation_m[0] > 0.0 || self.slip_relaxation_m[1] > 0.0
    }

    /// Friction change per kelvin of tread-temperature rise, 1/K: q C / 1000 (q per kJ, C in J/K).
    pub fn tread_mu_per_k(&self) -> f64 {
        self.tread_mu_per_kj * self.tread_heat_capacity_j_per_k * 1e-3
    }
}

impl Default for Lateral {
    fn default() -> Self {
        Lateral {
            steer_compliance_rad_per_kn: 0.0,
            mu_scale: 1.0,
            steer_lag_s: 0.0,
            relaxation_length_y_m: 0.0,
            load_transfer_height_m: 0.0,
            thermal_mu_per_k: 0.0,
            stiffness_scale: [1.0; 2],
            mu_axle_scale: [1.0; 2],
            load_sensitivity: [0.0; 2],
            slip_relaxation_m: [0.0; 2],
            slip_relaxation_saturating: false,
            tread_mu_per_kj: 0.0,
            tread_heat_capacity_j_per_k: 300.0,
            tread_cooling_time_s: 3.0,
            longitudinal_transfer_height_m: 0.0,
        }
    }
}

/// The allowed ranges of the `[sensors]` keys, each declared once (`vehsim discover` fits the
/// measurement-chain effects within the same ranges).
pub mod sensor_bounds {
    use crate::error::Bound;

    /// `sensors.latency_yaw_rate_s`: [0, 0.5] s (a logger's buffering, a filter's group delay).
    pub const LATENCY_YAW_RATE: Bound = Bound::closed("sensors.latency_yaw_rate_s", 0.0, 0.5, "s");
    /// `sensors.latency_ay_s`: [0, 0.5] s.
    pub const LATENCY_AY: Bound = Bound::closed("sensors.latency_ay_s", 0.0, 0.5, "s");
    /// `sensors.bias_yaw_rate_radps`: [-0.5, 0.5] rad/s.
    pub const BIAS_YAW_RATE: Bound = Bound::closed("sensors.bias_yaw_rate_radps", -0.5, 0.5, "rad/s");
    /// `sensors.bias_ay_mps2`: [-5, 5] m/s^2.
    pub const BIAS_AY: Bound = Bound::closed("sensors.bias_ay_mps2", -5.0, 5.0, "m/s^2");
    /// `sensors.accel_x_m`: [-3, 3] m ahead of the CG (within a car's half length).
    pub const ACCEL_X: Bound = Bound::closed("sensors.accel_x_m", -3.0, 3.0, "m");
    /// `sensors.accel_y_m`: [-1.5, 1.5] m left of the CG (within a car's half width).
    pub const ACCEL_Y: Bound = Bound::closed("sensors.accel_y_m", -1.5, 1.5, "m");
    /// `sensors.scale_yaw_rate`: [0.5, 2], dimensionless (a gyro's scale-factor error: a few % by
    /// datasheet, up to a factor 2 for a wrong sensitivity range or unit setting).
    pub const SCALE_YAW_RATE: Bound = Bound::closed("sensors.scale_yaw_rate", 0.5, 2.0, "");
    /// `sensors.scale_ay`: [0.5, 2], dimensionless (as the gyro's).
    pub const SCALE_AY: Bound = Bound::closed("sensors.scale_ay", 0.5, 2.0, "");
    /// `sensors.clock_skew_ppm`: [-20000, 20000] ppm: the inertial unit's clock (yaw rate and
    /// lateral acceleration) runs fast by this much against the logger's (steer and speed); a
    /// crystal keeps within 100 ppm, a microcontroller's uncalibrated RC oscillator within 1-2 %.
    pub const CLOCK_SKEW: Bound = Bound::closed("sensors.clock_skew_ppm", -20_000.0, 20_000.0, "ppm");
    /// `sensors.accel_yaw_misalignment_rad`: [-0.35, 0.35] rad (20 degrees: a logger placed by eye);
    /// the accelerometer's y axis turned this much towards +x.
    pub const ACCEL_YAW: Bound = Bound::closed("sensors.accel_yaw_misalignment_rad", -0.35, 0.35, "rad");

    /// Every bound above, in the order of [`super::Sensors::values`].
    pub const ALL: [Bound; 10] = [
        LATENCY_YAW_RATE,
        LATENCY_AY,
        BIAS_YAW_RATE,
        BIAS_AY,
        ACCEL_X,
        ACCEL_Y,
        SCALE_YAW_RATE,
        SCALE_AY,
        CLOCK_SKEW,
        ACCEL_YAW,
    ];
}

/// The validation ranges of the body keys that the lateral models read (mass, yaw inertia, CG
/// position, track, CG height), each declared once: the spec layer checks a vehicle file against
/// them, and `vehsim discover` generates its vehicle-parameter candidates from the same
/// declarations. Upper ends: beyond any road vehicle (a 40 t lorry, a bus) by a wide margin; they
/// keep a mistyped unit or exponent from reaching the engine.
pub mod body_bounds {
    use crate::error::Bound;

    /// `mass_kg`: (0, 100000] kg.
    pub const MASS: Bound = Bound::left_open("mass_kg", 0.0, 100_000.0, "kg");
    /// `yaw_inertia_kgm2`: (0, 1e6] kg m^2.
    pub const YAW_INERTIA: Bound = Bound::left_open("yaw_inertia_kgm2", 0.0, 1e6, "kg m^2");
    /// `cg_to_front_axle_m`: (0, 10] m.
    pub const CG_TO_FRONT: Bound = Bound::left_open("cg_to_front_axle_m", 0.0, 10.0, "m");
    /// `cg_to_rear_axle_m`: (0, 10] m.
    pub const CG_TO_REAR: Bound = Bound::left_open("cg_to_rear_axle_m", 0.0, 10.0, "m");
    /// `track_m`: (0, 5] m.
    pub const TRACK: Bound = Bound::left_open("track_m", 0.0, 5.0, "m");
    /// `cg_height_m`: [0, 5] m.
    pub const CG_HEIGHT: Bound = Bound::closed("cg_height_m", 0.0, 5.0, "m");
}

/// The instruments on the car (the spec layer reads them from a vehicle file's `[sensors]`
/// section): what turns the simulated yaw rate and lateral acceleration at the CG into the logged
/// channels. They change only what is logged, never the motion; the default logs the true values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensors {
    /// Latency of the logged yaw rate and lateral acceleration, s.
    pub latency_s: [f64; 2],
    /// Constant offsets of the yaw rate (rad/s) and the lateral acceleration (m/s^2).
    pub bias: [f64; 2],
    /// Accelerometer position: x ahead of the CG, y to its left, m.
    pub accel_position_m: [f64; 2],
    /// Scale factors of the logged yaw rate and lateral acceleration, dimensionless (1 = true).
    pub scale: [f64; 2],
    /// The inertial unit's clock runs fast against the logger's by this much, ppm (0 = none).
    pub clock_skew_ppm: f64,
    /// The accelerometer's y axis turned towards +x by this angle, rad (0 = aligned).
    pub accel_yaw_misalignment_rad: f64,
}

impl Default for Sensors {
    /// True, prompt instruments at the CG.
    fn default() -> Self {
        Sensors {
            latency_s: [0.0; 2],
            bias: [0.0; 2],
            accel_position_m: [0.0; 2],
            scale: [1.0; 2],
            clock_skew_ppm: 0.0,
            accel_yaw_misalignment_rad: 0.0,
        }
    }
}

impl Sensors {
    /// The values in the order of [`sensor_bounds::ALL`].
    pub fn values(&self) -> [f64; 10] {
        let s = self;
        [
            s.latency_s[0],
            s.latency_s[1],
            s.bias[0],
            s.bias[1],
            s.accel_position_m[0],
            s.accel_position_m[1],
            s.scale[0],
            s.scale[1],
            s.clock_skew_ppm,
            s.accel_yaw_misalignment_rad,
        ]
    }
}

/// Validated roll data, with the derived sprung-mass geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Roll {
    /// Roll-centre heights (front, rear), m.
    pub rc_height_m: [f64; 2],
    /// Roll stiffness (front, rear), N m/rad.
    pub stiffness_nm_per_rad: [f64; 2],
    /// Roll damping (front, rear), N m s/rad.
    pub damping_nms_per_rad: [f64; 2],
    /// Unsprung mass per axle (front, rear), kg.
    pub unsprung_mass_kg: [f64; 2],
    /// Unsprung CG height, m.
    pub unsprung_cg_height_m: f64,
    /// Sprung-mass roll inertia about its own CG, kg m^2.
    pub roll_inertia_kgm2: f64,
    /// Fraction of ideal Ackermann, [0, 1].
    pub ackermann: f64,
    /// Load-transfer acceleration lag, s.
    pub load_transfer_lag_s: f64,
    /// Sprung mass m_s, kg.
    pub sprung_mass_kg: f64,
    /// Sprung-mass CG height above ground h_s, m.
    pub sprung_cg_height_m: f64,
    /// Sprung-mass CG ahead of the whole vehicle's CG, m (x_s; usually a few cm either way).
    pub sprung_cg_ahead_m: f64,
    /// Roll-axis height under the sprung CG, m.
    pub roll_axis_height_m: f64,
    /// h' = h_s - roll-axis height: sprung CG above the roll axis, m (>= 0).
    pub h_prime_m: f64,
}

impl Roll {
    /// Sprung-mass CG to the front and rear axle (a_s, b_s), m, for a vehicle with CG-to-axle
    /// distances a, b.
    pub fn sprung_axle_distances(&self, a: f64, b: f64) -> (f64, f64) {
        (a - self.sprung_cg_ahead_m, b + self.sprung_cg_ahead_m)
    }

    /// Total roll stiffness K_phi, N m/rad.
    pub fn total_stiffness(&self) -> f64 {
        self.stiffness_nm_per_rad[0] + self.stiffness_nm_per_rad[1]
    }
}

/// Air density used for drag, kg/m^3 (ISA sea level at 15 degC; cold air on ice is ~5 % denser).
pub const AIR_DENSITY: f64 = 1.225;
/// Standard gravity, m/s^2.
pub const GRAVITY: f64 = 9.80665;

/// A validated vehicle with its tyre built for one provider.
#[derive(Debug, Clone)]
pub struct Vehicle {
    /// Name from the vehicle file.
    pub name: String,
    /// Total mass, kg (> 0).
    pub mass_kg: f64,
    /// Yaw moment of inertia about the z axis through the CG, kg m^2 (> 0).
    pub yaw_inertia_kgm2: f64,
    /// CG to front axle a, m.
    pub a_m: f64,
    /// CG to rear axle b, m.
    pub b_m: f64,
    /// Track width (average of front and rear), m (> 0).
    pub track_m: f64,
    /// CG height above ground, m.
    pub cg_height_m: f64,
    /// Body width without mirrors, m; sets the ISO 3888-2 lane widths.
    pub body_width_m: f64,
    /// Body length, bumper to bumper, m.
    pub body_length_m: f64,
    /// Front overhang: front axle to front bumper, m.
    pub front_overhang_m: f64,
    /// Spin inertia of one wheel with tyre, brake and its share of the driveline, kg m^2.
    pub wheel_inertia_kgm2: f64,
    /// Driven axle(s).
    pub drive: DriveLayout,
    /// Front share of drive torque for [`DriveLayout::All`], in [0, 1] (ignored otherwise).
    pub front_drive_share: f64,
    /// Largest total drive torque at the wheels, N m (>= 0).
    pub drive_torque_max_nm: f64,
    /// Largest total brake torque at the wheels, N m (> 0).
    pub brake_torque_max_nm: f64,
    /// Front share of brake torque, in [0, 1].
    pub brake_front_share: f64,
    /// Largest road-wheel steer angle, rad (magnitude; steer is positive to the left).
    pub steer_max_rad: f64,
    /// Largest road-wheel steer rate, rad/s (magnitude).
    pub steer_rate_max_radps: f64,
    /// Aerodynamic drag area C_d A, m^2 (0: no drag); see [`AIR_DENSITY`].
    pub drag_area_m2: f64,
    /// Rolling-resistance coefficient, dimensionless (0: none); torque = coefficient x load x radius.
    pub rolling_resistance: f64,
    /// Roll data for the 4-DOF model (`None` when the file has no `[roll]` section).
    pub roll: Option<Roll>,
    /// Lateral extensions of the bicycle model (default: none).
    pub lateral: Lateral,
    /// The instruments (`None` when the file has no `[sensors]` section: nothing measured is
    /// logged).
    pub sensors: Option<Sensors>,
    /// The ranges the tyre file declares as measured (plausibility, [`crate::sim::range_check`]).
    pub tyre_ranges: crate::tyre::ranges::TyreRanges,
    /// The powertrain (`None`: the single torque limit, the models' unchanged path).
    pub powertrain: Option<crate::vehicle::powertrain::Powertrain>,
    /// The tyre on all four corners: geometry and the built force provider.
    pub tyre: Tyre,
    /// Warnings from reading the tyre data (e.g. `.tir` sections ignored), for the CLI to print.
    pub tyre_warnings: Vec<String>,
}

impl Vehicle {
    /// Wheelbase a + b, m.
    pub fn wheelbase_m(&self) -> f64 {
        self.a_m + self.b_m
    }

    /// Rear overhang: rear axle to rear bumper, m.
    pub fn rear_overhang_m(&self) -> f64 {
        self.body_length_m - self.front_overhang_m - self.wheelbase_m()
    }

    /// Aerodynamic drag at body-frame forward speed `vx_mps` (m/s), N: ½ ρ C_d A vx |vx|, acting
    /// against the motion (positive when moving forward).
    #[inline]
    pub fn drag_n(&self, vx_mps: f64) -> f64 {
        0.5 * AIR_DENSITY * self.drag_area_m2 * vx_mps * vx_mps.abs()
    }

    /// Static axle loads (front, rear), N.
    pub fn static_axle_loads_n(&self) -> (f64, f64) {
        let w = self.mass_kg * GRAVITY;
        let l = self.wheelbase_m();
        (w * self.b_m / l, w * self.a_m / l)
    }

    /// Front share of drive torque for this layout.
    pub fn drive_front_share(&self) -> f64 {
        match self.drive {
            DriveLayout::Front => 1.0,
            DriveLayout::Rear => 0.0,
            DriveLayout::All => self.front_drive_share,
        }
    }
}
