//! Spec files of the contact model: the optional `[contact]` table of manoeuvre files
//! ([`ContactSpec`], built into a [`ContactTemperature`]) and the ATIIM scenario files of
//! `vehsim atiim` ([`ScenarioSpec`]). Raw serde types are checked here into validated values;
//! every problem is an `Error::Input` naming the file and the key.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::files::{read_input, resolve};
use crate::patch_file::{parse_csv, read_png_map, ImageLayout};
use vehsim_core::contact::estimator::{AtiimEstimator, BulkParams, FlashTable, Statistic, TableRanges, TyreBuild};
use vehsim_core::contact::film::FilmParams;
use vehsim_core::contact::model::{carcass_stiffness_n_per_m, PatchParams};
use vehsim_core::contact::patch::{synthesize, tilt_for_slip_angle, PressureGrid, SynthInputs, TreadPattern};
use vehsim_core::contact::thermal::{gent_modulus_mpa, preset_shore_a, Compound, PRESETS};
use vehsim_core::contact::tread_state::TreadState;
use vehsim_core::contact::{ContactTemperature, Isothermal};
use vehsim_core::error::{Checker, Error, Result};
use vehsim_core::tyre::friction::IceFriction;
use vehsim_core::vehicle::params::Lateral;

fn d_inflation() -> f64 {
    241.3
}
fn d_width() -> f64 {
    0.18
}
fn d_rated() -> f64 {
    7000.0
}
fn d_compound() -> String {
    "srtt".into()
}
fn d_void() -> f64 {
    0.3
}
fn d_ribs() -> usize {
    5
}
fn d_pitch() -> f64 {
    0.03
}
fn d_depth() -> f64 {
    7.97e-3
}
fn d_mu() -> f64 {
    0.15
}
fn d_kappa() -> f64 {
    1.0
}
fn d_asp() -> f64 {
    vehsim_core::contact::film::DEFAULT_ASPERITY_D_M
}
fn d_hc() -> f64 {
    50.0
}
fn d_true() -> bool {
    true
}
fn d_lock() -> f64 {
    1.0
}
fn d_sub() -> usize {
    8
}
fn d_radius() -> f64 {
    0.328
}
fn d_peak() -> f64 {
    0.35
}
fn d_peak_speed() -> f64 {
    0.005
}
fn d_peak_width() -> f64 {
    1.0
}
fn d_p_exp() -> f64 {
    0.25
}
fn d_t_coeff() -> f64 {
    IceFriction::srtt(0.15).temp_coeff_per_k
}
fn d_speed_scale() -> f64 {
    IceFriction::srtt(0.15).speed_scale_mps
}
fn d_speed_exp() -> f64 {
    IceFriction::srtt(0.15).speed_exponent
}
fn d_carcass() -> f64 {
    vehsim_core::contact::model::SRTT_CARCASS_N_PER_M * 1e-3
}
fn d_frr() -> f64 {
    0.010
}

