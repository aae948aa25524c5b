//! Residuals, noise estimate, disagreement windows and operating regions, the scores and
//! thresholds by which effects are selected on held-out data with an information criterion, and
//! the result types. The greedy search itself is [`super::search`].
//!
//! Noise: for each run and channel, sigma = MAD(second differences) / 0.6745 / sqrt(6). The second
//! difference of a smooth signal sampled at 100 Hz is tiny, while white noise of variance s^2
//! gives second differences of variance 6 s^2; the median absolute deviation ignores outliers.
//!
//! Residuals are divided by their channel's noise, so a perfect model leaves a mean square of 1
//! per channel and sample. A run that logs its heading, position or lateral velocity adds one
//! normalized residual per window and channel ([`super::increments`]: their increments over 1 s).
//! Held-out data: with two runs or more, half the runs, stratified by surface and by the
//! baseline's disagreement ([`Dataset::stratified`]), never used by a fit; with one run,
//! alternate 3 s blocks (a quarter of the run when it is shorter than 12 s).
//!
//! Score of a model with k fitted parameters on the n held-out normalized residuals:
//! BIC = n ln(RSS / n) + k ln(n). A candidate is accepted when it lowers the held-out BIC by more
//! than [`BIC_MIN`] *and* lowers the held-out RSS by at least [`MIN_GAIN`] (a practical-significance
//! floor against correlated residuals in long records). Effects are added greedily, one per round,
//! until no candidate passes. From the second accepted effect on, every accepted effect's
//! parameters are refitted together after each acceptance ([`fit_jointly`]), and the refit is
//! kept when it does not raise the held-out RSS.

use rayon::prelude::*;
use serde::Serialize;

use super::effects::Effect;
use super::equivalence::{Class, Equivalent};
use super::fit::nelder_mead;
use super::increments::{self, IncrementNoise};
use super::measured::MeasuredRun;
use super::model::{EffectParams, ReplayModel, Simulated};
use super::search::triples;
use super::uncertainty::{refine, significant, Interval};

/// Held-out BIC improvement needed to accept an effect.
pub const BIC_MIN: f64 = 10.0;
/// Relative held-out RSS reduction needed to accept an effect.
pub const MIN_GAIN: f64 = 0.05;
/// Held-out RMS residual over the noise, in every channel and every fold, at or below which the
/// data are explained.
pub const EXPLAINED_NOISE_RATIO: f64 = 1.5;
/// Length of held-out blocks when there is one run, s.
pub const BLOCK_S: f64 = 3.0;
/// Evaluation budget of one fit.
pub const FIT_EVALS: usize = 60;

/// Noise level of one run, per channel.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Noise {
    pub yaw_rate: f64,
    pub ay: f64,
    /// The noise of the channels scored on their increments, when the run logs a heading or a
    /// lateral velocity ([`super::increments`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub increments: Option<IncrementNoise>,
}

/// Estimate white-noise sigma from second differences (robust).
pub fn noise_sigma(v: &[f64]) -> f64 {
    if v.len() < 4 {
        return 1e-6;
    }
    let mut d: Vec<f64> = v.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs()).collect();
    d.sort_by(|a, b| a.total_cmp(b));
    let med = d[d.len() / 2];
    (med / 0.6745 / 6f64.sqrt()).max(1e-6)
}

/// Runs with their noise and their fit/held-out split.
#[derive(Debug, Clone)]
pub struct Dataset {
    pub runs: Vec<MeasuredRun>,
    pub noise: Vec<Noise>,
    /// Per run and sample: true when the sample is held out.
    pub held: Vec<Vec<bool>>,
}

/// The one-run split: alternate blocks of [`BLOCK_S`] (shorter for runs under 12 s, so that at
/// least two are held out), the odd ones held out.
pub fn alternate_blocks(r: &MeasuredRun) -> Vec<bool> {
    let block = BLOCK_S.min(r.duration_s() / 4.0).max(1e-3);
    r.t.iter().map(|t| (((t - r.t[0]) / block).floor() as i64) % 2 == 1).collect()
}

impl Dataset {
    pub fn new(runs: Vec<MeasuredRun>) -> Self {
        let noise = runs
            .iter()
            .map(|r| Noise {
                yaw_rate: noise_sigma(&r.yaw_rate),
                ay: noise_sigma(&r.ay),
                increments: increments::noise(r),
            })
            .collect();
        let held = if runs.len() >= 2 {
            runs.iter().enumerate().map(|(i, r)| vec![i % 2 == 1; r.t.len()]).collect()
        } else {
            runs.iter().map(alternate_blocks).collect()
        };
        Self { runs, noise, held }
    }

    /// Names of the runs that are held out entirely (empty with one run).
    pub fn heldout_runs(&self) -> Vec<String> {
        if self.runs.len() >= 2 {
            self.runs
                .iter()
                .zip(&self.held)
                .filter(|(_, h)| h.iter().all(|x| *x))
                .map(|(r, _)| r.name.clone())
                .collect()
        } else {
            Vec::new()
        }
    }

