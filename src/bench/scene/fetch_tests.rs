//! The fetch floor's tests: what its passes fetch, against the CPU.

use super::*;
use crate::gl::{Clock, Rect};

/// What the floor's inputs hold: value `i` of the flat data (see [`FetchFloor::input`]).
fn value(i: usize) -> f32 {
    (i as f32 * 0.618_034).fract()
}

/// The texel `(x, y, z)` of a float input of `size`, as `texelFetch` returns it (missing
/// channels 0, alpha 1).
fn texel(r: &ReadShape, [x, y, z]: [u32; 3]) -> [f32; 4] {
    let c = r.format.channels();
    let at = ((z * r.size[1] + y) * r.size[0] + x) as usize * c;
    let mut out = [0.0, 0.0, 0.0, 1.0];
    for (k, o) in out.iter_mut().enumerate().take(c) {
        *o = value(at + k);
    }
    out
}

/// Every target of `shape`'s floor holds, at each texel of its viewport, the sum of one
/// fetch of each read at the texel clamped to the read's size.
fn check_sums(floor: &FetchFloor, shape: &DrawShape) {
    let targets = floor.targets.borrow();
    let fb = &targets[&(shape.size, shape.formats.clone())];
    for t in fb.textures() {
        let got = t.read_f32().unwrap();
        for y in 1..4u32 {
            for x in 0..8u32 {
                let mut want = [0.0f32; 4];
                for r in &shape.reads {
                    let p = [x.min(r.size[0] - 1), y.min(r.size[1] - 1), 0];
                    // Both reads of `small` hold the same values (the same pattern).
                    for (w, v) in want.iter_mut().zip(texel(r, p)) {
                        *w += v;
                    }
                }
                let at = (y * 8 + x) as usize * 4;
                for k in 0..4 {
                    assert!(
                        (got[at + k] - want[k]).abs() < 1e-5,
                        "texel ({x}, {y}) channel {k}: {} against {}",
                        got[at + k],
                        want[k]
                    );
                }
            }
        }
    }
}

/// The floor's pass fetches, for every target, one texel of each bound texture at the
/// fragment's texel clamped to the texture (a 3D one at the draw's layer, 0): revealed, it
/// writes their sum, against the same sum on the CPU; as timed, zeros.
#[test]
fn the_fetch_floor_writes_the_sum_of_one_fetch_of_each_texture() {
    let ctx = Context::new(0).unwrap();
    let d2 = |w, h, format| ReadShape {
        size: [w, h, 1],
        three_d: false,
        format,
    };
    let small = d2(5, 3, TextureFormat::Rgba32F);
    let volume = ReadShape {
        size: [2, 2, 2],
        three_d: true,
        format: TextureFormat::Rgba32F,
    };
    let reads = vec![small, d2(8, 4, TextureFormat::R32F), volume, small];
    let shape = DrawShape {
        program: "test".into(),
        size: [8, 4],
        formats: vec![TextureFormat::Rgba32F; 2],
        viewport: Some(Rect {
            x: 0,
            y: 1,
            width: 8,
            height: 3,
        }),
        primitive: Primitive::Triangles,
        count: 3,
        reads: reads.clone(),
        sources: Vec::new(),
        samplers: Vec::new(),
        defines: Vec::new(),
        ints: Vec::new(),
        floats: Vec::new(),
    };
    let floor = FetchFloor::new(&ctx).unwrap();
    let timer = PassTimer::new(&ctx, Clock::Wall).unwrap();
    floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
    let zeros = |floor: &FetchFloor| {
        let targets = floor.targets.borrow();
        let fb = &targets[&(shape.size, shape.formats.clone())];
        fb.textures()
            .iter()
            .all(|t| t.read_f32().unwrap().iter().all(|&v| v == 0.0))
    };
    assert!(zeros(&floor), "the timed floor writes zeros");
    floor.reveal.set(true);
    let (_, drawn) = floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
    assert_eq!((drawn.stats.draws, drawn.stats.passes), (1, 1));
    assert_eq!(drawn.stats.bytes_written, 8 * 3 * 32);
    check_sums(&floor, &shape);
    // Draws of points have no fetch floor: nothing drawn, nothing timed.
    let points = DrawShape {
        primitive: Primitive::Points,
        ..shape
    };
    let (ms, drawn) = floor.measure(&timer, &[points]).unwrap();
    assert_eq!((ms, drawn.stats.draws), (0.0, 0));
    ctx.check_error("the fetch floor").unwrap();
}

/// What `shape`'s floor writes into its one target when revealed (the sums of its fetches).
fn revealed(ctx: &Context, shape: &DrawShape) -> Vec<f32> {
    let floor = FetchFloor::new(ctx).unwrap();
    floor.reveal.set(true);
    let timer = PassTimer::new(ctx, Clock::Wall).unwrap();
    floor.measure(&timer, std::slice::from_ref(shape)).unwrap();
    let targets = floor.targets.borrow();
    let fb = &targets[&(shape.size, shape.formats.clone())];
    fb.only_texture().read_f32().unwrap()
}

