//! Fuzz target `tir`: bytes go to `vehsim::fuzz_entry::tir` (see docs/fuzzing.md).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| vehsim::fuzz_entry::tir(data));
