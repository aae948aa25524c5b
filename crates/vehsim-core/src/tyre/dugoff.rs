//! Dugoff tyre (dissertation eq. 5.2–5.4, lateral term corrected) and its thermal variant (eq. 5.5–5.6).
//!
//! Slip mapping. The dissertation's slip ratio lambda (eq. 5.1) is 1 - R Omega / u, positive when
//! braking; vehsim's kappa = (omega R_e - V_x)/|V_x| is positive when driving, so lambda = -kappa and
//! 1 - lambda = 1 + kappa. In vehsim's signs (force positive forward):
//!
//! ```text
//! Fx = C_k kappa / (1 + kappa) f(z),      Fy = C_a tan(alpha) / (1 + kappa) f(z)
//! z  = mu Fz (1 + kappa) / (2 sqrt((C_k kappa)^2 + (C_a tan alpha)^2))
//! f(z) = z (2 - z) for z < 1, 1 otherwise
//! ```
//!
//! Eq. 5.3 as printed uses C_lambda in the lateral force, a misprint: the lateral term is C_alpha tan(alpha).
//! For z < 1 the product f(z)/(1 + kappa) is evaluated as mu Fz (2 - z) / (2 q) with
//! q = sqrt((C_k kappa)^2 + (C_a tan alpha)^2), which stays finite at a locked wheel (kappa = -1);
//! |F| = mu Fz (1 - z/2) <= mu Fz there and |F| = mu Fz / (2 z) <= mu Fz / 2 for z >= 1: the combined
//! force is bounded by the friction circle mu Fz.
//!
//! Thermal variant (eq. 5.5–5.6): Fx is multiplied by
//! `H = (dT - 0.75 mu_max) S^2 - (dT - 0.75 mu_max) S + 1.27` with dT = `TyreInput::delta_t_k()`
//! in K, mu_max the tyre's peak friction coefficient and S the slip ratio as the dissertation's
//! rig measured it: S = kappa / (1 + kappa) (eq. 3.2, driving slip over omega R, in [0, 1)) for
//! kappa >= 0 and S = -kappa (eq. 2.11, braking slip over V, clamped to [0, 1]) for kappa < 0.
//! Properties of H as published, and what vehsim does with them:
//! - H(S = 0) = H(S = 1) = 1.27 for every dT, and for dT < 0.75 mu H exceeds 1.27 at mid slip: a
//!   "temperature factor" that amplifies the Dugoff force at no heating.
//! - H is a parabola in S with its extremum 1.27 - (dT - 0.75 mu)/4 at S = 0.5. For dT > 0.75 mu
//!   (any heating on ice) H dips towards S = 0.5; for dT > 5.08 + 0.75 mu it turns negative there:
//!   the longitudinal force would reverse (a driven wheel would be pushed backwards and spin up).
//!
//! vehsim applies H_used = clamp(H, 0, 1). Reason: H stands for the loss of friction as the contact
//! heats; a friction-reducing factor is at most 1 (heating never adds friction to the Dugoff curve
//! fitted at no heating, and the plain Dugoff force is already bounded by mu Fz) and at least 0
//! (friction opposes the slip; it cannot turn into a driving force in the slip direction). So the
//! longitudinal stiffness is C_k min(1, 1.27) = C_k and |F| <= mu Fz. An input at which the
//! published H is negative is a departure ([`TyreModel::departure`]): the run reports it once as
//! the event `thermal_factor_clamped`, at the first step where a tyre's state shows it.

use super::combine::{positive, powf_memo};
use super::{TyreForces, TyreInput, TyreModel};
use crate::event::EventKind;

/// Dugoff parameters, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct DugoffTyre {
    /// Longitudinal slip stiffness C_k at the nominal load, N per unit slip (dry 50e3–150e3; on ice
    /// fitted to the linear range, 15e3–40e3 at 4 kN).
    pub longitudinal_stiffness_n: f64,
    /// Cornering stiffness C_a at the nominal load, N/rad (dry 40e3–100e3; ice 10e3–40e3).
    pub cornering_stiffness_n_per_rad: f64,
    /// Nominal load, N.
    pub nominal_load_n: f64,
    /// Load exponent p: C(Fz) = C_nominal (Fz/Fz_nominal)^p, in (0, 1].
    pub load_exponent: f64,
    /// Tyre peak friction relative to the surface's mu, dimensionless (0.5–1.5; 1 = surface mu).
    pub mu_scale: f64,
}

/// Coefficients of the dissertation's temperature factor H (eq. 5.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalFactor {
    /// Constant term, dimensionless (published: 1.27).
    pub offset: f64,
    /// Weight of mu_max against dT, K per unit friction (published: 0.75).
    pub mu_coefficient: f64,
}

impl Default for ThermalFactor {
    fn default() -> Self {
        Self { offset: 1.27, mu_coefficient: 0.75 }
    }
}

