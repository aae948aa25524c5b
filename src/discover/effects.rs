//! The library of candidate effects: each names the physical effect, its parameters (with units,
//! start values and bounds) and how they switch on the extension in the replay model
//! ([`super::model::ReplayModel`]). Every candidate is a model extension that the replay model
//! integrates, not a curve fitted to the residual.

use super::model::EffectParams;

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
}

/// `name (form)`, or `name` for a one-form effect (form `""`).
pub fn label(name: &str, form: &str) -> String {
    if form.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({form})")
    }
}

/// A candidate effect. Two effects come in two forms each, tried as separate candidates under
/// one name: `steer_compliance` (force compliance [`Effect::SteerCompliance`] or a steering lag
/// [`Effect::SteerLag`]) and `friction_change` (global [`Effect::FrictionChange`] or over a
/// stretch of the path [`Effect::FrictionStretch`]). The information criterion decides between
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
}

impl Effect {
    /// Every candidate the discovery tries, in a fixed order.
    pub const TRIED: [Effect; 8] = [
        Effect::SensorBias,
        Effect::SteerCompliance,
        Effect::SteerLag,
        Effect::TyreRelaxation,
        Effect::FrictionChange,
        Effect::FrictionStretch,
        Effect::ThermalFriction,
        Effect::LoadTransfer,
    ];

    /// Every candidate, in the order of [`Self::TRIED`].
    pub const ALL: [Effect; 8] = Self::TRIED;

    /// Every name accepted on the command line.
    pub const NAMES: [&'static str; 6] =
        ["tyre_relaxation", "load_transfer", "thermal_friction", "friction_change", "steer_compliance", "sensor_bias"];

    pub fn name(self) -> &'static str {
        match self {
            Effect::TyreRelaxation => "tyre_relaxation",
            Effect::LoadTransfer => "load_transfer",
            Effect::ThermalFriction => "thermal_friction",
            Effect::FrictionChange | Effect::FrictionStretch => "friction_change",
            Effect::SteerCompliance | Effect::SteerLag => "steer_compliance",
            Effect::SensorBias => "sensor_bias",
        }
    }

    /// The form of an effect that has two (`force`/`lag`, `global`/`stretch`), else `""`.
    pub fn form(self) -> &'static str {
        match self {
            Effect::SteerCompliance => "force",
            Effect::SteerLag => "lag",
            Effect::FrictionChange => "global",
            Effect::FrictionStretch => "stretch",
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
            _ => Vec::new(),
        }
    }

    /// Its parameters; the first is the main parameter.
    pub fn params(self) -> &'static [ParamDef] {
        match self {
            Effect::TyreRelaxation => {
                &[ParamDef { name: "relaxation_length_y_m", unit: "m", start: 0.5, scale: 0.5, lo: 0.05, hi: 10.0 }]
            }
            Effect::LoadTransfer => {
                &[ParamDef { name: "load_transfer_height_m", unit: "m", start: 0.5, scale: 0.3, lo: 0.0, hi: 2.0 }]
            }
            Effect::ThermalFriction => {
                &[ParamDef { name: "thermal_mu_per_k", unit: "1/K", start: -0.2, scale: 0.2, lo: -2.0, hi: 0.0 }]
            }
            Effect::FrictionChange => {
                &[ParamDef { name: "mu_scale", unit: "1", start: 0.9, scale: 0.2, lo: 0.05, hi: 3.0 }]
            }
            Effect::FrictionStretch => &[
                ParamDef { name: "mu_scale", unit: "1", start: 0.7, scale: 0.2, lo: 0.05, hi: 3.0 },
                ParamDef { name: "stretch_start_m", unit: "m", start: 20.0, scale: 20.0, lo: 0.0, hi: 2000.0 },
                ParamDef { name: "stretch_length_m", unit: "m", start: 40.0, scale: 20.0, lo: 2.0, hi: 2000.0 },
            ],
            Effect::SteerLag => {
                &[ParamDef { name: "steer_lag_s", unit: "s", start: 0.1, scale: 0.1, lo: 0.005, hi: 2.0 }]
            }
            Effect::SteerCompliance => &[ParamDef {
                name: "steer_compliance_rad_per_kn",
                unit: "rad/kN",
                start: 0.002,
                scale: 0.003,
                lo: 0.0,
                hi: 0.1,
            }],
            Effect::SensorBias => &[
                ParamDef { name: "bias_yaw_rate_radps", unit: "rad/s", start: 0.0, scale: 0.01, lo: -0.5, hi: 0.5 },
                ParamDef { name: "bias_ay_mps2", unit: "m/s^2", start: 0.0, scale: 0.1, lo: -5.0, hi: 5.0 },
            ],
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
                p.mu_scale = v[0];
                p.stretch_start_m = v[1];
                p.stretch_length_m = v[2];
            }
            Effect::SteerCompliance => p.steer_compliance_rad_per_kn = v[0],
            Effect::SteerLag => p.steer_lag_s = v[0],
            Effect::SensorBias => {
                p.bias_yaw_rate_radps = v[0];
                p.bias_ay_mps2 = v[1];
            }
        }
    }
}
