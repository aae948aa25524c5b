//! Friction laws of the patch model, pure functions in SI units:
//! - [`IceFriction`]: the rubber-ice friction law mu(T, v_slide, p) with an adhesion peak, used by
//!   the contact patch and by the car's tyre alike;
//! - `WetFilm`: one friction law for a pixel carrying a water film of height h, from which both the
//!   shear stress tau = mu p and the frictional heat q = tau v_slide follow (eq. 2.1 with the viscous
//!   friction of eq. 4.13 as its floor);
//! - viscous film friction (eq. 4.11–4.13), friction versus film height (eq. 2.1), the brush stress
//!   and sliding power under severe slip (eq. 2.12 = 4.15).
//!
//! Eq. 4.14, 4.16 and 4.17 (heat generated inside the tread, decaying exponentially with depth,
//! with an in-tread share eps) are not used as such: the patch model puts all frictional heat at
//! the interface (assumptions 2, 3, 9) and splits it between tread and ice by effusivity, which
//! gives eps directly (`heat::tread_fraction`). Eq. 4.16 also reuses S for both slip and area.

/// Coldest interface temperature the ice friction law distinguishes, degC: below it the friction
/// holds its cold plateau (the dissertation, 2.5 citing its ref. 37: dry ice below about -10 degC
/// holds 0.16-0.20, i.e. the rise with cold levels off). Assumption: -12 degC, so that with
/// c_T = 0.028 /K the plateau is 6 % above the -10 degC value (0.157 -> 0.166 on the rig's ice,
/// inside 0.16-0.20).
pub(crate) const COLD_PLATEAU_C: f64 = -12.0;

/// The rubber-ice friction law of vehsim: mu(T, v_slide, p), one function used by the contact
/// patch (every dry pixel, and the dry limit of every wet one) and by the car's Magic Formula tyre
/// (its peak friction, `tyre::ice::SurfaceFriction`).
///
/// mu = mu_ref * Phi(T, v, p) / Phi(T_ref, v_ref, p_ref),
/// Phi = exp(-c_T clamp(T, T_cold, 0)) * S(v) * (1 + v / v_c)^(-n_v) * max(p, p_min)^(-n_p),
/// S(v) = 1 + g exp(-ln^2(v / v_pk(p)) / (2 w^2)),  v_pk(p) = v_pk (max(p, p_min) / p_ref)^(-n_p),
///
/// with T the interface (contact) temperature, degC, T_cold = `COLD_PLATEAU_C`, and v clamped to
/// at least 1e-6 m/s. Trends (the dissertation's 2.2, Fig. 2.4 and Fig. 2.14): the friction is higher on
/// colder ice down to a plateau, falls toward melting, falls with sliding speed above the adhesion
/// peak (Fig. 2.14 and 2.5.4: 'a decrease in rubber friction with increasing sliding velocity for
/// v > 0.01 m/s') and falls with contact pressure. The bell S is the adhesion peak of rubber
/// friction versus log sliding speed (a Grosch-type master curve) that gives the rig's drawbar
/// peak at 5-10 % slip; the power (1 + v/v_c)^(-n_v) is its fall at road sliding speeds. A tread
/// element sticks until its stress reaches the peak value ([`IceFriction::static_mu`]). The water
/// film (the contact at 0 degC) is not in this law: the patch adds it pixel by pixel
/// (`WetFilm`), the car's ATIIM-Pacejka tyre through its melt law.
///
/// Parameters (defaults in [`IceFriction::srtt`]; each a source or a stated assumption):
/// - `mu_ref`: the friction at the reference conditions (T_ref, v_ref, p_ref), which the caller
///   states (a patch scenario: the rig's `mu_dry` at -10 degC, 0.028 m/s, 250 kPa; a manoeuvre's
///   surface: `mu` at its `mu_reference_temperature_c` and 1 m/s, see docs/tyres.md);
/// - adhesion peak: gain g 0.35 at v_pk 5 mm/s (at p_ref), width w 1.0 (in ln v). Assumption, set
///   from the rig's ratio of peak to saturated drawbar pull (about 1.2) and its peak at 5-10 % slip
///   at 7 cm/s travel (3.5-7 mm/s sliding); Fig. 2.14 gives no numbers. The peak's speed falls
///   with pressure with the same exponent n_p (derived, not a parameter: [`IceFriction::peak_speed_at`]);
/// - speed fall: v_c 0.1 m/s, n_v 0.1. Assumption: the fall starts near 0.01-0.1 m/s (2.5.4) and
///   is mild, so that the rig's friction at mm/s sliding (0.16-0.21 peaks) and a road tyre's peak
///   on ice at about 1 m/s sliding stay of one size (0.8x from 0.028 to 1 m/s), and a locked
///   wheel at 25 m/s keeps about 0.7x of the friction at 1 m/s;
/// - pressure exponent n_p 0.25 (assumption: real contact area growing less than in proportion
///   to load, between 0 for Amontons and 1/3 for Hertzian asperities), p_min 10 kPa;
/// - temperature coefficient c_T 0.028 /K: the rig's peak drawbar pull fell 18 % from -10 to
///   -3 degC (0.179 -> 0.146, the dissertation's 5.3.3 and Fig. 5.7/5.8); exp(-0.028 * 7) = 0.82.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IceFriction {
    /// Friction at the reference conditions, 0.02-0.6.
    pub mu_ref: f64,
    /// Reference sliding speed, m/s.
    pub v_ref_mps: f64,
    /// Reference contact pressure, Pa.
    pub p_ref_pa: f64,
    /// Reference interface temperature, degC (<= 0).
    pub t_ref_c: f64,
    /// Adhesion-peak gain g over the base, 0-2 (0 = no peak).
    pub peak_gain: f64,
    /// Sliding speed of the adhesion peak, m/s (1e-4 - 1).
    pub peak_speed_mps: f64,
    /// Width of the peak in ln(v), 0.2-5.
    pub peak_width: f64,
    /// Pressure exponent n_p, 0-1.
    pub pressure_exponent: f64,
    /// Temperature coefficient c_T, 1/K, 0-0.2.
    pub temp_coeff_per_k: f64,
    /// Sliding speed v_c where the road-speed fall sets in, m/s (0.001-10).
    pub speed_scale_mps: f64,
    /// Exponent n_v of the road-speed fall, 0-1 (0 = none).
    pub speed_exponent: f64,
}

