//! Tyre spec files (`vehicles/tyres/*.toml`): one physical tyre, with one section per provider.
//!
//! A manoeuvre chooses the provider by name (`tyre_model = "linear"`); building a provider whose
//! section is missing from the tyre file is a bad-input error naming the section. Sections:
//! `[linear]`, `[polynomial]`, `[pacejka]` (a `.tir` file or inline MF coefficients),
//! `[dugoff]`, `[dugoff_thermal]`, `[atiim_pacejka]` with `[atiim_pacejka.longitudinal]` and
//! `[atiim_pacejka.lateral]`; every key is documented on its field below and in docs/tyres.md,
//! and `vehicles/tyres/srtt_p225_60r16.toml` is a complete example.
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

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::files::{parse_toml, read_input, resolve};
use vehsim_core::error::{Checker, Error, Result};
use vehsim_core::tyre::atiim::{AtiimPacejkaTyre, AxisLaw, KShift, MeltLaw};
use vehsim_core::tyre::dugoff::{DugoffThermalTyre, DugoffTyre, ThermalFactor};
use vehsim_core::tyre::pacejka::{Combination, MfCoefficients, PacejkaTyre, TyreSide};
use vehsim_core::tyre::polynomial::{PolyShape, PolynomialTyre};
use vehsim_core::tyre::ranges::TyreRanges;
use vehsim_core::tyre::{LinearTyre, Tyre, TyreModel, TyreModelKind};

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

/// Raw `[polynomial]` section (see [`PolynomialTyre`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialSection {
    /// Longitudinal slip stiffness at the nominal load, N per unit slip.
    pub longitudinal_stiffness_n: f64,
    /// Cornering stiffness at the nominal load, N/rad.
    pub cornering_stiffness_n_per_rad: f64,
    /// Load exponent of the stiffnesses, in (0, 1]; default 1.
    #[serde(default = "one")]
    pub load_exponent: f64,
    /// Tyre peak friction relative to the surface mu, in (0, 5]; default 1.
    #[serde(default = "one")]
    pub mu_scale: f64,
    /// `"brush"` (default: a2 = -1/3, a3 = 1/27) or `"general"` (give `a2` and `a3`).
    #[serde(default = "brush")]
    pub form: String,
    /// Quadratic coefficient of the general form, dimensionless.
    #[serde(default)]
    pub a2: Option<f64>,
    /// Cubic coefficient of the general form, dimensionless.
    #[serde(default)]
    pub a3: Option<f64>,
}

fn brush() -> String {
    "brush".into()
}

/// Raw `[pacejka]` section (see [`PacejkaTyre`]). Exactly one of `tir_file` and `coefficients`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PacejkaSection {
    /// Path of a `.tir` property file, relative to the tyre file.
    #[serde(default)]
    pub tir_file: Option<String>,
    /// Inline coefficients named as in `.tir` files (PCX1, PDX1, ...). FNOMIN and UNLOADED_RADIUS
    /// default to the tyre file's `nominal_load_n` and `unloaded_radius_m`.
    #[serde(default)]
    pub coefficients: Option<BTreeMap<String, f64>>,
    /// Coefficients that replace the file's values (for example `LKX = 0.5`).
    #[serde(default)]
    pub overrides: BTreeMap<String, f64>,
    /// Friction of the surface the coefficients were fitted on; default 1.0 (dry road).
    #[serde(default = "one")]
    pub mu_reference: f64,
    /// Exponent p of LKX' = LKX (mu_surface/mu_reference)^p (also LKY), in [0, 2]; default 0.
    #[serde(default)]
    pub stiffness_mu_exponent: f64,
    /// `"auto"` (default) or `"magic_formula"`: the MF functions (absent R coefficients are 0, as in
    /// PAC2002, with a warning); `"ellipse"`: the normalised-slip friction ellipse.
    #[serde(default = "auto")]
    pub combined: String,
    /// Compute the aligning moment Mz (MF 5.2 combined slip, see [`PacejkaTyre`]); default false (cost).
    #[serde(default)]
    pub aligning_moment: bool,
}

fn auto() -> String {
    "auto".into()
}

