//! Fuzz target `pressure_csv`: bytes go to `vehsim::fuzz_entry::pressure_csv` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::pressure_csv(data));
