//! What the data cannot tell apart: candidates that explain a round's data as well as the effect
//! accepted in it, within the criterion's resolution, and the manoeuvre that would separate them.
//!
//! **Equivalent candidates.** In the round an effect A is accepted, another candidate B is
//! equivalent to it when B too passes the held-out tests (held-out BIC lower by more than
//! [`BIC_MIN`], RSS lower by at least [`MIN_GAIN`]) and its held-out BIC is within
//! [`EQUIVALENCE_BIC`] of A's. That is the acceptance threshold itself: the data must prefer a
//! named effect over an alternative by the same margin they must prefer it over no effect at all,
//! or they have not told the two apart. The BIC carries its own penalty per parameter (ln n of the
//! held-out residuals: 7.1 for one 12 s run at 100 Hz with half of it held out, 9.2 for four
//! held-out runs), so a form with one parameter more is equivalent only when it fits better. A form that contains A as a special case (or is contained in it: [`nested`]) is not an
//! alternative explanation but the same one with a parameter more or less; the criterion's
//! penalty decides between those, and they are not reported as equivalent.
//!
//! **The separating manoeuvre.** For a class {A, B1, B2, ...}, every manoeuvre `vehsim synth`
//! knows ([`super::synth::MANOEUVRES`]) is simulated noise-free with the final model (the inputs;
//! the lane change's steer is the driver's response to that model) and then replayed open loop
//! with A replaced by each Bj at Bj's fitted values. The predicted difference of a member is the
//! RMS difference of the two replays over the data's noise (median of the runs' estimates), the
//! larger of the two channels (yaw rate, a_y); a manoeuvre separates the class as well as its
//! least-separated member. The manoeuvre with the largest such figure is proposed: runs of it,
//! added to the data, make the class split when that figure is well above 1.
//!
//! **A logged heading.** The instruments' errors (the `[sensors]` forms) do not reach a heading
//! logged by a satellite receiver ([`super::increments`]), so a class that mixes a sensor form with
//! a form of the car may split with the heading logged where yaw rate and a_y cannot split it.
//! Every manoeuvre's separation is therefore also given for the heading: the RMS over 1 s windows
//! of the difference of the two replays' heading increments, over the increment's noise at
//! `vehsim synth`'s survey-grade heading noise (sqrt(2) x 5e-4 rad, [`super::synth::LOGGABLE`]),
//! and the manoeuvre with the largest such figure is named beside the proposal.

use serde::Serialize;

use super::effects::Effect;
use super::model::{EffectParams, ReplayModel, Simulated};
use super::select::{apply_flat, Dataset, Trial, BIC_MIN, MIN_GAIN};
use super::synth::{truth, Manoeuvre, MANOEUVRES};
use super::uncertainty::{refine, Interval};

/// Largest gap in held-out BIC between the accepted effect and a candidate reported as equivalent
/// to it (the acceptance threshold, [`BIC_MIN`]).
pub const EQUIVALENCE_BIC: f64 = BIC_MIN;

/// A candidate that explains the data of a round as well as the accepted effect.
#[derive(Debug, Clone)]
pub struct Equivalent {
    pub effect: Effect,
    /// Its parameters fitted in that round and polished jointly with the effects accepted before
    /// it ([`refit`]): (name, value, unit).
    pub params: Vec<(String, f64, String)>,
    /// The same values in the order of [`Effect::params`].
    pub values: Vec<f64>,
    /// Their 95 % intervals, estimated jointly with the effects accepted before it (empty before
    /// [`refit`]).
    pub intervals: Vec<Interval>,
    /// Its held-out BIC improvement in the round, and the accepted effect's.
    pub delta_bic: f64,
    pub named_delta_bic: f64,
}

/// One manoeuvre's predicted difference between the named effect and each equivalent.
#[derive(Debug, Clone, Serialize)]
pub struct Separation {
    /// The manoeuvre's id (`vehsim synth --maneuvers ID`).
    pub maneuver: &'static str,
    /// Per equivalent (in the class's order): RMS difference over the noise, the larger channel.
    pub per_member: Vec<f64>,
    /// The smallest of those: how well the manoeuvre separates the whole class.
    pub class: f64,
    /// Per equivalent: the RMS difference of the heading increments over 1 s windows, over the
    /// increment's noise with a survey-grade logged heading (see the module docs).
    pub per_member_heading: Vec<f64>,
    /// The smallest of those.
    pub class_heading: f64,
}

