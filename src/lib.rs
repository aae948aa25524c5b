//! vehsim — a vehicle-dynamics simulation engine for driving on ice.
//!
//! The public API, for callers outside the command line (one concept per module):
//! - [`spec`]: vehicle and manoeuvre spec files, validated into models before anything runs.
//! - [`vehicle`]: vehicle models as pure equations (nonlinear bicycle, 4-DOF roll model).
//! - [`tyre`]: tyre-force providers behind [`tyre::TyreModel`] and the tyre spec files.
//! - [`contact`]: per-step contact-temperature estimate (ATIIM).
//! - [`control`]: PID speed controller and path-following driver.
//! - [`maneuver`]: ISO 3888-2, constant radius (ISO 4138) and open-loop manoeuvres, reference paths,
//!   steady-state analysis; run events ([`maneuver::Event`], [`maneuver::EventKind`]).
//! - [`sim`]: integrators and the steppable engine that owns time ([`sim::Simulation`]).
//! - [`run`]: one run from a spec to result files; [`batch`]: sweeps and their summaries;
//!   [`envelope`]: limit searches; [`compare`]: trajectory comparison.
//! - [`discover`]: the discrepancy workflow (measured runs vs. model, effect discovery, synthetic data).
//! - [`error`]: the error type and spec-value checks ([`error::Bound`]); [`output`]: atomic files
//!   and reading result tables back.
//!
//! Internal: the command line's glue (`cli`, hidden: the binary calls `cli::main`), timing runs
//! (`bench`), charts (`plot`) and progress counters (`progress`). `fuzz_entry` (hidden) is one
//! bytes-in entry point per kind of input, public only for the fuzz crate and its corpus test.
//!
//! # Example: a run built in code and stepped by hand
//!
//! A spec is checked as a file would be ([`spec::ManeuverFile::build`]), the engine
//! ([`sim::Simulation`]) is advanced one step at a time with the state readable between steps, and
//! [`sim::Simulation::finish`] gives the summary. [`run::execute`] does the same in one call and
//! adds the plausibility checks and the steady-state analysis.
//!
//! ```
//! use std::path::Path;
//! use vehsim::contact::Isothermal;
//! use vehsim::sim::{observer::NoOutput, EndReason, Simulation};
//! use vehsim::spec::ManeuverFile;
//! use vehsim::vehicle::{Bicycle, VehicleModel};
//!
//! # fn main() -> vehsim::Result<()> {
//! // The path anchors the relative paths inside the spec (here the shipped sedan); no file is read
//! // at that path.
//! let anchor = Path::new(env!("CARGO_MANIFEST_DIR")).join("maneuvers/in_code.toml");
//! let text = r#"
//!     name = "in_code"
//!     vehicle = "../vehicles/sedan.toml"
//!     tyre_model = "pacejka"
//!     [surface]
//!     mu = 1.0
//!     [maneuver]
//!     kind = "iso3888_2"
//!     speed_mps = 8.0
//! "#;
//! let mut spec: ManeuverFile = vehsim::error::parse_toml(&anchor, text)?;
//! spec.surface.mu = 0.15; // ice
//! let cfg = spec.build(&anchor)?; // every value checked, as for a file
//!
//! let model = Bicycle::new(cfg.vehicle.clone());
//! let mut maneuver = vehsim::run::build_maneuver(&cfg);
//! let controls = vehsim::run::controls(&cfg, maneuver.start().speed_mps);
//! let (mut contact, mut observer) = (Isothermal, NoOutput);
//! let mut sim =
//!     Simulation::new(&model, cfg.env, maneuver.as_mut(), &mut contact, &controls, &cfg.settings, &mut observer);
//! let (mut steps, mut peak_r) = (0_u64, 0.0_f64);
//! let end = loop {
//!     if let Some(end) = sim.step() {
//!         break end;
//!     }
//!     steps += 1;
//!     peak_r = peak_r.max(model.kinematics(sim.state()).yaw_rate_radps.abs());
//! };
//! let summary = sim.finish();
//! assert_eq!((end, summary.end_reason), (EndReason::Completed, EndReason::Completed));
//! assert!(summary.steps >= steps && summary.peak_yaw_rate_radps >= peak_r && peak_r > 0.05);
//! println!("{:?} at {:.2} s, passed {:?}, peak yaw rate {peak_r:.3} rad/s", end, summary.end_time_s, summary.passed);
//! # Ok(())
//! # }
//! ```

/// The names of a closed set of choices (spec keywords, flag values, result strings), each written
/// once: generates `ALL` (declaration order), `as_str`, `parse` and `allowed` (comma-separated, for
/// messages) for a unit-variant enum from its `Variant => "name"` list.
macro_rules! choice_names {
    ($t:ident { $($v:ident => $s:literal),+ $(,)? }) => {
        impl $t {
            /// Every value, in declaration order.
            pub const ALL: &'static [$t] = &[$($t::$v),+];

            /// The value's name in spec and result files.
            pub fn as_str(self) -> &'static str {
                match self {
                    $($t::$v => $s),+
                }
            }

            /// The value named `name`, if any.
            pub fn parse(name: &str) -> Option<Self> {
                Self::ALL.iter().copied().find(|k| k.as_str() == name)
            }

            /// Every name, comma-separated (for messages).
            pub fn allowed() -> String {
                Self::ALL.iter().map(|k| k.as_str()).collect::<Vec<_>>().join(", ")
            }
        }
    };
}

/// `Serialize` and `Display` for an enum through its `as_str(self) -> &'static str`, the one list
/// of its names (outcomes and event kinds written to result files).
macro_rules! named_by_as_str {
    ($t:ty) => {
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
                s.serialize_str(self.as_str())
            }
        }

        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }
    };
}

pub mod batch;
pub(crate) mod bench;
#[doc(hidden)] // the binary's glue: `main` and the argument definitions (for `--help` tests)
pub mod cli;
pub mod compare;
pub mod contact;
pub mod control;
pub mod discover;
pub mod envelope;
pub mod error;
pub mod files;
#[doc(hidden)] // for the fuzz crate (fuzz/) and tests/fuzz_corpus.rs only
pub mod fuzz_entry;
pub mod maneuver;
pub mod output;
pub(crate) mod plot;
pub(crate) mod progress;
pub mod run;
pub mod run_files;
pub mod sim;
pub mod spec;
pub mod tyre;
pub mod vehicle;

pub use error::{Error, Result};
