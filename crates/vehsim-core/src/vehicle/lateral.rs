//! The lateral extensions of a vehicle model that `vehsim discover` can name, as pure functions
//! shared by the engine's bicycle model (`[lateral]` section, [`super::bicycle`]) and the
//! discovery's replay model (`vehsim::discover::model`), so that both integrate the same equations
//! (the body equations they share are in [`super::single_track`]).
//!
//! Sign conventions (ISO 8855): lateral forces positive to the left, the yaw rate r positive
//! turning left, so vx r > 0 in a left turn, which loads the right (outer) tyres.

use crate::tyre::{TyreForces, TyreInput, TyreSide};

/// Floor on |vx| in the lateral relaxation rate, m/s (keeps a relaxed force decaying at rest).
pub(crate) const V_RELAX_MPS: f64 = 1.0;
/// Floor of the thermal friction factor (keeps friction positive for large rises).
pub(crate) const THERMAL_FLOOR: f64 = 0.1;
/// Damped fixed-point iterations of the steer compliance ([`compliant_steer`]).
pub(crate) const COMPLIANCE_ITERATIONS: usize = 4;

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

/// Quasi-static longitudinal load transfer, N per axle (front, rear): the tyres' longitudinal
/// forces act at the ground, `height_m` (m) below the CG, so their sum along the body's x axis
/// `sum_fx_n` (N, positive driving) pitches h S / L of load off the front axle onto the rear one
/// (L = `wheelbase_m`); braking (S < 0) loads the front. The weight and the road are not in S
/// (gravity acts at the CG; the grade's share is in the static loads), nor is the drag (taken at
/// the CG's height).
pub fn longitudinal_transfer_n(height_m: f64, sum_fx_n: f64, wheelbase_m: f64) -> [f64; 2] {
    let dz = height_m * sum_fx_n / wheelbase_m;
    [-dz, dz]
}

/// Normal loads of an axle's two tyres under a lateral load transfer, N, as
/// [(right, Fz + dz), (left, Fz - dz)]: `fz_tyre_n` is the static load of one tyre (N, >= 0),
/// `transfer_n` the axle's transfer ([`load_transfer_n`]; > 0 loads the right tyre) and dz the
/// transfer clamped to [-Fz, Fz], so a tyre's load never falls below 0 (the inner tyre lifts and
/// the outer one carries the whole axle, 2 Fz).
pub(crate) fn tyre_loads(fz_tyre_n: f64, transfer_n: f64) -> [(TyreSide, f64); 2] {
    let dz = transfer_n.clamp(-fz_tyre_n, fz_tyre_n);
    [(TyreSide::Right, fz_tyre_n + dz), (TyreSide::Left, fz_tyre_n - dz)]
}

/// Force of an axle's two tyres (wheel axes, N and N m, summed): each tyre at its own load from
/// `tyre_loads`, the right one first; `tyre(side, fz)` evaluates the tyre on `side` at load
/// `fz` (N, > 0). A lifted tyre (load 0) carries nothing and is not evaluated.
pub fn axle_forces(fz_tyre_n: f64, transfer_n: f64, mut tyre: impl FnMut(TyreSide, f64) -> TyreForces) -> TyreForces {
    let mut sum = TyreForces::default();
    for (side, fz) in tyre_loads(fz_tyre_n, transfer_n) {
        if fz > 0.0 {
            let t = tyre(side, fz);
            sum.fx_n += t.fx_n;
            sum.fy_n += t.fy_n;
            sum.mz_nm += t.mz_nm;
        }
    }
    sum
}

/// Effective road-wheel angle under steer compliance, rad: delta_e = delta - c Fy_f, with the
/// steer `delta_rad` (rad, positive left), the compliance `c_rad_per_n` (rad/N: the spec's rad/kN
/// x 1e-3) and the front axle lateral force `fy_front_n` (N, wheel axes, positive left) that
/// turns the wheels back. Used as it is when that force is known beforehand (a relaxed force or
/// the force at lagged slip angles, a state); [`compliant_steer`] solves it otherwise.
pub fn effective_steer(delta_rad: f64, c_rad_per_n: f64, fy_front_n: f64) -> f64 {
    delta_rad - c_rad_per_n * fy_front_n
}

/// Steer compliance with the steady-state front force: the fixed point delta_e = delta - c F(delta_e)
/// ([`effective_steer`]), where `at(delta_e)` evaluates the front axle at road-wheel angle delta_e
/// (rad) and `fy_front(&value)` reads its lateral force F (N). Damped iteration from F_0 = F(delta):
/// F_(k+1) = (F_k + F(delta - c F_k)) / 2, `COMPLIANCE_ITERATIONS` times (it converges for
/// c dF/d(delta) < 3; the damping halves the error at c dF/d(delta) = 1 and more below), then
/// delta_e = delta - c F_4. Returns delta_e and the front axle evaluated at it, so the force that
/// acts is the one at the steer it is reported with (not the damped iterate). c = 0 gives delta
/// and `at(delta)` with no iteration.
pub fn compliant_steer<T>(
    delta_rad: f64,
    c_rad_per_n: f64,
    mut at: impl FnMut(f64) -> T,
    fy_front: impl Fn(&T) -> f64,
) -> (f64, T) {
    if c_rad_per_n == 0.0 {
        return (delta_rad, at(delta_rad));
    }
    let mut f = fy_front(&at(delta_rad));
    for _ in 0..COMPLIANCE_ITERATIONS {
        let g = fy_front(&at(effective_steer(delta_rad, c_rad_per_n, f)));
        f = 0.5 * (f + g);
    }
    let delta_e = effective_steer(delta_rad, c_rad_per_n, f);
    (delta_e, at(delta_e))
}

