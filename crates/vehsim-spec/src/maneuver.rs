//! Manoeuvre spec (`maneuvers/*.toml`) and the validated [`RunConfig`].
//!
//! ```toml
//! name = "dlc_ice"                      # output folder results/<name>
//! vehicle = "../vehicles/sedan.toml"    # relative to this file
//! tyre_model = "linear"                 # a provider with a section in the vehicle's tyre file
//! vehicle_model = "bicycle"             # or "roll4dof" (needs the vehicle's [roll] section)
//! duration_s = 15.0                     # longest simulated time, s
//! [surface]
//! mu = 0.15                             # peak friction coefficient
//! temperature_c = -3.0                  # ice surface temperature, degC
//! [maneuver]
//! kind = "iso3888_2"                    # or sine_steer, step_steer, straight, constant_radius
//! speed_mps = 10.0
//! speed_mode = "hold"                   # or "coast" (ISO: throttle released at the entry gate)
//! [speed_control]                       # PID, N m per m/s
//! kp = 2000.0
//! ki = 1000.0
//! [driver]
//! preview_time_s = 0.55
//! [integrator]
//! method = "rk4"                        # or dopri5, dop853
//! control_period_s = 0.01               # controller sample period (default 0.01 s)
//! # step_s = 0.01                       # default: from the vehicle's fastest mode
//! [output]
//! interval_s = 0.01
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::contact::{ContactModelKind, ContactSpec};
use crate::files::{parse_toml, read_input, resolve};
use crate::vehicle::VehicleFile;
use vehsim_core::control::{DriverParams, PidParams};
use vehsim_core::error::{Checker, Error, Result};
use vehsim_core::maneuver::constant_radius::{ConstantRadiusParams, Direction};
use vehsim_core::maneuver::iso3888_2::{Iso3888_2Params, SpeedMode};
use vehsim_core::maneuver::open_loop::{SpeedSchedule, SteerProfile};
use vehsim_core::sim::{Method, SimSettings};
use vehsim_core::tyre::TyreModelKind;
use vehsim_core::vehicle::Environment;
use vehsim_core::vehicle::{Vehicle, VehicleModelKind};

/// `[surface]`: the road.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSection {
    /// Peak friction coefficient, (0, 2] (ice 0.05–0.2, snow 0.2–0.4, dry asphalt 0.9–1.1).
    pub mu: f64,
    /// Surface (ice) temperature, degC, in [-60, 40].
    #[serde(default = "minus_three")]
    pub temperature_c: f64,
    /// How `mu` acts (docs/tyres.md, "Ice friction"): "ice" (the Magic Formula tyres' peak
    /// friction follows the rubber-ice friction law at the tyre's ice or contact temperature and
    /// sliding speed, with `mu` the friction at the reference conditions) or "fixed" (`mu` at
    /// every temperature and sliding speed). Default: "ice" on ice (temperature_c <= 0 and
    /// mu <= 0.6), "fixed" otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction_law: Option<String>,
    /// Ice temperature at which `mu` is stated (with friction_law "ice"), degC, in [-60, 0];
    /// default -3 (a fixed temperature, not the surface's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mu_reference_temperature_c: Option<f64>,
    /// Friction patches on the ground (`[[surface.patch]]`, at most one; the bicycle model only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub patch: Vec<PatchRegion>,
    /// Friction bands across X (`[[surface.band]]`, at most one; the bicycle model only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub band: Vec<BandRegion>,
    /// Friction stretches of the distance travelled (`[[surface.stretch]]`, at most one; the
    /// bicycle model only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stretch: Vec<StretchRegion>,
}

/// `[road]`: the road's constant bank and grade ([`vehsim_core::vehicle::road`]; the bicycle
/// model only). Geometry of the road, not a property of its surface's grip, so a section of its
/// own rather than keys of `[surface]`; a measured run's sidecar takes the same section.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoadSection {
    /// Bank angle, deg, positive when the road's left edge is higher (default 0).
    #[serde(default)]
    pub bank_deg: f64,
    /// Grade angle, deg, positive uphill in the direction of travel (default 0).
    #[serde(default)]
    pub grade_deg: f64,
}

impl RoadSection {
    /// The road, each key within its bound and the grade within what tyres of peak friction
    /// `mu` can climb at a held speed ([`vehsim_core::vehicle::road::Road::too_steep`]).
    pub fn road(&self, path: &Path, mu: f64) -> Result<vehsim_core::vehicle::road::Road> {
        use vehsim_core::vehicle::road::{road_bounds as b, Road};
        let c = Checker::new(path);
        let road = Road::from_deg(c.bound(&b::BANK_DEG, self.bank_deg)?, c.bound(&b::GRADE_DEG, self.grade_deg)?);
        match road.too_steep(mu) {
            Some(why) => Err(Error::key(path, "road.grade_deg", why)),
            None => Ok(road),
        }
    }
}

/// `[[surface.patch]]`: a disc on the ground where the friction is `mu_scale` times the
/// surface's, with a 1 m logistic edge ([`vehsim_core::vehicle::ground`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatchRegion {
    /// Friction scale inside, [0.05, 3].
    pub mu_scale: f64,
    /// Centre X, m, [-5000, 5000] (the start at the origin heading +X).
    pub x_m: f64,
    /// Centre Y, m, [-5000, 5000].
    pub y_m: f64,
    /// Radius, m, [1, 1000].
    pub radius_m: f64,
}

/// `[[surface.band]]`: a band across X (any Y) where the friction is `mu_scale` times the
/// surface's, with 1 m logistic edges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BandRegion {
    /// Friction scale inside, [0.05, 3].
    pub mu_scale: f64,
    /// Start X, m, [-5000, 5000].
    pub start_x_m: f64,
    /// Length along X, m, [2, 2000].
    pub length_m: f64,
}

/// `[[surface.stretch]]`: a stretch of the distance the CG travels from the start where the
/// friction is `mu_scale` times the surface's, with 1 m logistic edges.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StretchRegion {
    /// Friction scale inside, [0.05, 3].
    pub mu_scale: f64,
    /// Start, m of distance travelled, [0, 2000].
    pub start_m: f64,
    /// Length, m, [2, 2000].
    pub length_m: f64,
}

/// Validated friction regions of a `[surface]` (a manoeuvre's or a measured run's sidecar,
/// `path` named in messages): each key within its bound, at most one region of each kind.
pub fn ground_regions(
    path: &Path,
    patch: &[PatchRegion],
    band: &[BandRegion],
    stretch: &[StretchRegion],
) -> Result<vehsim_core::vehicle::ground::GroundRegions> {
    use vehsim_core::vehicle::ground::region_bounds as b;
    let c = Checker::new(path);
    for (kind, n) in [("patch", patch.len()), ("band", band.len()), ("stretch", stretch.len())] {
        if n > 1 {
            return Err(Error::key(path, &format!("surface.{kind}"), format!("{n} regions; at most one of each kind")));
        }
    }
    let within =
        |key: &str, bound: vehsim_core::error::Bound, v: f64| c.require(key, v, bound.contains(v), &bound.allowed());
    let mut g = vehsim_core::vehicle::ground::GroundRegions::NONE;
    if let Some(p) = patch.first() {
        g.patch = Some([
            within("surface.patch.mu_scale", b::MU_SCALE_REGION, p.mu_scale)?,
            within("surface.patch.x_m", b::PATCH_XY, p.x_m)?,
            within("surface.patch.y_m", b::PATCH_XY, p.y_m)?,
            c.bound(&b::PATCH_RADIUS, p.radius_m)?,
        ]);
    }
    if let Some(p) = band.first() {
        g.band = Some([
            within("surface.band.mu_scale", b::MU_SCALE_REGION, p.mu_scale)?,
            c.bound(&b::BAND_START, p.start_x_m)?,
            within("surface.band.length_m", b::REGION_LENGTH, p.length_m)?,
        ]);
    }
    if let Some(p) = stretch.first() {
        g.stretch = Some([
            within("surface.stretch.mu_scale", b::MU_SCALE_REGION, p.mu_scale)?,
            c.bound(&b::STRETCH_START, p.start_m)?,
            within("surface.stretch.length_m", b::REGION_LENGTH, p.length_m)?,
        ]);
    }
    Ok(g)
}

/// Largest `mu` the ice friction law accepts at its reference conditions (ice friction is
/// 0.05-0.3; studded tyres on rough ice reach about 0.4).
pub const ICE_MU_MAX: f64 = 0.6;

impl SurfaceSection {
    /// The friction regions, each key within its bound, at most one of each kind.
    pub fn regions(&self, path: &Path) -> Result<vehsim_core::vehicle::ground::GroundRegions> {
        ground_regions(path, &self.patch, &self.band, &self.stretch)
    }

