//! Controllers sampled by the engine once per control period, their outputs ramped across it
//! (`crate::sim::engine`): the PID speed controller and
//! the path-following driver. They see only the vehicle's kinematics, never its internal state.

pub mod abs;
pub mod driver;
pub mod pid;
pub mod tcs;

pub use driver::{Driver, DriverParams};
pub use pid::{Pid, PidParams};