/// Smallest pressure used in the pressure factor, Pa (edge pixels carry almost none).
const P_MIN_PA: f64 = 10e3;

impl IceFriction {
    /// The SRTT defaults documented on the type, with reference friction `mu_ref` at -10 degC,
    /// 0.028 m/s and 250 kPa (the rig's conditions).
    pub fn srtt(mu_ref: f64) -> Self {
        IceFriction {
            mu_ref,
            v_ref_mps: 0.028,
            p_ref_pa: 250e3,
            t_ref_c: -10.0,
            peak_gain: 0.35,
            peak_speed_mps: 0.005,
            peak_width: 1.0,
            pressure_exponent: 0.25,
            temp_coeff_per_k: 0.028,
            speed_scale_mps: 0.1,
            speed_exponent: 0.1,
        }
    }

    /// A constant friction `mu` (no peak, no speed, pressure or temperature dependence).
    pub fn constant(mu: f64) -> Self {
        IceFriction {
            peak_gain: 0.0,
            pressure_exponent: 0.0,
            temp_coeff_per_k: 0.0,
            speed_exponent: 0.0,
            ..Self::srtt(mu)
        }
    }

    /// The speed factor S(v) (1 + v/v_c)^(-n_v), dimensionless, at the reference pressure (where the
    /// adhesion peak lies at `peak_speed_mps`).
    pub fn speed_factor(&self, v_mps: f64) -> f64 {
        self.speed_factor_ln_shift(v_mps, 0.0)
    }

    /// The speed factor at contact pressure `p_pa`: the adhesion peak lies at
    /// v_pk(p) = v_pk (max(p, p_min) / p_ref)^(-n_p) ([`Self::peak_speed_at`]).
    pub fn speed_factor_at(&self, v_mps: f64, p_pa: f64) -> f64 {
        self.speed_factor_ln_shift(v_mps, -self.pressure_exponent * self.ln_pressure_ratio(p_pa))
    }