/// Tyre and interface parameters shared by `[contact]` and scenario files (all optional).
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TyreSpec {
    /// Inflation pressure, kPa (100–400; 35 psi = 241.3).
    #[serde(default = "d_inflation")]
    pub inflation_kpa: f64,
    /// Tread (contact) width at rated load, m (0.05–0.4; SRTT 0.18).
    #[serde(default = "d_width")]
    pub tread_width_m: f64,
    /// Rated load (100 % load index), N (SRTT 7000).
    #[serde(default = "d_rated")]
    pub rated_load_n: f64,
    /// Compound preset from Table 3.4: "srtt" (= "tire_a"), "tire_b", "tire_d", "tire_e".
    #[serde(default = "d_compound")]
    pub compound: String,
    /// Shore A hardness overriding the preset (30–95).
    pub shore_a: Option<f64>,
    /// Void ratio, 0–0.6.
    #[serde(default = "d_void")]
    pub void_ratio: f64,
    /// Circumferential ribs, 1–12.
    #[serde(default = "d_ribs")]
    pub ribs: usize,
    /// Transverse groove pitch, m (0 = ribs only).
    #[serde(default = "d_pitch")]
    pub block_pitch_m: f64,
    /// Tread depth, m (0.002–0.015).
    #[serde(default = "d_depth")]
    pub tread_depth_m: f64,
    /// Dry rubber-ice friction at the reference conditions (-10 degC, 0.028 m/s sliding,
    /// 250 kPa), 0.02–0.6.
    #[serde(default = "d_mu")]
    pub mu_dry: f64,
    /// Adhesion-peak gain of the dry friction over its base, 0–2 (0 = no peak).
    #[serde(default = "d_peak")]
    pub adhesion_peak: f64,
    /// Sliding speed of the adhesion peak, m/s (1e-4 – 1).
    #[serde(default = "d_peak_speed")]
    pub peak_speed_mps: f64,
    /// Width of the adhesion peak in ln(sliding speed), 0.2–5.
    #[serde(default = "d_peak_width")]
    pub peak_width: f64,
    /// Exponent of the dry friction's fall with contact pressure, 0–1.
    #[serde(default = "d_p_exp")]
    pub pressure_exponent: f64,
    /// Relative fall of the dry friction per kelvin of interface temperature, 1/K (0–0.2).
    #[serde(default = "d_t_coeff")]
    pub temp_coeff_per_k: f64,
    /// Sliding speed where the friction's fall at road sliding speeds sets in, m/s (0.001–10).
    #[serde(default = "d_speed_scale")]
    pub speed_scale_mps: f64,
    /// Exponent of that fall, (1 + v/v_c)^-n, 0–1 (0 = none).
    #[serde(default = "d_speed_exp")]
    pub speed_exponent: f64,
    /// In-patch belt and carcass compliance at 241.3 kPa inflation, as a longitudinal spring shared
    /// by the contact area, kN/m (0 = rigid, else 50–5000; SRTT 3600, which puts the slip stiffness
    /// at 22 F_z at 7 kN); scaled in proportion to `inflation_kpa`.
    #[serde(default = "d_carcass")]
    pub carcass_stiffness_kn_per_m: f64,
    /// Rolling-resistance coefficient for the rolling (hysteresis) heat, 0–0.05.
    #[serde(default = "d_frr")]
    pub rolling_resistance: f64,
    /// Real-contact ratio kappa, (0, 1].
    #[serde(default = "d_kappa")]
    pub kappa: f64,
    /// Asperity contact diameter D for squeeze-out, m (1e-6 – 1); default 20 µm
    /// (`film::DEFAULT_ASPERITY_D_M`, docs/atiim.md).
    #[serde(default = "d_asp")]
    pub asperity_d_m: f64,
    /// Critical film height of eq. 2.1, nm (1–10000).
    #[serde(default = "d_hc")]
    pub critical_film_nm: f64,
    /// Brush adhesion zone (true) or full sliding (false).
    #[serde(default = "d_true")]
    pub brush: bool,
    /// Tread contact-time cap (lock duration), s (0.01–100).
    #[serde(default = "d_lock")]
    pub lock_time_s: f64,
    /// Film sub-steps per pixel, 1–256.
    #[serde(default = "d_sub")]
    pub film_substeps: usize,
}

impl Default for TyreSpec {
    fn default() -> Self {
        // deserializing an empty table applies every default
        toml::from_str("").unwrap_or_else(|_| unreachable!("defaults are valid"))
    }
}

impl TyreSpec {
    /// Validated pattern.
    pub fn pattern(&self) -> TreadPattern {
        TreadPattern { ribs: self.ribs, void_ratio: self.void_ratio, block_pitch_m: self.block_pitch_m }
    }

