//! ATIIM-modified Magic Formula (dissertation eq. 5.8–5.17): peak and stiffness depend on the
//! contact-temperature rise.
//!
//! Temperatures (all in K differences, degC levels):
//! - T is the contact-patch (tread/ice interface) temperature, `TyreInput::contact_temp_c`.
//! - T_m is the "average tire surface temperature used for the steady state conditions" (text under
//!   eq. 5.11): the temperature at which the base coefficients D0, K0 were fitted. The dissertation
//!   fitted them to steady rig runs whose interface sits at the ice temperature, so vehsim takes
//!   T_m = `TyreInput::surface_temp_c` (bulk ice temperature).
//! - Delta-T = T - T_m = `TyreInput::delta_t_k()`, the contact-temperature rise above the ice. The
//!   base coefficients below belong to Delta-T = 0 (no frictional heating).
//!
//! For each axis (x: slip ratio kappa; y: slip angle alpha in rad):
//!
//! ```text
//! k_shift  = a Delta-T^2 + b                                   (eq. 5.14–5.17, or user a, b)
//! D(T)     = D0 max(1 + dmu/dT k_shift Delta-T, f_min)          (eq. 5.12; 5.9 with k_shift = 1)
//! K(T)     = K0 max(1 + dC/dT  k_shift Delta-T, f_min)          (eq. 5.13; 5.10 with k_shift = 1)
//! B(T)     = K(T) / (C D(T))                                    (eq. 5.11)
//! F0(s)    = D(T) sin(C atan(B s - E (B s - atan(B s))))         (eq. 5.8, S_V = 0)
//! D0       = mu_0 (mu_surface / mu_reference) Fz,   K0 = (K0/Fz) Fz
//! ```
//!
//! k_shift families (a in 1/K^2, b dimensionless): srtt 25/3, 5/3 (eq. 5.14); all_season 7/3, 1/3
//! (5.15); directional 64/5, 1/8 (5.16); average 352/45, 17/24 (5.17, mislabelled k^3 in the
//! dissertation, erratum 7: (25/3 + 7/3 + 64/5)/3 = 352/45 and (5/3 + 1/3 + 1/8)/3 = 17/24);
//! none: a = 0, b = 1 (eq. 5.9–5.10 as used for Fig. 5.2/5.3).
//!
//! The floor f_min is a vehsim guard, not in the dissertation: the published factor is linear in
//! k_shift Delta-T, which grows as Delta-T^3 and would make the peak force negative for large
//! rises; f_min (default 0.1) keeps the friction and stiffness positive and the force continuous.
//!
//! Combined slip: the normalised-slip friction ellipse of [`super::combine`] with reference slips
//! D/K per axis, so (Fx/Dx)^2 + (Fy/Dy)^2 <= 1 and |F| <= max(Dx, Dy).

use super::combine::{equivalent, mf_sin, normalised, sgn};
use super::{TyreForces, TyreInput, TyreModel};

/// The shift factor k_shift(Delta-T) = a Delta-T^2 + b.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KShift {
    /// k = 1 (eq. 5.9–5.10, no shift factor).
    None,
    /// SRTT fit, eq. 5.14: 25/3 dT^2 + 5/3.
    Srtt,
    /// 19" all-season tyre, eq. 5.15: 7/3 dT^2 + 1/3.
    AllSeason,
    /// 16" directional tyre, eq. 5.16: 64/5 dT^2 + 1/8.
    Directional,
    /// Average of the three, eq. 5.17: 352/45 dT^2 + 17/24.
    Average,
    /// User quadratic a dT^2 + b (a in 1/K^2).
    Quadratic { a: f64, b: f64 },
}

impl KShift {
    /// (a, b) of a dT^2 + b.
    pub fn coefficients(self) -> (f64, f64) {
        match self {
            KShift::None => (0.0, 1.0),
            KShift::Srtt => (25.0 / 3.0, 5.0 / 3.0),
            KShift::AllSeason => (7.0 / 3.0, 1.0 / 3.0),
            KShift::Directional => (64.0 / 5.0, 1.0 / 8.0),
            KShift::Average => (352.0 / 45.0, 17.0 / 24.0),
            KShift::Quadratic { a, b } => (a, b),
        }
    }

    /// k_shift at rise `dt_k`, dimensionless.
    pub fn value(self, dt_k: f64) -> f64 {
        let (a, b) = self.coefficients();
        a * dt_k * dt_k + b
    }
}

/// Coefficients of one axis, at Delta-T = 0 on a surface of friction `mu_reference`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AtiimAxis {
    /// Shape factor C, dimensionless (1 < C < 2; longitudinal ~1.4–1.7, lateral ~1.2–1.4).
    pub c: f64,
    /// Curvature factor E, dimensionless (<= 1; -1–0.9 typical).
    pub e: f64,
    /// Peak friction coefficient mu_0 = D0/Fz at mu_reference, dimensionless (ice 0.1–0.25).
    pub mu: f64,
    /// Slip stiffness per load K0/Fz: per unit slip (x) or per rad (y); ice 3–10 (x), 2–8 (y).
    pub k_per_fz: f64,
    /// dmu/dT: relative change of the peak per K of k_shift-weighted rise, 1/K (typically < 0).
    pub dmu_dt_per_k: f64,
    /// dC_p/dT: relative change of the stiffness per K of k_shift-weighted rise, 1/K (typically > 0).
    pub dc_dt_per_k: f64,
}

