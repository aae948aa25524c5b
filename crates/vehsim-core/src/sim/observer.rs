//! Observers: what the engine tells the outside world after each recorded step. Output files,
//! progress and plots subscribe here; the engine itself does no I/O.

use crate::vehicle::{Inputs, Observation};

/// One recorded instant: the state at `t_s` and the inputs held over the following step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Simulation time of the row, s.
    pub t_s: f64,
    /// What the vehicle model reports at `t_s`.
    pub obs: Observation,
    /// Driver and controller inputs held over the following step.
    pub inputs: Inputs,
    /// Speed target of the PID, m/s (NaN while coasting).
    pub speed_target_mps: f64,
    /// Signed lateral deviation from the reference path, m (NaN for open-loop manoeuvres).
    pub path_error_m: f64,
}

/// Receives recorded rows. All methods have no-op defaults.
pub trait Observer {
    /// Called after each recorded step with its row.
    fn record(&mut self, _row: &Row) {}
}

/// Observer that does nothing.
pub struct NoOutput;
impl Observer for NoOutput {}

/// Keeps every recorded row in memory.
#[derive(Debug, Default, Clone)]
pub struct Recorder {
    /// Every recorded row, in time order.
    pub rows: Vec<Row>,
}

impl Recorder {
    /// A recorder with room for `rows` rows (no reallocation while a run of that many records).
    pub fn with_capacity(rows: usize) -> Self {
        Self { rows: Vec::with_capacity(rows) }
    }
}

impl Observer for Recorder {
    fn record(&mut self, row: &Row) {
        // Copied once, straight from `row` into the vector (`push(*row)` copied it to the stack
        // first: two copies of a few hundred bytes per row).
        self.rows.extend_from_slice(std::slice::from_ref(row));
    }
}