impl ThermalFactor {
    /// H at slip ratio `kappa` (vehsim convention), temperature rise `dt_k` and peak friction `mu`.
    pub fn h(&self, kappa: f64, dt_k: f64, mu: f64) -> f64 {
        let s = if kappa >= 0.0 { kappa / (1.0 + kappa) } else { (-kappa).min(1.0) };
        let s = if s.is_finite() { s } else { 0.0 };
        let a = dt_k - self.mu_coefficient * mu;
        a * s * s - a * s + self.offset
    }
}

impl DugoffTyre {
    fn load_factor(&self, fz: f64) -> f64 {
        let r = fz / self.nominal_load_n;
        if r > 0.0 {
            powf_memo(r, self.load_exponent)
        } else {
            0.0
        }
    }

    fn mu(&self, i: &TyreInput) -> f64 {
        self.mu_scale * i.mu_surface
    }

    /// Plain Dugoff forces (Fx, Fy).
    pub fn dugoff(&self, i: &TyreInput) -> (f64, f64) {
        let fz = i.fz_n;
        let mu = self.mu(i);
        if !(fz > 0.0 && fz.is_finite() && mu > 0.0) {
            return (0.0, 0.0);
        }
        let lf = self.load_factor(fz);
        let qx = self.longitudinal_stiffness_n * lf * i.kappa;
        let qy = self.cornering_stiffness_n_per_rad * lf * i.alpha_rad.tan();
        let q = (qx * qx + qy * qy).sqrt(); // |q| <~ 1e21 for alpha up to pi/2: no overflow
        if !positive(q) {
            return (0.0, 0.0);
        }
        let om = (1.0 + i.kappa).max(0.0);
        let z = mu * fz * om / (2.0 * q);
        let factor = if z < 1.0 { mu * fz * (2.0 - z) / (2.0 * q) } else { 1.0 / om };
        (qx * factor, qy * factor)
    }
}

impl TyreModel for DugoffTyre {
    fn name(&self) -> &'static str {
        "dugoff"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        let (fx, fy) = self.dugoff(i);
        TyreForces { fx_n: fx, fy_n: fy, mz_nm: 0.0 }
    }

    fn peak_friction(&self, i: &TyreInput) -> f64 {
        self.mu(i).max(0.0)
    }

    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        if !positive(self.mu(i)) {
            return 0.0;
        }
        self.longitudinal_stiffness_n * self.load_factor(i.fz_n)
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        if !positive(self.mu(i)) {
            return 0.0;
        }
        self.cornering_stiffness_n_per_rad * self.load_factor(i.fz_n)
    }
}

/// Dugoff with the dissertation's temperature factor H on Fx (eq. 5.5–5.6), H clamped to [0, 1];
/// see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct DugoffThermalTyre {
    /// The underlying Dugoff tyre.
    pub base: DugoffTyre,
    /// The factor H.
    pub h: ThermalFactor,
}

impl DugoffThermalTyre {
    /// A thermal Dugoff tyre.
    pub fn new(base: DugoffTyre, h: ThermalFactor) -> Self {
        Self { base, h }
    }

    /// H as applied, clamp(H, 0, 1) (a NaN H gives 0), with the published value.
    fn h_used(&self, i: &TyreInput) -> (f64, f64) {
        let h = self.h.h(i.kappa, i.delta_t_k(), self.base.mu(i));
        (if h > 0.0 { h.min(1.0) } else { 0.0 }, h)
    }
}

impl TyreModel for DugoffThermalTyre {
    fn name(&self) -> &'static str {
        "dugoff_thermal"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        let (fx, fy) = self.base.dugoff(i);
        if fx == 0.0 {
            return TyreForces { fx_n: 0.0, fy_n: fy, mz_nm: 0.0 };
        }
        let (h, _) = self.h_used(i);
        TyreForces { fx_n: fx * h, fy_n: fy, mz_nm: 0.0 }
    }

    /// mu: H_used <= 1 keeps |F| within the Dugoff friction circle.
    fn peak_friction(&self, i: &TyreInput) -> f64 {
        self.base.mu(i).max(0.0)
    }

    /// H_used(S = 0) C_k = min(1, offset) C_k.
    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        self.base.longitudinal_stiffness(i) * self.h.offset.clamp(0.0, 1.0)
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        self.base.cornering_stiffness(i)
    }

    fn reports_departures(&self) -> bool {
        true
    }

    /// `thermal_factor_clamped` where the published H is negative and there is an Fx to reverse.
    fn departure(&self, i: &TyreInput) -> Option<(EventKind, String)> {
        let (_, h) = self.h_used(i);
        let reverses = h < 0.0; // false for a NaN H
        if !reverses || self.base.dugoff(i).0 == 0.0 {
            return None;
        }
        let (dt, kappa) = (i.delta_t_k(), i.kappa);
        Some((
            EventKind::ThermalFactorClamped,
            format!(
                "dugoff_thermal: the published H ({h:.3e}) would reverse Fx (Delta-T {dt:.2} K, kappa {kappa:.3}); H is clamped to [0, 1]"
            ),
        ))
    }
}