    /// The surface friction law of this surface (None: `mu` is fixed), validated.
    pub fn friction(&self, path: &Path) -> Result<Option<vehsim_core::tyre::ice::SurfaceFriction>> {
        let c = Checker::new(path);
        let on_ice = self.temperature_c <= 0.0 && self.mu <= ICE_MU_MAX;
        let ice = match self.friction_law.as_deref() {
            None => on_ice,
            Some("fixed") => false,
            Some("ice") => {
                c.require(
                    "surface.temperature_c",
                    self.temperature_c,
                    self.temperature_c <= 0.0,
                    "friction_law \"ice\" needs ice: temperature_c <= 0 degC (or friction_law = \"fixed\")",
                )?;
                c.require(
                    "surface.mu",
                    self.mu,
                    self.mu <= ICE_MU_MAX,
                    &format!("friction_law \"ice\" takes mu <= {ICE_MU_MAX} (ice); use friction_law = \"fixed\" for another surface"),
                )?;
                true
            }
            Some(other) => {
                return Err(Error::key(
                    path,
                    "surface.friction_law",
                    format!("unknown friction law '{other}'; allowed: ice, fixed"),
                ))
            }
        };
        let t_ref = match self.mu_reference_temperature_c {
            Some(t) => c.range("surface.mu_reference_temperature_c", t, -60.0, 0.0)?,
            None => vehsim_core::tyre::ice::DEFAULT_REFERENCE_C,
        };
        if !ice {
            if self.mu_reference_temperature_c.is_some() {
                return Err(Error::key(
                    path,
                    "surface.mu_reference_temperature_c",
                    "applies only with friction_law = \"ice\" (on ice: temperature_c <= 0, mu <= 0.6)",
                ));
            }
            return Ok(None);
        }
        Ok(Some(vehsim_core::tyre::ice::SurfaceFriction::new(t_ref, self.temperature_c)))
    }
}

fn minus_three() -> f64 {
    -3.0
}

/// ISO 3888-2 speed mode as written in specs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum SpeedModeSpec {
    Hold,
    Coast,
}

fn default_approach() -> f64 {
    30.0
}
fn default_exit() -> f64 {
    20.0
}
fn default_lane5() -> f64 {
    3.0
}
fn default_clearance() -> f64 {
    0.1
}
fn default_period() -> f64 {
    10.0
}
fn default_ramp() -> f64 {
    0.2
}

/// `[maneuver]` with `kind = "iso3888_2"`: ISO 3888-2 severe lane change with the path-following driver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Iso3888_2Spec {
    /// Entry speed, m/s (> 0).
    pub speed_mps: f64,
    /// `hold` (PID all the way) or `coast` (throttle released at the entry gate).
    #[serde(default = "hold")]
    pub speed_mode: SpeedModeSpec,
    /// Straight run-up before the entry gate, m (default 30).
    #[serde(default = "default_approach")]
    pub approach_m: f64,
    /// Distance after the exit gate before the run ends, m (default 20).
    #[serde(default = "default_exit")]
    pub exit_m: f64,
    /// Lower bound on the lane-5 width, m (default 3.0, our reading of the standard).
    #[serde(default = "default_lane5")]
    pub lane5_min_width_m: f64,
    /// Clearance the reference path keeps between the body and the gate boundaries, m (default 0.1).
    #[serde(default = "default_clearance")]
    pub clearance_m: f64,
}

/// `[maneuver]` with `kind = "sine_steer"`: open-loop sine steer at a held speed (dissertation Fig. 6.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SineSteerSpec {
    pub speed_mps: f64,
    /// Road-wheel amplitude, degrees.
    pub steer_amplitude_deg: f64,
    /// Sine period, s (default 10).
    #[serde(default = "default_period")]
    pub period_s: f64,
    /// Start of the sine, s (default 0).
    #[serde(default)]
    pub start_s: f64,
}

/// `[maneuver]` with `kind = "step_steer"`: open-loop ramped step steer at a held speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct StepSteerSpec {
    pub speed_mps: f64,
    /// Road-wheel angle, degrees.
    pub steer_amplitude_deg: f64,
    /// Start of the ramp, s (default 0).
    #[serde(default)]
    pub start_s: f64,
    /// Ramp duration, s (default 0.2).
    #[serde(default = "default_ramp")]
    pub ramp_s: f64,
}

/// `[maneuver]` with `kind = "straight"`: straight running following a speed schedule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct StraightSpec {
    /// [[t_s, v_mps], ...], piecewise linear, held beyond the ends.
    pub speed_schedule: Vec<[f64; 2]>,
}

/// Turn direction as written in specs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum DirectionSpec {
    Left,
    Right,
}

/// Constant-radius speed mode as written in specs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(crate) enum RadiusSpeedModeSpec {
    /// One speed held by the PID (`speed_mps`).
    Hold,
    /// Speed raised in steps of nominal lateral acceleration (`ay_*` keys).
    Steps,
}

fn left() -> DirectionSpec {
    DirectionSpec::Left
}
fn hold_radius() -> RadiusSpeedModeSpec {
    RadiusSpeedModeSpec::Hold
}
fn default_settle() -> f64 {
    10.0
}
fn default_window() -> f64 {
    3.0
}
fn default_speed_ramp() -> f64 {
    0.5
}

/// `[maneuver]` with `kind = "constant_radius"`: steady-state circular driving (ISO 4138 method 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ConstantRadiusSpec {
    /// Circle radius, m (> 0; ISO 4138 suggests 40 m or 100 m, among others).
    pub radius_m: f64,
    /// `left` (counter-clockwise, default) or `right`.
    #[serde(default = "left")]
    pub direction: DirectionSpec,
    /// `hold` (one speed, `speed_mps`; default) or `steps` (lateral-acceleration steps).
    #[serde(default = "hold_radius")]
    pub speed_mode: RadiusSpeedModeSpec,
    /// Held speed, m/s (speed_mode = hold).
    #[serde(default)]
    pub speed_mps: Option<f64>,
    /// Nominal lateral acceleration v^2/R of the first step, m/s^2 (steps; default ay_step_mps2).
    #[serde(default)]
    pub ay_first_mps2: Option<f64>,
    /// Increase of nominal lateral acceleration per step, m/s^2, in (0, 0.5] (steps; default 0.5).
    #[serde(default)]
    pub ay_step_mps2: Option<f64>,
    /// Largest nominal lateral acceleration, m/s^2 (steps; required).
    #[serde(default)]
    pub ay_max_mps2: Option<f64>,
    /// Settling time at the start of each step, s (default 10).
    #[serde(default = "default_settle")]
    pub settle_s: f64,
    /// Steady-state averaging window at the end of each step, s (default 3).
    #[serde(default = "default_window")]
    pub window_s: f64,
    /// Largest rate of the speed target between steps, m/s^2 (default 0.5).
    #[serde(default = "default_speed_ramp")]
    pub speed_ramp_mps2: f64,
}

/// A parsed `[maneuver]` table.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ManeuverSpec {
    Iso3888_2(Iso3888_2Spec),
    SineSteer(SineSteerSpec),
    StepSteer(StepSteerSpec),
    Straight(StraightSpec),
    ConstantRadius(ConstantRadiusSpec),
    Braking(BrakingSpec),
    Launch(LaunchSpec),
    BrakingInTurn(BrakingInTurnSpec),
}

/// The allowed ranges of the manoeuvre file's numeric keys, each declared once (README's
/// "Manoeuvre" table gives the same; `tests/spec_bounds.rs` holds the two together).
pub mod bounds {
    use vehsim_core::error::Bound;

    /// `surface.mu`: peak friction coefficient, (0, 2].
    pub const MU: Bound = Bound::left_open("surface.mu", 0.0, 2.0, "");
    /// `surface.temperature_c`: surface (ice) temperature, [-60, 40] degC.
    pub const TEMPERATURE_C: Bound = Bound::closed("surface.temperature_c", -60.0, 40.0, "degC");
    /// `driver.preview_time_s`: preview time of the path-following driver, [0, 5] s.
    pub const PREVIEW_TIME_S: Bound = Bound::closed("driver.preview_time_s", 0.0, 5.0, "s");
    /// `driver.preview_min_m`: shortest preview distance, [0.5, 100] m.
    pub const PREVIEW_MIN_M: Bound = Bound::closed("driver.preview_min_m", 0.5, 100.0, "m");
    /// `driver.gain`: gain on the preview correction, [0, 5], dimensionless.
    pub const GAIN: Bound = Bound::closed("driver.gain", 0.0, 5.0, "");
    /// `integrator.step_s`: integration step, (0, 0.05] s.
    pub const STEP_S: Bound = Bound::left_open("integrator.step_s", 0.0, 0.05, "s");
    /// `integrator.control_period_s`: controller sample period, (0, 1] s (a whole multiple of the step).
    pub const CONTROL_PERIOD_S: Bound = Bound::left_open("integrator.control_period_s", 0.0, 1.0, "s");
    /// `integrator.rtol`: relative tolerance of the adaptive methods, (0, 1).
    pub const RTOL: Bound = Bound::open("integrator.rtol", 0.0, 1.0, "");
    /// `integrator.atol`: absolute tolerance of the adaptive methods, (0, 1).
    pub const ATOL: Bound = Bound::open("integrator.atol", 0.0, 1.0, "");
    /// `output.interval_s`: interval between timeseries rows, (0, 10] s.
    pub const INTERVAL_S: Bound = Bound::left_open("output.interval_s", 0.0, 10.0, "s");
    /// `duration_s`: longest simulated time, (0, 3600] s.
    pub const DURATION_S: Bound = Bound::left_open("duration_s", 0.0, 3600.0, "s");
    /// `maneuver.speed_mps`: entry, held or start speed, (0, 100] m/s.
    pub const SPEED_MPS: Bound = Bound::left_open("maneuver.speed_mps", 0.0, 100.0, "m/s");
    /// `maneuver.steer_amplitude_deg`: road-wheel steer amplitude, [-60, 60] deg (positive left).
    pub const STEER_AMPLITUDE_DEG: Bound = Bound::closed("maneuver.steer_amplitude_deg", -60.0, 60.0, "deg");
    /// `maneuver.approach_m`: ISO 3888-2 run-up before the entry gate, [5, 1000] m.
    pub const APPROACH_M: Bound = Bound::closed("maneuver.approach_m", 5.0, 1000.0, "m");
    /// `maneuver.exit_m`: ISO 3888-2 distance after the exit gate, [0, 1000] m.
    pub const EXIT_M: Bound = Bound::closed("maneuver.exit_m", 0.0, 1000.0, "m");
    /// `maneuver.lane5_min_width_m`: lower bound on the ISO 3888-2 lane-5 width, [0, 10] m.
    pub const LANE5_MIN_WIDTH_M: Bound = Bound::closed("maneuver.lane5_min_width_m", 0.0, 10.0, "m");
    /// `maneuver.clearance_m`: clearance of the reference path from the gate boundaries, [0, 0.5] m.
    pub const CLEARANCE_M: Bound = Bound::closed("maneuver.clearance_m", 0.0, 0.5, "m");
    /// `maneuver.period_s`: sine-steer period, [0.05, 1000] s.
    pub const PERIOD_S: Bound = Bound::closed("maneuver.period_s", 0.05, 1000.0, "s");
    /// `maneuver.start_s`: start of the sine or of the steer ramp, [0, 3600] s.
    pub const START_S: Bound = Bound::closed("maneuver.start_s", 0.0, 3600.0, "s");
    /// `maneuver.ramp_s`: step-steer ramp duration, [0, 100] s.
    pub const RAMP_S: Bound = Bound::closed("maneuver.ramp_s", 0.0, 100.0, "s");
    /// `maneuver.radius_m`: circle radius, (0, 10000] m.
    pub const RADIUS_M: Bound = Bound::left_open("maneuver.radius_m", 0.0, 10_000.0, "m");
    /// `maneuver.settle_s`: settling time at the start of each constant-radius step, [0, 3600] s.
    pub const SETTLE_S: Bound = Bound::closed("maneuver.settle_s", 0.0, 3600.0, "s");
    /// `maneuver.window_s`: steady-state window at the end of each step, (0, 3600] s.
    pub const WINDOW_S: Bound = Bound::left_open("maneuver.window_s", 0.0, 3600.0, "s");
    /// `maneuver.speed_ramp_mps2`: largest rate of the speed target between steps, (0, 20] m/s^2.
    pub const SPEED_RAMP_MPS2: Bound = Bound::left_open("maneuver.speed_ramp_mps2", 0.0, 20.0, "m/s^2");
    /// `maneuver.ay_first_mps2`: nominal lateral acceleration of the first step, (0, 20] m/s^2.
    pub const AY_FIRST_MPS2: Bound = Bound::left_open("maneuver.ay_first_mps2", 0.0, 20.0, "m/s^2");