    /// The split stratified by surface and by the baseline's disagreement (two runs or more; one
    /// run keeps its alternate blocks): runs are grouped by surface (dry, then ice), sorted within
    /// each group by the mean square normalized residual of the baseline simulations `base_sims`
    /// (largest first, ties by order given), and dealt out fitted, held, held, fitted, ... on dry
    /// and held, fitted, fitted, held, ... on ice. Runs of similar disagreement thus fall on both
    /// sides, each side gets the same share of each surface and of each effect's disagreement
    /// windows, and a manoeuvre that ranks alike on both surfaces is on both sides.
    pub fn stratified(&self, base_sims: &[Simulated]) -> Dataset {
        let mut out = self.clone();
        if self.runs.len() < 2 {
            return out;
        }
        let excess: Vec<f64> = (0..self.runs.len()).map(|i| mean_square(self, i, &base_sims[i])).collect();
        let mut order: Vec<usize> = (0..self.runs.len()).collect();
        order.sort_by(|&a, &b| {
            self.runs[a].on_ice.cmp(&self.runs[b].on_ice).then(excess[b].total_cmp(&excess[a])).then(a.cmp(&b))
        });
        let mut c = 0;
        for (j, &i) in order.iter().enumerate() {
            if j > 0 && self.runs[i].on_ice != self.runs[order[j - 1]].on_ice {
                c = 0;
            }
            // Fitted, held, held, fitted on dry; the mirror on ice, so that runs of the same kind
            // that rank alike on both surfaces land on opposite sides.
            let held = matches!(c % 4, 1 | 2) != self.runs[i].on_ice;
            out.held[i] = vec![held; self.runs[i].t.len()];
            c += 1;
        }
        // Both sides must have a run.
        if out.held.iter().all(|h| h[0]) || out.held.iter().all(|h| !h[0]) {
            let flip = order[order.len() - 1];
            out.held[flip].iter_mut().for_each(|x| *x = !*x);
        }
        out
    }

    /// The same runs with fitted and held-out samples swapped (the second fold).
    pub fn swapped(&self) -> Dataset {
        let mut out = self.clone();
        out.held.iter_mut().for_each(|h| h.iter_mut().for_each(|x| *x = !*x));
        out
    }
}

/// Mean square normalized residual (per channel) of run `i` over all its samples.
fn mean_square(data: &Dataset, i: usize, sim: &Simulated) -> f64 {
    let (r, nz) = (&data.runs[i], data.noise[i]);
    let z: f64 = (0..r.t.len())
        .map(|k| ((r.yaw_rate[k] - sim.yaw_rate[k]) / nz.yaw_rate).powi(2) + ((r.ay[k] - sim.ay[k]) / nz.ay).powi(2))
        .sum();
    0.5 * z / r.t.len().max(1) as f64
}

/// Sums of squares of one model over the data set.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Scores {
    /// Normalized RSS (both channels) on fitted and held-out samples; n counts samples.
    pub rss_fit: f64,
    pub rss_held: f64,
    pub n_fit: usize,
    pub n_held: usize,
    /// Raw sums of squared residuals per channel (yaw rate, ay) on fitted and held-out samples.
    pub ss_fit: [f64; 2],
    pub ss_held: [f64; 2],
    /// Normalized sums of squares per channel on held-out samples.
    pub zs_held: [f64; 2],
    /// The increment windows ([`super::increments`]): their count on the fitted side, and per
    /// channel (heading, lateral position, lateral velocity) their count and normalized sum of
    /// squares on the held-out side. Their squares are in `rss_fit` and `rss_held` too.
    pub increment_n_fit: usize,
    pub increment_n_held: [usize; increments::N],
    pub increment_zs_held: [f64; increments::N],
}

impl Scores {
    /// Per-channel RMS error on fitted or held-out samples.
    pub fn rmse(&self, held: bool) -> Rmse {
        let (ss, n) = if held { (self.ss_held, self.n_held) } else { (self.ss_fit, self.n_fit) };
        let n = n.max(1) as f64;
        Rmse { yaw_rate_radps: (ss[0] / n).sqrt(), ay_mps2: (ss[1] / n).sqrt() }
    }

    /// Held-out RMS residual over the noise, per channel (yaw rate, ay); 1 = noise only.
    pub fn noise_ratio(&self) -> [f64; 2] {
        let n = self.n_held.max(1) as f64;
        [(self.zs_held[0] / n).sqrt(), (self.zs_held[1] / n).sqrt()]
    }

    /// Held-out RMS over the noise of the increment windows, per channel (heading, lateral
    /// position, lateral velocity); None for a channel without a held-out window.
    pub fn increment_noise_ratio(&self) -> [Option<f64>; increments::N] {
        std::array::from_fn(|c| {
            (self.increment_n_held[c] > 0).then(|| (self.increment_zs_held[c] / self.increment_n_held[c] as f64).sqrt())
        })
    }

