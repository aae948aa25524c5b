//! Surface temperature rise under the moving frictional heat source (Jaeger's band source,
//! dissertation §4.1.1, with erratum 1), discretized as a Duhamel sum along each track.
//!
//! In the frame of the contact patch, the ice (and, when rolling, the tread) passes through the
//! patch at the transit speed V, so a surface point at distance x behind the leading edge has been
//! heated for t = x / V. At road speeds the Peclet number V L / a is of order 1e5–1e6, so heat
//! conducts essentially only normal to the surface (the lateral and longitudinal terms of the
//! point-source kernel of erratum 1 integrate to 1 over a track): each surface point is a 1-D
//! semi-infinite solid with a time-varying surface flux q(t), whose surface temperature rise is
//!
//!   dT(t) = 1 / (e sqrt(pi)) * integral_0^t q(tau) / sqrt(t - tau) dtau,   e = sqrt(k rho c).
//!
//! Two bodies in perfect contact (assumption 5: no interface resistance) with the same contact
//! time share the flux in the ratio of their effusivities and rise by dT = (that integral) /
//! (e_tread + e_ice); for uniform flux dT = 2 q sqrt(t / pi) / (e_tread + e_ice).
//! If the tread's contact time t_t differs from the ice's t_i (locked wheel: the tread stays in the
//! patch for the lock duration while the ice passes), the tread acts with e_tread sqrt(t_i / t_t)
//! (Blok's partition); that is exact for constant flux and used pixel by pixel here.
//!
//! Piecewise-constant flux per pixel (duration dt = dx / V) gives the Duhamel weights
//! sqrt(m + 1) - sqrt(m); the sum is exact at pixel ends for any piecewise-constant flux.
//! The lateral (nearest-neighbour) contribution of assumption 6/12 is not included: its range,
//! sqrt(a_ice t) ~ 0.1 mm at t = 10 ms, is far below a pixel width (1–5 mm).

/// Duhamel weights `w[m] = sqrt(m + 1) - sqrt(m)`, m = 0..n (dimensionless; multiply by sqrt(dt)).
pub(crate) fn duhamel_weights(n: usize) -> Vec<f64> {
    (0..n).map(|m| ((m + 1) as f64).sqrt() - (m as f64).sqrt()).collect()
}

/// Centre weights: contribution of pixel k to the rise at the centre of pixel i = k + m:
/// `c[0] = sqrt(1/2)`, `c[m] = sqrt(m + 1/2) - sqrt(m - 1/2)`.
pub(crate) fn centre_weights(n: usize) -> Vec<f64> {
    (0..n).map(|m| if m == 0 { 0.5f64.sqrt() } else { (m as f64 + 0.5).sqrt() - (m as f64 - 0.5).sqrt() }).collect()
}

/// Effective effusivity of the tread + ice pair, W s^0.5/(m^2 K):
/// e_ice + e_tread sqrt(t_ice / t_tread). `t_ice_s`, `t_tread_s` > 0 (equal when rolling).
pub(crate) fn effective_effusivity(e_tread: f64, e_ice: f64, t_ice_s: f64, t_tread_s: f64) -> f64 {
    let r = if t_tread_s > 0.0 && t_ice_s > 0.0 { (t_ice_s / t_tread_s).sqrt() } else { 1.0 };
    e_ice + e_tread * r
}

/// Fraction of the interface flux that enters the tread (the eps of eq. 4.17):
/// e_tread sqrt(t_i/t_t) / e_eff. Typically 0.25 (rolling) to < 0.1 (locked wheel).
pub fn tread_fraction(e_tread: f64, e_ice: f64, t_ice_s: f64, t_tread_s: f64) -> f64 {
    let e = effective_effusivity(e_tread, e_ice, t_ice_s, t_tread_s);
    (e - e_ice) / e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_telescope_to_sqrt_n() {
        let w = duhamel_weights(50);
        let s: f64 = w.iter().sum();
        assert!((s - 50f64.sqrt()).abs() < 1e-12);
        let c = centre_weights(50);
        let s: f64 = c.iter().sum();
        assert!((s - 49.5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn tread_fraction_is_effusivity_share_when_rolling() {
        let f = tread_fraction(700.0, 2100.0, 0.01, 0.01);
        assert!((f - 0.25).abs() < 1e-12);
        assert!(tread_fraction(700.0, 2100.0, 0.01, 1.0) < 0.05);
    }
}
