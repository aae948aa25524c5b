//! The friction-region forms against the runs' paths: start points of their fits placed where the
//! residuals are, and the check that a fitted region is a region at all.
//!
//! **Placed starts.** A short, mild region
//! falls between the fixed grids of [`super::effects::Effect::starts`] (discs of 12 or 30 m,
//! windows of 25 m and more), and the simplex does not find it from there, because the objective
//! is flat away from the region.
//!
//! From the current model's residuals on the fitted samples (held-out samples count as agreeing,
//! so that the held-out side does not steer the fit), the disagreement windows
//! ([`super::select::disagreement_windows`]: the 0.5 s moving mean of the squared normalised
//! residual above 2) are ranked by excess × duration and the largest [`WINDOWS`] are taken. For a
//! window [t0, t1] of a run, with the pose and the distance travelled at those times (the logged
//! `x`, `y`, `psi` when the run has them, else dead reckoning from the origin heading +X on the
//! measured yaw rate and vx, as the replay places a run without them), and s = the distance
//! travelled over the window (m):
//! - patch: centres at the CG's position at 1/3 and 1/2 of the window, radii 0.25 s and 0.5 s;
//! - stretch: starts at the distance travelled at t0 and 0.25 s before it, lengths 0.5 s and s;
//! - band: as the stretch, in X (only where X advances over the window);
//!
//! each at a friction scale of 0.6 and 1.5 (a region may be slipperier or grippier), clamped to
//! the parameters' bounds. A window's response lags the region (the yaw response takes a few
//! tenths of a second to build and to decay), so the window spans more than the region; the
//! smaller sizes allow for that.
//!
//! **Whole-run regions.** A fitted region whose weight is at least 1/2 at [`WHOLE_SHARE`] or more of
//! the samples of the runs (every run, fitted and held out, at the CG's pose or distance as above)
//! covers the whole of what was driven: on these runs it is the global friction change with a
//! parameter or three more, not a place. [`region_coverage`] gives that share, and the search does
//! not name such a region (its reason says so), so the global form is named instead.

use super::effects::Effect;
use super::measured::MeasuredRun;
use super::model::{EffectParams, ReplayModel};
use super::report::largest_windows;
use super::select::{disagreement_windows, simulate_all, Dataset};

/// Number of disagreement windows that place starts.
pub const WINDOWS: usize = 3;

/// Friction scales of the starts: lower and higher than the surface's.
const SCALES: [f64; 2] = [0.6, 1.5];

/// The CG's ground pose (X, Y in m, psi in rad) and distance travelled (m) at every sample of `r`:
/// the logged pose when the run has `x`, `y` and `psi`, else dead reckoning (trapezoid) from the
/// origin heading +X; the distance is the trapezoid of the measured vx.
fn poses(r: &MeasuredRun) -> Vec<[f64; 4]> {
    let n = r.t.len();
    let mut out = vec![[0.0; 4]; n];
    for k in 1..n {
        let dt = r.t[k] - r.t[k - 1];
        let [x, y, psi, d] = out[k - 1];
        let psi1 = psi + 0.5 * dt * (r.yaw_rate[k] + r.yaw_rate[k - 1]);
        let (v0, v1) = (r.vx[k - 1], r.vx[k]);
        let x1 = x + 0.5 * dt * (v0 * psi.cos() + v1 * psi1.cos());
        let y1 = y + 0.5 * dt * (v0 * psi.sin() + v1 * psi1.sin());
        out[k] = [x1, y1, psi1, d + 0.5 * dt * (v0 + v1)];
    }
    if let (Some(x), Some(y), Some(psi)) = (r.channel("x"), r.channel("y"), r.channel("psi")) {
        for (k, p) in out.iter_mut().enumerate() {
            (p[0], p[1], p[2]) = (x[k], y[k], psi[k]);
        }
    }
    out
}

/// The sample of `r` nearest time `t`.
fn sample_at(r: &MeasuredRun, t: f64) -> usize {
    r.t.partition_point(|&s| s < t).min(r.t.len().saturating_sub(1))
}