/// Raw `[dugoff]` section (see [`DugoffTyre`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DugoffSection {
    /// Longitudinal slip stiffness C_lambda at the nominal load, N per unit slip.
    pub longitudinal_stiffness_n: f64,
    /// Cornering stiffness C_alpha at the nominal load, N/rad.
    pub cornering_stiffness_n_per_rad: f64,
    /// Load exponent of the stiffnesses, in (0, 1]; default 1.
    #[serde(default = "one")]
    pub load_exponent: f64,
    /// Tyre peak friction relative to the surface mu, in (0, 5]; default 1.
    #[serde(default = "one")]
    pub mu_scale: f64,
}

/// Raw `[dugoff_thermal]` section (see [`DugoffThermalTyre`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DugoffThermalSection {
    /// Longitudinal slip stiffness C_lambda at the nominal load, N per unit slip.
    pub longitudinal_stiffness_n: f64,
    /// Cornering stiffness C_alpha at the nominal load, N/rad.
    pub cornering_stiffness_n_per_rad: f64,
    /// Load exponent of the stiffnesses, in (0, 1]; default 1.
    #[serde(default = "one")]
    pub load_exponent: f64,
    /// Tyre peak friction relative to the surface mu, in (0, 5]; default 1.
    #[serde(default = "one")]
    pub mu_scale: f64,
    /// Constant term of H; default 1.27 (eq. 5.6).
    #[serde(default = "h_offset")]
    pub h_offset: f64,
    /// Weight of mu_max in H, K; default 0.75 (eq. 5.6).
    #[serde(default = "h_mu")]
    pub h_mu_coefficient: f64,
}

fn h_offset() -> f64 {
    1.27
}

fn h_mu() -> f64 {
    0.75
}

/// One axis of `[atiim_pacejka]`: the temperature factors at melting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtiimAxisSection {
    /// Peak friction with the contact at melting over that at the ice temperature, in
    /// [min_factor, 1].
    pub peak_factor_at_melt: f64,
    /// Slip stiffness factor at melting, in [min_factor, 1]; default 1 (stiffness unchanged).
    #[serde(default = "one")]
    pub stiffness_factor_at_melt: f64,
}

/// Raw `[atiim_pacejka]` section (see [`AtiimPacejkaTyre`]). The base curve is the file's
/// `[pacejka]` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtiimSection {
    /// `"srtt"`, `"all_season"`, `"directional"`, `"average"`, `"none"` or `"quadratic"`.
    pub k_shift: String,
    /// a of the user quadratic a dT^2 + b, 1/K^2, >= 0 (only with `k_shift = "quadratic"`).
    #[serde(default)]
    pub k_shift_a: Option<f64>,
    /// b of the user quadratic, >= 0 (only with `k_shift = "quadratic"`).
    #[serde(default)]
    pub k_shift_b: Option<f64>,
    /// Floor of the temperature factors, in (0, 1]; default 0.1.
    #[serde(default = "min_factor")]
    pub min_factor: f64,
    /// Longitudinal factors at melting.
    pub longitudinal: AtiimAxisSection,
    /// Lateral factors at melting.
    pub lateral: AtiimAxisSection,
}

fn min_factor() -> f64 {
    0.1
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
    /// Polynomial (brush) provider coefficients.
    #[serde(default)]
    pub polynomial: Option<PolynomialSection>,
    /// Magic Formula provider: a `.tir` file or inline coefficients.
    #[serde(default)]
    pub pacejka: Option<PacejkaSection>,
    /// Dugoff provider coefficients.
    #[serde(default)]
    pub dugoff: Option<DugoffSection>,
    /// Thermal Dugoff provider coefficients.
    #[serde(default)]
    pub dugoff_thermal: Option<DugoffThermalSection>,
    /// ATIIM-modified Magic Formula coefficients.
    #[serde(default)]
    pub atiim_pacejka: Option<AtiimSection>,
}

impl TyreFileSpec {
    /// Read and parse a tyre file (no validation yet).
    pub fn load(path: &Path) -> Result<Self> {
        parse_toml(path, &read_input(path)?)
    }

    /// Validate the common fields and build provider `kind`; `path` is the file the spec came from.
    /// Warnings (for example unknown `.tir` sections) are dropped; see [`Self::build_with_warnings`].
    pub fn build(&self, path: &Path, kind: TyreModelKind) -> Result<Tyre> {
        self.build_with_warnings(path, kind).map(|(t, _)| t)
    }

