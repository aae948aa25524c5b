//! The lateral equations of the single-track (bicycle) body, as pure functions shared by the
//! engine's bicycle model ([`super::bicycle`]) and the discovery's replay model
//! (`vehsim::discover::model`), so that both integrate the same equations.
//!
//! Body frame, ISO 8855: x forward, y left, z up; vy (m/s) positive to the left, the yaw rate r
//! (rad/s) and yaw moments (N m) positive counter-clockwise seen from above. The front axle is
//! steered by the road-wheel angle delta (rad, positive left) and its forces are given in its
//! wheel axes; the rear axle is not steered (wheel axes = body axes). With a, b the CG to front and
//! rear axle distances (m):
//!
//!   m (dvy/dt + r vx) = Fx_f sin(delta) + Fy_f cos(delta) + Fy_r
//!   I_z dr/dt         = a (Fx_f sin(delta) + Fy_f cos(delta)) - b Fy_r + Mz_f + Mz_r

use crate::tyre::TyreForces;

/// Lateral force (N) and yaw moment (N m) on the body from the front axle's forces `front`
/// (wheel axes, steered by delta with `cos_d`, `sin_d` = cos, sin of delta), the rear axle's
/// `rear` (body axes; its Fx has no lateral or yaw effect) and the CG to axle distances `a_m`,
/// `b_m` (m): Fy = Fx_f sin(delta) + Fy_f cos(delta) + Fy_r and
/// Mz = a (Fx_f sin(delta) + Fy_f cos(delta)) - b Fy_r + Mz_f + Mz_r.
#[inline]
pub fn lateral_loads(front: &TyreForces, rear: &TyreForces, cos_d: f64, sin_d: f64, a_m: f64, b_m: f64) -> (f64, f64) {
    let fyf_body = front.fx_n * sin_d + front.fy_n * cos_d;
    (fyf_body + rear.fy_n, a_m * fyf_body - b_m * rear.fy_n + front.mz_nm + rear.mz_nm)
}

/// dvy/dt (m/s^2) and dr/dt (rad/s^2) of the body of mass `mass_kg` (kg) and yaw inertia
/// `yaw_inertia_kgm2` (kg m^2) at forward speed `vx_mps` (m/s) and yaw rate `r_radps` (rad/s)
/// under the lateral force `fy_n` (N) and yaw moment `mz_nm` (N m) of [`lateral_loads`]:
/// dvy/dt = Fy / m - r vx, dr/dt = Mz / I_z.
#[inline]
pub fn lateral_rates(
    mass_kg: f64,
    yaw_inertia_kgm2: f64,
    vx_mps: f64,
    r_radps: f64,
    fy_n: f64,
    mz_nm: f64,
) -> (f64, f64) {
    (fy_n / mass_kg - r_radps * vx_mps, mz_nm / yaw_inertia_kgm2)
}