    /// Validate and build the patch-model parameters at ice temperature `ice_c` (for the preset).
    pub fn params(&self, file: &Path, prefix: &str, ice_c: f64) -> Result<PatchParams> {
        let ck = Checker::new(file);
        let k = |n: &str| format!("{prefix}{n}");
        ck.range(&k("inflation_kpa"), self.inflation_kpa, 100.0, 400.0)?;
        ck.range(&k("tread_width_m"), self.tread_width_m, 0.05, 0.4)?;
        ck.range(&k("rated_load_n"), self.rated_load_n, 500.0, 50_000.0)?;
        ck.range(&k("void_ratio"), self.void_ratio, 0.0, 0.6)?;
        ck.range(&k("ribs"), self.ribs as f64, 1.0, 12.0)?;
        ck.range(&k("block_pitch_m"), self.block_pitch_m, 0.0, 0.2)?;
        ck.range(&k("tread_depth_m"), self.tread_depth_m, 0.002, 0.015)?;
        ck.range(&k("mu_dry"), self.mu_dry, 0.02, 0.6)?;
        ck.range(&k("adhesion_peak"), self.adhesion_peak, 0.0, 2.0)?;
        ck.range(&k("peak_speed_mps"), self.peak_speed_mps, 1e-4, 1.0)?;
        ck.range(&k("peak_width"), self.peak_width, 0.2, 5.0)?;
        ck.range(&k("pressure_exponent"), self.pressure_exponent, 0.0, 1.0)?;
        ck.range(&k("temp_coeff_per_k"), self.temp_coeff_per_k, 0.0, 0.2)?;
        ck.range(&k("speed_scale_mps"), self.speed_scale_mps, 0.001, 10.0)?;
        ck.range(&k("speed_exponent"), self.speed_exponent, 0.0, 1.0)?;
        let c = self.carcass_stiffness_kn_per_m;
        ck.require(
            &k("carcass_stiffness_kn_per_m"),
            c,
            c == 0.0 || (50.0..=5000.0).contains(&c),
            "expected 0 (rigid) or 50..5000 kN/m",
        )?;
        ck.range(&k("rolling_resistance"), self.rolling_resistance, 0.0, 0.05)?;
        ck.require(&k("kappa"), self.kappa, self.kappa > 0.0 && self.kappa <= 1.0, "expected 0 < kappa <= 1")?;
        ck.range(&k("asperity_d_m"), self.asperity_d_m, 1e-6, 1.0)?;
        ck.range(&k("critical_film_nm"), self.critical_film_nm, 1.0, 10_000.0)?;
        ck.range(&k("lock_time_s"), self.lock_time_s, 0.01, 100.0)?;
        ck.range(&k("film_substeps"), self.film_substeps as f64, 1.0, 256.0)?;
        let shore = match self.shore_a {
            Some(s) => ck.range(&k("shore_a"), s, 30.0, 95.0)?,
            None => preset_shore_a(&self.compound, ice_c).ok_or_else(|| {
                Error::key(
                    file,
                    &k("compound"),
                    format!("unknown compound '{}'; expected one of {}", self.compound, PRESETS.join(", ")),
                )
            })?,
        };
        if gent_modulus_mpa(shore).is_none() {
            return Err(Error::key(file, &k("shore_a"), "Shore A must be in (0, 99]"));
        }
        Ok(PatchParams {
            compound: Compound::generic(shore),
            mu_dry: self.mu_dry,
            dry: IceFriction {
                mu_ref: self.mu_dry,
                peak_gain: self.adhesion_peak,
                peak_speed_mps: self.peak_speed_mps,
                peak_width: self.peak_width,
                pressure_exponent: self.pressure_exponent,
                temp_coeff_per_k: self.temp_coeff_per_k,
                speed_scale_mps: self.speed_scale_mps,
                speed_exponent: self.speed_exponent,
                ..IceFriction::srtt(self.mu_dry)
            },
            carcass_n_per_m: carcass_stiffness_n_per_m(self.carcass_stiffness_kn_per_m * 1e3, self.inflation_kpa * 1e3),
            rolling_resistance: self.rolling_resistance,
            film: FilmParams { kappa: self.kappa, asperity_d_m: self.asperity_d_m, substeps: self.film_substeps },
            critical_film_m: self.critical_film_nm * 1e-9,
            tread_depth_m: self.tread_depth_m,
            void_ratio: self.void_ratio,
            brush: self.brush,
            lock_time_s: self.lock_time_s,
        })
    }
}

fn d_model() -> String {
    "isothermal".into()
}