    /// Held-out BIC with k parameters.
    pub fn bic_held(&self, k: usize) -> f64 {
        // Two residuals (yaw rate, ay) per held-out sample, and one per increment window and channel.
        let n = (2 * self.n_held + self.increment_n_held.iter().sum::<usize>()).max(1) as f64;
        n * (self.rss_held.max(1e-300) / n).ln() + k as f64 * n.ln()
    }
}

/// Per-channel RMS error.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Rmse {
    pub yaw_rate_radps: f64,
    pub ay_mps2: f64,
}

/// Simulate every run (in parallel) with `p`.
pub fn simulate_all(model: &ReplayModel, data: &Dataset, p: &EffectParams) -> Vec<Simulated> {
    data.runs.par_iter().map(|r| model.simulate(r, p)).collect()
}

/// Simulate (in parallel) only the runs with fitted samples, None for runs held out whole: what a
/// fit's objective and its Jacobian need (held-out runs add nothing to them).
pub fn simulate_fitted(model: &ReplayModel, data: &Dataset, p: &EffectParams) -> Vec<Option<Simulated>> {
    data.runs
        .par_iter()
        .zip(&data.held)
        .map(|(r, h)| h.iter().any(|held| !held).then(|| model.simulate(r, p)))
        .collect()
}

/// Score simulations against the data.
pub fn score(data: &Dataset, sims: &[Simulated]) -> Scores {
    let mut s = Scores::default();
    for (i, (r, sim)) in data.runs.iter().zip(sims).enumerate() {
        let nz = data.noise[i];
        for k in 0..r.t.len() {
            let er = r.yaw_rate[k] - sim.yaw_rate[k];
            let ea = r.ay[k] - sim.ay[k];
            let z = (er / nz.yaw_rate).powi(2) + (ea / nz.ay).powi(2);
            if data.held[i][k] {
                s.rss_held += z;
                s.n_held += 1;
                s.ss_held[0] += er * er;
                s.ss_held[1] += ea * ea;
                s.zs_held[0] += (er / nz.yaw_rate).powi(2);
                s.zs_held[1] += (ea / nz.ay).powi(2);
            } else {
                s.rss_fit += z;
                s.n_fit += 1;
                s.ss_fit[0] += er * er;
                s.ss_fit[1] += ea * ea;
            }
        }
        for w in increments::residuals(r, &nz, sim, &data.held[i]) {
            let z = w.z * w.z;
            if w.held {
                s.rss_held += z;
                s.increment_n_held[w.channel] += 1;
                s.increment_zs_held[w.channel] += z;
            } else {
                s.rss_fit += z;
                s.increment_n_fit += 1;
            }
        }
    }
    s
}

/// Normalized RSS of the fitted samples only (the fit objective).
fn fit_cost(model: &ReplayModel, data: &Dataset, p: &EffectParams) -> f64 {
    let sims = simulate_fitted(model, data, p);
    let mut c = 0.0;
    for (i, (r, sim)) in data.runs.iter().zip(&sims).enumerate() {
        let Some(sim) = sim else { continue };
        let nz = data.noise[i];
        for k in 0..r.t.len() {
            if !data.held[i][k] {
                c +=
                    ((r.yaw_rate[k] - sim.yaw_rate[k]) / nz.yaw_rate).powi(2) + ((r.ay[k] - sim.ay[k]) / nz.ay).powi(2);
            }
        }
        c += increments::residuals(r, &nz, sim, &data.held[i])
            .iter()
            .filter(|w| !w.held)
            .map(|w| w.z * w.z)
            .sum::<f64>();
        if !sim.ok {
            c *= 10.0;
        }
    }
    c
}

/// A candidate tried in one round.
#[derive(Debug, Clone)]
pub struct Trial {
    /// The candidate (its name and form are what reports record).
    pub effect: Effect,
    pub round: usize,
    /// Fitted parameters: (name, value, unit).
    pub params: Vec<(String, f64, String)>,
    /// Held-out BIC improvement over the current model (positive is better).
    pub delta_bic: f64,
    /// Held-out RSS of the candidate over that of the current model.
    pub heldout_rss_ratio: f64,
    /// 95 % intervals of the parameters (computed only for candidates that passed the held-out
    /// tests; empty otherwise).
    pub intervals: Vec<Interval>,
    /// Why it was not accepted (empty for the accepted one).
    pub reason: String,
    /// The fitted parameter values (in the order of [`Effect::params`]).
    pub values: Vec<f64>,
    /// The candidate's scores on the data.
    pub scores: Scores,
}

