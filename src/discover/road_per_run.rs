//! The road per run: each run's own constant bank and grade, fitted as a nuisance pair per run
//! and compared with the one pair shared by every run ([`Effect::Road`]) and with no road, on the
//! same held-out samples.
//!
//! Split: every run's alternate 3 s blocks ([`super::select::BLOCK_S`], the rule discovery uses
//! for a single run), so that every run has fitted and held-out samples. Fold 1 fits on the even
//! blocks and scores on the odd ones; fold 2 swaps them.
//!
//! Fit: given the shared effects (fixed over `base`), the runs' pairs are independent, so run
//! `i`'s pair (φ_i, θ_i) is fitted alone on run `i`'s fitted blocks (the road candidate's simplex
//! and Gauss–Newton polish on a one-run data set): N fits of two parameters, not one simplex of
//! 2N. With shared effects, these are then refitted jointly on the same fitted blocks with every
//! run on its fitted road and the runs' pairs again given them, alternated until the fitted cost
//! settles, so that no score sees a sample any fit has used.
//!
//! Score: the held-out BIC n ln(RSS/n) + k ln(n) of [`Scores::bic_held`], k = 2N for the per-run
//! form, 2 for the shared pair, 0 for no road (the shared effects' parameters are the same in
//! all three and cancel). A form passes against a simpler one when it lowers its held-out BIC by
//! more than [`BIC_MIN`] and its held-out RSS by at least [`MIN_GAIN`], in both folds.
//!
//! The step after the search ([`consider`]): a cheap screen, the three forms compared, the
//! search run again with each run on its pair, the forms compared again with what it named, and
//! the pairs adopted when they still win (the result's split, scores and verdict then the
//! blocks'); docs/discover.md, "The road: bank and grade".
//!
//! Angles in degrees; bank positive when the road's left edge is higher, grade positive uphill
//! ([`vehsim_core::vehicle::road`]).

use rayon::prelude::*;

use super::effects::Effect;
use super::model::{EffectParams, ReplayModel};
use super::search::Progress;
use super::select::{
    alternate_blocks, apply_flat, fit_effect, fit_jointly, score, simulate_all, Dataset, Discovery, Dropped, Fold,
    Scores, Verdict, BIC_MIN, MIN_GAIN,
};
use super::uncertainty::{refine, significant, Interval};
use vehsim_core::vehicle::road::Road;

/// One run's fitted road.
#[derive(Debug, Clone)]
pub struct RunRoad {
    /// The run's name.
    pub run: String,
    /// Bank and grade, deg.
    pub bank_deg: f64,
    pub grade_deg: f64,
    /// 95 % intervals of bank and grade ([`refine`] on the run's fitted blocks).
    pub intervals: [Interval; 2],
}

impl RunRoad {
    /// The road of this pair.
    pub fn road(&self) -> Road {
        Road::from_deg(self.bank_deg, self.grade_deg)
    }

    /// The `[road]` table to add to the run's sidecar (values written to round-trip exactly).
    pub fn sidecar_toml(&self) -> String {
        format!("[road]\nbank_deg = {:?}\ngrade_deg = {:?}\n", self.bank_deg, self.grade_deg)
    }
}

/// The road forms compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoadForm {
    /// No road (each run's own from its sidecar).
    None,
    /// One pair for every run.
    Shared,
    /// A pair per run.
    PerRun,
}

impl RoadForm {
    /// The form's name as reports write it (`road (per_run)`, `road`, `none`).
    pub fn as_str(self) -> &'static str {
        match self {
            RoadForm::None => "none",
            RoadForm::Shared => "road",
            RoadForm::PerRun => "road (per_run)",
        }
    }
}

