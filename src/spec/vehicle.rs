//! Vehicle spec (`vehicles/*.toml`) and the validated [`Vehicle`].
//!
//! Geometry follows ISO 8855: x forward, y left, z up; `a` and `b` are the horizontal distances from
//! the centre of gravity to the front and rear axle.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{parse_toml, read_input, resolve, Checker, Result};
use crate::tyre::spec::Tyre;
use crate::tyre::{TyreFileSpec, TyreModelKind};

/// Which axle(s) the engine drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveLayout {
    Front,
    Rear,
    All,
}

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
}

fn half() -> f64 {
    0.5
}

/// Air density used for drag, kg/m^3 (ISA sea level at 15 degC; cold air on ice is ~5 % denser).
pub const AIR_DENSITY: f64 = 1.225;
/// Standard gravity, m/s^2.
pub const GRAVITY: f64 = 9.80665;

/// A validated vehicle with its tyre built for one provider.
#[derive(Debug, Clone)]
pub struct Vehicle {
    pub name: String,
    pub mass_kg: f64,
    pub yaw_inertia_kgm2: f64,
    /// CG to front axle a, m.
    pub a_m: f64,
    /// CG to rear axle b, m.
    pub b_m: f64,
    pub track_m: f64,
    pub cg_height_m: f64,
    pub body_width_m: f64,
    pub body_length_m: f64,
    pub front_overhang_m: f64,
    pub wheel_inertia_kgm2: f64,
    pub drive: DriveLayout,
    pub front_drive_share: f64,
    pub drive_torque_max_nm: f64,
    pub brake_torque_max_nm: f64,
    pub brake_front_share: f64,
    pub steer_max_rad: f64,
    pub steer_rate_max_radps: f64,
    pub drag_area_m2: f64,
    pub rolling_resistance: f64,
    pub tyre: Tyre,
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

impl VehicleFile {
    /// Read and parse a vehicle file.
    pub fn load(path: &Path) -> Result<Self> {
        parse_toml(path, &read_input(path)?)
    }

    /// Validate every value and build the tyre for provider `tyre_model`.
    pub fn build(&self, path: &Path, tyre_model: TyreModelKind) -> Result<Vehicle> {
        let c = Checker::new(path);
        c.positive("mass_kg", self.mass_kg)?;
        c.positive("yaw_inertia_kgm2", self.yaw_inertia_kgm2)?;
        c.positive("cg_to_front_axle_m", self.cg_to_front_axle_m)?;
        c.positive("cg_to_rear_axle_m", self.cg_to_rear_axle_m)?;
        c.positive("track_m", self.track_m)?;
        c.non_negative("cg_height_m", self.cg_height_m)?;
        c.positive("body_width_m", self.body_width_m)?;
        c.non_negative("front_overhang_m", self.front_overhang_m)?;
        let wheelbase = self.cg_to_front_axle_m + self.cg_to_rear_axle_m;
        c.require(
            "body_length_m",
            self.body_length_m,
            self.body_length_m >= wheelbase + self.front_overhang_m,
            "expected body_length_m >= wheelbase + front_overhang_m (m)",
        )?;
        c.positive("wheel_inertia_kgm2", self.wheel_inertia_kgm2)?;
        c.range("front_drive_share", self.front_drive_share, 0.0, 1.0)?;
        c.non_negative("drive_torque_max_nm", self.drive_torque_max_nm)?;
        c.positive("brake_torque_max_nm", self.brake_torque_max_nm)?;
        c.range("brake_front_share", self.brake_front_share, 0.0, 1.0)?;
        c.range("steer_max_rad", self.steer_max_rad, 1e-3, 1.2)?;
        c.positive("steer_rate_max_radps", self.steer_rate_max_radps)?;
        c.non_negative("drag_area_m2", self.drag_area_m2)?;
        c.range("rolling_resistance", self.rolling_resistance, 0.0, 0.1)?;
        let tyre_path = resolve(path, &self.tyre);
        let tyre = TyreFileSpec::load(&tyre_path)?.build(&tyre_path, tyre_model)?;
        Ok(Vehicle {
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
            tyre,
        })
    }
}