/// One accepted effect.
#[derive(Debug, Clone)]
pub struct Step {
    pub effect: Effect,
    pub params: Vec<(String, f64, String)>,
    /// 95 % intervals of the parameters at acceptance (estimated jointly with the effects
    /// accepted before).
    pub intervals: Vec<Interval>,
    pub rmse_before: Rmse,
    pub rmse_after: Rmse,
    pub heldout_rmse_before: Rmse,
    pub heldout_rmse_after: Rmse,
    pub evidence: String,
    /// The candidates of its round that explain the data as well, within the criterion's
    /// resolution ([`super::equivalence::members`]); empty when the data told it apart from all.
    pub equivalents: Vec<Equivalent>,
}

/// One fold of the held-out design: the model is fitted on one side of the split and scored on
/// the other.
#[derive(Debug, Clone, Serialize)]
pub struct Fold {
    /// Runs held out entirely in this fold (empty with one run: alternate blocks).
    pub heldout_runs: Vec<String>,
    pub baseline_heldout_rmse: Rmse,
    pub final_heldout_rmse: Rmse,
    /// Held-out RMS residual over the noise, per channel [yaw rate, ay], baseline and final.
    pub baseline_noise_ratio: [f64; 2],
    pub final_noise_ratio: [f64; 2],
    /// The same for the increment windows [heading, lateral position, lateral velocity]
    /// ([`super::increments`]); null for a channel no run logs, and left out of the report when
    /// no run logs any.
    #[serde(skip_serializing_if = "no_increments")]
    pub baseline_increment_noise_ratio: [Option<f64>; increments::N],
    #[serde(skip_serializing_if = "no_increments")]
    pub final_increment_noise_ratio: [Option<f64>; increments::N],
    /// Held-out increment windows per channel (what [`increment_noise_limit`] is taken at).
    #[serde(skip_serializing_if = "no_windows")]
    pub increment_windows: [usize; increments::N],
}

fn no_increments(r: &[Option<f64>; increments::N]) -> bool {
    r.iter().all(Option::is_none)
}

fn no_windows(n: &[usize; increments::N]) -> bool {
    n.iter().all(|n| *n == 0)
}

/// The held-out RMS over the noise at or below which an increment channel with `n` held-out windows is
/// at the noise: [`EXPLAINED_NOISE_RATIO`], or, when there are so few windows that noise alone
/// passes that ratio by chance, the RMS that noise alone stays below with probability 0.999 (the
/// chi-square quantile with n degrees of freedom by the Wilson-Hilferty cube; 1.94 for 6 windows,
/// 1.66 for 12, 1.5 from 21 on). The sample channels have thousands of held-out samples,
/// whose noise-only RMS stays within a few per cent of 1, so the ratio alone is their limit.
pub fn increment_noise_limit(n: usize) -> f64 {
    const Z999: f64 = 3.090_232;
    let n = n.max(1) as f64;
    let c = 2.0 / (9.0 * n);
    let q = (1.0 - c + Z999 * c.sqrt()).powi(3);
    EXPLAINED_NOISE_RATIO.max(q.sqrt())
}

impl Fold {
    /// A fold's figures from its baseline's and final model's scores.
    pub fn new(heldout_runs: Vec<String>, baseline: &Scores, fin: &Scores) -> Self {
        Fold {
            heldout_runs,
            baseline_heldout_rmse: baseline.rmse(true),
            final_heldout_rmse: fin.rmse(true),
            baseline_noise_ratio: baseline.noise_ratio(),
            final_noise_ratio: fin.noise_ratio(),
            baseline_increment_noise_ratio: baseline.increment_noise_ratio(),
            final_increment_noise_ratio: fin.increment_noise_ratio(),
            increment_windows: fin.increment_n_held,
        }
    }

    /// True when the final model leaves every scored channel of this fold's held-out side at the
    /// noise: the yaw rate and a_y within [`EXPLAINED_NOISE_RATIO`], each increment channel within
    /// [`increment_noise_limit`] of its window count.
    pub fn final_at_noise(&self) -> bool {
        self.final_noise_ratio.iter().all(|r| *r <= EXPLAINED_NOISE_RATIO)
            && (0..increments::N).all(|c| {
                self.final_increment_noise_ratio[c]
                    .is_none_or(|r| r <= increment_noise_limit(self.increment_windows[c]))
            })
    }
}

/// An effect named in an earlier round and dropped after a later round's joint refit, because
/// the intervals of its parameters (estimated jointly with every effect then accepted) all
/// contain their no-effect values: a later effect explains what it stood in for.
#[derive(Debug, Clone)]
pub struct Dropped {
    pub effect: Effect,
    /// The round it was accepted in and the round after whose refit it was dropped.
    pub accepted_round: usize,
    pub dropped_round: usize,
    /// Its parameters after the joint refit, with their intervals.
    pub params: Vec<(String, f64, String)>,
    pub intervals: Vec<Interval>,
    pub reason: String,
}

/// An accepted effect with its final parameters (after any joint refit) and their intervals.
#[derive(Debug, Clone)]
pub struct FinalEffect {
    pub effect: Effect,
    /// (name, value, unit).
    pub params: Vec<(String, f64, String)>,
    pub intervals: Vec<Interval>,
    /// Whether some parameter's interval still excludes its no-effect value.
    pub significant: bool,
}