/// Friction factor from contact heating: max(1 + k_T dT, `THERMAL_FLOOR`), with k_T in 1/K
/// (negative: friction falls) and dT the contact-temperature rise above the surface, K.
pub fn thermal_friction_factor(mu_per_k: f64, rise_k: f64) -> f64 {
    (1.0 + mu_per_k * rise_k).max(THERMAL_FLOOR)
}

/// Floor of a load-sensitivity factor ([`load_factor`]): a tyre keeps 5 % of its friction or
/// stiffness however far its load rises.
pub const LOAD_FACTOR_FLOOR: f64 = 0.05;
/// Floor on the ratio of the local to the initial tyre slope in the saturating transient-slip
/// form ([`saturating_relaxation_length`]).
pub const SLIP_SLOPE_FLOOR: f64 = 0.25;
/// Half-step of the central difference of an axle's lateral force in slip angle, rad, that the
/// saturating transient-slip form takes its local slope from.
pub const SLIP_SLOPE_STEP_RAD: f64 = 2e-3;

/// Load-sensitivity factor of one tyre: max(1 - k z, [`LOAD_FACTOR_FLOOR`]) with its relative
/// load change z = Fz / Fz0 - 1 (`fz_n` its load, `fz0_n` its static load, N, > 0) and the
/// sensitivity `k` (per unit of z; > 0: the property falls as the load rises). Friction and
/// cornering stiffness each take their own k (`lateral.load_sensitivity_mu`, `_stiffness`).
pub fn load_factor(k: f64, fz_n: f64, fz0_n: f64) -> f64 {
    (1.0 - k * (fz_n / fz0_n - 1.0)).max(LOAD_FACTOR_FLOOR)
}

/// A tyre's input under the fitted load sensitivities [k_mu, k_c] at its load `input.fz_n`
/// against the static tyre load `fz0_n` (N): the slip angle scaled by the stiffness factor and the
/// surface friction by the friction factor ([`load_factor`]).
pub fn load_sensitive_input(input: TyreInput, fz0_n: f64, [k_mu, k_c]: [f64; 2]) -> TyreInput {
    TyreInput {
        alpha_rad: input.alpha_rad * load_factor(k_c, input.fz_n, fz0_n),
        mu_surface: input.mu_surface * load_factor(k_mu, input.fz_n, fz0_n),
        ..input
    }
}

/// Relaxation length of the saturating transient-slip form, m: the nominal `sigma_m` times the
/// ratio of the axle force's local slope dFy/dalpha to its slope at alpha = 0 (`slope_ratio`),
/// clamped to [[`SLIP_SLOPE_FLOOR`], 1] (a string model's relaxation length is the cornering
/// stiffness over the carcass stiffness, so it shortens as the tyre saturates); the nominal length
/// when the ratio is not finite.
pub fn saturating_relaxation_length(sigma_m: f64, slope_ratio: f64) -> f64 {
    let ratio = slope_ratio.clamp(SLIP_SLOPE_FLOOR, 1.0);
    if ratio.is_finite() {
        sigma_m * ratio
    } else {
        sigma_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The load split keeps the axle load, clamps at lift-off, and the fixed point satisfies its
    /// equation for a linear force law (F = C (delta - beta): closed form delta_e =
    /// (delta + c C beta) / (1 + c C)).
    #[test]
    fn load_split_and_compliance_follow_their_closed_forms() {
        for (dz, right, left) in [(300.0, 4300.0, 3700.0), (-300.0, 3700.0, 4300.0), (5000.0, 8000.0, 0.0)] {
            let [(sr, r), (sl, l)] = tyre_loads(4000.0, dz);
            assert_eq!((sr, sl), (TyreSide::Right, TyreSide::Left));
            assert_eq!((r, l), (right, left));
        }
        let mut n = 0;
        let f = axle_forces(4000.0, -9000.0, |side, fz| {
            n += 1;
            assert_eq!((side, fz), (TyreSide::Left, 8000.0));
            TyreForces { fx_n: 1.0, fy_n: 2.0, mz_nm: 3.0 }
        });
        assert_eq!((n, f), (1, TyreForces { fx_n: 1.0, fy_n: 2.0, mz_nm: 3.0 }));
        let (cs, beta, delta, c) = (30_000.0, 0.01, 0.05, 2e-6);
        let (de, fy) = compliant_steer(delta, c, |d| cs * (d - beta), |f| *f);
        let exact = (delta + c * cs * beta) / (1.0 + c * cs);
        // The damped map is linear here: the force error shrinks by q = (1 - c C) / 2 per
        // iteration from F_0 - F* = C (delta - delta_e*), so delta_e = delta_e* - c q^4 (F_0 - F*).
        let q = (1.0 - c * cs) / 2.0;
        let predicted = exact - c * q.powi(4) * cs * (delta - exact);
        assert!((de - predicted).abs() < 1e-15, "{de} vs {predicted} (converged {exact})");
        assert!((de - exact).abs() < 0.05 * (delta - exact).abs());
        assert_eq!(fy, cs * (de - beta));
        assert_eq!(compliant_steer(delta, 0.0, |d| d, |f| *f), (delta, delta));
    }
}