/// A named effect with the candidates the data cannot tell from it, and the manoeuvre proposed to
/// separate them.
#[derive(Debug, Clone)]
pub struct Class {
    pub named: Effect,
    pub members: Vec<Equivalent>,
    /// Every manoeuvre, in [`MANOEUVRES`] order.
    pub separations: Vec<Separation>,
    /// Index into `separations` of the proposed manoeuvre (the largest `class` figure).
    pub proposed: usize,
}

/// Index of the largest of `f` over `s` (the first on ties).
fn best(s: &[Separation], f: fn(&Separation) -> f64) -> usize {
    (0..s.len()).fold(0, |b, i| if f(&s[i]) > f(&s[b]) { i } else { b })
}

impl Class {
    /// The proposed manoeuvre's separation.
    pub fn proposal(&self) -> &Separation {
        &self.separations[self.proposed]
    }

    /// The manoeuvre that separates the class best with a logged heading.
    pub fn heading_proposal(&self) -> &Separation {
        &self.separations[best(&self.separations, |s| s.class_heading)]
    }

    /// "A = B = C" by labels (name and form), the named effect first.
    pub fn text(&self) -> String {
        std::iter::once(self.named.label())
            .chain(self.members.iter().map(|m| m.effect.label()))
            .collect::<Vec<_>>()
            .join(" = ")
    }
}

/// True when one of `a`, `b` is a special case of the other (a richer form of the same
/// explanation): per-axle friction scales contain the global one (equal scales); the friction
/// stretch, patch and band contain it too (a region covering every run); the load-sensitive load
/// transfer contains the plain one (zero sensitivities).
pub fn nested(a: Effect, b: Effect) -> bool {
    let contains = |rich: Effect, plain: Effect| match plain {
        Effect::FrictionChange => matches!(
            rich,
            Effect::AxleFriction | Effect::FrictionStretch | Effect::FrictionPatch | Effect::FrictionBand
        ),
        Effect::LoadTransfer => rich == Effect::LoadTransferSensitive,
        _ => false,
    };
    contains(a, b) || contains(b, a)
}

/// Whether a trial passed the held-out tests of acceptance.
fn passes(t: &Trial) -> bool {
    t.delta_bic > BIC_MIN && t.heldout_rss_ratio < 1.0 - MIN_GAIN
}

/// The candidates of a round equivalent to the accepted `chosen` (see the module docs), best
/// first. `trials` is the round's every trial, the chosen one included.
pub fn members(chosen: &Trial, trials: &[&Trial]) -> Vec<Equivalent> {
    let mut out: Vec<Equivalent> = trials
        .iter()
        .filter(|t| t.effect != chosen.effect && !nested(t.effect, chosen.effect))
        .filter(|t| passes(t) && chosen.delta_bic - t.delta_bic <= EQUIVALENCE_BIC)
        .map(|t| Equivalent {
            effect: t.effect,
            params: t.params.clone(),
            values: t.values.clone(),
            intervals: Vec::new(),
            delta_bic: t.delta_bic,
            named_delta_bic: chosen.delta_bic,
        })
        .collect();
    out.sort_by(|a, b| b.delta_bic.total_cmp(&a.delta_bic));
    out
}

/// Each equivalent polished and given its 95 % intervals as the named effect was: jointly with
/// the effects `accepted` before the round (on top of `base`), by [`refine`] (so a member's values
/// are its optimum on the same footing as the named effect's, not the simplex's stopping point).
pub fn refit(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    accepted: &[(Effect, Vec<f64>)],
    members: &mut [Equivalent],
) {
    for m in members {
        let mut with = accepted.to_vec();
        with.push((m.effect, m.values.clone()));
        let (vals, ivs) = refine(model, data, base, &with);
        if let (Some(v), Some(iv)) = (vals.last(), ivs.last()) {
            m.values = v.clone();
            m.params = super::search::triples(m.effect, v);
            m.intervals = iv.clone();
        }
    }
}

/// The data's noise per channel (yaw rate, a_y): the median of the runs' estimates.
fn median_noise(data: &Dataset) -> [f64; 2] {
    let median = |f: &dyn Fn(usize) -> f64| {
        let mut v: Vec<f64> = (0..data.noise.len()).map(f).collect();
        v.sort_by(|a, b| a.total_cmp(b));
        v.get(v.len() / 2).copied().unwrap_or(1.0)
    };
    [median(&|i| data.noise[i].yaw_rate), median(&|i| data.noise[i].ay)]
}

