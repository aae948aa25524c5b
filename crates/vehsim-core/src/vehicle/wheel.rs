//! Wheel kinematics and wheel-spin torques shared by the vehicle models.
//!
//! Slip definitions (kappa > 0 when the wheel drives; alpha > 0 when the wheel centre moves to the
//! right of its heading, which makes a leftward, positive lateral force):
//! kappa = (omega R_e - V_x) / |V_x|, alpha = -atan(V_y / |V_x|), with V_x, V_y the wheel-centre
//! velocity in wheel axes. Near standstill |V_x| is floored at
//! [`V_LOW`] so nothing divides by zero; the longitudinal slip the tyre sees additionally lags
//! the kinematic one over the relaxation length sigma (first-order transient slip):
//!
//!   sigma d(kappa')/dt = (omega R_e - V_x) - max(|V_x|, V_LOW) kappa'
//!
//! whose steady state is the kinematic slip. This keeps the wheel-spin equations non-stiff at low
//! speed (the wheel/tyre pair becomes a spring of stiffness C_kappa / sigma instead of a damper
//! of rate C_kappa R^2 / (I |V_x|) that grows without bound as |V_x| -> 0).

/// Speed floor in slip denominators, m/s.
pub const V_LOW: f64 = 0.5;

/// Largest stiffness (1/s) of the regularised brake and rolling-resistance torques; sets their
/// regularisation speed so that RK4 stays stable for steps up to a few milliseconds.
pub const TORQUE_RATE_MAX: f64 = 400.0;

/// Velocity of a wheel centre in wheel axes, from its body-frame velocity (vx, vy) and steer angle.
#[inline]
pub(crate) fn to_wheel_axes(vx: f64, vy: f64, steer_rad: f64) -> (f64, f64) {
    let (s, c) = crate::tyre::fastmath::sin_cos(steer_rad);
    (vx * c + vy * s, -vx * s + vy * c)
}

/// Slip angle, rad, from wheel-axis velocities (the arctangent by [`crate::tyre::fastmath`]).
#[inline]
pub(crate) fn slip_angle(vxw: f64, vyw: f64) -> f64 {
    -crate::tyre::fastmath::atan(vyw / vxw.abs().max(V_LOW))
}

/// Kinematic slip ratio (what the relaxed slip tends to).
#[inline]
pub fn kinematic_slip(omega: f64, radius: f64, vxw: f64) -> f64 {
    (omega * radius - vxw) / vxw.abs().max(V_LOW)
}

/// Rate of the relaxed slip ratio kappa', 1/s.
#[inline]
pub(crate) fn relaxed_slip_rate(kappa: f64, omega: f64, radius: f64, vxw: f64, sigma: f64) -> f64 {
    ((omega * radius - vxw) - vxw.abs().max(V_LOW) * kappa) / sigma
}

/// The regularisation speed omega_1 (rad/s) of [`resisting_torque`] for the largest torque
/// `torque_max_nm` and spin inertia `inertia`: it depends only on the vehicle, so the models
/// compute it once ([`resisting_torque_at`]).
#[inline]
pub(crate) fn resisting_omega1(torque_max_nm: f64, inertia: f64) -> f64 {
    (1.5 * torque_max_nm / (inertia * TORQUE_RATE_MAX)).max(1e-3)
}

/// [`resisting_torque`] with its regularisation speed `omega1` ([`resisting_omega1`]) given.
#[inline]
pub(crate) fn resisting_torque_at(torque_nm: f64, omega1: f64, omega: f64) -> f64 {
    let u = omega / omega1;
    if u >= 1.0 {
        torque_nm
    } else if u <= -1.0 {
        -torque_nm
    } else {
        torque_nm * 0.5 * u * (3.0 - u * u)
    }
}

/// Sliding speed of the tread over the surface, m/s, from slip ratio and slip angle at rolling
/// speed `vxw` (dissertation eq. 2.12: |V| sqrt(s^2 + sin^2 alpha) form). Speeds and slips are
/// far from overflow, so the plain root serves (`hypot` is several times slower).
#[inline]
pub fn slide_speed(kappa: f64, alpha: f64, vxw: f64) -> f64 {
    let v = vxw.abs();
    let (sx, sy) = (v * kappa, v * crate::tyre::fastmath::tan(alpha).clamp(-1e3, 1e3));
    (sx * sx + sy * sy).sqrt()
}
