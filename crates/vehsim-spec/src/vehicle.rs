//! Vehicle spec (`vehicles/*.toml`) and the validated [`Vehicle`].
//!
//! Geometry follows ISO 8855: x forward, y left, z up; `a` and `b` are the horizontal distances from
//! the centre of gravity to the front and rear axle.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::files::{parse_toml, read_input, resolve};

use crate::tyre::TyreFileSpec;
use vehsim_core::error::{Checker, Error, Result};
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::params::{
    lateral_bounds, sensor_bounds, DriveLayout, Lateral, Roll, Sensors, Vehicle, GRAVITY,
};
use vehsim_core::vehicle::powertrain::{Differential, GearMode, Powertrain, TorqueSource};

/// Raw vehicle file as written by the user. Every field: unit in the name, typical range in the docs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleFile {
    /// Human-readable name.
    pub name: String,
    /// Tyre spec file, relative to this file (all four tyres are the same).
    pub tyre: String,
    /// Total mass, kg (passenger cars 800–3000).
    pub mass_kg: f64,
    /// Yaw moment of inertia about the vertical axis through the CG, kg m^2 (1000–6000).
    pub yaw_inertia_kgm2: f64,
    /// CG to front axle, m (0.8–2.0).
    pub cg_to_front_axle_m: f64,
    /// CG to rear axle, m (0.8–2.0).
    pub cg_to_rear_axle_m: f64,
    /// Track width (average of front and rear), m (1.2–1.8).
    pub track_m: f64,
    /// CG height above ground, m (0.3–1.2).
    pub cg_height_m: f64,
    /// Body width (without mirrors), m (1.4–2.2); sets the ISO 3888-2 lane widths.
    pub body_width_m: f64,
    /// Body length, m (3.0–6.0).
    pub body_length_m: f64,
    /// Front overhang: front axle to front bumper, m (0.6–1.2).
    pub front_overhang_m: f64,
    /// Spin inertia of one wheel with tyre, brake and its share of the driveline, kg m^2 (0.8–3).
    pub wheel_inertia_kgm2: f64,
    /// Driven axle(s).
    pub drive: DriveLayout,
    /// Front share of drive torque for `drive = "all"`, in [0, 1] (ignored otherwise).
    #[serde(default = "half")]
    pub front_drive_share: f64,
    /// Largest total drive torque at the wheels, N m (1000–6000).
    pub drive_torque_max_nm: f64,
    /// Largest total brake torque at the wheels, N m (3000–12000).
    pub brake_torque_max_nm: f64,
    /// Front share of brake torque, in [0, 1] (0.6–0.75 typical).
    pub brake_front_share: f64,
    /// Largest road-wheel steer angle, rad (0.5–0.7).
    pub steer_max_rad: f64,
    /// Largest road-wheel steer rate, rad/s (0.5–2).
    pub steer_rate_max_radps: f64,
    /// Aerodynamic drag area C_d A, m^2 (0.5–1.2); 0 disables drag.
    #[serde(default)]
    pub drag_area_m2: f64,
    /// Rolling-resistance coefficient, dimensionless (0.008–0.015); 0 disables it.
    #[serde(default)]
    pub rolling_resistance: f64,
    /// Roll, load-transfer and steering-geometry data of the 4-DOF model (optional; the bicycle
    /// model ignores it, the 4-DOF model requires it).
    #[serde(default)]
    pub roll: Option<RollSection>,
    /// Lateral extensions found by `vehsim discover` (optional; bicycle model only, a 4-DOF run
    /// refuses them; the defaults leave the model unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lateral: Option<LateralSection>,
    /// The instruments: latency, offset and the accelerometer's position (optional; with it,
    /// `vehsim run` adds the measured channels to timeseries.csv).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensors: Option<SensorsSection>,
    /// Engine or motor, gearbox, final drive, driveline inertia and differential (optional; see
    /// [`PowertrainSection`]; without it the single limit `drive_torque_max_nm` is the drive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub powertrain: Option<PowertrainSection>,
}

