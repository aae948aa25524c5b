//! Per-step contact-temperature estimator for the engine ([`AtiimEstimator`]).
//!
//! Contact temperature of tyre i = min(0 degC, T_start + flash), where
//! - T_b is a bulk tread-surface temperature state (one per tyre), heated by the tread's share of
//!   the sliding power F v_slide and by the band's rolling (hysteresis) heat s f_rr F_z v_roll, and
//!   cooled toward the ice (conduction through the patch) and the air (convection over the tread
//!   band): C dT_b/dt = f_t F v + s f_rr F_z v_r - G_ice (T_b - T_ice) - G_air (T_b - T_air).
//!   The ODE is linear over a step and is advanced exactly (exponential), so any step size is stable;
//! - T_start = (e_tread T_b + e_ice T_ice) / (e_tread + e_ice) is the temperature two semi-infinite
//!   bodies take on first contact;
//! - flash = the patch-average interface rise of the full patch model ([`super::model::solve_patch`])
//!   (with the whole patch sliding, see [`FlashTable::build`])
//!   at (load, sliding speed, rolling speed, T_start), read from a table built once per run and
//!   interpolated trilinearly on ln(rise) in (ln F_z, ln v_slide, ln sigma), with the ice
//!   temperature handled through the dry law's temperature factor and the melting cap (see
//!   [`FlashTable`]);
//!   the rolling
//!   speed enters through the slip fraction sigma = v_slide / (v_roll + v_slide) (0 free rolling,
//!   1 locked). In these coordinates the dry-regime rise, about mu p v_slide sqrt(L / v_roll), is
//!   nearly linear, and the brush model's sliding onset, a function of the slip alone, lies along
//!   one axis. Below the smallest sliding-speed node the rise is scaled linearly with v_slide (dry
//!   regime); outside the other ranges the inputs are clamped.
//!
//! Statistic. The patch model gives a rise per pixel; the table stores one statistic of it,
//! [`Statistic::Max`] (the hottest pixel, the dissertation's choice for the modified tyre model,
//! section 6.2: "the maximum predicted temperature rise"; the default) or [`Statistic::Mean`]
//! (the patch average, about half the maximum).
//!
//! Flash heat. The table is built with the patch model's dry heat flux mu_dry p v_slide. At run
//! time the heat is priced with the force the tyre model transmits at that step: the generated
//! power is F v_slide instead of mu_dry Fz v_slide, so the dry rise R0 is scaled by
//! F / (mu_dry Fz) (the conduction problem is linear in the flux; the melting cap is applied after
//! the scaling through the table's w coordinate). A tyre transmitting no force heats nothing.
//!
//! Coupling with the tyre. That force itself depends on the contact temperature (a warmer contact
//! lowers the tyre's friction), so the estimate solves T = G(T), G the estimate under the
//! conditions at contact temperature T ([`ContactTemperature::update_coupled`]), rather than
//! pricing the heat with the force at the previous estimate: near melting |G'| exceeds 1 and that
//! lagged loop alternates between a melting and a cooler contact from sample to sample.

use super::heat::effective_effusivity;
use super::model::{solve_patch, Operating, PatchParams};
use super::patch::{synthesize, PressureGrid, SynthInputs, TreadPattern};
use super::thermal::{ICE, MELT_C};
use super::{ContactTemperature, TyreContact};
use crate::error::Result;
use crate::tyre::fastmath::fast_ln;
use rayon::prelude::*;
use std::path::Path;

/// An axis of table nodes in a transformed coordinate (strictly increasing).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Node coordinates, >= 2, strictly increasing.
    pub nodes: Vec<f64>,
    /// (first node, 1 / spacing) when the nodes are uniform: direct cell lookup.
    uniform: Option<(f64, f64)>,
}

impl Axis {
    /// Uniform axis from `lo` to `hi` with `n` nodes.
    pub fn new(lo: f64, hi: f64, n: usize) -> Self {
        let n = n.max(2);
        let dx = ((hi - lo) / (n - 1) as f64).max(1e-12);
        Axis { nodes: (0..n).map(|k| lo + dx * k as f64).collect(), uniform: Some((lo, 1.0 / dx)) }
    }
    /// Axis through explicit nodes (must be strictly increasing, >= 2).
    pub fn from_nodes(nodes: Vec<f64>) -> Self {
        Axis { nodes, uniform: None }
    }
    /// Number of nodes.
    pub fn n(&self) -> usize {
        self.nodes.len()
    }
    /// Node k.
    pub fn node(&self, k: usize) -> f64 {
        self.nodes[k.min(self.nodes.len() - 1)]
    }
    /// Cell index and fraction for x (clamped to the axis).
    #[inline(always)]
    fn locate(&self, x: f64) -> (usize, f64) {
        let v = &self.nodes;
        let n = v.len();
        if let Some((x0, inv)) = self.uniform {
            let u = (x - x0) * inv;
            let u = if u.is_finite() { u.clamp(0.0, (n - 1) as f64) } else { 0.0 };
            let k = (u as usize).min(n - 2);
            return (k, u - k as f64);
        }
        if x.is_nan() || x <= v[0] {
            return (0, 0.0);
        }
        if x >= v[n - 1] {
            return (n - 2, 1.0);
        }
        let k = v.partition_point(|&t| t <= x).saturating_sub(1).min(n - 2);
        (k, (x - v[k]) / (v[k + 1] - v[k]))
    }
}

/// Slip fraction sigma = v_slide / (v_roll + v_slide), in (0, 1]; 1 for v_roll = v_slide = 0.
#[inline]
#[cfg(test)]
pub(crate) fn slip_fraction(vs_mps: f64, vr_mps: f64) -> f64 {
    let d = vr_mps.max(0.0) + vs_mps.max(0.0);
    if d > 0.0 {
        vs_mps.max(0.0) / d
    } else {
        1.0
    }
}

/// Rolling speed for sliding speed `vs` and slip fraction `sigma`: vs (1 - sigma) / sigma.
pub fn roll_speed_for(vs_mps: f64, sigma: f64) -> f64 {
    vs_mps * (1.0 - sigma).max(0.0) / sigma.max(1e-12)
}

/// Smallest rise stored (ln is taken), K.
const RISE_FLOOR_K: f64 = 1e-9;

/// Flash-rise table.
///
/// Melting caps the rise at dtm = (0 degC - T), which puts a kink into the rise as a function of
/// ice temperature. To interpolate across it, the table stores, for each (load, sliding speed,
/// slip fraction) node, the dry (never-melting) rise with the friction of -40 degC (the dry law's
/// clamp; no self-heating), and, on a fixed grid of w = ln(dtm / R0(T)) (the kink sits near w = 0
/// for every node), the ratio G = rise / S of the rise to the smooth cap S = R0 dtm / (R0 + dtm).
/// R0(T) is the stored rise carried to start temperature T by the dry law's temperature factor
/// exp(-c_T (T + 40)) and a first-order self-heating correction (`ln_dry_rise`); each w node is
/// solved at the ice temperature where w(T) equals it ([`node_ice_temp_c`]). G is near 1 at both
/// ends (dry: rise = R0; fully capped: rise = dtm) and smooth between, so it interpolates well.
/// Above the w range G is held at its last-node value (dry); below it the rise is proportional
/// to dtm (capped).
#[derive(Debug, Clone, PartialEq)]
pub struct FlashTable {
    /// ln F_z.
    pub load: Axis,
    /// ln v_slide.
    pub slide: Axis,
    /// ln sigma, sigma = v_slide / (v_roll + v_slide).
    pub roll: Axis,
    /// w = ln((0 degC - T) / R0(T)).
    pub w: Axis,
    /// ln of the dry rise with the friction of -40 degC (K), index (il * ns + is) * nr + ir.
    pub ln_r0: Vec<f64>,
    /// ln G, index ((il * ns + is) * nr + ir) * nw + iw.
    pub ln_g: Vec<f64>,
    /// Smallest tabulated sliding speed, m/s (cached).
    vs_min: f64,
    /// Dry friction the table's heat flux assumed (patch model's mu_dry), for the force pricing.
    mu_dry: f64,
    /// Temperature coefficient c_T of the dry friction law, 1/K: R0 at start temperature T is
    /// the stored R0 (built at [`DRY_LAW_COLD_C`]) times exp(-c_T (clamp(T) - DRY_LAW_COLD_C)).
    c_t: f64,
    /// The rise's factors beyond the ends of the w range ([`w_caps`]).
    caps: [f64; 2],
}

