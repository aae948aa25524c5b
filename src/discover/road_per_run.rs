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
//! run on its fitted road, and the runs' pairs once more given them (one alternation), so that no
//! score sees a sample any fit has used.
//!
//! Score: the held-out BIC n ln(RSS/n) + k ln(n) of [`Scores::bic_held`], k = 2N for the per-run
//! form, 2 for the shared pair, 0 for no road (the shared effects' parameters are the same in
//! all three and cancel). A form is chosen when it lowers the held-out BIC of the next simpler
//! one by more than [`BIC_MIN`] and its held-out RSS by at least [`MIN_GAIN`], in both folds.
//!
//! Angles in degrees; bank positive when the road's left edge is higher, grade positive uphill
//! ([`vehsim_core::vehicle::road`]).

use rayon::prelude::*;

use super::effects::Effect;
use super::model::{EffectParams, ReplayModel};
use super::select::{apply_flat, fit_effect, fit_jointly, score, simulate_all, Dataset, Scores, BIC_MIN, MIN_GAIN};
use super::uncertainty::{refine, Interval};
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
    /// The form the data ask for: the per-run pairs when they pass against the shared pair (and
    /// it against no road) in both folds, else the shared pair when it passes against no road in
    /// both, else none.
    pub fn chosen(&self) -> RoadForm {
        let all = |a, b| self.folds.iter().all(|f| f.passes(a, b));
        let per_run_vs_none = all(0, 2);
        match (all(0, 1), all(1, 2)) {
            (_, true) if per_run_vs_none => RoadForm::PerRun,
            (true, _) => RoadForm::Shared,
            _ if per_run_vs_none => RoadForm::PerRun,
            _ => RoadForm::None,
        }
    }

    /// The `roads.toml` of fold 1's pairs: each run's `[road]` under its name, to copy into its
    /// sidecar.
    pub fn roads_toml(&self) -> String {
        let mut s = String::from(
            "# Each run's road (bank, grade), fitted on its even 3 s blocks: the [road] of its sidecar.\n",
        );
        for r in &self.folds[0].per_run {
            s.push_str(&format!("\n# {}.toml\n{}", r.run, r.sidecar_toml()));
        }
        s
    }
}

/// Every run's alternate 3 s blocks: the even ones fitted, the odd ones held out.
pub fn blocked(data: &Dataset) -> Dataset {
    let mut out = data.clone();
    for (i, r) in data.runs.iter().enumerate() {
        // The one-run rule of [`Dataset::new`], run by run.
        out.held[i] = Dataset::new(vec![r.clone()]).held.remove(0);
    }
    out
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
    let refit = |d: &Dataset, with: &[(Effect, Vec<f64>)]| -> Vec<Vec<f64>> {
        if with.is_empty() {
            Vec::new()
        } else {
            fit_jointly(model, d, base, with).0
        }
    };
    let zip = |vals: Vec<Vec<f64>>, with: &[(Effect, Vec<f64>)]| -> Vec<(Effect, Vec<f64>)> {
        with.iter().map(|a| a.0).zip(vals).collect()
    };
    // No road: the shared effects refitted on these blocks.
    let none = zip(refit(data, effects), effects);
    let s_none = score(data, &simulate_all(model, data, &apply_flat(base, &none)));
    // The shared pair, fitted with the shared effects.
    let mut with_road = effects.to_vec();
    with_road.push((Effect::Road, Effect::Road.params().iter().map(|d| d.start).collect()));
    let shared0 = fit_effect(model, data, &apply_flat(base, &none), Effect::Road).0;
    with_road.last_mut().expect("the road").1 = shared0;
    let (vals, ivs) = refine(model, data, base, &zip(refit(data, &with_road), &with_road));
    let s_shared = score(data, &simulate_all(model, data, &apply_flat(base, &zip(vals.clone(), &with_road))));
    // The per-run pairs given the shared effects, the shared effects given the pairs, and the
    // pairs once more.
    let mut per_run = fit_each(model, data, &apply_flat(base, &none));
    let mut own = none.clone();
    if !effects.is_empty() {
        let d = with_roads(data, &per_run);
        own = zip(refit(&d, &none), effects);
        per_run = fit_each(model, data, &apply_flat(base, &own));
    }
    let d = with_roads(data, &per_run);
    let s_per_run = score(&d, &simulate_all(model, &d, &apply_flat(base, &own)));
    RoadFold {
        per_run,
        shared: vals.last().cloned().unwrap_or_default(),
        shared_intervals: ivs.last().cloned().unwrap_or_default(),
        effects: own.into_iter().map(|a| a.1).collect(),
        scores: [s_none, s_shared, s_per_run],
    }
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
