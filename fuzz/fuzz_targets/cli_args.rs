//! Fuzz target `cli_args`: bytes go to `vehsim::fuzz_entry::cli_args` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::cli_args(data));