    /// As [`Self::build`], also returning warnings the caller may print.
    pub fn build_with_warnings(&self, path: &Path, kind: TyreModelKind) -> Result<(Tyre, Vec<String>)> {
        let mut warnings = Vec::new();
        let c = Checker::new(path);
        c.range("unloaded_radius_m", self.unloaded_radius_m, 0.05, 2.0)?;
        c.require(
            "rolling_radius_m",
            self.rolling_radius_m,
            self.rolling_radius_m > 0.0 && self.rolling_radius_m <= self.unloaded_radius_m,
            "expected 0 < rolling_radius_m <= unloaded_radius_m (m)",
        )?;
        c.positive_up_to("nominal_load_n", self.nominal_load_n, MAX_NOMINAL_LOAD_N, "N")?;
        c.range("relaxation_length_x_m", self.relaxation_length_x_m, 0.01, 2.0)?;
        // Set by the Magic Formula providers when the tyre differs from its mirror image.
        let mut sided: Option<[Arc<dyn TyreModel>; 2]> = None;
        let model: Arc<dyn TyreModel> = match kind {
            TyreModelKind::Linear => {
                let s = self.linear.as_ref().ok_or_else(|| missing(path, "linear"))?;
                c.positive_up_to(
                    "linear.cornering_stiffness_n_per_rad",
                    s.cornering_stiffness_n_per_rad,
                    MAX_STIFFNESS_N,
                    "N/rad",
                )?;
                c.positive_up_to("linear.longitudinal_stiffness_n", s.longitudinal_stiffness_n, MAX_STIFFNESS_N, "N")?;
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
            TyreModelKind::Polynomial => Arc::new(self.build_polynomial(path)?),
            TyreModelKind::Pacejka => {
                let (t, w) = self.build_pacejka(path)?;
                warnings.extend(w);
                if !t.is_mirror_symmetric() {
                    sided = Some(TyreSide::BOTH.map(|s| Arc::new(t.mounted_on(s)) as Arc<dyn TyreModel>));
                }
                Arc::new(t)
            }
            TyreModelKind::Dugoff => Arc::new(self.build_dugoff(path)?),
            TyreModelKind::DugoffThermal => Arc::new(self.build_dugoff_thermal(path)?),
            TyreModelKind::AtiimPacejka => {
                let (t, w) = self.build_atiim(path)?;
                warnings.extend(w);
                if !t.base.is_mirror_symmetric() {
                    sided = Some(TyreSide::BOTH.map(|s| Arc::new(t.mounted_on(s)) as Arc<dyn TyreModel>));
                }
                Arc::new(t)
            }
        };
        let mounted = sided.unwrap_or_else(|| [model.clone(), model.clone()]);
        let tyre = Tyre {
            name: self.name.clone(),
            rolling_radius_m: self.rolling_radius_m,
            unloaded_radius_m: self.unloaded_radius_m,
            nominal_load_n: self.nominal_load_n,
            relaxation_length_x_m: self.relaxation_length_x_m,
            model,
            mounted,
        };
        Ok((tyre, warnings))
    }

    fn stiffness_common(c: &Checker, sec: &str, cx: f64, cy: f64, p: f64, mu_scale: f64) -> Result<()> {
        c.positive_up_to(&format!("{sec}.longitudinal_stiffness_n"), cx, MAX_STIFFNESS_N, "N")?;
        c.positive_up_to(&format!("{sec}.cornering_stiffness_n_per_rad"), cy, MAX_STIFFNESS_N, "N/rad")?;
        c.require(&format!("{sec}.load_exponent"), p, p > 0.0 && p <= 1.0, "expected 0 < load_exponent <= 1")?;
        c.require(
            &format!("{sec}.mu_scale"),
            mu_scale,
            mu_scale > 0.0 && mu_scale <= 5.0,
            "expected 0 < mu_scale <= 5",
        )?;
        Ok(())
    }

    fn build_polynomial(&self, path: &Path) -> Result<PolynomialTyre> {
        let s = self.polynomial.as_ref().ok_or_else(|| missing(path, "polynomial"))?;
        let c = Checker::new(path);
        Self::stiffness_common(
            &c,
            "polynomial",
            s.longitudinal_stiffness_n,
            s.cornering_stiffness_n_per_rad,
            s.load_exponent,
            s.mu_scale,
        )?;
        let shape = match s.form.as_str() {
            "brush" => {
                if s.a2.is_some() || s.a3.is_some() {
                    return Err(Error::key(path, "polynomial.form", "a2/a3 are only used with form = \"general\""));
                }
                PolyShape::brush()
            }
            "general" => {
                let (Some(a2), Some(a3)) = (s.a2, s.a3) else {
                    return Err(Error::key(path, "polynomial.form", "form = \"general\" needs both a2 and a3"));
                };
                PolyShape::general(a2, a3).map_err(|m| Error::key(path, "polynomial.a2", m))?
            }
            other => {
                return Err(Error::key(
                    path,
                    "polynomial.form",
                    format!("unknown form '{other}'; allowed: brush, general"),
                ))
            }
        };
        Ok(PolynomialTyre {
            longitudinal_stiffness_n: s.longitudinal_stiffness_n,
            cornering_stiffness_n_per_rad: s.cornering_stiffness_n_per_rad,
            nominal_load_n: self.nominal_load_n,
            load_exponent: s.load_exponent,
            mu_scale: s.mu_scale,
            shape,
        })
    }

    fn dugoff_base(&self, path: &Path, sec: &str, cx: f64, cy: f64, p: f64, mu_scale: f64) -> Result<DugoffTyre> {
        Self::stiffness_common(&Checker::new(path), sec, cx, cy, p, mu_scale)?;
        Ok(DugoffTyre {
            longitudinal_stiffness_n: cx,
            cornering_stiffness_n_per_rad: cy,
            nominal_load_n: self.nominal_load_n,
            load_exponent: p,
            mu_scale,
        })
    }

    fn build_dugoff(&self, path: &Path) -> Result<DugoffTyre> {
        let s = self.dugoff.as_ref().ok_or_else(|| missing(path, "dugoff"))?;
        self.dugoff_base(
            path,
            "dugoff",
            s.longitudinal_stiffness_n,
            s.cornering_stiffness_n_per_rad,
            s.load_exponent,
            s.mu_scale,
        )
    }

    fn build_dugoff_thermal(&self, path: &Path) -> Result<DugoffThermalTyre> {
        let s = self.dugoff_thermal.as_ref().ok_or_else(|| missing(path, "dugoff_thermal"))?;
        let base = self.dugoff_base(
            path,
            "dugoff_thermal",
            s.longitudinal_stiffness_n,
            s.cornering_stiffness_n_per_rad,
            s.load_exponent,
            s.mu_scale,
        )?;
        let c = Checker::new(path);
        c.positive("dugoff_thermal.h_offset", s.h_offset)?;
        c.finite("dugoff_thermal.h_mu_coefficient", s.h_mu_coefficient)?;
        Ok(DugoffThermalTyre::new(base, ThermalFactor { offset: s.h_offset, mu_coefficient: s.h_mu_coefficient }))
    }

    /// Build the ATIIM-modified Magic Formula: the `[pacejka]` base and the temperature law.
    fn build_atiim(&self, path: &Path) -> Result<(AtiimPacejkaTyre, Vec<String>)> {
        let s = self.atiim_pacejka.as_ref().ok_or_else(|| missing(path, "atiim_pacejka"))?;
        let c = Checker::new(path);
        c.require(
            "atiim_pacejka.min_factor",
            s.min_factor,
            s.min_factor > 0.0 && s.min_factor <= 1.0,
            "expected 0 < min_factor <= 1",
        )?;
        let k_shift = match s.k_shift.as_str() {
            "srtt" => KShift::Srtt,
            "all_season" => KShift::AllSeason,
            "directional" => KShift::Directional,
            "average" => KShift::Average,
            "none" => KShift::None,
            "quadratic" => {
                let (Some(a), Some(b)) = (s.k_shift_a, s.k_shift_b) else {
                    return Err(Error::key(
                        path,
                        "atiim_pacejka.k_shift",
                        "k_shift = \"quadratic\" needs k_shift_a and k_shift_b",
                    ));
                };
                c.range("atiim_pacejka.k_shift_a", a, 0.0, 1e3)?;
                c.range("atiim_pacejka.k_shift_b", b, 0.0, 1e3)?;
                c.require(
                    "atiim_pacejka.k_shift_b",
                    b,
                    a + b > 0.0,
                    "expected k_shift_a + k_shift_b > 0 (the shift must grow with the rise)",
                )?;
                KShift::Quadratic { a, b }
            }
            other => {
                return Err(Error::key(
                    path,
                    "atiim_pacejka.k_shift",
                    format!(
                    "unknown shift factor '{other}'; allowed: srtt, all_season, directional, average, none, quadratic"
                ),
                ))
            }
        };
        if !matches!(k_shift, KShift::Quadratic { .. }) && (s.k_shift_a.is_some() || s.k_shift_b.is_some()) {
            return Err(Error::key(
                path,
                "atiim_pacejka.k_shift",
                "k_shift_a/k_shift_b are only used with k_shift = \"quadratic\"",
            ));
        }
        let floor = s.min_factor;
        let axis = |name: &str, a: &AtiimAxisSection| -> Result<AxisLaw> {
            let allowed = format!("expected min_factor ({floor}) <= value <= 1");
            for (key, v) in [
                ("peak_factor_at_melt", a.peak_factor_at_melt),
                ("stiffness_factor_at_melt", a.stiffness_factor_at_melt),
            ] {
                c.require(&format!("atiim_pacejka.{name}.{key}"), v, v >= floor && v <= 1.0, &allowed)?;
            }
            Ok(AxisLaw { peak_at_melt: a.peak_factor_at_melt, stiffness_at_melt: a.stiffness_factor_at_melt })
        };
        let law =
            MeltLaw { k_shift, x: axis("longitudinal", &s.longitudinal)?, y: axis("lateral", &s.lateral)?, floor };
        if self.pacejka.is_none() {
            return Err(Error::key(
                path,
                "atiim_pacejka",
                "the ATIIM-modified Magic Formula needs a base curve: add a [pacejka] section (tir_file or coefficients)",
            ));
        }
        let (base, warnings) = self.build_pacejka(path)?;
        Ok((AtiimPacejkaTyre { base, law }, warnings))
    }

    /// Build the Magic Formula provider of the `[pacejka]` section, with reader warnings.
    pub fn build_pacejka(&self, path: &Path) -> Result<(PacejkaTyre, Vec<String>)> {
        let s = self.pacejka.as_ref().ok_or_else(|| missing(path, "pacejka"))?;
        let c = Checker::new(path);
        c.positive("pacejka.mu_reference", s.mu_reference)?;
        c.range("pacejka.stiffness_mu_exponent", s.stiffness_mu_exponent, 0.0, 2.0)?;
        let combination = combination(path, &s.combined)?;
        check_coefficient_names(path, "pacejka.overrides", s.overrides.keys())?;
        let mut warnings = Vec::new();
        let (source, base, side) = self.coefficient_source(path, s, &mut warnings)?;
        let mut missing_names = Vec::new();
        let coeffs = MfCoefficients::from_lookup(
            |n| s.overrides.get(n).copied().or_else(|| base.get(n).copied()),
            &mut missing_names,
        );
        if !missing_names.is_empty() {
            return Err(Error::input(
                &source,
                format!("missing required Magic Formula coefficient(s): {}", missing_names.join(", ")),
            ));
        }
        check_coefficients(&Checker::new(&source), &coeffs)?;
        let mut t = PacejkaTyre::new(coeffs, s.mu_reference, s.stiffness_mu_exponent, combination, s.aligning_moment);
        t.measured_side = side;
        warnings.extend(combined_slip_warning(&t, &source));
        Ok((t, warnings))
    }

    /// Where the `[pacejka]` coefficients come from (the `.tir` file, or the spec file for an
    /// inline table), the coefficients by name, and the side the tyre was measured on (a `.tir`
    /// file's TYRESIDE; left otherwise). The `.tir` reader's warnings go to `warnings`.
    fn coefficient_source(
        &self,
        path: &Path,
        s: &PacejkaSection,
        warnings: &mut Vec<String>,
    ) -> Result<(std::path::PathBuf, BTreeMap<String, f64>, TyreSide)> {
        match (&s.tir_file, &s.coefficients) {
            (Some(rel), None) => {
                let tir_path = resolve(path, rel);
                let f = crate::tir::read_tir(&tir_path)
                    .map_err(vehsim_core::error::referred_by(path, "pacejka.tir_file"))?;
                warnings.extend(f.warnings.iter().cloned());
                let side = tir_side(&f, &tir_path)?;
                let map = MfCoefficients::NAMES.iter().filter_map(|n| f.num(n).map(|v| (n.to_string(), v))).collect();
                Ok((tir_path, map, side))
            }
            (None, Some(map)) => {
                check_coefficient_names(path, "pacejka.coefficients", map.keys())?;
                let mut m = map.clone();
                m.entry("FNOMIN".into()).or_insert(self.nominal_load_n);
                m.entry("UNLOADED_RADIUS".into()).or_insert(self.unloaded_radius_m);
                Ok((path.to_path_buf(), m, TyreSide::Left))
            }
            _ => Err(Error::key(
                path,
                "pacejka",
                "give exactly one of tir_file (a .tir property file) and coefficients (an inline table)",
            )),
        }
    }
}

/// The combined-slip method named by `pacejka.combined` (`None`: auto, the MF functions).
fn combination(path: &Path, name: &str) -> Result<Option<Combination>> {
    match name {
        "auto" => Ok(None),
        "magic_formula" => Ok(Some(Combination::MagicFormula)),
        "ellipse" => Ok(Some(Combination::Ellipse)),
        other => Err(Error::key(
            path,
            "pacejka.combined",
            format!("unknown method '{other}'; allowed: auto, magic_formula, ellipse"),
        )),
    }
}

/// Every key of the table `table` (e.g. `pacejka.overrides`) names a Magic Formula coefficient.
fn check_coefficient_names<'a>(path: &Path, table: &str, keys: impl Iterator<Item = &'a String>) -> Result<()> {
    for k in keys {
        if !MfCoefficients::NAMES.contains(&k.as_str()) {
            return Err(Error::key(path, &format!("{table}.{k}"), "not a Magic Formula coefficient name"));
        }
    }
    Ok(())
}