/// Raw `[lateral]` section: optional extensions of the bicycle model's lateral behaviour, as
/// fitted by `vehsim discover` (docs/discover.md). The 4-DOF model has none of them: a 4-DOF run
/// refuses a vehicle that switches one on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LateralSection {
    /// Steer compliance: the effective road-wheel angle is reduced by this much per kN of front
    /// axle lateral force, rad/kN (0 = rigid steering, default; typical 0.001–0.01; at most 0.1).
    #[serde(default)]
    pub steer_compliance_rad_per_kn: f64,
    /// Scale on the surface friction seen by every tyre, dimensionless (default 1; [0.05, 3]).
    #[serde(default = "one")]
    pub mu_scale: f64,
    /// First-order steering lag between the commanded and the effective road-wheel angle, s
    /// (0 = none, default; at most 2).
    #[serde(default)]
    pub steer_lag_s: f64,
    /// Lateral relaxation length of the axle forces, m (0 = none, default; at most 10).
    #[serde(default)]
    pub relaxation_length_y_m: f64,
    /// Effective height of quasi-static lateral load transfer, m (0 = none, default; at most 2):
    /// each tyre of an axle is evaluated at its own load.
    #[serde(default)]
    pub load_transfer_height_m: f64,
    /// Friction change per kelvin of contact-temperature rise above the surface, 1/K (0 = none,
    /// default; [-2, 0]). Acts only when the manoeuvre's `[contact] model = "atiim"`.
    #[serde(default)]
    pub thermal_mu_per_k: f64,
    /// Front axle cornering-stiffness factor: the front tyres see this times the slip angle, so
    /// the slope at 0 scales and the peak force does not (default 1; [0.2, 5]).
    #[serde(default = "one")]
    pub stiffness_scale_front: f64,
    /// Rear axle cornering-stiffness factor (default 1; [0.2, 5]).
    #[serde(default = "one")]
    pub stiffness_scale_rear: f64,
    /// Front axle friction factor on top of `mu_scale` (default 1; [0.05, 3]).
    #[serde(default = "one")]
    pub mu_scale_front: f64,
    /// Rear axle friction factor on top of `mu_scale` (default 1; [0.05, 3]).
    #[serde(default = "one")]
    pub mu_scale_rear: f64,
    /// Load sensitivity of each tyre's friction under load transfer: friction x max(1 - k z,
    /// 0.05), z = Fz / Fz0 - 1 (default 0; [-1, 1]; acts with `load_transfer_height_m` > 0).
    #[serde(default)]
    pub load_sensitivity_mu: f64,
    /// Load sensitivity of each tyre's cornering stiffness (slip angle x max(1 - k z, 0.05);
    /// default 0; [-1, 1]).
    #[serde(default)]
    pub load_sensitivity_stiffness: f64,
    /// Transient slip: relaxation length of the front axle's lagged slip angle, m (0 = off,
    /// default; at most 10; with the rear one, both above 0 or both 0; not with
    /// `relaxation_length_y_m`).
    #[serde(default)]
    pub relaxation_length_front_m: f64,
    /// Transient slip: relaxation length of the rear axle's lagged slip angle, m.
    #[serde(default)]
    pub relaxation_length_rear_m: f64,
    /// Transient slip, saturating form: the relaxation lengths shorten with the tyre's local
    /// slope (default false).
    #[serde(default)]
    pub slip_relaxation_saturating: bool,
    /// Tread state: friction change per kJ of heat stored in one axle's tread, 1/kJ (0 = off,
    /// default; [-20, 0]).
    #[serde(default)]
    pub tread_mu_per_kj: f64,
    /// Tread state: heat capacity of one axle's tread layer, J/K (default 300; [10, 1e5]).
    #[serde(default = "tread_capacity")]
    pub tread_heat_capacity_j_per_k: f64,
    /// Tread state: cooling time constant, s (default 3; [0.1, 100]).
    #[serde(default = "tread_cooling")]
    pub tread_cooling_time_s: f64,
    /// Height at which the tyres' longitudinal (drive and brake) forces move load between the
    /// axles, m (0 = static loads, default; at most 2; a car's CG height is 0.45-0.65 m).
    #[serde(default)]
    pub longitudinal_transfer_height_m: f64,
}

fn one() -> f64 {
    1.0
}

fn tread_capacity() -> f64 {
    Lateral::default().tread_heat_capacity_j_per_k
}

fn tread_cooling() -> f64 {
    Lateral::default().tread_cooling_time_s
}

/// Raw `[sensors]` section: the instruments on the car, as fitted by `vehsim discover`
/// (docs/discover.md); every key defaults to 0 (a true, prompt instrument at the CG).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorsSection {
    /// Latency of the logged yaw rate, s ([0, 0.5]).
    #[serde(default)]
    pub latency_yaw_rate_s: f64,
    /// Latency of the logged lateral acceleration, s ([0, 0.5]).
    #[serde(default)]
    pub latency_ay_s: f64,
    /// Constant offset of the yaw-rate sensor, rad/s ([-0.5, 0.5]).
    #[serde(default)]
    pub bias_yaw_rate_radps: f64,
    /// Constant offset of the lateral accelerometer, m/s^2 ([-5, 5]).
    #[serde(default)]
    pub bias_ay_mps2: f64,
    /// Accelerometer position ahead of the CG, m ([-3, 3]).
    #[serde(default)]
    pub accel_x_m: f64,
    /// Accelerometer position left of the CG, m ([-1.5, 1.5]).
    #[serde(default)]
    pub accel_y_m: f64,
    /// Scale factor of the logged yaw rate (default 1; [0.5, 2]).
    #[serde(default = "one")]
    pub scale_yaw_rate: f64,
    /// Scale factor of the logged lateral acceleration (default 1; [0.5, 2]).
    #[serde(default = "one")]
    pub scale_ay: f64,
    /// The inertial unit's clock runs fast against the logger's by this much, ppm (default 0;
    /// [-20000, 20000]).
    #[serde(default)]
    pub clock_skew_ppm: f64,
    /// The accelerometer's y axis turned towards +x by this angle, rad (default 0; [-0.35, 0.35]).
    #[serde(default)]
    pub accel_yaw_misalignment_rad: f64,
}

