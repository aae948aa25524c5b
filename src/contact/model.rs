//! The coupled patch model: per pixel, frictional heating, temperature rise, wet/dry state, water
//! film and friction, marching each track from the leading edge (dissertation §4.1–4.1.5).
//!
//! Per track (one column of the grid), pixel by pixel in the order the surface meets them:
//! 1. Brush adhesion: an element at distance xi behind the track's first loaded pixel carries
//!    k_b s xi (s = slide speed / roll speed, k_b from Gent's E); it slides once that reaches
//!    mu_dry p and keeps sliding (simple brush model). Adhering pixels generate no heat; in the
//!    pixel where sliding starts, only the sliding part of its length heats (sub-pixel onset).
//! 2. Dry sliding pixel: flux q = mu_dry p v_slide into tread + ice (`heat.rs`); if the interface
//!    would reach 0 degC by the pixel's end, the pixel is wet instead.
//! 3. Wet pixel: the interface is pinned at 0 degC. The conducted flux q_c is the flux that keeps
//!    the Duhamel sum at exactly (0 - T_ice) at the pixel end (discrete Abel inversion, clamped
//!    at zero from below); the film then follows `film.rs` with viscous heating kappa eta v^2 / h, and the heat
//!    generated is the viscous heat (time-averaged 1/h). Excess over q_c melts ice.
//! 4. Friction per pixel: adhesion stress / p; dry sliding mu_dry; wet: eq. 2.1 with the floor
//!    mu_F = min(viscous mu (eq. 4.13), mu_dry) and dmu = mu_dry - mu_F. The patch drawbar-pull
//!    coefficient is sum(tau dA) / F_z (eq. 4.20–4.22 as a stress sum: in the sliding zone it equals
//!    the heat balance q_generated / (p v_slide)).
//!
//! Time base: the ice passes at the transit speed V_g = max(roll speed, slide speed) (exact for free
//! rolling and a locked wheel, first order in slip otherwise); the tread's contact time is
//! min(x / roll speed, lock time).

use super::film::{advance, FilmCoeffs, FilmParams};
use super::friction::{beta_from_critical_height, brush_stress_pa, film_mu, viscous_mu};
use super::heat::{centre_weights, duhamel_weights, effective_effusivity};
use super::patch::PressureGrid;
use super::thermal::{Compound, ICE, LATENT_HEAT_J_KG, MELT_C, WATER_VISCOSITY_PA_S};
use std::f64::consts::PI;

/// Parameters of the patch model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchParams {
    /// Tread compound (thermal properties, Shore A).
    pub compound: Compound,
    /// Sliding friction of dry ice, 0.05–0.4 (0.15–0.20 measured on dry ice, §2.6.4).
    pub mu_dry: f64,
    /// Water-film parameters.
    pub film: FilmParams,
    /// Critical film height of eq. 2.1 (excess friction down to 25 %), m (20e-9 – 1e-6).
    pub critical_film_m: f64,
    /// Tread depth, m (0.002–0.010; SRTT 7.97 mm), for the brush stiffness.
    pub tread_depth_m: f64,
    /// Void ratio used for the brush stiffness, 0–0.6.
    pub void_ratio: f64,
    /// Brush adhesion zone on (true) or the whole patch sliding (false).
    pub brush: bool,
    /// Tread contact-time cap, s (locked wheel: the lock duration; 0.1–10).
    pub lock_time_s: f64,
}

impl PatchParams {
    /// SRTT defaults used by the shipped scenarios (each documented in docs/atiim.md).
    pub fn srtt(ice_temp_c: f64) -> Self {
        PatchParams {
            compound: Compound::generic(super::thermal::preset_shore_a("srtt", ice_temp_c).unwrap_or(67.3)),
            mu_dry: 0.15,
            film: FilmParams { kappa: 1.0, asperity_d_m: 2e-4, substeps: 8 },
            critical_film_m: 50e-9,
            tread_depth_m: 7.97e-3,
            void_ratio: 0.3,
            brush: true,
            lock_time_s: 1.0,
        }
    }
}

/// Operating point of the patch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Operating {
    /// Rolling speed omega R_e of the tread, m/s (>= 0; 0 = locked).
    pub roll_speed_mps: f64,
    /// Sliding speed of tread over ice, m/s (>= 0).
    pub slide_speed_mps: f64,
    /// Bulk ice temperature (and initial tread surface temperature), degC (-30..0).
    pub ice_temp_c: f64,
}

