//! The greedy search that names effects: rounds of candidate fits scored on held-out data,
//! acceptance, joint refits and drops, the final significance rule, the second fold and the
//! verdict. The scores, thresholds and result types are [`super::select`]'s; what the data
//! cannot tell apart is [`super::equivalence`]'s.
//!
//! [`discover_with`] reads as its phases: stratify the split, run rounds
//! (`Search::round`: fit every candidate left, choose the best that passes the held-out tests
//! and the interval test, accept it, refit jointly and drop what it made redundant) until none
//! passes, make every named effect significant in the final joint fit
//! (`Search::final_intervals`), then score the second fold and give the verdict
//! (`Search::conclude`).

use rayon::prelude::*;

use super::effects::Effect;
use super::equivalence::{self, Class};
use super::model::{EffectParams, ReplayModel, Simulated};
use super::select::{
    apply_flat, fit_effect, fit_jointly, fit_ranked, ranked_starts, redundant, score, simulate_all, Dataset, Discovery,
    Dropped, FinalEffect, Fold, Scores, Step, Trial, Verdict, BIC_MIN, MIN_GAIN,
};
use super::uncertainty::{refine, significant, Interval};

/// A progress sink: one line per finished candidate and per round.
pub type Progress<'a> = Option<&'a (dyn Fn(&str) + Sync)>;

/// Run the greedy discovery over `candidates` from the plain bicycle baseline.
pub fn discover(model: &ReplayModel, data: &Dataset, candidates: &[Effect]) -> Discovery {
    discover_from(model, data, EffectParams::default(), candidates)
}

/// Run the greedy discovery over `candidates` from the baseline `base`.
pub fn discover_from(model: &ReplayModel, data: &Dataset, base: EffectParams, candidates: &[Effect]) -> Discovery {
    discover_with(model, data, base, candidates, None)
}

/// Run the greedy discovery over `candidates` from the baseline `base`, on the split stratified
/// from the baseline's residuals ([`Dataset::stratified`]), reporting progress to `progress`.
pub fn discover_with(
    model: &ReplayModel,
    data: &Dataset,
    base: EffectParams,
    candidates: &[Effect],
    progress: Progress,
) -> Discovery {
    let base_sims = simulate_all(model, data, &base);
    let data = &data.stratified(&base_sims);
    let mut search = Search::new(model, data, base, candidates, progress, score(data, &base_sims));
    while !search.left.is_empty() && search.round() {}
    let final_iv = search.final_intervals();
    let mut d = search.conclude(&base_sims, final_iv);
    if candidates.contains(&Effect::Road) {
        super::road_per_run::consider(model, data, &base, candidates, &mut d, progress);
    }
    d
}

/// Parameter triples (name, value, unit) of an effect.
pub(super) fn triples(e: Effect, v: &[f64]) -> Vec<(String, f64, String)> {
    e.params().iter().zip(v).map(|(d, x)| (d.name.to_string(), *x, d.unit.to_string())).collect()
}

/// A round's trial: the candidate, its scores and the parameters with it switched on.
type Fitted = (Effect, Trial, EffectParams);

/// How many one-parameter candidates a round fits by simplex: those whose 7-point scan reaches the
/// lowest fitted cost. The others keep their scan's best point (scored like any trial, not
/// accepted, reason "screened out"). Every one-parameter candidate costs its 7 scan replays per
/// round; only these also cost a simplex (about 20 replays more each), so a candidate generated
/// from the vehicle spec adds 7 replays of the fitted runs per round, not a fit.
pub const SCREEN_KEEP: usize = 6;

/// A candidate of a round after the screen: fitted by simplex from its ranked starts, or screened
/// out at its scan's best point.
struct Screened {
    effect: Effect,
    ranked: Vec<(f64, Vec<f64>)>,
    fit: bool,
}

/// The search between rounds.
struct Search<'a> {
    model: &'a ReplayModel,
    data: &'a Dataset,
    base: EffectParams,
    progress: Progress<'a>,
    /// The baseline's scores, and the current model's parameters and scores.
    baseline: Scores,
    p: EffectParams,
    current: Scores,
    /// Parameters fitted so far (the BIC's k).
    k_params: usize,
    steps: Vec<Step>,
    rejected: Vec<Trial>,
    named: Vec<Effect>,
    /// Candidates still in the pool.
    left: Vec<Effect>,
    /// The accepted effects with their current values, and the round each was accepted in.
    accepted: Vec<(Effect, Vec<f64>)>,
    accepted_round: Vec<usize>,
    dropped: Vec<Dropped>,
    round: usize,
}