impl SensorsSection {
    /// The validated instruments, each key within its bound ([`sensor_bounds`]).
    fn build(&self, c: &Checker) -> Result<Sensors> {
        use sensor_bounds as b;
        Ok(Sensors {
            latency_s: [
                c.bound(&b::LATENCY_YAW_RATE, self.latency_yaw_rate_s)?,
                c.bound(&b::LATENCY_AY, self.latency_ay_s)?,
            ],
            bias: [c.bound(&b::BIAS_YAW_RATE, self.bias_yaw_rate_radps)?, c.bound(&b::BIAS_AY, self.bias_ay_mps2)?],
            accel_position_m: [c.bound(&b::ACCEL_X, self.accel_x_m)?, c.bound(&b::ACCEL_Y, self.accel_y_m)?],
            scale: [c.bound(&b::SCALE_YAW_RATE, self.scale_yaw_rate)?, c.bound(&b::SCALE_AY, self.scale_ay)?],
            clock_skew_ppm: c.bound(&b::CLOCK_SKEW, self.clock_skew_ppm)?,
            accel_yaw_misalignment_rad: c.bound(&b::ACCEL_YAW, self.accel_yaw_misalignment_rad)?,
        })
    }
}

/// Raw `[roll]` section: what the 4-DOF roll model needs beyond the bicycle's data.
///
/// Roll-centre heights are above the ground at each axle; the roll axis joins them. The sprung
/// mass is `mass_kg` minus both unsprung masses; its CG height follows from `cg_height_m` (the
/// whole vehicle's) and the unsprung CG height.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollSection {
    /// Front roll-centre height above ground, m (MacPherson / double wishbone: 0.0–0.15).
    pub roll_centre_height_front_m: f64,
    /// Rear roll-centre height above ground, m (0.05–0.35).
    pub roll_centre_height_rear_m: f64,
    /// Front roll stiffness (springs + anti-roll bar), N m/rad (passenger cars 20e3–80e3).
    pub roll_stiffness_front_nm_per_rad: f64,
    /// Rear roll stiffness, N m/rad (15e3–60e3).
    pub roll_stiffness_rear_nm_per_rad: f64,
    /// Front roll damping (dampers), N m s/rad (1e3–6e3).
    pub roll_damping_front_nms_per_rad: f64,
    /// Rear roll damping, N m s/rad (1e3–6e3).
    pub roll_damping_rear_nms_per_rad: f64,
    /// Unsprung mass of the front axle (both corners), kg (60–120).
    pub unsprung_mass_front_kg: f64,
    /// Unsprung mass of the rear axle (both corners), kg (50–120).
    pub unsprung_mass_rear_kg: f64,
    /// Height of the unsprung masses' CG above ground, m (default: the tyre's unloaded radius).
    #[serde(default)]
    pub unsprung_cg_height_m: Option<f64>,
    /// Roll moment of inertia of the sprung mass about the x axis through its own CG, kg m^2
    /// (passenger cars 300–900).
    pub roll_inertia_kgm2: f64,
    /// Fraction of ideal Ackermann steering geometry, in [0, 1] (0 = parallel steer; default 0).
    #[serde(default)]
    pub ackermann: f64,
    /// Time constant of the first-order lag on the accelerations that drive load transfer, s
    /// (default 0.02; in [0.001, 1]). Breaks the algebraic loop load -> force -> acceleration -> load.
    #[serde(default = "default_lag")]
    pub load_transfer_lag_s: f64,
}

fn default_lag() -> f64 {
    0.02
}

fn half() -> f64 {
    0.5
}

impl VehicleFile {
    /// Read and parse a vehicle file.
    pub fn load(path: &Path) -> Result<Self> {
        parse_toml(path, &read_input(path)?)
    }