    /// Sliding speed of the adhesion peak at contact pressure `p_pa`, m/s:
    /// v_pk (max(p, p_min) / p_ref)^(-n_p). Derivation (docs/atiim.md, "Peak slip and inflation"):
    /// the peak is where flash heating of the real contact spots starts to weaken the interface;
    /// at the rig's millimetre-per-second sliding the spots (micrometres) heat at low Peclet number,
    /// their rise is tau_s v a / (4 k) with tau_s the interfacial shear strength, so the peak speed
    /// goes as 1 / a, the spot radius. The pressure exponent n_p says the real contact area grows as
    /// p^(1 - n_p); with spots of radius a ~ p^(n_p) and a number ~ p^(1 - 3 n_p) (Hertzian spots of
    /// fixed number at n_p = 1/3, spots of fixed size at n_p = 0, Amontons), v_pk ~ p^(-n_p).
    pub fn peak_speed_at(&self, p_pa: f64) -> f64 {
        self.peak_speed_mps * (-self.pressure_exponent * self.ln_pressure_ratio(p_pa)).exp()
    }

    /// ln(max(p, p_min) / p_ref) (0 where the law has no pressure dependence or p is not finite).
    #[inline]
    fn ln_pressure_ratio(&self, p_pa: f64) -> f64 {
        if self.pressure_exponent > 0.0 && p_pa.is_finite() {
            (p_pa.max(P_MIN_PA) / self.p_ref_pa).ln()
        } else {
            0.0
        }
    }

    /// S(v) (1 + v/v_c)^(-n_v) with the adhesion peak at ln v_pk + `ln_shift`.
    fn speed_factor_ln_shift(&self, v_mps: f64, ln_shift: f64) -> f64 {
        let v = if v_mps.is_finite() { v_mps.abs().max(1e-6) } else { 1e-6 };
        let l = ((v / self.peak_speed_mps).ln() - ln_shift) / self.peak_width;
        let bell = 1.0 + self.peak_gain * (-0.5 * l * l).exp();
        if self.speed_exponent > 0.0 {
            bell * (1.0 + v / self.speed_scale_mps).powf(-self.speed_exponent)
        } else {
            bell
        }
    }

    /// The temperature factor exp(-c_T (clamp(T) - T_ref)) relative to the reference, with T the
    /// interface temperature, degC (a non-finite T counts as T_ref).
    pub fn temp_factor(&self, t_c: f64) -> f64 {
        self.ln_temp_factor(t_c).exp()
    }

    /// ln of [`Self::temp_factor`]: -c_T (clamp(T) - clamp(T_ref)).
    #[inline]
    pub fn ln_temp_factor(&self, t_c: f64) -> f64 {
        let t = if t_c.is_finite() { t_c.clamp(COLD_PLATEAU_C, 0.0) } else { self.t_ref_c };
        -self.temp_coeff_per_k * (t - self.t_ref_c.clamp(COLD_PLATEAU_C, 0.0))
    }

    /// The pressure factor relative to the reference, (max(p, p_min) / p_ref)^(-n_p).
    fn pressure_factor(&self, p_pa: f64) -> f64 {
        if self.pressure_exponent > 0.0 {
            (-self.pressure_exponent * self.ln_pressure_ratio(p_pa)).exp()
        } else {
            1.0
        }
    }

    /// Pressure and temperature factor times mu_ref / S(v_ref) (S at the reference pressure).
    fn scale(&self, t_c: f64, p_pa: f64) -> f64 {
        self.mu_ref / self.speed_factor(self.v_ref_mps) * self.pressure_factor(p_pa) * self.temp_factor(t_c)
    }

    /// Sliding friction at interface temperature `t_c` (degC), sliding speed `v_mps` and contact
    /// pressure `p_pa` (the adhesion peak at [`Self::peak_speed_at`] this pressure).
    pub fn mu(&self, t_c: f64, v_mps: f64, p_pa: f64) -> f64 {
        // one logarithm of the pressure for both the pressure factor and the peak's shift
        let shift = -self.pressure_exponent * self.ln_pressure_ratio(p_pa);
        let pressure = if self.pressure_exponent > 0.0 { shift.exp() } else { 1.0 };
        self.mu_ref / self.speed_factor(self.v_ref_mps)
            * pressure
            * self.temp_factor(t_c)
            * self.speed_factor_ln_shift(v_mps, shift)
    }

    /// Static (sticking) limit: the friction at the adhesion peak (no road-speed fall), >= every
    /// sliding value at the same temperature and pressure.
    pub fn static_mu(&self, t_c: f64, p_pa: f64) -> f64 {
        self.scale(t_c, p_pa) * (1.0 + self.peak_gain)
    }
}