/// The optional `[contact]` table of a manoeuvre file.
///
/// ```toml
/// [contact]
/// model = "atiim"              # "isothermal" (default) or "atiim"
/// rolling_radius_m = 0.328
/// load_range_n = [1000.0, 12000.0]
/// [contact.tyre]               # any TyreSpec key, all optional
/// inflation_kpa = 241.3
/// ```
#[derive(Debug, Clone, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// "isothermal" or "atiim".
    #[serde(default = "d_model")]
    pub model: String,
    /// Tyre and interface parameters (`[contact.tyre]`), all optional.
    #[serde(default)]
    pub tyre: TyreSpec,
    /// Rolling radius, m (0.2–0.6), for the tread band's area and heat capacity.
    #[serde(default = "d_radius")]
    pub rolling_radius_m: f64,
    /// Heated skin depth of the tread, m (0.5e-3 – 5e-3).
    pub skin_depth_m: Option<f64>,
    /// Air temperature, degC; default: the surface temperature.
    pub air_temp_c: Option<f64>,
    /// Table ranges: load N, sliding speed m/s, smallest slip fraction v_slide / (v_roll +
    /// v_slide) (1e-6 – 0.1). The ice temperature needs no range (see `FlashTable`).
    pub load_range_n: Option<[f64; 2]>,
    /// Sliding-speed range of the table [lo, hi], m/s (lo in [1e-4, 10], lo < hi <= 200; default [0.01, 30]).
    pub slide_speed_range_mps: Option<[f64; 2]>,
    /// Smallest slip fraction v_slide / (v_roll + v_slide) of the table, [1e-6, 0.1] (default 1e-4).
    pub slip_fraction_min: Option<f64>,
    /// Table nodes per axis [load, slide, slip fraction, melting-cap coordinate w] (each 2–32).
    pub table_nodes: Option<[usize; 4]>,
    /// Patch grid of the table [rows, cols] (each 8–128).
    pub table_grid: Option<[usize; 2]>,
    /// Statistic of the patch's rise fed to the tyre: "max" (default) or "mean".
    pub statistic: Option<String>,
}

/// The contact-temperature models a spec can select (`[contact] model`, `bench --contact`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactModelKind {
    /// No heating: the tyre sees the surface temperature.
    Isothermal,
    /// The ATIIM flash-temperature estimate ([`AtiimEstimator`]).
    Atiim,
}

vehsim_core::choice_names!(ContactModelKind {
    Isothermal => "isothermal",
    Atiim => "atiim",
});

impl Default for ContactSpec {
    fn default() -> Self {
        toml::from_str("").unwrap_or_else(|_| unreachable!("defaults are valid"))
    }
}

impl ContactSpec {
    /// Validated table ranges.
    pub fn ranges(&self, file: &Path) -> Result<TableRanges> {
        let ck = Checker::new(file);
        let mut r = TableRanges::default();
        if let Some([a, b]) = self.load_range_n {
            ck.range("contact.load_range_n[0]", a, 100.0, 50_000.0)?;
            ck.require("contact.load_range_n[1]", b, b > a && b <= 100_000.0, "expected lo < hi <= 100000")?;
            r.load_n = (a, b, r.load_n.2);
        }
        if let Some([a, b]) = self.slide_speed_range_mps {
            ck.range("contact.slide_speed_range_mps[0]", a, 1e-4, 10.0)?;
            ck.require("contact.slide_speed_range_mps[1]", b, b > a && b <= 200.0, "expected lo < hi <= 200")?;
            r.slide_mps = (a, b, r.slide_mps.2);
        }
        if let Some(v) = self.slip_fraction_min {
            ck.range("contact.slip_fraction_min", v, 1e-6, 0.1)?;
            r.sigma_min.0 = v;
        }
        if let Some(n) = self.table_nodes {
            for (i, v) in n.iter().enumerate() {
                ck.range(&format!("contact.table_nodes[{i}]"), *v as f64, 2.0, 32.0)?;
            }
            r.load_n.2 = n[0];
            r.slide_mps.2 = n[1];
            r.sigma_min.1 = n[2];
            r.w.2 = n[3];
        }
        if let Some([a, b]) = self.table_grid {
            ck.range("contact.table_grid[0]", a as f64, 8.0, 128.0)?;
            ck.range("contact.table_grid[1]", b as f64, 8.0, 128.0)?;
            r.grid = (a, b);
        }
        if let Some(st) = &self.statistic {
            r.statistic = Statistic::parse(st).ok_or_else(|| {
                Error::key(
                    file,
                    "contact.statistic",
                    format!("unknown statistic '{st}'; allowed: {}", Statistic::allowed()),
                )
            })?;
        }
        Ok(r)
    }

