//! vehsim — a vehicle-dynamics simulation engine for driving on ice.
//!
//! Layout (one concept per module):
//! - [`spec`]: vehicle and manoeuvre spec files, validated into models before anything runs.
//! - [`vehicle`]: vehicle models as pure equations (nonlinear bicycle, 4-DOF roll model).
//! - [`tyre`]: tyre-force providers behind [`tyre::TyreModel`] and the tyre spec files.
//! - [`contact`]: per-step contact-temperature estimate (ATIIM).
//! - [`control`]: PID speed controller and path-following driver.
//! - [`maneuver`]: ISO 3888-2, constant radius (ISO 4138) and open-loop manoeuvres, reference paths,
//!   steady-state analysis.
//! - [`sim`]: integrators and the engine that owns time.
//! - [`run`]: one run from a spec to result files; [`cli`]: the command line; [`bench`]: timing runs.
//! - [`discover`]: the discrepancy workflow (measured runs vs. model, effect discovery, synthetic data).
//! - [`error`]: the error type and spec-value checks; [`output`]: atomic files; [`plot`]: charts;
//!   [`progress`]: progress counters on the terminal.
//! - [`fuzz_entry`]: one bytes-in entry point per kind of input, for fuzzing and its corpus test.

pub mod batch;
pub mod bench;
pub mod cli;
pub mod compare;
pub mod contact;
pub mod control;
pub mod discover;
pub mod envelope;
pub mod error;
pub mod fuzz_entry;
pub mod maneuver;
pub mod output;
pub mod plot;
pub mod progress;
pub mod run;
pub mod sim;
pub mod spec;
pub mod tyre;
pub mod vehicle;

pub use error::{Error, Result};
