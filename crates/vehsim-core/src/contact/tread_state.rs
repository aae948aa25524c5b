//! The tread state: each axle's tread-temperature rise as a lumped heat balance, the contact
//! temperature of `[lateral] tread_*` (the thermal form `vehsim discover` fits, docs/discover.md).
//!
//! Per tyre i (an axle of the bicycle model), the rise dT_i above the surface, K:
//!
//!   d(dT_i)/dt = P_i / C - dT_i / tau_c,   P_i = v_slide,i |F_i|   (W),
//!
//! with C the tread layer's heat capacity (J/K), tau_c its cooling time (s), v_slide the tread's
//! sliding speed over the surface and |F| the friction force it transmits
//! ([`super::TyreContact`]). So dT_i is a first-order lag towards P_i tau_c / C. It is capped at
//! melting, 0 <= dT_i <= 0 degC - T_surface (heat beyond the cap melts ice rather than warming the
//! tread), the cap applied after every update. The contact temperature the tyre sees is
//! T_surface + dT_i; the friction change per kelvin, q C / 1000 (`Lateral::tread_mu_per_k`), is
//! the vehicle model's.
//!
//! The update is exact for a lag whose input varies linearly over the step, from the previous
//! update's P to this one's: with u = P tau_c / C, E = exp(-h / tau_c),
//!
//!   dT(t + h) = u_1 + (dT(t) - u_0) E - (u_1 - u_0) (tau_c / h) (1 - E),
//!
//! the form the discovery replay uses for its lags. At the first update u_0 = u_1.

use super::thermal::MELT_C;
use super::{ContactTemperature, TyreContact};

/// Most tyres a vehicle model has.
const MAX_TYRES: usize = 4;

/// The tread-temperature state of every tyre (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TreadState {
    /// Heat capacity of one tyre's (axle's) tread layer, J/K (> 0).
    capacity_j_per_k: f64,
    /// Cooling time constant towards the surface temperature, s (> 0).
    cooling_s: f64,
    /// Rise above the surface, K, per tyre.
    rise_k: [f64; MAX_TYRES],
    /// The lag's input P tau_c / C at the previous update, K, per tyre (None before the first).
    input_k: Option<[f64; MAX_TYRES]>,
}

impl TreadState {
    /// A tread at the surface temperature, with heat capacity `capacity_j_per_k` (J/K) and cooling
    /// time `cooling_s` (s); both must be positive and finite (the spec layer's bounds).
    pub fn new(capacity_j_per_k: f64, cooling_s: f64) -> Self {
        TreadState { capacity_j_per_k, cooling_s, rise_k: [0.0; MAX_TYRES], input_k: None }
    }

    /// The rise of each tyre above the surface, K.
    pub fn rise_k(&self) -> &[f64] {
        &self.rise_k
    }

    /// The lag's input of one tyre, K: its steady rise P tau_c / C (0 for a non-finite power).
    fn input_of(&self, t: &TyreContact) -> f64 {
        let p = t.slide_speed_mps.max(0.0) * t.friction_force_n.abs();
        if p.is_finite() {
            p * self.cooling_s / self.capacity_j_per_k
        } else {
            0.0
        }
    }
}

/// One exact step of the lag dy/dt = (u - y) / tau with u linear from `u0` to `u1` over `h`.
fn lag_step(y: f64, u0: f64, u1: f64, h: f64, tau: f64) -> f64 {
    if h <= 0.0 {
        return y;
    }
    let r = h / tau;
    let e = (-r).exp();
    // (1 - E) / r, by its series where r is small (no cancellation).
    let g = if r < 1e-4 { 1.0 - 0.5 * r + r * r / 6.0 } else { -(-r).exp_m1() / r };
    u1 + (y - u0) * e - (u1 - u0) * g
}