    /// Validate every value and build the tyre for provider `tyre_model`.
    pub fn build(&self, path: &Path, tyre_model: TyreModelKind) -> Result<Vehicle> {
        let c = Checker::new(path);
        self.check_body(&c)?;
        let tyre_path = resolve(path, &self.tyre);
        let (tyre, tyre_warnings) = TyreFileSpec::load(&tyre_path)
            .and_then(|t| t.build_with_warnings(&tyre_path, tyre_model))
            .map_err(vehsim_core::error::referred_by(path, "tyre"))?;
        let roll = match &self.roll {
            Some(r) => Some(r.build(&c, self, tyre.unloaded_radius_m)?),
            None => None,
        };
        let lateral = match &self.lateral {
            Some(l) => l.build(&c)?,
            None => Lateral::default(),
        };
        let sensors = match &self.sensors {
            Some(s) => Some(s.build(&c)?),
            None => None,
        };
        let powertrain = match &self.powertrain {
            Some(p) => Some(p.build(&c)?),
            None => None,
        };
        Ok(Vehicle {
            lateral,
            sensors,
            powertrain,
            tyre_ranges: crate::tyre::declared_ranges(&tyre_path),
            name: self.name.clone(),
            mass_kg: self.mass_kg,
            yaw_inertia_kgm2: self.yaw_inertia_kgm2,
            a_m: self.cg_to_front_axle_m,
            b_m: self.cg_to_rear_axle_m,
            track_m: self.track_m,
            cg_height_m: self.cg_height_m,
            body_width_m: self.body_width_m,
            body_length_m: self.body_length_m,
            front_overhang_m: self.front_overhang_m,
            wheel_inertia_kgm2: self.wheel_inertia_kgm2,
            drive: self.drive,
            front_drive_share: self.front_drive_share,
            drive_torque_max_nm: self.drive_torque_max_nm,
            brake_torque_max_nm: self.brake_torque_max_nm,
            brake_front_share: self.brake_front_share,
            steer_max_rad: self.steer_max_rad,
            steer_rate_max_radps: self.steer_rate_max_radps,
            drag_area_m2: self.drag_area_m2,
            rolling_resistance: self.rolling_resistance,
            roll,
            tyre,
            tyre_warnings,
        })
    }

    /// The body, mass and actuator keys within their ranges. Upper ends: beyond any road
    /// vehicle (a 40 t lorry, a bus) by a wide margin; they keep a mistyped unit or exponent
    /// from reaching the engine (where it makes a run take hours).
    fn check_body(&self, c: &Checker) -> Result<()> {
        use vehsim_core::vehicle::body_bounds as bb;
        for (b, v) in [
            (bb::MASS, self.mass_kg),
            (bb::YAW_INERTIA, self.yaw_inertia_kgm2),
            (bb::CG_TO_FRONT, self.cg_to_front_axle_m),
            (bb::CG_TO_REAR, self.cg_to_rear_axle_m),
            (bb::TRACK, self.track_m),
        ] {
            c.positive_up_to(b.key, v, b.hi, b.unit)?;
        }
        c.range(bb::CG_HEIGHT.key, self.cg_height_m, bb::CG_HEIGHT.lo, bb::CG_HEIGHT.hi)?;
        c.positive_up_to("body_width_m", self.body_width_m, 5.0, "m")?;
        c.range("front_overhang_m", self.front_overhang_m, 0.0, 5.0)?;
        let wheelbase = self.cg_to_front_axle_m + self.cg_to_rear_axle_m;
        c.require(
            "body_length_m",
            self.body_length_m,
            self.body_length_m >= wheelbase + self.front_overhang_m && self.body_length_m <= 30.0,
            "expected wheelbase + front_overhang_m <= body_length_m <= 30 (m)",
        )?;
        c.range("wheel_inertia_kgm2", self.wheel_inertia_kgm2, 0.01, 100.0)?;
        c.range("front_drive_share", self.front_drive_share, 0.0, 1.0)?;
        c.range("drive_torque_max_nm", self.drive_torque_max_nm, 0.0, 100_000.0)?;
        c.positive_up_to("brake_torque_max_nm", self.brake_torque_max_nm, 100_000.0, "N m")?;
        c.range("brake_front_share", self.brake_front_share, 0.0, 1.0)?;
        c.range("steer_max_rad", self.steer_max_rad, 1e-3, 1.2)?;
        c.positive_up_to("steer_rate_max_radps", self.steer_rate_max_radps, 20.0, "rad/s")?;
        c.range("drag_area_m2", self.drag_area_m2, 0.0, 20.0)?;
        c.range("rolling_resistance", self.rolling_resistance, 0.0, 0.1)?;
        Ok(())
    }
}