/// The friction law of a wet pixel (water film of height h between tread and ice, interface at
/// 0 degC): eq. 2.1 with the viscous friction of eq. 4.13 as its floor,
///
///   mu(h) = mu_F + (mu_d - mu_F) e^(-beta h),   mu_F = min(mu_v(h), mu_d),   mu_v = kappa eta v / (p h),
///
/// and the frictional heat per unit area q(h) = mu(h) p v (the work of the shear stress). mu_d is
/// the dry friction at 0 degC; beta = ln 4 / h_c. While the film is so thin that mu_v >= mu_d
/// (h <= h* = kappa eta v / (p mu_d)) the law gives mu_d; beyond, it falls continuously toward
/// the viscous friction. q is therefore bounded (<= mu_d p v) and non-increasing in h, so the
/// film ODE has a unique implicit step (see `film::advance_wet`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WetFilm {
    /// p v, W/m^2 per unit friction.
    pub pv: f64,
    /// Dry friction at 0 degC.
    pub mu_d: f64,
    /// beta, 1/m.
    pub beta: f64,
    /// kappa eta v / p, m (mu_v = this / h).
    pub visc_m: f64,
}

impl WetFilm {
    /// The floor mu_F = min(mu_v(h), mu_d) (the viscous friction of eq. 4.13, capped at mu_d).
    #[inline]
    pub fn viscous_part(&self, h_m: f64) -> f64 {
        if h_m > 0.0 && self.visc_m < self.mu_d * h_m {
            self.visc_m / h_m
        } else {
            self.mu_d
        }
    }

    /// Heat q(h), W/m^2, and its derivative dq/dh, W/m^3 (0 on the flat part h <= h*).
    #[inline]
    pub fn heat(&self, h_m: f64) -> (f64, f64) {
        if !(h_m > 0.0 && self.visc_m < self.mu_d * h_m) {
            return (self.pv * self.mu_d, 0.0);
        }
        let mv = self.visc_m / h_m;
        let e = (-self.beta * h_m).exp();
        let mu = mv + (self.mu_d - mv) * e;
        let dmu = -mv / h_m * (1.0 - e) - self.beta * (self.mu_d - mv) * e;
        (self.pv * mu, self.pv * dmu)
    }
}

/// Viscous friction coefficient of a film (eq. 4.13): mu = kappa eta v / (p h), written with the
/// time-average of 1/h over a pixel (`inv_h_mean`, 1/m) so that the h -> 0 onset stays integrable.
/// `kappa` 0–1, `eta_pa_s` water viscosity, `v_mps` sliding speed >= 0, `p_pa` > 0.
/// Returns 0 if p <= 0.
#[cfg(test)]
pub(crate) fn viscous_mu(kappa: f64, eta_pa_s: f64, v_mps: f64, p_pa: f64, inv_h_mean: f64) -> f64 {
    if p_pa > 0.0 && inv_h_mean.is_finite() {
        kappa * eta_pa_s * v_mps.abs() * inv_h_mean / p_pa
    } else {
        0.0
    }
}

/// Friction versus film height (eq. 2.1, Kulakowski & Harwood): mu = dmu exp(-beta h) + mu_f, with
/// dmu = mu_dry - mu_f so that mu(0) = mu_dry. `beta_per_m` from the critical height h_c at which
/// the excess friction has dropped to 25 %: beta = ln 4 / h_c (see [`beta_from_critical_height`]).
#[cfg(test)]
pub(crate) fn film_mu(mu_dry: f64, mu_f: f64, beta_per_m: f64, h_m: f64) -> f64 {
    (mu_dry - mu_f) * (-beta_per_m * h_m.max(0.0)).exp() + mu_f
}

/// beta = ln 4 / h_c, 1/m. `h_c_m` > 0 (tens of nm to a few µm).
pub(crate) fn beta_from_critical_height(h_c_m: f64) -> f64 {
    4f64.ln() / h_c_m.max(1e-12)
}

/// Sliding power under severe slip (eq. 2.12 / 4.15), W: (sin^2 alpha + s^2)^0.5 mu_d V F_z.
/// `alpha_rad` slip angle, `s` slip ratio magnitude (1 = locked), `mu_d` sliding friction,
/// `v_mps` travel speed, `fz_n` load.
#[cfg(test)]
pub(crate) fn sliding_power_w(alpha_rad: f64, s: f64, mu_d: f64, v_mps: f64, fz_n: f64) -> f64 {
    severe_slip_factor(alpha_rad, s) * mu_d * v_mps.abs() * fz_n
}

