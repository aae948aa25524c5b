//! vehsim — the application: the `vehsim` command line (run, batch, merge, envelope, tyre, atiim,
//! discover, synth, compare, plot, bench), result files and charts.
//!
//! The physics and the engine are in `vehsim-core` (no files); spec files are read and built into
//! the core's types by `vehsim-spec`. This crate adds:
//! - [`run`]: the files of one run; [`batch`]: sweeps, shards and their summaries;
//!   [`envelope`]: limit searches; [`compare`]: trajectory comparison.
//! - [`tyre_sweep`]: the `vehsim tyre` command; [`atiim`]: the `vehsim atiim` command.
//! - [`discover`]: the discrepancy workflow (measured runs vs. model, effect discovery, synthetic data).
//! - [`output`]: atomic files, signals and reading result tables back.
//!
//! Internal: the command line's glue (`cli`, hidden: the binary calls `cli::main`), timing runs
//! (`bench`), charts (`plot`) and progress counters (`progress`). `fuzz_entry` (hidden) is one
//! bytes-in entry point per kind of input, public only for the fuzz crate and its corpus test.

pub mod atiim;
pub mod batch;
pub(crate) mod bench;
#[doc(hidden)] // the binary's glue: `main` and the argument definitions (for `--help` tests)
pub mod cli;
pub mod compare;
pub mod discover;
pub mod envelope;
#[doc(hidden)] // for the fuzz crate (fuzz/) and tests/fuzz_corpus.rs only
pub mod fuzz_entry;
pub mod output;
pub(crate) mod plot;
pub(crate) mod progress;
pub mod run;
pub mod tyre_sweep;

pub use vehsim_core::{Error, Result};
