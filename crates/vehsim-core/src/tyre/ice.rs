//! The surface friction of ice as the car's Magic Formula tyre sees it: the peak friction of the
//! Magic Formula (LMUX', LMUY') follows the rubber-ice friction law
//! [`crate::tyre::friction::IceFriction`] (the same function the contact patch uses) at the
//! tyre's own state, at every evaluation.
//!
//! ```text
//! mu_eff = mu_spec * Phi(T, v_s) / Phi(T_ref, v_ref)
//! v_s    = |V_x| sqrt(kappa^2 + tan^2 alpha)          the contact's sliding speed, m/s
//! T      = the contact temperature (atiim_pacejka)      degC
//!          the ice temperature (pacejka: no frictional heating)
//! ```
//!
//! `mu_spec` is the manoeuvre's `surface.mu`, now stated as the friction at the reference
//! conditions: ice (interface) temperature T_ref (`surface.mu_reference_temperature_c`, default
//! [`DEFAULT_REFERENCE_C`]) and sliding speed v_ref = `REFERENCE_SLIDING_MPS` (about the sliding
//! speed at a car tyre's friction peak on ice: 10 % slip at 10 m/s). The law's pressure factor is
//! not applied: a Magic Formula tyre carries its own load sensitivity of friction (PDX2, PDY2),
//! fitted with the pressure that load gives; applying the law's pressure fall on top would count
//! it twice. So the car tyre evaluates the law at its reference pressure.
//!
//! The law's adhesion peak (the bell at millimetres per second of sliding, which gives the brush
//! patch its drawbar peak at 5-10 % slip on the rig) is not applied here: the Magic Formula's own
//! shape already carries the tyre's rise to a peak and fall beyond it (its B, C, E), so the car
//! tyre takes the law's temperature factor and its fall at road sliding speeds only.
//!
//! How the factor enters the Magic Formula ([`super::pacejka::Scale`]): both peak-friction scales
//! are multiplied by Phi ratio; both slip-stiffness scales by the temperature part of it raised to
//! the tyre's `stiffness_mu_exponent` (the exponent by which a change of surface friction moves
//! the slip stiffness; the sliding-speed part shapes the curve beyond its peak and leaves the
//! stiffness at zero slip alone). With B = K / (C D), a smaller D at large slip (faster sliding)
//! makes the curve fall faster beyond its peak and moves the peak to a slightly smaller slip.
//!
//! Cost per evaluation: the sliding speed (the tangent squared, by one sine kernel, and a square
//! root), the speed factor (a table-based logarithm and an exponential by a short polynomial:
//! smooth in v, which keeps the integrators' order) and the temperature factor (the same
//! exponential, kept for the ice temperature of the run it was built for, so a `pacejka` tyre
//! pays it once per run).

use super::atiim::AtiimPacejkaTyre;
use super::pacejka::{PacejkaTyre, Scale};
use super::{Prepared, TyreForces, TyreInput, TyreModel};
use crate::tyre::fastmath::fast_ln;
use crate::tyre::friction::IceFriction;

/// e^a for the factors' exponents, which stay within a few units of 0: e^a = (p(a / 16))^16 with p
/// the Taylor polynomial of degree 9 (|a / 16| <= 0.25: truncation below 3e-13, 4e-12 relative
/// after the four squarings), a polynomial and so smooth in a, and about a quarter of the
/// library's cost; |a| > 4 (or not finite) falls back to `f64::exp`.
#[inline]
fn exp_near_zero(a: f64) -> f64 {
    if !(a.abs() <= 4.0) {
        return a.exp();
    }
    let x = a * (1.0 / 16.0);
    // Horner form of sum x^k / k!, k = 0..9
    let mut p = 1.0 / 362_880.0;
    p = p * x + 1.0 / 40_320.0;
    p = p * x + 1.0 / 5_040.0;
    p = p * x + 1.0 / 720.0;
    p = p * x + 1.0 / 120.0;
    p = p * x + 1.0 / 24.0;
    p = p * x + 1.0 / 6.0;
    p = p * x + 0.5;
    p = p * x + 1.0;
    p = p * x + 1.0;
    let p2 = p * p;
    let p4 = p2 * p2;
    let p8 = p4 * p4;
    p8 * p8
}