/// The side a `.tir` file's TYRESIDE names (left when absent).
fn tir_side(f: &crate::tir::TirFile, tir_path: &Path) -> Result<TyreSide> {
    match f.string("TYRESIDE").map(|v| v.trim().to_ascii_uppercase()) {
        None if f.num("TYRESIDE").is_some() => {
            Err(Error::key(tir_path, "TYRESIDE", "expected 'LEFT' or 'RIGHT' (a quoted string)"))
        }
        None => Ok(TyreSide::Left),
        Some(v) if v == "LEFT" => Ok(TyreSide::Left),
        Some(v) if v == "RIGHT" => Ok(TyreSide::Right),
        Some(v) => Err(Error::key(tir_path, "TYRESIDE", format!("unknown tyre side '{v}'; allowed: 'LEFT', 'RIGHT'"))),
    }
}

/// The coefficients within the ranges a Magic Formula tyre has (messages name the file `c` checks).
fn check_coefficients(cs: &Checker, coeffs: &MfCoefficients) -> Result<()> {
    cs.positive_up_to("FNOMIN", coeffs.fnomin, MAX_NOMINAL_LOAD_N, "N")?;
    cs.positive_up_to("UNLOADED_RADIUS", coeffs.unloaded_radius, 2.0, "m")?;
    cs.positive_up_to("LFZO", coeffs.lfzo, 10.0, "scale factor")?;
    // The ranges a Magic Formula tyre has (PAC2002): shape factors C up to 3 (lateral about
    // 1.3, longitudinal about 1.65), peak friction D/Fz up to 5 (racing slicks stay under 2),
    // slip stiffness over load up to 100 (passenger tyres 15-30).
    for (n, v, hi, what) in [
        ("PCX1", coeffs.pcx1, 3.0, "shape factor"),
        ("PDX1", coeffs.pdx1, 5.0, "peak friction"),
        ("PCY1", coeffs.pcy1, 3.0, "shape factor"),
        ("PDY1", coeffs.pdy1, 5.0, "peak friction"),
        ("PKX1", coeffs.pkx1, 100.0, "slip stiffness over load"),
    ] {
        cs.positive_up_to(n, v, hi, what)?;
    }
    cs.require(
        "PKY1",
        coeffs.pky1,
        coeffs.pky1 != 0.0 && coeffs.pky1.abs() <= 100.0,
        "expected a non-zero cornering stiffness factor with |PKY1| <= 100 (Ky / Fz0'; ISO files -10 to -25)",
    )?;
    cs.require(
        "PKY2",
        coeffs.pky2,
        coeffs.pky2 > 0.0 && coeffs.pky2 <= 10.0,
        "expected 0 < PKY2 <= 10 (load at which Ky peaks, in Fz0')",
    )?;
    // The curvature factor E must stay <= 1 (PAC2002; above it the curve folds back). At the
    // nominal load: Ex = PEX1 LEX (1 -/+ PEX4) for driving / braking, Ey = PEY1 LEY (1 -/+ PEY3).
    for (n, e0, asym, lbl) in [
        ("PEX1", coeffs.pex1 * coeffs.lex, coeffs.pex4, "PEX1 LEX (1 -/+ PEX4)"),
        ("PEY1", coeffs.pey1 * coeffs.ley, coeffs.pey3, "PEY1 LEY (1 -/+ PEY3)"),
    ] {
        let e = (e0 * (1.0 - asym)).max(e0 * (1.0 + asym));
        if e > 1.0 || e.is_nan() {
            return Err(Error::key(
                cs.file,
                n,
                format!(
                    "the curvature factor E = {lbl} reaches {} at the nominal load; the Magic Formula needs \
                     E <= 1 (PAC2002)",
                    vehsim_core::error::short_num(e)
                ),
            ));
        }
    }
    Ok(())
}