impl LateralSection {
    /// The validated extensions, each within its bound ([`lateral_bounds`]).
    fn build(&self, c: &Checker) -> Result<Lateral> {
        use lateral_bounds as b;
        let lat = Lateral {
            steer_compliance_rad_per_kn: c.bound(&b::STEER_COMPLIANCE, self.steer_compliance_rad_per_kn)?,
            mu_scale: c.bound(&b::MU_SCALE, self.mu_scale)?,
            steer_lag_s: c.bound(&b::STEER_LAG, self.steer_lag_s)?,
            relaxation_length_y_m: c.bound(&b::RELAXATION_LENGTH, self.relaxation_length_y_m)?,
            load_transfer_height_m: c.bound(&b::LOAD_TRANSFER_HEIGHT, self.load_transfer_height_m)?,
            thermal_mu_per_k: c.bound(&b::THERMAL_MU, self.thermal_mu_per_k)?,
            stiffness_scale: [
                c.bound(&b::STIFFNESS_SCALE_FRONT, self.stiffness_scale_front)?,
                c.bound(&b::STIFFNESS_SCALE_REAR, self.stiffness_scale_rear)?,
            ],
            mu_axle_scale: [
                c.bound(&b::MU_SCALE_FRONT, self.mu_scale_front)?,
                c.bound(&b::MU_SCALE_REAR, self.mu_scale_rear)?,
            ],
            load_sensitivity: [
                c.bound(&b::LOAD_SENSITIVITY_MU, self.load_sensitivity_mu)?,
                c.bound(&b::LOAD_SENSITIVITY_STIFFNESS, self.load_sensitivity_stiffness)?,
            ],
            slip_relaxation_m: [
                c.bound(&b::RELAXATION_FRONT, self.relaxation_length_front_m)?,
                c.bound(&b::RELAXATION_REAR, self.relaxation_length_rear_m)?,
            ],
            slip_relaxation_saturating: self.slip_relaxation_saturating,
            tread_mu_per_kj: c.bound(&b::TREAD_MU_PER_KJ, self.tread_mu_per_kj)?,
            tread_heat_capacity_j_per_k: c.bound(&b::TREAD_HEAT_CAPACITY, self.tread_heat_capacity_j_per_k)?,
            tread_cooling_time_s: c.bound(&b::TREAD_COOLING_TIME, self.tread_cooling_time_s)?,
            longitudinal_transfer_height_m: c
                .bound(&b::LONGITUDINAL_TRANSFER_HEIGHT, self.longitudinal_transfer_height_m)?,
        };
        Self::check_forms(c, &lat)?;
        Ok(lat)
    }

    /// The forms that exclude one another: transient slip on both axles or neither, and not
    /// beside the force relaxation (two forms of one tyre relaxation); the saturating flag only
    /// with transient slip.
    fn check_forms(c: &Checker, lat: &Lateral) -> Result<()> {
        let [front, rear] = lat.slip_relaxation_m;
        c.require(
            "lateral.relaxation_length_rear_m",
            rear,
            (front > 0.0) == (rear > 0.0),
            "expected relaxation_length_front_m and relaxation_length_rear_m both > 0 (transient slip) or both 0",
        )?;
        c.require(
            "lateral.relaxation_length_front_m",
            front,
            !(lat.transient_slip() && lat.relaxation_length_y_m > 0.0),
            "expected 0 when relaxation_length_y_m > 0: transient slip per axle and the force relaxation are two \
             forms of tyre relaxation; set one",
        )?;
        let saturating = lat.slip_relaxation_saturating && !lat.transient_slip();
        c.require(
            "lateral.slip_relaxation_saturating",
            0.0,
            !saturating,
            "expected false unless relaxation_length_front_m and relaxation_length_rear_m are > 0",
        )?;
        Ok(())
    }
}

