//! Helpers shared by the GPU tests. Every test makes its own context on its own thread (GL
//! contexts are bound to a thread) and ends with `no_gl_error`.

#![allow(dead_code)]

use texflow::gl::Context;

/// A context on the first EGL device (llvmpipe in CI).
pub fn context() -> Context {
    Context::new(0).expect("an EGL device (install libegl1 libegl-mesa0 libgl1-mesa-dri)")
}

/// Asserts that no GL error is pending.
pub fn no_gl_error(ctx: &Context) {
    ctx.check_error("the test").expect("no pending GL error");
}