/// One fold of the comparison: the fits on one side of the blocks, scored on the other.
#[derive(Debug, Clone)]
pub struct RoadFold {
    /// Each run's pair.
    pub per_run: Vec<RunRoad>,
    /// The shared pair (bank, grade, deg) and its intervals.
    pub shared: Vec<f64>,
    pub shared_intervals: Vec<Interval>,
    /// The shared effects' values with the per-run roads (in the order given).
    pub effects: Vec<Vec<f64>>,
    /// Scores of no road, the shared pair and the per-run pairs.
    pub scores: [Scores; 3],
}

impl RoadFold {
    /// Held-out BIC of each form (none, shared, per-run: k = 0, 2, 2N).
    pub fn bic(&self) -> [f64; 3] {
        let n = self.per_run.len();
        [self.scores[0].bic_held(0), self.scores[1].bic_held(2), self.scores[2].bic_held(2 * n)]
    }

    /// Whether form `b` passes against the simpler form `a` (indices of [`Self::bic`]).
    fn passes(&self, a: usize, b: usize) -> bool {
        let bic = self.bic();
        bic[a] - bic[b] > BIC_MIN && self.scores[b].rss_held < (1.0 - MIN_GAIN) * self.scores[a].rss_held
    }
}

/// Both folds of the comparison, and the form chosen.
#[derive(Debug, Clone)]
pub struct RoadComparison {
    pub folds: [RoadFold; 2],
}

impl RoadComparison {
    /// The form the data ask for: the per-run pairs when they pass against both the shared pair
    /// and no road in both folds, else the shared pair when it passes against no road in both,
    /// else none.
    pub fn chosen(&self) -> RoadForm {
        let all = |a, b| self.folds.iter().all(|f| f.passes(a, b));
        if all(0, 2) && all(1, 2) {
            RoadForm::PerRun
        } else if all(0, 1) {
            RoadForm::Shared
        } else {
            RoadForm::None
        }
    }

    /// The `roads.toml` of fold 1's pairs: each run's `[road]` under its name, to copy into its
    /// sidecar.
    pub fn roads_toml(&self) -> String {
        let mut s = String::from(
            "# Each run's road (bank, grade), fitted on its even 3 s blocks: the [road] of its sidecar (append it, or\n\
             # replace the sidecar's own [road] with it).\n",
        );
        for r in &self.folds[0].per_run {
            s.push_str(&format!("\n# {}.toml\n{}", r.run, r.sidecar_toml()));
        }
        s
    }
}

/// Every run's alternate 3 s blocks: the even ones fitted, the odd ones held out.
pub fn blocked(data: &Dataset) -> Dataset {
    Dataset { held: data.runs.iter().map(alternate_blocks).collect(), ..data.clone() }
}

/// `data` with run `i` on the road of `roads[i]`.
pub fn with_roads(data: &Dataset, roads: &[RunRoad]) -> Dataset {
    let mut out = data.clone();
    for (run, r) in out.runs.iter_mut().zip(roads) {
        run.road = r.road();
    }
    out
}

/// Run `i` of `data` alone (its noise and split).
fn one_run(data: &Dataset, i: usize) -> Dataset {
    Dataset { runs: vec![data.runs[i].clone()], noise: vec![data.noise[i]], held: vec![data.held[i].clone()] }
}

/// Each run's pair fitted on its fitted samples over `base` (whose shared road, if any, is
/// ignored), in parallel over the runs.
pub fn fit_each(model: &ReplayModel, data: &Dataset, base: &EffectParams) -> Vec<RunRoad> {
    let base = EffectParams { road: None, ..*base };
    (0..data.runs.len())
        .into_par_iter()
        .map(|i| {
            let d = one_run(data, i);
            let (v, _) = fit_effect(model, &d, &base, Effect::Road);
            let (v, iv) = refine(model, &d, &base, &[(Effect::Road, v)]);
            RunRoad {
                run: data.runs[i].name.clone(),
                bank_deg: v[0][0],
                grade_deg: v[0][1],
                intervals: [iv[0][0], iv[0][1]],
            }
        })
        .collect()
}

