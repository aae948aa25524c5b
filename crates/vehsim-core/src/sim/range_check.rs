//! Plausibility by the tyre's own range: events when a run's slip ratio, slip angle or tyre load
//! leaves the range the tyre file declares as measured (the `.tir` sections
//! `[LONG_SLIP_RANGE]` KPUMIN/KPUMAX, `[SLIP_ANGLE_RANGE]` ALPMIN/ALPMAX (rad) and
//! `[VERTICAL_FORCE_RANGE]` FZMIN/FZMAX (N), read by the spec layer when it builds the vehicle). A tyre that
//! declares no range is not checked on that quantity (nothing to hold it to).
//!
//! Checked on every recorded row: each axle's slip ratio and slip angle as the tyre sees them
//! (the observation's axle values: the bicycle's, or the mean over a four-wheel model's axle) and
//! each wheel's normal load. Each quantity gives one onset event when it first leaves the range,
//! naming the axle or wheel, the value and the range, and one recovery event when it returns (at
//! most `super::watch::MAX_ONSETS` onsets each); a run that left a range is implausible, with
//! the first time, the worst value and where.

use super::observer::Row;
use super::watch::MAX_ONSETS;
use crate::event::{Event, EventKind};
use crate::tyre::ranges::TyreRanges;

const AXLES: [&str; 2] = ["front axle", "rear axle"];
const WHEELS: [&str; 4] = ["front-left wheel", "front-right wheel", "rear-left wheel", "rear-right wheel"];

/// One quantity's state over the run.
#[derive(Debug, Clone, Copy, Default)]
struct Track {
    active: [bool; 4],
    onsets: u32,
    /// First time out of range, and the worst excess (distance outside the range), its value,
    /// time and subject.
    first_t_s: Option<f64>,
    worst: Option<(f64, f64, f64, usize)>,
}

/// The range checker of one run.
#[derive(Debug, Clone)]
pub(crate) struct RangeCheck {
    ranges: TyreRanges,
    tracks: [Track; 3],
    events: Vec<Event>,
}

/// (name, unit, onset, recovery) of the three quantities.
const QUANTITIES: [(&str, &str, EventKind, EventKind); 3] = [
    ("slip ratio", "", EventKind::SlipRatioBeyondRange, EventKind::SlipRatioWithinRange),
    ("slip angle", " rad", EventKind::SlipAngleBeyondRange, EventKind::SlipAngleWithinRange),
    ("normal load", " N", EventKind::LoadBeyondRange, EventKind::LoadWithinRange),
];

impl RangeCheck {
    pub fn new(ranges: TyreRanges) -> Self {
        Self { ranges, tracks: [Track::default(); 3], events: Vec::new() }
    }

    /// Check one recorded row.
    pub fn check(&mut self, row: &Row) {
        let o = &row.obs;
        if let Some(r) = self.ranges.kappa {
            for (i, v) in o.kappa.iter().enumerate() {
                self.update(0, i, row.t_s, *v, r, &AXLES);
            }
        }
        if let Some(r) = self.ranges.alpha_rad {
            for (i, v) in o.alpha_rad.iter().enumerate() {
                self.update(1, i, row.t_s, *v, r, &AXLES);
            }
        }
        if let Some(r) = self.ranges.fz_n {
            for (i, v) in o.fz_n.iter().enumerate() {
                self.update(2, i, row.t_s, *v, r, &WHEELS);
            }
        }
    }

    #[inline]
    fn update(&mut self, q: usize, i: usize, t_s: f64, v: f64, (lo, hi): (f64, f64), subjects: &[&str]) {
        // the common case first: in range and not out before
        if v >= lo && v <= hi && !self.tracks[q].active[i] {
            return;
        }
        self.change(q, i, t_s, v, (lo, hi), subjects);
    }

    #[cold]
    fn change(&mut self, q: usize, i: usize, t_s: f64, v: f64, (lo, hi): (f64, f64), subjects: &[&str]) {
        if !v.is_finite() {
            return;
        }
        let excess = (lo - v).max(v - hi);
        let out = excess > 0.0;
        let tr = &mut self.tracks[q];
        if out {
            tr.first_t_s.get_or_insert(t_s);
            if tr.worst.is_none_or(|w| excess > w.0) {
                tr.worst = Some((excess, v, t_s, i));
            }
        }
        if out == tr.active[i] {
            return;
        }
        tr.active[i] = out;
        if out {
            tr.onsets += 1;
        }
        if tr.onsets > MAX_ONSETS {
            return;
        }
        let (name, unit, onset, recovery) = QUANTITIES[q];
        let detail = format!("{}: {name} {v:.3}{unit}, the tyre's range [{lo}, {hi}]{unit}", subjects[i]);
        self.events.push(Event { t_s, kind: if out { onset } else { recovery }, detail });
    }

    /// The reasons for the summary (one per quantity that left its range).
    pub fn reasons(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (q, tr) in self.tracks.iter().enumerate() {
            let (Some(t0), Some((_, v, t, i))) = (tr.first_t_s, tr.worst) else { continue };
            let (name, unit, _, _) = QUANTITIES[q];
            let subject = if q == 2 { WHEELS[i] } else { AXLES[i] };
            let (lo, hi) = [self.ranges.kappa, self.ranges.alpha_rad, self.ranges.fz_n][q].unwrap_or_default();
            out.push(format!(
                "{name} outside the tyre's range [{lo}, {hi}]{unit} from t = {t0:.2} s: {v:.3}{unit} on the {subject} \
                 at t = {t:.2} s (the tyre model is not measured there)"
            ));
        }
        out
    }

    /// The events so far.
    pub fn into_events(self) -> Vec<Event> {
        self.events
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::{Inputs, Observation};

    fn row(t: f64, kappa: [f64; 2]) -> Row {
        Row {
            t_s: t,
            obs: Observation { kappa, fz_n: [4000.0; 4], ..Observation::default() },
            inputs: Inputs::default(),
            speed_target_mps: f64::NAN,
            path_error_m: f64::NAN,
        }
    }

    #[test]
    fn onset_recovery_and_reason_name_the_axle() {
        let mut c =
            RangeCheck::new(TyreRanges { kappa: Some((-1.0, 1.0)), alpha_rad: None, fz_n: Some((100.0, 8000.0)) });
        c.check(&row(0.0, [0.1, 0.0]));
        c.check(&row(0.1, [3.0, 0.0]));
        c.check(&row(0.2, [7.0, 0.0]));
        c.check(&row(0.3, [0.2, 0.0]));
        let r = c.reasons();
        assert_eq!(r.len(), 1, "{r:?}");
        assert!(r[0].contains("front axle") && r[0].contains("7.000") && r[0].contains("t = 0.10 s"), "{r:?}");
        let e = c.into_events();
        assert_eq!(e.len(), 2);
        assert_eq!((e[0].kind, e[0].t_s), (EventKind::SlipRatioBeyondRange, 0.1));
        assert_eq!((e[1].kind, e[1].t_s), (EventKind::SlipRatioWithinRange, 0.3));
        // nothing declared: nothing checked
        let mut c = RangeCheck::new(TyreRanges::default());
        c.check(&row(0.0, [50.0, 0.0]));
        assert!(c.reasons().is_empty());
    }
}