    /// Every bound above.
    pub const ALL: [Bound; 25] = [
        MU,
        TEMPERATURE_C,
        PREVIEW_TIME_S,
        PREVIEW_MIN_M,
        GAIN,
        STEP_S,
        CONTROL_PERIOD_S,
        RTOL,
        ATOL,
        INTERVAL_S,
        DURATION_S,
        SPEED_MPS,
        STEER_AMPLITUDE_DEG,
        APPROACH_M,
        EXIT_M,
        LANE5_MIN_WIDTH_M,
        CLEARANCE_M,
        PERIOD_S,
        START_S,
        RAMP_S,
        RADIUS_M,
        SETTLE_S,
        WINDOW_S,
        SPEED_RAMP_MPS2,
        AY_FIRST_MPS2,
    ];
}

/// The manoeuvre kinds of `[maneuver] kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ManeuverKind {
    /// ISO 3888-2 severe lane change.
    Iso3888_2,
    /// Open loop: sinusoidal steer.
    SineSteer,
    /// Open loop: a (ramped) steer step.
    StepSteer,
    /// Open loop: straight ahead on a speed schedule.
    Straight,
    /// ISO 4138 constant radius.
    ConstantRadius,
    /// Straight-line braking with the pedal at its stop.
    Braking,
    /// Launch from standstill at full throttle.
    Launch,
    /// Braking in a turn (after ISO 7975).
    BrakingInTurn,
}

vehsim_core::choice_names!(ManeuverKind {
    Iso3888_2 => "iso3888_2",
    SineSteer => "sine_steer",
    StepSteer => "step_steer",
    Straight => "straight",
    ConstantRadius => "constant_radius",
    Braking => "braking",
    Launch => "launch",
    BrakingInTurn => "braking_in_turn",
});

impl std::fmt::Display for ManeuverKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl ManeuverSpec {
    /// Parse a raw `[maneuver]` table: its `kind` selects the parameter set, whose keys are then
    /// checked with their full path (`maneuver.speed_mps`) in any message.
    pub fn from_table(path: &Path, table: &toml::Table) -> Result<Self> {
        let kind = match table.get("kind") {
            Some(toml::Value::String(k)) => k.clone(),
            Some(_) => return Err(Error::key(path, "maneuver.kind", "expected a string")),
            None => {
                return Err(Error::key(path, "maneuver.kind", format!("missing; allowed: {}", ManeuverKind::allowed())))
            }
        };
        let mut rest = table.clone();
        rest.remove("kind");
        fn parse<T: serde::de::DeserializeOwned>(path: &Path, t: toml::Table) -> Result<T> {
            serde_path_to_error::deserialize(toml::Value::Table(t)).map_err(|e| {
                let key = e.path().to_string();
                let key = if key.is_empty() || key == "." { "maneuver".to_string() } else { format!("maneuver.{key}") };
                // The toml value deserializer appends "in `key`" on a second line; the key is named already.
                let msg = e.into_inner().to_string();
                Error::key(path, &key, msg.lines().next().unwrap_or_default())
            })
        }
        Ok(match ManeuverKind::parse(&kind) {
            Some(ManeuverKind::Iso3888_2) => ManeuverSpec::Iso3888_2(parse(path, rest)?),
            Some(ManeuverKind::SineSteer) => ManeuverSpec::SineSteer(parse(path, rest)?),
            Some(ManeuverKind::StepSteer) => ManeuverSpec::StepSteer(parse(path, rest)?),
            Some(ManeuverKind::Straight) => ManeuverSpec::Straight(parse(path, rest)?),
            Some(ManeuverKind::ConstantRadius) => ManeuverSpec::ConstantRadius(parse(path, rest)?),
            Some(ManeuverKind::Braking) => ManeuverSpec::Braking(parse(path, rest)?),
            Some(ManeuverKind::Launch) => ManeuverSpec::Launch(parse(path, rest)?),
            Some(ManeuverKind::BrakingInTurn) => ManeuverSpec::BrakingInTurn(parse(path, rest)?),
            None => {
                return Err(Error::key(
                    path,
                    "maneuver.kind",
                    format!("unknown kind '{kind}'; allowed: {}", ManeuverKind::allowed()),
                ))
            }
        })
    }
}

fn hold() -> SpeedModeSpec {
    SpeedModeSpec::Hold
}

/// `[integrator]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorSection {
    /// `rk4` (fixed step), `dopri5` or `dop853` (adaptive between controller samples).
    #[serde(default = "rk4")]
    pub method: String,
    /// Integration step, s, in (0, 0.05] and within RK4's stability bound for the vehicle's
    /// fastest mode (default: the control period divided into the fewest whole steps with
    /// h |lambda| <= 2; see `sim::stability`). Where h |lambda| > 2, RK4 integrates the
    /// wheel-spin / transient-slip pairs exactly (exponential RK4), and the bound and the default
    /// are those of the fastest remaining mode.
    #[serde(default)]
    pub step_s: Option<f64>,
    /// Controller sample period, s, in (0, 1], a whole multiple of step_s (default: 0.01 s, or the
    /// whole multiple of a given step_s nearest to it).
    #[serde(default)]
    pub control_period_s: Option<f64>,
    /// Relative tolerance of the adaptive methods, in (0, 1) (default 1e-8).
    #[serde(default = "rtol")]
    pub rtol: f64,
    /// Absolute tolerance of the adaptive methods, in state units, in (0, 1) (default 1e-10).
    #[serde(default = "atol")]
    pub atol: f64,
}

fn rk4() -> String {
    "rk4".into()
}
fn rtol() -> f64 {
    1e-8
}
fn atol() -> f64 {
    1e-10
}

impl Default for IntegratorSection {
    fn default() -> Self {
        Self { method: rk4(), step_s: None, control_period_s: None, rtol: rtol(), atol: atol() }
    }
}

/// `[output]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// Interval between rows of timeseries.csv, s (rounded to whole steps; default 0.01).
    #[serde(default = "cs")]
    pub interval_s: f64,
    /// Write timeseries.csv (default true; large sweeps may want only the summaries).
    #[serde(default = "yes")]
    pub timeseries: bool,
    /// Draw the comparison plots after a run or batch (default true; skipped above 24 runs).
    #[serde(default = "yes")]
    pub plots: bool,
    /// Write a folder per run of a sweep (default true). With `runs = false` a sweep writes only
    /// summary.csv and the course layout once per vehicle (summary-only mode).
    #[serde(default = "yes")]
    pub runs: bool,
}

fn yes() -> bool {
    true
}

fn cs() -> f64 {
    0.01
}

impl Default for OutputSection {
    fn default() -> Self {
        Self { interval_s: cs(), timeseries: true, plots: true, runs: true }
    }
}

