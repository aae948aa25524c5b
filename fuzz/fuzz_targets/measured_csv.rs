//! Fuzz target `measured_csv`: bytes go to `vehsim::fuzz_entry::measured_csv` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::measured_csv(data));
