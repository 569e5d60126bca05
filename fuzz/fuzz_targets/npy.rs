//! Every .npy reader on arbitrary bytes: refused as bad input, or exactly the declared elements.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| texflow_fuzz::npy(data));