impl RollSection {
    /// Validate the section against its vehicle (`unloaded_radius` is the tyre's, m).
    fn build(&self, c: &Checker, v: &VehicleFile, unloaded_radius: f64) -> Result<Roll> {
        self.check_axle_ranges(c)?;
        let m_u = self.unsprung_mass_front_kg + self.unsprung_mass_rear_kg;
        c.require(
            "roll.unsprung_mass_rear_kg",
            self.unsprung_mass_rear_kg,
            m_u < 0.5 * v.mass_kg,
            "expected unsprung_mass_front_kg + unsprung_mass_rear_kg < mass_kg / 2 (kg)",
        )?;
        let h_u = match self.unsprung_cg_height_m {
            Some(h) => c.range("roll.unsprung_cg_height_m", h, 0.0, 1.0)?,
            None => unloaded_radius,
        };
        c.positive_up_to("roll.roll_inertia_kgm2", self.roll_inertia_kgm2, 1e6, "kg m^2")?;
        c.range("roll.ackermann", self.ackermann, 0.0, 1.0)?;
        c.range("roll.load_transfer_lag_s", self.load_transfer_lag_s, 0.001, 1.0)?;
        let m = v.mass_kg;
        let m_s = m - m_u;
        let h_s = (m * v.cg_height_m - m_u * h_u) / m_s;
        c.require(
            "roll.unsprung_cg_height_m",
            h_u,
            h_s >= 0.0,
            &format!(
                "the sprung-mass CG would lie below ground (h_s = {h_s:.3} m); expected unsprung mass x height \
                 <= mass_kg x cg_height_m"
            ),
        )?;
        let (a, b) = (v.cg_to_front_axle_m, v.cg_to_rear_axle_m);
        let l = a + b;
        let x_s = (self.unsprung_mass_rear_kg * b - self.unsprung_mass_front_kg * a) / m_s;
        let (a_s, b_s) = (a - x_s, b + x_s);
        let above = "expected a roll centre at or below the sprung-mass CG height h_s";
        c.require(
            "roll.roll_centre_height_front_m",
            self.roll_centre_height_front_m,
            self.roll_centre_height_front_m <= h_s,
            &format!("{above} = {h_s:.3} m (m)"),
        )?;
        c.require(
            "roll.roll_centre_height_rear_m",
            self.roll_centre_height_rear_m,
            self.roll_centre_height_rear_m <= h_s,
            &format!("{above} = {h_s:.3} m (m)"),
        )?;
        let h_ra = (self.roll_centre_height_front_m * b_s + self.roll_centre_height_rear_m * a_s) / l;
        let h_prime = (h_s - h_ra).max(0.0);
        let k = self.roll_stiffness_front_nm_per_rad + self.roll_stiffness_rear_nm_per_rad;
        let k_min = m_s * crate::vehicle::GRAVITY * h_prime;
        c.require(
            "roll.roll_stiffness_rear_nm_per_rad",
            self.roll_stiffness_rear_nm_per_rad,
            k > 1.05 * k_min,
            &format!(
                "the body would fall over: expected total roll stiffness > 1.05 m_s g h' = {:.0} N m/rad",
                1.05 * k_min
            ),
        )?;
        Ok(Roll {
            rc_height_m: [self.roll_centre_height_front_m, self.roll_centre_height_rear_m],
            stiffness_nm_per_rad: [self.roll_stiffness_front_nm_per_rad, self.roll_stiffness_rear_nm_per_rad],
            damping_nms_per_rad: [self.roll_damping_front_nms_per_rad, self.roll_damping_rear_nms_per_rad],
            unsprung_mass_kg: [self.unsprung_mass_front_kg, self.unsprung_mass_rear_kg],
            unsprung_cg_height_m: h_u,
            roll_inertia_kgm2: self.roll_inertia_kgm2,
            ackermann: self.ackermann,
            load_transfer_lag_s: self.load_transfer_lag_s,
            sprung_mass_kg: m_s,
            sprung_cg_height_m: h_s,
            sprung_cg_ahead_m: x_s,
            roll_axis_height_m: h_ra,
            h_prime_m: h_prime,
        })
    }

    /// Roll-centre heights, roll stiffness and damping and unsprung masses, per axle, within
    /// their ranges.
    fn check_axle_ranges(&self, c: &Checker) -> Result<()> {
        c.range("roll.roll_centre_height_front_m", self.roll_centre_height_front_m, -0.5, 2.0)?;
        c.range("roll.roll_centre_height_rear_m", self.roll_centre_height_rear_m, -0.5, 2.0)?;
        c.positive_up_to("roll.roll_stiffness_front_nm_per_rad", self.roll_stiffness_front_nm_per_rad, 1e7, "N m/rad")?;
        c.positive_up_to("roll.roll_stiffness_rear_nm_per_rad", self.roll_stiffness_rear_nm_per_rad, 1e7, "N m/rad")?;
        c.range("roll.roll_damping_front_nms_per_rad", self.roll_damping_front_nms_per_rad, 0.0, 1e6)?;
        c.range("roll.roll_damping_rear_nms_per_rad", self.roll_damping_rear_nms_per_rad, 0.0, 1e6)?;
        c.non_negative("roll.unsprung_mass_front_kg", self.unsprung_mass_front_kg)?;
        c.non_negative("roll.unsprung_mass_rear_kg", self.unsprung_mass_rear_kg)?;
        Ok(())
    }
}

/// Raw `[powertrain]` section of a vehicle file (docs/powertrain.md). Engine speeds in rpm,
/// torques in N m at the engine or motor shaft, power in kW.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowertrainSection {
    /// `engine` (a full-load torque curve) or `motor` (constant torque, then constant power).
    pub kind: String,
    /// Engine: full-load curve `[[speed_rpm, torque_nm], ...]`, speeds strictly increasing
    /// (at least two points, torques >= 0); the last speed is the rev limit.
    #[serde(default)]
    pub torque_curve: Option<Vec<[f64; 2]>>,
    /// Power cap, kW (engine: optional; motor: required).
    #[serde(default)]
    pub power_max_kw: Option<f64>,
    /// Motor: torque up to the base speed, N m.
    #[serde(default)]
    pub torque_max_nm: Option<f64>,
    /// Motor: top speed, rpm.
    #[serde(default)]
    pub speed_max_rpm: Option<f64>,
    /// Gearbox ratios, first gear first, each > 0 (a single-speed motor: one ratio).
    pub gear_ratios: Vec<f64>,
    /// Final-drive ratio, > 0.
    pub final_drive_ratio: f64,
    /// Driveline efficiency, (0, 1] (default 1).
    #[serde(default = "one")]
    pub efficiency: f64,
    /// Engine-side rotating inertia (engine, flywheel, gearbox input), kg m^2, >= 0 (default 0).
    #[serde(default)]
    pub engine_inertia_kgm2: f64,
    /// Fixed gear, 1 = first; omitted: the automatic schedule (the gear with the most wheel torque).
    #[serde(default)]
    pub fixed_gear: Option<f64>,
    /// `open` (default), `locked` or `limited_slip`.
    #[serde(default)]
    pub differential: Option<String>,
    /// Limited slip: torque bias ratio, >= 1 (required with `limited_slip`, refused otherwise).
    #[serde(default)]
    pub torque_bias_ratio: Option<f64>,
}

