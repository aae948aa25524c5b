//! ATIIM-modified Magic Formula: the base Magic Formula of [`super::pacejka`] with its peak
//! friction and slip stiffness scaled by a bounded law of how near the contact comes to melting.
//!
//! The base curve is the tyre file's `[pacejka]` section (a `.tir` file or inline coefficients,
//! pure and combined slip, aligning moment): with no frictional heating this provider IS that
//! Magic Formula, bit for bit. The temperature law only multiplies the peak friction scales
//! (LMUX', LMUY') and the slip-stiffness scales (LKX', LKY') of the base by factors f_D, f_K.
//!
//! Temperatures (degC levels, K differences):
//! - T_c contact (tread/ice interface) temperature, `TyreInput::contact_temp_c`;
//! - T_i bulk ice temperature, `TyreInput::surface_temp_c`;
//! - Delta-T = T_c - T_i >= 0, the rise; the melting point 0 degC caps T_c, so the largest
//!   reachable rise is the melting margin M = -T_i (taken >= `MIN_MARGIN_K`).
//!
//! ```text
//! w(dT)  = k_shift(dT) dT = (a dT^2 + b) dT                (the dissertation's eq. 5.14–5.17 shape)
//! p      = w(clamp(Delta-T, 0, M)) / w(M)                  in [0, 1]: 0 no heating, 1 at melting
//! f_D    = 1 - (1 - D_melt) p                              in [D_melt, 1]
//! f_K    = 1 - (1 - K_melt) p                              in [K_melt, 1]
//! ```
//!
//! per axis (x: longitudinal, y: lateral), with D_melt, K_melt the factors at melting, both in
//! [floor, 1]. Properties: bounded (never below the floor), continuous and saturating (p stops at
//! 1 when the contact reaches melting), equal to the base at Delta-T = 0 on any ice, and for the
//! same rise colder ice gives a smaller p (w is increasing, M larger), so colder ice never gives
//! a lower peak. The spec's mu (the surface friction `mu_surface` and the base curve's peak) is
//! the friction with the contact at the ice temperature, no frictional heating. On an ice surface
//! with the friction law on (the default), `super::ice::IceSurfaceTyre` applies this law on top
//! of the rubber-ice friction law taken at the contact temperature.
//!
//! k_shift families (a in 1/K^2, b dimensionless): srtt 25/3, 5/3 (eq. 5.14); all_season 7/3, 1/3
//! (5.15); directional 64/5, 1/8 (5.16); average 352/45, 17/24 (5.17, printed as a cube in the
//! dissertation; its value is the mean of the three: (25/3 + 7/3 + 64/5)/3 = 352/45 and
//! (5/3 + 1/3 + 1/8)/3 = 17/24); none: a = 0, b = 1 (linear in the rise). Derivation, calibration
//! and what the dissertation leaves out: docs/tyres.md.

use super::pacejka::{PacejkaTyre, Scale, TyreSide};
use super::{TyreForces, TyreInput, TyreModel};

/// Smallest melting margin used in the law, K: ice at -0.1 degC or warmer (and a non-ice surface)
/// reaches the full effect at a 0.1 K rise; keeps the law finite and continuous at 0 degC.
pub(crate) const MIN_MARGIN_K: f64 = 0.1;

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
    /// User quadratic a dT^2 + b (a in 1/K^2, a >= 0, b >= 0, a + b > 0).
    Quadratic {
        /// Coefficient of dT^2, 1/K^2 (>= 0).
        a: f64,
        /// Constant term, dimensionless (>= 0).
        b: f64,
    },
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

    /// The weighted rise w = k_shift(dT) dT, K (increasing in dT >= 0).
    pub fn weighted(self, dt_k: f64) -> f64 {
        self.value(dt_k) * dt_k
    }
}

/// Factors at melting of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisLaw {
    /// f_D at melting: peak friction with the contact at 0 degC over that at the ice temperature,
    /// in [floor, 1].
    pub peak_at_melt: f64,
    /// f_K at melting: slip stiffness factor, in [floor, 1].
    pub stiffness_at_melt: f64,
}

/// The bounded temperature law (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeltLaw {
    /// Shape of the approach to melting.
    pub k_shift: KShift,
    /// Longitudinal factors at melting.
    pub x: AxisLaw,
    /// Lateral factors at melting.
    pub y: AxisLaw,
    /// Floor of every factor, in (0, 1].
    pub floor: f64,
}

