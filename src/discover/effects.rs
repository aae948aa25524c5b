//! The library of candidate effects: each names the physical effect, its parameters (with units,
//! start values and bounds) and how they switch on the extension in the replay model
//! ([`super::model::ReplayModel`]). Every candidate is a model extension that the replay model
//! integrates, not a curve fitted to the residual.

use super::measured::sidecar_bounds as rb;
use super::model::EffectParams;
use super::vehicle_params as vp;
use vehsim_core::error::Bound;
use vehsim_core::vehicle::lateral_bounds as lb;
use vehsim_core::vehicle::road::road_bounds as roadb;
use vehsim_core::vehicle::sensor_bounds as sb;

/// One parameter of an effect.
#[derive(Debug, Clone, Copy)]
pub struct ParamDef {
    /// Key as written in reports and specs.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Start value of the fit.
    pub start: f64,
    /// Typical magnitude (scale of the search).
    pub scale: f64,
    /// Bounds.
    pub lo: f64,
    pub hi: f64,
    /// The value at which the effect is off (None for a parameter that only places it, such as
    /// where a stretch starts). An effect is named only when the confidence interval of at least
    /// one of its parameters excludes that parameter's no-effect value.
    pub null: Option<f64>,
}

/// A parameter definition (`null` as in [`ParamDef::null`]).
const fn pd(
    name: &'static str,
    unit: &'static str,
    start: f64,
    scale: f64,
    lo: f64,
    hi: f64,
    null: Option<f64>,
) -> ParamDef {
    ParamDef { name, unit, start, scale, lo, hi, null }
}

/// A parameter that is a `[lateral]` key of the vehicle: its name (the key without `lateral.`),
/// unit and range come from the key's declared bound, the lower end raised to `lo` when the fit
/// must stay off the bound's own (e.g. a lag of 0, which switches the effect off).
const fn pdl(b: Bound, lo: Option<f64>, start: f64, scale: f64, null: Option<f64>) -> ParamDef {
    let name = b.key.split_at(LATERAL.len()).1;
    let lo = match lo {
        Some(v) => v,
        None => b.lo,
    };
    pd(name, unit_of(b), start, scale, lo, b.hi, null)
}

/// A parameter that is a `[sensors]` key of the vehicle: its name (the key without `sensors.`),
/// unit and range from the key's declared bound; its no-effect value is 0.
const fn pds(b: Bound, start: f64, scale: f64) -> ParamDef {
    let name = b.key.split_at(SENSORS.len()).1;
    pd(name, unit_of(b), start, scale, b.lo, b.hi, Some(0.0))
}

/// A `[sensors]` scale factor: name, unit and range from the key's declared bound, start and
/// no-effect value 1.
const fn pds1(b: Bound, scale: f64) -> ParamDef {
    let name = b.key.split_at(SENSORS.len()).1;
    pd(name, unit_of(b), 1.0, scale, b.lo, b.hi, Some(1.0))
}

/// A parameter that places a friction region on the ground (no no-effect value), with the unit and
/// range of the sidecar key's declared bound ([`super::measured::sidecar_bounds`]).
const fn pdb(name: &'static str, b: Bound, start: f64, scale: f64) -> ParamDef {
    pd(name, unit_of(b), start, scale, b.lo, b.hi, None)
}

/// A parameter that is a `[road]` key of a run's sidecar (and of a manoeuvre): its name (the key
/// without `road.`), unit and range from the key's declared bound; its no-effect value is 0 (a
/// flat road).
const fn pdr(b: Bound, start: f64, scale: f64) -> ParamDef {
    let name = b.key.split_at(ROAD.len()).1;
    pd(name, unit_of(b), start, scale, b.lo, b.hi, Some(0.0))
}

/// The section prefix of the `[road]` keys.
pub const ROAD: &str = "road.";

/// The key of a friction region's parameter in a sidecar's `[[surface.<form>]]` table: the
/// parameter's name without its form's prefix (`patch_x_m` is `x_m` of `[[surface.patch]]`).
pub fn region_key<'a>(form: &str, param: &'a str) -> &'a str {
    param.strip_prefix(form).and_then(|r| r.strip_prefix('_')).unwrap_or(param)
}

