//! A draw's inputs are data: [`Draw`] lists its textures by sampler name and its uniforms, and
//! `Context::draw` gives the textures units in order on every draw. Checked on a real driver:
//! a program whose sampler the draw leaves out is refused, and draws with other lists read their
//! own textures and uniforms, never what the draw before left bound. The draws it counts tell
//! a follow-on draw and a concurrent one from a pass.

mod common;

use common::{context, no_gl_error};
use texflow::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, Sampled, Texture, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};

/// Reads `u_a` and `u_b` at the fragment's texel and writes `a + 10 b + u_k`.
const TWO: &str = "uniform sampler2D u_a; uniform sampler2D u_b; uniform float u_k;
    layout(location = 0) out vec4 o;
    void main() {
        ivec2 t = ivec2(gl_FragCoord.xy);
        o = texelFetch(u_a, t, 0) + 10.0 * texelFetch(u_b, t, 0) + vec4(u_k);
    }";

/// Reads `u_x` alone.
const ONE: &str = "uniform sampler2D u_x;
    layout(location = 0) out vec4 o;
    void main() { o = texelFetch(u_x, ivec2(gl_FragCoord.xy), 0); }";

const SIZE: u32 = 4;

/// A 4×4 RGBA32F texture holding `v` in every channel.
fn filled(ctx: &Context, v: f32) -> Texture {
    let t = Texture::new(
        ctx,
        TextureDesc {
            width: SIZE,
            height: SIZE,
            format: TextureFormat::Rgba32F,
            label: "input",
        },
    )
    .unwrap();
    t.upload_f32(&[v; 4 * (SIZE * SIZE) as usize]).unwrap();
    t
}

fn target(ctx: &Context) -> Framebuffer {
    Framebuffer::new(ctx, "out", vec![filled(ctx, 0.0)]).unwrap()
}

fn program(ctx: &Context, name: &str, source: &str) -> Program {
    Program::with_fragment_source(ctx, FULLSCREEN_VERTEX, name, source, &Defines::new()).unwrap()
}

/// Every texel of `fb`'s texture, which must all be `v`.
fn assert_all(fb: &Framebuffer, v: f32, what: &str) {
    let got = fb.only_texture().read_f32().unwrap();
    assert!(got.iter().all(|&x| x == v), "{what}: want {v}, got {got:?}");
}

#[test]
#[should_panic(expected = "reads sampler(s) [\"u_b\"] that this draw binds no texture to")]
fn a_draw_without_an_active_sampler_is_refused() {
    let ctx = context();
    let p = program(&ctx, "two.frag", TWO);
    let a = filled(&ctx, 1.0);
    let fb = target(&ctx);
    // u_b would read whatever an earlier draw left on its unit: refused.
    FullscreenPass::new(&ctx)
        .unwrap()
        .draw(&p, &[("u_a", (&a).into())], &[], &fb);
}

#[test]
fn draws_with_other_texture_lists_read_their_own_textures() {
    let ctx = context();
    let pass = FullscreenPass::new(&ctx).unwrap();
    let (a, b, c) = (filled(&ctx, 1.0), filled(&ctx, 2.0), filled(&ctx, 3.0));
    let one = program(&ctx, "one.frag", ONE);
    let two = program(&ctx, "two.frag", TWO);
    let k = |v: f32| [("u_k", Uniform::F32(v))];
    let (fa, fb, fc, fd) = (target(&ctx), target(&ctx), target(&ctx), target(&ctx));
    // The same program, another texture: each draw reads its own.
    pass.draw(&one, &[("u_x", (&a).into())], &[], &fa);
    pass.draw(&one, &[("u_x", (&b).into())], &[], &fb);
    assert_all(&fa, 1.0, "u_x = a");
    assert_all(&fb, 2.0, "u_x = b");
    // Listed out of declaration order, then swapped, with another uniform each time: the
    // units follow the list, not the names or the draw before.
    let list: [(&str, Sampled); 2] = [("u_b", (&c).into()), ("u_a", (&a).into())];
    pass.draw(&two, &list, &k(0.5), &fc);
    pass.draw(
        &two,
        &[("u_a", (&b).into()), ("u_b", (&a).into())],
        &k(0.25),
        &fd,
    );
    assert_all(&fc, 1.0 + 10.0 * 3.0 + 0.5, "a + 10 c + 0.5");
    assert_all(&fd, 2.0 + 10.0 * 1.0 + 0.25, "b + 10 a + 0.25");
    // Back to the one-sampler program after the two-sampler one left c and a on units 0 and 1.
    pass.draw(&one, &[("u_x", (&c).into())], &[], &fa);
    assert_all(&fa, 3.0, "u_x = c");
    no_gl_error(&ctx);
}

/// Writes `u_v[0] + 10 u_v[1]`.
const ARRAY: &str = "uniform vec4 u_v[2];
    layout(location = 0) out vec4 o;
    void main() { o = u_v[0] + 10.0 * u_v[1]; }";

