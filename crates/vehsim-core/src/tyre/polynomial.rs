//! Third-order polynomial (brush / Fiala-type) tyre with theoretical-slip combination.
//!
//! Theoretical slip (Pacejka, Tyre and Vehicle Dynamics, ch. 3, brush model):
//! sigma_x = kappa / (1 + kappa), sigma_y = tan(alpha) / (1 + kappa). The "linear force"
//! psi = sqrt((C_x sigma_x)^2 + (C_y sigma_y)^2) is what a tyre without friction limit would give.
//! With the friction limit F_max = mu Fz and u = psi / F_max, the force magnitude is
//!
//! ```text
//! F = F_max g(u),   g(u) = P(P_s u) / P_s   for P_s u < u_s,   g = 1 beyond,
//! P(v) = v + a2 v^2 + a3 v^3,   u_s = first positive root of P'(v) = 1 + 2 a2 v + 3 a3 v^2,
//! P_s = P(u_s)
//! ```
//!
//! and it acts along (C_x sigma_x, C_y sigma_y). g(0) = 0, g'(0) = 1 (so the slopes at zero slip are
//! C_x and C_y), g reaches 1 with zero slope at the sliding point (C1 saturation at mu Fz).
//! The brush form is a2 = -1/3, a3 = 1/27: P(v) = v - v^2/3 + v^3/27 = 1 - (1 - v/3)^3, u_s = 3,
//! P_s = 1, which is the Fiala / isotropic brush model with
//! parabolic pressure: F = psi - psi^2/(3 F_max) + psi^3/(27 F_max^2) up to psi = 3 F_max.
//! The general form takes user coefficients a2, a3 (validated to have a saturation point).
//!
//! |F| <= mu Fz everywhere (a friction circle). The model is odd in alpha but not in kappa (the
//! theoretical slip is asymmetric: braking to lock saturates at kappa = -1). The division by
//! 1 + kappa is never formed: u is compared as psi' = sqrt((C_x kappa)^2 + (C_y tan alpha)^2) against
//! (1 + kappa) F_max, so a locked wheel (kappa = -1) is simply fully sliding.

use super::combine::{positive, powf_memo};
use super::{TyreForces, TyreInput, TyreModel};

/// Shape of the normalised polynomial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolyShape {
    /// Quadratic coefficient a2 (brush: -1/3).
    pub a2: f64,
    /// Cubic coefficient a3 (brush: 1/27).
    pub a3: f64,
    /// First positive root of P' (brush: 3).
    pub u_s: f64,
    /// P(u_s) (brush: 1).
    pub p_s: f64,
}

impl PolyShape {
    /// The brush (Fiala) shape.
    pub fn brush() -> Self {
        Self { a2: -1.0 / 3.0, a3: 1.0 / 27.0, u_s: 3.0, p_s: 1.0 }
    }

    /// A general shape; `Err` describes why (a2, a3) has no saturation point.
    pub fn general(a2: f64, a3: f64) -> Result<Self, String> {
        if !(a2.is_finite() && a3.is_finite()) {
            return Err("a2 and a3 must be finite".into());
        }
        // Smallest positive root of 1 + 2 a2 v + 3 a3 v^2.
        let u_s = if a3 == 0.0 {
            if a2 < 0.0 {
                -1.0 / (2.0 * a2)
            } else {
                f64::NAN
            }
        } else {
            let disc = 4.0 * a2 * a2 - 12.0 * a3;
            if disc < 0.0 {
                f64::NAN
            } else {
                let sq = disc.sqrt();
                let r1 = (-2.0 * a2 - sq) / (6.0 * a3);
                let r2 = (-2.0 * a2 + sq) / (6.0 * a3);
                [r1, r2].into_iter().filter(|r| *r > 0.0).fold(f64::NAN, |m, r| if m.is_nan() { r } else { m.min(r) })
            }
        };
        if !(u_s.is_finite() && u_s > 0.0) {
            return Err(format!(
                "P(v) = v + a2 v^2 + a3 v^3 with a2 = {a2}, a3 = {a3} never levels off (P' has no positive root); \
                 the brush form is a2 = -1/3, a3 = 1/27"
            ));
        }
        let p_s = u_s + a2 * u_s * u_s + a3 * u_s * u_s * u_s;
        Ok(Self { a2, a3, u_s, p_s })
    }

