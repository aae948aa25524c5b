//! The tread band's bulk temperature over a rig run: the rolling (hysteresis) heat and the tread's
//! share of the friction heat warm the whole tread band over many revolutions, and it loses heat
//! to the ice through the patch and to the air. A lumped state (one temperature for the band's
//! rubber), in SI units and kelvin above the ice temperature.
//!
//! C dT/dt = P - G T,  T(0) = 0  =>  T(t) = (P / G) (1 - e^(-t G / C)),
//!
//! - C = rho c 2 pi R w d (1 - void): the band's rubber (R rolling radius, w tread width, d tread
//!   depth);
//! - P = s f_rr F_z v_r + P_f: the tread's share s of the rolling-resistance power
//!   ([`super::estimator::TREAD_HYSTERESIS_SHARE`], the engine estimator's value) plus the friction
//!   heat the patch sends into the tread (`PatchSummary::power_tread_w`, in proportion to the
//!   friction's share of the generated heat);
//! - G = 2 pi R w / (d / (3 k) + 1 / h_s): the band's outer surface behind the conduction resistance
//!   of a slab heated uniformly through its depth with an adiabatic base (the belt side), mean to
//!   surface d / (3 k); the surface's time-averaged coefficient is h_s = (A / (2 pi R w)) h_c + h_air,
//!   with h_c = 2 e_s / sqrt(pi t_c) the mean conductance of a contact of duration t_c = L / v_r
//!   between two semi-infinite bodies (e_s = e_t e_i / (e_t + e_i)), A the patch area, L its length,
//!   and h_air = 10 + 7 sqrt(v_r) W/(m^2 K) (the engine estimator's convection over the band), air at
//!   the ice temperature.
//!
//! The interface sees the band's rise at first contact weighted by effusivity, e_t / (e_t + e_i)
//! ([`TreadBulk::contact_rise_k`]), as the engine estimator's start temperature does.

use super::estimator::TREAD_HYSTERESIS_SHARE;
use super::model::{PatchParams, PatchSummary};
use super::thermal::ICE;
use std::f64::consts::PI;

/// Rolling radius of the SRTT P225/60R16, m (the `[contact]` table's default `rolling_radius_m`).
pub const SRTT_ROLLING_RADIUS_M: f64 = 0.328;

/// Length of the rig's ice track, m: the 16 ft path of travel (dissertation 3.2.1). A run at the
/// carriage speed V lasts `RIG_TRACK_M / V`: 70 s at 7 cm/s, 2.4 revolutions of the SRTT.
pub const RIG_TRACK_M: f64 = 16.0 * 0.3048;

/// The lumped tread band of one rig run.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TreadBulk {
    /// Heat capacity of the band's rubber, J/K.
    pub heat_capacity_j_k: f64,
    /// Rolling (hysteresis) heat into the band, W.
    pub power_rolling_w: f64,
    /// Friction heat into the band, W.
    pub power_friction_w: f64,
    /// Conductance to ice and air, W/K.
    pub conductance_w_k: f64,
    /// Steady rise (P / G), K.
    pub steady_rise_k: f64,
    /// Time constant C / G, s.
    pub time_constant_s: f64,
    /// Share of the band's rise the interface sees at first contact, e_t / (e_t + e_i).
    pub contact_share: f64,
}

impl TreadBulk {
    /// The band at load `fz_n`, rolling speed `roll_mps`, patch area `area_m2`, with the patch's
    /// powers `patch` (its friction heat into the tread), tread width `width_m`, rolling radius
    /// `radius_m` and the patch parameters `pp` (compound, tread depth, void ratio, f_rr).
    pub fn new(
        pp: &PatchParams,
        patch: &PatchSummary,
        fz_n: f64,
        roll_mps: f64,
        area_m2: f64,
        width_m: f64,
        radius_m: f64,
    ) -> Self {
        let solid = pp.compound.solid;
        let (e_t, e_i) = (solid.effusivity(), ICE.effusivity());
        let band = 2.0 * PI * radius_m * width_m;
        let d = pp.tread_depth_m.max(1e-4);
        let heat_capacity_j_k = solid.density_kg_m3 * solid.specific_heat_j_kgk * band * d * (1.0 - pp.void_ratio);
        let vr = roll_mps.max(0.0);
        let power_rolling_w = TREAD_HYSTERESIS_SHARE * pp.rolling_resistance.max(0.0) * fz_n.max(0.0) * vr;
        let power_friction_w = if patch.power_generated_w > 0.0 {
            patch.power_tread_w * (patch.power_friction_w / patch.power_generated_w).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let e_s = e_t * e_i / (e_t + e_i);
        let h_c = if vr > 0.0 && area_m2 > 0.0 {
            let t_c = area_m2 / width_m.max(1e-3) / vr;
            2.0 * e_s / (PI * t_c).sqrt()
        } else {
            0.0
        };
        let h_s = area_m2.max(0.0) / band * h_c + 10.0 + 7.0 * vr.sqrt();
        let conductance_w_k = band / (d / (3.0 * solid.conductivity_w_mk) + 1.0 / h_s);
        let p = power_rolling_w + power_friction_w;
        TreadBulk {
            heat_capacity_j_k,
            power_rolling_w,
            power_friction_w,
            conductance_w_k,
            steady_rise_k: p / conductance_w_k,
            time_constant_s: heat_capacity_j_k / conductance_w_k,
            contact_share: e_t / (e_t + e_i),
        }
    }

    /// The band's rise after `t_s` seconds of running from the ice temperature, K.
    pub fn rise_after_k(&self, t_s: f64) -> f64 {
        self.steady_rise_k * (1.0 - (-t_s.max(0.0) / self.time_constant_s).exp())
    }

    /// The interface's rise at first contact from a band risen by `band_rise_k`, K.
    pub fn contact_rise_k(&self, band_rise_k: f64) -> f64 {
        self.contact_share * band_rise_k
    }
}
