//! Tyre-force providers behind one trait.
//!
//! Conventions (ISO 8855, wheel axes):
//! - x along the wheel heading, y to the left, z up. Forces act on the tyre from the road.
//! - Slip ratio `kappa = (omega R_e - V_x) / |V_x|`: positive when driving, -1 at a locked wheel.
//! - Slip angle `alpha = -atan(V_y / |V_x|)` with V_y the lateral velocity of the wheel centre in
//!   wheel axes, so a positive alpha gives a positive (leftward) lateral force.
//! - Contact temperature: `contact_temp_c` is the estimated tread/ice interface temperature in degC;
//!   `surface_temp_c` is the bulk ice (or road) surface temperature. Their difference is the
//!   contact-temperature rise Delta-T that the ATIIM-modified providers use. Without a contact
//!   estimator both are equal.
//!
//! Providers (selected by [`TyreModelKind`]): [`linear`], [`polynomial`] (brush), [`pacejka`]
//! (MF 5.2 / PAC2002; `.tir` files are read by the spec layer), [`dugoff`] (plain and thermal),
//! [`atiim`] (the ATIIM modifier on top of the Magic Formula). [`combine`] holds the shared curve
//! and friction-ellipse pieces, [`friction`] the rubber-ice friction law, [`ice`] the car tyre's
//! friction from that law, [`ranges`] the ranges a tyre's data declares. Equations and
//! conventions: docs/tyres.md.
//!
//! Every provider must be finite and continuous for kappa in [-1, 10], alpha in [-pi/2, pi/2] and
//! load in [0, 3 Fz_nominal], give zero force at zero load, and bound combined slip with a friction
//! ellipse or the Magic Formula combined-slip functions.

pub mod atiim;
pub mod combine;
pub mod dugoff;
pub mod fastmath;
pub mod friction;
pub mod ice;
pub mod kind;
pub mod linear;
pub mod mounted;
pub mod pacejka;
pub mod polynomial;
pub mod ranges;

pub use atiim::{AtiimPacejkaTyre, KShift};
pub use dugoff::{DugoffThermalTyre, DugoffTyre};
pub use kind::TyreModelKind;
pub use linear::LinearTyre;
pub use mounted::Tyre;
pub use pacejka::{PacejkaTyre, TyreSide};
pub use polynomial::PolynomialTyre;

/// Everything a provider may use to compute the force of one tyre at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TyreInput {
    /// Normal load on the tyre, N (>= 0; a lifted wheel has 0).
    pub fz_n: f64,
    /// Longitudinal slip ratio, dimensionless (see module docs).
    pub kappa: f64,
    /// Slip angle, rad (see module docs).
    pub alpha_rad: f64,
    /// Camber (inclination) angle, rad, positive when the top of the wheel leans to the vehicle's left.
    pub camber_rad: f64,
    /// Forward speed of the wheel centre in wheel axes, m/s (>= 0 in forward driving).
    pub vx_mps: f64,
    /// Peak friction coefficient of the surface (dry asphalt ~1.0, ice 0.05–0.2).
    pub mu_surface: f64,
    /// Bulk surface (ice) temperature, degC.
    pub surface_temp_c: f64,
    /// Estimated contact-patch temperature, degC (equals `surface_temp_c` without heating).
    pub contact_temp_c: f64,
}

impl TyreInput {
    /// A pure-slip input on a surface of friction `mu` at 0 degC with no heating and no camber.
    pub fn new(fz_n: f64, kappa: f64, alpha_rad: f64, mu_surface: f64) -> Self {
        Self {
            fz_n,
            kappa,
            alpha_rad,
            camber_rad: 0.0,
            vx_mps: 10.0,
            mu_surface,
            surface_temp_c: 0.0,
            contact_temp_c: 0.0,
        }
    }

    /// Contact-temperature rise above the surface, K.
    pub fn delta_t_k(&self) -> f64 {
        self.contact_temp_c - self.surface_temp_c
    }
}

/// Forces and moment of one tyre, wheel axes, N and N m.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TyreForces {
    /// Longitudinal force, N (positive forward).
    pub fx_n: f64,
    /// Lateral force, N (positive left).
    pub fy_n: f64,
    /// Aligning moment about z, N m (positive counter-clockwise seen from above); 0 where not modelled.
    pub mz_nm: f64,
}

/// Coefficients of a provider prepared for one load and set of conditions
/// ([`TyreModel::prepare`]): what does not depend on the slips, computed once instead of at every
/// evaluation (a vehicle model with static loads prepares each tyre once per run), and what
/// depends neither on the slips nor on the load (a model with load transfer prepares it once per
/// surface). The load-dependent part is valid for inputs with the load, friction and camber of
/// [`Prepared::input`] ([`Prepared::matches_load`]), the load-independent part for inputs with its
/// friction and camber ([`Prepared::matches_surface`]); the temperatures are not prepared (the
/// ATIIM modifier is applied per input). A `Prepared` belongs to the provider instance that made it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prepared {
    /// The input it was prepared for (its slips and speed are not used).
    pub input: TyreInput,
    /// The Magic Formula's pure-slip coefficients at the input's load, for the providers built on it.
    pub(crate) pacejka: Option<pacejka::Pure>,
    /// The Magic Formula's load-independent coefficients on the input's surface.
    pub(crate) surface: Option<pacejka::Surface>,
}