/// What the discovery concludes about the data (serialised, and printed, as [`Verdict::as_str`],
/// the one list of its names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Nothing named, and the baseline already leaves every fold's held-out residuals within
    /// [`EXPLAINED_NOISE_RATIO`] times the noise.
    NothingMissing,
    /// Effects named, and with them every fold's held-out residuals are within that ratio.
    Explained,
    /// As `Explained`, but some named effect has equivalent forms: candidates that explain the
    /// data as well ([`Discovery::classes`]), which the runs given cannot tell apart.
    ExplainedEquivalent,
    /// Effects named, but some fold's held-out residuals stay above that ratio.
    PartlyExplained,
    /// Nothing named, and the residuals stay above that ratio.
    Unexplained,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::NothingMissing => "nothing_missing",
            Verdict::Explained => "explained",
            Verdict::ExplainedEquivalent => "explained (equivalent forms)",
            Verdict::PartlyExplained => "partly_explained",
            Verdict::Unexplained => "unexplained",
        }
    }

    /// True when the final model leaves the data at the noise (explained or nothing missing).
    pub fn at_noise(self) -> bool {
        matches!(self, Verdict::NothingMissing | Verdict::Explained | Verdict::ExplainedEquivalent)
    }
}

vehsim_core::named_by_as_str!(Verdict);

/// Result of the greedy search.
#[derive(Debug, Clone)]
pub struct Discovery {
    pub baseline: Scores,
    pub final_scores: Scores,
    pub params: EffectParams,
    pub steps: Vec<Step>,
    /// Every accepted effect with its final parameters. They equal the steps' values unless a
    /// joint refit moved them (see [`fit_jointly`]).
    pub final_effects: Vec<FinalEffect>,
    pub rejected: Vec<Trial>,
    /// Effects named in an earlier round and dropped after a later joint refit (see [`Dropped`]);
    /// they are no longer in `named` nor in `final_effects`.
    pub dropped: Vec<Dropped>,
    /// The effects named, in the order they were accepted, each in its accepted form (reports
    /// list them by name).
    pub named: Vec<Effect>,
    pub verdict: Verdict,
    /// The split used (per run and sample: true when held out); see [`Dataset::stratified`].
    pub held: Vec<Vec<bool>>,
    /// Fold 1: fitted on the split's fitted side, scored on its held-out side (the selection's own
    /// scores); fold 2: the accepted effects refitted on the held-out side and scored on the
    /// fitted side.
    pub folds: Vec<Fold>,
    /// Leave-one-run-out intervals of the final effects ([`jackknife`]), when asked for.
    pub jackknife: Option<Jackknife>,
    /// The named effects that have equivalent forms, each with the manoeuvre proposed to
    /// separate them ([`super::equivalence`]); empty when every named effect was told apart.
    pub classes: Vec<Class>,
    /// The road-per-run step after the search ([`super::road_per_run::consider`]): None when it
    /// was not asked (one run, or `road` not among the candidates).
    pub road_per_run: Option<super::road_per_run::Outcome>,
}

/// Parameters with `effects` switched on over `base`, their values the flat vector `x` (in the
/// order of the effects and of their parameters).
pub fn apply_all(base: &EffectParams, effects: &[(Effect, Vec<f64>)], x: &[f64]) -> EffectParams {
    let mut p = *base;
    let mut i = 0;
    for (e, _) in effects {
        let n = e.params().len();
        e.apply(&mut p, &x[i..i + n]);
        i += n;
    }
    p
}

/// Parameters with `effects` switched on at their values over `base`.
pub fn apply_flat(base: &EffectParams, effects: &[(Effect, Vec<f64>)]) -> EffectParams {
    let x: Vec<f64> = effects.iter().flat_map(|(_, v)| v.iter().copied()).collect();
    apply_all(base, effects, &x)
}

pub(super) fn fit_effect(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    e: Effect,
) -> (Vec<f64>, EffectParams) {
    fit_ranked(model, data, base, e, &ranked_starts(model, data, base, e))
}

/// The fitted cost of candidate `e` (over `base`) at its start value and at each of its start
/// points ([`Effect::starts`]: the 7-point scan of a one-parameter effect), best first.
pub(super) fn ranked_starts(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    e: Effect,
) -> Vec<(f64, Vec<f64>)> {
    let cost = |v: &[f64]| {
        let mut p = *base;
        e.apply(&mut p, v);
        fit_cost(model, data, &p)
    };
    // The simplex starts from the best of the start value, the effect's start points and, for a
    // friction region, the points placed at the largest disagreement windows
    // ([`super::region_starts`]), so that it begins in the right basin; an effect with several basins
    // ([`Effect::fit_passes`]) gets a simplex from each of its basins' best starts
    // ([`pass_starts`]), the best kept.
    let x0: Vec<f64> = e.params().iter().map(|d| d.start).collect();
    let placed = super::region_starts::region_starts(e, model, data, base);
    let mut ranked: Vec<(f64, Vec<f64>)> =
        std::iter::once(x0).chain(e.starts()).chain(placed).map(|s| (cost(&s), s)).collect();
    // Stable: ties keep the start value first.
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    ranked
}

