//! Step-resolution events from the model's watched conditions ([`crate::vehicle::Condition`]).
//!
//! After every step (and once for the initial state) the engine asks the model for its conditions
//! and reports a change: an onset event (kind `Condition::onset`) when a condition starts to hold
//! and a recovery event (kind `Condition::recovery`) when it stops, each at the time of the state
//! that first shows the change (step resolution) with the condition's detail. A condition that
//! holds for many steps gives one onset, not one event per step. A condition that flaps (starts
//! more than `MAX_ONSETS` times in a run) is then reported once more as `events_suppressed` and
//! no longer, so a summary never floods.
//!
//! The model's one-off notes ([`crate::vehicle::capability::Monitored::notes`], e.g. a tyre clamping its published law) are
//! checked at the same instants; each kind is reported once per run, at the first state showing it.

use nalgebra::SVector;

use crate::event::{Event, EventKind};
use crate::vehicle::{Condition, Environment, Inputs, VehicleModel};

/// Onsets reported per condition and run before its changes are suppressed.
pub(crate) const MAX_ONSETS: u32 = 20;

/// Previous activity of each condition (by position in the model's list).
#[derive(Debug, Default)]
pub(crate) struct Watch {
    buf: Vec<Condition>,
    active: Vec<bool>,
    onsets: Vec<u32>,
    notes: Vec<(EventKind, String)>,
    /// Note kinds already reported.
    noted: Vec<EventKind>,
}

impl Watch {
    /// Check the conditions of state `x` at time `t_s` and push the events of what changed.
    pub fn check<const N: usize, M: VehicleModel<N>>(
        &mut self,
        model: &M,
        x: &SVector<f64, N>,
        u: &Inputs,
        env: &Environment,
        t_s: f64,
        events: &mut Vec<Event>,
    ) {
        let Some(model) = model.monitor() else {
            return;
        };
        self.buf.clear();
        model.conditions(x, u, env, &mut self.buf);
        if self.buf.len() != self.active.len() {
            // The model's list is fixed; this only sizes the memory on the first call.
            self.active.resize(self.buf.len(), false);
            self.onsets.resize(self.buf.len(), 0);
        }
        for (i, c) in self.buf.iter().enumerate() {
            if c.active == self.active[i] {
                continue;
            }
            self.active[i] = c.active;
            if self.onsets[i] > MAX_ONSETS {
                continue;
            }
            if c.active {
                self.onsets[i] += 1;
                if self.onsets[i] > MAX_ONSETS {
                    events.push(Event {
                        t_s,
                        kind: EventKind::EventsSuppressed,
                        detail: format!(
                            "{}: {} reported {MAX_ONSETS} times; its further onsets and recoveries are not reported",
                            c.subject, c.onset
                        ),
                    });
                    continue;
                }
            }
            let kind = if c.active { c.onset } else { c.recovery };
            events.push(Event { t_s, kind, detail: c.detail() });
        }
        model.notes(x, u, env, &mut self.notes);
        for (kind, detail) in self.notes.drain(..) {
            if !self.noted.contains(&kind) {
                self.noted.push(kind);
                events.push(Event { t_s, kind, detail });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::capability::Monitored;
    use crate::vehicle::Extras;

    /// One state component s; the condition "s < 0" is watched.
    struct Toy;

    impl VehicleModel<1> for Toy {
        const TYRES: usize = 0;
        fn state_names(&self) -> [&'static str; 1] {
            ["s"]
        }
        fn evaluate(&self, _x: &SVector<f64, 1>, _u: &Inputs, _env: &Environment, _e: Extras<'_>) -> SVector<f64, 1> {
            SVector::zeros()
        }
        fn initial_state(&self, _x: f64, _y: f64, _yaw: f64, _v: f64) -> SVector<f64, 1> {
            SVector::zeros()
        }
        fn body_acceleration(&self, _x: &SVector<f64, 1>, _dx: &SVector<f64, 1>) -> (f64, f64) {
            (0.0, 0.0)
        }
        fn monitor(&self) -> Option<&dyn Monitored<1>> {
            Some(self)
        }
    }

    impl Monitored<1> for Toy {
        fn conditions(&self, x: &SVector<f64, 1>, _u: &Inputs, _env: &Environment, out: &mut Vec<Condition>) {
            out.push(Condition {
                onset: EventKind::WheelLift,
                recovery: EventKind::WheelContact,
                subject: "s",
                quantity: "value",
                value: x[0],
                unit: "m",
                active: x[0] < 0.0,
            });
        }
        fn notes(&self, _x: &SVector<f64, 1>, _u: &Inputs, _env: &Environment, _out: &mut Vec<(EventKind, String)>) {}
    }

    /// A condition held for many steps gives one onset and one recovery; one that flaps every step
    /// is reported MAX_ONSETS times, then once as `events_suppressed`, then no more.
    #[test]
    fn onset_and_recovery_once_and_flapping_is_capped() {
        let (u, env) = (
            Inputs::default(),
            Environment {
                mu: 0.1,
                surface_temp_c: -3.0,
                regions: crate::vehicle::ground::GroundRegions::NONE,
                road: crate::vehicle::road::Road::FLAT,
            },
        );
        let mut w = Watch::default();
        let mut ev = Vec::new();
        for k in 0..100 {
            let s = if (10..50).contains(&k) { -1.0 } else { 1.0 };
            w.check(&Toy, &SVector::<f64, 1>::new(s), &u, &env, k as f64, &mut ev);
        }
        assert_eq!(ev.len(), 2, "{ev:?}");
        assert_eq!((ev[0].t_s, ev[0].kind, ev[0].detail.as_str()), (10.0, EventKind::WheelLift, "s: value -1.0 m"));
        assert_eq!((ev[1].t_s, ev[1].kind), (50.0, EventKind::WheelContact));

        let mut w = Watch::default();
        let mut ev = Vec::new();
        for k in 0..1000 {
            let s = if k % 2 == 0 { -1.0 } else { 1.0 };
            w.check(&Toy, &SVector::<f64, 1>::new(s), &u, &env, k as f64, &mut ev);
        }
        let onsets = ev.iter().filter(|e| e.kind == EventKind::WheelLift).count();
        assert_eq!(onsets, MAX_ONSETS as usize);
        assert_eq!(ev.iter().filter(|e| e.kind == EventKind::EventsSuppressed).count(), 1);
        assert_eq!(ev.len(), 2 * MAX_ONSETS as usize + 1, "{ev:?}");
    }
}