/// The comparison on the blocks of `data` ([`blocked`]), the shared `effects` (over `base`) fitted
/// with each form on the same blocks.
pub fn compare(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    effects: &[(Effect, Vec<f64>)],
) -> RoadComparison {
    let b = blocked(data);
    let f1 = fold(model, &b, base, effects);
    let f2 = fold(model, &b.swapped(), base, effects);
    RoadComparison { folds: [f1, f2] }
}

/// One fold: no road, the shared pair and the per-run pairs fitted on `data`'s fitted samples and
/// scored on its held-out ones.
fn fold(model: &ReplayModel, data: &Dataset, base: &EffectParams, effects: &[(Effect, Vec<f64>)]) -> RoadFold {
    // No road: the shared effects refitted on these blocks.
    let none = refit(model, data, base, effects);
    let s_none = score(data, &simulate_all(model, data, &apply_flat(base, &none)));
    // The shared pair, fitted with the shared effects.
    let mut with_road = effects.to_vec();
    let shared0 = fit_effect(model, data, &apply_flat(base, &none), Effect::Road).0;
    with_road.push((Effect::Road, shared0));
    let (vals, ivs) = refine(model, data, base, &refit(model, data, base, &with_road));
    let shared = zip(vals.clone(), &with_road);
    let s_shared = score(data, &simulate_all(model, data, &apply_flat(base, &shared)));
    let (per_run, own, s_per_run) = per_run_fold(model, data, base, &none);
    RoadFold {
        per_run,
        shared: vals.last().cloned().unwrap_or_default(),
        shared_intervals: ivs.last().cloned().unwrap_or_default(),
        effects: own.into_iter().map(|a| a.1).collect(),
        scores: [s_none, s_shared, s_per_run],
    }
}

/// `effects` with new values `vals` (in their order).
fn zip(vals: Vec<Vec<f64>>, effects: &[(Effect, Vec<f64>)]) -> Vec<(Effect, Vec<f64>)> {
    effects.iter().map(|a| a.0).zip(vals).collect()
}

/// `effects` refitted jointly on `data`'s fitted samples (none: none).
fn refit(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    effects: &[(Effect, Vec<f64>)],
) -> Vec<(Effect, Vec<f64>)> {
    if effects.is_empty() {
        Vec::new()
    } else {
        zip(fit_jointly(model, data, base, effects).0, effects)
    }
}

/// The per-run form on one fold: each run's pair given the shared `effects` (already fitted on
/// these samples), then the shared effects given the pairs and the pairs given them, alternated
/// until the fitted cost falls by less than [`ALTERNATION_TOL`] (at most [`ALTERNATIONS`] times);
/// with the scores of every run on its own pair.
fn per_run_fold(model: &ReplayModel, data: &Dataset, base: &EffectParams, effects: &[(Effect, Vec<f64>)]) -> PerRunFit {
    let scored = |per_run: &[RunRoad], own: &[(Effect, Vec<f64>)]| {
        let d = with_roads(data, per_run);
        score(&d, &simulate_all(model, &d, &apply_flat(base, own)))
    };
    let mut per_run = fit_each(model, data, &apply_flat(base, effects));
    let mut own = effects.to_vec();
    let mut s = scored(&per_run, &own);
    for _ in 0..if effects.is_empty() { 0 } else { ALTERNATIONS } {
        own = refit(model, &with_roads(data, &per_run), base, &own);
        per_run = fit_each(model, data, &apply_flat(base, &own));
        let next = scored(&per_run, &own);
        let done = next.rss_fit > (1.0 - ALTERNATION_TOL) * s.rss_fit;
        s = next;
        if done {
            break;
        }
    }
    (per_run, own, s)
}

/// The per-run form fitted on one fold: each run's pair, the shared effects with them, and the
/// scores.
type PerRunFit = (Vec<RunRoad>, Vec<(Effect, Vec<f64>)>, Scores);

