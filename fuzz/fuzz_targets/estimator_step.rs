//! Arbitrary estimator configuration, then arbitrary samples (NaN, ∞, huge included).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|case: fado_fuzz::EstimatorCase| case.run());