/// The allowed ranges of the `[powertrain]` keys.
pub mod powertrain_bounds {
    use vehsim_core::error::Bound;

    /// `powertrain.torque_curve` engine speeds: [0, 30000] rpm.
    pub const SPEED_RPM: Bound = Bound::closed("powertrain.torque_curve", 0.0, 30_000.0, "rpm");
    /// `powertrain.torque_curve` full-load torques: [0, 5000] N m.
    pub const TORQUE_NM: Bound = Bound::closed("powertrain.torque_curve", 0.0, 5_000.0, "N m");
    /// `powertrain.power_max_kw`: power cap, (0, 2000] kW.
    pub const POWER_MAX_KW: Bound = Bound::left_open("powertrain.power_max_kw", 0.0, 2_000.0, "kW");
    /// `powertrain.torque_max_nm`: motor torque up to the base speed, (0, 5000] N m.
    pub const TORQUE_MAX_NM: Bound = Bound::left_open("powertrain.torque_max_nm", 0.0, 5_000.0, "N m");
    /// `powertrain.speed_max_rpm`: motor top speed, (0, 30000] rpm.
    pub const SPEED_MAX_RPM: Bound = Bound::left_open("powertrain.speed_max_rpm", 0.0, 30_000.0, "rpm");
    /// `powertrain.gear_ratios`: each gearbox ratio, (0, 20].
    pub const GEAR_RATIO: Bound = Bound::left_open("powertrain.gear_ratios", 0.0, 20.0, "");
    /// `powertrain.final_drive_ratio`: (0, 20].
    pub const FINAL_DRIVE: Bound = Bound::left_open("powertrain.final_drive_ratio", 0.0, 20.0, "");
    /// `powertrain.efficiency`: driveline efficiency, (0, 1].
    pub const EFFICIENCY: Bound = Bound::left_open("powertrain.efficiency", 0.0, 1.0, "");
    /// `powertrain.engine_inertia_kgm2`: engine-side rotating inertia, [0, 10] kg m^2.
    pub const ENGINE_INERTIA: Bound = Bound::closed("powertrain.engine_inertia_kgm2", 0.0, 10.0, "kg m^2");
    /// `powertrain.torque_bias_ratio`: limited-slip torque bias ratio, [1, 20].
    pub const TORQUE_BIAS_RATIO: Bound = Bound::closed("powertrain.torque_bias_ratio", 1.0, 20.0, "");
}

/// rad/s per rpm.
const RPM: f64 = std::f64::consts::PI / 30.0;

impl PowertrainSection {
    /// Validate into a [`vehsim_core::vehicle::powertrain::Powertrain`]; bad input names the key.
    pub fn build(&self, c: &Checker) -> Result<Powertrain> {
        let source = match self.kind.as_str() {
            "engine" => self.engine(c)?,
            "motor" => self.motor(c)?,
            other => {
                return Err(Error::key(
                    c.file,
                    "powertrain.kind",
                    format!("unknown powertrain kind '{other}'; allowed: engine, motor"),
                ))
            }
        };
        self.check_gearbox(c)?;
        Ok(Powertrain::new(
            source,
            self.gear_ratios.clone(),
            self.final_drive_ratio,
            self.efficiency,
            self.engine_inertia_kgm2,
            self.gear_mode(c)?,
            self.differential(c)?,
        ))
    }

    /// `powertrain.{key}` is not a key of the powertrain `kind` (bad input).
    fn refuse<T>(c: &Checker, key: &str, kind: &str) -> Result<T> {
        Err(Error::key(c.file, &format!("powertrain.{key}"), format!("not used with kind = \"{kind}\"; remove it")))
    }

