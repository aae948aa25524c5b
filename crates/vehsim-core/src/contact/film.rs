//! Water-film height under a sliding tread element (dissertation eq. 4.5–4.7, 4.10).
//!
//! The patch model uses `advance_wet`: the film grows from the heat of the pixel's own friction
//! law (`friction::WetFilm`, bounded as h -> 0) plus rolling heat, minus conduction, and thins by
//! squeeze-out; it is integrated in h directly. [`advance`] below integrates eq. 4.10 as printed
//! (viscous heat kappa eta v^2 / h, singular at h = 0) and is kept as the reference form with its
//! closed-form checks:
//!
//! Balance per unit nominal area while the ice surface is at the melting point (erratum 4: the
//! melting indicator of eq. 4.10 is "surface at T_m", as eq. 4.8 says):
//!
//!   rho_ice L dh/dt = kappa eta v^2 / h - q_c(t)  -  rho_ice L (8 p / (3 eta D^2)) h^3
//!
//! - `kappa eta v^2 / h`: viscous heating in the film (eq. 4.12 times v), W/m^2;
//! - `q_c`: heat conducted away from the 0 degC interface into ice *and* tread, W/m^2. Eq. 4.10
//!   keeps only the ice; we keep both because the tread's effusivity is about a third of the ice's
//!   (not negligible). The caller computes q_c from the thermal history (see `heat.rs`);
//! - the last term is squeeze-out below asperities of diameter D (eq. 4.6).
//!
//! `1/h` is singular at h = 0 (the film at melting onset), so we integrate u = h^2 instead:
//!
//!   du/dt = A - B sqrt(u) - C u^2,  A = 2 kappa eta v^2 / (rho L),  B = 2 q_c / (rho L),
//!   C = 16 p / (3 eta D^2),
//!
//! which is regular at u = 0 (u grows linearly from 0). Each step is backward Euler (implicit,
//! unconditionally stable for the stiff squeeze term), solved exactly for s = sqrt(u) >= 0 by a
//! monotone Newton iteration on the increasing convex function g(s) = s^2 + dt B s + dt C s^4 - (u_n + dt A);
//! g(0) <= 0 so a non-negative root always exists: no NaN, no negative film.
//!
//! A film below zero therefore cannot occur, by construction, and no run reports it as an event:
//! the state is s = h >= 0 itself (u = s^2 is never formed from a difference), the Newton iterate
//! is floored at 0 (a guard only: from the left of the root a Newton step on the increasing convex
//! g moves right, from the right it stays right of the root), the start value and the water
//! supply u_n + dt A are non-negative (A is floored at 0, NaN coefficients count as 0), and a
//! non-finite result (only from non-finite input) falls back to 0. The film is solved only by the
//! patch model (`vehsim atiim` and the flash table that `[contact] model = "atiim"` builds once per
//! run); the engine's per-step estimator reads that table and computes no film of its own. The
//! guards are tested below with hostile coefficients; `advance_wet` keeps h >= 0 the same way
//! (a bracketed root on [0, h0 + dt q(0) / (rho L)]).

use super::thermal::{ICE, LATENT_HEAT_J_KG, WATER_VISCOSITY_PA_S};

/// Default asperity contact diameter D of the squeeze-out term, m: 20 µm. Assumption: the real
/// contact spots of rubber on ice are micrometres to tens of micrometres across. D sets the wet
/// regime: with 20 µm the squeeze-out holds the film near the height at which viscous friction
/// takes over (h*), so a wet pixel's friction follows the friction law at 0 degC and falls with
/// sliding speed, as the dissertation's Fig. 2.14 shows; with 0.2 mm (the chapter-4 film
/// scenarios, which reproduce the dissertation's 110-155 nm films) the film thickens into the
/// viscous regime of eq. 4.13, where friction rises as about v^0.5 on ice near melting.
pub const DEFAULT_ASPERITY_D_M: f64 = 2e-5;

/// Film-model parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmParams {
    /// Real-contact ratio kappa = A_real / A_nominal in eq. 4.10–4.13, 0 < kappa <= 1 (0.3–1).
    pub kappa: f64,
    /// Mean asperity contact diameter D in eq. 4.6, m (1e-5 – 1e-3; smaller = stronger squeeze-out;
    /// use a large value, e.g. 1 m, to switch squeeze-out off).
    pub asperity_d_m: f64,
    /// Backward-Euler sub-steps per pixel, 1–256 (8–32 typical).
    pub substeps: usize,
}

