//! What only some vehicle models offer, and only some integrators or controllers use: each is a
//! capability a model hands out through its [`VehicleModel`](super::VehicleModel) accessor
//! (`spin_slip`, `lags`, `monitor`, `wheel_speeds`, `prescribed`), `None` when it has none.
//!
//! - [`SpinSlip`]: the stiff wheel-spin / transient-slip pairs that
//!   [`crate::sim::Method::Rk4Exp`] integrates exactly (bicycle, 4-DOF).
//! - [`Lagged`]: first-order lag components that [`crate::sim::Method::Rk4Lag`] relaxes exactly
//!   (the discovery replay).
//! - [`Monitored`]: unphysical conditions and one-off notes the engine reports (tyre departures;
//!   wheel lift on the 4-DOF model).
//! - [`WheelSpeeds`]: the wheel-speed sensors of ABS and traction control.
//! - [`Prescribed`]: components set from outside the equations after every step (the replay's
//!   measured speed); such a model's run is not ended by a spin-out.

use nalgebra::SVector;

use super::{Condition, Environment, Inputs, WheelSensor};
use crate::contact::TyreContact;
use crate::event::EventKind;

/// Most first-order lag components a model can declare ([`Lagged`]).
pub const MAX_LAGS: usize = 8;

/// The stiff wheel-spin / transient-slip pairs of a model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinSlip {
    /// (omega index, relaxed-slip index) per wheel or axle.
    pub pairs: &'static [(usize, usize)],
    /// d(dkappa/dt)/d(omega) = R_e / sigma, m/m (see [`super::wheel`]), the same for every pair.
    pub kappa_per_omega: f64,
}

/// A model whose state has first-order lag components dy_j/dt = k_j (u_j - y_j).
pub trait Lagged<const N: usize> {
    /// The lag components' indices (at most [`MAX_LAGS`]).
    fn lag_states(&self) -> &[usize];

    /// The derivative of the state with the lag components' entries left out (their values are
    /// not used where the lag's rate is positive), and each lag's input u_j in
    /// [`Self::lag_states`] order; with `contacts`, also the tyres' contact conditions (as
    /// [`super::Extras::contacts`]). With the rates of [`Self::lag_rates`], the model's derivative
    /// must equal it with entry j replaced by k_j (u_j - y_j) wherever k_j > 0.
    fn lag_split(
        &self,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        contacts: Option<&mut [TyreContact]>,
    ) -> (SVector<f64, N>, [f64; MAX_LAGS]);

    /// The lag rates k_j (1/s) at state `x`, in [`Self::lag_states`] order (0: the component is
    /// integrated like any other).
    fn lag_rates(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment) -> [f64; MAX_LAGS];
}

/// A model that reports unphysical conditions and one-off notes.
pub trait Monitored<const N: usize> {
    /// Push the unphysical conditions this model watches, evaluated at state `x` under inputs
    /// `u`, onto `out`: the same conditions in the same order at every call (the engine reports
    /// when one starts or stops holding).
    fn conditions(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, out: &mut Vec<Condition>);

    /// Push the one-off notes of state `x` under inputs `u` as (event kind, detail): the tyres'
    /// departures from their published laws ([`crate::tyre::TyreModel::departure`]), with the
    /// tyre named in the detail. The engine reports each kind once per run, at the first state
    /// that shows it (step resolution).
    fn notes(&self, x: &SVector<f64, N>, u: &Inputs, env: &Environment, out: &mut Vec<(EventKind, String)>);
}

/// A model with wheel-speed sensors for the slip controllers.
pub trait WheelSpeeds<const N: usize> {
    /// The sensors at state `x` with road-wheel angle `steer_rad`, into `out`; returns how many
    /// wheels (2 for the bicycle's axles, 4 for four wheels).
    fn wheel_sensors(&self, x: &SVector<f64, N>, steer_rad: f64, out: &mut [WheelSensor; 4]) -> usize;
}

/// A model with components prescribed from outside its equations.
pub trait Prescribed<const N: usize> {
    /// Map the state at the end of every accepted step, at time `t_s`, onto the model's
    /// admissible set (prescribed components, bounds the equations do not keep by themselves).
    fn project(&self, t_s: f64, x: &mut SVector<f64, N>);
}