/// The factors the rise takes beyond the ends w0 < w1 of the table's w range: exp(soft_cap(w0) -
/// w0) (times dtm below w0) and exp(soft_cap(w1)) (times R0 above w1).
fn w_caps(w: &Axis) -> [f64; 2] {
    let (w0, w1) = (w.nodes[0], w.nodes[w.n() - 1]);
    [(soft_cap(w0) - w0).exp(), soft_cap(w1).exp()]
}

/// Which statistic of the patch's rise field the table stores (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Statistic {
    /// The largest pixel rise (default; the dissertation's choice).
    #[default]
    Max,
    /// The patch-average rise.
    Mean,
}

choice_names!(Statistic {
    Max => "max",
    Mean => "mean",
});

impl Statistic {
    /// This statistic of a patch solution, K.
    pub fn of(self, s: &super::model::PatchSummary) -> f64 {
        match self {
            Statistic::Max => s.max_rise_k,
            Statistic::Mean => s.mean_rise_k,
        }
    }
}

/// Ranges and resolution of the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableRanges {
    /// Load range, N, and nodes (log-spaced).
    pub load_n: (f64, f64, usize),
    /// Sliding-speed range, m/s (> 0), and nodes (log-spaced).
    pub slide_mps: (f64, f64, usize),
    /// Smallest slip fraction sigma = v_slide / (v_roll + v_slide) (0 < sigma < 0.1; 1e-4 covers
    /// 0.01 % slip) and the number of log-spaced nodes from it up to 0.1; above 0.1 fixed nodes
    /// 0.2, 0.35, 0.5 (where the transit speed switches from rolling to sliding), 0.65, 0.8, 0.9,
    /// 0.97 and 1 (locked) resolve the approach to a locked wheel.
    pub sigma_min: (f64, usize),
    /// Range of w = ln((0 degC - T) / R0(T)) and nodes (default -2 .. 2, 9 nodes).
    pub w: (f64, f64, usize),
    /// Patch grid of the table (rows along travel, cols across).
    pub grid: (usize, usize),
    /// Statistic of the rise field stored.
    pub statistic: Statistic,
}

impl Default for TableRanges {
    fn default() -> Self {
        TableRanges {
            load_n: (2000.0, 12000.0, 5),
            slide_mps: (0.01, 30.0, 9),
            sigma_min: (1e-4, 5),
            w: (-2.0, 2.0, 9),
            grid: (16, 12),
            statistic: Statistic::Max,
        }
    }
}

/// What the table is built from: the tyre (synthesized patches) and the patch-model parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TyreBuild {
    /// Inflation pressure, Pa (sets the synthesized patch area load / pressure).
    pub inflation_pa: f64,
    /// Tread (contact) width at full load, m.
    pub tread_width_m: f64,
    /// Rated load (100 % load index), N: sets the synthesized patch shape.
    pub rated_load_n: f64,
    /// Tread pattern of the synthesized patches.
    pub pattern: TreadPattern,
    /// Patch-model parameters the table nodes are solved with.
    pub params: PatchParams,
}

/// ln(S / R0) for w = ln(dtm / R0), where S = R0 dtm / (R0 + dtm) is a smooth stand-in for the
/// melting cap min(R0, dtm): w - ln(1 + e^w), computed without overflow.
#[inline]
pub(crate) fn soft_cap(w: f64) -> f64 {
    if w > 0.0 {
        -(-w).exp().ln_1p()
    } else {
        w - w.exp().ln_1p()
    }
}

/// Reference patch grid (rows, cols) whose rise the table reproduces (see `FlashTable::build`).
pub const REFERENCE_GRID: (usize, usize) = (64, 48);

/// Ice temperature used for the dry (never-melting) rise, degC. The friction law clamps its
/// temperature to [DRY_LAW_COLD_C, 0 degC], so this rise is the one with the friction of
/// DRY_LAW_COLD_C everywhere (no self-heating, no melting): linear in the friction.
const DRY_ICE_C: f64 = -1e6;

/// Coldest temperature the dry friction law distinguishes (its clamp), degC.
pub(crate) const DRY_LAW_COLD_C: f64 = crate::tyre::friction::COLD_PLATEAU_C;

/// ln of the dry law's temperature factor relative to [`DRY_LAW_COLD_C`]:
/// -c_T (clamp(T, T_cold, 0) - T_cold).
#[inline]
fn ln_temp_factor(c_t: f64, t_c: f64) -> f64 {
    -c_t * (t_c.clamp(DRY_LAW_COLD_C, MELT_C) - DRY_LAW_COLD_C)
}

/// Share of the dry rise that the friction of the sliding pixels sees on average (self-heating
/// of the dry law), used in [`ln_dry_rise`].
const SELF_HEAT_SHARE: f64 = 0.5;

/// ln of a cell's dry rise R0(T) at start temperature `t_c` from ln `ln_r_lin`, the rise the
/// friction of T would give with no self-heating (the stored R0 times the law's temperature
/// factor and the force pricing): R0 = R_lin / (1 + a c_T R_band), a = 0.5, R_band = the part
/// of R_lin above the law's -40 degC clamp. The sliding pixels' friction falls by
/// exp(-c_T rise) with the rise the earlier pixels left; this first-order form takes out most of
/// that amplitude dependence, and the table's ratio G carries the rest (so a is not fitted).
#[inline]
fn ln_dry_rise(ln_r_lin: f64, c_t: f64, t_c: f64) -> f64 {
    if c_t <= 0.0 {
        return ln_r_lin;
    }
    let r = ln_r_lin.exp();
    let band = (t_c - DRY_LAW_COLD_C + r).clamp(0.0, r);
    ln_r_lin - fast_ln(1.0 + SELF_HEAT_SHARE * c_t * band)
}

/// The ice temperature, degC, at which a table cell's melting coordinate
/// w = ln((0 degC - T) / R0(T)) equals `w`, with R0(T) the dry rise of `ln_dry_rise` for a
/// cell whose rise with the friction of -40 degC is exp(`ln_r0_cold`) and c_T = `c_t`. w is not
/// monotonic in T (the friction rises as the ice gets colder), so the warmest solution is
/// returned: a scan up in ln(-T) from 1e-6 K in steps of 0.05, then 50 bisections. The table's
/// w nodes sit at these temperatures.
pub fn node_ice_temp_c(ln_r0_cold: f64, c_t: f64, w: f64) -> f64 {
    let g = |u: f64| {
        let t = -u.exp();
        u - ln_dry_rise(ln_r0_cold + ln_temp_factor(c_t, t), c_t, t) - w
    };
    let (mut lo, mut hi) = (-14.0f64, -14.0f64);
    while g(hi) < 0.0 && hi < 40.0 {
        lo = hi;
        hi += 0.05;
    }
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if g(mid) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    -(0.5 * (lo + hi)).exp()
}

