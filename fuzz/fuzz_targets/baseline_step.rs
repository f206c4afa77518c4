//! The reference estimators: arbitrary configuration, then arbitrary samples.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|case: fado_fuzz::BaselineCase| case.run());