    /// `kind = "engine"`: a torque curve over engine speed (rpm in the file, rad/s built), an
    /// optional power limit.
    fn engine(&self, c: &Checker) -> Result<TorqueSource> {
        use powertrain_bounds as b;
        for (k, set) in
            [("torque_max_nm", self.torque_max_nm.is_some()), ("speed_max_rpm", self.speed_max_rpm.is_some())]
        {
            if set {
                return Self::refuse(c, k, "engine");
            }
        }
        let curve = self.torque_curve.as_ref().ok_or_else(|| {
            Error::key(
                c.file,
                "powertrain.torque_curve",
                "required with kind = \"engine\": [[speed_rpm, torque_nm], ...]",
            )
        })?;
        if curve.len() < 2 {
            return Err(Error::key(
                c.file,
                "powertrain.torque_curve",
                "expected at least two [speed_rpm, torque_nm] points",
            ));
        }
        let mut prev = f64::NEG_INFINITY;
        for (n, [w, t]) in curve.iter().enumerate() {
            let key = format!("powertrain.torque_curve[{n}]");
            c.require(
                &key,
                *w,
                b::SPEED_RPM.contains(*w) && *w > prev,
                "expected engine speeds in [0, 30000] rpm, strictly increasing",
            )?;
            c.require(&key, *t, b::TORQUE_NM.contains(*t), "expected a torque in [0, 5000] N m")?;
            prev = *w;
        }
        c.require(
            "powertrain.torque_curve",
            curve.iter().map(|p| p[1]).fold(0.0, f64::max),
            curve.iter().any(|p| p[1] > 0.0),
            "expected some torque > 0 on the curve",
        )?;
        let power_max_w = match self.power_max_kw {
            Some(p) => 1e3 * c.bound(&b::POWER_MAX_KW, p)?,
            None => f64::INFINITY,
        };
        Ok(TorqueSource::Engine { curve: curve.iter().map(|p| (p[0] * RPM, p[1])).collect(), power_max_w })
    }

    /// `kind = "motor"`: constant torque up to the power limit, then constant power, up to a
    /// top speed.
    fn motor(&self, c: &Checker) -> Result<TorqueSource> {
        use powertrain_bounds as b;
        if self.torque_curve.is_some() {
            return Self::refuse(c, "torque_curve", "motor");
        }
        let need = |k: &str, v: Option<f64>, bound: &vehsim_core::error::Bound| -> Result<f64> {
            let v =
                v.ok_or_else(|| Error::key(c.file, &format!("powertrain.{k}"), "required with kind = \"motor\""))?;
            c.bound(bound, v)
        };
        Ok(TorqueSource::Motor {
            torque_max_nm: need("torque_max_nm", self.torque_max_nm, &b::TORQUE_MAX_NM)?,
            power_max_w: 1e3 * need("power_max_kw", self.power_max_kw, &b::POWER_MAX_KW)?,
            speed_max_radps: RPM * need("speed_max_rpm", self.speed_max_rpm, &b::SPEED_MAX_RPM)?,
        })
    }

    /// Gear ratios, final drive, efficiency and engine inertia within their ranges.
    fn check_gearbox(&self, c: &Checker) -> Result<()> {
        use powertrain_bounds as b;
        if self.gear_ratios.is_empty() || self.gear_ratios.len() > 12 {
            return Err(Error::key(c.file, "powertrain.gear_ratios", "expected 1 to 12 ratios, first gear first"));
        }
        for (n, g) in self.gear_ratios.iter().enumerate() {
            c.require(
                &format!("powertrain.gear_ratios[{n}]"),
                *g,
                b::GEAR_RATIO.contains(*g),
                "expected 0 < ratio <= 20",
            )?;
        }
        c.bound(&b::FINAL_DRIVE, self.final_drive_ratio)?;
        c.bound(&b::EFFICIENCY, self.efficiency)?;
        c.bound(&b::ENGINE_INERTIA, self.engine_inertia_kgm2)?;
        Ok(())
    }

    /// Automatic shifting, or the gear `fixed_gear` names (1 = first).
    fn gear_mode(&self, c: &Checker) -> Result<GearMode> {
        Ok(match self.fixed_gear {
            None => GearMode::Auto,
            Some(g) => {
                let n = self.gear_ratios.len();
                c.require(
                    "powertrain.fixed_gear",
                    g,
                    g.fract() == 0.0 && g >= 1.0 && g <= n as f64,
                    &format!("expected a whole gear number from 1 to {n} (the number of gear_ratios)"),
                )?;
                GearMode::Fixed(g as usize - 1)
            }
        })
    }

    /// The differential between the driven wheels (default open).
    fn differential(&self, c: &Checker) -> Result<Differential> {
        use powertrain_bounds as b;
        Ok(match (self.differential.as_deref().unwrap_or("open"), self.torque_bias_ratio) {
            ("open", None) => Differential::Open,
            ("locked", None) => Differential::Locked,
            ("limited_slip", Some(t)) => {
                Differential::LimitedSlip { torque_bias_ratio: c.bound(&b::TORQUE_BIAS_RATIO, t)? }
            }
            ("limited_slip", None) => {
                return Err(Error::key(
                    c.file,
                    "powertrain.torque_bias_ratio",
                    "required with differential = \"limited_slip\" (a number in [1, 20])",
                ))
            }
            ("open" | "locked", Some(_)) => {
                return Err(Error::key(
                    c.file,
                    "powertrain.torque_bias_ratio",
                    "only used with differential = \"limited_slip\"; remove it",
                ))
            }
            (other, _) => {
                return Err(Error::key(
                    c.file,
                    "powertrain.differential",
                    format!("unknown differential '{other}'; allowed: open, locked, limited_slip"),
                ))
            }
        })
    }
}