#[test]
fn uniform_arrays_travel_in_the_draw() {
    let ctx = context();
    let pass = FullscreenPass::new(&ctx).unwrap();
    let p = program(&ctx, "array.frag", ARRAY);
    let (fa, fb) = (target(&ctx), target(&ctx));
    let v = |a: f32, b: f32| {
        [(
            "u_v",
            Uniform::Vec4s(vec![glam::Vec4::splat(a), glam::Vec4::splat(b)].into()),
        )]
    };
    pass.draw(&p, &[], &v(1.0, 2.0), &fa);
    pass.draw(&p, &[], &v(3.0, 0.5), &fb);
    assert_all(&fa, 21.0, "1 + 10 * 2");
    assert_all(&fb, 8.0, "3 + 10 * 0.5");
    no_gl_error(&ctx);
}

/// The uniform cache (a draw uploads only the values its program does not hold already)
/// changes no result: the state after a few frames and the picture are bit for bit the same with
/// it off, for scenes with orbiting spheres and relaxation, DEM neighbours, the fluid, lit
/// slices, animated emitters, collisions, the fire and a sorted render; and it does save uploads.
#[test]
fn the_uniform_cache_changes_no_result() {
    use texflow::engine::{self, EngineKind};
    let ctx = context();
    for name in [
        "hair", "dem", "dam", "smoke", "flicker", "gas", "fire", "e3",
    ] {
        let mut s = texflow::scene::builtin(name).unwrap();
        s.render.resolution = [32, 24];
        let run = |cache: bool| {
            ctx.set_uniform_cache(cache);
            let mut e = engine::build(&ctx, &s, 5, EngineKind::Gpu).unwrap();
            ctx.take_draw_stats();
            for _ in 0..3 {
                e.advance_frame().unwrap();
            }
            let uploads = ctx.take_draw_stats().uniform_uploads;
            let d = e.dump().unwrap();
            let picture = e.render().unwrap().into_raw();
            (uploads, (d.positions, d.velocities, picture))
        };
        let ((cached_uploads, cached), (all_uploads, all)) = (run(true), run(false));
        ctx.set_uniform_cache(true);
        assert!(!cached.0.is_empty(), "{name}: no live particle to compare");
        assert!(cached == all, "{name}: the cache changed a result");
        assert!(
            cached_uploads < all_uploads,
            "{name}: {cached_uploads} uploads with the cache, {all_uploads} without"
        );
    }
    no_gl_error(&ctx);
}

/// The GL layer counts a draw into the framebuffer that the draw before it drew into as a
/// follow-on, a draw that reads nothing an earlier draw wrote and writes nothing an earlier one
/// read as concurrent (the cost model charges both less than a pass), and no draw after the
/// counts were taken as either: A A B B B A, none reading, gives 3 follow-ons and 2 concurrent;
/// a ping-pong chain, each draw reading what the one before wrote, gives neither; a draw that
/// overwrites what an earlier one read waits on it.
#[test]
fn follow_on_and_concurrent_draws_are_counted_by_what_they_touch() {
    let ctx = context();
    let pass = FullscreenPass::new(&ctx).unwrap();
    let p = program(&ctx, "array.frag", ARRAY);
    let (fa, fb) = (target(&ctx), target(&ctx));
    let v = [(
        "u_v",
        Uniform::Vec4s(vec![glam::Vec4::ONE, glam::Vec4::ZERO].into()),
    )];
    pass.draw(&p, &[], &v, &fa);
    ctx.take_draw_stats();
    for fb in [&fa, &fa, &fb, &fb, &fb, &fa] {
        pass.draw(&p, &[], &v, fb);
    }
    let s = ctx.take_draw_stats();
    assert_eq!((s.draws, s.follow_ons, s.concurrent), (6, 3, 2), "{s:?}");
    assert_eq!(s.chained(), 1, "{s:?}");
    // A chain: each draw reads the target the one before wrote.
    let one = program(&ctx, "one.frag", ONE);
    for k in 0..6 {
        let (from, to) = ([&fa, &fb][k % 2], [&fb, &fa][k % 2]);
        pass.draw(&one, &[("u_x", from.only_texture().into())], &[], to);
    }
    let s = ctx.take_draw_stats();
    assert_eq!((s.draws, s.follow_ons, s.concurrent), (6, 0, 0), "{s:?}");
    // Reading a texture none of them wrote, into A and B in turn: all but the first concurrent;
    // then a draw into the texture they read waits on them.
    let c = target(&ctx);
    for k in 0..4 {
        pass.draw(
            &one,
            &[("u_x", c.only_texture().into())],
            &[],
            [&fa, &fb][k % 2],
        );
    }
    pass.draw(&p, &[], &v, &c);
    let s = ctx.take_draw_stats();
    assert_eq!((s.draws, s.follow_ons, s.concurrent), (5, 0, 3), "{s:?}");
    no_gl_error(&ctx);
}
