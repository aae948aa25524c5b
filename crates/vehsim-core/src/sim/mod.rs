//! Time stepping: the integrators and the engine that owns time, samples the controllers, updates
//! the contact temperature, advances the state, reports the model's unphysical conditions and
//! notifies observers.

pub mod columns;
pub mod engine;
pub mod external;
pub mod integrator;
pub mod observer;
pub mod plausibility;
pub mod range_check;
pub mod slip_control;
pub mod stability;
pub mod steady_state;
pub mod watch;

pub use engine::{simulate, Controls, SimSettings, Simulation, Summary};
pub use external::{ExternalInputs, SteerRate, Torque};
pub use integrator::Method;
pub use observer::{Observer, Recorder, Row};
pub use plausibility::Plausibility;