impl ContactTemperature for TreadState {
    fn update(&mut self, h: f64, tyres: &[TyreContact], out: &mut [f64]) {
        let n = tyres.len().min(MAX_TYRES);
        let mut now = [0.0; MAX_TYRES];
        for (u, t) in now.iter_mut().zip(&tyres[..n]) {
            *u = self.input_of(t);
        }
        let before = self.input_k.unwrap_or(now);
        for i in 0..n {
            let cap = (MELT_C - tyres[i].surface_temp_c).max(0.0);
            let y = lag_step(self.rise_k[i], before[i], now[i], h, self.cooling_s);
            self.rise_k[i] = y.clamp(0.0, cap);
        }
        self.input_k = Some(now);
        for ((o, t), dt) in out.iter_mut().zip(&tyres[..n]).zip(self.rise_k) {
            *o = t.surface_temp_c + dt;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sliding(power_w: f64, surface_c: f64) -> TyreContact {
        TyreContact {
            fz_n: 4000.0,
            roll_speed_mps: 10.0,
            slide_speed_mps: 0.5,
            friction_force_n: power_w / 0.5,
            surface_temp_c: surface_c,
        }
    }

    /// Constant power: dT(t) = P tau / C (1 - exp(-t / tau)), exactly at every step.
    #[test]
    fn constant_power_follows_the_closed_form() {
        let (c, tau, p) = (300.0, 3.0, 60.0);
        let mut s = TreadState::new(c, tau);
        let tyres = [sliding(p, -20.0), sliding(0.0, -20.0)];
        let mut out = [0.0; 2];
        let h = 0.01;
        for k in 1..=500 {
            s.update(h, &tyres, &mut out);
            let t = k as f64 * h;
            let want = p * tau / c * (1.0 - (-t / tau).exp());
            assert!((s.rise_k()[0] - want).abs() < 1e-12, "t {t}: {} vs {want}", s.rise_k()[0]);
            assert!((out[0] - (-20.0 + want)).abs() < 1e-12);
            assert_eq!(out[1], -20.0, "no power, no rise");
        }
    }

    /// With the power switched off the rise decays by exp(-h / tau) per step.
    #[test]
    fn the_rise_cools_with_its_time_constant() {
        let mut s = TreadState::new(100.0, 2.0);
        let mut out = [0.0; 1];
        for _ in 0..100 {
            s.update(0.05, &[sliding(40.0, -10.0)], &mut out);
        }
        let before = s.rise_k()[0];
        s.update(0.05, &[sliding(0.0, -10.0)], &mut out); // the ramp down to no power
        s.update(0.05, &[sliding(0.0, -10.0)], &mut out);
        let after = s.rise_k()[0];
        assert!(before > 0.5);
        assert!(after < before);
        // One step at zero input decays exactly.
        let mut out2 = [0.0; 1];
        let mut s2 = s.clone();
        s2.update(0.05, &[sliding(0.0, -10.0)], &mut out2);
        assert!((s2.rise_k()[0] - after * (-0.025f64).exp()).abs() < 1e-14);
    }

    /// The rise never passes melting, however large the power.
    #[test]
    fn the_rise_is_capped_at_melting() {
        let mut s = TreadState::new(10.0, 100.0);
        let mut out = [0.0; 2];
        for _ in 0..1000 {
            s.update(0.01, &[sliding(1e6, -3.0), sliding(1e6, 5.0)], &mut out);
        }
        assert_eq!(out[0], 0.0, "capped at 0 degC");
        assert_eq!(s.rise_k()[1], 0.0, "a surface above melting has no room to warm");
        assert!(out.iter().all(|t| t.is_finite()));
        let mut s = TreadState::new(300.0, 3.0);
        s.update(0.01, &[sliding(f64::NAN, -3.0)], &mut out[..1]);
        assert_eq!(out[0], -3.0, "a non-finite power heats nothing");
    }

    /// A power ramp: the update is exact for a linear input, so halving the step changes nothing
    /// beyond round-off, and it matches the lag's closed form for u = a t.
    #[test]
    fn a_linear_power_ramp_is_integrated_exactly() {
        let (c, tau) = (200.0, 1.5);
        let slope = 30.0; // W/s
        let run = |h: f64| {
            let mut s = TreadState::new(c, tau);
            let mut out = [0.0; 1];
            let n = (2.0 / h).round() as usize;
            for k in 0..=n {
                s.update(if k == 0 { 0.0 } else { h }, &[sliding(slope * k as f64 * h, -15.0)], &mut out);
            }
            s.rise_k()[0]
        };
        // u(t) = a t with a = slope tau / C: y(t) = a (t - tau (1 - exp(-t / tau))).
        let a = slope * tau / c;
        let want = a * (2.0 - tau * (1.0 - (-2.0 / tau).exp()));
        for h in [0.1, 0.05, 0.01] {
            assert!((run(h) - want).abs() < 1e-12, "h {h}: {} vs {want}", run(h));
        }
    }
}
