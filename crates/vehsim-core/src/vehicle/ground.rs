//! Friction regions on the ground: a disc (patch) and a band across X, each scaling the surface
//! friction by 1 + (s - 1) w with w a window of 1 inside it and logistic edges of [`EDGE_M`], so
//! that friction changes continuously. A region acts on each axle at that axle's own ground
//! position (X + l cos psi, Y + l sin psi; l = a for the front axle, -b for the rear), so the
//! front axle meets it first. A stretch is the same window along the distance the CG has
//! travelled since the start (the integral of its forward speed, m; `Inputs::distance_m`), on
//! both axles at once: the form `vehsim discover` fits where a run has no logged position. The engine's bicycle reads them from the manoeuvre's `[surface]`
//! ([`super::Environment::regions`]); `vehsim discover`'s replay fits and reads the same ones.
//!
//! Ground frame (ISO 8855): X, Y in m, the manoeuvre's start at the origin heading +X.

/// The allowed ranges of a region's keys (`[[surface.patch]]`, `[[surface.band]]` of a manoeuvre
/// and of a measured run's sidecar, `[[surface.stretch]]` of a sidecar), each declared once.
pub mod region_bounds {
    use crate::error::Bound;
    use crate::vehicle::lateral_bounds::MU_SCALE;

    /// `mu_scale` of a region: the range of the vehicle's `lateral.mu_scale`.
    pub const MU_SCALE_REGION: Bound = Bound::closed("surface.*.mu_scale", MU_SCALE.lo, MU_SCALE.hi, "");
    /// `[[surface.patch]]` centre `x_m`, `y_m`: +-5000 m (a large test ground).
    pub const PATCH_XY: Bound = Bound::closed("surface.patch.x_m", -5000.0, 5000.0, "m");
    /// `[[surface.patch]] radius_m`: [1, 1000] m (at least its 1 m edge).
    pub const PATCH_RADIUS: Bound = Bound::closed("surface.patch.radius_m", 1.0, 1000.0, "m");
    /// `[[surface.band]] start_x_m`: +-5000 m.
    pub const BAND_START: Bound = Bound::closed("surface.band.start_x_m", -5000.0, 5000.0, "m");
    /// `length_m` of a band or a stretch: [2, 2000] m (at least its two edges).
    pub const REGION_LENGTH: Bound = Bound::closed("surface.*.length_m", 2.0, 2000.0, "m");
    /// `[[surface.stretch]] start_m`: [0, 2000] m of distance travelled.
    pub const STRETCH_START: Bound = Bound::closed("surface.stretch.start_m", 0.0, 2000.0, "m");
}

/// Width of the logistic edges of a region, m.
pub const EDGE_M: f64 = 1.0;

/// The friction regions of a surface (none by default).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GroundRegions {
    /// A disc: [scale s, centre X (m), centre Y (m), radius (m)].
    pub patch: Option<[f64; 4]>,
    /// A band across X (any Y): [scale s, start X (m), length along X (m)].
    pub band: Option<[f64; 3]>,
    /// A stretch of distance travelled: [scale s, start (m), length (m)].
    pub stretch: Option<[f64; 3]>,
}

impl GroundRegions {
    /// No regions (a constant for `const` environments).
    pub const NONE: GroundRegions = GroundRegions { patch: None, band: None, stretch: None };

    /// True when no region is set.
    pub fn is_empty(&self) -> bool {
        self.patch.is_none() && self.band.is_none() && self.stretch.is_none()
    }

    /// Friction factor of the stretch at `distance_m` travelled (1 without a stretch).
    pub fn factor_along(&self, distance_m: f64) -> f64 {
        self.stretch.map_or(1.0, |b| band_factor(b, distance_m))
    }

    /// Friction factor at ground point (X, Y), m: the patch's times the band's (1 outside both).
    pub fn factor(&self, x_m: f64, y_m: f64) -> f64 {
        self.patch.map_or(1.0, |p| patch_factor(p, x_m, y_m)) * self.band.map_or(1.0, |b| band_factor(b, x_m))
    }
}

/// A window of 1 where both distances inside its two edges (m) are positive, 0 outside, with
/// logistic edges of width [`EDGE_M`].
pub fn window(from_start_m: f64, to_end_m: f64) -> f64 {
    let edge = |z: f64| 1.0 / (1.0 + (-z / EDGE_M).exp());
    edge(from_start_m) * edge(to_end_m)
}

/// Friction factor of the disc `[s, X0, Y0, R]` at ground point (X, Y), m:
/// 1 + (s - 1) / (1 + exp((|P - P0| - R) / [`EDGE_M`])); 1 for a radius <= 0.
pub fn patch_factor([s, x0, y0, radius]: [f64; 4], x_m: f64, y_m: f64) -> f64 {
    if radius <= 0.0 {
        return 1.0;
    }
    let r = (x_m - x0).hypot(y_m - y0);
    1.0 + (s - 1.0) / (1.0 + ((r - radius) / EDGE_M).exp())
}

/// Friction factor of the band `[s, X0, L]` at ground abscissa X, m: 1 + (s - 1) w with w a
/// [`window`] over [X0, X0 + L]; 1 for a length <= 0.
pub fn band_factor([s, x0, len]: [f64; 3], x_m: f64) -> f64 {
    if len <= 0.0 {
        return 1.0;
    }
    1.0 + (s - 1.0) * window(x_m - x0, x0 + len - x_m)
}

/// Ground position (X, Y), m, of the axle `l_m` ahead of the CG (negative behind) for the CG at
/// (X, Y) with heading `psi_rad`.
pub fn axle_position(x_m: f64, y_m: f64, psi_rad: f64, l_m: f64) -> (f64, f64) {
    let (s, c) = psi_rad.sin_cos();
    (x_m + l_m * c, y_m + l_m * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Inside, at the edge and far outside: the closed forms of the logistic window.
    #[test]
    fn regions_follow_their_logistic_closed_forms() {
        let p = [0.5, 10.0, 0.0, 5.0];
        assert!((patch_factor(p, 10.0, 0.0) - (1.0 - 0.5 / (1.0 + (-5.0f64).exp()))).abs() < 1e-15);
        assert_eq!(patch_factor(p, 15.0, 0.0), 0.75);
        assert_eq!(patch_factor(p, 100.0, 0.0), 1.0);
        let b = [0.4, 20.0, 30.0];
        let mid = 1.0 - 0.6 / (1.0 + (-15.0f64).exp()).powi(2);
        assert!((band_factor(b, 35.0) - mid).abs() < 1e-15);
        assert_eq!(band_factor(b, -200.0), 1.0);
        let g = GroundRegions { patch: Some(p), band: Some(b), stretch: None };
        assert_eq!(g.factor(15.0, 0.0), 0.75 * band_factor(b, 15.0));
        assert!(GroundRegions::NONE.is_empty() && GroundRegions::NONE.factor(0.0, 0.0) == 1.0);
        let (x, y) = axle_position(1.0, 2.0, std::f64::consts::FRAC_PI_2, 1.5);
        assert!((x - 1.0).abs() < 1e-15 && (y - 3.5).abs() < 1e-15);
    }
}