/// Raw manoeuvre file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManeuverFile {
    /// Run name: the output folder `results/<name>`; letters, digits, `_`, `-`, `.`.
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Vehicle file, relative to this file.
    pub vehicle: String,
    /// Tyre provider name.
    pub tyre_model: String,
    /// Vehicle model: `bicycle` (default) or `roll4dof` (needs the vehicle's `[roll]` section).
    #[serde(default)]
    pub vehicle_model: Option<String>,
    /// Longest simulated time, s (ISO 3888-2: default from the course length and speed).
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// Road surface: friction coefficient, temperature and friction law (`[surface]`).
    pub surface: SurfaceSection,
    /// The road's constant bank and grade (`[road]`; absent: flat).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub road: Option<RoadSection>,
    /// The manoeuvre table; its `kind` selects the parameter set (see `ManeuverSpec`).
    pub maneuver: toml::Table,
    /// Speed PID gains (`[speed_control]`; default kp 2000, ki 1000, kd 0, each >= 0).
    #[serde(default)]
    pub speed_control: PidParams,
    /// Path-following driver (`[driver]`): preview time and distance, gain, understeer compensation.
    #[serde(default)]
    pub driver: DriverParams,
    /// Integration method, step and controller period (`[integrator]`).
    #[serde(default)]
    pub integrator: IntegratorSection,
    /// Output switches and row interval (`[output]`).
    #[serde(default)]
    pub output: OutputSection,
    /// Contact-temperature estimate: `model = "isothermal"` (default) or `"atiim"` with its
    /// parameters (see docs/atiim.md).
    #[serde(default)]
    pub contact: ContactSpec,
    /// Anti-lock braking (`[abs]`; absent: off). See [`AbsSection`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub abs: Option<AbsSection>,
    /// Traction control (`[tcs]`; absent: off). See [`TcsSection`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tcs: Option<TcsSection>,
    /// Sweeps: dotted spec paths (`tyre_model`, `"surface.mu"`, `"maneuver.speed_mps"`, `vehicle`,
    /// any numeric key) mapped to lists of values; the batch runs their full product.
    #[serde(default)]
    pub sweep: Option<toml::Table>,
}

/// The validated manoeuvre, ready to instantiate.
#[derive(Debug, Clone, PartialEq)]
pub enum ManeuverConfig {
    /// ISO 3888-2 severe lane change.
    Iso3888_2(Iso3888_2Params),
    /// Open loop (sine steer, step steer, straight): a steer profile and a speed schedule.
    OpenLoop {
        /// Road-wheel steer angle versus time (zero for `straight`).
        steer: SteerProfile,
        /// Speed target versus time (one point for a held speed).
        speed: SpeedSchedule,
    },
    /// Constant radius (ISO 4138 method 1), held speed or lateral-acceleration steps.
    ConstantRadius(ConstantRadiusParams),
    /// Straight-line braking with the pedal at its stop.
    Braking(vehsim_core::maneuver::longitudinal::BrakingParams),
    /// Launch from standstill at full throttle.
    Launch(vehsim_core::maneuver::longitudinal::LaunchParams),
    /// Braking in a turn (after ISO 7975).
    BrakingInTurn(vehsim_core::maneuver::brake_in_turn::BrakeInTurnParams),
}

impl ManeuverConfig {
    /// Lowest and highest speed the manoeuvre asks for, m/s.
    pub fn speed_range_mps(&self) -> (f64, f64) {
        let fold =
            |it: &mut dyn Iterator<Item = f64>| it.fold((f64::INFINITY, 0.0_f64), |(a, b), v| (a.min(v), b.max(v)));
        let (lo, hi) = match self {
            ManeuverConfig::Iso3888_2(p) => (p.speed_mps, p.speed_mps),
            ManeuverConfig::OpenLoop { speed, .. } => fold(&mut speed.points.iter().map(|p| p.1)),
            ManeuverConfig::ConstantRadius(p) => fold(&mut p.step_speeds_mps.iter().copied()),
            // both reach standstill (or start from it)
            ManeuverConfig::Braking(p) => (0.0, p.speed_mps),
            ManeuverConfig::Launch(p) => (0.0, p.speed_mps),
            ManeuverConfig::BrakingInTurn(p) => (0.0, p.circle.step_speeds_mps[0]),
        };
        (if lo.is_finite() { lo } else { 0.0 }, hi)
    }
}

/// Vehicles already built from their files, keyed by (vehicle file, tyre model); see
/// [`ManeuverFile::build_cached`].
#[derive(Debug, Default)]
pub struct BuildCache {
    vehicles: std::collections::HashMap<(PathBuf, TyreModelKind), Vehicle>,
}

/// A fully validated run.
#[derive(Debug, Clone)]
pub struct RunConfig {
    /// The manoeuvre file the run was built from.
    pub spec_file: PathBuf,
    /// Run name (the results folder `results/<name>`).
    pub name: String,
    /// The vehicle file, resolved against the spec file.
    pub vehicle_file: PathBuf,
    /// The validated vehicle, its tyre built for `tyre_model` (and on the ice friction law when the surface has one).
    pub vehicle: Vehicle,
    /// Tyre force provider.
    pub tyre_model: TyreModelKind,
    /// Vehicle model: bicycle or 4-DOF roll.
    pub vehicle_model: VehicleModelKind,
    /// Surface friction and temperature.
    pub env: Environment,
    /// The validated manoeuvre.
    pub maneuver: ManeuverConfig,
    /// The manoeuvre kind as written in the spec.
    pub kind: ManeuverKind,
    /// Speed PID gains.
    pub pid: PidParams,
    /// Path-following driver parameters.
    pub driver: DriverParams,
    /// Time-stepping settings: method, step, control period, duration, output interval.
    pub settings: SimSettings,
    /// Output switches.
    pub output: OutputSection,
    /// The contact-temperature estimate (validated; built per run).
    pub contact: ContactSpec,
    /// ABS and traction control (validated; both off by default).
    pub slip: vehsim_core::sim::slip_control::SlipControlParams,
}

/// Fastest mode a run may have, 1/s: 100 times the sedan's on dry asphalt (250 1/s at 10 m/s).
/// Above it the default step would be below 80 us and the run of an ordinary manoeuvre would take
/// minutes; such a rate comes from a stiffness or inertia no car has.
pub(crate) const MAX_RATE_PER_S: f64 = 25_000.0;

/// Division counts up to which [`fewest_stable_division`] tries every count in turn; above it the
/// search bisects, assuming that a shorter step stays stable.
const DIVISIONS_SCANNED: usize = 16;

/// The refusal of a step `h` (s) at which the exponential RK4 is unstable for the model
/// linearised at straight running at `speeds` (m/s; analyses `a`), with the fastest mode's rate
/// `lambda` (1/s) and the longest stable step at the worse speed.
fn step_beyond_bound(
    path: &Path,
    h: f64,
    lambda: f64,
    a: &[vehsim_core::sim::stability::Analysis; 2],
    speeds: [f64; 2],
) -> Error {
    let (k, bound) =
        a.iter()
            .map(|x| x.exp_max_step(0.05))
            .enumerate()
            .fold((0, f64::INFINITY), |m, (k, b)| if b < m.1 { (k, b) } else { m });
    Error::key(
        path,
        "integrator.step_s",
        format!(
            "{h} s is beyond the stability bound of RK4 for this vehicle, even with the wheel-spin / \
             transient-slip pairs integrated exactly (the fastest mode has |lambda| = {lambda:.0} 1/s); \
             expected step_s <= {bound:.4} s (the longest step at which one such step of the model \
             linearised at straight running at {} m/s has a spectral radius <= 1), or leave step_s \
             unset for the default",
            speeds[k]
        ),
    )
}

/// The longest step `period / n` (n = 1, 2, ... below the `period / h` divisions of the plain
/// step `h`) for which `stable` holds, or `None`. The first `DIVISIONS_SCANNED` counts are tried
/// in turn (the shipped vehicles settle there); beyond them the count is found by bisection, so
/// the search costs at most about 16 + log2(period / h) stability checks whatever the inputs.
pub fn fewest_stable_division(period: f64, h: f64, stable: impl Fn(f64) -> bool) -> Option<f64> {
    let n_plain = (period / h).round();
    // Counts beyond usize (or NaN from a NaN rate) are clamped; bisection keeps the search short.
    let n_plain = if n_plain.is_finite() && n_plain >= 1.0 { n_plain.min(1e15) as usize } else { return None };
    let last = n_plain.saturating_sub(1);
    let scanned = last.min(DIVISIONS_SCANNED);
    if let Some(n) = (1..=scanned).find(|&n| stable(period / n as f64)) {
        return Some(period / n as f64);
    }
    if last <= DIVISIONS_SCANNED || !stable(period / last as f64) {
        return None;
    }
    // stable(period / hi) holds and stable(period / lo) does not.
    let (mut lo, mut hi) = (DIVISIONS_SCANNED, last);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if stable(period / mid as f64) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(period / hi as f64)
}

/// Is `name` usable as a results folder name?
pub fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 100
        && !name.starts_with('.')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == '.')
}

impl ManeuverFile {
    /// Read and parse a manoeuvre file (refusing a spec of another command); nothing is validated yet.
    pub fn load(path: &Path) -> Result<Self> {
        let text = read_input(path)?;
        super::kind::expect_text(path, &text, super::kind::SpecKind::Run)?;
        parse_toml(path, &text)
    }

    /// Parse an already-read TOML table (used for sweep combinations), naming keys by their path.
    pub fn from_table(path: &Path, table: toml::Table) -> Result<Self> {
        let value = toml::Value::Table(table);
        super::strict::check::<Self>(path, &value)?;
        serde_path_to_error::deserialize(value).map_err(|e| {
            let key = e.path().to_string();
            let msg = e.into_inner().to_string();
            Error::key(path, &key, msg.lines().next().unwrap_or_default())
        })
    }