/// Per-pixel fields and patch summary (row-major like the grid).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchResult {
    pub rows: usize,
    pub cols: usize,
    /// Temperature rise of the interface at pixel centres, K (capped at 0 degC - T_ice).
    pub rise_k: Vec<f64>,
    /// Wet (melting) pixels.
    pub wet: Vec<bool>,
    /// Sliding pixels (others adhere or are out of contact).
    pub sliding: Vec<bool>,
    /// Film height at pixel ends, m.
    pub film_m: Vec<f64>,
    /// Viscous friction (eq. 4.13, pixel average of 1/h) in wet pixels, else 0.
    pub mu_visc: Vec<f64>,
    /// Friction coefficient carried by each loaded pixel (tau / p), else 0.
    pub mu: Vec<f64>,
    /// Heat generated, into tread, into ice, into melting (incl. squeezed water), W/m^2.
    pub q_gen: Vec<f64>,
    pub q_tread: Vec<f64>,
    pub q_ice: Vec<f64>,
    pub q_melt: Vec<f64>,
    /// Summary.
    pub summary: PatchSummary,
}

/// Patch maxima and averages.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct PatchSummary {
    pub load_n: f64,
    pub contact_area_m2: f64,
    pub mean_pressure_pa: f64,
    pub max_pressure_pa: f64,
    pub max_rise_k: f64,
    /// Mean rise over loaded pixels, K (the estimator's flash rise).
    pub mean_rise_k: f64,
    pub wet_fraction: f64,
    pub sliding_fraction: f64,
    pub max_film_m: f64,
    pub mean_film_wet_m: f64,
    /// Viscous friction (eq. 4.13), pressure-weighted: over each track's first wet pixel (leading
    /// edge of the wet zone; grid-dependent, see docs/atiim.md), over wet pixels in the last 10 %
    /// of each track (trailing edge), and the plain mean over wet pixels.
    pub mu_visc_leading: f64,
    pub mu_visc_trailing: f64,
    pub mu_visc_mean: f64,
    /// Drawbar-pull coefficient sum(tau dA) / F_z.
    pub drawbar_coeff: f64,
    /// Patch powers, W.
    pub power_generated_w: f64,
    pub power_tread_w: f64,
    pub power_ice_w: f64,
    pub power_melt_w: f64,
}

