//! Channels scored on their increments over windows: a run that logs its heading `psi` (rad,
//! counter-clockwise), its position `x`, `y` (m, ground frame, with the heading) or its lateral
//! velocity `vy` (m/s, at the CG, positive left) is scored on them as well as on yaw rate and a_y.
//! Not sample by sample: the heading and the position are integrals of what the replay gets
//! wrong, so their sample residuals drift and are correlated over the whole run, and a lateral
//! velocity from an inertial navigation system carries an offset (its mounting angle times the
//! speed) that no effect of the car explains; a white-noise weight would let either swamp the yaw
//! rate and a_y. An increment over a window restarts from the measured value at the window's
//! start, so its residual is the replay's error over that window only, and a constant offset
//! cancels.
//!
//! Windows: each stretch of samples on one side of the held-out split is cut into windows of
//! [`WINDOW_S`] (the last one takes a remainder under half a window; a stretch shorter than a
//! window is one window; no window crosses the split). A window from sample k0 to k1 gives
//!
//!   heading:            e_psi = (psi(k1) - psi(k0)) - (psi_s(k1) - psi_s(k0)),
//!   lateral position:   e_lat = n(psi(k0)) . (p(k1) - p(k0)) - n(psi_s(k0)) . (p_s(k1) - p_s(k0)),
//!   lateral velocity:   e_vy  = (vy(k1) - vy(k0)) - (vy_s(k1) - vy_s(k0)),
//!
//! with the replay's own pose psi_s, p_s and lateral velocity vy_s (the engine integrates the pose
//! in its own ground frame; only increments are compared, so the frames need not agree) and
//! n(psi) = (-sin psi, cos psi) the unit vector to the left of a heading. The measured heading's
//! increment is the sum of its wrapped sample-to-sample differences (a heading logged within +-pi
//! unwraps). The position is scored only with a heading, and only across it: its component along
//! the heading is the integral of the measured speed, which the replay takes as its input, so it
//! tests the speed sensor and not the car.
//!
//! These channels are taken as the reference of the measurement chain: the `[sensors]` effects
//! (latency, scale, offsets, clock skew, accelerometer mounting) act on the inertial channels (yaw
//! rate, a_y) and not on the heading, position and lateral velocity, which a satellite receiver or
//! a survey-grade inertial navigation system logs on the logger's clock. That is what lets them
//! tell a sensor's error from the car's: a latency of both inertial channels and a steering lag
//! delay the yaw rate and a_y alike, but only the steering lag delays the heading.
//!
//! Noise of an increment (its normalization, like the channels' noise in [`super::select`]): each
//! channel's white noise sigma from second differences (as every channel's), so sigma(e_psi)^2 =
//! 2 sigma_psi^2, sigma(e_vy)^2 = 2 sigma_vy^2 and sigma(e_lat)^2 = 2 sigma_p^2 + (|p(k1) -
//! p(k0)| sigma_psi)^2 (the measured heading at k0 turns the measured increment). Each is floored
//! at what integrating the inertial channel's own noise over the window gives: sigma_r W / sqrt(m)
//! for the heading, sigma_ay W / sqrt(m) for the lateral velocity (v_y' = a_y - v_x r) and
//! sigma_ay W^2 / sqrt(3 m) for the lateral position, with W the window's duration and m its
//! sample intervals. A channel logged without noise, or one an inertial system integrated from the
//! same sensors, then weighs no more than the inertial samples it spans.

use super::measured::MeasuredRun;
use super::model::Simulated;
use super::select::{noise_sigma, Noise};

/// Duration of an increment window, s.
pub const WINDOW_S: f64 = 1.0;

/// The windowed channels a run logs, and their white-noise levels (None for one it does not log).
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct IncrementNoise {
    /// Heading noise, rad.
    pub psi_rad: Option<f64>,
    /// Position noise per axis, m (the run logs `x`, `y` and `psi`).
    pub position_m: Option<f64>,
    /// Lateral velocity noise, m/s.
    pub vy_mps: Option<f64>,
}

/// The scored window channels, in the order of [`Residual::channel`].
pub const CHANNELS: [&str; 3] = ["heading", "lateral_position", "lateral_velocity"];

/// Number of window channels.
pub const N: usize = CHANNELS.len();

/// Wrap an angle (or an angle difference), rad, into (-pi, pi].
pub fn wrap(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let w = a - tau * (a / tau).round();
    if w <= -std::f64::consts::PI {
        w + tau
    } else {
        w
    }
}