/// The fit of candidate `e` from its starts `ranked` ([`ranked_starts`]).
pub(super) fn fit_ranked(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    e: Effect,
    ranked: &[(f64, Vec<f64>)],
) -> (Vec<f64>, EffectParams) {
    // The simplex starts from the best of the start value and the effect's start points, so
    // that it begins in the right basin; an effect with several basins
    // ([`Effect::fit_passes`]) gets a simplex from each of its basins' best starts
    // ([`pass_starts`]), the best kept.
    let mut best: Option<(f64, Vec<f64>, EffectParams)> = None;
    for s in pass_starts(e, ranked) {
        let (mut vals, p) = fit_jointly(model, data, base, &[(e, s)]);
        let c = fit_cost(model, data, &p);
        if best.as_ref().is_none_or(|b| c < b.0) {
            best = Some((c, vals.remove(0), p));
        }
    }
    let (_, vals, p) = best.expect("one start at least");
    (vals, p)
}

/// The start points of an effect's simplex searches ([`Effect::fit_passes`] of them), from its
/// starts `ranked` by cost, best first: the best start, then the next best. The tread state's
/// heat capacity (its parameter 1) acts only through the melting cap: where the runs do not
/// reach melting, starts that differ only in it tie (to round-off) and their searches repeat one
/// another in the basin without melting, whose objective is flat in it. So its further passes
/// start from the best start at each heat capacity of the grid at which the runs do reach melting
/// (the cost differs from the same start at the grid's largest heat capacity), to search the
/// basin where they melt too, before any next-best start.
fn pass_starts(e: Effect, ranked: &[(f64, Vec<f64>)]) -> Vec<Vec<f64>> {
    let passes = e.fit_passes();
    let mut out: Vec<Vec<f64>> = ranked.iter().take(1).map(|r| r.1.clone()).collect();
    if e == Effect::ThermalState {
        let c_max = ranked.iter().map(|r| r.1[1]).fold(f64::MIN, f64::max);
        let melts = |cost: f64, s: &[f64]| {
            ranked
                .iter()
                .any(|(c, t)| t[1] == c_max && t[0] == s[0] && t[2] == s[2] && (c - cost).abs() > 1e-9 * cost.abs())
        };
        let mut capacities: Vec<f64> = Vec::new();
        for (cost, s) in ranked {
            if out.len() < passes && !capacities.contains(&s[1]) && melts(*cost, s) && !out.contains(s) {
                capacities.push(s[1]);
                out.push(s.clone());
            }
        }
    }
    for (_, s) in ranked {
        if out.len() < passes && !out.contains(s) {
            out.push(s.clone());
        }
    }
    out
}

/// Fit the parameters of `effects` together (all of them free at once) from their given values,
/// on the fitted samples only, by bounded Nelder–Mead. One effect: the fit of a candidate. All
/// accepted effects: the joint refit. Each greedy round fits only its new candidate, with the
/// earlier effects held at values fitted without it; when effects overlap (both change the front
/// axle's response, say) the earlier values are biased, and the joint refit removes that bias.
/// Returns the new values per effect and the parameters.
pub fn fit_jointly(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    effects: &[(Effect, Vec<f64>)],
) -> (Vec<Vec<f64>>, EffectParams) {
    let defs: Vec<_> = effects.iter().flat_map(|(e, _)| e.params().iter()).collect();
    let x0: Vec<f64> = effects.iter().flat_map(|(_, v)| v.iter().copied()).collect();
    let sc: Vec<f64> = defs.iter().map(|d| d.scale).collect();
    let lo: Vec<f64> = defs.iter().map(|d| d.lo).collect();
    let hi: Vec<f64> = defs.iter().map(|d| d.hi).collect();
    let split = |x: &[f64]| -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        let mut i = 0;
        for (e, _) in effects {
            let n = e.params().len();
            out.push(x[i..i + n].to_vec());
            i += n;
        }
        out
    };
    let mut f = |x: &[f64]| fit_cost(model, data, &apply_all(base, effects, x));
    // The simplex returns its best point inside the bounds.
    let (x, _) = nelder_mead(&mut f, &x0, &sc, &lo, &hi, FIT_EVALS * defs.len());
    (split(&x), apply_all(base, effects, &x))
}