    /// Build the estimator for `n_tyres` tyres on ice at `ice_temp_c` (used for the compound
    /// preset's hardness). `file` is the manoeuvre file (named in errors).
    pub fn build(&self, file: &Path, n_tyres: usize, ice_temp_c: f64) -> Result<Box<dyn ContactTemperature>> {
        match self.kind(file)? {
            ContactModelKind::Isothermal => Ok(Box::new(Isothermal)),
            ContactModelKind::Atiim => Ok(Box::new(self.build_atiim(file, n_tyres, ice_temp_c)?)),
        }
    }

    /// The run's estimate for a vehicle whose `[lateral]` section is `lateral`: its tread state
    /// ([`TreadState`]) when `tread_mu_per_kj` is set (the manoeuvre's validation refuses it beside
    /// another estimate), else [`ContactSpec::build`]. `tread_heat_capacity_j_per_k` is one axle's
    /// (as `vehsim discover` fits it, from axle forces); the estimate's conditions are one tyre's,
    /// so each tyre of the axle carries half the axle's heat in half its capacity.
    pub fn build_for(
        &self,
        file: &Path,
        lateral: &Lateral,
        n_tyres: usize,
        ice_temp_c: f64,
    ) -> Result<Box<dyn ContactTemperature>> {
        if lateral.tread_mu_per_kj != 0.0 {
            let per_tyre_j_per_k = 0.5 * lateral.tread_heat_capacity_j_per_k;
            return Ok(Box::new(TreadState::new(per_tyre_j_per_k, lateral.tread_cooling_time_s)));
        }
        self.build(file, n_tyres, ice_temp_c)
    }

    /// The contact model `model` names (`file`, the manoeuvre file, is named in the error).
    pub fn kind(&self, file: &Path) -> Result<ContactModelKind> {
        ContactModelKind::parse(&self.model).ok_or_else(|| {
            Error::key(
                file,
                "contact.model",
                format!("unknown model '{}'; allowed: {}", self.model, ContactModelKind::allowed()),
            )
        })
    }

    /// Build the concrete ATIIM estimator (see [`ContactSpec::build`]).
    pub fn build_atiim(&self, file: &Path, n_tyres: usize, ice_temp_c: f64) -> Result<AtiimEstimator> {
        let ck = Checker::new(file);
        ck.range("surface temperature", ice_temp_c, -60.0, 10.0)?;
        let params = self.tyre.params(file, "contact.tyre.", ice_temp_c)?;
        ck.range("contact.rolling_radius_m", self.rolling_radius_m, 0.1, 1.0)?;
        let skin = self.skin_depth_m.unwrap_or(2e-3);
        ck.range("contact.skin_depth_m", skin, 0.5e-3, 5e-3)?;
        if let Some(t) = self.air_temp_c {
            ck.range("contact.air_temp_c", t, -60.0, 50.0)?;
        }
        let rg = self.ranges(file)?;
        let tyre = TyreBuild {
            inflation_pa: self.tyre.inflation_kpa * 1e3,
            tread_width_m: self.tyre.tread_width_m,
            rated_load_n: self.tyre.rated_load_n,
            pattern: self.tyre.pattern(),
            params,
        };
        let table =
            cached_table(&format!("{self:?}|{}", ice_temp_c.to_bits()), || FlashTable::build(file, &tyre, &rg))?;
        let s = params.compound.solid;
        let band = 2.0 * std::f64::consts::PI * self.rolling_radius_m * self.tyre.tread_width_m;
        let bulk = BulkParams {
            heat_capacity_j_k: s.density_kg_m3 * s.specific_heat_j_kgk * band * skin,
            band_area_m2: band,
            tread_fraction: vehsim_core::contact::estimator::rolling_tread_fraction(s.effusivity()),
            air_temp_c: self.air_temp_c,
            area_per_n: 1.0 / (self.tyre.inflation_kpa * 1e3),
            width_m: self.tyre.tread_width_m,
            e_tread: s.effusivity(),
            rolling_heat_per_n_mps: vehsim_core::contact::estimator::TREAD_HYSTERESIS_SHARE
                * self.tyre.rolling_resistance,
        };
        Ok(AtiimEstimator::new(table, bulk, n_tyres))
    }
}