impl<'a> Search<'a> {
    fn new(
        model: &'a ReplayModel,
        data: &'a Dataset,
        base: EffectParams,
        candidates: &[Effect],
        progress: Progress<'a>,
        baseline: Scores,
    ) -> Self {
        Search {
            model,
            data,
            base,
            progress,
            baseline,
            p: base,
            current: baseline,
            k_params: 0,
            steps: Vec::new(),
            rejected: Vec::new(),
            named: Vec::new(),
            left: candidates.to_vec(),
            accepted: Vec::new(),
            accepted_round: Vec::new(),
            dropped: Vec::new(),
            round: 0,
        }
    }

    fn say(&self, m: String) {
        if let Some(f) = self.progress {
            f(&m)
        }
    }

    /// The current model with `accepted` at their values, and its scores.
    fn rescore(&mut self) {
        self.p = apply_flat(&self.base, &self.accepted);
        self.current = score(self.data, &simulate_all(self.model, self.data, &self.p));
    }

    /// One round: fit every candidate left, accept the best that passes. False when none passes.
    fn round(&mut self) -> bool {
        self.round += 1;
        let round = self.round;
        self.say(format!("round {round}: fitting {} candidates", self.left.len()));
        let t0 = std::time::Instant::now();
        let mut trials = self.fit_candidates();
        // Best first by held-out BIC.
        trials.sort_by(|a, b| b.1.delta_bic.total_cmp(&a.1.delta_bic));
        let chosen = self.choose(&mut trials);
        self.reject_all_but(&trials, chosen.as_ref().map(|c| c.0));
        let Some((bi, polished)) = chosen else {
            self.say(format!("round {round}: nothing accepted ({:.1} s)", t0.elapsed().as_secs_f64()));
            return false;
        };
        let e = trials[bi].0;
        self.say(format!("round {round}: accepted {} ({:.1} s)", e.label(), t0.elapsed().as_secs_f64()));
        self.accept(&trials, bi, polished);
        if self.accepted.len() >= 2 {
            self.refit_and_drop(e);
        }
        // Both forms of a named effect leave the pool together.
        self.left.retain(|x| x.name() != e.name());
        true
    }

    /// The candidates left after the screen ([`SCREEN_KEEP`]): every one-parameter candidate's
    /// scan, the best of them kept for the simplex; every other candidate is fitted.
    fn screen(&self) -> Vec<Screened> {
        let mut out: Vec<Screened> = self
            .left
            .par_iter()
            .map(|&e| {
                let scanned = e.params().len() == 1;
                let ranked = if scanned { ranked_starts(self.model, self.data, &self.p, e) } else { Vec::new() };
                Screened { effect: e, ranked, fit: !scanned }
            })
            .collect();
        let mut order: Vec<usize> = (0..out.len()).filter(|&i| !out[i].fit).collect();
        // Stable: ties keep the candidates' order.
        order.sort_by(|&a, &b| out[a].ranked[0].0.total_cmp(&out[b].ranked[0].0));
        for &i in order.iter().take(SCREEN_KEEP) {
            out[i].fit = true;
        }
        out
    }

    /// Every candidate left fitted on the fitted samples (in parallel; one-parameter candidates
    /// after the screen) and scored.
    fn fit_candidates(&self) -> Vec<Fitted> {
        let (round, k_params, current) = (self.round, self.k_params, self.current);
        self.screen()
            .par_iter()
            .map(|c| {
                let (e, t) = (c.effect, std::time::Instant::now());
                let (vals, pc) = match (c.fit, c.ranked.is_empty()) {
                    (true, true) => fit_effect(self.model, self.data, &self.p, e),
                    (true, false) => fit_ranked(self.model, self.data, &self.p, e, &c.ranked),
                    (false, _) => {
                        let v = c.ranked[0].1.clone();
                        (v.clone(), apply_flat(&self.p, &[(e, v)]))
                    }
                };
                let sc = score(self.data, &simulate_all(self.model, self.data, &pc));
                let k = k_params + e.params().len();
                let trial = Trial {
                    effect: e,
                    round,
                    params: triples(e, &vals),
                    delta_bic: current.bic_held(k_params) - sc.bic_held(k),
                    heldout_rss_ratio: sc.rss_held / current.rss_held.max(1e-300),
                    intervals: Vec::new(),
                    reason: if c.fit {
                        String::new()
                    } else {
                        format!(
                            "screened out: its 7-point scan was not among the {SCREEN_KEEP} best one-parameter scans"
                        )
                    },
                    values: vals,
                    scores: sc,
                };
                self.say(format!(
                    "round {round}: {} held-out dBIC {:.1} ({:.1} s)",
                    e.label(),
                    trial.delta_bic,
                    t.elapsed().as_secs_f64()
                ));
                (e, trial, pc)
            })
            .collect()
    }