    /// Validate everything (the vehicle and tyre files included) into a [`RunConfig`].
    pub fn build(&self, path: &Path) -> Result<RunConfig> {
        self.build_cached(path, &mut BuildCache::default())
    }

    /// As [`ManeuverFile::build`], reading each vehicle file (with its tyre and `.tir` files) once
    /// per (file, tyre model) over the builds that share `cache` (a sweep's combinations).
    pub fn build_cached(&self, path: &Path, cache: &mut BuildCache) -> Result<RunConfig> {
        let c = Checker::new(path);
        self.check_name(path)?;
        let tyre_model: TyreModelKind =
            self.tyre_model.parse().map_err(|e: String| Error::key(path, "tyre_model", e))?;
        c.bound(&bounds::MU, self.surface.mu)?;
        c.bound(&bounds::TEMPERATURE_C, self.surface.temperature_c)?;
        self.check_controllers(&c)?;
        let method = self.integrator_method(&c)?;
        c.bound(&bounds::INTERVAL_S, self.output.interval_s)?;
        let (maneuver, kind, default_duration) = self.build_maneuver(&c)?;
        let duration_s = match self.duration_s {
            Some(v) => c.bound(&bounds::DURATION_S, v)?,
            None => default_duration
                .ok_or_else(|| Error::key(path, "duration_s", "required for this manoeuvre kind (s)"))?,
        };
        // Validate the contact table now (builds and caches the ATIIM flash table once).
        self.contact.build(path, 4, self.surface.temperature_c)?;
        let vehicle_model = self.vehicle_model_kind(path)?;
        let (vehicle_file, vehicle) = self.vehicle(path, tyre_model, vehicle_model, cache)?;
        let (step_s, control_period_s, exp) =
            self.step_and_period(path, &vehicle, vehicle_model, &maneuver, method == Method::Rk4)?;
        let method = if exp { Method::Rk4Exp } else { method };
        Ok(RunConfig {
            spec_file: path.to_path_buf(),
            name: self.name.clone(),
            vehicle_file,
            vehicle,
            tyre_model,
            vehicle_model,
            env: Environment {
                mu: self.surface.mu,
                surface_temp_c: self.surface.temperature_c,
                regions: self.surface.regions(path)?,
                road: match &self.road {
                    Some(r) => r.road(path, self.surface.mu)?,
                    None => vehsim_core::vehicle::road::Road::FLAT,
                },
            },
            maneuver,
            kind,
            pid: self.speed_control,
            driver: self.driver,
            settings: SimSettings {
                method,
                step_s,
                control_period_s,
                duration_s,
                output_interval_s: self.output.interval_s,
            },
            output: self.output.clone(),
            contact: self.contact.clone(),
            slip: self.slip_control(&c, step_s)?,
        })
    }

    /// The run's name makes a usable folder name.
    fn check_name(&self, path: &Path) -> Result<()> {
        if !valid_name(&self.name) {
            return Err(Error::key(
                path,
                "name",
                format!(
                    "'{}' is not a usable folder name; use 1-100 letters, digits, '_', '-', '.', not starting with '.'",
                    self.name
                ),
            ));
        }
        Ok(())
    }

    /// The speed controller's gains and the driver's preview and gain within their ranges.
    fn check_controllers(&self, c: &Checker) -> Result<()> {
        let p = &self.speed_control;
        c.non_negative("speed_control.kp", p.kp)?;
        c.non_negative("speed_control.ki", p.ki)?;
        c.non_negative("speed_control.kd", p.kd)?;
        let d = &self.driver;
        c.bound(&bounds::PREVIEW_TIME_S, d.preview_time_s)?;
        c.bound(&bounds::PREVIEW_MIN_M, d.preview_min_m)?;
        c.bound(&bounds::GAIN, d.gain)?;
        Ok(())
    }

    /// The integrator (with its step, control period and tolerances checked).
    fn integrator_method(&self, c: &Checker) -> Result<Method> {
        let i = &self.integrator;
        if let Some(h) = i.step_s {
            c.bound(&bounds::STEP_S, h)?;
        }
        if let Some(cp) = i.control_period_s {
            c.bound(&bounds::CONTROL_PERIOD_S, cp)?;
            if let Some(h) = i.step_s {
                let m = (cp / h).round();
                c.require(
                    "integrator.control_period_s",
                    cp,
                    m >= 1.0 && (m * h - cp).abs() <= 1e-9 * cp,
                    &format!("expected a whole multiple of step_s = {h} s (at least one step)"),
                )?;
            }
        }
        let tolerances =
            || -> Result<(f64, f64)> { Ok((c.bound(&bounds::RTOL, i.rtol)?, c.bound(&bounds::ATOL, i.atol)?)) };
        match i.method.as_str() {
            "rk4" => Ok(Method::Rk4),
            "dopri5" => tolerances().map(|(rtol, atol)| Method::Dopri5 { rtol, atol }),
            "dop853" => tolerances().map(|(rtol, atol)| Method::Dop853 { rtol, atol }),
            other => Err(Error::key(
                c.file,
                "integrator.method",
                format!("unknown method '{other}'; allowed: rk4, dopri5, dop853"),
            )),
        }
    }

    /// The vehicle model (`vehicle_model`; default the bicycle).
    fn vehicle_model_kind(&self, path: &Path) -> Result<VehicleModelKind> {
        match self.vehicle_model.as_deref() {
            None => Ok(VehicleModelKind::Bicycle),
            Some(name) => VehicleModelKind::parse(name).ok_or_else(|| {
                Error::key(
                    path,
                    "vehicle_model",
                    format!("unknown vehicle model '{name}'; allowed: {}", VehicleModelKind::allowed()),
                )
            }),
        }
    }

    /// The vehicle file's path and the validated vehicle (built once per file and tyre model in
    /// `cache`), checked against the vehicle model, its tyre on the surface's ice friction law.
    fn vehicle(
        &self,
        path: &Path,
        tyre_model: TyreModelKind,
        vehicle_model: VehicleModelKind,
        cache: &mut BuildCache,
    ) -> Result<(PathBuf, Vehicle)> {
        let vehicle_file = resolve(path, &self.vehicle);
        let key = (vehicle_file.clone(), tyre_model);
        let vehicle = match cache.vehicles.get(&key) {
            Some(v) => v.clone(),
            None => {
                let v = VehicleFile::load(&vehicle_file)
                    .and_then(|v| v.build(&vehicle_file, tyre_model))
                    .map_err(vehsim_core::error::referred_by(path, "vehicle"))?;
                cache.vehicles.insert(key, v.clone());
                v
            }
        };
        if vehicle_model == VehicleModelKind::Roll4Dof && vehicle.roll.is_none() {
            return Err(Error::key(
                path,
                "vehicle_model",
                format!(
                    "'roll4dof' needs a [roll] section in the vehicle file {}, which has none (or use 'bicycle')",
                    vehicle_file.display()
                ),
            ));
        }
        if let (VehicleModelKind::Roll4Dof, Some(key)) = (vehicle_model, vehicle.lateral.first_active_key()) {
            return Err(Error::key(
                &vehicle_file,
                key,
                format!(
                    "the 4-DOF model (vehicle_model = \"roll4dof\" in {}) does not model [lateral]; remove the \
                 section or use the bicycle model",
                    path.display()
                ),
            ));
        }
        if vehicle_model == VehicleModelKind::Roll4Dof
            && !(self.surface.patch.is_empty() && self.surface.band.is_empty() && self.surface.stretch.is_empty())
        {
            return Err(Error::key(
                path,
                "surface.patch",
                "the 4-DOF model does not model friction regions; remove [[surface.patch]], [[surface.band]] and \
                 [[surface.stretch]] or \
                 use the bicycle model",
            ));
        }
        if let (VehicleModelKind::Roll4Dof, Some(_)) = (vehicle_model, &self.road) {
            return Err(Error::key(
                path,
                "road",
                "the 4-DOF model does not model a banked or graded road; remove [road] or use the bicycle model",
            ));
        }
        self.check_tread_state(path, &vehicle_file, &vehicle)?;
        // The ice friction law: the Magic Formula tyres take their peak friction from it.
        let mut vehicle = vehicle;
        if let Some(law) = self.surface.friction(path)? {
            vehicle.tyre = vehicle.tyre.on_ice(&law);
        }
        Ok((vehicle_file, vehicle))
    }

    /// The tread state (`[lateral] tread_*`) is the run's contact-temperature estimate: it cannot
    /// run beside another estimate (`[contact] model = "atiim"`) or beside the thermal form
    /// (`thermal_mu_per_k`), which reads the other estimate's temperature.
    fn check_tread_state(&self, path: &Path, vehicle_file: &Path, vehicle: &Vehicle) -> Result<()> {
        let lat = &vehicle.lateral;
        if lat.tread_mu_per_kj == 0.0 {
            return Ok(());
        }
        if lat.thermal_mu_per_k != 0.0 {
            return Err(Error::key(
                vehicle_file,
                "lateral.thermal_mu_per_k",
                "expected 0 when lateral.tread_mu_per_kj is set: the tread state is the contact temperature \
                 the friction change reads; keep one thermal form",
            ));
        }
        if self.contact.kind(path)? != ContactModelKind::Isothermal {
            return Err(Error::key(
                path,
                "contact.model",
                format!(
                    "expected \"isothermal\" (the default): the vehicle {} sets lateral.tread_mu_per_kj, whose \
                     tread state is this run's contact-temperature estimate",
                    vehicle_file.display()
                ),
            ));
        }
        Ok(())
    }

