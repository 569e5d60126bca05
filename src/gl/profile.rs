//! Per-draw timing on request: how long each draw of a frame took, named by its program, for
//! `texflow bench passes` (every pass of a frame next to its floor).
//!
//! While a [`DrawProfiler`] runs, [`Context::draw`] times every draw alone: on a hardware GPU
//! with a `GL_TIME_ELAPSED` query around it (the results are read at the end, so the pipeline
//! is not stalled between draws); on a software rasterizer (see [`Clock`]) as wall time between
//! two `glFinish` calls. No other timer query may be active meanwhile (they do not nest).
//! Work that is not a draw (clears, blits, texture copies, CPU work) is not timed here.

use std::cell::RefCell;
use std::time::Instant;

use super::{Clock, Context, TimerQuery};
use crate::error::Result;

/// One timed draw: its program (`vertex+fragment`), its milliseconds and the bytes it wrote
/// (full-screen draws: the viewport's texels × the target's bytes per texel; points and lines:
/// 0, their writes depend on what they cover).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawTime {
    /// The program drawn.
    pub program: String,
    /// Milliseconds the draw took.
    pub ms: f64,
    /// Bytes written by a full-screen draw; 0 for points and lines.
    pub bytes: u64,
    /// The label of the framebuffer drawn into.
    pub target: String,
}

enum Pending {
    Query(TimerQuery),
    Done(f64),
}

struct Log {
    clock: Clock,
    started: Option<Instant>,
    draws: Vec<(String, String, u64, Pending)>,
}

thread_local! {
    // One profile per thread: a GL context is current on one thread only.
    static PROFILE: RefCell<Option<Log>> = const { RefCell::new(None) };
}

/// Times every draw on this thread from [`DrawProfiler::start`] until
/// [`DrawProfiler::finish`] (or the profiler's drop, which discards the times). One at a time:
/// starting another replaces the profile under way, and dropping either ends it.
#[derive(Debug)]
pub struct DrawProfiler(());

impl DrawProfiler {
    /// Starts timing draws with `clock` (anew, where a profile was under way).
    pub fn start(clock: Clock) -> Self {
        PROFILE.with(|p| {
            *p.borrow_mut() = Some(Log {
                clock,
                started: None,
                draws: Vec::new(),
            })
        });
        DrawProfiler(())
    }

    /// Stops timing: every draw since the start, in order, with its time (waiting for the GPU
    /// where a query's result is not in yet).
    pub fn finish(self) -> Result<Vec<DrawTime>> {
        let log = PROFILE.with(|p| p.borrow_mut().take());
        let Some(log) = log else {
            return Ok(Vec::new());
        };
        let mut out = Vec::with_capacity(log.draws.len());
        for (program, target, bytes, pending) in log.draws {
            let ms = match pending {
                Pending::Query(q) => q.nanoseconds()? as f64 * 1e-6,
                Pending::Done(ms) => ms,
            };
            out.push(DrawTime {
                program,
                ms,
                bytes,
                target,
            });
        }
        Ok(out)
    }
}

impl Drop for DrawProfiler {
    fn drop(&mut self) {
        PROFILE.with(|p| p.borrow_mut().take());
    }
}

/// Called by [`Context::draw`] before a draw: starts its timing if a profile is under way;
/// returns whether it did (a query that cannot be made leaves the draw untimed).
pub(crate) fn before(ctx: &Context) -> bool {
    PROFILE.with(|p| {
        let mut p = p.borrow_mut();
        let Some(log) = p.as_mut() else {
            return false;
        };
        match log.clock {
            Clock::Gpu => match TimerQuery::new(ctx) {
                Ok(q) => {
                    q.begin();
                    (log.draws).push((String::new(), String::new(), 0, Pending::Query(q)));
                }
                Err(_) => return false,
            },
            Clock::Wall => {
                ctx.finish();
                log.started = Some(Instant::now());
            }
        }
        true
    })
}

/// Called by [`Context::draw`] after a draw that [`before`] started timing.
pub(crate) fn after(ctx: &Context, program: &str, target: &str, bytes: u64) {
    PROFILE.with(|p| {
        let mut p = p.borrow_mut();
        let Some(log) = p.as_mut() else {
            return;
        };
        match log.clock {
            Clock::Gpu => {
                if let Some((name, t, b, Pending::Query(q))) = log.draws.last_mut() {
                    q.end();
                    *name = program.to_owned();
                    *t = target.to_owned();
                    *b = bytes;
                }
            }
            Clock::Wall => {
                ctx.finish();
                let ms = log
                    .started
                    .take()
                    .map_or(0.0, |t| t.elapsed().as_secs_f64() * 1e3);
                let d = (program.to_owned(), target.to_owned(), bytes);
                log.draws.push((d.0, d.1, d.2, Pending::Done(ms)));
            }
        }
    });
}
