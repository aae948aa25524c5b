//! Contact temperature: the per-step estimate of the tread/ice interface temperature.
//!
//! The engine calls a [`ContactTemperature`] once per step, after sampling the controllers and
//! before advancing the state, with the current operating conditions of every tyre; the estimate it
//! returns is held over the step and fills `TyreInput::contact_temp_c`. The Advanced Tire-Ice
//! Interface Model (dissertation chapter 4) lives in the submodules; [`Isothermal`] is the estimator
//! that does no heating (contact temperature = surface temperature).
//!
//! Submodules: [`patch`] (pressure grids), [`thermal`] (materials, Shore A), [`heat`] (temperature
//! rise), [`film`] (water film), [`model`] (the coupled patch solve), [`estimator`] (the
//! per-step [`ContactTemperature`] for the engine), [`tread_bulk`] (the tread band's
//! temperature over a rig run) and [`tread_state`] (the lumped tread heat balance of the vehicle's
//! `[lateral] tread_*` keys, another per-step estimate). The rubber-ice friction law they share with the car's tyre is
//! [`crate::tyre::friction`]; the `[contact]` table and scenario files are read by the spec layer,
//! and `vehsim atiim` is the application's.

pub mod estimator;
pub mod film;
pub mod heat;
pub mod model;
pub mod patch;
pub mod thermal;
pub mod tread_bulk;
pub mod tread_state;

/// Operating conditions of one tyre at the start of a step (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TyreContact {
    /// Normal load, N.
    pub fz_n: f64,
    /// Rolling speed omega R_e of the tread through the patch, m/s (>= 0).
    pub roll_speed_mps: f64,
    /// Sliding speed of the tread over the surface, m/s (>= 0); from slip ratio and slip angle.
    pub slide_speed_mps: f64,
    /// Magnitude of the friction force, N (so sliding power = force x slide speed).
    pub friction_force_n: f64,
    /// Bulk ice (surface) temperature, degC.
    pub surface_temp_c: f64,
}

/// A per-step contact-temperature estimator.
pub trait ContactTemperature: Send {
    /// Advance the estimate by `h` seconds under `tyres` (one entry per tyre of the vehicle model)
    /// and write each tyre's contact temperature, degC, into `out` (same length as `tyres`).
    fn update(&mut self, h: f64, tyres: &[TyreContact], out: &mut [f64]);

    /// Whether `update` reads the tyres' operating conditions (if not, the engine skips computing
    /// them; the surface temperature is still passed).
    fn needs_conditions(&self) -> bool {
        true
    }

    /// Advance the estimate by `h` seconds where the tyres' conditions depend on the contact
    /// temperatures themselves (the transmitted friction force does, through the tyre model):
    /// `conditions(temps, tyres)` fills `tyres` at trial contact temperatures `temps` (tyre i's
    /// conditions depending on `temps[i]` only), `guess` is the previous estimate. The output
    /// (into `out`) and the conditions left in `tyres` are the ones the update used. The default
    /// evaluates the conditions once, at `guess` (when `needs_conditions`), and calls `update`.
    fn update_coupled(
        &mut self,
        h: f64,
        guess: &[f64],
        conditions: &mut dyn FnMut(&[f64], &mut [TyreContact]),
        tyres: &mut [TyreContact],
        out: &mut [f64],
    ) {
        update_at_guess(self, h, guess, conditions, tyres, out);
    }
}

/// The uncoupled update of an estimate `c`: the tyres' conditions once, at the contact
/// temperatures `guess` (when `c` reads them), then [`ContactTemperature::update`]. The default
/// [`ContactTemperature::update_coupled`]; the ATIIM estimator's for more tyres than it solves
/// jointly.
pub(crate) fn update_at_guess<C: ContactTemperature + ?Sized>(
    c: &mut C,
    h: f64,
    guess: &[f64],
    conditions: &mut dyn FnMut(&[f64], &mut [TyreContact]),
    tyres: &mut [TyreContact],
    out: &mut [f64],
) {
    if c.needs_conditions() {
        conditions(guess, tyres);
    }
    c.update(h, tyres, out);
}

/// No heating: the contact temperature equals the surface temperature.
#[derive(Debug, Clone, Copy, Default)]
pub struct Isothermal;

impl ContactTemperature for Isothermal {
    fn update(&mut self, _h: f64, tyres: &[TyreContact], out: &mut [f64]) {
        for (o, t) in out.iter_mut().zip(tyres) {
            *o = t.surface_temp_c;
        }
    }

    fn needs_conditions(&self) -> bool {
        false
    }
}