    /// The integration step and control period (see [`IntegratorSection`]), and whether RK4 is to
    /// carry the wheel-spin / transient-slip pairs exponentially (`sim::stability`): where
    /// h |lambda| of the fastest mode would exceed 2, over the manoeuvre's speed range. A step at
    /// which that scheme is not stable for the linearised model is refused.
    fn step_and_period(
        &self,
        path: &Path,
        vehicle: &Vehicle,
        model: VehicleModelKind,
        maneuver: &ManeuverConfig,
        rk4: bool,
    ) -> Result<(f64, f64, bool)> {
        use vehsim_core::sim::stability::{
            analyse, default_step_s, DEFAULT_CONTROL_PERIOD_S, DEFAULT_H_LAMBDA, EXP_MARGIN,
        };
        let i = &self.integrator;
        // One default period for every model, provider and contact estimate (`DEFAULT_CONTROL_PERIOD_S`).
        let default_cp = DEFAULT_CONTROL_PERIOD_S;
        let env = Environment {
            mu: self.surface.mu,
            surface_temp_c: self.surface.temperature_c,
            regions: vehsim_core::vehicle::ground::GroundRegions::NONE,
            road: vehsim_core::vehicle::road::Road::FLAT,
        };
        let (lo, hi) = maneuver.speed_range_mps();
        let speeds = [lo.max(1.0), hi.max(1.0)];
        let at = |v: f64| match (model, &vehicle.roll) {
            (VehicleModelKind::Roll4Dof, Some(roll)) => {
                analyse(&vehsim_core::vehicle::Roll4Dof::new(vehicle.clone(), roll.clone()), &env, v)
            }
            _ => analyse(&vehsim_core::vehicle::Bicycle::new(vehicle.clone()), &env, v),
        };
        let a = speeds.map(at);
        let lambda = a.iter().map(|x| x.rate_per_s).fold(0.0, f64::max);
        let rate_nan = a.iter().any(|x| !x.rate_per_s.is_finite());
        Self::check_rate(path, &resolve(path, &self.vehicle), if rate_nan { f64::INFINITY } else { lambda })?;
        let stable = |h: f64| a.iter().all(|x| x.exp_stable(h));
        match i.step_s {
            Some(h) => {
                let exp = rk4 && h * lambda > DEFAULT_H_LAMBDA;
                if exp && !stable(h) {
                    return Err(step_beyond_bound(path, h, lambda, &a, speeds));
                }
                let cp = i.control_period_s.unwrap_or(h * (default_cp / h).round().max(1.0));
                Ok((h, cp, exp))
            }
            None => {
                let cp = i.control_period_s.unwrap_or(default_cp);
                if !rk4 {
                    return Ok((cp, cp, false));
                }
                // Below the regularisation wheel speed omega_1 the brake and rolling-resistance
                // torques are stiff, up to TORQUE_RATE_MAX (crates/vehsim-core/src/vehicle/wheel.rs), a rate the
                // linearisation at free rolling does not see and the exponential RK4 leaves
                // explicit: a manoeuvre whose speed range reaches twice that speed (a stop) takes
                // it into the step's bound.
                let share = vehicle.brake_front_share.max(1.0 - vehicle.brake_front_share);
                let omega1 = 1.5 * vehicle.brake_torque_max_nm * share
                    / (2.0 * vehicle.wheel_inertia_kgm2 * vehsim_core::vehicle::wheel::TORQUE_RATE_MAX);
                if lo < 2.0 * omega1 * vehicle.tyre.rolling_radius_m {
                    let lambda = lambda.max(vehsim_core::vehicle::wheel::TORQUE_RATE_MAX);
                    return Ok((default_step_s(cp, lambda), cp, false));
                }
                let h = default_step_s(cp, lambda);
                // Plain RK4 would need several steps per period: the exponential one may take fewer.
                let fewer = fewest_stable_division(cp, h, |he| stable(EXP_MARGIN * he));
                Ok(match fewer {
                    Some(he) => (he, cp, true),
                    None => (h, cp, false),
                })
            }
        }
    }

    /// Bad input when the fastest mode of the linearised vehicle is so fast (a stiffness or an
    /// inertia far outside a car's) that no step the engine can take in reasonable time resolves
    /// it: `lambda` (1/s) above [`MAX_RATE_PER_S`], which the plain RK4 default would need steps
    /// shorter than 2 / lambda for.
    fn check_rate(path: &Path, vehicle_file: &Path, lambda: f64) -> Result<()> {
        if lambda.is_finite() && lambda <= MAX_RATE_PER_S {
            return Ok(());
        }
        let shown = if lambda.is_finite() { vehsim_core::error::short_num(lambda.round()) } else { "infinite".into() };
        Err(Error::input(
            vehicle_file,
            format!(
                "the vehicle's fastest mode (linearised at straight running) has |lambda| = {shown} 1/s, above the \
                 {} 1/s of any car model this engine resolves (it would need steps under {} s); check the tyre's \
                 stiffnesses and Magic Formula coefficients, the wheel inertia and any short lag ([lateral] \
                 steer_lag_s, [roll] load_transfer_lag_s) (named by {} key 'vehicle')",
                vehsim_core::error::short_num(MAX_RATE_PER_S),
                vehsim_core::error::short_num(2.0 / MAX_RATE_PER_S),
                path.display()
            ),
        ))
    }

    fn build_maneuver(&self, c: &Checker) -> Result<Built> {
        match &ManeuverSpec::from_table(c.file, &self.maneuver)? {
            ManeuverSpec::Iso3888_2(s) => s.build(c),
            ManeuverSpec::SineSteer(s) => s.build(c),
            ManeuverSpec::StepSteer(s) => s.build(c),
            ManeuverSpec::Straight(s) => s.build(c),
            ManeuverSpec::Braking(b) => {
                let p = b.build(c)?;
                let total = p.brake_at_s + 2.0 * p.speed_mps / LONGITUDINAL_MIN_DECEL + 2.0;
                Ok((ManeuverConfig::Braking(p), ManeuverKind::Braking, Some(total)))
            }
            ManeuverSpec::BrakingInTurn(b) => {
                let p = b.build(c)?;
                let total = p.brake_at_s + p.after_s + 0.5;
                Ok((ManeuverConfig::BrakingInTurn(p), ManeuverKind::BrakingInTurn, Some(total)))
            }
            ManeuverSpec::Launch(l) => {
                let v = speed(c, l.speed_mps)?;
                let p = vehsim_core::maneuver::longitudinal::LaunchParams { speed_mps: v };
                Ok((ManeuverConfig::Launch(p), ManeuverKind::Launch, Some(2.0 * v / LONGITUDINAL_MIN_DECEL + 2.0)))
            }
            ManeuverSpec::ConstantRadius(s) => s.build(c),
        }
    }
}

/// What a manoeuvre spec builds: the validated manoeuvre, its kind and its default duration, s
/// (`None`: the spec must give one).
type Built = (ManeuverConfig, ManeuverKind, Option<f64>);

/// An entry speed within its bound, m/s.
fn speed(c: &Checker, v: f64) -> Result<f64> {
    c.bound(&bounds::SPEED_MPS, v)
}

/// A steer amplitude within its bound, deg.
fn steer(c: &Checker, v: f64) -> Result<f64> {
    c.bound(&bounds::STEER_AMPLITUDE_DEG, v)
}

impl Iso3888_2Spec {
    fn build(&self, c: &Checker) -> Result<Built> {
        let v = speed(c, self.speed_mps)?;
        c.bound(&bounds::APPROACH_M, self.approach_m)?;
        c.bound(&bounds::EXIT_M, self.exit_m)?;
        c.bound(&bounds::LANE5_MIN_WIDTH_M, self.lane5_min_width_m)?;
        c.bound(&bounds::CLEARANCE_M, self.clearance_m)?;
        let mode = match self.speed_mode {
            SpeedModeSpec::Hold => SpeedMode::Hold,
            SpeedModeSpec::Coast => SpeedMode::Coast,
        };
        let params = Iso3888_2Params {
            speed_mps: v,
            mode,
            approach_m: self.approach_m,
            exit_m: self.exit_m,
            lane5_min_width_m: self.lane5_min_width_m,
            clearance_m: self.clearance_m,
        };
        // Twice the time of the run's length at the entry speed, plus 5 s.
        Ok((ManeuverConfig::Iso3888_2(params), ManeuverKind::Iso3888_2, Some(2.0 * params.run_length_m() / v + 5.0)))
    }
}

impl SineSteerSpec {
    fn build(&self, c: &Checker) -> Result<Built> {
        let v = speed(c, self.speed_mps)?;
        let a = steer(c, self.steer_amplitude_deg)?;
        c.bound(&bounds::PERIOD_S, self.period_s)?;
        c.bound(&bounds::START_S, self.start_s)?;
        let steer =
            SteerProfile::Sine { amplitude_rad: a.to_radians(), period_s: self.period_s, start_s: self.start_s };
        Ok((ManeuverConfig::OpenLoop { steer, speed: SpeedSchedule::constant(v) }, ManeuverKind::SineSteer, None))
    }
}

impl StepSteerSpec {
    fn build(&self, c: &Checker) -> Result<Built> {
        let v = speed(c, self.speed_mps)?;
        let a = steer(c, self.steer_amplitude_deg)?;
        c.bound(&bounds::START_S, self.start_s)?;
        c.bound(&bounds::RAMP_S, self.ramp_s)?;
        let steer = SteerProfile::Step { amplitude_rad: a.to_radians(), start_s: self.start_s, ramp_s: self.ramp_s };
        Ok((ManeuverConfig::OpenLoop { steer, speed: SpeedSchedule::constant(v) }, ManeuverKind::StepSteer, None))
    }
}