impl FlashTable {
    /// Build the table: one synthesized patch per load node, (1 + w nodes) patch solves per
    /// (load, sliding speed, slip fraction) node, in parallel (rayon).
    pub fn build(file: &Path, tyre: &TyreBuild, rg: &TableRanges) -> Result<Self> {
        let load = Axis::new(rg.load_n.0.ln(), rg.load_n.1.ln(), rg.load_n.2);
        let slide = Axis::new(rg.slide_mps.0.ln(), rg.slide_mps.1.ln(), rg.slide_mps.2);
        let mut nodes = Axis::new(rg.sigma_min.0.min(0.05).ln(), 0.1f64.ln(), rg.sigma_min.1).nodes;
        nodes.extend([0.2f64, 0.35, 0.5, 0.65, 0.8, 0.9, 0.97, 1.0].iter().map(|v| v.ln()));
        let roll = Axis::from_nodes(nodes);
        let w = Axis::new(rg.w.0, rg.w.1, rg.w.2);
        // The tyre's synthesized pressure grid at load node `il` on a rows x cols grid.
        let grid_at = |il: usize, (rows, cols): (usize, usize)| {
            synthesize(
                file,
                &SynthInputs {
                    load_n: load.node(il).exp(),
                    inflation_pa: tyre.inflation_pa,
                    tread_width_m: tyre.tread_width_m,
                    rated_load_n: tyre.rated_load_n,
                    camber_deg: 0.0,
                    pattern: tyre.pattern,
                    rows,
                    cols,
                },
            )
        };
        let grids = (0..load.n()).map(|il| grid_at(il, rg.grid)).collect::<Result<Vec<_>>>()?;
        // The table is built with the whole patch sliding (no brush adhesion zone): the brush's
        // sliding onset makes the rise a steep, grid-lumpy function of slip and load at small slip,
        // where the flash is negligible anyway (an upper bound there).
        let mut params = tyre.params;
        params.brush = false;
        let c_t = params.dry.temp_coeff_per_k.max(0.0);
        let per_load = slide.n() * roll.n();
        let cells: Vec<(f64, Vec<f64>)> = (0..load.n() * per_load)
            .into_par_iter()
            .map(|k| {
                let il = k / per_load;
                let is = (k % per_load) / roll.n();
                let ir = k % roll.n();
                let vs = slide.node(is).exp();
                let vr = roll_speed_for(vs, roll.node(ir).exp());
                let solve = |t: f64| {
                    let op = Operating { roll_speed_mps: vr, slide_speed_mps: vs, ice_temp_c: t };
                    rg.statistic.of(&solve_patch(&grids[il], &op, &params).summary)
                };
                let r0 = solve(DRY_ICE_C).max(RISE_FLOOR_K);
                let g = (0..w.n())
                    .map(|iw| {
                        let wk = w.node(iw);
                        let t = node_ice_temp_c(r0.ln(), c_t, wk);
                        let rise = solve(t).max(RISE_FLOOR_K);
                        rise.ln() - ln_dry_rise(r0.ln() + ln_temp_factor(c_t, t), c_t, t) - soft_cap(wk)
                    })
                    .collect();
                (r0.ln(), g)
            })
            .collect();
        let corr = grid_corrections(&grids, &grid_at, &params, rg);
        let mut ln_r0 = Vec::with_capacity(cells.len());
        let mut ln_g = Vec::with_capacity(cells.len() * w.n());
        for (k, (r, g)) in cells.into_iter().enumerate() {
            ln_r0.push(r + corr[k / per_load]);
            ln_g.extend(g);
        }
        let vs_min = slide.node(0).exp();
        let caps = w_caps(&w);
        Ok(FlashTable { load, slide, roll, w, ln_r0, ln_g, vs_min, mu_dry: tyre.params.mu_dry, c_t, caps })
    }

    /// Interpolated rise (the table's statistic), K, at load `fz_n`, sliding speed `vs_mps`,
    /// rolling speed `vr_mps` and start temperature `t_c` (degC). Never NaN; 0 for non-positive
    /// load or sliding speed or for t_c >= 0 degC.
    #[inline]
    pub fn rise_k(&self, fz_n: f64, vs_mps: f64, vr_mps: f64, t_c: f64) -> f64 {
        self.rise_k_priced(fz_n, vs_mps, vr_mps, t_c, 1.0)
    }

    /// As [`Self::rise_k`] with the heat flux scaled by `heat_ratio` = F / (mu_dry Fz), the
    /// transmitted friction force over the one the table assumed (clamped to [0, 100]).
    #[inline]
    pub fn rise_k_for_force(&self, fz_n: f64, vs_mps: f64, vr_mps: f64, t_c: f64, force_n: f64) -> f64 {
        let ratio = force_n.abs() / (self.mu_dry * fz_n);
        self.rise_k_priced(fz_n, vs_mps, vr_mps, t_c, if ratio.is_finite() { ratio.min(100.0) } else { 0.0 })
    }

