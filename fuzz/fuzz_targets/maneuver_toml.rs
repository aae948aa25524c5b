//! Fuzz target `maneuver_toml`: bytes go to `vehsim::fuzz_entry::maneuver_toml` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::maneuver_toml(data));