impl Prepared {
    /// Nothing prepared (the providers that have nothing to prepare).
    pub fn none(input: &TyreInput) -> Self {
        Prepared { input: *input, pacejka: None, surface: None }
    }

    /// Whether `i` has the load, friction, camber and temperatures this was prepared for.
    #[inline]
    pub fn matches(&self, i: &TyreInput) -> bool {
        self.matches_load(i)
            && (self.input.surface_temp_c, self.input.contact_temp_c) == (i.surface_temp_c, i.contact_temp_c)
    }

    /// Whether `i` has the load, friction and camber this was prepared for.
    #[inline]
    pub fn matches_load(&self, i: &TyreInput) -> bool {
        self.input.fz_n == i.fz_n && self.matches_surface(i)
    }

    /// Whether `i` has the friction and camber this was prepared for (any load).
    #[inline]
    pub fn matches_surface(&self, i: &TyreInput) -> bool {
        (self.input.mu_surface, self.input.camber_rad) == (i.mu_surface, i.camber_rad)
    }
}

/// A tyre-force provider. Implementations are pure: the same input gives the same output.
pub trait TyreModel: Send + Sync + std::fmt::Debug {
    /// Short name as used in spec files (`linear`, `pacejka`, ...).
    fn name(&self) -> &'static str;

    /// Forces for one input.
    fn forces(&self, input: &TyreInput) -> TyreForces;

    /// The bound on |F| / Fz this provider guarantees for this input (peak friction coefficient);
    /// `f64::INFINITY` for a provider with no bound (the unsaturated linear tyre).
    fn peak_friction(&self, input: &TyreInput) -> f64;

    /// dFx/dkappa at zero slip for this input's load and conditions, N per unit slip.
    fn longitudinal_stiffness(&self, input: &TyreInput) -> f64;

    /// dFy/dalpha at zero slip for this input's load and conditions, N/rad.
    fn cornering_stiffness(&self, input: &TyreInput) -> f64;

    /// Prepare the coefficients that depend on `input`'s load and conditions but not on its slips.
    /// Default: nothing to prepare.
    fn prepare(&self, input: &TyreInput) -> Prepared {
        Prepared::none(input)
    }

    /// [`Self::forces`] of `input` using what `prepared` (made by this instance's
    /// [`Self::prepare`]) holds for it, the same values bit for bit; an input the prepared
    /// coefficients do not [match](Prepared::matches_surface) is evaluated in full.
    /// Default: [`Self::forces`].
    fn forces_prepared(&self, _prepared: &Prepared, input: &TyreInput) -> TyreForces {
        self.forces(input)
    }

    /// [`Self::peak_friction`] of `input` using what `prepared` (made by this instance's
    /// [`Self::prepare`]) holds for it, the same value bit for bit (an input it does not match is
    /// evaluated in full). Default: [`Self::peak_friction`].
    fn peak_friction_prepared(&self, _prepared: &Prepared, input: &TyreInput) -> f64 {
        self.peak_friction(input)
    }

    /// A lower bound (N) of [`Self::peak_friction_prepared`] times the load at `input`, when the
    /// provider has one far cheaper than the bound itself (`None`: it has none for this input).
    /// For checks that only need to know a force is well within the bound. Default: `None`.
    fn peak_force_floor_prepared(&self, _prepared: &Prepared, _input: &TyreInput) -> Option<f64> {
        None
    }

    /// This provider on an ice surface whose friction follows `law` (`ice::IceSurfaceTyre`), or
    /// `None` for a provider that keeps its `mu` fixed. Default: `None`.
    fn on_ice(&self, _law: &ice::SurfaceFriction) -> Option<std::sync::Arc<dyn TyreModel>> {
        None
    }

    /// Whether [`Self::departure`] can report anything for this provider (false: the vehicle
    /// models need not ask). Default: false.
    fn reports_departures(&self) -> bool {
        false
    }

    /// Where the provider departs from its published law at this input, as (event kind, detail):
    /// thermal Dugoff where the published H would reverse Fx and is clamped. Pure, like
    /// [`Self::forces`]; the vehicle models ask it per tyre at every step and the engine reports
    /// each kind once per run, at the first step it holds ([`crate::vehicle::capability::Monitored::notes`]).
    /// It does not change any force. Default: none.
    fn departure(&self, _i: &TyreInput) -> Option<(crate::event::EventKind, String)> {
        None
    }
}

/// Test support: the SRTT Magic Formula of the shipped `.tir` file, embedded at compile time and
/// read by a minimal `NAME = value $ comment` scan (the file is SI and well formed; the spec
/// layer's reader, with units and validation, is not needed here), dry reference mu 1, slip
/// stiffness exponent 0.5, MF combination, no aligning moment.
#[cfg(test)]
pub(crate) fn srtt_for_tests() -> PacejkaTyre {
    const TIR: &str = include_str!("../../../../vehicles/tyres/srtt_p225_60r16.tir");
    let get = |name: &str| {
        TIR.lines().find_map(|l| {
            let (k, v) = l.split_once('=')?;
            let v = v.split('$').next()?.trim();
            (k.trim() == name).then(|| v.parse::<f64>().ok()).flatten()
        })
    };
    let mut missing = Vec::new();
    let coeffs = pacejka::MfCoefficients::from_lookup(get, &mut missing);
    assert!(missing.is_empty(), "{missing:?}");
    PacejkaTyre::new(coeffs, 1.0, 0.5, None, false)
}
