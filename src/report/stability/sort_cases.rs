//! The sort's extreme cases: identifiers beyond the float mantissa (fp32 and the R300's 24-bit
//! floats) and 10^5 particles sorted into one cell.

use std::time::Instant;

use glam::{UVec3, Vec3};

use super::{case, ExtremeCase, Outcome};
use crate::error::{Error, Result};
use crate::gl::{Context, Texture, TextureDesc, TextureFormat};
use crate::sort::precision::{FloatFormat, R300};
use crate::sort::{KeyMode, SortOptions, Sorter, Variant};

/// Identifiers beyond 2^24 in fp32: integers above 2^24 are not all floats.
pub(super) fn ids_fp32() -> ExtremeCase {
    let f32_format = FloatFormat {
        mantissa_bits: 23,
        exponent_bits: 8,
    };
    let limit = f32_format.max_exact_integer();
    let ids: Vec<u64> = (limit - 16..limit + 16).collect();
    let colliding: Vec<u64> = ids
        .iter()
        .copied()
        .filter(|&i| (i as f32) as u64 != i)
        .collect();
    case(
        "ids beyond 2^24 (fp32)",
        "particle ids 2^24 - 16 … 2^24 + 15 as f32 (the key pass writes float(i))",
        Outcome::IdsCollide,
        if colliding.is_empty() {
            Outcome::IdsDistinct
        } else {
            Outcome::IdsCollide
        },
        format!(
            "{} of the 16 ids above 2^24 = {limit} round onto a neighbour (2^24 + 1 → 2^24): \
             checked on the CPU, a 2^25-particle state needs over 1 GiB of textures; `texflow \
             sort` refuses more than 2^24 keys (exit 2)",
            colliding.len()
        ),
        colliding,
    )
}

fn state_texture(ctx: &Context, w: u32, h: u32, data: &[f32]) -> Result<Texture> {
    let t = Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format: TextureFormat::Rgba32F,
            label: "stability positions",
        },
    )?;
    t.upload_f32(data)?;
    Ok(t)
}

/// Identifiers under emulated 24-bit floats: the key pass's plain ids of 2^18 particles, and the
/// paper's enumeration.
pub(super) fn ids_fp24(ctx: &Context) -> Result<[ExtremeCase; 2]> {
    let (w, h) = (512u32, 512u32);
    let n = (w * h) as usize;
    let positions = state_texture(ctx, w, h, &vec![1.0; n * 4])?;
    let mode = KeyMode::GridCell {
        origin: Vec3::ZERO,
        spacing: 1.0,
        dims: UVec3::splat(4),
    };
    let mut out = Vec::new();
    for table in [false, true] {
        let options = SortOptions {
            precision: Some(R300),
            id_table: table,
            ..SortOptions::default()
        };
        let mut sorter = Sorter::new(ctx, Variant::Fp, w, h, options)?;
        sorter.write_keys(&positions, n, &mode, false)?;
        let ids: Vec<f32> = sorter.read()?.iter().map(|e| e[1]).collect();
        let mut bits: Vec<u32> = ids.iter().map(|v| v.to_bits()).collect();
        bits.sort_unstable();
        bits.dedup();
        let distinct = bits.len();
        let colliding: Vec<u64> = if table {
            Vec::new()
        } else {
            (0..n as u64)
                .filter(|&i| ids[i as usize] as u64 != i)
                .collect()
        };
        out.push(if table {
            case(
                "ids 2^18 (fp24, paper's table)",
                "key pass of 512x512 particles, R300 floats, UberFlow's identifier enumeration",
                Outcome::IdsDistinct,
                if distinct == n {
                    Outcome::IdsDistinct
                } else {
                    Outcome::IdsCollide
                },
                format!("{distinct} distinct of {n}"),
                vec![],
            )
        } else {
            case(
                "ids beyond 2^17 (fp24)",
                "key pass of 512x512 particles, R300 floats (16 stored mantissa bits), plain ids",
                Outcome::IdsCollide,
                if distinct < n {
                    Outcome::IdsCollide
                } else {
                    Outcome::IdsDistinct
                },
                format!(
                    "{distinct} distinct of {n}; first wrong id {} (exact up to 2^17 = 131072: 16 \
                     stored bits and the hidden one; docs/sorting.md)",
                    colliding.first().map_or("-".into(), |i| i.to_string())
                ),
                colliding,
            )
        });
    }
    ctx.check_error("identifier experiment")?;
    let [a, b]: [ExtremeCase; 2] = out
        .try_into()
        .map_err(|_| Error::Gl("two identifier cases".into()))?;
    Ok([a, b])
}

/// `count` particles at one point sorted by grid cell (UberFlow's collision sort, packed
/// bitonic): every key that cell's, no NaN, the ids a permutation, in bounded time.
pub(super) fn one_cell(ctx: &Context, count: usize) -> Result<ExtremeCase> {
    let n = count.next_power_of_two().max(4);
    let w = ((n as f64).sqrt() as u32).next_power_of_two().max(2);
    let h = (n as u32 / w).max(1);
    let mut data = vec![0f32; (w * h) as usize * 4];
    for p in data.chunks_exact_mut(4) {
        p.copy_from_slice(&[1.5, 1.5, 1.5, 1.0]);
    }
    let positions = state_texture(ctx, w, h, &data)?;
    let mode = KeyMode::GridCell {
        origin: Vec3::ZERO,
        spacing: 1.0,
        dims: UVec3::splat(4),
    };
    let t0 = Instant::now();
    let mut sorter = Sorter::new(ctx, Variant::Packed, w, h, SortOptions::default())?;
    sorter.write_keys(&positions, count, &mode, true)?;
    sorter.sort();
    let entries = sorter.read()?;
    let seconds = t0.elapsed().as_secs_f64();
    let cell = ((4 + 1) * 4 + 1) as f32;
    let mut seen = vec![0u32; count];
    let mut bad_keys = 0u64;
    let mut wrong: Vec<u64> = Vec::new();
    for (j, e) in entries[..count].iter().enumerate() {
        if e[0] != cell {
            bad_keys += 1;
            wrong.push(j as u64);
        }
        match seen.get_mut(e[1] as usize) {
            Some(s) if e[1] >= 0.0 && e[1].fract() == 0.0 => *s += 1,
            _ => wrong.push(j as u64),
        }
    }
    let lost: Vec<u64> = (0..count as u64)
        .filter(|&i| seen[i as usize] != 1)
        .collect();
    let padding_ok = entries[count..].iter().all(|e| e[0].is_nan());
    let ascending = entries[..count].windows(2).all(|p| p[0][1] < p[1][1]);
    wrong.extend(&lost);
    wrong.sort_unstable();
    wrong.dedup();
    let measured = if wrong.is_empty() && padding_ok {
        Outcome::Finite
    } else {
        Outcome::Corrupted
    };
    Ok(case(
        "1e5 particles in one cell",
        format!(
            "{count} particles at one point, grid-cell keys, packed bitonic sort of {w}x{h} entries"
        ),
        Outcome::Finite,
        measured,
        format!(
            "keys all {cell} (the cell) except {bad_keys}; ids a permutation: {} lost or \
             duplicated; ties in id order: {ascending}; padding after them: {padding_ok}; {} \
             passes in {seconds:.2} s",
            lost.len(),
            sorter.pass_count()
        ),
        wrong,
    ))
}