/// The warning for a Magic Formula combination whose R coefficients are absent or 0.
fn combined_slip_warning(t: &PacejkaTyre, source: &Path) -> Option<String> {
    if t.combination == Combination::MagicFormula {
        let c2 = &t.coeffs;
        let absent: Vec<&str> = [("RBX1", c2.rbx1), ("RCX1", c2.rcx1), ("RBY1", c2.rby1), ("RCY1", c2.rcy1)]
            .iter()
            .filter(|(_, v)| *v == 0.0)
            .map(|(n, _)| *n)
            .collect();
        if !absent.is_empty() {
            return Some(format!(
                "{}: combined-slip coefficient(s) {} absent or 0; as in PAC2002 implementations the weighting function is 1 there (no combined-slip interaction: each force keeps its pure-slip value, a friction square). Add the R coefficients or set combined = \"ellipse\" for a friction ellipse",
                source.display(),
                absent.join(", ")
            ));
        }
    }
    None
}

/// Largest slip stiffness (cornering N/rad, longitudinal N per unit slip) at the nominal load:
/// ten times a heavy lorry tyre's (passenger tyres 50-150 kN, lorry tyres up to about 500 kN).
pub(crate) const MAX_STIFFNESS_N: f64 = 5e6;

/// Largest nominal load of one tyre, N (a lorry tyre carries up to about 40 kN).
pub(crate) const MAX_NOMINAL_LOAD_N: f64 = 100_000.0;

