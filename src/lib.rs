//! vehsim — a vehicle-dynamics simulation engine for driving on ice.
//!
//! Layout (one concept per module):
//! - [`error`]: the error type and spec-value checks.
//! - [`tyre`]: tyre-force providers behind [`tyre::TyreModel`] and the tyre spec files.
//! - [`contact`]: per-step contact-temperature estimate (ATIIM).
//! - [`output`]: atomic result files; [`plot`]: PNG/SVG charts.

pub mod contact;
pub mod error;
pub mod output;
pub mod plot;
pub mod tyre;

pub use error::{Error, Result};