/// The heading unwrapped from its first sample (sample-to-sample steps wrapped into (-pi, pi]).
fn unwrapped(psi: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(psi.len());
    let mut acc = psi.first().copied().unwrap_or(0.0);
    for (k, &v) in psi.iter().enumerate() {
        if k > 0 {
            acc += wrap(v - psi[k - 1]);
        }
        out.push(acc);
    }
    out
}

/// The window channels' noise of `run`: None when it logs neither a heading nor a lateral
/// velocity.
pub fn noise(run: &MeasuredRun) -> Option<IncrementNoise> {
    let psi = run.channel("psi");
    let position_m = match (run.channel("x"), run.channel("y"), psi) {
        (Some(x), Some(y), Some(_)) => Some((0.5 * (noise_sigma(x).powi(2) + noise_sigma(y).powi(2))).sqrt()),
        _ => None,
    };
    let vy_mps = run.channel("vy").map(noise_sigma);
    let psi_rad = psi.map(|p| noise_sigma(&unwrapped(p)));
    (psi_rad.is_some() || vy_mps.is_some()).then_some(IncrementNoise { psi_rad, position_m, vy_mps })
}

/// One window's residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residual {
    /// On the held-out side of the split.
    pub held: bool,
    /// 0: heading (rad), 1: lateral position (m), 2: lateral velocity (m/s) ([`CHANNELS`]).
    pub channel: usize,
    /// Measured minus replayed increment, in the channel's unit.
    pub error: f64,
    /// The error over its noise.
    pub z: f64,
}

/// The windows of a run: (first sample, last sample, held) for every window. A window's samples
/// are all on its side of the split (a stretch of one sample gives none).
pub fn windows(t: &[f64], held: &[bool]) -> Vec<(usize, usize, bool)> {
    let n = t.len().min(held.len());
    let mut out = Vec::new();
    let mut a = 0;
    while a < n {
        // The stretch a..=e on one side.
        let mut e = a;
        while e + 1 < n && held[e + 1] == held[a] {
            e += 1;
        }
        let mut k0 = a;
        while k0 < e {
            // The end of this window: the first sample at or past WINDOW_S, or the stretch's end
            // when what would be left is under half a window.
            let mut k1 = k0 + 1;
            while k1 < e && t[k1] - t[k0] < WINDOW_S {
                k1 += 1;
            }
            if t[e] - t[k1] < 0.5 * WINDOW_S {
                k1 = e;
            }
            out.push((k0, k1, held[a]));
            k0 = k1;
        }
        a = e + 1;
    }
    out
}

