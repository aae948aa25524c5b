//! Unphysical conditions of a model state (a wheel off the ground, a negative normal load), which
//! the engine watches at every step and reports as events when they start and end.
//!
//! A model describes each condition it watches by a [`Condition`]: whether it holds in the state,
//! the event kinds of its onset and its recovery, what it concerns and the value that decides it
//! (with its unit). The engine ([`crate::sim::watch`]) turns the changes into events; the model
//! only evaluates the state.

use crate::event::EventKind;

/// One watched condition of a state, as reported by
/// [`Monitored::conditions`](super::capability::Monitored::conditions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Condition {
    /// Event kind when the condition starts to hold (e.g. `wheel_lift`).
    pub onset: EventKind,
    /// Event kind when it stops holding (e.g. `wheel_contact`).
    pub recovery: EventKind,
    /// What it concerns, e.g. `front-left wheel`.
    pub subject: &'static str,
    /// Name of the deciding quantity, e.g. `normal load before clamping`.
    pub quantity: &'static str,
    /// Its value in this state, in `unit`.
    pub value: f64,
    /// Unit of `value`, e.g. `N`.
    pub unit: &'static str,
    /// Whether the condition holds in this state.
    pub active: bool,
}

impl Condition {
    /// Event detail: subject, quantity and value, e.g.
    /// `front-left wheel: normal load before clamping -523.4 N`.
    pub fn detail(&self) -> String {
        format!("{}: {} {:.1} {}", self.subject, self.quantity, self.value, self.unit)
    }
}