/// Default reference ice temperature of a surface's `mu`, degC: vehsim's default ice temperature,
/// at which the shipped ice examples state their mu 0.15.
pub const DEFAULT_REFERENCE_C: f64 = -3.0;

/// Reference sliding speed of a surface's `mu`, m/s (see the module docs).
pub(crate) const REFERENCE_SLIDING_MPS: f64 = 1.0;

/// The law as the car's tyre uses it: ratios to the reference conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceFriction {
    /// The law, with mu_ref = 1 and the surface's reference conditions.
    pub law: IceFriction,
    /// Ice temperature of the run it was built for, degC (each tyre's [`TempFactors`] keeps its
    /// factors there).
    ice_c: f64,
    /// n_v ln(1 + v_ref / v_c): the speed factor's logarithm at the reference, negated.
    ln_ref: f64,
    /// 1 / v_c, s/m.
    inv_vc: f64,
}

impl SurfaceFriction {
    /// The law with the default parameters ([`IceFriction::srtt`]) and reference conditions
    /// (`t_ref_c`, `REFERENCE_SLIDING_MPS`), built for a run on ice at `ice_c`.
    pub fn new(t_ref_c: f64, ice_c: f64) -> Self {
        let law = IceFriction { t_ref_c, v_ref_mps: REFERENCE_SLIDING_MPS, ..IceFriction::srtt(1.0) };
        Self::with_law(law, ice_c)
    }

    /// `law` (its mu_ref is ignored: the factor is a ratio; its adhesion peak is not applied, see
    /// the module docs) for a run on ice at `ice_c`.
    pub fn with_law(law: IceFriction, ice_c: f64) -> Self {
        let law = IceFriction { mu_ref: 1.0, peak_gain: 0.0, ..law };
        let inv_vc = 1.0 / law.speed_scale_mps;
        SurfaceFriction { law, ice_c, ln_ref: law.speed_exponent * (law.v_ref_mps * inv_vc).ln_1p(), inv_vc }
    }

    /// Temperature factor Phi_T(T) / Phi_T(T_ref).
    #[inline]
    pub fn temp_ratio(&self, t_c: f64) -> f64 {
        self.ln_temp_ratio(t_c).exp()
    }

    /// ln of [`Self::temp_ratio`]: -c_T (clamp(T) - clamp(T_ref)) (no exponential).
    #[inline]
    pub fn ln_temp_ratio(&self, t_c: f64) -> f64 {
        self.law.ln_temp_factor(t_c)
    }

    /// Speed factor Phi_v(v) / Phi_v(v_ref) = ((1 + v/v_c) / (1 + v_ref/v_c))^(-n_v), smooth in v
    /// (an interpolated table would put kinks into the vehicle's derivative); a non-finite or
    /// negative v counts as 0.
    #[inline]
    pub fn speed_ratio(&self, v_mps: f64) -> f64 {
        let v = if v_mps > 0.0 { v_mps.min(1e6) } else { 0.0 };
        exp_near_zero(self.ln_ref - self.law.speed_exponent * fast_ln(1.0 + v * self.inv_vc))
    }

    /// The sliding speed of a tyre input, m/s: |V_x| sqrt(kappa^2 + tan^2 alpha).
    #[inline]
    pub fn sliding_speed(i: &TyreInput) -> f64 {
        let t2 = super::fastmath::tan_sq(i.alpha_rad);
        let v = i.vx_mps.abs() * (i.kappa * i.kappa + t2).sqrt();
        if v.is_finite() {
            v
        } else {
            100.0
        }
    }

    /// The Magic Formula modifier at input `i`, given the temperature part as the pair
    /// (Phi_T ratio, Phi_T ratio ^ k_exp) (see `TempFactors`).
    // inline(always): left outlined (as `#[inline]` left it), the calls and the modifier's return
    // through memory cost about 30 instructions per tyre evaluation
    #[inline(always)]
    pub fn scale(&self, i: &TyreInput, phi_t: (f64, f64)) -> Scale {
        let mu = phi_t.0 * self.speed_ratio(Self::sliding_speed(i));
        Scale { mu_x: mu, k_x: phi_t.1, mu_y: mu, k_y: phi_t.1 }
    }
}