/// Solve the patch model on `grid` at `op`. Never panics; degenerate inputs (zero speeds) give a
/// cold, dry patch.
pub fn solve_patch(grid: &PressureGrid, op: &Operating, pp: &PatchParams) -> PatchResult {
    // a grid whose shape does not match its data (possible only when built by hand, since every
    // reader validates) is treated as empty
    let (rows, cols) = if grid.p_pa.len() == grid.rows * grid.cols { (grid.rows, grid.cols) } else { (0, 0) };
    let n = rows * cols;
    let mut r = PatchResult {
        rows,
        cols,
        rise_k: vec![0.0; n],
        wet: vec![false; n],
        sliding: vec![false; n],
        film_m: vec![0.0; n],
        mu_visc: vec![0.0; n],
        mu: vec![0.0; n],
        q_gen: vec![0.0; n],
        q_tread: vec![0.0; n],
        q_ice: vec![0.0; n],
        q_melt: vec![0.0; n],
        summary: PatchSummary::default(),
    };
    let vr = if op.roll_speed_mps.is_finite() { op.roll_speed_mps.max(0.0) } else { 0.0 };
    let vs = if op.slide_speed_mps.is_finite() { op.slide_speed_mps.max(0.0) } else { 0.0 };
    let tice = if op.ice_temp_c.is_finite() { op.ice_temp_c } else { MELT_C };
    let vg = vr.max(vs);
    let dtm = (MELT_C - tice).max(0.0);
    let e_t = pp.compound.solid.effusivity();
    let e_i = ICE.effusivity();
    let kb = pp.compound.brush_stiffness_pa_per_m(pp.tread_depth_m, pp.void_ratio);
    let slip = if vr > 1e-9 { vs / vr } else { f64::INFINITY };
    let beta = beta_from_critical_height(pp.critical_film_m);
    let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
    let heating = vg > 1e-9 && vs > 0.0;
    let dt = if heating { grid.dx_m / vg } else { 0.0 };
    let wend = duhamel_weights(rows + 1);
    let wc = centre_weights(rows + 1);
    // Effective effusivity and tread share per row (same for every track).
    let mut e_row = vec![e_t + e_i; rows];
    let mut ft_row = vec![e_t / (e_t + e_i); rows];
    if heating {
        for i in 0..rows {
            let x = (i as f64 + 0.5) * grid.dx_m;
            let ti = x / vg;
            let tt = if vr > 1e-12 { (x / vr).min(pp.lock_time_s.max(1e-6)) } else { pp.lock_time_s.max(1e-6) };
            e_row[i] = effective_effusivity(e_t, e_i, ti, tt);
            ft_row[i] = (e_row[i] - e_i) / e_row[i];
        }
    }
    let sqdt = dt.sqrt();
    let k_rise = 2.0 * sqdt / PI.sqrt();
    let mut q = vec![0.0; rows];
    let eta = WATER_VISCOSITY_PA_S;
    let kappa = pp.film.kappa;
    for c in 0..cols {
        q.iter_mut().for_each(|v| *v = 0.0);
        let mut first: Option<usize> = None;
        let mut sliding = !pp.brush;
        let mut h = 0.0f64;
        let mut wet_prev = false;
        for i in 0..rows {
            let idx = i * cols + c;
            let p = grid.p_pa[i * grid.cols + c];
            // history sums of earlier pixels: at this pixel's end and centre
            let (mut s_end, mut s_mid) = (0.0, 0.0);
            if heating {
                for k in 0..i {
                    s_end += q[k] * wend[i - k];
                    s_mid += q[k] * wc[i - k];
                }
            }
            let e = e_row[i];
            if p <= 0.0 {
                // groove or outside: no contact, no heat; water stays in place
                r.rise_k[idx] = if heating { (k_rise * s_mid / e).min(dtm) } else { 0.0 };
                r.film_m[idx] = h;
                continue;
            }
            let i0 = *first.get_or_insert(i);
            let xi = (i - i0) as f64 * grid.dx_m + 0.5 * grid.dx_m;
            // Fraction of this pixel's length that slides: the onset xi_s = mu p / (k s) may fall
            // inside the pixel (sub-pixel onset keeps the result continuous in the slip).
            let mut frac = 1.0;
            let mut tau_adh = 0.0;
            if !sliding {
                let xi_s = if slip.is_finite() && slip > 0.0 { pp.mu_dry * p / (kb * slip) } else { f64::INFINITY };
                let xi_end = xi + 0.5 * grid.dx_m;
                frac = ((xi_end - xi_s) / grid.dx_m).clamp(0.0, 1.0);
                if !slip.is_finite() {
                    frac = 1.0;
                }
                // mean adhesion stress over the adhering part of the pixel
                let xa = 0.5 * (xi - 0.5 * grid.dx_m + xi_end.min(xi_s.max(xi - 0.5 * grid.dx_m)));
                tau_adh = brush_stress_pa(kb, slip.min(1e6), xa).min(pp.mu_dry * p);
                if frac > 0.0 {
                    sliding = true;
                } else {
                    r.mu[idx] = tau_adh / p;
                    r.rise_k[idx] = if heating { (k_rise * s_mid / e).min(dtm) } else { 0.0 };
                    continue;
                }
            }
            r.sliding[idx] = true;
            if !heating {
                r.mu[idx] = (frac * pp.mu_dry * p + (1.0 - frac) * tau_adh) / p;
                continue;
            }
            let q_dry = frac * pp.mu_dry * p * vs;
            let rise_end_dry = k_rise * (s_end + q_dry * wend[0]) / e;
            if !(wet_prev || h > 0.0) && rise_end_dry < dtm {
                q[i] = q_dry;
                r.rise_k[idx] = k_rise * (s_mid + q_dry * wc[0]) / e;
                r.mu[idx] = (frac * pp.mu_dry * p + (1.0 - frac) * tau_adh) / p;
                r.q_gen[idx] = q_dry;
                r.q_tread[idx] = ft_row[i] * q_dry;
                r.q_ice[idx] = q_dry - r.q_tread[idx];
                continue;
            }
            // wet: pin the interface at the melting point at the pixel end
            let qc = ((dtm * e / k_rise - s_end) / wend[0]).max(0.0);
            let coeffs = FilmCoeffs::new(&pp.film, vs, qc, p);
            let st = advance(h, dt, pp.film.substeps, &coeffs);
            let inv_h_mean = st.inv_h_integral / dt;
            let q_v = kappa * eta * vs * vs * inv_h_mean;
            let mu_v = viscous_mu(kappa, eta, vs, p, inv_h_mean);
            let melt = rl * (st.h_end_m - h + st.squeezed_m) / dt;
            q[i] = qc;
            r.wet[idx] = true;
            r.rise_k[idx] = dtm;
            r.film_m[idx] = st.h_end_m;
            r.mu_visc[idx] = mu_v;
            let h_mean = 0.5 * (h + st.h_end_m);
            r.mu[idx] = film_mu(pp.mu_dry, mu_v.min(pp.mu_dry), beta, h_mean);
            r.q_gen[idx] = q_v;
            r.q_tread[idx] = ft_row[i] * qc;
            r.q_ice[idx] = qc - r.q_tread[idx];
            r.q_melt[idx] = melt;
            h = st.h_end_m;
            wet_prev = h > 0.0;
        }
    }
    summarize(grid, op, &mut r);
    r
}

