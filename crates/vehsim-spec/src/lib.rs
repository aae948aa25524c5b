//! vehsim-spec — the spec files of vehsim: TOML manoeuvre, vehicle, tyre and contact specs and
//! `.tir` files, each read, checked (every number against its bound, every path resolved) and
//! built into the core's validated types before anything runs. Unknown keys are rejected; paths
//! inside a spec are relative to the spec file. [`kind`] tells a spec of another command (tyre
//! curves, ATIIM scenario) apart and names that command; [`strict`] refuses a table given in
//! another shape (`surface = [1.0, 2.0]`). [`run`] runs a validated spec in memory; [`step`] is
//! the step-by-step interface for external callers.
//!
//! # Example: a run built in code and stepped by hand
//!
//! A spec is checked as a file would be ([`ManeuverFile::build`]), the engine
//! ([`vehsim_core::sim::Simulation`]) is advanced one step at a time with the state readable between steps, and
//! [`vehsim_core::sim::Simulation::finish`] gives the summary. [`run::execute`] does the same in one call and
//! adds the plausibility checks and the steady-state analysis.
//!
//! ```
//! use std::path::Path;
//! use vehsim_core::contact::Isothermal;
//! use vehsim_core::event::EndReason;
//! use vehsim_core::sim::{observer::NoOutput, Simulation};
//! use vehsim_spec::ManeuverFile;
//! use vehsim_core::vehicle::{Bicycle, VehicleModel};
//!
//! # fn main() -> vehsim_core::Result<()> {
//! // The path anchors the relative paths inside the spec (here the shipped sedan); no file is read
//! // at that path.
//! let anchor = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../maneuvers/in_code.toml");
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
//! let mut spec: ManeuverFile = vehsim_spec::files::parse_toml(&anchor, text)?;
//! spec.surface.mu = 0.15; // ice
//! let cfg = spec.build(&anchor)?; // every value checked, as for a file
//!
//! let model = Bicycle::new(cfg.vehicle.clone());
//! let mut maneuver = vehsim_spec::run::build_maneuver(&cfg);
//! let controls = vehsim_spec::run::controls(&cfg, maneuver.start().speed_mps);
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

#![warn(missing_docs)]

pub mod contact;
pub mod files;
pub mod kind;
pub mod maneuver;
pub mod patch_file;
pub mod run;
pub mod step;
pub mod strict;
pub mod sweep;
pub mod tir;
pub mod tyre;
pub mod vehicle;

pub use maneuver::{ManeuverFile, RunConfig};
pub use vehicle::VehicleFile;