/// The flash table for `key` (the contact spec and ice temperature it is built from), built once
/// per process: a batch of runs with the same `[contact]` table shares it. Building is
/// deterministic, so a cached table equals a fresh one.
fn cached_table(key: &str, build: impl FnOnce() -> Result<FlashTable>) -> Result<FlashTable> {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    static CACHE: OnceLock<Mutex<HashMap<String, FlashTable>>> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(t) = cache.lock().ok().and_then(|c| c.get(key).cloned()) {
        return Ok(t);
    }
    let t = build()?;
    if let Ok(mut c) = cache.lock() {
        c.insert(key.to_string(), t.clone());
    }
    Ok(t)
}

/// Where the pressure grid of a scenario comes from (`[pressure] source`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PressureSource {
    /// Synthesised from the load, inflation and tread.
    Synth,
    /// A CSV grid of pressures.
    Csv,
    /// A pressure-film image with its colour bar.
    Image,
}

vehsim_core::choice_names!(PressureSource {
    Synth => "synth",
    Csv => "csv",
    Image => "image",
});

/// Raw `[pressure]` table of a scenario.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PressureSpec {
    /// "synth", "csv" or "image".
    pub source: String,
    /// synth: normal load, N.
    pub load_n: Option<f64>,
    /// synth: camber, deg.
    pub camber_deg: Option<f64>,
    /// synth: grid [rows along travel, cols across] (default [64, 48]).
    pub grid: Option<[usize; 2]>,
    /// csv / image: file path relative to the scenario file.
    pub file: Option<String>,
    /// csv / image: pixel length along travel and width across, m.
    pub pixel_length_m: Option<f64>,
    /// csv / image: pixel width across the tread, m.
    pub pixel_width_m: Option<f64>,
    /// image: footprint and colour-bar boxes [x0, y0, x1, y1) in image pixels.
    pub footprint: Option<[u32; 4]>,
    /// image: colour-bar box [x0, y0, x1, y1) in image pixels.
    pub colour_bar: Option<[u32; 4]>,
    /// image: pressures at the bar's bottom and top, kPa.
    pub bar_min_kpa: Option<f64>,
    /// image: pressure at the bar's top, kPa.
    pub bar_max_kpa: Option<f64>,
    /// image: colour-matching tolerance (RGB distance, default 60).
    pub tolerance: Option<f64>,
}

/// Operating point of a scenario.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OperatingSpec {
    /// Travel speed V, m/s (0.01–80).
    pub speed_mps: f64,
    /// Slip ratio kappa = (omega R - V_x) / V_x (-1 = locked wheel, < 0 braking, > 0 driving), -1..2.
    pub slip_ratio: f64,
    /// Slip angle, deg (-30..30): enters the sliding velocity and, for synthesized patches, tilts
    /// the pressure toward the side the wheel slides to.
    #[serde(default)]
    pub slip_angle_deg: f64,
    /// Ice temperature, degC (-40..0).
    pub ice_temp_c: f64,
    /// Wheel torque, N m — documentation only (the dissertation's figure label); not used.
    pub wheel_torque_nm: Option<f64>,
}

/// Drawbar-pull sweep of a scenario.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DrawbarSpec {
    /// Slip ratios, -1..2 (< 0 braking; default 0 to 0.02 in steps of 0.0005, then to 0.4 in steps of 0.005).
    pub slips: Option<Vec<f64>>,
    /// Travel speed of the sweep, m/s (default: the operating speed).
    pub speed_mps: Option<f64>,
}

/// An ATIIM scenario file (`vehsim atiim FILE`).
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Output folder name: letters, digits, '_', '-'.
    pub name: String,
    /// Free text shown in plot titles.
    #[serde(default)]
    pub title: String,
    /// Contact-pressure source (`[pressure]`): synthesized, CSV or image.
    pub pressure: PressureSpec,
    /// Operating point (`[operating]`): speed, slip ratio, slip angle, ice temperature.
    pub operating: OperatingSpec,
    /// Tyre and interface parameters (`[tyre]`), all optional.
    #[serde(default)]
    pub tyre: TyreSpec,
    /// Drawbar-pull sweep over slip ratio (`[drawbar]`; optional).
    pub drawbar: Option<DrawbarSpec>,
}