/// Most alternations between the shared effects and the runs' pairs on one fold.
pub const ALTERNATIONS: usize = 6;

/// The alternation stops when a pass lowers the fitted cost by less than this fraction.
pub const ALTERNATION_TOL: f64 = 1e-5;

/// What the road-per-run step found, kept in the [`Discovery`].
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The screen: how much the per-run pairs, fitted on fold 1's blocks with the final effects
    /// held, lower the held-out BIC (k = 2N) of the final model on the same blocks.
    pub screen_delta_bic: f64,
    /// The three forms compared on both folds, when the screen passed.
    pub comparison: Option<RoadComparison>,
    /// The form chosen ([`RoadForm::None`] when the screen did not pass).
    pub chosen: RoadForm,
    /// When the per-run pairs were adopted: what the first search (without them) had named.
    pub named_before: Vec<String>,
}

impl Outcome {
    /// Each run's pair when the per-run form was chosen (fold 1's: fitted on the even blocks).
    pub fn roads(&self) -> Option<&[RunRoad]> {
        match (&self.comparison, self.chosen) {
            (Some(c), RoadForm::PerRun) => Some(&c.folds[0].per_run),
            _ => None,
        }
    }

    /// report.json's `road_per_run`: the screen, each fold's held-out BIC of the three forms, the
    /// form chosen and each run's pair (fold 1's) with its interval.
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        let iv = |i: &Interval| json!({"std_error": i.std_error, "ci95_lo": i.lo, "ci95_hi": i.hi});
        json!({
            "screen_delta_bic": self.screen_delta_bic,
            "chosen": self.chosen.as_str(),
            "named_before": self.named_before,
            "folds": self.comparison.as_ref().map(|c| c.folds.iter().map(|f| {
                let [none, shared, per_run] = f.bic();
                json!({"heldout_bic": {"none": none, "road": shared, "road (per_run)": per_run},
                       "shared_road_deg": f.shared})
            }).collect::<Vec<_>>()),
            "runs": self.comparison.as_ref().map(|c| c.folds[0].per_run.iter().map(|r| json!({
                "run": r.run, "bank_deg": r.bank_deg, "grade_deg": r.grade_deg,
                "bank_ci": iv(&r.intervals[0]), "grade_ci": iv(&r.intervals[1]),
            })).collect::<Vec<_>>()),
        })
    }

    /// report.md's section on the road per run.
    pub fn markdown(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::from("\n## A road per run (bank and grade of each run)\n\n");
        let _ = writeln!(
            s,
            "Screen (fold 1's alternate 3 s blocks, the final effects held): each run on its own fitted road \
             lowers the held-out BIC by {:.1} (k = 2 per run; compared when above {BIC_MIN}).",
            self.screen_delta_bic
        );
        let Some(c) = &self.comparison else { return s };
        let _ = writeln!(s, "\n| fold | held-out BIC: no road | one road | a road per run |\n|---|---|---|---|");
        for (i, f) in c.folds.iter().enumerate() {
            let b = f.bic();
            let _ = writeln!(s, "| {} | {:.1} | {:.1} | {:.1} |", i + 1, b[0], b[1], b[2]);
        }
        let _ = writeln!(
            s,
            "\nThe comparison prefers: {}.{}",
            self.chosen.as_str(),
            if self.chosen == RoadForm::PerRun {
                ""
            } else {
                " This step adopts only a road per run; one road for every run is the search's own `road` candidate."
            }
        );
        if self.chosen == RoadForm::PerRun {
            let _ = writeln!(s, "\n| run | bank (deg, 95 %) | grade (deg, 95 %) |\n|---|---|---|");
            for r in &c.folds[0].per_run {
                let [b, g] = &r.intervals;
                let _ = writeln!(
                    s,
                    "| {} | {:.4} ({:.4} to {:.4}) | {:.4} ({:.4} to {:.4}) |",
                    r.run, r.bank_deg, b.lo, b.hi, r.grade_deg, g.lo, g.hi
                );
            }
            let before =
                if self.named_before.is_empty() { "nothing".to_string() } else { self.named_before.join(", ") };
            let _ = writeln!(
                s,
                "\nThe search without these roads named {before}; the search was run again with each run on its \
                 road, and the forms compared again with what it named (the table above).\n\n\
                 roads.toml holds each run's `[road]` for its sidecar."
            );
        }
        s
    }
}

