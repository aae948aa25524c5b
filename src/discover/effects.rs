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

/// A candidate effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effect {
    TyreRelaxation,
    LoadTransfer,
    ThermalFriction,
    FrictionChange,
    SteerCompliance,
    SensorBias,
}

impl Effect {
    /// Every effect the discovery tries, in a fixed order.
    pub const TRIED: [Effect; 5] = [
        Effect::SensorBias,
        Effect::SteerCompliance,
        Effect::TyreRelaxation,
        Effect::FrictionChange,
        Effect::LoadTransfer,
    ];

    /// Every name accepted on the command line.
    pub const NAMES: [&'static str; 6] =
        ["tyre_relaxation", "load_transfer", "thermal_friction", "friction_change", "steer_compliance", "sensor_bias"];

    pub fn name(self) -> &'static str {
        match self {
            Effect::TyreRelaxation => "tyre_relaxation",
            Effect::LoadTransfer => "load_transfer",
            Effect::ThermalFriction => "thermal_friction",
            Effect::FrictionChange => "friction_change",
            Effect::SteerCompliance => "steer_compliance",
            Effect::SensorBias => "sensor_bias",
        }
    }

    pub fn from_name(s: &str) -> Option<Effect> {
        [
            Effect::TyreRelaxation,
            Effect::LoadTransfer,
            Effect::ThermalFriction,
            Effect::FrictionChange,
            Effect::SteerCompliance,
            Effect::SensorBias,
        ]
        .into_iter()
        .find(|e| e.name() == s)
    }

    /// What the effect does, in one sentence.
    pub fn describe(self) -> &'static str {
        match self {
            Effect::TyreRelaxation => "lateral tyre force lags the slip angle over a relaxation length",
            Effect::LoadTransfer => "lateral load transfer with tyre load sensitivity lowers axle grip",
            Effect::ThermalFriction => "contact heating lowers friction on ice (not implemented in the replay model)",
            Effect::FrictionChange => "surface friction differs from the nominal mu over the whole run",
            Effect::SteerCompliance => "effective steer is reduced in proportion to the front lateral force",
            Effect::SensorBias => "constant offsets on the yaw-rate and lateral-acceleration sensors",
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
            Effect::ThermalFriction => &[],
            Effect::FrictionChange => {
                &[ParamDef { name: "mu_scale", unit: "1", start: 0.9, scale: 0.2, lo: 0.05, hi: 3.0 }]
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
            Effect::ThermalFriction => {}
            Effect::FrictionChange => p.mu_scale = v[0],
            Effect::SteerCompliance => p.steer_compliance_rad_per_kn = v[0],
            Effect::SensorBias => {
                p.bias_yaw_rate_radps = v[0];
                p.bias_ay_mps2 = v[1];
            }
        }
    }
}