    /// The first trial (best first) that passes the held-out tests and whose interval excludes its
    /// no-effect value: its index and the polished values of every accepted effect and of it.
    /// Trials tested and failed get their reason.
    fn choose(&self, trials: &mut [Fitted]) -> Option<(usize, Vec<Vec<f64>>)> {
        for (j, (e, t, _)) in trials.iter_mut().enumerate() {
            if !t.reason.is_empty() {
                continue;
            }
            if !(t.delta_bic > BIC_MIN && t.heldout_rss_ratio < 1.0 - MIN_GAIN) {
                t.reason = format!(
                    "held-out dBIC {:.1} (needs > {BIC_MIN}) or RSS ratio {:.3} (needs < {:.2})",
                    t.delta_bic,
                    t.heldout_rss_ratio,
                    1.0 - MIN_GAIN
                );
                continue;
            }
            if let Some(name) = at_a_far_bound(*e, &t.values) {
                t.reason = far_bound_reason(name);
                continue;
            }
            if let Some(share) = super::region_starts::region_coverage(*e, &t.values, self.data) {
                if share >= super::region_starts::WHOLE_SHARE {
                    t.reason = format!(
                        "the region covers {:.0} % of the runs' samples: on these runs it is the global friction change",
                        100.0 * share
                    );
                    continue;
                }
            }
            let mut with = self.accepted.clone();
            with.push((*e, t.values.clone()));
            let (vals, ivs) = refine(self.model, self.data, &self.base, &with);
            t.intervals = ivs.last().cloned().unwrap_or_default();
            // The polish may carry a value onto the edge of its range, too.
            if let Some(name) = vals.last().and_then(|v| at_a_far_bound(*e, v)) {
                t.reason = far_bound_reason(name);
                continue;
            }
            if significant(*e, &t.intervals) {
                return Some((j, vals));
            }
            t.reason = "a 95 % interval contains the no-effect value".to_string();
        }
        None
    }

    /// Every trial but the chosen one goes to `rejected`, with its reason.
    fn reject_all_but(&mut self, trials: &[Fitted], chosen: Option<usize>) {
        for (j, (_, tr, _)) in trials.iter().enumerate() {
            if Some(j) != chosen {
                let mut tr = tr.clone();
                if tr.reason.is_empty() {
                    tr.reason = "a better candidate was accepted this round".to_string();
                }
                self.rejected.push(tr);
            }
        }
    }

    /// Accept trial `bi` with the `polished` values of every accepted effect and of it; its
    /// equivalents are the trials ranked below it that explain the data as well.
    fn accept(&mut self, trials: &[Fitted], bi: usize, polished: Vec<Vec<f64>>) {
        // Those ranked above the chosen one failed its interval test: no alternative.
        let below: Vec<&Trial> = trials[bi + 1..].iter().map(|(_, t, _)| t).collect();
        let mut equivalents = equivalence::members(&trials[bi].1, &below);
        equivalence::refit(self.model, self.data, &self.base, &self.accepted, &mut equivalents);
        let (e, t, _) = &trials[bi];
        self.accepted.push((*e, Vec::new()));
        self.accepted_round.push(self.round);
        for (a, v) in self.accepted.iter_mut().zip(polished) {
            a.1 = v;
        }
        self.p = apply_flat(&self.base, &self.accepted);
        let after = score(self.data, &simulate_all(self.model, self.data, &self.p));
        self.steps.push(Step {
            effect: t.effect,
            params: triples(*e, &self.accepted[self.accepted.len() - 1].1),
            intervals: t.intervals.clone(),
            rmse_before: self.current.rmse(false),
            rmse_after: after.rmse(false),
            heldout_rmse_before: self.current.rmse(true),
            heldout_rmse_after: after.rmse(true),
            evidence: format!(
                "held-out BIC lower by {:.1} (threshold {BIC_MIN}); held-out normalized RSS x{:.3}; {} parameter(s) fitted on the fitted samples only; {}",
                t.delta_bic,
                t.heldout_rss_ratio,
                e.params().len(),
                if e.structural() {
                    "the form itself is the effect (no parameter value switches it off)"
                } else {
                    "95 % interval excludes the no-effect value"
                }
            ),
            equivalents,
        });
        self.named.push(t.effect);
        self.k_params += e.params().len();
        self.current = after;
    }

