//! Tyre spec files (`vehicles/tyres/*.toml`): one physical tyre, with one section per provider.
//!
//! A manoeuvre chooses the provider by name (`tyre_model = "linear"`); building a provider whose
//! section is missing from the tyre file is a bad-input error naming the section.
//!
//! ```toml
//! name = "SRTT P225/60R16 97S"
//! unloaded_radius_m = 0.3485       # m
//! rolling_radius_m = 0.3380        # m, effective rolling radius R_e
//! nominal_load_n = 4000.0          # N
//! relaxation_length_x_m = 0.15     # m, longitudinal relaxation length
//! [linear]
//! cornering_stiffness_n_per_rad = 60000.0
//! longitudinal_stiffness_n = 80000.0
//! saturate = false
//! ```

use std::path::Path;
use std::str::FromStr;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::{LinearTyre, TyreModel};
use crate::error::{parse_toml, read_input, Checker, Error, Result};

/// Names of the tyre providers a spec can select.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum TyreModelKind {
    /// Linear in slip, stiffness proportional to load ([`LinearTyre`]).
    Linear,
}

impl TyreModelKind {
    /// Every provider name accepted in spec files, for error messages.
    pub const ALLOWED: &'static [&'static str] = &["linear"];

    /// The name used in spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            TyreModelKind::Linear => "linear",
        }
    }
}

impl FromStr for TyreModelKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "linear" => Ok(TyreModelKind::Linear),
            _ => Err(format!("unknown tyre model '{s}'; allowed: {}", Self::ALLOWED.join(", "))),
        }
    }
}

/// Raw `[linear]` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSection {
    /// Cornering stiffness at the nominal load, N/rad.
    pub cornering_stiffness_n_per_rad: f64,
    /// Longitudinal slip stiffness at the nominal load, N per unit slip.
    pub longitudinal_stiffness_n: f64,
    /// Load exponent p of the stiffness, C(Fz) = C_nominal (Fz/Fz_nominal)^p, in (0, 1]; default 1.
    #[serde(default = "one")]
    pub load_exponent: f64,
    /// Saturate the combined force at mu Fz (default false, as in the dissertation).
    #[serde(default)]
    pub saturate: bool,
}

fn one() -> f64 {
    1.0
}

fn default_relaxation_x() -> f64 {
    0.15
}

/// Raw tyre file as written by the user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TyreFileSpec {
    /// Human-readable name of the tyre.
    pub name: String,
    /// Unloaded (free) radius, m (passenger tyres 0.28–0.40).
    pub unloaded_radius_m: f64,
    /// Effective rolling radius R_e used in the slip ratio and the wheel torque balance, m
    /// (slightly below the unloaded radius).
    pub rolling_radius_m: f64,
    /// Nominal load, N, at which stiffness-type coefficients are given.
    pub nominal_load_n: f64,
    /// Longitudinal relaxation length, m (0.05–0.5). The slip ratio the force sees lags the
    /// kinematic one over this rolled distance; it keeps the wheel-spin dynamics well-posed at
    /// low speed.
    #[serde(default = "default_relaxation_x")]
    pub relaxation_length_x_m: f64,
    /// Linear provider coefficients.
    #[serde(default)]
    pub linear: Option<LinearSection>,
}

/// A validated tyre: geometry plus one built provider.
#[derive(Debug, Clone)]
pub struct Tyre {
    /// Name from the spec file.
    pub name: String,
    /// Effective rolling radius, m.
    pub rolling_radius_m: f64,
    /// Unloaded radius, m.
    pub unloaded_radius_m: f64,
    /// Nominal load, N.
    pub nominal_load_n: f64,
    /// Longitudinal relaxation length, m.
    pub relaxation_length_x_m: f64,
    /// The force provider.
    pub model: Arc<dyn TyreModel>,
}

impl TyreFileSpec {
    /// Read and parse a tyre file (no validation yet).
    pub fn load(path: &Path) -> Result<Self> {
        parse_toml(path, &read_input(path)?)
    }

    /// Validate the common fields and build provider `kind`; `path` is the file the spec came from.
    pub fn build(&self, path: &Path, kind: TyreModelKind) -> Result<Tyre> {
        let c = Checker::new(path);
        c.range("unloaded_radius_m", self.unloaded_radius_m, 0.05, 2.0)?;
        c.require(
            "rolling_radius_m",
            self.rolling_radius_m,
            self.rolling_radius_m > 0.0 && self.rolling_radius_m <= self.unloaded_radius_m,
            "expected 0 < rolling_radius_m <= unloaded_radius_m (m)",
        )?;
        c.positive("nominal_load_n", self.nominal_load_n)?;
        c.range("relaxation_length_x_m", self.relaxation_length_x_m, 0.01, 2.0)?;
        let model: Arc<dyn TyreModel> = match kind {
            TyreModelKind::Linear => {
                let s = self.linear.as_ref().ok_or_else(|| missing(path, "linear"))?;
                c.positive("linear.cornering_stiffness_n_per_rad", s.cornering_stiffness_n_per_rad)?;
                c.positive("linear.longitudinal_stiffness_n", s.longitudinal_stiffness_n)?;
                c.require(
                    "linear.load_exponent",
                    s.load_exponent,
                    s.load_exponent > 0.0 && s.load_exponent <= 1.0,
                    "expected 0 < load_exponent <= 1",
                )?;
                Arc::new(LinearTyre {
                    cornering_stiffness_n_per_rad: s.cornering_stiffness_n_per_rad,
                    longitudinal_stiffness_n: s.longitudinal_stiffness_n,
                    nominal_load_n: self.nominal_load_n,
                    load_exponent: s.load_exponent,
                    saturate: s.saturate,
                })
            }
        };
        Ok(Tyre {
            name: self.name.clone(),
            rolling_radius_m: self.rolling_radius_m,
            unloaded_radius_m: self.unloaded_radius_m,
            nominal_load_n: self.nominal_load_n,
            relaxation_length_x_m: self.relaxation_length_x_m,
            model,
        })
    }
}

/// Error for a provider whose section is absent from the tyre file.
pub fn missing(path: &Path, section: &str) -> Error {
    Error::input(
        path,
        format!(
            "tyre model '{section}' was selected but the tyre file has no [{section}] section with its coefficients"
        ),
    )
}
