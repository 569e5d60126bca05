//! A cost model of the papers' tables: every cell of Table 1 and Table 2 predicted from its pass
//! list (passes, bytes written, texel fetches, points drawn) and four constants of the device,
//! each measured by a microbenchmark in the same run ([`crate::bench::cost`] says which).
//!
//! predicted ms = passes × fixed + follow-ons × follow-on + concurrent × concurrent + bytes ×
//! per byte + fetches × per fetch + points × per point + other vertices × per vertex
//! ([`Constants::predict_drawn`]).
//! The passes, bytes and fetches of each cell are what the GL layer counted while it ran
//! ([`crate::gl::DrawStats`]): the fetches as the passes that know them declared them (the
//! sorts' key, network and gather passes, in Table 1 and in Table 2's sorted frames, and
//! UberFlow's detection and mutual check, E4's, as for an all-live state); the other passes of a
//! frame (integration, the collision response, rendering) declare none, so the model
//! underestimates a frame where those wait on fetches.
//!
//! The same model with the ATI Radeon 9800 Pro's published figures (fill rate and memory
//! bandwidth) against UberFlow's own Table 1 says where the 2004 sorts were bound by memory and
//! where by something else (see [`Gpu2004`]).

use std::path::Path;

use super::{write_json, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::cost::{measure_constants, Constants};
use crate::bench::scenes::{self as bs, ScenesOptions};
use crate::bench::{bench_sort, Clock, PassTimer, SortBenchOptions};
use crate::error::Result;
use crate::gl::{Context, DrawStats};
use crate::sort::Variant;

/// The ATI Radeon 9800 Pro of UberFlow's tables, from ATI's published specifications (2003):
/// 8 pixel pipelines at 380 MHz (3.04 G pixels/s) and 21.8 GB/s of memory bandwidth (256 bits
/// at 340 MHz DDR). Fragments write and fetch RGBA32F (16 bytes): the card's float render
/// targets are four-channel.
#[derive(Debug, Clone, Copy)]
pub struct Gpu2004;

impl Gpu2004 {
    /// Pixels per second.
    pub const FILL: f64 = 3.04e9;
    /// Bytes per second.
    pub const BANDWIDTH: f64 = 21.8e9;

    /// Milliseconds of one full sort of side² entries by `variant` (`passes` network passes):
    /// the larger of the fill-rate time and the memory time, pass by pass.
    pub fn sort_ms(variant: Variant, side: u32, passes: usize) -> f64 {
        let n = side as f64 * side as f64;
        // Fragments per network pass and texel fetches per fragment.
        let (fragments, fetches) = match variant {
            Variant::Packed => (n / 2.0, 2.0),
            // Every other variant as a fragment per entry reading two: a new variant must say
            // what it writes here.
            Variant::Fp
            | Variant::GpFp
            | Variant::OddEven
            | Variant::Multistep
            | Variant::Blocked => (n, 2.0),
        };
        let bytes = fragments * 16.0 * (1.0 + fetches);
        let pass = (fragments / Self::FILL).max(bytes / Self::BANDWIDTH);
        passes as f64 * pass * 1e3
    }
}

/// One predicted cell.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Cell {
    /// `Table 1` or `Table 2`.
    pub table: &'static str,
    /// Variant or experiment.
    pub what: String,
    /// State side.
    pub size: u32,
    /// Measured median ms.
    pub measured_ms: f64,
    /// The model's ms.
    pub predicted_ms: f64,
    /// Passes, bytes written, fetches and points the prediction used.
    pub passes: u64,
    /// Bytes written.
    pub bytes: u64,
    /// Texel fetches (0: not counted).
    pub fetches: u64,
    /// Points drawn.
    pub points: u64,
}

fn sizes(size: Size, clock: Clock) -> (Vec<u32>, usize) {
    match (size, clock) {
        (Size::Quick, _) => (vec![64, 128], 3),
        (Size::Full, Clock::Gpu) => (vec![256, 512, 1024], 7),
        (Size::Full, Clock::Wall) => (vec![128, 256], 3),
    }
}

/// The report section: constants, Table 1 and Table 2 predicted against measured, and the 2004
/// card against the paper.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let clock = Clock::for_context(ctx);
    let timer = PassTimer::new(ctx, clock)?;
    let (sizes, repeats) = sizes(opts.size, clock);
    progress("cost model: constants");
    let side = *sizes.last().unwrap_or(&256);
    let c = measure_constants(ctx, &timer, side, repeats)?;
    let mut cells = table1_cells(ctx, &c, &sizes, repeats, progress)?;
    cells.extend(table2_cells(ctx, &c, &sizes, repeats, opts.size, progress)?);
    let json = out.join("cost_model.json");
    write_json(
        &json,
        &serde_json::json!({ "constants": c, "cells": cells }),
    )?;
    let markdown = markdown(ctx, &c, &cells);
    let md = out.join("cost_model.md");
    super::write_atomic(&md, markdown.as_bytes())?;
    Ok(SectionOutput {
        files: vec![json, md],
        markdown,
        warnings: Vec::new(),
    })
}

