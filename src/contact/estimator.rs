//! Per-step contact-temperature estimator for the engine ([`AtiimEstimator`]).
//!
//! Contact temperature of tyre i = min(0 degC, T_start + flash), where
//! - T_b is a bulk tread-surface temperature state (one per tyre), heated by the tread's share of
//!   the sliding power F v_slide and cooled toward the ice (conduction through the patch) and the
//!   air (convection over the tread band): C dT_b/dt = f_t F v - G_ice (T_b - T_ice) - G_air (T_b - T_air).
//!   The ODE is linear over a step and is advanced exactly (exponential), so any step size is stable;
//! - T_start = (e_tread T_b + e_ice T_ice) / (e_tread + e_ice) is the temperature two semi-infinite
//!   bodies take on first contact;
//! - flash = the patch-average interface rise of the full patch model ([`super::model::solve_patch`])
//!   at (load, sliding speed, rolling speed, T_start), read from a table built once per run and
//!   interpolated multilinearly in (ln F_z, ln v_slide, ln(v_roll + 0.3 m/s), T) on ln(rise). In
//!   these coordinates the dry-regime rise, about mu p v_slide sqrt(L / v_roll), is nearly linear,
//!   so a coarse table suffices. Below the smallest sliding-speed node the rise is scaled linearly
//!   with v_slide (dry regime); outside the other ranges the inputs are clamped.
//!
//! The flash table uses the spec's dry friction mu_dry for heat generation (as the patch model
//! does); the actual friction force enters through the bulk state.

use super::heat::effective_effusivity;
use super::model::{solve_patch, Operating, PatchParams};
use super::patch::{synthesize, SynthInputs, TreadPattern};
use super::thermal::{ICE, MELT_C};
use super::{ContactTemperature, TyreContact};
use crate::error::Result;
use rayon::prelude::*;
use std::path::Path;

/// A uniform axis in a transformed coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// First node (transformed coordinate).
    pub x0: f64,
    /// Node spacing (transformed coordinate), > 0.
    pub dx: f64,
    /// Number of nodes, >= 2.
    pub n: usize,
}

impl Axis {
    /// Axis from `lo` to `hi` with `n` nodes.
    pub fn new(lo: f64, hi: f64, n: usize) -> Self {
        let n = n.max(2);
        let dx = ((hi - lo) / (n - 1) as f64).max(1e-12);
        Axis { x0: lo, dx, n }
    }
    /// Node k.
    pub fn node(&self, k: usize) -> f64 {
        self.x0 + self.dx * k as f64
    }
    /// Cell index and fraction for x (clamped to the axis).
    #[inline]
    fn locate(&self, x: f64) -> (usize, f64) {
        let u = (x - self.x0) / self.dx;
        let u = if u.is_finite() { u.clamp(0.0, (self.n - 1) as f64) } else { 0.0 };
        let k = (u as usize).min(self.n - 2);
        (k, u - k as f64)
    }
}

/// Offset in the rolling-speed coordinate ln(v_roll + V0), m/s (keeps a locked wheel on the axis).
pub const ROLL_OFFSET_MPS: f64 = 0.3;

/// Smallest rise stored (ln is taken), K.
const RISE_FLOOR_K: f64 = 1e-9;

/// Flash-rise table over (ln F_z, ln v_slide, ln(v_roll + V0), T_start).
#[derive(Debug, Clone, PartialEq)]
pub struct FlashTable {
    pub load: Axis,
    pub slide: Axis,
    pub roll: Axis,
    pub temp: Axis,
    /// ln(rise in K), index ((il * ns + is) * nr + ir) * nt + it.
    pub ln_rise: Vec<f64>,
}

/// Ranges and resolution of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableRanges {
    /// Load range, N, and nodes (log-spaced).
    pub load_n: (f64, f64, usize),
    /// Sliding-speed range, m/s (> 0), and nodes (log-spaced).
    pub slide_mps: (f64, f64, usize),
    /// Largest rolling speed, m/s, and nodes (log-spaced in v + 0.3 from 0).
    pub roll_max_mps: (f64, usize),
    /// Ice-temperature range, degC (<= 0), and nodes.
    pub temp_c: (f64, f64, usize),
    /// Patch grid of the table (rows along travel, cols across).
    pub grid: (usize, usize),
}

impl Default for TableRanges {
    fn default() -> Self {
        TableRanges {
            load_n: (1000.0, 12000.0, 6),
            slide_mps: (0.01, 30.0, 9),
            roll_max_mps: (60.0, 8),
            temp_c: (-30.0, 0.0, 7),
            grid: (24, 12),
        }
    }
}