/// A validated scenario.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Output folder name.
    pub name: String,
    /// Free text shown in plot titles.
    pub title: String,
    /// The contact-pressure grid (for a synthesized patch, tilted for the slip angle).
    pub grid: PressureGrid,
    /// Validated patch-model parameters at the scenario's ice temperature.
    pub params: PatchParams,
    /// Travel speed, slip ratio, slip angle (rad), ice temperature.
    pub speed_mps: f64,
    /// Slip ratio (omega R - V_x) / V_x, in [-1, 2] (positive driving, -1 locked).
    pub slip_ratio: f64,
    /// Slip angle, rad (from `slip_angle_deg`, [-30, 30] deg).
    pub slip_angle_rad: f64,
    /// Ice temperature, degC, in [-40, 0].
    pub ice_temp_c: f64,
    /// Slip ratios of the drawbar-pull sweep (< 0 braking).
    pub drawbar_slips: Vec<f64>,
    /// Travel speed of the drawbar-pull sweep, m/s, in [0.01, 80].
    pub drawbar_speed_mps: f64,
    /// The scenario file as read.
    pub spec: ScenarioSpec,
}

fn need<T: Copy>(file: &Path, key: &str, v: Option<T>, src: &str) -> Result<T> {
    v.ok_or_else(|| Error::key(file, key, format!("required when source = \"{src}\"")))
}

impl ScenarioSpec {
    /// Read and validate a scenario file.
    pub fn load(file: &Path) -> Result<Scenario> {
        let text = read_input(file)?;
        crate::kind::expect_text(file, &text, crate::kind::SpecKind::AtiimScenario)?;
        let spec: ScenarioSpec = crate::files::parse_toml(file, &text)?;
        spec.validate(file)
    }