/// The section prefix of the `[sensors]` keys.
pub const SENSORS: &str = "sensors.";

/// The section prefix of the `[lateral]` keys.
const LATERAL: &str = "lateral.";

/// A bound's unit as reports write it (`1` when dimensionless).
const fn unit_of(b: Bound) -> &'static str {
    if b.unit.is_empty() {
        "1"
    } else {
        b.unit
    }
}

/// `name (form)`, or `name` for a one-form effect (form `""`).
pub fn label(name: &str, form: &str) -> String {
    if form.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({form})")
    }
}

/// Where an effect's fitted value belongs in a vehicle spec file ([`Effect::in_vehicle_spec`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InVehicleSpec {
    /// `[lateral]` keys: each of the effect's parameters, named as its key (its bound is the
    /// key's); the saturating transient slip also sets `slip_relaxation_saturating = true`.
    Lateral,
    /// A factor on a body key of the vehicle (`mass_kg`, `yaw_inertia_kgm2`, ...: the
    /// [`vp::TABLE`] entry's key), written as the key's new value.
    Body,
    /// A property of the road (a friction change at some place), not of the vehicle.
    Road,
    /// A property of the instruments (offsets, latencies, the accelerometer's position): the
    /// vehicle spec's `[sensors]` section.
    Instruments,
    /// The road's bank and grade: a run sidecar's (and a manoeuvre's) `[road]` section.
    RoadGeometry,
}

/// A candidate effect. Some effects come in several forms, tried as separate candidates under
/// one name: `steer_compliance` (force compliance [`Effect::SteerCompliance`] or a steering lag
/// [`Effect::SteerLag`]), `friction_change` (global [`Effect::FrictionChange`] or over a
/// stretch of the path [`Effect::FrictionStretch`]) and `tyre_relaxation` (one length lagging
/// both axles' forces [`Effect::TyreRelaxation`], or transient slip per axle
/// [`Effect::TransientSlip`], optionally saturating [`Effect::TransientSlipSaturating`]). The information criterion decides between
/// the forms like between any two candidates (the stretch pays for its two extra parameters).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    TyreRelaxation,
    LoadTransfer,
    ThermalFriction,
    FrictionChange,
    FrictionStretch,
    SteerCompliance,
    SteerLag,
    SensorBias,
    AxleStiffness,
    AxleFriction,
    /// A physical parameter of the vehicle spec: entry `i` of [`vp::TABLE`].
    VehicleParam(usize),
    TransientSlip,
    TransientSlipSaturating,
    FrictionPatch,
    LoadTransferSensitive,
    ThermalState,
    FrictionBand,
    SensorLatency,
    AccelPosition,
    /// The road's constant bank and grade, one pair for every run of the set
    /// ([`vehsim_core::vehicle::road`]).
    Road,
    SensorScale,
    ClockSkew,
    AccelOrientation,
    /// The measured speed change as the tyres' longitudinal forces: load moved between the axles
    /// at a fitted height and friction taken from the lateral capacity ([`super::coupling`]).
    LongitudinalCoupling,
}

/// The hand-written candidates, in the order tried (the generated vehicle parameters follow them).
const LISTED: [Effect; 23] = [
    Effect::SensorBias,
    Effect::SensorLatency,
    Effect::AccelPosition,
    Effect::SteerCompliance,
    Effect::SteerLag,
    Effect::TyreRelaxation,
    Effect::TransientSlip,
    Effect::TransientSlipSaturating,
    Effect::FrictionChange,
    Effect::FrictionStretch,
    Effect::FrictionPatch,
    Effect::FrictionBand,
    Effect::ThermalFriction,
    Effect::ThermalState,
    Effect::LoadTransfer,
    Effect::LoadTransferSensitive,
    Effect::AxleStiffness,
    Effect::AxleFriction,
    Effect::SensorScale,
    Effect::ClockSkew,
    Effect::AccelOrientation,
    Effect::Road,
    Effect::LongitudinalCoupling,
];