impl StraightSpec {
    fn build(&self, c: &Checker) -> Result<Built> {
        if self.speed_schedule.is_empty() {
            return Err(Error::key(c.file, "maneuver.speed_schedule", "expected at least one [t_s, v_mps] pair"));
        }
        let mut prev = f64::NEG_INFINITY;
        for (n, [t, v]) in self.speed_schedule.iter().enumerate() {
            let key = format!("maneuver.speed_schedule[{n}]");
            c.require(&key, *t, t.is_finite() && *t >= 0.0 && *t > prev, "expected times >= 0, strictly increasing")?;
            c.range(&key, *v, 0.0, 100.0)?;
            prev = *t;
        }
        let speed = SpeedSchedule { points: self.speed_schedule.iter().map(|p| (p[0], p[1])).collect() };
        Ok((ManeuverConfig::OpenLoop { steer: SteerProfile::Zero, speed }, ManeuverKind::Straight, None))
    }
}

impl ConstantRadiusSpec {
    fn build(&self, c: &Checker) -> Result<Built> {
        let r = c.bound(&bounds::RADIUS_M, self.radius_m)?;
        c.bound(&bounds::SETTLE_S, self.settle_s)?;
        c.bound(&bounds::WINDOW_S, self.window_s)?;
        c.bound(&bounds::SPEED_RAMP_MPS2, self.speed_ramp_mps2)?;
        let not_for = |key: &str, mode: &str| {
            Error::key(c.file, &format!("maneuver.{key}"), format!("not used with speed_mode = \"{mode}\"; remove it"))
        };
        let speeds = match self.speed_mode {
            RadiusSpeedModeSpec::Hold => {
                for (k, v) in [
                    ("ay_first_mps2", self.ay_first_mps2),
                    ("ay_step_mps2", self.ay_step_mps2),
                    ("ay_max_mps2", self.ay_max_mps2),
                ] {
                    if v.is_some() {
                        return Err(not_for(k, "hold"));
                    }
                }
                let v = self.speed_mps.ok_or_else(|| {
                    Error::key(c.file, "maneuver.speed_mps", "required with speed_mode = \"hold\" (m/s)")
                })?;
                vec![speed(c, v)?]
            }
            RadiusSpeedModeSpec::Steps => {
                if self.speed_mps.is_some() {
                    return Err(not_for("speed_mps", "steps"));
                }
                let step = self.ay_step_mps2.unwrap_or(0.5);
                c.require(
                    "maneuver.ay_step_mps2",
                    step,
                    step > 0.0 && step <= 0.5,
                    "expected 0 < ay_step_mps2 <= 0.5 (m/s^2; ISO 4138 steps)",
                )?;
                let first = self.ay_first_mps2.unwrap_or(step);
                c.bound(&bounds::AY_FIRST_MPS2, first)?;
                let max = self.ay_max_mps2.ok_or_else(|| {
                    Error::key(c.file, "maneuver.ay_max_mps2", "required with speed_mode = \"steps\" (m/s^2)")
                })?;
                c.require(
                    "maneuver.ay_max_mps2",
                    max,
                    max >= first && max <= 20.0 && (max - first) / step <= 200.0,
                    "expected ay_first_mps2 <= ay_max_mps2 <= 20 (m/s^2), at most 200 steps",
                )?;
                let v = ConstantRadiusParams::stepped_speeds(r, first, step, max);
                if let Some(top) = v.last() {
                    c.require("maneuver.ay_max_mps2", max, *top <= 100.0, "the top step would exceed 100 m/s")?;
                }
                v
            }
        };
        let direction = match self.direction {
            DirectionSpec::Left => Direction::Left,
            DirectionSpec::Right => Direction::Right,
        };
        // The steady-state window must not fall inside a speed ramp.
        let longest_ramp_s = speeds.windows(2).map(|w| (w[1] - w[0]).abs() / self.speed_ramp_mps2).fold(0.0, f64::max);
        c.require(
            "maneuver.speed_ramp_mps2",
            self.speed_ramp_mps2,
            longest_ramp_s <= self.settle_s,
            &format!(
                "the largest speed step takes {longest_ramp_s:.1} s at this ramp, longer than settle_s = {} s; raise speed_ramp_mps2 or settle_s",
                self.settle_s
            ),
        )?;
        let params = ConstantRadiusParams {
            radius_m: r,
            direction,
            step_speeds_mps: speeds,
            settle_s: self.settle_s,
            window_s: self.window_s,
            speed_ramp_mps2: self.speed_ramp_mps2,
        };
        let total = params.total_s();
        c.require("maneuver.window_s", self.window_s, total <= 3600.0, "the whole schedule must fit in 3600 s")?;
        Ok((ManeuverConfig::ConstantRadius(params), ManeuverKind::ConstantRadius, Some(total + 0.5)))
    }
}

/// The slowest mean acceleration (m/s^2) the default duration of a braking or launch run allows
/// for, twice over: 0.05 g.
const LONGITUDINAL_MIN_DECEL: f64 = 0.05 * vehsim_core::vehicle::GRAVITY;

/// `[maneuver]` with `kind = "braking"`: straight-line braking with the pedal at its stop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BrakingSpec {
    /// Start speed, m/s.
    pub speed_mps: f64,
    /// End speed, m/s, below the start speed (default 0: standstill).
    #[serde(default)]
    pub end_speed_mps: f64,
    /// Brake onset, s (default 0.5; the PID holds the start speed before it).
    #[serde(default = "half_second")]
    pub brake_at_s: f64,
}

fn half_second() -> f64 {
    0.5
}

/// `[maneuver]` with `kind = "launch"`: from standstill at full throttle to a speed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LaunchSpec {
    /// Target speed, m/s.
    pub speed_mps: f64,
}

impl BrakingSpec {
    fn build(&self, c: &Checker) -> Result<vehsim_core::maneuver::longitudinal::BrakingParams> {
        let v = c.bound(&bounds::SPEED_MPS, self.speed_mps)?;
        c.require(
            "maneuver.end_speed_mps",
            self.end_speed_mps,
            self.end_speed_mps >= 0.0 && self.end_speed_mps < v,
            &format!("expected 0 <= end_speed_mps < speed_mps = {v} (m/s)"),
        )?;
        c.bound(&bounds::START_S, self.brake_at_s)?;
        Ok(vehsim_core::maneuver::longitudinal::BrakingParams {
            speed_mps: v,
            end_speed_mps: self.end_speed_mps,
            brake_at_s: self.brake_at_s,
        })
    }
}

/// `[abs]`: anti-lock braking on for the run ([`vehsim_core::control::abs`]); every key optional.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AbsSection {
    /// `false` switches the ABS off (default true; lets a sweep compare on and off).
    pub enabled: Option<bool>,
    /// Sample period, s, a whole multiple of the integration step (default 0.01).
    pub period_s: Option<f64>,
    /// Slip magnitude beyond which the pressure is dumped, in (0, 1) (default 0.15).
    pub slip_dump: Option<f64>,
    /// Slip magnitude below which the pressure builds again, in (0, slip_dump) (default 0.06).
    pub slip_build: Option<f64>,
    /// Pressure fall rate, fraction of full pressure per s, (0, 1000] (default 20).
    pub dump_rate_per_s: Option<f64>,
    /// Pressure rise rate, fraction of full pressure per s, (0, 1000] (default 6).
    pub build_rate_per_s: Option<f64>,
    /// Speed below which the ABS stops modulating, m/s, [0, 10] (default 1.5).
    pub cutout_speed_mps: Option<f64>,
}

/// `[tcs]`: traction control on for the run ([`vehsim_core::control::tcs`]); every key optional.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TcsSection {
    /// `false` switches the traction control off (default true; lets a sweep compare on and off).
    pub enabled: Option<bool>,
    /// Sample period, s, a whole multiple of the integration step (default 0.01).
    pub period_s: Option<f64>,
    /// Slip above which the drive torque is reduced, in (0, 1) (default 0.15).
    pub slip_high: Option<f64>,
    /// Slip below which it is restored, in (0, slip_high) (default 0.10).
    pub slip_low: Option<f64>,
    /// Reduction rate, fraction of the largest drive torque per s, (0, 1000] (default 30).
    pub reduction_rate_per_s: Option<f64>,
    /// Restore rate, fraction of the largest drive torque per s, (0, 1000] (default 5).
    pub restore_rate_per_s: Option<f64>,
}

/// The allowed ranges of the `[abs]` and `[tcs]` keys.
pub mod slip_bounds {
    use vehsim_core::error::Bound;