    /// The rise with the heat flux scaled by `heat_ratio`. With R_lin = exp(ln R0 + ln
    /// temperature factor + ln heat_ratio) the rise the friction of the start temperature would
    /// give without self-heating, R0 = R_lin / (1 + a c_T R_band) ([`ln_dry_rise`]), dtm the
    /// melting margin and w = ln(dtm / R0), the rise is G(w) S with S = R0 dtm / (R0 + dtm) =
    /// R0 exp(soft_cap(w)) inside the table's w range, R0 exp(soft_cap(w1)) G above it and
    /// dtm exp(soft_cap(w0) - w0) G below it (the same values to round-off as the log-domain
    /// form: `rise_matches_the_log_domain_form`). Arranged for a short chain from the start
    /// temperature, which arrives last (it follows the bulk step): w is formed from logarithms
    /// taken beside that chain (ln dtm, ln heat_ratio, the trilinear ln R0), so the chain is one
    /// exponential, one division-free logarithm (the self-heating term), the w lookup and one
    /// exponential (both by `crate::tyre::fastmath::exp`, within an ulp or two of the library's);
    /// the divisions of R0 and S run beside it.
    #[inline]
    fn rise_k_priced(&self, fz_n: f64, vs_mps: f64, vr_mps: f64, t_c: f64, heat_ratio: f64) -> f64 {
        if !(fz_n > 0.0 && vs_mps > 0.0 && t_c < MELT_C && vs_mps.is_finite() && heat_ratio > 0.0) {
            return 0.0;
        }
        let vs_min = self.vs_min;
        let ln_vs = fast_ln(vs_mps);
        // below the smallest sliding-speed node the rise scales with v_slide, so the cap does too
        let (scale, ln_vs_node) = if vs_mps < vs_min { (vs_mps / vs_min, self.slide.nodes[0]) } else { (1.0, ln_vs) };
        let (il, fl) = self.load.locate(fast_ln(fz_n));
        let (is, fs) = self.slide.locate(ln_vs_node);
        // ln sigma = ln v_slide - ln(v_roll + v_slide) ([`slip_fraction`], v_slide > 0 here)
        let vr = if vr_mps.is_finite() { vr_mps.max(0.0) } else { 0.0 };
        let (ir, fr) = self.roll.locate(ln_vs - fast_ln(vr + vs_mps));
        let (ns, nr) = (self.slide.n(), self.roll.n());
        // ln R0 trilinear in (ln F_z, ln v_slide, ln sigma) (with the whole patch sliding the dry
        // rise is close to a power law in each); then ln G at the resulting w, trilinear likewise.
        let mut corners = [(0usize, 0.0f64); 8];
        let mut lr0 = 0.0;
        let mut n = 0;
        for a in 0..2 {
            let wa = if a == 0 { 1.0 - fl } else { fl };
            for b in 0..2 {
                let wb = wa * if b == 0 { 1.0 - fs } else { fs };
                for c in 0..2 {
                    let wc = wb * if c == 0 { 1.0 - fr } else { fr };
                    let cell = ((il + a) * ns + is + b) * nr + ir + c;
                    lr0 += wc * self.ln_r0[cell];
                    corners[n] = (cell, wc);
                    n += 1;
                }
            }
        }
        let lr0 = lr0 + fast_ln(heat_ratio);
        let dtm = if scale < 1.0 { (MELT_C - t_c) / scale } else { MELT_C - t_c };
        let ln_dtm = fast_ln(dtm);
        // the dry rise is linear in the heat flux: the force pricing and the dry law's temperature
        // factor at the start temperature; then the self-heating correction of `ln_dry_rise`
        let ln_r_lin = lr0 + ln_temp_factor(self.c_t, t_c);
        let r_lin = crate::tyre::fastmath::exp(ln_r_lin);
        let (r0, wq) = if self.c_t <= 0.0 {
            (r_lin, ln_dtm - ln_r_lin)
        } else {
            let d = 1.0 + SELF_HEAT_SHARE * self.c_t * (t_c - DRY_LAW_COLD_C + r_lin).clamp(0.0, r_lin);
            (r_lin / d, ln_dtm - ln_r_lin + fast_ln(d))
        };
        let (k, f) = self.w.locate(wq);
        let nw = self.w.n();
        let mut lg = 0.0;
        for (cell, wt) in corners {
            let g = &self.ln_g[cell * nw..(cell + 1) * nw];
            lg += wt * ((1.0 - f) * g[k] + f * g[k + 1]);
        }
        // outside the w range: dry above it (rise = its value at the last node), melting-capped
        // below it (rise proportional to dtm)
        let (w0, w1) = (self.w.nodes[0], self.w.nodes[nw - 1]);
        let capped = if wq >= w1 {
            r0 * self.caps[1]
        } else if wq <= w0 {
            dtm * self.caps[0]
        } else {
            r0 * dtm / (r0 + dtm)
        };
        let r = (capped * crate::tyre::fastmath::exp(lg) * scale).min(MELT_C - t_c);
        if r.is_finite() && r > RISE_FLOOR_K * 10.0 {
            r
        } else {
            0.0
        }
    }

    /// [`Self::rise_k_priced`] in the log domain throughout (the form the table's nodes are
    /// defined in, with exact logarithms): the reference its linear-domain evaluation is tested against.
    #[cfg(test)]
    fn rise_k_log_domain(&self, fz_n: f64, vs_mps: f64, vr_mps: f64, t_c: f64, heat_ratio: f64) -> f64 {
        if !(fz_n > 0.0 && vs_mps > 0.0 && t_c < MELT_C && vs_mps.is_finite() && heat_ratio > 0.0) {
            return 0.0;
        }
        let (scale, vs) = if vs_mps < self.vs_min { (vs_mps / self.vs_min, self.vs_min) } else { (1.0, vs_mps) };
        let (il, fl) = self.load.locate(fz_n.ln());
        let (is, fs) = self.slide.locate(vs.ln());
        let (ir, fr) = self.roll.locate(slip_fraction(vs_mps, vr_mps).ln());
        let ln_dtm = ((MELT_C - t_c) / scale).ln();
        let (ns, nr, nw) = (self.slide.n(), self.roll.n(), self.w.n());
        let cell_weights = (0..8).map(|n| {
            let (a, b, c) = (n / 4, (n / 2) % 2, n % 2);
            let w = [1.0 - fl, fl][a] * [1.0 - fs, fs][b] * [1.0 - fr, fr][c];
            (((il + a) * ns + is + b) * nr + ir + c, w)
        });
        let lr0: f64 = cell_weights.clone().map(|(cell, w)| w * self.ln_r0[cell]).sum();
        let lr0 = ln_dry_rise(lr0 + ln_temp_factor(self.c_t, t_c) + heat_ratio.ln(), self.c_t, t_c);
        let wq = ln_dtm - lr0;
        let (k, f) = self.w.locate(wq);
        let lg: f64 = cell_weights
            .map(|(cell, w)| w * ((1.0 - f) * self.ln_g[cell * nw + k] + f * self.ln_g[cell * nw + k + 1]))
            .sum();
        let (w0, w1) = (self.w.nodes[0], self.w.nodes[nw - 1]);
        let ln_ratio = if wq >= w1 {
            soft_cap(w1)
        } else if wq <= w0 {
            soft_cap(w0) + (wq - w0)
        } else {
            soft_cap(wq)
        };
        let r = ((lr0 + ln_ratio + lg).exp() * scale).min(MELT_C - t_c);
        if r.is_finite() && r > RISE_FLOOR_K * 10.0 {
            r
        } else {
            0.0
        }
    }
}

/// Grid correction, ln per load node: the table grid is coarse (cost); its patch-average rise is biased low by
/// partly covered edge pixels. Per load node, the dry rise at a reference point (1 m/s
/// sliding at 20 m/s rolling) on the 64 x 48 reference grid over that on the table grid
/// rescales every R0 of that load (the melting-cap ratio G is left as is).
fn grid_corrections<F>(grids: &[PressureGrid], grid_at: &F, params: &PatchParams, rg: &TableRanges) -> Vec<f64>
where
    F: Fn(usize, (usize, usize)) -> Result<PressureGrid> + Sync,
{
    (0..grids.len())
        .into_par_iter()
        .map(|il| {
            let op = Operating { roll_speed_mps: 20.0, slide_speed_mps: 1.0, ice_temp_c: DRY_ICE_C };
            let fine = grid_at(il, REFERENCE_GRID);
            let coarse = rg.statistic.of(&solve_patch(&grids[il], &op, params).summary);
            match fine {
                Ok(g) if coarse > 0.0 => (rg.statistic.of(&solve_patch(&g, &op, params).summary) / coarse).ln(),
                _ => 0.0,
            }
        })
        .collect()
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
    /// Rolling (hysteresis) heat released in the tread band per unit load and rolling speed,
    /// W/(N m/s): the tread's share of the rolling loss times the rolling-resistance coefficient
    /// ([`TREAD_HYSTERESIS_SHARE`] f_rr; 0 = none).
    pub rolling_heat_per_n_mps: f64,
}

/// Share of a passenger tyre's rolling (hysteresis) loss dissipated in the tread band, 0-1.
/// Assumption: about half (the tread compound is the tyre's most hysteretic part; the sidewalls,
/// belts and bead take the rest), within the 0.4-0.6 usually quoted for passenger tyres.
pub const TREAD_HYSTERESIS_SHARE: f64 = 0.5;

