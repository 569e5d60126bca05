//! The field front end on arbitrary bytes (see `fuzz/src/lib.rs`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| texflow_fuzz::field(data));