    /// `abs.period_s`: ABS sample period, (0, 0.1] s.
    pub const ABS_PERIOD_S: Bound = Bound::left_open("abs.period_s", 0.0, 0.1, "s");
    /// `abs.slip_dump`: slip magnitude beyond which the pressure is dumped, (0, 1).
    pub const SLIP_DUMP: Bound = Bound::open("abs.slip_dump", 0.0, 1.0, "");
    /// `abs.slip_build`: slip magnitude below which the pressure builds again, (0, 1) (and below `slip_dump`).
    pub const SLIP_BUILD: Bound = Bound::open("abs.slip_build", 0.0, 1.0, "");
    /// `abs.dump_rate_per_s`: pressure fall rate, (0, 1000] fractions of full pressure per s.
    pub const DUMP_RATE: Bound = Bound::left_open("abs.dump_rate_per_s", 0.0, 1000.0, "1/s");
    /// `abs.build_rate_per_s`: pressure rise rate, (0, 1000] fractions of full pressure per s.
    pub const BUILD_RATE: Bound = Bound::left_open("abs.build_rate_per_s", 0.0, 1000.0, "1/s");
    /// `abs.cutout_speed_mps`: speed below which the ABS stops modulating, [0, 10] m/s.
    pub const CUTOUT: Bound = Bound::closed("abs.cutout_speed_mps", 0.0, 10.0, "m/s");
    /// `tcs.period_s`: traction-control sample period, (0, 0.1] s.
    pub const TCS_PERIOD_S: Bound = Bound::left_open("tcs.period_s", 0.0, 0.1, "s");
    /// `tcs.slip_high`: slip above which the drive torque is reduced, (0, 1).
    pub const SLIP_HIGH: Bound = Bound::open("tcs.slip_high", 0.0, 1.0, "");
    /// `tcs.slip_low`: slip below which the drive torque is restored, (0, 1) (and below `slip_high`).
    pub const SLIP_LOW: Bound = Bound::open("tcs.slip_low", 0.0, 1.0, "");
    /// `tcs.reduction_rate_per_s`: torque reduction rate, (0, 1000] fractions of the largest drive torque per s.
    pub const REDUCTION_RATE: Bound = Bound::left_open("tcs.reduction_rate_per_s", 0.0, 1000.0, "1/s");
    /// `tcs.restore_rate_per_s`: torque restore rate, (0, 1000] fractions of the largest drive torque per s.
    pub const RESTORE_RATE: Bound = Bound::left_open("tcs.restore_rate_per_s", 0.0, 1000.0, "1/s");
}

impl ManeuverFile {
    /// The validated `[abs]` and `[tcs]` sections for integration step `step_s` (s).
    fn slip_control(&self, c: &Checker, step_s: f64) -> Result<vehsim_core::sim::slip_control::SlipControlParams> {
        use slip_bounds as b;
        use vehsim_core::control::abs::AbsParams;
        use vehsim_core::control::tcs::TcsParams;
        let period = |bound: &vehsim_core::error::Bound, v: f64| -> Result<f64> {
            c.bound(bound, v)?;
            let m = (v / step_s).round();
            c.require(
                bound.key,
                v,
                m >= 1.0 && (m * step_s - v).abs() <= 1e-9 * v,
                &format!("expected a whole multiple of the integration step {step_s} s (at least one step)"),
            )
        };
        let abs = match &self.abs {
            None => None,
            Some(a) if a.enabled == Some(false) => None,
            Some(a) => {
                let d = AbsParams::default();
                let p = AbsParams {
                    period_s: period(&b::ABS_PERIOD_S, a.period_s.unwrap_or(d.period_s))?,
                    slip_dump: c.bound(&b::SLIP_DUMP, a.slip_dump.unwrap_or(d.slip_dump))?,
                    slip_build: c.bound(&b::SLIP_BUILD, a.slip_build.unwrap_or(d.slip_build))?,
                    dump_rate_per_s: c.bound(&b::DUMP_RATE, a.dump_rate_per_s.unwrap_or(d.dump_rate_per_s))?,
                    build_rate_per_s: c.bound(&b::BUILD_RATE, a.build_rate_per_s.unwrap_or(d.build_rate_per_s))?,
                    cutout_speed_mps: c.bound(&b::CUTOUT, a.cutout_speed_mps.unwrap_or(d.cutout_speed_mps))?,
                };
                c.require(
                    "abs.slip_build",
                    p.slip_build,
                    p.slip_build < p.slip_dump,
                    &format!("expected slip_build < slip_dump = {} (the hysteresis band)", p.slip_dump),
                )?;
                Some(p)
            }
        };
        let tcs = match &self.tcs {
            None => None,
            Some(t) if t.enabled == Some(false) => None,
            Some(t) => {
                let d = TcsParams::default();
                let p = TcsParams {
                    period_s: period(&b::TCS_PERIOD_S, t.period_s.unwrap_or(d.period_s))?,
                    slip_high: c.bound(&b::SLIP_HIGH, t.slip_high.unwrap_or(d.slip_high))?,
                    slip_low: c.bound(&b::SLIP_LOW, t.slip_low.unwrap_or(d.slip_low))?,
                    reduction_rate_per_s: c
                        .bound(&b::REDUCTION_RATE, t.reduction_rate_per_s.unwrap_or(d.reduction_rate_per_s))?,
                    restore_rate_per_s: c
                        .bound(&b::RESTORE_RATE, t.restore_rate_per_s.unwrap_or(d.restore_rate_per_s))?,
                };
                c.require(
                    "tcs.slip_low",
                    p.slip_low,
                    p.slip_low < p.slip_high,
                    &format!("expected slip_low < slip_high = {} (the hysteresis band)", p.slip_high),
                )?;
                Some(p)
            }
        };
        Ok(vehsim_core::sim::slip_control::SlipControlParams { abs, tcs })
    }
}

/// `[maneuver]` with `kind = "braking_in_turn"`: steady on a circle, then the steering held and
/// the brake applied (after ISO 7975; [`vehsim_core::maneuver::brake_in_turn`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct BrakingInTurnSpec {
    /// Circle radius, m.
    pub radius_m: f64,
    /// `left` (default) or `right`.
    #[serde(default = "left")]
    pub direction: DirectionSpec,
    /// Speed held on the circle, m/s.
    pub speed_mps: f64,
    /// Brake onset (the time on the circle before it), s (default 10).
    #[serde(default = "ten")]
    pub brake_at_s: f64,
    /// Brake pedal as a fraction of its stop, (0, 1] (default 1).
    #[serde(default = "one_f")]
    pub brake_fraction: f64,
    /// Longest time after the onset, s (default 10).
    #[serde(default = "ten")]
    pub after_s: f64,
}

fn ten() -> f64 {
    10.0
}

fn one_f() -> f64 {
    1.0
}

impl BrakingInTurnSpec {
    fn build(&self, c: &Checker) -> Result<vehsim_core::maneuver::brake_in_turn::BrakeInTurnParams> {
        let r = c.bound(&bounds::RADIUS_M, self.radius_m)?;
        let v = c.bound(&bounds::SPEED_MPS, self.speed_mps)?;
        c.require(
            "maneuver.brake_at_s",
            self.brake_at_s,
            self.brake_at_s >= 1.0 && self.brake_at_s <= 3600.0,
            "expected 1 <= brake_at_s <= 3600 (s)",
        )?;
        c.require(
            "maneuver.brake_fraction",
            self.brake_fraction,
            self.brake_fraction > 0.0 && self.brake_fraction <= 1.0,
            "expected 0 < brake_fraction <= 1",
        )?;
        c.require(
            "maneuver.after_s",
            self.after_s,
            self.after_s >= 1.0 && self.after_s <= 3600.0,
            "expected 1 <= after_s <= 3600 (s)",
        )?;
        let direction = match self.direction {
            DirectionSpec::Left => Direction::Left,
            DirectionSpec::Right => Direction::Right,
        };
        Ok(vehsim_core::maneuver::brake_in_turn::BrakeInTurnParams {
            circle: ConstantRadiusParams {
                radius_m: r,
                direction,
                step_speeds_mps: vec![v],
                // the circle's own end (settle + window) lies beyond the onset
                settle_s: self.brake_at_s,
                window_s: 1.0,
                speed_ramp_mps2: 0.5,
            },
            brake_at_s: self.brake_at_s,
            brake_fraction: self.brake_fraction,
            after_s: self.after_s,
        })
    }
}

/// [`crate::strict`] on manoeuvre specs (here, not there, so that `strict` needs no manoeuvre type).
#[cfg(test)]
mod strict_tests {
    use super::ManeuverFile;
    use crate::strict::{check, MARK};
    use std::path::Path;

    const BASE: &str = "name = 'a'\nvehicle = 'v.toml'\ntyre_model = 'linear'\n[maneuver]\nkind = 'sine_steer'\n";

    fn value(extra: &str) -> toml::Value {
        toml::from_str(&format!("{extra}\n{BASE}")).unwrap()
    }

    #[test]
    fn a_table_given_as_an_array_or_a_scalar_names_its_key() {
        for (extra, key, found) in [
            ("surface = [1.0, 2.0]", "surface", "an array"),
            ("integrator = ['rk4', 0.01]\nsurface = { mu = 0.1 }", "integrator", "an array"),
            ("surface = 0.3", "surface", "a float"),
            ("surface = { mu = 0.1 }\noutput = 'none'", "output", "a string"),
        ] {
            let e = check::<ManeuverFile>(Path::new("m.toml"), &value(extra)).unwrap_err().to_string();
            assert!(e.contains(&format!("key '{key}'")) && e.contains(found) && e.contains(MARK), "{extra}: {e}");
        }
    }

    #[test]
    fn well_shaped_tables_and_other_errors_pass_to_the_ordinary_parse() {
        let ok = value("surface = { mu = 0.1, temperature_c = -5 }\nintegrator = { method = 'rk4', step_s = 0.01 }");
        assert!(check::<ManeuverFile>(Path::new("m.toml"), &ok).is_ok());
        // A wrong type inside a well-shaped table is the ordinary parse's to report.
        let typed = value("surface = { mu = 'ice' }");
        assert!(check::<ManeuverFile>(Path::new("m.toml"), &typed).is_ok());
        // And the ordinary parse does accept the ok spec exactly as given.
        let f: ManeuverFile = ok.try_into().unwrap();
        assert_eq!((f.surface.mu, f.surface.temperature_c, f.integrator.step_s), (0.1, -5.0, Some(0.01)));
    }
}