/// RMS difference of two replays over the noise, the larger channel.
fn difference(a: &Simulated, b: &Simulated, noise: [f64; 2]) -> f64 {
    let n = a.yaw_rate.len().max(1) as f64;
    let rms = |x: &[f64], y: &[f64]| (x.iter().zip(y).map(|(p, q)| (p - q).powi(2)).sum::<f64>() / n).sqrt();
    let d = (rms(&a.yaw_rate, &b.yaw_rate) / noise[0]).max(rms(&a.ay, &b.ay) / noise[1]);
    if a.ok && b.ok {
        d
    } else {
        // A replay that diverged on the manoeuvre separates nothing that can be measured.
        0.0
    }
}

/// The separations of class {`named`, `members`} on every manoeuvre, the proposed one's index:
/// `accepted` is the final model's effects (with `named` among them) over `base`.
pub fn separate(
    model: &ReplayModel,
    data: &Dataset,
    base: &EffectParams,
    accepted: &[(Effect, Vec<f64>)],
    named: Effect,
    members: &[Equivalent],
) -> (Vec<Separation>, usize) {
    let noise = median_noise(data);
    let p_named = apply_flat(base, accepted);
    let p_members: Vec<EffectParams> = members
        .iter()
        .map(|m| {
            let swapped: Vec<(Effect, Vec<f64>)> = accepted
                .iter()
                .map(|(e, v)| if *e == named { (m.effect, m.values.clone()) } else { (*e, v.clone()) })
                .collect();
            apply_flat(base, &swapped)
        })
        .collect();
    let separations: Vec<Separation> =
        MANOEUVRES.iter().map(|m| separation(model, m, &p_named, &p_members, noise)).collect();
    let proposed = best(&separations, |s| s.class);
    (separations, proposed)
}

/// One manoeuvre's separation: its inputs from the named model, each member replayed on them.
fn separation(
    model: &ReplayModel,
    m: &Manoeuvre,
    p_named: &EffectParams,
    p_members: &[EffectParams],
    noise: [f64; 2],
) -> Separation {
    let run = truth(model, p_named, m, m.id);
    let reference = model.simulate(&run, p_named);
    let sims: Vec<Simulated> = p_members.iter().map(|p| model.simulate(&run, p)).collect();
    let per_member: Vec<f64> = sims.iter().map(|s| difference(&reference, s, noise)).collect();
    let windows = super::increments::windows(&run.t, &vec![false; run.t.len()]);
    let per_member_heading: Vec<f64> = sims.iter().map(|s| heading_difference(&reference, s, &windows)).collect();
    let least = |v: &[f64]| {
        let m = v.iter().copied().fold(f64::INFINITY, f64::min);
        if m.is_finite() {
            m
        } else {
            0.0
        }
    };
    Separation {
        maneuver: m.id,
        class: least(&per_member),
        class_heading: least(&per_member_heading),
        per_member,
        per_member_heading,
    }
}

/// RMS over `windows` of the difference of two replays' heading increments, over the increment's
/// noise with a survey-grade logged heading (sqrt(2) x [`super::synth::log_noise`] of `psi`).
fn heading_difference(a: &Simulated, b: &Simulated, windows: &[(usize, usize, bool)]) -> f64 {
    if !(a.ok && b.ok) || windows.is_empty() || a.psi.len() != b.psi.len() {
        return 0.0;
    }
    let sigma = 2f64.sqrt() * super::synth::log_noise("psi");
    let ss: f64 = windows.iter().map(|&(k0, k1, _)| ((a.psi[k1] - a.psi[k0]) - (b.psi[k1] - b.psi[k0])).powi(2)).sum();
    (ss / windows.len() as f64).sqrt() / sigma
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_is_symmetric_and_only_for_the_listed_pairs() {
        assert!(nested(Effect::AxleFriction, Effect::FrictionChange));
        assert!(nested(Effect::FrictionChange, Effect::FrictionStretch));
        assert!(nested(Effect::LoadTransfer, Effect::LoadTransferSensitive));
        assert!(!nested(Effect::SteerCompliance, Effect::AxleStiffness));
        assert!(!nested(Effect::FrictionStretch, Effect::FrictionBand));
        for a in Effect::ALL {
            assert!(!nested(a, a), "{a:?} nested in itself");
            for b in Effect::ALL {
                assert_eq!(nested(a, b), nested(b, a), "{a:?} / {b:?}");
            }
        }
    }
}