/// The temperature factor of one tyre, Phi_T ratio and its power k_exp (the tyre's
/// `stiffness_mu_exponent`), with the run's ice temperature precomputed: a `pacejka` tyre (law at
/// the ice temperature) pays no transcendental function for it per evaluation, an `atiim_pacejka`
/// tyre (law at the contact temperature) one exponential (two where k_exp is neither 0 nor 0.5).
#[derive(Debug, Clone, Copy, PartialEq)]
struct TempFactors {
    k_exp: f64,
    cached_t_c: f64,
    cached: (f64, f64),
}

impl TempFactors {
    fn new(surface: &SurfaceFriction, k_exp: f64) -> Self {
        let mut f = TempFactors { k_exp, cached_t_c: surface.ice_c, cached: (1.0, 1.0) };
        f.cached = f.compute(surface.ln_temp_ratio(surface.ice_c));
        f
    }

    #[inline]
    fn compute(&self, ln_phi: f64) -> (f64, f64) {
        let phi = exp_near_zero(ln_phi);
        let phi_k = if self.k_exp == 0.0 {
            1.0
        } else if self.k_exp == 0.5 {
            phi.sqrt()
        } else {
            exp_near_zero(self.k_exp * ln_phi)
        };
        (phi, phi_k)
    }

    #[inline(always)]
    fn at(&self, surface: &SurfaceFriction, t_c: f64) -> (f64, f64) {
        if t_c == self.cached_t_c {
            self.cached
        } else {
            self.compute(surface.ln_temp_ratio(t_c))
        }
    }
}

/// Product of two modifiers (both act as factors on the same scales).
#[inline]
fn times(a: &Scale, b: &Scale) -> Scale {
    Scale { mu_x: a.mu_x * b.mu_x, k_x: a.k_x * b.k_x, mu_y: a.mu_y * b.mu_y, k_y: a.k_y * b.k_y }
}

/// The Magic Formula provider under it.
#[derive(Debug, Clone, PartialEq)]
enum Base {
    /// Plain Magic Formula: the law at the ice temperature.
    Pacejka(PacejkaTyre),
    /// ATIIM-Pacejka: the law at the contact temperature, times the tyre's melt law.
    Atiim(AtiimPacejkaTyre),
}

/// A Magic Formula tyre on ice whose friction follows [`SurfaceFriction`] (see the module docs).
/// Its name is the base provider's, so outputs are labelled as before.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct IceSurfaceTyre {
    base: Base,
    surface: SurfaceFriction,
    temp: TempFactors,
}

impl IceSurfaceTyre {
    /// Plain Magic Formula `tyre` on `surface`.
    pub fn pacejka(tyre: PacejkaTyre, surface: SurfaceFriction) -> Self {
        let temp = TempFactors::new(&surface, tyre.stiffness_mu_exponent);
        IceSurfaceTyre { base: Base::Pacejka(tyre), surface, temp }
    }

    /// ATIIM-Pacejka `tyre` on `surface`.
    pub fn atiim(tyre: AtiimPacejkaTyre, surface: SurfaceFriction) -> Self {
        let temp = TempFactors::new(&surface, tyre.base.stiffness_mu_exponent);
        IceSurfaceTyre { base: Base::Atiim(tyre), surface, temp }
    }

    fn mf(&self) -> &PacejkaTyre {
        match &self.base {
            Base::Pacejka(p) => p,
            Base::Atiim(a) => &a.base,
        }
    }

    /// The combined modifier at input `i`.
    #[inline(always)]
    fn scale(&self, i: &TyreInput) -> Scale {
        match &self.base {
            Base::Pacejka(_) => self.surface.scale(i, self.temp.at(&self.surface, i.surface_temp_c)),
            Base::Atiim(a) => {
                times(&self.surface.scale(i, self.temp.at(&self.surface, i.contact_temp_c)), &a.law.scale_for(i))
            }
        }
    }
}

