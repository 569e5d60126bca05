//! The scene parser and validation on arbitrary text: refused with a line and column, or valid.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| texflow_fuzz::scene(data));