    /// Validate into a [`Scenario`] (reads the CSV or image the spec points to).
    pub fn validate(self, file: &Path) -> Result<Scenario> {
        let ck = Checker::new(file);
        if self.name.is_empty() || !self.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(Error::key(
                file,
                "name",
                format!("'{}' is not allowed; use letters, digits, '_' and '-'", self.name),
            ));
        }
        let o = &self.operating;
        ck.range("operating.speed_mps", o.speed_mps, 0.01, 80.0)?;
        ck.range("operating.slip_ratio", o.slip_ratio, -1.0, 2.0)?;
        ck.range("operating.slip_angle_deg", o.slip_angle_deg, -30.0, 30.0)?;
        ck.range("operating.ice_temp_c", o.ice_temp_c, -40.0, 0.0)?;
        let params = self.tyre.params(file, "tyre.", o.ice_temp_c)?;
        let grid = self.pressure_grid(file)?;
        let (slips, dspeed) = self.drawbar_slips(&ck)?;
        Ok(Scenario {
            name: self.name.clone(),
            title: self.title.clone(),
            grid,
            params,
            speed_mps: o.speed_mps,
            slip_ratio: o.slip_ratio,
            slip_angle_rad: o.slip_angle_deg.to_radians(),
            ice_temp_c: o.ice_temp_c,
            drawbar_slips: slips,
            drawbar_speed_mps: dspeed,
            spec: self,
        })
    }

    /// The contact-pressure grid of `[pressure]`: synthesized (and tilted for the slip angle),
    /// or read from a CSV file or a PNG pressure map; at most 512 x 512 pixels.
    fn pressure_grid(&self, file: &Path) -> Result<PressureGrid> {
        let p = &self.pressure;
        let source = PressureSource::parse(&p.source).ok_or_else(|| {
            Error::key(
                file,
                "pressure.source",
                format!("unknown source '{}'; allowed: {}", p.source, PressureSource::allowed()),
            )
        })?;
        let grid = match source {
            PressureSource::Synth => {
                let mut grid = self.synthesized_grid(file)?;
                tilt_for_slip_angle(&mut grid, self.operating.slip_angle_deg.to_radians());
                grid
            }
            PressureSource::Csv | PressureSource::Image => self.grid_from_file(file, source)?,
        };
        if grid.rows * grid.cols > 512 * 512 {
            return Err(Error::key(file, "pressure", "grid larger than 512 x 512 pixels"));
        }
        Ok(grid)
    }

    /// `source = "synth"`: a grid synthesized from the load and the tyre data.
    fn synthesized_grid(&self, file: &Path) -> Result<PressureGrid> {
        let p = &self.pressure;
        let [rows, cols] = p.grid.unwrap_or([64, 48]);
        // (named here: `synthesize` names its own fields, not the scenario's keys)
        let ck = Checker::new(file);
        ck.range("pressure.grid[0]", rows as f64, 4.0, 512.0)?;
        ck.range("pressure.grid[1]", cols as f64, 4.0, 512.0)?;
        let load = need(file, "pressure.load_n", p.load_n, "synth")?;
        synthesize(
            file,
            &SynthInputs {
                load_n: load,
                inflation_pa: self.tyre.inflation_kpa * 1e3,
                tread_width_m: self.tyre.tread_width_m,
                rated_load_n: self.tyre.rated_load_n,
                camber_deg: p.camber_deg.unwrap_or(0.0),
                pattern: self.tyre.pattern(),
                rows,
                cols,
            },
        )
    }

    /// `source = "csv"` or `"image"`: a grid read from the file `pressure.file` names.
    fn grid_from_file(&self, file: &Path, source: PressureSource) -> Result<PressureGrid> {
        let p = &self.pressure;
        let ck = Checker::new(file);
        let rel =
            p.file.as_deref().ok_or_else(|| Error::key(file, "pressure.file", "required for csv and image sources"))?;
        let path: PathBuf = resolve(file, rel);
        let dx = ck.range(
            "pressure.pixel_length_m",
            need(file, "pressure.pixel_length_m", p.pixel_length_m, &p.source)?,
            1e-5,
            0.05,
        )?;
        let dy = ck.range(
            "pressure.pixel_width_m",
            need(file, "pressure.pixel_width_m", p.pixel_width_m, &p.source)?,
            1e-5,
            0.05,
        )?;
        if source == PressureSource::Csv {
            parse_csv(&path, &read_input(&path)?, dx, dy)
        } else {
            let bytes = std::fs::read(&path).map_err(|e| Error::input(&path, format!("cannot read image: {e}")))?;
            let lo = need(file, "pressure.bar_min_kpa", p.bar_min_kpa, "image")?;
            let hi = need(file, "pressure.bar_max_kpa", p.bar_max_kpa, "image")?;
            read_png_map(
                &path,
                &bytes,
                &ImageLayout {
                    footprint: need(file, "pressure.footprint", p.footprint, "image")?,
                    colour_bar: need(file, "pressure.colour_bar", p.colour_bar, "image")?,
                    bar_min_pa: lo * 1e3,
                    bar_max_pa: hi * 1e3,
                    tolerance: ck.range("pressure.tolerance", p.tolerance.unwrap_or(60.0), 1.0, 442.0)?,
                    dx_m: dx,
                    dy_m: dy,
                },
            )
        }
    }

    /// The slips of the drawbar-pull curve (default: fine near 0, 0.5 % steps to 40 %) and the
    /// speed it is evaluated at, m/s (default the operating speed).
    fn drawbar_slips(&self, ck: &Checker) -> Result<(Vec<f64>, f64)> {
        let o = &self.operating;
        let (slips, dspeed) = match &self.drawbar {
            Some(d) => (
                d.slips.clone().unwrap_or_else(default_slips),
                ck.range("drawbar.speed_mps", d.speed_mps.unwrap_or(o.speed_mps), 0.01, 80.0)?,
            ),
            None => (default_slips(), o.speed_mps),
        };
        for (i, s) in slips.iter().enumerate() {
            ck.range(&format!("drawbar.slips[{i}]"), *s, -1.0, 2.0)?;
        }
        Ok((slips, dspeed))
    }
}

/// 0 to 0.02 in steps of 0.0005 (the steep rise), then to 0.40 in steps of 0.005: fine enough
/// that the drawn curve is the curve, not a polygon through a few points.
fn default_slips() -> Vec<f64> {
    (0..40).map(|i| f64::from(i) * 0.0005).chain((4..=80).map(|i| f64::from(i) * 0.005)).collect()
}

impl Scenario {
    /// Kinematics of the scenario: travel speed, slip ratio, slip angle, ice temperature.
    pub fn operating(&self) -> vehsim_core::contact::model::Kinematics {
        vehsim_core::contact::model::Kinematics {
            travel_speed_mps: self.speed_mps,
            slip_ratio: self.slip_ratio,
            slip_angle_rad: self.slip_angle_rad,
            ice_temp_c: self.ice_temp_c,
        }
    }
}