/// The reason a shared effect leaves the named set when the per-run roads come in.
const NOT_SIGNIFICANT_WITH_ROADS: &str = "with each run on its own fitted road, every 95 % interval of its \
                                          parameters contains the no-effect value: the roads explain what it stood in for";

/// After the search (`d` its result over `data`, baseline `base`, over `candidates`): ask
/// whether each run has its own road. A cheap screen first (fold 1, the final effects held);
/// when it passes, the three forms are compared on both folds of every run's alternate blocks
/// ([`compare`]). When the per-run pairs win, the search is run again with each run on its
/// pair (shared effects that the roads' residuals hid can now pass; `road` is no longer a
/// candidate), the forms are compared again with what that search named, and if the per-run
/// pairs still win they are adopted. With fewer than two runs the per-run and shared
/// forms are the same and nothing is done.
pub fn consider(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    candidates: &[Effect],
    d: &mut Discovery,
    progress: Progress,
) {
    let n = data.runs.len();
    if n < 2 {
        return;
    }
    if let Some(f) = progress {
        f("road per run: does each run have its own bank and grade?");
    }
    let effects = shared_effects(d);
    let b = blocked(data);
    let p = apply_flat(base, &effects);
    let pairs = fit_each(model, &b, &p);
    let on_roads = with_roads(&b, &pairs);
    let s_per = score(&on_roads, &simulate_all(model, &on_roads, &p));
    let s_now = score(&b, &simulate_all(model, &b, &d.params));
    let screen_delta_bic = s_now.bic_held(0) - s_per.bic_held(2 * n);
    let passes = screen_delta_bic > BIC_MIN && s_per.rss_held < (1.0 - MIN_GAIN) * s_now.rss_held;
    let mut out = Outcome { screen_delta_bic, comparison: None, chosen: RoadForm::None, named_before: Vec::new() };
    if passes {
        let cmp = compare(model, data, base, &effects);
        out.chosen = cmp.chosen();
        if out.chosen == RoadForm::PerRun {
            if let Some(f) = progress {
                f("road per run: each run has its own road; searching again with each run on it");
            }
            let cands: Vec<Effect> = candidates.iter().copied().filter(|e| *e != Effect::Road).collect();
            let mut d2 =
                super::search::discover_with(model, &with_roads(data, &cmp.folds[0].per_run), *base, &cands, progress);
            let effects2 = shared_effects(&d2);
            let cmp2 = compare(model, data, base, &effects2);
            out.chosen = cmp2.chosen();
            out.comparison = Some(cmp2);
            if out.chosen == RoadForm::PerRun {
                out.named_before = d.named_names().iter().map(|s| s.to_string()).collect();
                replaced(d, &mut d2);
                *d = d2;
                adopt(model, &b, base, d, &mut out, effects2);
            }
        } else {
            out.comparison = Some(cmp);
        }
    }
    d.road_per_run = Some(out);
}

/// Record in `d2` (the search with each run on its road) what the first search `d` named and
/// `d2` does not: dropped, replaced by the roads; `d`'s own dropped effects come first.
fn replaced(d: &mut Discovery, d2: &mut Discovery) {
    let round = d.steps.len() + 1;
    let mut dropped = std::mem::take(&mut d.dropped);
    for i in (0..d.final_effects.len()).rev() {
        if !d2.named.contains(&d.final_effects[i].effect) {
            drop_named(d, i, round, REPLACED_BY_ROADS.to_string());
        }
    }
    dropped.extend(d.dropped.drain(..).rev());
    dropped.append(&mut d2.dropped);
    d2.dropped = dropped;
}

