//! The road's constant bank and grade: gravity in the road plane and the normal loads it leaves.
//!
//! Frames (ISO 8855): body x forward, y left, z up, the body's x-y plane in the road plane (the
//! car neither rolls nor pitches relative to the road). The car drives along the road, so its
//! heading relative to the road's own direction is small and the bank and grade are taken as
//! angles about the body's x and y axes (their cosine with that heading error is 1).
//!
//! - Bank phi (`bank_deg`, positive when the road's left edge is higher than its right: the road
//!   plane rolled by +phi about x). Gravity, (0, 0, -g) in the level frame, has in the road plane
//!   the lateral component g_y = -g cos(theta) sin(phi): a left-high bank pulls the car to the
//!   right (downhill).
//! - Grade theta (`grade_deg`, positive uphill in the direction of travel; the road plane's ISO
//!   pitch angle is -theta): g_x = -g sin(theta), so climbing slows the car.
//! - Normal to the road: g_n = g cos(theta) cos(phi) presses the car onto it.
//!
//! What the car does: m (dvx/dt - r vy) = sum Fx + m g_x and m (dvy/dt + r vx) = sum Fy + m g_y
//! (gravity acts at the CG, no yaw moment). What an accelerometer fixed to the body logs is the
//! specific force, the contact forces over the mass: a_y,logged = sum Fy / m = dvy/dt + r vx - g_y.
//! It does not see the gravity component the kinematics do; on a bank driven straight
//! (dvy/dt = r = 0) the tyres hold the car against g_y and the accelerometer reads -g_y =
//! g cos(theta) sin(phi).
//!
//! Normal loads (quasi-static pitch balance about the CG at height h, wheelbase L = a + b): the
//! road carries m g_n, split b/L front and a/L rear, and on a grade the tyres push m g sin(theta)
//! along the road at the ground to hold the speed, which moves m g sin(theta) h / L from the
//! front axle to the rear: Fz_f = m (g_n b - g sin(theta) h) / L, Fz_r = m (g_n a + g sin(theta) h) / L.
//! Flat road: every term above is exactly the level one (g_x = g_y = 0, g_n = g).

use super::params::GRAVITY;

/// The allowed ranges of the road keys (`[road]` of a manoeuvre and of a measured run's sidecar),
/// each declared once.
pub mod road_bounds {
    use crate::error::Bound;

    /// `road.bank_deg`: +-35 deg. Road superelevation stays within 12 % (6.8 deg) by design
    /// rules; banked test-track ovals reach about 31 deg (Daytona's turns) and the steepest
    /// high-speed test bowls a little more.
    pub const BANK_DEG: Bound = Bound::closed("road.bank_deg", -35.0, 35.0, "deg");
    /// `road.grade_deg`: +-20 deg. Road design limits grades to about 15-20 % (8.5-11.3 deg); the
    /// steepest public streets reach about 35 % (19.3 deg) and test-track hills 30 % (16.7 deg).
    pub const GRADE_DEG: Bound = Bound::closed("road.grade_deg", -20.0, 20.0, "deg");
    /// Every road bound.
    pub const ALL: [Bound; 2] = [BANK_DEG, GRADE_DEG];
}

/// A road's constant bank and grade (flat by default).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Road {
    /// Bank angle phi, rad (positive: the road's left edge higher).
    pub bank_rad: f64,
    /// Grade angle theta, rad (positive: uphill in the direction of travel).
    pub grade_rad: f64,
}

impl Road {
    /// The flat road.
    pub const FLAT: Road = Road { bank_rad: 0.0, grade_rad: 0.0 };

    /// The road of a bank and a grade in degrees.
    pub fn from_deg(bank_deg: f64, grade_deg: f64) -> Self {
        Self { bank_rad: bank_deg.to_radians(), grade_rad: grade_deg.to_radians() }
    }

    /// True when both angles are 0 (the level equations apply unchanged).
    pub fn is_flat(&self) -> bool {
        self.bank_rad == 0.0 && self.grade_rad == 0.0
    }