fn summarize(grid: &PressureGrid, op: &Operating, r: &mut PatchResult) {
    let da = grid.pixel_area_m2();
    let (rows, cols) = (r.rows, r.cols);
    let mut s = PatchSummary {
        load_n: grid.load_n(),
        contact_area_m2: grid.contact_area_m2(),
        mean_pressure_pa: grid.mean_contact_pressure_pa(),
        max_pressure_pa: grid.p_pa.iter().cloned().fold(0.0, f64::max),
        ..Default::default()
    };
    let (mut nl, mut nw, mut ns) = (0usize, 0usize, 0usize);
    let (mut sum_rise, mut sum_film, mut sum_mu_v, mut tau) = (0.0, 0.0, 0.0, 0.0);
    for idx in 0..rows * cols {
        let p = grid.p_pa[idx];
        s.max_rise_k = s.max_rise_k.max(r.rise_k[idx]);
        s.max_film_m = s.max_film_m.max(r.film_m[idx]);
        s.power_generated_w += r.q_gen[idx] * da;
        s.power_tread_w += r.q_tread[idx] * da;
        s.power_ice_w += r.q_ice[idx] * da;
        s.power_melt_w += r.q_melt[idx] * da;
        if p > 0.0 {
            nl += 1;
            sum_rise += r.rise_k[idx];
            tau += r.mu[idx] * p * da;
            if r.sliding[idx] {
                ns += 1;
            }
            if r.wet[idx] {
                nw += 1;
                sum_film += r.film_m[idx];
                sum_mu_v += r.mu_visc[idx];
            }
        }
    }
    // Viscous friction at the wet zone's leading edge (each track's onset pixel) and trailing edge
    // (wet pixels in the last 10 % of the track's loaded length), pressure-weighted
    // (sum mu p / sum p = shear force / normal force), so low-pressure edge pixels do not dominate.
    let (mut lead_t, mut lead_p, mut trail_t, mut trail_p) = (0.0, 0.0, 0.0, 0.0);
    for c in 0..cols {
        let loaded: Vec<usize> = (0..rows).filter(|&i| grid.p_pa[i * cols + c] > 0.0).collect();
        let (Some(&i0), Some(&i1)) = (loaded.first(), loaded.last()) else { continue };
        if let Some(f) = (0..rows).find(|&i| r.wet[i * cols + c]) {
            let p = grid.p_pa[f * cols + c];
            lead_t += r.mu_visc[f * cols + c] * p;
            lead_p += p;
        }
        let tail = i1 as f64 - 0.1 * (i1 - i0 + 1) as f64;
        for &i in loaded.iter().filter(|&&i| i as f64 > tail) {
            if r.wet[i * cols + c] {
                let p = grid.p_pa[i * cols + c];
                trail_t += r.mu_visc[i * cols + c] * p;
                trail_p += p;
            }
        }
    }
    if lead_p > 0.0 {
        s.mu_visc_leading = lead_t / lead_p;
    }
    if trail_p > 0.0 {
        s.mu_visc_trailing = trail_t / trail_p;
    }
    let _ = op;
    if nl > 0 {
        s.mean_rise_k = sum_rise / nl as f64;
        s.wet_fraction = nw as f64 / nl as f64;
        s.sliding_fraction = ns as f64 / nl as f64;
    }
    if nw > 0 {
        s.mean_film_wet_m = sum_film / nw as f64;
        s.mu_visc_mean = sum_mu_v / nw as f64;
    }
    if s.load_n > 0.0 {
        s.drawbar_coeff = tau / s.load_n;
    }
    r.summary = s;
}

/// Drawbar-pull coefficient versus slip ratio at travel speed `speed_mps`: for each slip ratio
/// kappa (>= 0, driving; DESIGN §4 convention kappa = (omega R - V) / V) the patch is solved with
/// roll speed V (1 + kappa) and slide speed kappa V. Returns (kappa, coefficient, summary).
pub fn drawbar_curve(
    grid: &PressureGrid,
    pp: &PatchParams,
    speed_mps: f64,
    ice_temp_c: f64,
    slips: &[f64],
) -> Vec<(f64, PatchSummary)> {
    slips
        .iter()
        .map(|&k| {
            let k = k.max(0.0);
            let op = Operating { roll_speed_mps: speed_mps * (1.0 + k), slide_speed_mps: speed_mps * k, ice_temp_c };
            (k, solve_patch(grid, &op, pp).summary)
        })
        .collect()
}