/// Error for a provider whose section is absent from the tyre file.
pub fn missing(path: &Path, section: &str) -> Error {
    Error::input(
        path,
        format!(
            "tyre model '{section}' was selected but the tyre file has no [{section}] section with its coefficients"
        ),
    )
}

/// The ranges declared by the `.tir` file of the tyre file `tyre_file`'s `[pacejka]` section
/// (none for a tyre without one). The files were validated when the vehicle was built; a
/// file that cannot be read here declares nothing.
pub(crate) fn declared_ranges(tyre_file: &Path) -> TyreRanges {
    let Ok(spec) = crate::tyre::TyreFileSpec::load(tyre_file) else { return TyreRanges::default() };
    let Some(tir) = spec.pacejka.as_ref().and_then(|p| p.tir_file.as_ref()) else { return TyreRanges::default() };
    let Ok(f) = crate::tir::read_tir(&crate::files::resolve(tyre_file, tir)) else {
        return TyreRanges::default();
    };
    let pair = |lo: &str, hi: &str| match (f.num(lo), f.num(hi)) {
        (Some(a), Some(b)) if a < b => Some((a, b)),
        _ => None,
    };
    TyreRanges { kappa: pair("KPUMIN", "KPUMAX"), alpha_rad: pair("ALPMIN", "ALPMAX"), fz_n: pair("FZMIN", "FZMAX") }
}