    /// Gravity in the road plane, m/s^2: (g_x, g_y) = (-g sin(theta), -g cos(theta) sin(phi)).
    pub fn gravity_in_plane(&self) -> (f64, f64) {
        (-GRAVITY * self.grade_rad.sin(), -GRAVITY * self.grade_rad.cos() * self.bank_rad.sin())
    }

    /// Normal loads of the front and rear axles, N, of a car of mass `m_kg` with its CG `a_m`
    /// behind the front axle, `b_m` ahead of the rear one and `h_m` above the road (module docs).
    pub fn axle_loads_n(&self, m_kg: f64, a_m: f64, b_m: f64, h_m: f64) -> [f64; 2] {
        let l = a_m + b_m;
        let g_n = GRAVITY * self.grade_rad.cos() * self.bank_rad.cos();
        let shift = GRAVITY * self.grade_rad.sin() * h_m;
        [m_kg * (g_n * b_m - shift) / l, m_kg * (g_n * a_m + shift) / l]
    }

    /// Why tyres of peak friction `mu` cannot drive on this road at a held speed, if they cannot:
    /// the grade needs a drive force m g sin(theta) against a grip of at most mu m g_n, so
    /// tan|theta| must stay below mu (a bank is held at speed by the turn, as on an oval, and is
    /// not refused).
    pub fn too_steep(&self, mu: f64) -> Option<String> {
        let need = self.grade_rad.tan().abs() / self.bank_rad.cos();
        (need > mu).then(|| {
            format!(
                "a grade of {:.2} deg needs a drive force of {need:.3} times the normal load to hold the speed, \
                 above the surface friction mu = {mu}: allowed |tan(grade)| <= mu cos(bank)",
                self.grade_rad.to_degrees()
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Flat: the level loads (to round-off; the models take their own static loads on a flat
    /// road, [`Road::is_flat`], so a run without a road is bit for bit the level one), no gravity
    /// in the plane.
    #[test]
    fn the_flat_road_is_the_level_one() {
        let r = Road::FLAT;
        assert!(r.is_flat() && !Road::from_deg(0.0, 1e-9).is_flat());
        assert_eq!(r.gravity_in_plane(), (-0.0, -0.0));
        let [f, rr] = r.axle_loads_n(1500.0, 1.2, 1.5, 0.55);
        let level = [1500.0 * GRAVITY * 1.5 / 2.7, 1500.0 * GRAVITY * 1.2 / 2.7];
        assert!((f - level[0]).abs() < 1e-12 * level[0] && (rr - level[1]).abs() < 1e-12 * level[1]);
    }

    /// Loads sum to the normal component, the grade moves m g sin(theta) h / L rearwards, and the
    /// in-plane and normal components recompose g (|g| = g for any bank and grade).
    #[test]
    fn loads_and_gravity_close() {
        let r = Road::from_deg(6.0, 8.0);
        let (m, a, b, h) = (1500.0, 1.2, 1.5, 0.55);
        let [f, rr] = r.axle_loads_n(m, a, b, h);
        let g_n = GRAVITY * r.grade_rad.cos() * r.bank_rad.cos();
        assert!((f + rr - m * g_n).abs() < 1e-9 * m * GRAVITY);
        let level = Road::from_deg(6.0, 0.0).axle_loads_n(m, a, b, h);
        let shift = m * GRAVITY * r.grade_rad.sin() * h / (a + b);
        assert!((level[0] * r.grade_rad.cos() - shift - f).abs() < 1e-9 * m * GRAVITY);
        let (gx, gy) = r.gravity_in_plane();
        assert!(((gx * gx + gy * gy + g_n * g_n).sqrt() - GRAVITY).abs() < 1e-12);
        assert!(gx < 0.0 && gy < 0.0, "uphill slows, left-high pulls right");
    }

    #[test]
    fn a_grade_steeper_than_the_grip_is_refused() {
        assert!(Road::from_deg(0.0, 5.0).too_steep(0.1).is_none());
        assert!(Road::from_deg(0.0, -6.0).too_steep(0.1).is_some());
        assert!(Road::from_deg(30.0, 0.0).too_steep(0.1).is_none());
    }
}