/// The reason an effect of the first search is not named once every run has its own road.
const REPLACED_BY_ROADS: &str = "named by the search before each run had its own road, not by the search with \
                                 the roads: it stood in for them";

/// The named effects of `d` but a shared `road`, at their final values.
fn shared_effects(d: &Discovery) -> Vec<(Effect, Vec<f64>)> {
    d.final_effects
        .iter()
        .filter(|fe| fe.effect != Effect::Road)
        .map(|fe| (fe.effect, fe.params.iter().map(|p| p.1).collect()))
        .collect()
}

/// The per-run pairs adopted: the named effects (of the search with the roads) re-examined with
/// the roads refitted on the blocks, and `d`'s split, scores, folds and verdict taken from the
/// blocks `b` (fold 1 fits on `b`'s fitted side).
fn adopt(
    model: &ReplayModel,
    b: &Dataset,
    base: &EffectParams,
    d: &mut Discovery,
    out: &mut Outcome,
    mut effects: Vec<(Effect, Vec<f64>)>,
) {
    let round = d.steps.len() + 1;
    let cmp = out.comparison.as_mut().expect("compared");
    let ivs = loop {
        let f1 = &cmp.folds[0];
        let own = zip(f1.effects.clone(), &effects);
        if own.is_empty() {
            break Vec::new();
        }
        let (vals, ivs) = refine(model, &with_roads(b, &f1.per_run), base, &own);
        match (0..own.len()).rev().find(|&i| !significant(own[i].0, &ivs[i])) {
            None => {
                cmp.folds[0].effects = vals;
                break ivs;
            }
            Some(i) => {
                let at = d.final_effects.iter().position(|fe| fe.effect == own[i].0).expect("named");
                drop_named(d, at, round, NOT_SIGNIFICANT_WITH_ROADS.to_string());
                effects.remove(i);
                for (k, data) in [b.clone(), b.swapped()].iter().enumerate() {
                    let start = refit(model, data, base, &effects);
                    let (per_run, own, s) = per_run_fold(model, data, base, &start);
                    let f = &mut cmp.folds[k];
                    (f.per_run, f.effects, f.scores[2]) = (per_run, own.into_iter().map(|a| a.1).collect(), s);
                }
            }
        }
    };
    let own = zip(cmp.folds[0].effects.clone(), &effects);
    for ((fe, (e, v)), iv) in d.final_effects.iter_mut().zip(&own).zip(&ivs) {
        debug_assert_eq!(fe.effect, *e);
        (fe.params, fe.intervals, fe.significant) = (super::search::triples(*e, v), iv.clone(), true);
    }
    d.params = apply_flat(base, &own);
    let on_roads = with_roads(b, &cmp.folds[0].per_run);
    d.final_scores = score(&on_roads, &simulate_all(model, &on_roads, &d.params));
    let base_sims = simulate_all(model, b, base);
    d.baseline = score(b, &base_sims);
    d.held = b.held.clone();
    let other_base = score(&b.swapped(), &base_sims);
    d.folds = [(&d.baseline, &d.final_scores), (&other_base, &cmp.folds[1].scores[2])]
        .into_iter()
        .map(|(s0, s1)| Fold::new(Vec::new(), s0, s1))
        .collect();
    let named = &d.named;
    d.classes.retain(|c| named.contains(&c.named));
    let explained = d.folds.iter().all(Fold::final_at_noise);
    d.verdict = match (explained, d.classes.is_empty()) {
        (true, false) => Verdict::ExplainedEquivalent,
        (true, true) => Verdict::Explained,
        (false, _) => Verdict::PartlyExplained,
    };
}

