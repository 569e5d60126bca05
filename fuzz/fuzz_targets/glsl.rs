//! The custom-force GLSL front end on arbitrary bytes: the text checks, then include resolution
//! and `#line` mapping of what they accept.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| texflow_fuzz::glsl(data));
