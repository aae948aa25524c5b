//! Friction laws of the patch model: viscous film friction (eq. 4.11–4.13), friction versus film
//! height (eq. 2.1), the tread-brush adhesion stress, and sliding power under severe slip
//! (eq. 2.12 = 4.15). Pure functions, SI units.
//!
//! Eq. 4.14, 4.16 and 4.17 (heat generated inside the tread, decaying exponentially with depth,
//! with an in-tread share eps) are not used as such: the patch model puts all frictional heat at
//! the interface (assumptions 2, 3, 9) and splits it between tread and ice by effusivity, which
//! gives eps directly (`heat::tread_fraction`). Eq. 4.16 also reuses S for both slip and area
//! (erratum 4).

/// Viscous friction coefficient of a film (eq. 4.13): mu = kappa eta v / (p h), written with the
/// time-average of 1/h over a pixel (`inv_h_mean`, 1/m) so that the h -> 0 onset stays integrable.
/// `kappa` 0–1, `eta_pa_s` water viscosity, `v_mps` sliding speed >= 0, `p_pa` > 0.
/// Returns 0 if p <= 0.
pub fn viscous_mu(kappa: f64, eta_pa_s: f64, v_mps: f64, p_pa: f64, inv_h_mean: f64) -> f64 {
    if p_pa > 0.0 && inv_h_mean.is_finite() {
        kappa * eta_pa_s * v_mps.abs() * inv_h_mean / p_pa
    } else {
        0.0
    }
}

/// Friction versus film height (eq. 2.1, Kulakowski & Harwood): mu = dmu exp(-beta h) + mu_f, with
/// dmu = mu_dry - mu_f so that mu(0) = mu_dry. `beta_per_m` from the critical height h_c at which
/// the excess friction has dropped to 25 %: beta = ln 4 / h_c (see [`beta_from_critical_height`]).
pub fn film_mu(mu_dry: f64, mu_f: f64, beta_per_m: f64, h_m: f64) -> f64 {
    (mu_dry - mu_f) * (-beta_per_m * h_m.max(0.0)).exp() + mu_f
}

/// beta = ln 4 / h_c, 1/m. `h_c_m` > 0 (tens of nm to a few µm).
pub fn beta_from_critical_height(h_c_m: f64) -> f64 {
    4f64.ln() / h_c_m.max(1e-12)
}

/// Shear stress of an adhering tread element, Pa: stiffness (Pa/m) x slip x distance from the
/// leading edge (brush model: deflection grows linearly through the adhesion zone).
pub fn brush_stress_pa(stiffness_pa_per_m: f64, slip: f64, xi_m: f64) -> f64 {
    stiffness_pa_per_m * slip.abs() * xi_m.max(0.0)
}

/// Sliding power under severe slip (eq. 2.12 / 4.15), W: (sin^2 alpha + s^2)^0.5 mu_d V F_z.
/// `alpha_rad` slip angle, `s` slip ratio magnitude (1 = locked), `mu_d` sliding friction,
/// `v_mps` travel speed, `fz_n` load.
pub fn sliding_power_w(alpha_rad: f64, s: f64, mu_d: f64, v_mps: f64, fz_n: f64) -> f64 {
    severe_slip_factor(alpha_rad, s) * mu_d * v_mps.abs() * fz_n
}

/// (sin^2 alpha + s^2)^0.5: the sliding speed over the travel speed implied by eq. 2.12.
pub fn severe_slip_factor(alpha_rad: f64, s: f64) -> f64 {
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
    fn locked_wheel_power_is_mu_v_fz() {
        assert!((sliding_power_w(0.0, 1.0, 0.15, 10.0, 7000.0) - 10500.0).abs() < 1e-9);
    }
}