/// The effects of `accepted` (all but the last, the newest) that are no longer significant when
/// their intervals are estimated jointly with all of them ([`refine`]): their indices, with the
/// polished values and the intervals of every effect.
pub fn redundant(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    accepted: &[(Effect, Vec<f64>)],
) -> (Vec<Vec<f64>>, Vec<Vec<Interval>>, Vec<usize>) {
    let (vals, ivs) = refine(model, data, base, accepted);
    let last = accepted.len().saturating_sub(1);
    let gone = (0..last).filter(|&i| !significant(accepted[i].0, &ivs[i])).collect();
    (vals, ivs, gone)
}

impl Discovery {
    /// The names of the effects named, in order (as reports list them), then `road (per_run)`
    /// when each run was given its own road.
    pub fn named_names(&self) -> Vec<&'static str> {
        let per_run = self.road_per_run.as_ref().and_then(|o| o.roads()).map(|_| "road (per_run)");
        self.named.iter().map(|e| e.name()).chain(per_run).collect()
    }

    /// Each run's own road (bank, grade), when the road-per-run step adopted them.
    pub fn run_roads(&self) -> Option<&[super::road_per_run::RunRoad]> {
        self.road_per_run.as_ref().and_then(|o| o.roads())
    }

    /// The named effects' names joined by ", ", or "none".
    pub fn named_text(&self) -> String {
        if self.named_names().is_empty() {
            "none".to_string()
        } else {
            self.named_names().join(", ")
        }
    }
}

/// A time window where the residuals exceed the noise.
#[derive(Debug, Clone, Serialize)]
pub struct Window {
    pub run: String,
    pub t0_s: f64,
    pub t1_s: f64,
    /// Mean square normalized residual (per channel) inside the window.
    pub excess: f64,
}

/// Windows where the moving mean (0.5 s) of the squared normalized residual, per channel, exceeds 2.
pub fn disagreement_windows(data: &Dataset, sims: &[Simulated]) -> Vec<Window> {
    let mut out = Vec::new();
    for (i, (r, sim)) in data.runs.iter().zip(sims).enumerate() {
        let nz = data.noise[i];
        let z: Vec<f64> = (0..r.t.len())
            .map(|k| {
                0.5 * (((r.yaw_rate[k] - sim.yaw_rate[k]) / nz.yaw_rate).powi(2)
                    + ((r.ay[k] - sim.ay[k]) / nz.ay).powi(2))
            })
            .collect();
        let n = z.len();
        let dt = (r.t[n - 1] - r.t[0]) / (n - 1) as f64;
        let half = ((0.25 / dt).round() as usize).max(2);
        let mut prefix = vec![0.0; n + 1];
        for k in 0..n {
            prefix[k + 1] = prefix[k] + z[k];
        }
        let mut start: Option<usize> = None;
        for k in 0..=n {
            let flagged = k < n && {
                let a = k.saturating_sub(half);
                let b = (k + half + 1).min(n);
                (prefix[b] - prefix[a]) / (b - a) as f64 > 2.0
            };
            match (flagged, start) {
                (true, None) => start = Some(k),
                (false, Some(s)) => {
                    let e = k - 1;
                    if r.t[e] - r.t[s] >= 0.2 {
                        let m = (prefix[e + 1] - prefix[s]) / (e + 1 - s) as f64;
                        out.push(Window { run: r.name.clone(), t0_s: r.t[s], t1_s: r.t[e], excess: m });
                    }
                    start = None;
                }
                _ => {}
            }
        }
    }
    out
}

/// Residual statistics over one bin of an operating variable.
#[derive(Debug, Clone, Serialize)]
pub struct RegionBin {
    pub variable: String,
    pub lo: f64,
    pub hi: f64,
    pub samples: usize,
    /// Mean square normalized residual per channel in the bin (1 = noise only).
    pub excess: f64,
    /// True when the excess is beyond what noise explains (> 2).
    pub disagrees: bool,
}