/// The ATIIM per-step estimator: one bulk state per tyre plus the flash table.
#[derive(Debug, Clone)]
pub struct AtiimEstimator {
    /// The flash-rise table, built once per tyre and surface.
    pub table: FlashTable,
    /// Bulk-state parameters, shared by every tyre.
    pub bulk: BulkParams,
    /// Bulk tread-surface temperature per tyre, degC (NaN until the first update).
    pub t_bulk_c: Vec<f64>,
    /// Ice effusivity, W s^0.5/(m^2 K) (cached).
    e_ice: f64,
    /// The last two values of G, for the coupled update's first trial point.
    recent: Recent,
    /// Per tyre, the bulk ODE's conductance G and source S = P + G_ice T_ice + G_air T_air at the
    /// last accepted sample (NaN before the first): the period behind a sample is advanced with
    /// the mean of these and the sample's own (the exponential midpoint rule, second order in the
    /// period, where holding the sample's own would be first order).
    forcing: Vec<[f64; 2]>,
}

/// The last two values of G per tyre (of the first four) at the estimates the coupled update
/// accepted (the plain update's outputs, which are G), and the period between them.
#[derive(Debug, Clone, Copy)]
struct Recent {
    /// The latest value per tyre, degC (NaN: none yet).
    latest: [f64; 4],
    /// The one before it, degC (NaN: none yet).
    before: [f64; 4],
    /// The last update's period, s (NaN: none yet).
    period_s: f64,
}

impl Recent {
    /// Record tyre `i`'s new value `t_c` (tyres beyond the fourth are not tracked).
    fn push(&mut self, i: usize, t_c: f64) {
        if i < 4 {
            self.before[i] = self.latest[i];
            self.latest[i] = t_c;
        }
    }
}

/// The per-sample constants of [`AtiimEstimator::update`] that depend only on the bulk parameters
/// and the ice effusivity (computed once per update, not per tyre).
#[derive(Debug, Clone, Copy)]
struct BulkConstants {
    /// Series effusivity of tread and ice, W s^0.5/(m^2 K).
    e_series: f64,
    /// Contact width floored at 1 mm, m.
    width_m: f64,
    /// Heat capacity floored at 1e-6 J/K.
    heat_capacity_j_k: f64,
}

impl AtiimEstimator {
    /// New estimator for `n_tyres` tyres; bulk states start at the first update's surface temperature.
    pub fn new(table: FlashTable, bulk: BulkParams, n_tyres: usize) -> Self {
        AtiimEstimator {
            table,
            bulk,
            t_bulk_c: vec![f64::NAN; n_tyres],
            e_ice: ICE.effusivity(),
            recent: Recent { latest: [f64::NAN; 4], before: [f64::NAN; 4], period_s: f64::NAN },
            forcing: vec![[f64::NAN; 2]; n_tyres],
        }
    }

    /// The bulk ODE's forcing (G, S) at tyre `i`'s last accepted sample (NaN before the first).
    fn forcing_of(&self, i: usize) -> [f64; 2] {
        self.forcing.get(i).copied().unwrap_or([f64::NAN; 2])
    }

    /// Record tyre `i`'s forcing at the accepted sample (grows the state).
    fn set_forcing(&mut self, i: usize, f: [f64; 2]) {
        if self.forcing.len() <= i {
            self.forcing.resize(i + 1, [f64::NAN; 2]);
        }
        self.forcing[i] = f;
    }

