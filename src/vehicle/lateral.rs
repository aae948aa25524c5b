//! The lateral extensions of a vehicle model that `vehsim discover` can name, as pure functions
//! shared by the engine's bicycle model (`[lateral]` section, [`super::bicycle`]) and the
//! discovery's replay model (`crate::discover::model`), so that both integrate the same equations.

/// Floor on |vx| in the lateral relaxation rate, m/s (keeps a relaxed force decaying at rest).
pub const V_RELAX_MPS: f64 = 1.0;
/// Floor of the thermal friction factor (keeps friction positive for large rises).
pub const THERMAL_FLOOR: f64 = 0.1;

/// Rate of a relaxed lateral force, 1/s: dFy/dt = rate (Fy_ss - Fy), with relaxation length
/// `sigma_m` (m, > 0) at forward speed `vx_mps` (m/s).
pub fn relaxation_rate(vx_mps: f64, sigma_m: f64) -> f64 {
    vx_mps.abs().max(V_RELAX_MPS) / sigma_m
}

/// Quasi-static lateral load transfer of one axle, N (added to the outer tyre, taken from the
/// inner): m vx r h / track x `axle_share` (the axle's share of the static weight). `vx r` is
/// the steady-state lateral acceleration (m/s^2; > 0 turning left, loading the right tyres).
pub fn load_transfer_n(mass_kg: f64, vx_mps: f64, r_radps: f64, height_m: f64, track_m: f64, axle_share: f64) -> f64 {
    mass_kg * vx_mps * r_radps * height_m / track_m * axle_share
}

/// Friction factor from contact heating: max(1 + k_T dT, [`THERMAL_FLOOR`]), with k_T in 1/K
/// (negative: friction falls) and dT the contact-temperature rise above the surface, K.
pub fn thermal_friction_factor(mu_per_k: f64, rise_k: f64) -> f64 {
    (1.0 + mu_per_k * rise_k).max(THERMAL_FLOOR)
}