impl MeltLaw {
    /// Melt proximity p in [0, 1] for ice at `surface_c` and contact at `contact_c` (degC);
    /// 0 for a non-finite input.
    pub fn proximity(&self, surface_c: f64, contact_c: f64) -> f64 {
        let margin = (-surface_c).max(MIN_MARGIN_K);
        let dt = contact_c - surface_c;
        if !(dt > 0.0 && margin.is_finite()) {
            return 0.0; // no heating, a NaN rise or a NaN/infinite ice temperature
        }
        let p = self.k_shift.weighted(dt.min(margin)) / self.k_shift.weighted(margin);
        if p.is_finite() {
            p.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// The base-curve multipliers at proximity `p`.
    pub fn scale(&self, p: f64) -> Scale {
        // exact at both ends: 1 at p = 0, melt at p = 1
        let f = |melt: f64| (melt * p + (1.0 - p)).max(self.floor);
        Scale {
            mu_x: f(self.x.peak_at_melt),
            k_x: f(self.x.stiffness_at_melt),
            mu_y: f(self.y.peak_at_melt),
            k_y: f(self.y.stiffness_at_melt),
        }
    }

    /// The multipliers for one input. (Inlined into the tyre evaluation: outlined, the call and
    /// the multipliers' return through memory cost about as much as the law.)
    #[inline(always)]
    pub fn scale_for(&self, i: &TyreInput) -> Scale {
        let p = self.proximity(i.surface_temp_c, i.contact_temp_c);
        if p == 0.0 {
            Scale::ONE
        } else {
            self.scale(p)
        }
    }
}

/// The ATIIM-modified Magic Formula tyre: a base Magic Formula and the temperature law.
#[derive(Debug, Clone, PartialEq)]
pub struct AtiimPacejkaTyre {
    /// The base curve (the tyre file's `[pacejka]` section).
    pub base: PacejkaTyre,
    /// The temperature law applied on top.
    pub law: MeltLaw,
}

impl AtiimPacejkaTyre {
    /// The same tyre mounted on `side`: the base curve mounted there ([`PacejkaTyre::mounted_on`]),
    /// the same temperature law (it acts on the peak and stiffness scales, which are even in y).
    pub fn mounted_on(&self, side: TyreSide) -> Self {
        Self { base: self.base.mounted_on(side), law: self.law }
    }
}

impl TyreModel for AtiimPacejkaTyre {
    fn name(&self) -> &'static str {
        "atiim_pacejka"
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        self.base.forces_scaled(i, &self.law.scale_for(i))
    }

    fn on_ice(&self, law: &super::ice::SurfaceFriction) -> Option<std::sync::Arc<dyn TyreModel>> {
        Some(std::sync::Arc::new(super::ice::IceSurfaceTyre::atiim(self.clone(), law.clone())))
    }

    /// The base curve's coefficients without the modifier (it depends on the contact
    /// temperature, applied per input by [`Self::forces_prepared`]).
    fn prepare(&self, i: &TyreInput) -> super::Prepared {
        self.base.prepare_scaled(i)
    }

    fn forces_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> TyreForces {
        let p = self.law.proximity(i.surface_temp_c, i.contact_temp_c);
        if p == 0.0 {
            self.base.forces_prepared(prepared, i) // Scale::ONE
        } else {
            self.base.forces_prepared_scaled(prepared, i, &self.law.scale(p))
        }
    }

    fn peak_friction(&self, i: &TyreInput) -> f64 {
        self.base.peak_friction_scaled(i, &self.law.scale_for(i))
    }

    fn peak_friction_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> f64 {
        self.base.peak_friction_prepared_scaled(prepared, i, &self.law.scale_for(i))
    }

    /// The base curve's floor with the temperature law's peak factors applied.
    fn peak_force_floor_prepared(&self, prepared: &super::Prepared, i: &TyreInput) -> Option<f64> {
        self.base.peak_force_floor_prepared_scaled(prepared, i, &self.law.scale_for(i))
    }

    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        self.base.longitudinal_stiffness_scaled(i, &self.law.scale_for(i))
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        self.base.cornering_stiffness_scaled(i, &self.law.scale_for(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tyre::pacejka::Combination;

    /// The SRTT curve, and the same with every camber, shift and scaling coefficient that the
    /// prepared (load-independent and load-dependent) parts touch set away from 0 and 1, so that
    /// the order of every product is exercised; each with the MF and the ellipse combination.
    fn curves() -> Vec<PacejkaTyre> {
        let base = crate::tyre::srtt_for_tests();
        let mut c = base.coeffs.clone();
        (c.pdx3, c.pdy3, c.pky3, c.phy3, c.pey3, c.pey4, c.pvy3, c.pvy4) = (3.0, 2.0, 0.7, 0.01, 0.2, -0.3, 0.02, 0.01);
        (c.phx1, c.phx2, c.pvx1, c.pvx2, c.pkx3, c.phy1, c.pvy1, c.pvy2) =
            (0.002, 0.001, 0.01, -0.02, 0.3, 0.003, 0.02, 0.01);
        (c.lmux, c.lmuy, c.lkx, c.lky, c.lhx, c.lhy, c.lvx, c.lvy, c.lgax, c.lgay) =
            (0.9, 1.1, 1.2, 0.8, 1.3, 0.7, 1.1, 0.9, 1.2, 0.8);
        (c.rhx1, c.rhy1, c.rvy1, c.rvy4, c.rvy5, c.rvy6) = (0.01, 0.02, 0.05, 3.0, 1.9, 10.0);
        let mut out = Vec::new();
        for (coeffs, exponent) in [(base.coeffs.clone(), 0.5), (c, 0.7)] {
            for comb in [Combination::MagicFormula, Combination::Ellipse] {
                let t = PacejkaTyre::new(coeffs.clone(), 1.0, exponent, Some(comb), true);
                out.extend(TyreSide::BOTH.map(|s| t.mounted_on(s)));
            }
        }
        out
    }

    /// Prepared forces and peak friction equal the unprepared ones bit for bit, for the Magic
    /// Formula and its ATIIM modification: at the prepared load and surface (heated or not), at
    /// other loads on the same surface (load transfer), a lifted wheel, and on another surface or
    /// camber (the fallback).
    #[test]
    fn prepared_forces_change_no_bit() {
        let law = MeltLaw {
            k_shift: KShift::Srtt,
            x: AxisLaw { peak_at_melt: 0.5, stiffness_at_melt: 0.8 },
            y: AxisLaw { peak_at_melt: 0.9, stiffness_at_melt: 0.7 },
            floor: 0.1,
        };
        let mut n = 0;
        for base in curves() {
            let atiim = AtiimPacejkaTyre { base: base.clone(), law };
            let tyres: [&dyn TyreModel; 2] = [&base, &atiim];
            for t in tyres {
                let at = TyreInput {
                    surface_temp_c: -3.0,
                    contact_temp_c: -3.0,
                    camber_rad: 0.01,
                    ..TyreInput::new(3900.0, 0.0, 0.0, 0.15)
                };
                let prepared = t.prepare(&at);
                for fz in [3900.0, 2500.0, 5200.0, 0.0, -10.0] {
                    for (mu, camber) in [(0.15, 0.01), (0.3, 0.01), (0.15, 0.0)] {
                        for contact in [-3.0, -1.5, 0.5] {
                            for (kappa, alpha) in [(0.0, 0.0), (0.05, -0.02), (-0.3, 0.1), (0.01, 0.3)] {
                                let i = TyreInput {
                                    fz_n: fz,
                                    kappa,
                                    alpha_rad: alpha,
                                    camber_rad: camber,
                                    mu_surface: mu,
                                    contact_temp_c: contact,
                                    ..at
                                };
                                let (a, b) = (t.forces_prepared(&prepared, &i), t.forces(&i));
                                assert_eq!(
                                    [a.fx_n.to_bits(), a.fy_n.to_bits(), a.mz_nm.to_bits()],
                                    [b.fx_n.to_bits(), b.fy_n.to_bits(), b.mz_nm.to_bits()],
                                    "{} {i:?}: {a:?} vs {b:?}",
                                    t.name()
                                );
                                let (pa, pb) = (t.peak_friction_prepared(&prepared, &i), t.peak_friction(&i));
                                assert_eq!(pa.to_bits(), pb.to_bits(), "{} peak {i:?}: {pa} vs {pb}", t.name());
                                n += 1;
                            }
                        }
                    }
                }
            }
        }
        assert_eq!(n, 8 * 2 * 5 * 3 * 3 * 4);
    }
}