    /// Joint refit of everything accepted so far (kept only when it does not make the held-out
    /// data worse); then an effect named earlier whose intervals, now estimated jointly with the
    /// newest `e`, all contain their no-effect values is dropped, and the rest refitted without it.
    fn refit_and_drop(&mut self, e: Effect) {
        let (vals, pj) = fit_jointly(self.model, self.data, &self.base, &self.accepted);
        let sj = score(self.data, &simulate_all(self.model, self.data, &pj));
        if sj.rss_held <= self.current.rss_held {
            for (a, v) in self.accepted.iter_mut().zip(vals) {
                a.1 = v;
            }
            self.current = sj;
            self.p = pj;
        }
        let (vals, ivs, gone) = redundant(self.model, self.data, &self.base, &self.accepted);
        if gone.is_empty() {
            return;
        }
        for &i in gone.iter().rev() {
            let reason = format!(
                "after the joint refit with {}, every 95 % interval of its parameters contains the no-effect value",
                e.label()
            );
            let at = format!("round {}", self.round);
            self.drop_effect(i, triples(self.accepted[i].0, &vals[i]), ivs[i].clone(), reason, &at);
        }
        let (vals, _) = fit_jointly(self.model, self.data, &self.base, &self.accepted);
        for (a, v) in self.accepted.iter_mut().zip(vals) {
            a.1 = v;
        }
        self.rescore();
    }

    /// Remove accepted effect `i` from the named ones, recording it as dropped this round (`at`
    /// heads the progress line).
    fn drop_effect(
        &mut self,
        i: usize,
        params: Vec<(String, f64, String)>,
        intervals: Vec<Interval>,
        reason: String,
        at: &str,
    ) {
        let (de, _) = self.accepted.remove(i);
        let r0 = self.accepted_round.remove(i);
        self.named.remove(i);
        self.k_params -= de.params().len();
        self.say(format!("{at}: dropped {} (its intervals contain the no-effect values)", de.label()));
        self.dropped.push(Dropped {
            effect: de,
            accepted_round: r0,
            dropped_round: self.round,
            params,
            intervals,
            reason,
        });
    }

    /// The final values and intervals, all accepted effects polished together. The final set
    /// answers to the rule of every round, the newest effect included: an effect whose intervals,
    /// estimated jointly with all the others, contain their no-effect values (or cannot be
    /// estimated: a singular Jacobian) is not named. The newest such effect is dropped and the
    /// rest refitted, until every remaining one is significant.
    fn final_intervals(&mut self) -> Vec<Vec<Interval>> {
        loop {
            if self.accepted.is_empty() {
                return Vec::new();
            }
            let (vals, iv) = refine(self.model, self.data, &self.base, &self.accepted);
            for (a, v) in self.accepted.iter_mut().zip(vals) {
                a.1 = v;
            }
            self.rescore();
            let Some(i) = (0..self.accepted.len()).rev().find(|&i| !significant(self.accepted[i].0, &iv[i])) else {
                return iv;
            };
            let params = triples(self.accepted[i].0, &self.accepted[i].1);
            let reason =
                "in the final joint fit of every named effect, every 95 % interval of its parameters contains \
                          the no-effect value (or none could be estimated)"
                    .to_string();
            self.drop_effect(i, params, iv[i].clone(), reason, "final");
            if !self.accepted.is_empty() {
                let (vals, _) = fit_jointly(self.model, self.data, &self.base, &self.accepted);
                for (a, v) in self.accepted.iter_mut().zip(vals) {
                    a.1 = v;
                }
            }
        }
    }

    /// The result: final effects, the second fold (the accepted effects refitted on the other
    /// side of the split), the classes of what the data cannot tell apart, and the verdict.
    fn conclude(self, base_sims: &[Simulated], final_iv: Vec<Vec<Interval>>) -> Discovery {
        let final_effects = self
            .accepted
            .iter()
            .zip(&final_iv)
            .map(|((e, v), iv)| FinalEffect {
                effect: *e,
                params: triples(*e, v),
                intervals: iv.clone(),
                significant: significant(*e, iv),
            })
            .collect();
        let folds = self.folds(base_sims);
        let classes = self.classes();
        let explained = folds.iter().all(Fold::final_at_noise);
        let verdict = match (explained, self.named.is_empty()) {
            (true, true) => Verdict::NothingMissing,
            (true, false) if !classes.is_empty() => Verdict::ExplainedEquivalent,
            (true, false) => Verdict::Explained,
            (false, true) => Verdict::Unexplained,
            (false, false) => Verdict::PartlyExplained,
        };
        Discovery {
            baseline: self.baseline,
            final_scores: self.current,
            params: self.p,
            steps: self.steps,
            final_effects,
            rejected: self.rejected,
            dropped: self.dropped,
            named: self.named,
            verdict,
            held: self.data.held.clone(),
            folds,
            jackknife: None,
            classes,
            road_per_run: None,
        }
    }