/// Number of candidates: the listed ones and one per vehicle parameter.
const N_TRIED: usize = LISTED.len() + vp::N;

/// The listed candidates, then [`Effect::VehicleParam`] for every entry of [`vp::TABLE`].
const fn tried() -> [Effect; N_TRIED] {
    let mut out = [Effect::SensorBias; N_TRIED];
    let mut i = 0;
    while i < LISTED.len() {
        out[i] = LISTED[i];
        i += 1;
    }
    let mut j = 0;
    while j < vp::N {
        out[LISTED.len() + j] = Effect::VehicleParam(j);
        j += 1;
    }
    out
}

impl Effect {
    /// Every candidate the discovery tries, in a fixed order: the listed ones, then one per
    /// vehicle parameter of [`vp::TABLE`].
    pub const TRIED: [Effect; N_TRIED] = tried();

    /// Every candidate, in the order of [`Self::TRIED`].
    pub const ALL: [Effect; N_TRIED] = Self::TRIED;

    /// The yaw-inertia candidate (the vehicle parameter that keeps its earlier name).
    #[allow(non_upper_case_globals)]
    pub const YawInertia: Effect = Effect::VehicleParam(0);

    /// Every name accepted on the command line (each effect once, in the order of [`Self::ALL`]).
    pub fn names() -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        for e in Self::ALL {
            if !out.contains(&e.name()) {
                out.push(e.name());
            }
        }
        out
    }

    pub fn name(self) -> &'static str {
        match self {
            Effect::TyreRelaxation | Effect::TransientSlip | Effect::TransientSlipSaturating => "tyre_relaxation",
            Effect::LoadTransfer | Effect::LoadTransferSensitive => "load_transfer",
            Effect::ThermalFriction | Effect::ThermalState => "thermal_friction",
            Effect::FrictionChange | Effect::FrictionStretch | Effect::FrictionPatch | Effect::FrictionBand => {
                "friction_change"
            }
            Effect::SteerCompliance | Effect::SteerLag => "steer_compliance",
            Effect::SensorBias => "sensor_bias",
            Effect::SensorLatency => "sensor_latency",
            Effect::AccelPosition => "accelerometer_position",
            Effect::AxleStiffness => "axle_cornering_stiffness",
            Effect::AxleFriction => "axle_peak_friction",
            Effect::VehicleParam(i) => vp::TABLE[i].effect,
            Effect::SensorScale => "sensor_scale",
            Effect::ClockSkew => "clock_skew",
            Effect::AccelOrientation => "accelerometer_orientation",
            Effect::Road => "road",
            Effect::LongitudinalCoupling => "longitudinal_coupling",
        }
    }

    /// The form of an effect that has two (`force`/`lag`, `global`/`stretch`), else `""`.
    pub fn form(self) -> &'static str {
        match self {
            Effect::SteerCompliance => "force",
            Effect::SteerLag => "lag",
            Effect::FrictionChange => "global",
            Effect::FrictionStretch => "stretch",
            Effect::TransientSlip => "slip",
            Effect::FrictionPatch => "patch",
            Effect::LoadTransferSensitive => "sensitive",
            Effect::TransientSlipSaturating => "slip_saturating",
            Effect::FrictionBand => "band",
            Effect::ThermalState => "tread_state",
            _ => "",
        }
    }

    /// The name with its form, e.g. `steer_compliance (lag)`.
    pub fn label(self) -> String {
        label(self.name(), self.form())
    }

    /// The candidate with this name and form (as reports record them).
    pub fn find(name: &str, form: &str) -> Option<Effect> {
        Self::ALL.into_iter().find(|e| e.name() == name && e.form() == form)
    }

    /// The first (primary) form of an effect name.
    pub fn from_name(s: &str) -> Option<Effect> {
        Self::ALL.into_iter().find(|e| e.name() == s)
    }

    /// The form of effect `name` whose parameters include every name in `given` (the primary
    /// form when `given` is empty); None when no form has them all.
    pub fn from_name_and_params(name: &str, given: &[&str]) -> Option<Effect> {
        Self::ALL
            .into_iter()
            .filter(|e| e.name() == name)
            .find(|e| given.iter().all(|g| e.params().iter().any(|d| d.name == *g)))
    }

    /// What the effect does, in one sentence.
    pub fn describe(self) -> &'static str {
        match self {
            Effect::TyreRelaxation => "lateral tyre force lags the slip angle over a relaxation length",
            Effect::LoadTransfer => "lateral load transfer with tyre load sensitivity lowers axle grip",
            Effect::ThermalFriction => {
                "contact heating (ATIIM estimator) lowers friction on ice in proportion to the contact-temperature rise"
            }
            Effect::FrictionChange => "surface friction differs from the nominal mu over the whole run",
            Effect::FrictionStretch => "surface friction differs from the nominal mu over a stretch of the path",
            Effect::SteerCompliance => "effective steer is reduced in proportion to the front lateral force",
            Effect::SteerLag => "effective steer follows the measured steer with a first-order lag",
            Effect::SensorBias => "constant offsets on the yaw-rate and lateral-acceleration sensors",
            Effect::SensorLatency => "the logged yaw rate and lateral acceleration arrive late, each by its own delay",
            Effect::AccelPosition => {
                "the accelerometer sits away from the CG and also measures the yaw acceleration and centripetal terms there"
            }
            Effect::AxleStiffness => {
                "each axle's cornering stiffness differs from the tyre's by its own factor (peak force unchanged)"
            }
            Effect::AxleFriction => "each axle's peak friction differs from the nominal by its own factor",
            Effect::LoadTransferSensitive => {
                "lateral load transfer with fitted load sensitivities of each tyre's friction and cornering stiffness"
            }
            Effect::FrictionPatch => {
                "surface friction differs over a disc on the ground, crossed by each axle at its own time"
            }
            Effect::FrictionBand => {
                "surface friction differs over a band of the ground between two X, crossed by each axle at its own time"
            }
            Effect::ThermalState => {
                "each axle's tread temperature, heated by frictional power and cooling towards the ice (capped at melting), lowers friction on ice"
            }
            Effect::TransientSlip => "each axle's slip angle lags the kinematic one over its own relaxation length",
            Effect::TransientSlipSaturating => {
                "each axle's slip angle lags over its own relaxation length, shortening as the tyre saturates"
            }
            Effect::VehicleParam(i) => vp::TABLE[i].describe,
            Effect::SensorScale => "the logged yaw rate and lateral acceleration are scaled, each by its own factor",
            Effect::ClockSkew => {
                "the inertial unit's clock runs fast or slow against the logger's, so its channels drift in time"
            }
            Effect::AccelOrientation => {
                "the accelerometer is turned in yaw, so its lateral axis also senses the longitudinal acceleration"
            }
            Effect::Road => {
                "the road is banked and graded: gravity pulls the car across and along the road plane (which the accelerometer does not log) and shifts the axle loads"
            }
            Effect::LongitudinalCoupling => {
                "the speed change is driven and braked through the tyres: it moves load between the axles and uses up part of their lateral grip"
            }
        }
    }

    /// Start points of the fit to try before the simplex search; the best (with the start value)
    /// is kept, so that the simplex begins in the right basin.
    pub fn starts(self) -> Vec<Vec<f64>> {
        match self {
            // One parameter: a coarse 7-point scan over the bounds, geometric when the lower
            // bound is positive.
            _ if self.params().len() == 1 => {
                let d = self.params()[0];
                (0..7)
                    .map(|j| {
                        let u = j as f64 / 6.0;
                        vec![if d.lo > 0.0 { d.lo * (d.hi / d.lo).powf(u) } else { d.lo + u * (d.hi - d.lo) }]
                    })
                    .collect()
            }
            // The stretch: a grid over where it starts and how long it is, at a clear friction
            // change, so that the simplex starts near the right window.
            Effect::FrictionStretch => {
                let mut v = Vec::new();
                for s0 in [0.0, 25.0, 50.0, 75.0, 100.0, 150.0] {
                    for len in [25.0, 50.0, 100.0] {
                        v.push(vec![0.6, s0, len]);
                    }
                }
                v
            }
            // The patch: a grid of discs along the first stretch of +X (where every run starts
            // when the pose is the replay's own) at a clear friction change.
            Effect::FrictionPatch => {
                let mut v = Vec::new();
                for x0 in [20.0, 45.0, 70.0, 95.0, 120.0, 170.0] {
                    for radius in [12.0, 30.0] {
                        v.push(vec![0.6, x0, 0.0, radius]);
                    }
                }
                v
            }
            // The band: as the stretch, in X.
            Effect::FrictionBand => {
                let mut v = Vec::new();
                for x0 in [0.0, 25.0, 50.0, 75.0, 100.0, 150.0] {
                    for len in [25.0, 50.0, 100.0] {
                        v.push(vec![0.6, x0, len]);
                    }
                }
                v
            }
            // The latencies: a grid of both delays, so that the simplex starts near the right
            // pair (the objective is periodic-looking in a delay on a sine steer).
            Effect::SensorLatency => {
                let mut v = Vec::new();
                for tr in [0.0, 0.03, 0.1, 0.25] {
                    for ta in [0.0, 0.03, 0.1, 0.25] {
                        v.push(vec![tr, ta]);
                    }
                }
                v
            }
            // The tread state: a grid of sensitivities, heat capacities (which act only through
            // the melting cap, so the simplex cannot find them from a flat start) and cooling times.
            Effect::ThermalState => {
                let mut v = Vec::new();
                for k in [-0.3, -1.0, -3.0] {
                    for c in [100.0, 200.0, 400.0, 1000.0] {
                        for tau in [1.5, 3.0, 6.0] {
                            v.push(vec![k, c, tau]);
                        }
                    }
                }
                v
            }
            _ => Vec::new(),
        }
    }

    /// True for a form that changes the model's structure whatever its parameters (the
    /// longitudinal coupling: free-rolling tyres become driven and braked ones), so that it has
    /// no no-effect value and the information criterion alone decides whether it is named.
    pub fn structural(self) -> bool {
        self == Effect::LongitudinalCoupling
    }

    /// Number of simplex searches of a candidate's fit, from its best start points: 3 for the
    /// tread state, whose heat capacity acts only through the melting cap, so that the
    /// objective has one basin where the fitted runs reach melting and another where they do
    /// not; else 1.
    pub fn fit_passes(self) -> usize {
        if self == Effect::ThermalState {
            3
        } else {
            1
        }
    }

    /// Its parameters; the first is the main parameter.
    pub fn params(self) -> &'static [ParamDef] {
        const ONE: Option<f64> = Some(1.0);
        const ZERO: Option<f64> = Some(0.0);
        match self {
            Effect::TyreRelaxation => const { &[pdl(lb::RELAXATION_LENGTH, Some(0.05), 0.5, 0.5, ZERO)] },
            Effect::LoadTransfer => const { &[pdl(lb::LOAD_TRANSFER_HEIGHT, None, 0.5, 0.3, ZERO)] },
            Effect::ThermalFriction => const { &[pdl(lb::THERMAL_MU, None, -0.2, 0.2, ZERO)] },
            Effect::FrictionChange => const { &[pdl(lb::MU_SCALE, None, 0.9, 0.2, ONE)] },
            Effect::FrictionStretch => {
                const {
                    &[
                        pdl(lb::MU_SCALE, None, 0.7, 0.2, ONE),
                        pdb("stretch_start_m", rb::STRETCH_START, 20.0, 20.0),
                        pdb("stretch_length_m", rb::REGION_LENGTH, 40.0, 20.0),
                    ]
                }
            }
            Effect::SteerLag => const { &[pdl(lb::STEER_LAG, Some(0.005), 0.1, 0.1, ZERO)] },
            Effect::SteerCompliance => const { &[pdl(lb::STEER_COMPLIANCE, None, 0.002, 0.003, ZERO)] },
            Effect::SensorBias => const { &[pds(sb::BIAS_YAW_RATE, 0.0, 0.01), pds(sb::BIAS_AY, 0.0, 0.1)] },
            Effect::SensorLatency => {
                const { &[pds(sb::LATENCY_YAW_RATE, 0.02, 0.03), pds(sb::LATENCY_AY, 0.02, 0.03)] }
            }
            Effect::AccelPosition => const { &[pds(sb::ACCEL_X, 0.0, 0.5), pds(sb::ACCEL_Y, 0.0, 0.3)] },
            Effect::AxleStiffness => {
                const {
                    &[
                        pdl(lb::STIFFNESS_SCALE_FRONT, None, 1.0, 0.2, ONE),
                        pdl(lb::STIFFNESS_SCALE_REAR, None, 1.0, 0.2, ONE),
                    ]
                }
            }
            Effect::AxleFriction => {
                const { &[pdl(lb::MU_SCALE_FRONT, None, 1.0, 0.2, ONE), pdl(lb::MU_SCALE_REAR, None, 1.0, 0.2, ONE)] }
            }
            Effect::VehicleParam(i) => std::slice::from_ref(&vp::DEFS[i]),
            Effect::SensorScale => const { &[pds1(sb::SCALE_YAW_RATE, 0.05), pds1(sb::SCALE_AY, 0.05)] },
            Effect::ClockSkew => const { &[pds(sb::CLOCK_SKEW, 0.0, 2000.0)] },
            Effect::AccelOrientation => const { &[pds(sb::ACCEL_YAW, 0.0, 0.05)] },
            Effect::Road => const { &[pdr(roadb::BANK_DEG, 0.0, 2.0), pdr(roadb::GRADE_DEG, 0.0, 2.0)] },
            // The form itself is the effect (free-rolling tyres become driven and braked ones), so
            // its height has no no-effect value; it stays above 0.05 m (a car's CG is higher), so
            // that the key written back switches the form on ([`Self::structural`]).
            Effect::LongitudinalCoupling => {
                const { &[pdl(lb::LONGITUDINAL_TRANSFER_HEIGHT, Some(0.05), 0.5, 0.3, None)] }
            }
            Effect::LoadTransferSensitive => {
                const {
                    &[
                        pdl(lb::LOAD_TRANSFER_HEIGHT, None, 0.5, 0.3, ZERO),
                        pdl(lb::LOAD_SENSITIVITY_MU, None, 0.0, 0.2, ZERO),
                        pdl(lb::LOAD_SENSITIVITY_STIFFNESS, None, 0.0, 0.2, ZERO),
                    ]
                }
            }
            Effect::FrictionPatch => {
                const {
                    &[
                        pdl(lb::MU_SCALE, None, 0.7, 0.2, ONE),
                        pdb("patch_x_m", rb::PATCH_XY, 50.0, 20.0),
                        pdb("patch_y_m", rb::PATCH_XY, 0.0, 20.0),
                        pdb("patch_radius_m", rb::PATCH_RADIUS, 20.0, 10.0),
                    ]
                }
            }
            Effect::TransientSlip | Effect::TransientSlipSaturating => {
                const {
                    &[
                        pdl(lb::RELAXATION_FRONT, Some(0.05), 0.5, 0.5, ZERO),
                        pdl(lb::RELAXATION_REAR, Some(0.05), 0.5, 0.5, ZERO),
                    ]
                }
            }
            Effect::FrictionBand => {
                const {
                    &[
                        pdl(lb::MU_SCALE, None, 0.7, 0.2, ONE),
                        pdb("band_start_x_m", rb::BAND_START, 20.0, 20.0),
                        pdb("band_length_m", rb::REGION_LENGTH, 40.0, 20.0),
                    ]
                }
            }
            Effect::ThermalState => {
                const {
                    &[
                        pdl(lb::TREAD_MU_PER_KJ, None, -0.5, 0.5, ZERO),
                        pdl(lb::TREAD_HEAT_CAPACITY, None, 300.0, 150.0, None),
                        pdl(lb::TREAD_COOLING_TIME, None, 3.0, 2.0, None),
                    ]
                }
            }
        }
    }

    /// Where the effect's fitted value belongs in a vehicle spec file (`vehsim discover` writes
    /// the improved vehicle.toml from it). Every effect is listed, so a new one must be placed.
    pub fn in_vehicle_spec(self) -> InVehicleSpec {
        match self {
            Effect::TyreRelaxation
            | Effect::LoadTransfer
            | Effect::ThermalFriction
            | Effect::FrictionChange
            | Effect::SteerCompliance
            | Effect::SteerLag
            | Effect::AxleStiffness
            | Effect::AxleFriction
            | Effect::TransientSlip
            | Effect::TransientSlipSaturating
            | Effect::LoadTransferSensitive
            | Effect::ThermalState
            | Effect::LongitudinalCoupling => InVehicleSpec::Lateral,
            Effect::VehicleParam(_) => InVehicleSpec::Body,
            Effect::FrictionStretch | Effect::FrictionPatch | Effect::FrictionBand => InVehicleSpec::Road,
            Effect::SensorBias
            | Effect::SensorLatency
            | Effect::AccelPosition
            | Effect::SensorScale
            | Effect::ClockSkew
            | Effect::AccelOrientation => InVehicleSpec::Instruments,
            Effect::Road => InVehicleSpec::RoadGeometry,
        }
    }

    /// Switch the effect on in `p` with parameter values `v` (in the order of [`Self::params`]).
    pub fn apply(self, p: &mut EffectParams, v: &[f64]) {
        match self {
            Effect::TyreRelaxation => p.sigma_y_m = v[0],
            Effect::LoadTransfer => p.load_transfer_height_m = v[0],
            Effect::ThermalFriction => p.thermal_mu_per_k = v[0],
            Effect::FrictionChange => p.mu_scale = v[0],
            Effect::FrictionStretch => {
                p.stretch_scale = v[0];
                p.stretch_start_m = v[1];
                p.stretch_length_m = v[2];
            }
            Effect::SteerCompliance => p.steer_compliance_rad_per_kn = v[0],
            Effect::SteerLag => p.steer_lag_s = v[0],
            Effect::SensorBias => {
                p.bias_yaw_rate_radps = v[0];
                p.bias_ay_mps2 = v[1];
            }
            Effect::SensorLatency => p.latency_s = [v[0], v[1]],
            Effect::AccelPosition => p.accel_position_m = [v[0], v[1]],
            Effect::AxleStiffness => p.stiffness_scale = [v[0], v[1]],
            Effect::AxleFriction => p.mu_axle_scale = [v[0], v[1]],
            Effect::VehicleParam(i) => p.body_scale[i] = v[0],
            Effect::SensorScale => p.sensor_scale = [v[0], v[1]],
            Effect::ClockSkew => p.clock_skew_ppm = v[0],
            Effect::AccelOrientation => p.accel_yaw_misalignment_rad = v[0],
            Effect::FrictionPatch => p.patch = [v[0], v[1], v[2], v[3]],
            Effect::LoadTransferSensitive => {
                p.load_transfer_height_m = v[0];
                p.load_sensitivity = [v[1], v[2]];
            }
            Effect::TransientSlip | Effect::TransientSlipSaturating => {
                p.slip_relaxation_m = [v[0], v[1]];
                p.slip_relaxation_saturating = self == Effect::TransientSlipSaturating;
            }
            Effect::FrictionBand => p.band = [v[0], v[1], v[2]],
            Effect::Road => p.road = Some(vehsim_core::vehicle::road::Road::from_deg(v[0], v[1])),
            Effect::LongitudinalCoupling => p.longitudinal_transfer_height_m = v[0],
            Effect::ThermalState => {
                // Friction change per kelvin = per kJ of tread heat x the heat capacity in kJ/K.
                p.tread_mu_per_k = v[0] * v[1] * 1e-3;
                p.tread_heat_capacity_j_per_k = v[1];
                p.tread_cooling_s = v[2];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The improved vehicle.toml writes a `[lateral]` effect's parameters under their own names:
    /// each is a declared `[lateral]` key; the yaw inertia has one parameter, its scale factor.
    /// Every `[lateral]` key is written by some effect.
    #[test]
    fn vehicle_spec_placement_matches_the_lateral_keys() {
        let keys: Vec<&str> = lb::ALL.iter().map(|b| &b.key[LATERAL.len()..]).collect();
        let mut written = Vec::new();
        for e in Effect::ALL {
            match e.in_vehicle_spec() {
                InVehicleSpec::Lateral => {
                    for d in e.params() {
                        assert!(keys.contains(&d.name), "{}: {}", e.label(), d.name);
                        written.push(d.name);
                    }
                }
                InVehicleSpec::Body => assert_eq!(e.params().len(), 1, "{}", e.label()),
                _ => {}
            }
        }
        for k in keys {
            assert!(written.contains(&k), "no effect writes lateral.{k}");
        }
    }

    /// The instrument effects' parameters are the `[sensors]` keys, with their declared ranges,
    /// and every key is written by one.
    #[test]
    fn sensor_parameters_are_the_declared_sensor_keys() {
        let defs: Vec<&ParamDef> = Effect::ALL
            .iter()
            .filter(|e| e.in_vehicle_spec() == InVehicleSpec::Instruments)
            .flat_map(|e| e.params().iter())
            .collect();
        assert_eq!(defs.len(), sb::ALL.len());
        for b in sb::ALL {
            let d = defs.iter().find(|d| format!("{SENSORS}{}", d.name) == b.key).expect(b.key);
            assert_eq!((d.lo, d.hi, d.unit), (b.lo, b.hi, unit_of(b)), "{}", b.key);
        }
    }

    /// The road effect's parameters are the `[road]` keys, with their declared ranges.
    #[test]
    fn road_parameters_are_the_declared_road_keys() {
        let defs = Effect::Road.params();
        assert_eq!(defs.len(), roadb::ALL.len());
        for (d, b) in defs.iter().zip(roadb::ALL) {
            assert_eq!((format!("{ROAD}{}", d.name), d.lo, d.hi, d.unit), (b.key.to_string(), b.lo, b.hi, unit_of(b)));
        }
    }

    /// The vehicle-parameter candidates are generated from the table: one per entry, in its order,
    /// after the listed ones, each with the entry's name, parameter and fitting range, written
    /// back to the entry's own key. (A table of one more entry makes one more candidate: nothing
    /// else lists them.)
    #[test]
    fn one_candidate_per_vehicle_parameter_of_the_table() {
        let generated: Vec<Effect> =
            Effect::TRIED.iter().copied().filter(|e| matches!(e, Effect::VehicleParam(_))).collect();
        assert_eq!(generated.len(), vp::TABLE.len());
        assert_eq!(&Effect::TRIED[..LISTED.len()], &LISTED);
        for (i, (e, row)) in generated.iter().zip(&vp::TABLE).enumerate() {
            assert_eq!(*e, Effect::VehicleParam(i));
            assert_eq!((e.name(), e.in_vehicle_spec()), (row.effect, InVehicleSpec::Body));
            let d = e.params();
            assert_eq!(
                (d.len(), d[0].name, d[0].lo, d[0].hi, d[0].null),
                (1, row.param, row.fit[0], row.fit[1], Some(1.0))
            );
            assert_eq!(Effect::find(row.effect, ""), Some(*e));
            let mut p = EffectParams::default();
            e.apply(&mut p, &[1.1]);
            assert_eq!(p.body_scale[i], 1.1);
        }
        assert_eq!(Effect::YawInertia.name(), "yaw_inertia");
        assert!(Effect::names().contains(&"mass"));
    }

    #[test]
    fn lateral_parameters_take_name_unit_and_range_from_the_declared_bounds() {
        for b in lb::ALL {
            assert!(b.key.starts_with(LATERAL), "{}", b.key);
            let name = &b.key[LATERAL.len()..];
            let defs: Vec<&ParamDef> =
                Effect::ALL.iter().flat_map(|e| e.params().iter()).filter(|d| d.name == name).collect();
            assert!(!defs.is_empty(), "no effect parameter for {}", b.key);
            for d in defs {
                assert_eq!(d.hi, b.hi, "{name}");
                assert!(d.lo >= b.lo && d.lo < d.hi, "{name}");
                assert_eq!(d.unit, unit_of(b), "{name}");
            }
        }
    }
}