/// Coefficients of du/dt = A - B sqrt(u) - C u^2 (see the module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmCoeffs {
    /// m^2/s.
    pub a: f64,
    /// m/s.
    pub b: f64,
    /// 1/(m^2 s).
    pub c: f64,
}

impl FilmCoeffs {
    /// Coefficients for sliding speed `v_mps` (>= 0), conducted flux `q_c_w_m2` (clamped >= 0),
    /// contact pressure `p_pa` (>= 0).
    pub fn new(fp: &FilmParams, v_mps: f64, q_c_w_m2: f64, p_pa: f64) -> Self {
        let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
        let d = fp.asperity_d_m.max(1e-9);
        FilmCoeffs {
            a: 2.0 * fp.kappa * WATER_VISCOSITY_PA_S * v_mps * v_mps / rl,
            b: 2.0 * q_c_w_m2.max(0.0) / rl,
            c: 16.0 * p_pa.max(0.0) / (3.0 * WATER_VISCOSITY_PA_S * d * d),
        }
    }
}

/// Result of advancing the film over one interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmStep {
    /// Film height at the end, m (>= 0).
    pub h_end_m: f64,
    /// Integral of 1/h over the interval, s/m (exact for u linear within each sub-step);
    /// viscous heat = kappa eta v^2 times this.
    pub inv_h_integral: f64,
    /// Water height removed by squeeze-out during the interval, m.
    pub squeezed_m: f64,
}

/// One backward-Euler step from s_n = sqrt(u_n); returns s_{n+1} >= 0.
pub fn implicit_step(s_n: f64, dt: f64, k: &FilmCoeffs) -> f64 {
    let rhs = s_n * s_n + dt * k.a.max(0.0);
    if rhs <= 0.0 {
        return 0.0;
    }
    // g is increasing and convex on s >= 0, so Newton from any start lands right of the root after
    // one step and then decreases monotonically to it. Start from the previous value (close to
    // the root over a small step) unless g' vanishes there.
    let mut s = if s_n > 0.0 && s_n.is_finite() { s_n.min(rhs.sqrt()) } else { rhs.sqrt() };
    for _ in 0..60 {
        let g = s * s + dt * k.b * s + dt * k.c * s.powi(4) - rhs;
        let dg = 2.0 * s + dt * k.b + 4.0 * dt * k.c * s.powi(3);
        if dg <= 0.0 {
            break;
        }
        let next = (s - g / dg).max(0.0);
        if (s - next).abs() <= 1e-12 * s.max(1e-30) {
            s = next;
            break;
        }
        s = next;
    }
    if s.is_finite() {
        s
    } else {
        0.0
    }
}

/// Advance the film from `h0_m` over `dt_s` with `substeps` backward-Euler steps.
pub fn advance(h0_m: f64, dt_s: f64, substeps: usize, k: &FilmCoeffs) -> FilmStep {
    let n = substeps.max(1);
    let dt = dt_s.max(0.0) / n as f64;
    let mut s = if h0_m.is_finite() { h0_m.max(0.0) } else { 0.0 };
    let mut inv = 0.0;
    let mut sq = 0.0;
    for _ in 0..n {
        let s1 = implicit_step(s, dt, k);
        if s + s1 > 0.0 {
            inv += 2.0 * dt / (s + s1);
        }
        // squeeze-out rate dh/dt = -(C/2) h^3 at the end of the step (consistent with backward Euler)
        sq += dt * 0.5 * k.c * s1.powi(3);
        s = s1;
    }
    FilmStep { h_end_m: s, inv_h_integral: inv, squeezed_m: sq }
}

/// Result of advancing a wet pixel's film under the friction law [`crate::tyre::friction::WetFilm`] (energies per unit
/// area over the interval, J/m^2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct WetStep {
    /// Film height at the end, m (>= 0).
    pub h_end_m: f64,
    /// Frictional heat generated, integral of q(h) dt.
    pub friction_j_m2: f64,
    /// Heat conducted away from the 0 degC interface (<= q_c dt: less when the film refreezes
    /// completely within a sub-step).
    pub conducted_j_m2: f64,
    /// Water height removed by squeeze-out, m.
    pub squeezed_m: f64,
    /// Integral of 1/h over the interval, s/m (trapezoid per sub-step; for eq. 4.13 diagnostics).
    pub inv_h_integral: f64,
    /// Integral of the law's viscous floor ([`crate::tyre::friction::WetFilm::viscous_part`]) over the
    /// interval, s (backward-Euler consistent, like the heat).
    pub viscous_mu_integral: f64,
}

