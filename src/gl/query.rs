//! `GL_TIME_ELAPSED` timer queries: GPU time of a range of commands, without stalling the
//! pipeline until the result is asked for.

use glow::HasContext;

use super::Context;
use crate::error::{Error, Result};

/// An owned timer query object.
pub struct TimerQuery {
    ctx: Context,
    raw: glow::Query,
}

impl std::fmt::Debug for TimerQuery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TimerQuery")
    }
}

impl TimerQuery {
    /// Makes a query object.
    pub fn new(ctx: &Context) -> Result<Self> {
        // SAFETY: plain object creation.
        let raw = unsafe { ctx.gl().create_query().map_err(Error::Gl)? };
        Ok(TimerQuery {
            ctx: ctx.clone(),
            raw,
        })
    }

    /// Starts timing. Timer queries do not nest: end one before beginning the next.
    pub fn begin(&self) {
        // SAFETY: the query is alive; no other TIME_ELAPSED query is active by contract.
        unsafe { self.ctx.gl().begin_query(glow::TIME_ELAPSED, self.raw) }
    }

    /// Stops timing.
    pub fn end(&self) {
        // SAFETY: ends the active TIME_ELAPSED query.
        unsafe { self.ctx.gl().end_query(glow::TIME_ELAPSED) }
    }

    /// The elapsed GPU time in nanoseconds; waits for the GPU if the result is not ready.
    pub fn nanoseconds(&self) -> Result<u64> {
        let mut value = 0u64;
        // SAFETY: glGetQueryObjectui64v writes one u64 to the pointer (no query buffer bound).
        unsafe {
            self.ctx.gl().get_query_parameter_u64_with_offset(
                self.raw,
                glow::QUERY_RESULT,
                &mut value as *mut u64 as usize,
            );
        }
        self.ctx.check_error("reading a timer query")?;
        Ok(value)
    }

    /// Times the GL commands issued by `f`, returning its result and the GPU milliseconds.
    pub fn time<T>(&self, f: impl FnOnce() -> T) -> Result<(T, f64)> {
        self.begin();
        let out = f();
        self.end();
        Ok((out, self.nanoseconds()? as f64 * 1e-6))
    }
}

impl Drop for TimerQuery {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_query(self.raw) }
        }
    }
}

/// An owned `GL_SAMPLES_PASSED` query: the fragments a range of draws wrote (that passed the
/// depth test and were not discarded), for the benchmarks' check that a floor draws no more than
/// the pass it bounds.
pub struct SamplesQuery {
    ctx: Context,
    raw: glow::Query,
}

impl std::fmt::Debug for SamplesQuery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SamplesQuery")
    }
}

impl SamplesQuery {
    /// Makes a query object.
    pub fn new(ctx: &Context) -> Result<Self> {
        // SAFETY: plain object creation.
        let raw = unsafe { ctx.gl().create_query().map_err(Error::Gl)? };
        Ok(SamplesQuery {
            ctx: ctx.clone(),
            raw,
        })
    }

    /// Counts the samples written by the GL commands `f` issues (waits for them); returns `f`'s
    /// result and the count. Queries of one target do not nest.
    pub fn count<T>(&self, f: impl FnOnce() -> T) -> Result<(T, u64)> {
        let gl = self.ctx.gl();
        // SAFETY: the query is alive; no other SAMPLES_PASSED query is active by contract.
        unsafe { gl.begin_query(glow::SAMPLES_PASSED, self.raw) };
        let out = f();
        let mut value = 0u64;
        // SAFETY: ends the active query; glGetQueryObjectui64v writes one u64 to the pointer
        // (no query buffer bound).
        unsafe {
            gl.end_query(glow::SAMPLES_PASSED);
            gl.get_query_parameter_u64_with_offset(
                self.raw,
                glow::QUERY_RESULT,
                &mut value as *mut u64 as usize,
            );
        }
        self.ctx.check_error("reading a samples query")?;
        Ok((out, value))
    }
}

impl Drop for SamplesQuery {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_query(self.raw) }
        }
    }
}