/// Residual excess binned by |ay| (m/s^2), vx (m/s), |front slip angle| (rad, simulated),
/// elapsed time (s) and distance travelled (m).
pub fn operating_regions(data: &Dataset, sims: &[Simulated]) -> Vec<RegionBin> {
    let vars: [(&str, &[f64]); 5] = [
        ("abs_ay_mps2", &[0.0, 1.0, 2.0, 4.0, 7.0, 1e9]),
        ("vx_mps", &[0.0, 5.0, 10.0, 20.0, 30.0, 1e9]),
        ("abs_front_slip_rad", &[0.0, 0.01, 0.03, 0.06, 0.1, 1e9]),
        ("elapsed_s", &[0.0, 2.0, 5.0, 10.0, 20.0, 1e9]),
        ("distance_m", &[0.0, 50.0, 100.0, 200.0, 500.0, 1e9]),
    ];
    let mut out = Vec::new();
    for (name, edges) in vars {
        let mut acc = vec![(0usize, 0.0f64); edges.len() - 1];
        for (i, (r, sim)) in data.runs.iter().zip(sims).enumerate() {
            let nz = data.noise[i];
            let mut s = 0.0;
            for k in 0..r.t.len() {
                if k > 0 {
                    s += 0.5 * (r.vx[k] + r.vx[k - 1]) * (r.t[k] - r.t[k - 1]);
                }
                let v = match name {
                    "abs_ay_mps2" => r.ay[k].abs(),
                    "vx_mps" => r.vx[k],
                    "abs_front_slip_rad" => sim.alpha_f[k].abs(),
                    "elapsed_s" => r.t[k] - r.t[0],
                    _ => s,
                };
                if let Some(b) = (0..edges.len() - 1).find(|&b| v >= edges[b] && v < edges[b + 1]) {
                    acc[b].0 += 1;
                    acc[b].1 += 0.5
                        * (((r.yaw_rate[k] - sim.yaw_rate[k]) / nz.yaw_rate).powi(2)
                            + ((r.ay[k] - sim.ay[k]) / nz.ay).powi(2));
                }
            }
        }
        for (b, (n, z)) in acc.into_iter().enumerate() {
            if n > 0 {
                let m = z / n as f64;
                out.push(RegionBin {
                    variable: name.to_string(),
                    lo: edges[b],
                    hi: edges[b + 1],
                    samples: n,
                    excess: m,
                    disagrees: m > 2.0,
                });
            }
        }
    }
    out
}

/// Leave-one-run-out (jackknife) uncertainty of the final effects: a check on the Jacobian
/// intervals that does not rest on the residuals' noise model. Each fitted run in turn is moved
/// to the held-out side and every final effect is refitted jointly on the remaining fitted runs
/// (from the final values); with n such refits theta_(i) and their mean theta_bar,
///
///   se = sqrt((n - 1) / n sum_i (theta_(i) - theta_bar)^2),   95 %: theta +- t_(0.975, n-1) se.
///
/// Runs, not samples, are left out, so correlation within a run and differences between runs
/// (a manoeuvre the effect does not describe well) widen it. With few fitted runs it is coarse
/// (t = 4.30 at n = 3, 3.18 at n = 4).
#[derive(Debug, Clone)]
pub struct Jackknife {
    /// The fitted runs, each left out once, in order.
    pub runs_left_out: Vec<String>,
    pub effects: Vec<JackknifeEffect>,
}

/// The jackknife of one final effect.
#[derive(Debug, Clone)]
pub struct JackknifeEffect {
    pub effect: Effect,
    /// (name, value, unit) at the final fit.
    pub params: Vec<(String, f64, String)>,
    pub intervals: Vec<Interval>,
    /// The refitted values with each run left out (in the order of `runs_left_out`).
    pub leave_one_out: Vec<Vec<f64>>,
}

/// Two-sided 97.5 % quantile of Student's t with `df` degrees of freedom: exact for 1 and 2,
/// else the expansion z + (z^3 + z) / (4 df) (within 0.3 % from 3 on).
pub fn t975(df: usize) -> f64 {
    match df {
        0 => f64::INFINITY,
        1 => 12.706,
        2 => 4.303,
        _ => {
            let z = super::uncertainty::Z95;
            z + (z.powi(3) + z) / (4.0 * df as f64)
        }
    }
}

/// The jackknife over the fitted runs of `data` (its split as the discovery used it) for the
/// `effects` at their final values over `base`; None with fewer than three fitted runs.
pub fn jackknife(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    effects: &[(Effect, Vec<f64>)],
) -> Option<Jackknife> {
    let fitted: Vec<usize> = (0..data.runs.len()).filter(|&i| data.held[i].iter().any(|h| !h)).collect();
    let n = fitted.len();
    if n < 3 || effects.is_empty() {
        return None;
    }
    // Each refit in turn (each is parallel over the runs inside); the order is fixed.
    let loo: Vec<Vec<Vec<f64>>> = fitted
        .iter()
        .map(|&i| {
            let mut d = data.clone();
            d.held[i].iter_mut().for_each(|h| *h = true);
            fit_jointly(model, &d, base, effects).0
        })
        .collect();
    let t = t975(n - 1);
    let out = effects
        .iter()
        .enumerate()
        .map(|(j, (e, v))| {
            let intervals = (0..v.len())
                .map(|k| {
                    let xs: Vec<f64> = loo.iter().map(|r| r[j][k]).collect();
                    let mean = xs.iter().sum::<f64>() / n as f64;
                    let ss: f64 = xs.iter().map(|x| (x - mean).powi(2)).sum();
                    let se = ((n - 1) as f64 / n as f64 * ss).sqrt();
                    Interval { std_error: se, lo: v[k] - t * se, hi: v[k] + t * se }
                })
                .collect();
            JackknifeEffect {
                effect: *e,
                params: triples(*e, v),
                intervals,
                leave_one_out: loo.iter().map(|r| r[j].clone()).collect(),
            }
        })
        .collect();
    Some(Jackknife { runs_left_out: fitted.iter().map(|&i| data.runs[i].name.clone()).collect(), effects: out })
}