    /// Fold 1 (the selection's own scores) and fold 2 (the accepted effects refitted on the
    /// held-out side and scored on the fitted side).
    fn folds(&self, base_sims: &[Simulated]) -> Vec<Fold> {
        let (model, base) = (self.model, &self.base);
        let other = self.data.swapped();
        let other_base = score(&other, base_sims);
        let other_final = if self.accepted.is_empty() {
            other_base
        } else {
            let (vals, _) = fit_jointly(model, &other, base, &self.accepted);
            let refit: Vec<(Effect, Vec<f64>)> = self.accepted.iter().map(|a| a.0).zip(vals).collect();
            let (vals, _) = refine(model, &other, base, &refit);
            let refit: Vec<(Effect, Vec<f64>)> = self.accepted.iter().map(|a| a.0).zip(vals).collect();
            score(&other, &simulate_all(model, &other, &apply_flat(base, &refit)))
        };
        [(self.data, &self.baseline, &self.current), (&other, &other_base, &other_final)]
            .into_iter()
            .map(|(d, b, f)| Fold::new(d.heldout_runs(), b, f))
            .collect()
    }

    /// The classes of the effects still named at the end (final values): each with the
    /// equivalents of the round it was accepted in, and the manoeuvres that would separate them.
    fn classes(&self) -> Vec<Class> {
        self.accepted
            .iter()
            .filter_map(|(e, _)| {
                let step = self.steps.iter().rev().find(|s| s.effect == *e)?;
                if step.equivalents.is_empty() {
                    return None;
                }
                let members = step.equivalents.clone();
                let (separations, proposed) =
                    equivalence::separate(self.model, self.data, &self.base, &self.accepted, *e, &members);
                Some(Class { named: *e, members, separations, proposed })
            })
            .collect()
    }
}

/// The first parameter of `e` fitted at a bound of its range that is not its no-effect value
/// (`values` in the order of `e.params()`): the optimum lies beyond the physical range, so the
/// form is not a point estimate of that cause. Parameters without a no-effect value (a region's
/// place and size) and a parameter resting at its no-effect bound (one channel's latency at 0)
/// are not counted.
pub(super) fn at_a_far_bound(e: Effect, values: &[f64]) -> Option<&'static str> {
    e.params().iter().zip(values).find_map(|(d, v)| {
        let tol = 1e-6 * (d.hi - d.lo);
        let null = d.null?;
        let at = |b: f64| (v - b).abs() <= tol && (b - null).abs() > tol;
        (at(d.lo) || at(d.hi)).then_some(d.name)
    })
}

/// The reason a candidate with parameter `name` at the edge of its range is not named.
fn far_bound_reason(name: &str) -> String {
    format!(
        "{name} fitted at the edge of its physical range: the data ask for more than the form allows, so it \
         stands in for another cause"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A parameter on a bound other than its no-effect value counts; one at its no-effect bound,
    /// one inside its range, and a region's place and size at their bounds do not.
    #[test]
    fn the_edge_rule_counts_only_far_bounds() {
        assert_eq!(at_a_far_bound(Effect::SensorLatency, &[0.0, 0.2]), None);
        assert_eq!(at_a_far_bound(Effect::SensorLatency, &[0.0, 0.5]), Some("latency_ay_s"));
        assert_eq!(at_a_far_bound(Effect::Road, &[3.0, 20.0]), Some("grade_deg"));
        assert_eq!(at_a_far_bound(Effect::Road, &[-35.0, 0.0]), Some("bank_deg"));
        assert_eq!(at_a_far_bound(Effect::FrictionChange, &[0.6]), None);
        assert_eq!(at_a_far_bound(Effect::FrictionChange, &[3.0]), Some("mu_scale"));
        assert_eq!(at_a_far_bound(Effect::FrictionPatch, &[0.6, 5000.0, 0.0, 1.0]), None);
    }
}
