//! Fuzz target `tyre_toml`: bytes go to `vehsim::fuzz_entry::tyre_toml` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::tyre_toml(data));
