//! Fuzz target `sidecar_toml`: bytes go to `vehsim::fuzz_entry::sidecar_toml` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::sidecar_toml(data));
