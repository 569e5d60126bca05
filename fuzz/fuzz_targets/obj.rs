//! The OBJ reader of distance-field meshes on arbitrary bytes: refused with a message, or
//! between 1 and 1024 finite triangles.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| texflow_fuzz::obj(data));