/// Extra start points of `e`'s fit placed at the largest disagreement windows of the model `base`
/// on the fitted samples of `data` (none for an effect that is not a friction region).
pub fn region_starts(e: Effect, model: &ReplayModel, data: &Dataset, base: &EffectParams) -> Vec<Vec<f64>> {
    if !matches!(e, Effect::FrictionPatch | Effect::FrictionBand | Effect::FrictionStretch) {
        return Vec::new();
    }
    let mut sims = simulate_all(model, data, base);
    for ((r, s), held) in data.runs.iter().zip(&mut sims).zip(&data.held) {
        for (k, h) in held.iter().enumerate() {
            if *h {
                (s.yaw_rate[k], s.ay[k]) = (r.yaw_rate[k], r.ay[k]);
            }
        }
    }
    let windows = largest_windows(&disagreement_windows(data, &sims), WINDOWS);
    let bounds = e.params();
    let clamp = |v: Vec<f64>| -> Vec<f64> { v.iter().zip(bounds).map(|(x, d)| x.clamp(d.lo, d.hi)).collect() };
    let mut out = Vec::new();
    for w in &windows {
        let Some(r) = data.runs.iter().find(|r| r.name == w.run) else { continue };
        let pose = poses(r);
        let at = |t: f64| pose[sample_at(r, t)];
        let (p0, p1) = (at(w.t0_s), at(w.t1_s));
        let span = (p1[3] - p0[3]).max(2.0);
        for s in SCALES {
            match e {
                Effect::FrictionPatch => {
                    for f in [1.0 / 3.0, 0.5] {
                        let c = at(w.t0_s + f * (w.t1_s - w.t0_s));
                        for radius in [0.25 * span, 0.5 * span] {
                            out.push(clamp(vec![s, c[0], c[1], radius]));
                        }
                    }
                }
                Effect::FrictionStretch => {
                    for start in [p0[3], p0[3] - 0.25 * span] {
                        for len in [0.5 * span, span] {
                            out.push(clamp(vec![s, start, len]));
                        }
                    }
                }
                _ => {
                    let dx = p1[0] - p0[0];
                    if dx > 1.0 {
                        for start in [p0[0], p0[0] - 0.25 * dx] {
                            for len in [0.5 * dx, dx] {
                                out.push(clamp(vec![s, start, len]));
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// Share of samples a region covers, at or above which it is the global change ([`region_coverage`]).
pub const WHOLE_SHARE: f64 = 0.95;

/// The share of all samples of `data`'s runs at which the region of form `e` with parameters
/// `values` (in the order of `e.params()`) has a weight of at least 1/2, at the CG's pose or
/// distance travelled (as for the placed starts); None for a form that is not a friction region.
pub fn region_coverage(e: Effect, values: &[f64], data: &Dataset) -> Option<f64> {
    use vehsim_core::vehicle::ground::{band_factor, patch_factor};
    let weight = |p: &[f64; 4]| -> f64 {
        // The factor of a region of scale 0 is 1 - w: its weight w.
        match (e, values) {
            (Effect::FrictionPatch, [_, x0, y0, r]) => 1.0 - patch_factor([0.0, *x0, *y0, *r], p[0], p[1]),
            (Effect::FrictionBand, [_, x0, len]) => 1.0 - band_factor([0.0, *x0, *len], p[0]),
            (Effect::FrictionStretch, [_, d0, len]) => 1.0 - band_factor([0.0, *d0, *len], p[3]),
            _ => f64::NAN,
        }
    };
    if !matches!(e, Effect::FrictionPatch | Effect::FrictionBand | Effect::FrictionStretch) {
        return None;
    }
    let (mut inside, mut all) = (0usize, 0usize);
    for r in &data.runs {
        for p in poses(r) {
            all += 1;
            if weight(&p) >= 0.5 {
                inside += 1;
            }
        }
    }
    Some(if all > 0 { inside as f64 / all as f64 } else { 0.0 })
}