impl TyreModel for IceSurfaceTyre {
    fn name(&self) -> &'static str {
        match &self.base {
            Base::Pacejka(p) => p.name(),
            Base::Atiim(a) => a.name(),
        }
    }

    fn forces(&self, i: &TyreInput) -> TyreForces {
        self.mf().forces_scaled(i, &self.scale(i))
    }

    fn peak_friction(&self, i: &TyreInput) -> f64 {
        self.mf().peak_friction_scaled(i, &self.scale(i))
    }

    fn longitudinal_stiffness(&self, i: &TyreInput) -> f64 {
        self.mf().longitudinal_stiffness_scaled(i, &self.scale(i))
    }

    fn cornering_stiffness(&self, i: &TyreInput) -> f64 {
        self.mf().cornering_stiffness_scaled(i, &self.scale(i))
    }

    fn prepare(&self, i: &TyreInput) -> Prepared {
        self.mf().prepare_scaled(i)
    }

    fn forces_prepared(&self, prepared: &Prepared, i: &TyreInput) -> TyreForces {
        self.mf().forces_prepared_scaled(prepared, i, &self.scale(i))
    }

    fn peak_friction_prepared(&self, prepared: &Prepared, i: &TyreInput) -> f64 {
        self.mf().peak_friction_prepared_scaled(prepared, i, &self.scale(i))
    }

    fn peak_force_floor_prepared(&self, prepared: &Prepared, i: &TyreInput) -> Option<f64> {
        self.mf().peak_force_floor_prepared_scaled(prepared, i, &self.scale(i))
    }

    fn reports_departures(&self) -> bool {
        match &self.base {
            Base::Pacejka(p) => p.reports_departures(),
            Base::Atiim(a) => a.reports_departures(),
        }
    }

    fn departure(&self, i: &TyreInput) -> Option<(crate::event::EventKind, String)> {
        match &self.base {
            Base::Pacejka(p) => p.departure(i),
            Base::Atiim(a) => a.departure(i),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_is_one_at_reference_and_follows_the_law() {
        let s = SurfaceFriction::new(-3.0, -3.0);
        assert!((s.temp_ratio(-3.0) - 1.0).abs() < 1e-15);
        assert!((s.speed_ratio(REFERENCE_SLIDING_MPS) - 1.0).abs() < 1e-14);
        // the law's speed factor without its adhesion peak, across the range
        let bare = IceFriction { peak_gain: 0.0, ..s.law };
        let mut v = 2e-4;
        while v < 90.0 {
            let want = bare.speed_factor(v) / bare.speed_factor(1.0);
            assert!((s.speed_ratio(v) / want - 1.0).abs() < 1e-12, "{v}: {} {want}", s.speed_ratio(v));
            v *= 1.13;
        }
        // colder ice: more friction, down to the plateau; -20 vs -3 degC: exp(0.028 * 9)
        assert!((s.temp_ratio(-20.0) - (0.028f64 * 9.0).exp()).abs() < 1e-12);
        assert!(s.temp_ratio(-1.0) < 1.0 && s.temp_ratio(-5.0) > 1.0);
        // bad inputs stay finite
        assert!(s.speed_ratio(f64::NAN).is_finite() && s.speed_ratio(-1.0).is_finite());
        assert!(s.speed_ratio(1e300).is_finite() && s.temp_ratio(f64::NAN).is_finite());
    }

    #[test]
    fn exp_near_zero_matches_exp() {
        let mut a = -6.0;
        while a <= 6.0 {
            let (got, want) = (exp_near_zero(a), a.exp());
            assert!((got / want - 1.0).abs() < 1e-11, "{a}: {got} {want}");
            a += 0.001;
        }
        assert_eq!(exp_near_zero(0.0), 1.0);
        assert!(exp_near_zero(f64::NAN).is_nan() && exp_near_zero(-1e9) == 0.0);
    }

    #[test]
    fn sliding_speed_of_slip() {
        let mut i = TyreInput::new(4000.0, 0.1, 0.0, 0.15);
        i.vx_mps = 10.0;
        assert!((SurfaceFriction::sliding_speed(&i) - 1.0).abs() < 1e-12);
        i.kappa = 0.0;
        i.alpha_rad = 0.1;
        assert!((SurfaceFriction::sliding_speed(&i) - 10.0 * 0.1f64.tan()).abs() < 1e-12);
        i.alpha_rad = std::f64::consts::FRAC_PI_2;
        assert!(SurfaceFriction::sliding_speed(&i).is_finite());
    }
}