    /// g(u) = P(P_s u)/P_s below saturation, 1 above (u >= 0).
    #[inline]
    fn g(&self, u: f64) -> f64 {
        let v = self.p_s * u;
        if v >= self.u_s {
            1.0
        } else {
            (v + self.a2 * v * v + self.a3 * v * v * v) / self.p_s
        }
    }
}

/// Polynomial (brush) tyre parameters, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct PolynomialTyre {
    /// Longitudinal slip stiffness C_x at the nominal load, N per unit slip (dry 50e3–150e3;
    /// on ice about 5–8 Fz so that the peak falls at 5–10 % slip).
    pub longitudinal_stiffness_n: f64,
    /// Cornering stiffness C_y at the nominal load, N/rad (dry 40e3–100e3; ice 10e3–40e3).
    pub cornering_stiffness_n_per_rad: f64,
    /// Nominal load, N.
    pub nominal_load_n: f64,
    /// Load exponent p: C(Fz) = C_nominal (Fz/Fz_nominal)^p, in (0, 1].
    pub load_exponent: f64,
    /// Tyre peak friction relative to the surface's mu, dimensionless (0.5–1.5, 1 = surface mu).
    pub mu_scale: f64,
    /// Normalised polynomial shape.
    pub shape: PolyShape,
}

impl PolynomialTyre {
    fn load_factor(&self, fz: f64) -> f64 {
        let r = fz / self.nominal_load_n;
        if r > 0.0 {
            powf_memo(r, self.load_exponent)
        } else {
            0.0
        }
    }
}

impl TyreModel for PolynomialTyre {
    fn name(&self) -> &'static str {
        "polynomial"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        let fz = i.fz_n;
        let mu = self.mu_scale * i.mu_surface;
        if !(fz > 0.0 && fz.is_finite() && mu > 0.0) {
            return TyreForces::default();
        }
        let lf = self.load_factor(fz);
        let qx = self.longitudinal_stiffness_n * lf * i.kappa;
        let qy = self.cornering_stiffness_n_per_rad * lf * i.alpha_rad.tan();
        let q = (qx * qx + qy * qy).sqrt(); // |q| <~ 1e21 for alpha up to pi/2: no overflow
        if !positive(q) {
            return TyreForces::default();
        }
        let fmax = mu * fz;
        let d = (1.0 + i.kappa).max(0.0) * fmax;
        // u = psi / F_max = q / d; saturated when P_s u >= u_s.
        let mag = if self.shape.p_s * q >= self.shape.u_s * d { fmax } else { fmax * self.shape.g(q / d) };
        let s = mag / q;
        TyreForces { fx_n: qx * s, fy_n: qy * s, mz_nm: 0.0 }
    }

    fn peak_friction(&self, i: &TyreInput) -> f64 {
        (self.mu_scale * i.mu_surface).max(0.0)
    }

    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        if !positive(self.mu_scale * i.mu_surface) {
            return 0.0;
        }
        self.longitudinal_stiffness_n * self.load_factor(i.fz_n)
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        if !positive(self.mu_scale * i.mu_surface) {
            return 0.0;
        }
        self.cornering_stiffness_n_per_rad * self.load_factor(i.fz_n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn general_shape_with_brush_coefficients_is_the_brush_shape() {
        let g = PolyShape::general(-1.0 / 3.0, 1.0 / 27.0).unwrap();
        assert!((g.u_s - 3.0).abs() < 1e-6, "{g:?}");
        assert!((g.p_s - 1.0).abs() < 1e-9);
        assert!(PolyShape::general(0.5, 0.0).is_err());
        // a2 = -1/2, a3 = 0: P = v - v^2/2, u_s = 1, P_s = 1/2.
        let q = PolyShape::general(-0.5, 0.0).unwrap();
        assert!((q.u_s - 1.0).abs() < 1e-12 && (q.p_s - 0.5).abs() < 1e-12);
    }
}
