//! Arbitrary drive configuration, then arbitrary phase currents, DC link and speed reference.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|case: fado_fuzz::DriveCase| case.run());