    /// Contact temperature for one tyre from its bulk temperature (no state change), degC.
    #[inline]
    pub fn contact_temp_c(&self, t_bulk_c: f64, t: &TyreContact) -> f64 {
        let e_i = self.e_ice;
        let e_t = self.bulk.e_tread;
        let t_ice = t.surface_temp_c;
        // (the weights' divisions do not wait for the bulk temperature)
        let t_start = (e_t / (e_t + e_i) * t_bulk_c + e_i / (e_t + e_i) * t_ice).min(MELT_C);
        let flash =
            self.table.rise_k_for_force(t.fz_n, t.slide_speed_mps, t.roll_speed_mps, t_start, t.friction_force_n);
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

impl AtiimEstimator {
    /// The per-sample constants of [`Self::advance_tyre`].
    fn bulk_constants(&self) -> BulkConstants {
        let b = &self.bulk;
        let e_i = self.e_ice;
        BulkConstants {
            e_series: b.e_tread * e_i / (b.e_tread + e_i), // tread-to-ice conduction
            width_m: b.width_m.max(1e-3),
            heat_capacity_j_k: b.heat_capacity_j_k.max(1e-6),
        }
    }

    /// One tyre's bulk temperature after `h` seconds (>= 0, finite) from `tb` under conditions
    /// `t` at the period's end and forcing `prev` (G, S) at its start (NaN: none, the end's is
    /// held), its contact temperature then, degC, and the forcing at `t` (no state change).
    fn advance_tyre(
        &self,
        k: &BulkConstants,
        tb: f64,
        h: f64,
        t: &TyreContact,
        prev: [f64; 2],
    ) -> (f64, f64, [f64; 2]) {
        let b = &self.bulk;
        let e_s = k.e_series;
        let t_ice = finite_or(t.surface_temp_c, MELT_C);
        let tb = if tb.is_finite() { tb } else { t_ice };
        let fz = finite_or(t.fz_n, 0.0).max(0.0);
        let vr = finite_or(t.roll_speed_mps, 0.0).abs();
        let vs = finite_or(t.slide_speed_mps, 0.0).abs();
        // the tread's share of the sliding power, plus the rolling (hysteresis) heat of the band
        let power =
            b.tread_fraction * finite_or(t.friction_force_n, 0.0).abs() * vs + b.rolling_heat_per_n_mps * fz * vr;
        // conduction into the ice through the patch: area A, contact time t_c = L / v (L = A / W,
        // v = max(v_roll, v_slide, 0.1 m/s), t_c >= 1 us), two semi-infinite bodies in series:
        // G = A 2 e_s / sqrt(pi t_c) = 2 e_s sqrt(A W v / pi) (one root, no division)
        let area = fz * b.area_per_n;
        let v = vr.max(vs).max(0.1).min(area / k.width_m * 1e6);
        let g_ice =
            if area > 0.0 { 2.0 * e_s * (area * k.width_m * v * std::f64::consts::FRAC_1_PI).sqrt() } else { 0.0 };
        let g_air = b.band_area_m2 * (10.0 + 7.0 * vr.sqrt());
        let t_air = b.air_temp_c.unwrap_or(t_ice);
        let here = [g_ice + g_air, power + g_ice * t_ice + g_air * t_air];
        let (g, src) = if prev[0].is_finite() && prev[1].is_finite() {
            (0.5 * (prev[0] + here[0]), 0.5 * (prev[1] + here[1]))
        } else {
            (here[0], here[1])
        };
        let t_eq = src / g;
        let x = g * h / k.heat_capacity_j_k;
        // exp(-x); the series is exact to 1e-13 below 1e-4 (typical steps give x ~ 1e-6)
        let decay = if x < 1e-4 { 1.0 - x + 0.5 * x * x } else { (-x).exp() };
        let mut tb = t_eq + (tb - t_eq) * decay;
        if !tb.is_finite() {
            tb = t_ice;
        }
        let tt = TyreContact { surface_temp_c: t_ice, fz_n: fz, roll_speed_mps: vr, slide_speed_mps: vs, ..*t };
        (tb, self.contact_temp_c(tb, &tt), here)
    }

    /// Bulk temperature of tyre `i` before this update (NaN until the first; grows the state).
    fn bulk_of(&mut self, i: usize) -> f64 {
        if self.t_bulk_c.len() <= i {
            self.t_bulk_c.resize(i + 1, f64::NAN);
        }
        self.t_bulk_c[i]
    }
}

/// Largest number of condition evaluations of one coupled update ([`AtiimEstimator`]'s
/// `update_coupled`).
pub(crate) const COUPLED_MAX_EVALS: usize = 16;
/// Residual |T - G(T)| at which the coupled update over a 10 ms period ([`COUPLED_TOL_PERIOD_S`])
/// or longer stops, K (0.3 N of friction force where the force falls by 300 N per K of contact
/// temperature, as near melting on the sedan); shorter periods stop at a tolerance shrinking
/// with the square of the period ([`coupled_tol_k`]). The accepted estimate is a trial
/// temperature (the one the tyre's force was evaluated at), within the tolerance of the root, so
/// a fixed tolerance would put a floor under the error that does not shrink with the period:
/// scaled so, the estimate's share of the error stays a fixed fraction of the sampled loop's own,
/// which is second order in the period. Chosen by measurement on the ISO 3888-2 lane change on
/// ice (`tests/accuracy.rs`).
pub(crate) const COUPLED_TOL_K: f64 = 1e-3;
/// The control period at and above which [`COUPLED_TOL_K`] applies, s.
pub(crate) const COUPLED_TOL_PERIOD_S: f64 = 0.01;

/// The coupled update's tolerance over a period of `h_s` seconds, K: [`COUPLED_TOL_K`] times
/// (h / [`COUPLED_TOL_PERIOD_S`])^2, at most [`COUPLED_TOL_K`] and at least 1e-9 K (so the first
/// sample, which advances over no time, solves to 1e-9 K).
pub(crate) fn coupled_tol_k(h_s: f64) -> f64 {
    let q = h_s / COUPLED_TOL_PERIOD_S;
    let t = COUPLED_TOL_K * q * q;
    if t.is_finite() {
        t.clamp(1e-9, COUPLED_TOL_K)
    } else {
        COUPLED_TOL_K
    }
}

/// A coupled solve's accepted point for one tyre: (|residual|, bulk temperature, trial
/// temperature = output, G, the tyre's conditions, forcing), degC and K as in the solve.
type Accepted = (f64, f64, f64, f64, TyreContact, [f64; 2]);

impl ContactTemperature for AtiimEstimator {
    fn update(&mut self, h: f64, tyres: &[TyreContact], out: &mut [f64]) {
        let k = self.bulk_constants();
        let h = finite_or(h, 0.0).max(0.0);
        for (i, (t, o)) in tyres.iter().zip(out.iter_mut()).enumerate() {
            let tb = self.bulk_of(i);
            let (tb, tc, f) = self.advance_tyre(&k, tb, h, t, self.forcing_of(i));
            self.t_bulk_c[i] = tb;
            self.set_forcing(i, f);
            *o = tc;
            self.recent.push(i, tc);
        }
        self.recent.period_s = h;
    }

    /// The contact temperature consistent with the force it lets the tyre transmit. Per tyre,
    /// G(T) = the estimate after `h` under the conditions at contact temperature T; a warmer
    /// contact lowers the tyre's friction and so the heat, and G falls as T rises. The estimate
    /// is the root of T - G(T), which then rises strictly with T (unique). Near melting |G'| can
    /// exceed 1, so the plain lagged update (T_next = G(T_prev)) would alternate between a
    /// melting and a cooler contact from sample to sample instead of converging. Solved per tyre,
    /// all tyres in lockstep (one `conditions` call evaluates all of them): G at a first point
    /// (the last value of G accepted, closer to its root than the estimate, carried on over the
    /// period by the change between the last two; `guess` before there is one: in smooth
    /// running it is already within the tolerance, one evaluation), then G
    /// at that value, which brackets the root when G falls, then regula falsi (Illinois) within
    /// the bracket until |T - G(T)| <= `coupled_tol_k(h)`, at most `COUPLED_MAX_EVALS`
    /// evaluations. The estimate is the accepted trial point T itself, not G(T): the conditions
    /// left in `tyres` (and the caller's last evaluation, when the tyres converge together) are
    /// then exactly those at the estimate, and where G falls it is within the tolerance of the
    /// root: T - T* = (T - G(T)) / (1 - G'), 1 - G' > 1. A tyre whose first two points do not
    /// bracket (G not falling there) keeps the better of the two, as does a tyre that reaches
    /// the evaluation limit (the point with the smallest residual). The bulk state advances
    /// under the conditions of the accepted point.
    fn update_coupled(
        &mut self,
        h: f64,
        guess: &[f64],
        conditions: &mut dyn FnMut(&[f64], &mut [TyreContact]),
        tyres: &mut [TyreContact],
        out: &mut [f64],
    ) {
        const MAX_TYRES: usize = 4;
        let n = tyres.len().min(out.len()).min(guess.len());
        if n > MAX_TYRES {
            return super::update_at_guess(self, h, guess, conditions, tyres, out);
        }
        let k = self.bulk_constants();
        let h = finite_or(h, 0.0).max(0.0);
        let tol = coupled_tol_k(h);
        let tb0: [f64; MAX_TYRES] = std::array::from_fn(|i| if i < n { self.bulk_of(i) } else { f64::NAN });
        let f0: [[f64; 2]; MAX_TYRES] = std::array::from_fn(|i| self.forcing_of(i));
        // per tyre: trial temperature, bracket ends (T, residual) with residual < 0 and > 0,
        // the accepted point (|residual|, bulk, trial temperature = output, G, conditions),
        // whether it is done, and the Illinois side marker (-1 / +1: the end kept last time)
        let mut x = [0.0; MAX_TYRES];
        for i in 0..n {
            x[i] = self.first_trial(i, guess[i], &tyres[i], h);
        }
        let mut neg: [Option<(f64, f64)>; MAX_TYRES] = [None; MAX_TYRES];
        let mut pos: [Option<(f64, f64)>; MAX_TYRES] = [None; MAX_TYRES];
        let mut best: [Option<Accepted>; MAX_TYRES] = [None; MAX_TYRES];
        let mut done = [false; MAX_TYRES];
        let mut side = [0i8; MAX_TYRES];
        for eval in 0..COUPLED_MAX_EVALS {
            conditions(&x[..n], &mut tyres[..n]);
            for i in 0..n {
                if done[i] {
                    continue;
                }
                let (tb, g, f) = self.advance_tyre(&k, tb0[i], h, &tyres[i], f0[i]);
                let r = x[i] - g;
                if best[i].is_none_or(|b| r.abs() < b.0) {
                    best[i] = Some((r.abs(), tb, x[i], g, tyres[i], f));
                }
                if !r.is_finite() || r.abs() <= tol {
                    done[i] = true;
                    continue;
                }
                if r < 0.0 {
                    neg[i] = Some((x[i], r));
                } else {
                    pos[i] = Some((x[i], r));
                }
                x[i] = match (neg[i], pos[i]) {
                    (Some(a), Some(b)) => illinois_step(a, b, r, &mut neg[i], &mut pos[i], &mut side[i]),
                    _ if eval == 0 => g, // the plain iteration's next point
                    _ => {
                        done[i] = true; // no bracket from two points: keep the plain value
                        x[i]
                    }
                };
            }
            if done[..n].iter().all(|d| *d) {
                break;
            }
        }
        self.accept(h, &best[..n], tyres, out);
    }
}

impl AtiimEstimator {
    /// Tyre `i`'s first trial contact temperature over a period of `h` s: the last G accepted
    /// (closer to its root than the estimate) carried on over the period by the change between
    /// the last two; the `guess` where there are none (then the tyre's surface, then melting).
    #[inline(always)]
    fn first_trial(&self, i: usize, guess: f64, tyre: &TyreContact, h: f64) -> f64 {
        let r = &self.recent;
        let x = finite_or(r.latest[i], finite_or(guess, finite_or(tyre.surface_temp_c, MELT_C)));
        let ext = x + (r.latest[i] - r.before[i]) * (h / r.period_s);
        if ext.is_finite() {
            ext
        } else {
            x
        }
    }

    /// Keep each tyre's accepted point (`best`, per tyre): its bulk temperature, forcing, contact
    /// temperature (into `out`) and conditions (into `tyres`); the period `h` and each accepted G
    /// for the next period's first trial.
    #[inline(always)]
    fn accept(&mut self, h: f64, best: &[Option<Accepted>], tyres: &mut [TyreContact], out: &mut [f64]) {
        self.recent.period_s = h;
        for (i, b) in best.iter().enumerate() {
            if let Some((_, tb, x, g, t, f)) = *b {
                self.t_bulk_c[i] = tb;
                self.set_forcing(i, f);
                out[i] = x;
                self.recent.push(i, g);
                tyres[i] = t;
            }
        }
    }
}

/// One Illinois step of a bracketed root search on residual r(T) = T - G(T): the bracket ends
/// `(a, ra)` (residual < 0) and `(b, rb)` (> 0), the residual `r` just found at the point that
/// replaced one of them; halves the residual of the end kept twice in a row (`side`: the end kept
/// last time, -1 or +1), stores the ends back and returns the next trial: the secant through the
/// ends, or their midpoint where the secant leaves the bracket.
#[inline(always)]
fn illinois_step(
    (a, ra): (f64, f64),
    (b, rb): (f64, f64),
    r: f64,
    neg: &mut Option<(f64, f64)>,
    pos: &mut Option<(f64, f64)>,
    side: &mut i8,
) -> f64 {
    let kept = if r < 0.0 { 1 } else { -1 };
    let (ra, rb) = match (kept, *side) {
        (1, 1) => (ra, 0.5 * rb),
        (-1, -1) => (0.5 * ra, rb),
        _ => (ra, rb),
    };
    if kept == 1 {
        *pos = Some((b, rb));
    } else {
        *neg = Some((a, ra));
    }
    *side = kept;
    let s = a - ra * (b - a) / (rb - ra);
    if s.is_finite() && s > a.min(b) && s < a.max(b) {
        s
    } else {
        0.5 * (a + b)
    }
}

/// Effusivity weighting helper kept public for docs/tests: tread share at equal contact times.
pub fn rolling_tread_fraction(e_tread: f64) -> f64 {
    let e = effective_effusivity(e_tread, ICE.effusivity(), 1.0, 1.0);
    (e - ICE.effusivity()) / e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within 1e-14 of `f64::ln` from 1e-12 to 1e12 and across every cell of its table; 0 at 1.
    #[test]
    fn fast_ln_matches_std_ln() {
        let mut x = 1e-12;
        while x < 1e12 {
            assert!((fast_ln(x) - x.ln()).abs() < 1e-14, "{x}: {} {}", fast_ln(x), x.ln());
            x *= 1.37;
        }
        // every table cell, its edges included, and both sides of 1 (where ln c and ln(1 + r)
        // cancel)
        for e in [-3i32, -1, 0, 7] {
            for j in 0..=1024 {
                let m = 1.0 + j as f64 / 1024.0;
                for x in [m * 2f64.powi(e), (m * 2f64.powi(e)).next_up(), (m * 2f64.powi(e)).next_down()] {
                    assert!((fast_ln(x) - x.ln()).abs() < 1e-14, "{x}: {} {}", fast_ln(x), x.ln());
                }
            }
        }
        assert!(fast_ln(0.0) == f64::NEG_INFINITY && fast_ln(-1.0).is_nan() && fast_ln(1.0) == 0.0);
    }

    #[test]
    fn node_temperatures_solve_the_w_equation() {
        // c_T = 0: closed form T = -R0 e^w
        for (r0, w) in [(0.01f64, -2.0), (3.0, 0.5), (40.0, 2.0)] {
            let t = node_ice_temp_c(r0.ln(), 0.0, w);
            assert!((t / (-r0 * w.exp()) - 1.0).abs() < 1e-9, "{r0} {w}: {t}");
        }
        // c_T = 0.03: the warmest root of ln(-T) - ln R0(T) = w
        for (r0, w) in [(0.01f64, -2.0), (3.0, 0.5), (30.0, 2.0), (200.0, 1.0)] {
            let t = node_ice_temp_c(r0.ln(), 0.03, w);
            let res = (-t).ln() - ln_dry_rise(r0.ln() + ln_temp_factor(0.03, t), 0.03, t) - w;
            assert!(res.abs() < 1e-9 && t < 0.0, "{r0} {w}: T {t}, residual {res}");
        }
        // no self-heating correction where the rise stays below the law's -40 degC clamp
        assert_eq!(ln_dry_rise(2f64.ln(), 0.03, -1e6), 2f64.ln());
        assert!((ln_dry_rise(2f64.ln(), 0.03, -10.0) - (2.0 / 1.03f64).ln()).abs() < 1e-9);
    }

    /// An estimator on a synthetic table: dry rise 2 K per m/s of sliding (any load, any slip
    /// fraction), G = 1 (the smooth cap exactly), heat priced at mu_dry 0.15, no temperature factor.
    fn synthetic_estimator(n: usize) -> AtiimEstimator {
        let slide = Axis::new(0.01f64.ln(), 30f64.ln(), 2);
        let ln_r0 = (0..8).map(|k| (2.0 * slide.node((k / 2) % 2).exp()).ln()).collect();
        let table = FlashTable {
            load: Axis::new(2000f64.ln(), 12000f64.ln(), 2),
            slide,
            roll: Axis::from_nodes(vec![1e-4f64.ln(), 0.0]),
            w: Axis::new(-2.0, 2.0, 2),
            ln_r0,
            ln_g: vec![0.0; 16],
            vs_min: 0.01,
            mu_dry: 0.15,
            c_t: 0.0,
            caps: w_caps(&Axis::new(-2.0, 2.0, 2)),
        };
        let bulk = BulkParams {
            heat_capacity_j_k: 1500.0,
            band_area_m2: 0.37,
            tread_fraction: 0.26,
            air_temp_c: None,
            area_per_n: 1.0 / 200e3,
            width_m: 0.2,
            e_tread: 600.0,
            rolling_heat_per_n_mps: 0.0,
        };
        AtiimEstimator::new(table, bulk, n)
    }

    /// Conditions of a sliding tyre (4000 N, 3 m/s sliding, 10 m/s rolling, ice at -3 degC) whose
    /// friction falls with its contact temperature: mu = 0.15 (0.2 + 0.8 / (1 + e^((T + 1.5) / s)))
    /// with steepness `s` per tyre (infinite: constant friction).
    fn sliding(steep: &[f64], temps: &[f64], out: &mut [TyreContact]) {
        for ((o, &t), &s) in out.iter_mut().zip(temps).zip(steep) {
            let mu = 0.15 * (0.2 + 0.8 / (1.0 + ((t + 1.5) / s).exp()));
            *o = TyreContact {
                fz_n: 4000.0,
                roll_speed_mps: 10.0,
                slide_speed_mps: 3.0,
                friction_force_n: mu * 4000.0,
                surface_temp_c: -3.0,
            };
        }
    }

    /// The coupled update returns the fixed point T = G(T) of the plain update G under the
    /// conditions at T, where the lagged iteration T_next = G(T_prev) (the plain update at the
    /// previous estimate) does not converge; with a friction that does not depend on the contact
    /// temperature it is the plain update, bit for bit.
    /// The root of T - G(T) for tyre `i` by bisection on [-3, 0] degC (T - G(T) rises with T),
    /// every tyre at the same trial temperature.
    fn bisect_root(g: impl Fn([f64; 4]) -> [f64; 4], i: usize) -> f64 {
        let (mut lo, mut hi) = (-3.0, 0.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if mid - g([mid; 4])[i] > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    #[test]
    fn coupled_update_is_the_consistent_fixed_point() {
        let steep = [0.05, 0.3, f64::INFINITY, 0.02];
        let h = 0.01;
        // warm the bulk a little so the start is not the initial state
        let mut est = synthetic_estimator(4);
        let mut tyres = [TyreContact::default(); 4];
        let mut out = [0.0; 4];
        sliding(&steep, &[-3.0; 4], &mut tyres);
        est.update(h, &tyres, &mut out);
        let start = est.clone();
        // G(T) from the start state: the plain update under the conditions at T
        let g = |t: [f64; 4]| {
            let mut e = start.clone();
            let mut c = [TyreContact::default(); 4];
            let mut o = [0.0; 4];
            sliding(&steep, &t, &mut c);
            e.update(h, &c, &mut o);
            (o, e.t_bulk_c.clone())
        };
        // the lagged iteration on the steep tyres: a lasting alternation, no convergence
        let mut t = out;
        let mut last = [0.0; 4];
        for _ in 0..40 {
            last = t;
            t = g(t).0;
        }
        for i in [0, 3] {
            assert!((t[i] - last[i]).abs() > 0.05, "tyre {i}: {} -> {}", last[i], t[i]);
        }
        let guess = out;
        let mut coupled = start.clone();
        let mut cond = |temps: &[f64], o: &mut [TyreContact]| sliding(&steep, temps, o);
        let mut left = [TyreContact::default(); 4];
        let mut res = [0.0; 4];
        coupled.update_coupled(h, &guess, &mut cond, &mut left, &mut res);
        let root: [f64; 4] = std::array::from_fn(|i| bisect_root(|t| g(t).0, i));
        for i in 0..4 {
            assert!(res[i] < 0.0 && res[i] > -3.0, "tyre {i}: {}", res[i]);
            assert!((root[i] - res[i]).abs() <= COUPLED_TOL_K, "tyre {i}: {} but the root is {}", res[i], root[i]);
        }
        // the conditions left in `left` are those at the output temperatures, the bulk state is
        // the plain update's under them, and the output (the accepted trial point) is within the
        // tolerance of the plain update's output G
        let tol = coupled_tol_k(h);
        let mut at_res = [TyreContact::default(); 4];
        sliding(&steep, &res, &mut at_res);
        assert_eq!(at_res, left);
        let mut plain = start.clone();
        let mut o = [0.0; 4];
        plain.update(h, &left, &mut o);
        assert!(o.iter().zip(&res).all(|(g, t)| (g - t).abs() <= tol), "{o:?} {res:?}");
        assert_eq!(plain.t_bulk_c, coupled.t_bulk_c);
        // constant friction (tyre 2): G is the same at every T, so the bulk state is the plain
        // update's at the guess, bit for bit, and the output within the tolerance of its output
        let mut c = [TyreContact::default(); 4];
        sliding(&steep, &guess, &mut c);
        let mut plain = start.clone();
        plain.update(h, &c, &mut o);
        assert!((o[2] - res[2]).abs() <= tol, "{} {}", o[2], res[2]);
        assert_eq!(plain.t_bulk_c[2], coupled.t_bulk_c[2]);
        // non-finite guesses and conditions: finite output, no panic
        let mut bad = |temps: &[f64], o: &mut [TyreContact]| {
            sliding(&steep, temps, o);
            o[1].friction_force_n = f64::NAN;
        };
        let mut e = start.clone();
        e.update_coupled(h, &[f64::NAN, 0.0, f64::INFINITY, -3.0], &mut bad, &mut left, &mut res);
        assert!(res.iter().all(|v| v.is_finite()), "{res:?}");
    }

    /// The evaluation of the rise arranged for latency gives the log-domain form's values (with
    /// exact logarithms) within 1e-13 relative (measured 2.3e-15; `fast_ln`'s error is below
    /// 1e-14 absolute in each logarithm), on a table with uneven values (c_T = 0.03, a G that varies along every axis), across the
    /// w range and beyond both its ends, below the smallest sliding-speed node, with the force
    /// pricing on and off; and the two differ when one of the three branches is changed (the
    /// log-domain reference is not the code under test).
    #[test]
    fn rise_matches_the_log_domain_form() {
        let slide = Axis::new(0.01f64.ln(), 30f64.ln(), 3);
        let load = Axis::new(2000f64.ln(), 12000f64.ln(), 2);
        let roll = Axis::from_nodes(vec![1e-4f64.ln(), 0.1f64.ln(), 0.0]);
        let w = Axis::new(-2.0, 2.0, 5);
        let cells = load.n() * slide.n() * roll.n();
        // a deterministic, uneven fill: ln R0 from -3 to 4, ln G within +-0.3
        let ln_r0 = (0..cells).map(|k| -3.0 + 7.0 * ((k * 37 % 17) as f64 / 16.0)).collect();
        let ln_g = (0..cells * w.n()).map(|k| 0.3 * (((k * 53 % 29) as f64 / 14.0) - 1.0)).collect();
        let caps = w_caps(&w);
        let table = FlashTable { load, slide, roll, w, ln_r0, ln_g, vs_min: 0.01, mu_dry: 0.15, c_t: 0.03, caps };
        let mut worst: f64 = 0.0;
        let mut seen = [0usize; 3];
        for fz in [1500.0, 2600.0, 4000.0, 11000.0, 15000.0] {
            for vs in [0.002, 0.01, 0.3, 2.0, 29.0, 50.0] {
                for vr in [0.0, 0.05, 3.0, 20.0] {
                    for t in [-45.0, -30.0, -10.0, -3.0, -0.5, -0.01] {
                        for ratio in [1.0, 0.05, 0.7, 3.0] {
                            let fast = table.rise_k_priced(fz, vs, vr, t, ratio);
                            let slow = table.rise_k_log_domain(fz, vs, vr, t, ratio);
                            assert!(fast.is_finite() && slow > 0.0, "{fz} {vs} {vr} {t} {ratio}: {fast} {slow}");
                            worst = worst.max((fast / slow - 1.0).abs());
                            // the regime: at the melting cap, under a tenth of the margin
                            // (dry), or between
                            let margin = MELT_C - t;
                            let k = if slow >= margin * (1.0 - 1e-12) {
                                0
                            } else if slow < 0.1 * margin {
                                2
                            } else {
                                1
                            };
                            seen[k] += 1;
                        }
                    }
                }
            }
        }
        assert!(worst < 1e-13, "largest relative difference {worst:e}");
        assert!(seen.iter().all(|&n| n > 20), "regimes exercised (capped, between, dry): {seen:?}");
    }

    #[test]
    fn soft_cap_limits() {
        // S / R0 -> 1 for dtm >> R0 and -> dtm / R0 for dtm << R0
        assert!(soft_cap(40.0).abs() < 1e-15);
        assert!((soft_cap(-40.0) + 40.0).abs() < 1e-15);
        assert!((soft_cap(0.0) + 2f64.ln()).abs() < 1e-15);
    }
}