/// What the table is built from: the tyre (synthesized patches) and the patch-model parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TyreBuild {
    pub inflation_pa: f64,
    pub tread_width_m: f64,
    pub rated_load_n: f64,
    pub pattern: TreadPattern,
    pub params: PatchParams,
}

impl FlashTable {
    /// Build the table: one synthesized patch per load node, one patch solve per node.
    pub fn build(file: &Path, tyre: &TyreBuild, rg: &TableRanges) -> Result<Self> {
        let load = Axis::new(rg.load_n.0.ln(), rg.load_n.1.ln(), rg.load_n.2);
        let slide = Axis::new(rg.slide_mps.0.ln(), rg.slide_mps.1.ln(), rg.slide_mps.2);
        let roll = Axis::new(ROLL_OFFSET_MPS.ln(), (rg.roll_max_mps.0 + ROLL_OFFSET_MPS).ln(), rg.roll_max_mps.1);
        let temp = Axis::new(rg.temp_c.0, rg.temp_c.1, rg.temp_c.2);
        let grids = (0..load.n)
            .map(|il| {
                synthesize(
                    file,
                    &SynthInputs {
                        load_n: load.node(il).exp(),
                        inflation_pa: tyre.inflation_pa,
                        tread_width_m: tyre.tread_width_m,
                        rated_load_n: tyre.rated_load_n,
                        camber_deg: 0.0,
                        pattern: tyre.pattern,
                        rows: rg.grid.0,
                        cols: rg.grid.1,
                    },
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let per_load = slide.n * roll.n * temp.n;
        let ln_rise: Vec<f64> = (0..load.n * per_load)
            .into_par_iter()
            .map(|k| {
                let il = k / per_load;
                let rem = k % per_load;
                let is = rem / (roll.n * temp.n);
                let ir = (rem / temp.n) % roll.n;
                let it = rem % temp.n;
                let op = Operating {
                    roll_speed_mps: (roll.node(ir).exp() - ROLL_OFFSET_MPS).max(0.0),
                    slide_speed_mps: slide.node(is).exp(),
                    ice_temp_c: temp.node(it),
                };
                let r = solve_patch(&grids[il], &op, &tyre.params);
                r.summary.mean_rise_k.max(RISE_FLOOR_K).ln()
            })
            .collect();
        Ok(FlashTable { load, slide, roll, temp, ln_rise })
    }

    /// Interpolated patch-average rise, K, at load `fz_n`, sliding speed `vs_mps`, rolling speed
    /// `vr_mps` and start temperature `t_c`. Never NaN; 0 for non-positive load or sliding speed.
    #[inline]
    pub fn rise_k(&self, fz_n: f64, vs_mps: f64, vr_mps: f64, t_c: f64) -> f64 {
        if !(fz_n > 0.0 && vs_mps > 0.0) || !vs_mps.is_finite() {
            return 0.0;
        }
        let vs_min = self.slide.x0.exp();
        let (scale, vs) = if vs_mps < vs_min { (vs_mps / vs_min, vs_min) } else { (1.0, vs_mps) };
        let (il, fl) = self.load.locate(fz_n.ln());
        let (is, fs) = self.slide.locate(vs.ln());
        let (ir, fr) = self.roll.locate((vr_mps.max(0.0) + ROLL_OFFSET_MPS).ln());
        let (it, ft) = self.temp.locate(t_c);
        let (ns, nr, nt) = (self.slide.n, self.roll.n, self.temp.n);
        let mut acc = 0.0;
        for a in 0..2 {
            let wa = if a == 0 { 1.0 - fl } else { fl };
            for b in 0..2 {
                let wb = wa * if b == 0 { 1.0 - fs } else { fs };
                for c in 0..2 {
                    let wc = wb * if c == 0 { 1.0 - fr } else { fr };
                    let base = (((il + a) * ns + is + b) * nr + ir + c) * nt + it;
                    acc += wc * ((1.0 - ft) * self.ln_rise[base] + ft * self.ln_rise[base + 1]);
                }
            }
        }
        let r = acc.exp() * scale;
        if r.is_finite() && r > RISE_FLOOR_K * 10.0 {
            r
        } else {
            0.0
        }
    }
}

/// Bulk-state parameters (per tyre).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BulkParams {
    /// Heat capacity of the heated tread skin around the circumference, J/K
    /// (rho c x 2 pi R x width x skin depth; ~1500 J/K for 2 mm on a passenger tyre).
    pub heat_capacity_j_k: f64,
    /// Tread-band area exposed to air (2 pi R x width), m^2 (~0.37).
    pub band_area_m2: f64,
    /// Fraction of sliding power entering the tread, 0–1 (effusivity share ~0.26).
    pub tread_fraction: f64,
    /// Air temperature, degC; `None` = the surface (ice) temperature.
    pub air_temp_c: Option<f64>,
    /// Patch area per unit load, m^2/N (contact length and conduction area; 1 / (inflation)).
    pub area_per_n: f64,
    /// Contact width, m.
    pub width_m: f64,
    /// Tread effusivity, W s^0.5/(m^2 K).
    pub e_tread: f64,
}

/// The ATIIM per-step estimator: one bulk state per tyre plus the flash table.
#[derive(Debug, Clone)]
pub struct AtiimEstimator {
    pub table: FlashTable,
    pub bulk: BulkParams,
    /// Bulk tread-surface temperature per tyre, degC (NaN until the first update).
    pub t_bulk_c: Vec<f64>,
}

impl AtiimEstimator {
    /// New estimator for `n_tyres` tyres; bulk states start at the first update's surface temperature.
    pub fn new(table: FlashTable, bulk: BulkParams, n_tyres: usize) -> Self {
        AtiimEstimator { table, bulk, t_bulk_c: vec![f64::NAN; n_tyres] }
    }

    /// Contact temperature for one tyre from its bulk temperature (no state change), degC.
    #[inline]
    pub fn contact_temp_c(&self, t_bulk_c: f64, t: &TyreContact) -> f64 {
        let e_i = ICE.effusivity();
        let e_t = self.bulk.e_tread;
        let t_ice = t.surface_temp_c;
        let t_start = ((e_t * t_bulk_c + e_i * t_ice) / (e_t + e_i)).min(MELT_C);
        let flash = self.table.rise_k(t.fz_n, t.slide_speed_mps, t.roll_speed_mps, t_start);
        (t_start + flash).min(MELT_C)
    }
}

fn finite_or(v: f64, d: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        d
    }
}

impl ContactTemperature for AtiimEstimator {
    fn update(&mut self, h: f64, tyres: &[TyreContact], out: &mut [f64]) {
        let b = self.bulk;
        let e_i = ICE.effusivity();
        let e_s = b.e_tread * e_i / (b.e_tread + e_i); // series effusivity for tread-to-ice conduction
        let h = finite_or(h, 0.0).max(0.0);
        for (i, (t, o)) in tyres.iter().zip(out.iter_mut()).enumerate() {
            let t_ice = finite_or(t.surface_temp_c, MELT_C);
            if self.t_bulk_c.len() <= i {
                self.t_bulk_c.resize(i + 1, f64::NAN);
            }
            let mut tb = self.t_bulk_c[i];
            if !tb.is_finite() {
                tb = t_ice;
            }
            let fz = finite_or(t.fz_n, 0.0).max(0.0);
            let vr = finite_or(t.roll_speed_mps, 0.0).abs();
            let vs = finite_or(t.slide_speed_mps, 0.0).abs();
            let power = b.tread_fraction * finite_or(t.friction_force_n, 0.0).abs() * vs;
            // conduction into the ice through the patch: area A, contact time L / v
            let area = fz * b.area_per_n;
            let len = area / b.width_m.max(1e-3);
            let tc = len / vr.max(vs).max(0.1);
            let g_ice = if area > 0.0 { area * 2.0 * e_s / (std::f64::consts::PI * tc.max(1e-6)).sqrt() } else { 0.0 };
            let g_air = b.band_area_m2 * (10.0 + 7.0 * vr.sqrt());
            let t_air = b.air_temp_c.unwrap_or(t_ice);
            let g = g_ice + g_air;
            let t_eq = (power + g_ice * t_ice + g_air * t_air) / g;
            tb = t_eq + (tb - t_eq) * (-g * h / b.heat_capacity_j_k.max(1e-6)).exp();
            if !tb.is_finite() {
                tb = t_ice;
            }
            self.t_bulk_c[i] = tb;
            let tt = TyreContact { surface_temp_c: t_ice, fz_n: fz, roll_speed_mps: vr, slide_speed_mps: vs, ..*t };
            *o = self.contact_temp_c(tb, &tt);
        }
    }
}

/// Effusivity weighting helper kept public for docs/tests: tread share at equal contact times.
pub fn rolling_tread_fraction(e_tread: f64) -> f64 {
    let e = effective_effusivity(e_tread, ICE.effusivity(), 1.0, 1.0);
    (e - ICE.effusivity()) / e
}