/// The window residuals of `run` against the replay `sim` with the split `held`, every window in
/// order (heading, lateral position, lateral velocity, each when the run logs it); none when the
/// run logs none of them or the replay lacks the channels.
pub fn residuals(run: &MeasuredRun, nz: &Noise, sim: &Simulated, held: &[bool]) -> Vec<Residual> {
    let Some(pn) = nz.increments else { return Vec::new() };
    let n = run.t.len();
    if sim.psi.len() != n || sim.x.len() != n || sim.y.len() != n || sim.vy.len() != n {
        return Vec::new();
    }
    let psi = run.channel("psi").zip(pn.psi_rad).map(|(p, s)| (p, unwrapped(p), s));
    let xy = match (run.channel("x"), run.channel("y"), pn.position_m) {
        (Some(x), Some(y), Some(s)) => Some((x, y, s)),
        _ => None,
    };
    let vy = run.channel("vy").zip(pn.vy_mps);
    let mut out = Vec::new();
    for (k0, k1, side) in windows(&run.t, held) {
        let w = run.t[k1] - run.t[k0];
        let m = (k1 - k0) as f64;
        if let Some((psi, psi_u, sp)) = &psi {
            let e = (psi_u[k1] - psi_u[k0]) - (sim.psi[k1] - sim.psi[k0]);
            let s = (2f64.sqrt() * sp).max(nz.yaw_rate * w / m.sqrt());
            out.push(Residual { held: side, channel: 0, error: e, z: e / s });
            if let Some((x, y, sx)) = xy {
                let lateral = |psi: f64, dx: f64, dy: f64| -psi.sin() * dx + psi.cos() * dy;
                let (dx, dy) = (x[k1] - x[k0], y[k1] - y[k0]);
                let e = lateral(psi[k0], dx, dy) - lateral(sim.psi[k0], sim.x[k1] - sim.x[k0], sim.y[k1] - sim.y[k0]);
                let s = (2.0 * sx * sx + (dx.hypot(dy) * sp).powi(2)).sqrt().max(nz.ay * w * w / (3.0 * m).sqrt());
                out.push(Residual { held: side, channel: 1, error: e, z: e / s });
            }
        }
        if let Some((vy, sv)) = vy {
            let e = (vy[k1] - vy[k0]) - (sim.vy[k1] - sim.vy[k0]);
            let s = (2f64.sqrt() * sv).max(nz.ay * w / m.sqrt());
            out.push(Residual { held: side, channel: 2, error: e, z: e / s });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_cover_each_side_without_crossing_the_split() {
        // 10 s at 100 Hz, held out from 3 s to 6 s.
        let t: Vec<f64> = (0..1001).map(|k| k as f64 * 0.01).collect();
        let held: Vec<bool> = t.iter().map(|&t| (3.0..6.0).contains(&t)).collect();
        let w = windows(&t, &held);
        let bounds: Vec<(f64, f64, bool)> = w.iter().map(|&(a, b, h)| (t[a], t[b], h)).collect();
        // Stretches 0-2.99 s, 3-5.99 s (each two windows of 1 s and a last of 0.99 s) and
        // 6-10 s (four of 1 s).
        assert_eq!(bounds.len(), 10, "{bounds:?}");
        for &(a, b, h) in &w {
            assert!((a..=b).all(|k| held[k] == h), "window {a}..{b} crosses the split");
            let d = t[b] - t[a];
            assert!((0.99 - 1e-9..=1.0 + 1e-9).contains(&d), "window {a}..{b} lasts {d}");
        }
        assert_eq!((w[0].0, w.last().unwrap().1), (0, 1000));
        // Within a stretch consecutive windows share their ends; across the split they do not.
        for p in w.windows(2) {
            if p[0].2 == p[1].2 {
                assert_eq!(p[0].1, p[1].0);
            } else {
                assert_eq!(p[0].1 + 1, p[1].0);
            }
        }
    }

    #[test]
    fn a_remainder_under_half_a_window_joins_the_last_one() {
        let t: Vec<f64> = (0..231).map(|k| k as f64 * 0.01).collect();
        let w = windows(&t, &vec![false; t.len()]);
        assert_eq!(w, vec![(0, 100, false), (100, 230, false)]);
        let short: Vec<f64> = (0..41).map(|k| k as f64 * 0.01).collect();
        assert_eq!(windows(&short, &[true; 41]), vec![(0, 40, true)]);
    }

    #[test]
    fn the_increment_limit_is_what_noise_alone_passes_once_in_a_thousand() {
        use crate::discover::select::{increment_noise_limit, EXPLAINED_NOISE_RATIO};
        use crate::discover::synth::Rng;
        // Monte Carlo of the RMS of n standard normal residuals: the fraction above the limit is
        // 0.001 where the limit is the quantile (n = 6, 12) and smaller where 1.5 is larger.
        let mut rng = Rng::new(7);
        for (n, expect) in [(6usize, Some(1.944)), (12, Some(1.660)), (40, None)] {
            let lim = increment_noise_limit(n);
            if let Some(e) = expect {
                assert!((lim - e).abs() < 2e-3, "limit at {n}: {lim}");
            } else {
                assert_eq!(lim, EXPLAINED_NOISE_RATIO);
            }
            let draws = 200_000;
            let above = (0..draws)
                .filter(|_| ((0..n).map(|_| rng.normal().powi(2)).sum::<f64>() / n as f64).sqrt() > lim)
                .count();
            let frac = above as f64 / draws as f64;
            eprintln!("n = {n}: limit {lim:.3}, noise alone above it {frac:.5}");
            assert!(frac <= 0.0013, "n = {n}: {frac} of noise-only draws above the limit {lim}");
            if expect.is_some() {
                assert!(frac >= 0.0007, "n = {n}: {frac} of noise-only draws above the limit {lim}");
            }
        }
    }

    #[test]
    fn a_heading_unwraps_across_pi() {
        let psi = [3.0, 3.1, -3.1, -3.0];
        let u = unwrapped(&psi);
        let step = std::f64::consts::TAU - 6.2;
        assert!((u[2] - (3.1 + step)).abs() < 1e-12 && (u[3] - (3.2 + step)).abs() < 1e-12, "{u:?}");
        assert!((wrap(std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-15);
        assert!((wrap(-std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-15);
    }
}