/// (sin^2 alpha + s^2)^0.5: the sliding speed over the travel speed implied by eq. 2.12.
#[cfg(test)]
pub(crate) fn severe_slip_factor(alpha_rad: f64, s: f64) -> f64 {
    (alpha_rad.sin().powi(2) + s * s).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn film_mu_limits() {
        assert!((film_mu(0.2, 0.05, 1e7, 0.0) - 0.2).abs() < 1e-15);
        assert!((film_mu(0.2, 0.05, 1e7, 1.0) - 0.05).abs() < 1e-15);
        let b = beta_from_critical_height(100e-9);
        assert!((film_mu(0.2, 0.0, b, 100e-9) - 0.05).abs() < 1e-12);
    }

    #[test]
    fn viscous_mu_magnitude() {
        // kappa 1, eta 0.00182, v 2 m/s, p 250 kPa, h 130 nm -> 0.112
        let mu = viscous_mu(1.0, 0.00182, 2.0, 250e3, 1.0 / 130e-9);
        assert!((mu - 0.00364 / (250e3 * 130e-9)).abs() < 1e-12);
        assert_eq!(viscous_mu(1.0, 0.00182, 2.0, 0.0, 1e7), 0.0);
    }

    #[test]
    fn dry_law_is_mu_ref_at_reference_and_follows_fig_2_14_trends() {
        let f = IceFriction::srtt(0.15);
        assert!((f.mu(-10.0, 0.028, 250e3) - 0.15).abs() < 1e-12);
        // falls with speed above the peak, with pressure and with temperature
        assert!(f.mu(-10.0, 0.01, 250e3) > f.mu(-10.0, 0.1, 250e3));
        assert!(f.mu(-10.0, 0.1, 250e3) > f.mu(-10.0, 1.0, 250e3));
        assert!(f.mu(-10.0, 0.028, 150e3) > f.mu(-10.0, 0.028, 350e3));
        assert!(f.mu(-10.0, 0.028, 250e3) > f.mu(-3.0, 0.028, 250e3));
        // the adhesion peak: the static limit bounds every sliding value and is the bell's top
        // (the road-speed fall aside: at v_pk it is (1 + 0.005/0.1)^-0.1 = 0.9951 of it)
        let s = f.static_mu(-10.0, 250e3);
        let at_peak = f.mu(-10.0, 0.005, 250e3);
        assert!((at_peak / s - 1.05f64.powf(-0.1)).abs() < 1e-12, "{at_peak} {s}");
        for k in 0..200 {
            let v = 1e-5 * 1.1f64.powi(k);
            assert!(f.mu(-10.0, v, 250e3) <= s + 1e-15);
        }
        // hand value: g = 0.35, w = 1, ln(0.028/0.005) = 1.7228 -> S(v_ref) = 1 + 0.35 e^-1.4840,
        // times the fall (1 + 0.28)^-0.1
        let sref = (1.0 + 0.35 * (-0.5 * (0.028f64 / 0.005).ln().powi(2)).exp()) * 1.28f64.powf(-0.1);
        assert!((s - 0.15 * 1.35 / sref).abs() < 1e-12);
        // the cold plateau: no change below COLD_PLATEAU_C; -10 -> -3 degC: exp(-0.028 * 7)
        assert_eq!(f.mu(-12.0, 0.5, 2e5), f.mu(-30.0, 0.5, 2e5));
        assert!(f.mu(-11.0, 0.5, 2e5) < f.mu(-12.0, 0.5, 2e5));
        assert!((f.mu(-3.0, 0.5, 2e5) / f.mu(-10.0, 0.5, 2e5) - (-0.028f64 * 7.0).exp()).abs() < 1e-12);
        // the road-speed fall: 1 -> 25 m/s keeps (251/11)^-0.1 = 0.73 (the bell is 1 + 3e-7 there)
        let r = f.mu(-10.0, 25.0, 2e5) / f.mu(-10.0, 1.0, 2e5);
        assert!((r - (251.0f64 / 11.0).powf(-0.1)).abs() < 1e-6, "{r}");
        // extreme temperatures are clamped, not overflowed
        assert!(f.mu(-1e6, 1.0, 2e5).is_finite() && f.mu(f64::NAN, 1.0, 2e5).is_finite());
        let c = IceFriction::constant(0.2);
        assert_eq!(c.mu(-3.0, 5.0, 1e5), 0.2);
        assert_eq!(c.static_mu(-30.0, 9e5), 0.2);
    }

    /// The adhesion peak's sliding speed falls with pressure as p^(-n_p): the bell's maximum found
    /// by a scan in ln v (not from `peak_speed_at`) lies there, its height is unchanged, and the
    /// friction still falls with pressure at every sliding speed (n_p (1 - g / (w sqrt e)) > 0).
    #[test]
    fn adhesion_peak_speed_falls_with_pressure() {
        let f = IceFriction { speed_exponent: 0.0, ..IceFriction::srtt(0.15) };
        for p in [100e3, 145e3, 250e3, 400e3] {
            let mut best = (0.0, 0.0);
            for k in 0..4000 {
                let v = 1e-4 * (1.0 + 1e-3f64).powi(k * 2);
                let m = f.mu(-10.0, v, p);
                if m > best.1 {
                    best = (v, m);
                }
            }
            let want = 0.005 * (p / 250e3).powf(-0.25);
            assert!((best.0 / want - 1.0).abs() < 3e-3, "{p}: peak at {} vs {want}", best.0);
            assert!((best.1 / f.static_mu(-10.0, p) - 1.0).abs() < 1e-6);
            assert!((f.peak_speed_at(p) / want - 1.0).abs() < 1e-12);
        }
        let g = IceFriction::srtt(0.15);
        for k in 0..120 {
            let v = 1e-5 * 1.15f64.powi(k);
            assert!(g.mu(-10.0, v, 150e3) > g.mu(-10.0, v, 350e3), "v {v}");
        }
        // no pressure dependence: the peak stays at v_pk
        let h = IceFriction { pressure_exponent: 0.0, ..f };
        assert_eq!(h.peak_speed_at(400e3), 0.005);
        assert_eq!(h.mu(-10.0, 0.003, 100e3), h.mu(-10.0, 0.003, 400e3));
    }

    #[test]
    fn wet_law_limits_and_derivative() {
        let (kappa, eta, v, p, hc) = (1.0, 0.00182, 2.0, 250e3, 50e-9);
        let w = WetFilm { pv: p * v, mu_d: 0.12, beta: beta_from_critical_height(hc), visc_m: kappa * eta * v / p };
        // h = 0 and thin films (mu_v >= mu_d): dry friction
        let h_star = kappa * eta * v / (p * 0.12);
        for h in [0.0, 1e-9, 0.99 * h_star] {
            assert!((w.heat(h).0 - 0.12 * p * v).abs() < 1e-9 * p * v, "{h}");
        }
        // thick film: the viscous friction of eq. 4.13
        let h = 5e-6;
        let mu = w.heat(h).0 / (p * v);
        assert!((mu - viscous_mu(kappa, eta, v, p, 1.0 / h)).abs() < 1e-6, "{mu}");
        // equals eq. 2.1 with mu_F = min(mu_v, mu_d) at any h; continuous at h*; non-increasing
        let mut last = f64::INFINITY;
        for k in 0..400 {
            let h = 1e-9 * 1.03f64.powi(k);
            let mf = viscous_mu(kappa, eta, v, p, 1.0 / h).min(0.12);
            let want = film_mu(0.12, mf, w.beta, h);
            let got = w.heat(h).0 / (p * v);
            assert!((got - want).abs() < 1e-9 * want, "{h}: {got} vs {want}");
            assert!(got <= last + 1e-12);
            last = got;
        }
        for h in [1.5 * h_star, 3e-7, 1e-6] {
            let d = 1e-5 * h;
            let fd = (w.heat(h + d).0 - w.heat(h - d).0) / (2.0 * d);
            let an = w.heat(h).1;
            assert!((fd - an).abs() < 1e-4 * an.abs(), "{h}: {fd} vs {an}");
            assert!(an < 0.0);
        }
    }

    #[test]
    fn locked_wheel_power_is_mu_v_fz() {
        assert!((sliding_power_w(0.0, 1.0, 0.15, 10.0, 7000.0) - 10500.0).abs() < 1e-9);
    }
}