/// A tally's level (a block reduction) is floored by a pass that fetches the whole 4×4
/// block of each fragment, clamped to the texture: revealed, its sums against the CPU's.
#[test]
fn a_block_reduction_is_floored_by_its_blocks() {
    let ctx = Context::new(0).unwrap();
    let read = ReadShape {
        size: [14, 7, 1],
        three_d: false,
        format: TextureFormat::Rgba32F,
    };
    let shape = DrawShape {
        program: "collide/tally.frag".into(),
        size: [4, 2],
        formats: vec![TextureFormat::R32F],
        viewport: None,
        primitive: Primitive::Triangles,
        count: 3,
        reads: vec![read],
        sources: Vec::new(),
        samplers: Vec::new(),
        defines: vec![("TALLY_BLOCK".into(), "4".into())],
        ints: Vec::new(),
        floats: Vec::new(),
    };
    let got = revealed(&ctx, &shape);
    for (y, x) in (0..2u32).flat_map(|y| (0..4u32).map(move |x| (y, x))) {
        let mut want = 0.0f32;
        for (j, i) in (0..4u32).flat_map(|j| (0..4u32).map(move |i| (j, i))) {
            let p = [(x * 4 + i).min(13), (y * 4 + j).min(6), 0];
            // An R32F target keeps the sum's first channel.
            want += texel(&read, p)[0];
        }
        let g = got[(y * 4 + x) as usize];
        assert!(
            (g - want).abs() < 1e-4,
            "block ({x}, {y}): {g} against {want}"
        );
    }
}

/// A recorded draw's own texture is read while it lives (the same data), and once freed
/// one of its shape is read instead.
/// An RGBA32F texture of `[w, h]` holding `data`.
fn rgba(ctx: &Context, label: &str, [width, height]: [u32; 2], data: &[f32]) -> Texture {
    let desc = TextureDesc {
        width,
        height,
        format: TextureFormat::Rgba32F,
        label,
    };
    let t = Texture::new(ctx, desc).unwrap();
    t.upload_f32(data).unwrap();
    t
}

/// A full-screen draw into one RGBA32F target of `size` that read `textures` through the
/// samplers named beside them, as the recorder notes it.
fn reading(size: [u32; 2], textures: &[(&str, &Texture)]) -> DrawShape {
    DrawShape {
        program: "test".into(),
        size,
        formats: vec![TextureFormat::Rgba32F],
        viewport: None,
        primitive: Primitive::Triangles,
        count: 3,
        reads: textures.iter().map(|(_, t)| t.recorded().shape).collect(),
        sources: textures.iter().map(|(_, t)| t.recorded()).collect(),
        samplers: textures.iter().map(|(n, _)| n.to_string()).collect(),
        defines: Vec::new(),
        ints: Vec::new(),
        floats: Vec::new(),
    }
}

#[test]
fn the_fetch_floor_reads_the_draws_own_texture_while_it_lives() {
    let ctx = Context::new(0).unwrap();
    let data: Vec<f32> = (0..32).map(|i| 100.0 + i as f32).collect();
    let own = rgba(&ctx, "own", [4, 2], &data);
    let shape = reading([4, 2], &[("u_own", &own)]);
    let floor = FetchFloor::new(&ctx).unwrap();
    floor.reveal.set(true);
    let timer = PassTimer::new(&ctx, Clock::Wall).unwrap();
    let written = |floor: &FetchFloor| {
        floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
        let targets = floor.targets.borrow();
        targets[&(shape.size, shape.formats.clone())]
            .only_texture()
            .read_f32()
            .unwrap()
    };
    assert_eq!(written(&floor), data);
    drop(own);
    let other: Vec<f32> = (0..32).map(value).collect();
    assert_eq!(written(&floor), other);
    ctx.check_error("the fetch floor").unwrap();
}

/// A draw that walked the cells: its floor walks the same cells of the same sorted keys
/// and fetches each neighbour's position once. Four entries in cells 0, 0, 1 and one with
/// a +inf key in a lattice of 2 cells along x: entry 0 visits 1 and 2, entry 2 visits 0
/// and 1, the last nothing; revealed, each fragment's sum is its own position and its
/// neighbours'.
#[test]
fn the_walking_floor_visits_the_same_neighbours() {
    let ctx = Context::new(0).unwrap();
    // Per entry (key, id, 0, 0): keys 0, 0, 1, +inf.
    let inf = f32::INFINITY;
    let k = [
        0., 0., 0., 0., 0., 1., 0., 0., 1., 2., 0., 0., inf, 3., 0., 0.,
    ];
    let keys = rgba(&ctx, "keys", [4, 1], &k);
    let pos: Vec<f32> = (0..16).map(|i| (1u32 << (i / 4)) as f32).collect();
    let position = rgba(&ctx, "position", [4, 1], &pos);
    let shape = DrawShape {
        defines: vec![("EXACT_SCAN".into(), "8".into())],
        ints: vec![
            ("u_key_width".into(), vec![4]),
            ("u_count".into(), vec![4]),
            ("u_dims".into(), vec![2, 1, 1]),
        ],
        ..reading([4, 1], &[("u_keys", &keys), ("u_position", &position)])
    };
    let got = revealed(&ctx, &shape);
    // Positions 1, 2, 4, 8 (one value in every channel, live: w > 0), read once at the own
    // texel; the keys only by the walk. The dead entry (+inf key) walks nothing.
    let own = [1.0, 2.0, 4.0, 8.0];
    let walked = [2.0 + 4.0, 1.0 + 4.0, 1.0 + 2.0, 0.0];
    for e in 0..4 {
        assert_eq!(
            got[e * 4],
            own[e] + walked[e],
            "entry {e}: {:?}",
            &got[e * 4..e * 4 + 4]
        );
    }
    ctx.check_error("the walking floor").unwrap();
}