/// Table 1's cells: every sort variant timed by `texflow bench sort` at `sizes`, with what its
/// full sort drew, against the model of constants `c`.
fn table1_cells(
    ctx: &Context,
    c: &Constants,
    sizes: &[u32],
    repeats: usize,
    progress: Progress<'_>,
) -> Result<Vec<Cell>> {
    let mut cells = Vec::new();
    let variants = [
        Variant::Fp,
        Variant::GpFp,
        Variant::Packed,
        Variant::OddEven,
        Variant::Blocked,
    ];
    let sort_opts = SortBenchOptions {
        repeats,
        clock: None,
        cpu: false,
        steps_per_pass: 2,
        blocked_shapes: Vec::new(),
    };
    let t1 = bench_sort(ctx, sizes, &variants, &sort_opts, |v, n| {
        progress(&format!("cost model: Table 1 {v} at {n}²"))
    })?;
    for r in &t1 {
        let (Some(d), Some(f)) = (r.draws, r.fetches) else {
            continue;
        };
        cells.push(Cell {
            table: "Table 1",
            what: r.variant.clone(),
            size: r.size,
            measured_ms: r.ms,
            predicted_ms: c.predict_drawn(&DrawStats { fetches: f, ..d }),
            passes: d.draws,
            bytes: d.bytes_written,
            fetches: f,
            points: d.points,
        });
    }
    Ok(cells)
}

/// Table 2's cells: E1-E4 (and E3p) frames timed by `texflow bench scenes` at `sizes` (after
/// 20 warm-up frames for a quick report), against the model of constants `c`.
fn table2_cells(
    ctx: &Context,
    c: &Constants,
    sizes: &[u32],
    repeats: usize,
    size: Size,
    progress: Progress<'_>,
) -> Result<Vec<Cell>> {
    let mut cells = Vec::new();
    let scene_opts = ScenesOptions {
        repeats,
        warmup_frames: matches!(size, Size::Quick).then_some(20),
        experiments: ["E1", "E2", "E3", "E3p", "E4"].map(String::from).to_vec(),
        ..ScenesOptions::default()
    };
    let t2 = bs::bench_scenes(ctx, sizes, &scene_opts, |e, n| {
        progress(&format!("cost model: Table 2 {e} at {n}²"))
    })?;
    for r in &t2 {
        let (Some(ms), Some(d)) = (r.ms, r.frame_draws) else {
            continue;
        };
        cells.push(Cell {
            table: "Table 2",
            what: r.experiment.clone(),
            size: r.size,
            measured_ms: ms,
            predicted_ms: c.predict_drawn(&d),
            passes: d.draws,
            bytes: d.bytes_written,
            fetches: d.fetches,
            points: d.points,
        });
    }
    Ok(cells)
}

fn markdown(ctx: &Context, c: &Constants, cells: &[Cell]) -> String {
    let mut m = format!(
        "## A cost model of Tables 1 and 2 (`texflow report all --only cost`)\n\n\
         Device: {}. Constants measured in the same run: {}. Predicted ms = passes × fixed + \
         follow-ons × follow-on + concurrent × concurrent + bytes × per byte + fetches × per \
         fetch + points × per point + other vertices × per vertex (a follow-on: a draw into the \
         target the draw before it drew into; a concurrent draw: one that reads nothing the \
         draws before it wrote and writes nothing they read; fetches: those the sorts' passes \
         and UberFlow's detection declare).\n\n\
         | table | sort / experiment | size | passes | MB written | M fetches | M points | \
         measured ms | predicted ms | predicted / measured |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        ctx.limits().renderer,
        c.describe()
    );
    for x in cells {
        m += &format!(
            "| {} | {} | {}² | {} | {:.1} | {:.2} | {:.2} | {:.3} | {:.3} | {:.2} |\n",
            x.table,
            x.what,
            x.size,
            x.passes,
            x.bytes as f64 * 1e-6,
            x.fetches as f64 * 1e-6,
            x.points as f64 * 1e-6,
            x.measured_ms,
            x.predicted_ms,
            x.predicted_ms / x.measured_ms
        );
    }
    m += "\n### The same model on the 2004 card against UberFlow's Table 1\n\n\
          ATI Radeon 9800 Pro (ATI's specifications: 8 pipelines × 380 MHz = 3.04 G pixels/s, \
          21.8 GB/s): each pass is bound by the larger of its fragments at the fill rate and its \
          bytes (16 written and 16 per fetch, RGBA32F) at the bandwidth; the paper's fps beside \
          it.\n\n\
          | variant | size | passes | predicted fps | paper fps | paper / predicted |\n\
          |---|---:|---:|---:|---:|---:|\n";
    for v in [Variant::Fp, Variant::GpFp, Variant::Packed] {
        for side in [128u32, 256, 512, 1024] {
            let Some(paper) = crate::bench::paper_table1_fps(v, side) else {
                continue;
            };
            let o = crate::sort::SortOptions::default();
            let passes = crate::sort::pass_count(v, side, side, side * side, &o);
            let fps = 1e3 / Gpu2004::sort_ms(v, side, passes);
            m += &format!(
                "| {} | {side}² | {passes} | {fps:.1} | {paper:.1} | {:.2} |\n",
                v.name(),
                paper / fps
            );
        }
    }
    m
}
