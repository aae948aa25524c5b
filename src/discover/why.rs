//! Why a set is left above the noise: when the verdict is not at the noise, the report says where
//! the final model's remaining disagreement lives and what that suggests, from numbers the user
//! can check in the same report.
//!
//! With z the squared normalised residual per sample (mean of the two channels; 1 = noise) of the
//! final model, the excess of a sample is max(z - 1, 0). The diagnosis gives:
//! - **where in time**: the share of the total excess inside the final model's disagreement windows
//!   ([`super::select::disagreement_windows`]) and the share of the run time they cover. Most of the
//!   excess in little of the time (share >= 0.6 in <= 20 % of the time) is **localised**: a short
//!   event (a region of the ground, a transient, a fault in the log) that no candidate form places;
//!   otherwise it is **spread**: a model error across the operating range.
//! - **where on the surface**: the share of the excess on ice runs and on dry ones.
//! - **where in the operating range**: the final model's operating-region bins
//!   ([`super::select::operating_regions`]) still above 2× the noise (report.md lists the five
//!   furthest above).
//! - **the folds**: when one fold is at the noise (both ratios <= 1.5) and the other is not, the two
//!   halves of the runs disagree about the effect: the runs are not alike in what is missing.
//! - **the nearest miss**: the rejected candidate of the last round with the largest held-out
//!   ΔBIC, and why it was not named (its rejection reason).

use serde::Serialize;

use super::model::Simulated;
use super::select::{operating_regions, Dataset, Discovery, Window};

/// Share of the excess above which, within [`LOCAL_TIME_SHARE`] of the time, it is localised.
pub const LOCAL_EXCESS_SHARE: f64 = 0.6;
/// Largest share of the run time the windows of a localised excess cover.
pub const LOCAL_TIME_SHARE: f64 = 0.2;

/// The diagnosis of a set left above the noise (see the module docs).
#[derive(Debug, Clone, Serialize)]
pub struct AboveNoise {
    /// "localised" or "spread".
    pub kind: &'static str,
    /// Share of the excess inside the final model's disagreement windows, and of the time they cover.
    pub excess_share_in_windows: f64,
    pub time_share_of_windows: f64,
    /// Share of the excess on runs on ice (the rest is on the others).
    pub excess_share_on_ice: f64,
    /// Operating-region bins still above 2x the noise: (variable, lo, hi, excess).
    pub bins_above: Vec<(String, f64, f64, f64)>,
    /// True when one fold is at the noise and the other is not.
    pub folds_disagree: bool,
    /// The rejected candidate of the last round with the largest held-out dBIC: (label, dBIC, reason).
    pub nearest_miss: Option<(String, f64, String)>,
    /// The diagnosis in sentences, for report.md.
    pub sentences: Vec<String>,
}

/// The diagnosis of `d` on `data` with the final model's simulations `last` and its disagreement
/// windows `windows` ([`super::select::disagreement_windows`] of `last`, which the report computes
/// anyway); None when the verdict is at the noise.
pub fn above_noise(data: &Dataset, d: &Discovery, last: &[Simulated], windows: &[Window]) -> Option<AboveNoise> {
    if d.verdict.at_noise() {
        return None;
    }
    let (mut total, mut inside, mut on_ice, mut t_all, mut t_in) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (i, (r, s)) in data.runs.iter().zip(last).enumerate() {
        let nz = data.noise[i];
        let mine: Vec<_> = windows.iter().filter(|w| w.run == r.name).collect();
        t_all += r.duration_s();
        t_in += mine.iter().map(|w| w.t1_s - w.t0_s).sum::<f64>();
        for k in 0..r.t.len() {
            let z =
                0.5 * (((r.yaw_rate[k] - s.yaw_rate[k]) / nz.yaw_rate).powi(2) + ((r.ay[k] - s.ay[k]) / nz.ay).powi(2));
            let e = (z - 1.0).max(0.0);
            total += e;
            if r.on_ice {
                on_ice += e;
            }
            if mine.iter().any(|w| r.t[k] >= w.t0_s && r.t[k] <= w.t1_s) {
                inside += e;
            }
        }
    }
    let share = |a: f64| if total > 0.0 { a / total } else { 0.0 };
    let (in_share, time_share, ice_share) =
        (share(inside), if t_all > 0.0 { t_in / t_all } else { 0.0 }, share(on_ice));
    let localised = in_share >= LOCAL_EXCESS_SHARE && time_share <= LOCAL_TIME_SHARE;
    let bins_above: Vec<(String, f64, f64, f64)> = operating_regions(data, last)
        .into_iter()
        .filter(|b| b.disagrees)
        .map(|b| (b.variable, b.lo, b.hi, b.excess))
        .collect();
    let at = super::select::Fold::final_at_noise;
    let folds_disagree = d.folds.len() == 2 && at(&d.folds[0]) != at(&d.folds[1]);
    let last_round = d.rejected.iter().map(|t| t.round).max();
    let nearest_miss = d
        .rejected
        .iter()
        .filter(|t| Some(t.round) == last_round)
        .max_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic))
        .map(|t| (t.effect.label(), t.delta_bic, t.reason.clone()));
    let mut sentences = vec![if localised {
        format!(
            "Localised: {:.0} % of the remaining excess lies in disagreement windows covering {:.0} % of the time, \
             a short event (a region of the ground, a transient, a fault in the log) that no candidate form places.",
            100.0 * in_share,
            100.0 * time_share
        )
    } else {
        format!(
            "Spread: {:.0} % of the remaining excess lies in disagreement windows covering {:.0} % of the time, so the \
             rest is a model error across the operating range rather than one event.",
            100.0 * in_share,
            100.0 * time_share
        )
    }];
    sentences.push(format!(
        "{:.0} % of the excess is on ice runs, {:.0} % on the others.",
        100.0 * ice_share,
        100.0 * (1.0 - ice_share)
    ));
    if !bins_above.is_empty() {
        let mut top = bins_above.clone();
        top.sort_by(|a, b| b.3.total_cmp(&a.3));
        let list: Vec<String> =
            top.iter().take(5).map(|(v, lo, hi, e)| format!("{v} in [{lo}, {hi}) at {e:.1}x")).collect();
        sentences.push(format!(
            "Operating regions furthest above 2x the noise ({} of {} above): {}.",
            list.len(),
            top.len(),
            list.join("; ")
        ));
    }
    if folds_disagree {
        sentences.push(
            "One fold is at the noise and the other is not: the two halves of the runs disagree about what is missing."
                .into(),
        );
    }
    if let Some((label, dbic, reason)) = &nearest_miss {
        sentences.push(format!("Nearest miss in the last round: {label} (held-out dBIC {dbic:.1}): {reason}."));
    }
    Some(AboveNoise {
        kind: if localised { "localised" } else { "spread" },
        excess_share_in_windows: in_share,
        time_share_of_windows: time_share,
        excess_share_on_ice: ice_share,
        bins_above,
        folds_disagree,
        nearest_miss,
        sentences,
    })
}