/// Remove final effect `i` from the named set, recording why.
fn drop_named(d: &mut Discovery, i: usize, round: usize, reason: String) {
    let fe = d.final_effects.remove(i);
    d.named.retain(|e| *e != fe.effect);
    let accepted_round = d.steps.iter().position(|s| s.effect == fe.effect).map_or(0, |k| k + 1);
    d.dropped.push(Dropped {
        effect: fe.effect,
        accepted_round,
        dropped_round: round,
        params: fe.params,
        intervals: fe.intervals,
        reason,
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 12 s sine-steer run on ice at 100 Hz, noise-free.
    fn run() -> super::super::measured::MeasuredRun {
        super::super::synth::truth(
            &ReplayModel::new(
                super::super::load_vehicle(
                    &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("vehicles/sedan.toml"),
                    None,
                    super::super::tyre_kind("pacejka").unwrap(),
                )
                .unwrap(),
            ),
            &EffectParams::default(),
            &super::super::synth::select(&["sine_ice".to_string()]).unwrap()[0],
            "x",
        )
    }

    /// Every run gets the alternate 3 s blocks: the first 3 s fitted, the next held out.
    #[test]
    fn every_run_is_split_into_alternate_blocks() {
        let r = run();
        let b = blocked(&Dataset::new(vec![r.clone(), r]));
        for h in &b.held {
            assert!(!h[0] && !h[299] && h[300] && h[599] && !h[600], "{:?}", &h[295..305]);
        }
    }

    /// Scores whose held-out RSS is `rss` over 1000 held-out samples.
    fn held(rss: f64) -> Scores {
        Scores { rss_held: rss, n_held: 1000, ..Scores::default() }
    }

    /// A comparison of two runs whose folds both have held-out RSS `rss` (none, shared, per-run).
    fn comparison(rss: [f64; 3]) -> RoadComparison {
        let r = RunRoad { run: "a".into(), bank_deg: 0.0, grade_deg: 0.0, intervals: [Interval::UNKNOWN; 2] };
        let f = RoadFold {
            per_run: vec![r.clone(), r],
            shared: vec![0.0, 0.0],
            shared_intervals: Vec::new(),
            effects: Vec::new(),
            scores: rss.map(held),
        };
        RoadComparison { folds: [f.clone(), f] }
    }

    /// The per-run pairs must beat both simpler forms, the shared pair no road, in both folds.
    #[test]
    fn the_chosen_form_beats_every_simpler_one_in_both_folds() {
        assert_eq!(comparison([1000.0, 1000.0, 1000.0]).chosen(), RoadForm::None);
        assert_eq!(comparison([1000.0, 500.0, 500.0]).chosen(), RoadForm::Shared);
        assert_eq!(comparison([1000.0, 500.0, 100.0]).chosen(), RoadForm::PerRun);
        // Per-run beats no road but not the shared pair: the shared pair.
        assert_eq!(comparison([1000.0, 100.0, 99.0]).chosen(), RoadForm::Shared);
        // Per-run beats no road, but not the shared pair by 5 % of RSS, and the shared pair does
        // not beat no road: none.
        assert_eq!(comparison([1000.0, 960.0, 940.0]).chosen(), RoadForm::None);
        let mut c = comparison([1000.0, 500.0, 100.0]);
        c.folds[1].scores[2] = held(600.0);
        assert_eq!(c.chosen(), RoadForm::Shared, "both folds must agree");
    }

    /// The sidecar snippet round-trips the fitted values exactly.
    #[test]
    fn the_sidecar_snippet_round_trips() {
        let r =
            RunRoad { run: "a".into(), bank_deg: 0.1 + 0.2, grade_deg: -1.0 / 3.0, intervals: [Interval::UNKNOWN; 2] };
        let t: toml::Value = toml::from_str(&r.sidecar_toml()).unwrap();
        assert_eq!(t["road"]["bank_deg"].as_float(), Some(0.1 + 0.2));
        assert_eq!(t["road"]["grade_deg"].as_float(), Some(-1.0 / 3.0));
    }
}
