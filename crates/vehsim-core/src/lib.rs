//! vehsim-core — the physics and the engine of vehsim, a vehicle-dynamics simulation engine for
//! driving on ice. Nothing here reads or writes files; specs are read by `vehsim-spec`, results
//! written by the `vehsim` application.
//!
//! - [`vehicle`]: vehicle models as pure equations (nonlinear bicycle, 4-DOF roll model) and the
//!   validated [`vehicle::Vehicle`] they read.
//! - [`tyre`]: tyre-force providers behind [`tyre::TyreModel`], the ice friction law.
//! - [`contact`]: the per-step contact-temperature estimate (ATIIM) and the contact-patch model.
//! - [`control`]: PID speed controller, path-following driver, ABS and traction control.
//! - [`maneuver`]: ISO 3888-2, constant radius, open-loop, braking and launch manoeuvres;
//!   [`path`]: the reference paths the driver follows.
//! - [`event`]: what happens during a run and why it ends.
//! - [`sim`]: integrators and the steppable engine that owns time ([`sim::Simulation`]), recorded
//!   rows, plausibility checks, steady-state analysis.
//! - [`error`]: the error type shared by the vehsim crates, and the bound checks.
//!
//! Feature `serde`: `Serialize`/`Deserialize` for the parameter and result types.

#![warn(missing_docs)]

/// The names of a closed set of choices (spec keywords, flag values, result strings), each written
/// once: generates `ALL` (declaration order), `as_str`, `parse` and `allowed` (comma-separated, for
/// messages) for a unit-variant enum from its `Variant => "name"` list.
#[macro_export]
#[doc(hidden)]
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
#[macro_export]
#[doc(hidden)]
macro_rules! named_by_as_str {
    ($t:ty) => {
        $crate::serialize_by_as_str!($t);

        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.as_str())
            }
        }
    };
}

/// `Serialize` through `as_str` (with the `serde` feature; nothing without it).
#[cfg(feature = "serde")]
#[macro_export]
#[doc(hidden)]
macro_rules! serialize_by_as_str {
    ($t:ty) => {
        impl $crate::serde::Serialize for $t {
            fn serialize<S: $crate::serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
                s.serialize_str(self.as_str())
            }
        }
    };
}

/// `Serialize` through `as_str` (with the `serde` feature; nothing without it).
#[cfg(not(feature = "serde"))]
#[macro_export]
#[doc(hidden)]
macro_rules! serialize_by_as_str {
    ($t:ty) => {};
}

#[cfg(feature = "serde")]
#[doc(hidden)]
pub use serde;

pub mod contact;
pub mod control;
pub mod error;
pub mod event;
pub mod maneuver;
pub mod path;
pub mod sim;
pub mod tyre;
pub mod vehicle;

pub use error::{Error, Result};
