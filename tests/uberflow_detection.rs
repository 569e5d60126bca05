//! UberFlow's detection (§4.4) against a CPU twin on the layouts it read: each live particle's
//! closest live neighbour closer than 2r among the k to each side in its row (nearest first,
//! left before right), then the mutual check, on both lattices, for several k.

mod common;

use common::scene::{collide_scene, random_gas};
use common::{context, no_gl_error};
use texflow::sim::{particle_live, ParticleSim};

/// (partner or -1, distance) of every texel of a layout `width` texels wide.
fn twin(pos: &[f32], width: usize, k: usize, reach: f32) -> Vec<(f32, f32)> {
    let at = |i: usize| glam::Vec4::from_slice(&pos[4 * i..4 * i + 4]);
    (0..pos.len() / 4)
        .map(|i| {
            let (mut partner, mut best) = (-1.0, reach);
            if !particle_live(at(i).to_array()) {
                return (partner, best);
            }
            let (row, x) = (i / width, (i % width) as i64);
            for m in 1..=k as i64 {
                for xx in [x - m, x + m] {
                    if xx < 0 || xx >= width as i64 {
                        continue;
                    }
                    let j = row * width + xx as usize;
                    let d = at(i).truncate().distance(at(j).truncate());
                    if particle_live(at(j).to_array()) && d < best {
                        (partner, best) = (j as f32, d);
                    }
                }
            }
            (partner, best)
        })
        .collect()
}

#[test]
fn detection_matches_its_twin_on_both_lattices() {
    let ctx = context();
    let (radius, width) = (0.03f32, 32usize);
    for (k, seed) in [(1usize, 5u32), (3, 6), (8, 7)] {
        let s = collide_scene(
            [width as u32, 32],
            &format!(
                "[collisions]\nradius = {radius}\nneighbours = {k}\nstaggered = true\n\
                 bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        common::set_particles(&mut sim, &random_gas(900, seed, 0.0, 0.6), |_, _| 0.5);
        sim.run(texflow::sim::Stage::Collide).unwrap();
        let c = sim.collisions().unwrap();
        let mut found = 0;
        for staggered in [false, true] {
            let r = c.read_back(staggered).unwrap().unwrap();
            let want = twin(&r.positions, width, k, 2.0 * radius);
            let raw = |i: usize| r.partners[4 * i + 3];
            for (i, &(partner, best)) in want.iter().enumerate() {
                let what = format!("k {k}, staggered {staggered}, texel {i}");
                // A tie between two neighbours may round either way on the GPU: then both lie
                // at the distance the GPU found.
                if raw(i) != partner {
                    let j = raw(i) as usize;
                    let d = |j: usize| {
                        let p = |i: usize| glam::Vec3::from_slice(&r.positions[4 * i..4 * i + 3]);
                        p(i).distance(p(j))
                    };
                    assert!(
                        raw(i) >= 0.0 && (d(j) - best).abs() < 1e-6,
                        "{what}: GPU {}, twin {partner}",
                        raw(i)
                    );
                    continue;
                }
                if partner >= 0.0 {
                    assert!((r.partners[4 * i + 1] - best).abs() < 1e-6, "{what}");
                }
                // Mutual: kept only if the partner chose this particle too.
                let mutual = partner >= 0.0 && raw(partner as usize) == i as f32;
                let kept = if mutual { partner } else { -1.0 };
                assert_eq!(r.partners[4 * i], kept, "{what}");
                assert_eq!(r.partners[4 * i + 2], mutual as u32 as f32, "{what}");
                found += mutual as usize;
            }
        }
        assert!(found > 100, "k {k}: {found} mutual partners");
    }
    no_gl_error(&ctx);
}

/// Exact ties, on rows of 2 to 32 particles (rows end inside the detection's window): particles
/// 2^-7 apart along x in one cell, so that left and right neighbours lie at the same distance,
/// and the paper's order (nearest first, left before right) decides; with `gaps`, every third
/// particle is lifted out of reach, so that the second to the left ties with the first to the
/// right, which must win. The twin's partner must be taken exactly.
#[test]
fn detection_breaks_ties_in_the_papers_order() {
    let ctx = context();
    let shapes = [(2usize, 16usize, 1usize), (4, 8, 2), (32, 4, 1), (32, 4, 5)];
    for ((w, h, k), gaps) in shapes.into_iter().flat_map(|s| [(s, false), (s, true)]) {
        let s = collide_scene(
            [w as u32, h as u32],
            &format!(
                "[collisions]\nradius = 0.03\nneighbours = {k}\ncell = 1.0\n\
                 bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        let lifted = |col: usize| gaps && col % 3 == 2;
        // The last row's last particle stays dead: rows may end in dead texels.
        let gas: Vec<_> = (0..w * h - 1)
            .map(|i| {
                let (row, col) = (i / w, i % w);
                let step = (0..col).filter(|&c| !lifted(c)).count();
                let x = 0.25 + step as f32 / 128.0;
                let y = 0.125 + 0.75 * row as f32 / h as f32 + if lifted(col) { 0.1 } else { 0.0 };
                ([x, y, 0.5], [0.0; 3])
            })
            .collect();
        common::set_particles(&mut sim, &gas, |_, _| 0.5);
        sim.run(texflow::sim::Stage::Collide).unwrap();
        let r = sim.collisions().unwrap().read_back(false).unwrap().unwrap();
        let want = twin(&r.positions, w, k, 0.06);
        let mut right = 0;
        for (i, &(partner, _)) in want.iter().enumerate() {
            let what = format!("{w}x{h}, k {k}, gaps {gaps}, texel {i}");
            assert_eq!(r.partners[4 * i + 3], partner, "{what}");
            right += (partner > i as f32) as usize;
        }
        // Ties decided: to the left without gaps, to the right past each gap.
        let rows_firsts = h;
        match gaps && w >= 8 && k >= 2 {
            true => assert!(
                right >= rows_firsts + w / 3,
                "{w}x{h} k {k}: {right} to the right"
            ),
            false if !gaps => assert!(right <= rows_firsts, "{w}x{h} k {k}: {right} to the right"),
            false => {}
        }
    }
    no_gl_error(&ctx);
}

/// The detection declares its fetches to the cost model: its own position and each neighbour
/// inside the row, k each side at most, per particle and lattice. Between k = 8 and k = 1 on
/// the same particles (the same sorts and gathers) the declared fetches differ by exactly the
/// extra neighbours, counted here column by column.
#[test]
fn detection_declares_the_neighbours_it_fetches() {
    let ctx = context();
    let (w, rows) = (32u32, 16u32);
    for staggered in [false, true] {
        let fetches = |k: u32| {
            let s = collide_scene(
                [w, rows],
                &format!(
                    "[collisions]\nradius = 0.03\nneighbours = {k}\nstaggered = {staggered}\n\
                     bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
                ),
            );
            let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
            common::set_particles(&mut sim, &random_gas(300, 9, 0.0, 0.6), |_, _| 0.5);
            ctx.take_draw_stats();
            sim.run(texflow::sim::Stage::Collide).unwrap();
            ctx.take_draw_stats().fetches
        };
        let reach = |k: u32| -> u64 {
            (0..w)
                .map(|x| (x.min(k) + (w - 1 - x).min(k)) as u64)
                .sum::<u64>()
                * rows as u64
        };
        let lattices = if staggered { 2 } else { 1 };
        assert_eq!(
            fetches(8) - fetches(1),
            lattices * (reach(8) - reach(1)),
            "staggered {staggered}"
        );
    }
    no_gl_error(&ctx);
}
