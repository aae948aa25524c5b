//! Linear tyre: force proportional to slip, stiffness proportional to load.
//!
//! Fx = C_kappa(Fz) kappa, Fy = C_alpha(Fz) alpha with C(Fz) = C_nominal (Fz / Fz_nominal)^p, so the
//! force is zero at zero load. p = 1 makes the stiffness proportional to load (a bicycle model on
//! such tyres is exactly neutral-steer); real tyres are degressive (p < 1, typically 0.7–0.9 near the
//! nominal load), which is what makes a front-heavy car understeer. As in the dissertation's linear model (section 6.1) there is no saturation by
//! default; with `saturate = true` the combined force is scaled back onto the friction circle
//! |F| <= mu Fz (a friction ellipse with equal semi-axes).

use super::combine::powf_memo;
use super::{TyreForces, TyreInput, TyreModel};

/// Parameters of the linear tyre, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearTyre {
    /// Cornering stiffness at the nominal load, N/rad (passenger tyres 40e3–100e3 on dry road).
    pub cornering_stiffness_n_per_rad: f64,
    /// Longitudinal slip stiffness at the nominal load, N per unit slip (passenger tyres 50e3–150e3).
    pub longitudinal_stiffness_n: f64,
    /// Nominal load, N, at which the stiffnesses are given.
    pub nominal_load_n: f64,
    /// Load exponent p of the stiffness, dimensionless, in (0, 1] (1 = proportional to load).
    pub load_exponent: f64,
    /// Scale the force back to mu Fz when it exceeds it.
    pub saturate: bool,
}

impl LinearTyre {
    /// Stiffness scale factor (Fz / Fz_nominal)^p at load `fz_n`.
    fn load_factor(&self, fz_n: f64) -> f64 {
        let r = fz_n.max(0.0) / self.nominal_load_n;
        if r <= 0.0 {
            0.0
        } else if self.load_exponent == 1.0 {
            r
        } else {
            powf_memo(r, self.load_exponent)
        }
    }
}

impl TyreModel for LinearTyre {
    fn name(&self) -> &'static str {
        "linear"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        let fz = i.fz_n.max(0.0);
        let load = self.load_factor(fz);
        let mut fx = self.longitudinal_stiffness_n * load * i.kappa;
        let mut fy = self.cornering_stiffness_n_per_rad * load * i.alpha_rad;
        if self.saturate {
            let cap = i.mu_surface * fz;
            let mag = fx.hypot(fy);
            if mag > cap && mag > 0.0 {
                let s = cap / mag;
                fx *= s;
                fy *= s;
            }
        }
        TyreForces { fx_n: fx, fy_n: fy, mz_nm: 0.0 }
    }

    fn peak_friction(&self, i: &TyreInput) -> f64 {
        if self.saturate {
            i.mu_surface
        } else {
            f64::INFINITY
        }
    }

    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        self.longitudinal_stiffness_n * self.load_factor(i.fz_n)
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        self.cornering_stiffness_n_per_rad * self.load_factor(i.fz_n)
    }
}