/// The ATIIM-modified Magic Formula tyre, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct AtiimPacejkaTyre {
    /// Longitudinal axis (Fx vs kappa).
    pub x: AtiimAxis,
    /// Lateral axis (Fy vs alpha, rad).
    pub y: AtiimAxis,
    /// Friction of the surface the coefficients belong to (e.g. 0.15 for the dissertation's ice);
    /// D0 scales with mu_surface / mu_reference.
    pub mu_reference: f64,
    /// Shift-factor family.
    pub k_shift: KShift,
    /// Floor of the temperature factors, dimensionless in (0, 1] (default 0.1).
    pub min_factor: f64,
}

/// D and K of one axis at one input.
#[derive(Debug, Clone, Copy)]
struct AxisNow {
    b: f64,
    c: f64,
    d: f64,
    e: f64,
    k: f64,
}

impl AtiimPacejkaTyre {
    /// Temperature factors (f_D, f_K) of `axis` at rise `dt_k`.
    pub fn factors(&self, axis: &AtiimAxis, dt_k: f64) -> (f64, f64) {
        self.factors_at(axis, self.weighted_rise(dt_k))
    }

    /// The k_shift-weighted rise k_shift(Delta-T) Delta-T (0 for a non-finite rise); the same for
    /// both axes, so [`TyreModel::forces`] computes it once.
    #[inline]
    fn weighted_rise(&self, dt_k: f64) -> f64 {
        if dt_k.is_finite() {
            self.k_shift.value(dt_k) * dt_k
        } else {
            0.0
        }
    }

    /// Temperature factors (f_D, f_K) of `axis` at weighted rise `w`.
    #[inline]
    fn factors_at(&self, axis: &AtiimAxis, w: f64) -> (f64, f64) {
        let fd = (1.0 + axis.dmu_dt_per_k * w).max(self.min_factor);
        let fk = (1.0 + axis.dc_dt_per_k * w).max(self.min_factor);
        (if fd.is_finite() { fd } else { self.min_factor }, if fk.is_finite() { fk } else { self.min_factor })
    }

    fn axis_now(&self, axis: &AtiimAxis, fz: f64, ratio: f64, w: f64) -> AxisNow {
        let (fd, fk) = self.factors_at(axis, w);
        let d = axis.mu * ratio * fz * fd;
        let k = axis.k_per_fz * fz * fk;
        AxisNow { b: k / (axis.c * d), c: axis.c, d, e: axis.e, k }
    }

    fn active(i: &TyreInput) -> Option<f64> {
        if i.fz_n > 0.0 && i.fz_n.is_finite() && i.mu_surface > 0.0 && i.mu_surface.is_finite() {
            Some(i.mu_surface)
        } else {
            None
        }
    }
}

impl TyreModel for AtiimPacejkaTyre {
    fn name(&self) -> &'static str {
        "atiim_pacejka"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        let Some(mu) = Self::active(i) else { return TyreForces::default() };
        let ratio = mu / self.mu_reference;
        let w = self.weighted_rise(i.delta_t_k());
        let x = self.axis_now(&self.x, i.fz_n, ratio, w);
        let y = self.axis_now(&self.y, i.fz_n, ratio, w);
        let kref = x.d / x.k;
        let aref = y.d / y.k;
        let (s, wx, wy) = normalised(i.kappa / kref, i.alpha_rad / aref);
        let fx = wx * mf_sin(x.b, x.c, x.d, x.e, equivalent(sgn(i.kappa), s, kref));
        let fy = wy * mf_sin(y.b, y.c, y.d, y.e, equivalent(sgn(i.alpha_rad), s, aref));
        TyreForces { fx_n: fx, fy_n: fy, mz_nm: 0.0 }
    }

    /// max(Dx(T), Dy(T)) / Fz: the friction ellipse's larger semi-axis.
    fn peak_friction(&self, i: &TyreInput) -> f64 {
        let Some(mu) = Self::active(i) else { return 0.0 };
        let ratio = mu / self.mu_reference;
        let dt = i.delta_t_k();
        let (fdx, _) = self.factors(&self.x, dt);
        let (fdy, _) = self.factors(&self.y, dt);
        ratio * (self.x.mu * fdx).max(self.y.mu * fdy)
    }

    /// K_x(T) = K0 f_K (eq. 5.13).
    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        let Some(_) = Self::active(i) else { return 0.0 };
        self.x.k_per_fz * i.fz_n * self.factors(&self.x, i.delta_t_k()).1
    }

    /// K_y(T) = K0 f_K (eq. 5.13 applied to the lateral axis), N/rad.
    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        let Some(_) = Self::active(i) else { return 0.0 };
        self.y.k_per_fz * i.fz_n * self.factors(&self.y, i.delta_t_k()).1
    }
}