/// Advance a wet pixel's film from `h0_m` over `dt_s` in `substeps` backward-Euler steps of
///
///   rho_ice L dh/dt = q(h) + q_extra - q_c - rho_ice L (C/2) h^3,
///
/// where q(h) is the frictional heat of `law` (bounded and decreasing in h), `q_extra_w_m2` other
/// heat released at the interface (rolling hysteresis), `q_c_w_m2` the conducted flux and
/// `c` = 16 p / (3 eta D^2) the squeeze-out coefficient of [`FilmCoeffs`]. Because q is bounded,
/// the film grows linearly from h = 0 (no 1/h singularity) and each implicit step has exactly one
/// root h >= 0 (the residual is strictly increasing in h), found by a bracketed Newton iteration.
/// The energy balance friction + extra = conducted + rho L (h_end - h0 + squeezed) holds to the
/// solver tolerance by construction.
pub(crate) fn advance_wet(
    h0_m: f64,
    dt_s: f64,
    substeps: usize,
    law: &crate::tyre::friction::WetFilm,
    q_extra_w_m2: f64,
    q_c_w_m2: f64,
    c: f64,
) -> WetStep {
    let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
    let n = substeps.max(1);
    let dt = if dt_s.is_finite() { dt_s.max(0.0) / n as f64 } else { 0.0 };
    let qx = if q_extra_w_m2.is_finite() { q_extra_w_m2.max(0.0) } else { 0.0 };
    let qc = if q_c_w_m2.is_finite() { q_c_w_m2.max(0.0) } else { 0.0 };
    let c2 = if c.is_finite() { 0.5 * c.max(0.0) } else { 0.0 };
    let mut h = if h0_m.is_finite() { h0_m.max(0.0) } else { 0.0 };
    let mut out = WetStep::default();
    let (q0, _) = law.heat(0.0);
    for _ in 0..n {
        // residual F(x) = x - h - dt ((q(x) + qx - qc) / rl - c2 x^3), increasing in x
        let f = |x: f64| {
            let (q, dq) = law.heat(x);
            (x - h - dt * ((q + qx - qc) / rl - c2 * x * x * x), 1.0 - dt * (dq / rl - 3.0 * c2 * x * x))
        };
        let (f0, _) = f(0.0);
        let h1;
        if !(f0 < 0.0) {
            // the film refreezes (or never forms) within this sub-step
            h1 = 0.0;
            out.conducted_j_m2 += dt * (q0 + qx) + rl * h;
            out.friction_j_m2 += dt * q0;
        } else {
            let (mut lo, mut hi) = (0.0, h + dt * (q0 + qx) / rl);
            let mut x = h.clamp(lo, hi);
            for _ in 0..80 {
                let (fx, dfx) = f(x);
                if fx > 0.0 {
                    hi = x;
                } else {
                    lo = x;
                }
                let mut next = x - fx / dfx;
                if !(next > lo && next < hi) {
                    next = 0.5 * (lo + hi);
                }
                if (next - x).abs() <= 1e-12 * x.max(1e-15) || hi - lo <= 1e-13 * hi {
                    x = next;
                    break;
                }
                x = next;
            }
            h1 = x;
            out.friction_j_m2 += dt * law.heat(h1).0;
            out.conducted_j_m2 += dt * qc;
            out.squeezed_m += dt * c2 * h1 * h1 * h1;
        }
        if h + h1 > 0.0 {
            out.inv_h_integral += 2.0 * dt / (h + h1);
        }
        out.viscous_mu_integral += dt * law.viscous_part(h1);
        h = h1;
    }
    out.h_end_m = h;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The guards: for extreme coefficients, steps and start heights (far beyond validated input)
    /// every backward-Euler step returns a finite s >= 0 that solves its equation; non-finite or
    /// negative start heights and non-finite coefficients give a finite film >= 0.
    #[test]
    fn film_is_never_negative_and_solves_its_step() {
        let mut n = 0;
        for a in [0.0, 1e-20, 1e-12, 1e-6] {
            for b in [0.0, 1e-6, 1e-2, 1e3] {
                for c in [0.0, 1e6, 1e16, 1e22] {
                    for s_n in [0.0, 1e-9, 1e-6, 1e-3] {
                        for dt in [1e-9, 1e-5, 1e-3] {
                            let k = FilmCoeffs { a, b, c };
                            let s = implicit_step(s_n, dt, &k);
                            assert!(s.is_finite() && s >= 0.0, "{k:?} {s_n} {dt}: {s}");
                            let rhs = s_n * s_n + dt * a;
                            let g = s * s + dt * b * s + dt * c * s.powi(4) - rhs;
                            assert!(g.abs() <= 1e-9 * rhs.max(1e-300), "{k:?} {s_n} {dt}: residual {g} of {rhs}");
                            n += 1;
                        }
                    }
                }
            }
        }
        assert_eq!(n, 768);
        let fp = FilmParams { kappa: 1.0, asperity_d_m: 2e-4, substeps: 8 };
        let hostile = [
            (f64::NAN, FilmCoeffs::new(&fp, 5.0, 1e4, 3e5)),
            (-1e-6, FilmCoeffs::new(&fp, 5.0, 1e4, 3e5)),
            (f64::INFINITY, FilmCoeffs::new(&fp, 5.0, 1e4, 3e5)),
            (1e-7, FilmCoeffs::new(&fp, f64::NAN, f64::NAN, f64::NAN)),
            (1e-7, FilmCoeffs { a: -1.0, b: -1.0, c: -1.0 }),
            (1e-7, FilmCoeffs::new(&fp, f64::INFINITY, 0.0, 0.0)),
        ];
        for (h0, k) in hostile {
            let st = advance(h0, 1e-3, 8, &k);
            assert!(st.h_end_m.is_finite() && st.h_end_m >= 0.0, "{h0} {k:?}: {st:?}");
        }
    }

    /// advance_wet: friction + extra heat = conducted + latent heat of (film growth + squeezed
    /// water) to solver precision, h >= 0, for growing, steady, refreezing and squeezed films.
    #[test]
    fn wet_step_conserves_energy_and_keeps_film_non_negative() {
        use crate::tyre::friction::{beta_from_critical_height, WetFilm};
        let rl = ICE.density_kg_m3 * LATENT_HEAT_J_KG;
        let mut n = 0;
        for &(v, p) in &[(0.5, 1e5), (2.5, 2.5e5), (5.0, 4e5)] {
            let law = WetFilm {
                pv: p * v,
                mu_d: 0.1,
                beta: beta_from_critical_height(50e-9),
                visc_m: WATER_VISCOSITY_PA_S * v / p,
            };
            for &h0 in &[0.0, 1e-8, 3e-7, 2e-6] {
                for &qc in &[0.0, 2e4, 1e5, 1e7] {
                    for &d in &[1e-5, 2e-4, 1.0] {
                        let c = FilmCoeffs::new(&FilmParams { kappa: 1.0, asperity_d_m: d, substeps: 8 }, v, qc, p).c;
                        let dt = 1e-4;
                        let st = advance_wet(h0, dt, 8, &law, 500.0, qc, c);
                        assert!(st.h_end_m.is_finite() && st.h_end_m >= 0.0);
                        let gen = st.friction_j_m2 + 500.0 * dt;
                        let out = st.conducted_j_m2 + rl * (st.h_end_m - h0 + st.squeezed_m);
                        assert!((gen - out).abs() <= 1e-6 * gen, "v {v} h0 {h0} qc {qc} D {d}: {gen} vs {out}");
                        assert!(st.conducted_j_m2 <= qc * dt * (1.0 + 1e-12));
                        n += 1;
                    }
                }
            }
        }
        assert_eq!(n, 144);
    }

    #[test]
    fn no_nan_from_zero_film_and_zero_speed() {
        let fp = FilmParams { kappa: 1.0, asperity_d_m: 1e-5, substeps: 4 };
        for &(v, q, p) in &[(0.0, 0.0, 0.0), (0.0, 1e6, 1e6), (10.0, 0.0, 1e6), (1e-9, 1e9, 0.0)] {
            let k = FilmCoeffs::new(&fp, v, q, p);
            let st = advance(0.0, 1e-3, 4, &k);
            assert!(st.h_end_m.is_finite() && st.h_end_m >= 0.0);
            assert!(st.inv_h_integral.is_finite() && st.squeezed_m.is_finite());
        }
    }
}
