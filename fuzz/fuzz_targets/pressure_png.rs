//! Fuzz target `pressure_png`: bytes go to `vehsim::fuzz_entry::pressure_png` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::pressure_png(data));
