//! Spec files: serde types for `vehicles/*.toml` and `maneuvers/*.toml`, each turned into a
//! validated model (every number checked, every path resolved) before anything runs.
//! Unknown keys are rejected; paths inside a spec are relative to the spec file. [`kind`] tells a
//! spec of another command (tyre curves, ATIIM scenario) apart and names that command; [`strict`]
//! refuses a table given in another shape (`surface = [1.0, 2.0]`).

pub mod kind;
pub mod maneuver;
pub mod strict;
pub mod vehicle;

pub use maneuver::{ManeuverFile, RunConfig};
pub use vehicle::VehicleFile;
