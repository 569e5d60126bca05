//! The GL layer's contracts on a real driver: MRT with eight targets, distinct framebuffer
//! errors, shader errors that name the glsl/ file and line, draw state set in full on every draw,
//! the ring of three, and objects of two contexts on one thread kept apart.

mod common;

use common::{context, no_gl_error, test_shader};
use texflow::gl::{
    Attachment, Blend, BlendComponent, BlendFactor, Context, Defines, Depth, Draw, DrawState,
    Framebuffer, FullscreenPass, PingPong, PointSize, Primitive, Program, Ring3, Texture,
    TextureDesc, TextureFormat, VertexArray, FULLSCREEN_VERTEX,
};
use texflow::Error;

fn tex(ctx: &texflow::gl::Context, w: u32, h: u32, format: TextureFormat) -> Texture {
    Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format,
            label: "t",
        },
    )
    .unwrap()
}

#[test]
fn eight_render_targets_are_written_by_one_pass() {
    let ctx = context();
    let max = ctx.limits().max_draw_buffers.min(8) as usize;
    assert_eq!(max, 8, "this test needs 8 draw buffers");
    let (w, h) = (13, 5);
    let textures = (0..8)
        .map(|i| {
            tex(
                &ctx,
                w,
                h,
                if i % 2 == 0 {
                    TextureFormat::Rgba32F
                } else {
                    TextureFormat::Rgba16F
                },
            )
        })
        .collect();
    let fb = Framebuffer::new(&ctx, "eight", textures).unwrap();
    let program = Program::new(
        &ctx,
        FULLSCREEN_VERTEX,
        &test_shader("write8.frag"),
        &Defines::new(),
    )
    .unwrap();
    FullscreenPass::new(&ctx)
        .unwrap()
        .draw(&program, &[], &[], &fb);
    for (i, t) in fb.textures().iter().enumerate() {
        let v = t.read_f32().unwrap();
        assert!(
            v.iter().all(|&x| x == (i + 1) as f32),
            "target {i}: {:?}",
            &v[..4]
        );
    }
    no_gl_error(&ctx);
}

#[test]
fn framebuffer_misuse_gets_distinct_errors() {
    let ctx = context();
    // Nine attachments: over the limit.
    let nine = (0..9)
        .map(|_| tex(&ctx, 4, 4, TextureFormat::Rgba32F))
        .collect();
    let msg = Framebuffer::new(&ctx, "nine", nine)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("1 to 8 attachments"), "{msg}");
    // Attachments of different sizes.
    let mixed = vec![
        tex(&ctx, 4, 4, TextureFormat::Rgba32F),
        tex(&ctx, 4, 5, TextureFormat::Rgba32F),
    ];
    let msg = Framebuffer::new(&ctx, "mixed", mixed)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("differ in size"), "{msg}");
    // No attachment at all.
    assert!(Framebuffer::new(&ctx, "none", vec![]).is_err());
    // Zero-sized and oversized textures are refused before GL sees them.
    let max = ctx.limits().max_texture_size;
    for (w, h, needle) in [(0, 4, "empty"), (max + 1, 1, "GL_MAX_TEXTURE_SIZE")] {
        let msg = Texture::new(
            &ctx,
            TextureDesc {
                width: w,
                height: h,
                format: TextureFormat::Rgba32F,
                label: "big",
            },
        )
        .unwrap_err()
        .to_string();
        assert!(msg.contains(needle), "{msg}");
    }
    no_gl_error(&ctx);
}

/// The compile error of test shader `root`: at `file`:`line`, which its log names too; returns
/// the log.
fn compile_error_at(ctx: &texflow::gl::Context, root: &str, file: &str, line: u32) -> String {
    match Program::new(ctx, FULLSCREEN_VERTEX, &test_shader(root), &Defines::new()) {
        Err(Error::ShaderCompile {
            file: f,
            line: l,
            log,
        }) => {
            assert_eq!((f.as_str(), l), (file, line), "{log}");
            assert!(log.contains(&format!("{file}:{line}")), "{log}");
            log
        }
        other => panic!("expected a compile error, got {other:?}"),
    }
}

#[test]
fn shader_errors_name_the_glsl_file_and_line() {
    let ctx = context();
    compile_error_at(&ctx, "broken.frag", "tests/glsl/broken.frag", 7);
    // An error inside an included file names that file (Mesa reports such errors under source
    // number 0; the line numbers carry the file).
    test_shader("broken_helper.glsl");
    let log = compile_error_at(
        &ctx,
        "broken_include.frag",
        "tests/glsl/broken_helper.glsl",
        5,
    );
    assert!(!log.contains("broken_include.frag:5"), "{log}");
    match Program::new(
        &ctx,
        FULLSCREEN_VERTEX,
        "test/missing.frag",
        &Defines::new(),
    ) {
        Err(Error::MissingSource(p)) => assert_eq!(p, "test/missing.frag"),
        other => panic!("expected a missing source, got {other:?}"),
    }
    no_gl_error(&ctx);
}

#[test]
fn textures_round_trip_and_reject_wrong_lengths() {
    let ctx = context();
    let t = tex(&ctx, 3, 2, TextureFormat::Rgba32F);
    let data: Vec<f32> = (0..24).map(|i| i as f32 * 0.5 - 3.0).collect();
    t.upload_f32(&data).unwrap();
    assert_eq!(t.read_f32().unwrap(), data);
    assert!(t.upload_f32(&data[..20]).is_err());
    // RGBA16F keeps 11 significant bits: 1/3 rounds to the nearest half float.
    let h = tex(&ctx, 1, 1, TextureFormat::Rgba16F);
    h.upload_f32(&[1.0 / 3.0, 65504.0, -2.0, 0.0]).unwrap();
    let back = h.read_f32().unwrap();
    assert_eq!(back, vec![0.333_251_95, 65504.0, -2.0, 0.0]);
    no_gl_error(&ctx);
}

/// A 3×2 RGBA32F target, the program that writes 1.0 everywhere, and an empty vertex array.
fn write8_target(ctx: &Context) -> (Framebuffer, Program, VertexArray) {
    let fb = Framebuffer::new(ctx, "one", vec![tex(ctx, 3, 2, TextureFormat::Rgba32F)]).unwrap();
    let program = Program::new(
        ctx,
        FULLSCREEN_VERTEX,
        &test_shader("write8.frag"),
        &Defines::new(),
    )
    .unwrap();
    (fb, program, VertexArray::empty(ctx, "test").unwrap())
}

/// One triangle covering `fb`, drawn by `program` with `state`.
fn triangle(
    ctx: &Context,
    (fb, program, vao): (&Framebuffer, &Program, &VertexArray),
    state: &DrawState,
) {
    ctx.draw(&Draw {
        program,
        target: fb,
        viewport: None,
        vertices: vao,
        primitive: Primitive::Triangles,
        count: 3,
        state,
        textures: &[],
        uniforms: &[],
    });
}

/// A blended draw leaves nothing behind: the full-screen pass after it replaces the texels.
#[test]
fn every_draw_sets_its_own_blend_state() {
    let ctx = context();
    let (fb, program, vao) = write8_target(&ctx);
    let add = BlendComponent::add(BlendFactor::One, BlendFactor::One);
    fb.clear([0.5; 4]);
    let state = DrawState {
        blend: Some(Blend {
            color: add,
            alpha: add,
        }),
        point_size: PointSize::One,
        depth: Depth::Off,
        color_writes: true,
    };
    triangle(&ctx, (&fb, &program, &vao), &state);
    assert!(fb.texture(0).read_f32().unwrap().iter().all(|&v| v == 1.5));
    FullscreenPass::new(&ctx)
        .unwrap()
        .draw(&program, &[], &[], &fb);
    assert!(fb.texture(0).read_f32().unwrap().iter().all(|&v| v == 1.0));
    no_gl_error(&ctx);
}

/// A draw without colour writes (a benchmark's vertex floor) changes nothing, and leaves no
/// mask behind: the clear and the draw after it write as before.
#[test]
fn a_draw_without_colour_writes_changes_nothing_and_leaves_no_mask() {
    let ctx = context();
    let (fb, program, vao) = write8_target(&ctx);
    let draw = |color_writes| {
        let state = DrawState {
            color_writes,
            ..DrawState::REPLACE
        };
        triangle(&ctx, (&fb, &program, &vao), &state)
    };
    let all = |v: f32| fb.texture(0).read_f32().unwrap().iter().all(|&x| x == v);
    fb.clear([0.5; 4]);
    draw(false);
    assert!(all(0.5), "a draw without colour writes wrote");
    fb.clear([0.25; 4]);
    assert!(all(0.25), "the clear after it kept the mask");
    draw(true);
    assert!(all(1.0));
    no_gl_error(&ctx);
}

#[test]
fn ring_of_three_rotates_previous_current_next() {
    let ctx = context();
    let mut ring = Ring3::new(&ctx, "verlet", &["position"], &[TextureFormat::R32F], 2, 2).unwrap();
    let labels = |r: &Ring3| r.roles().map(|f| f.label().to_owned());
    assert_eq!(labels(&ring), ["verlet:0", "verlet:1", "verlet:2"]);
    ring.rotate();
    assert_eq!(labels(&ring), ["verlet:1", "verlet:2", "verlet:0"]);
    ring.rotate();
    assert_eq!(labels(&ring), ["verlet:2", "verlet:0", "verlet:1"]);
    ring.rotate();
    assert_eq!(labels(&ring), ["verlet:0", "verlet:1", "verlet:2"]);
    assert!(std::ptr::eq(ring.previous(), ring.roles()[0]));
    assert!(std::ptr::eq(ring.current(), ring.roles()[1]));
    assert!(std::ptr::eq(ring.next(), ring.roles()[2]));
    no_gl_error(&ctx);
}

#[test]
fn ring_of_three_swaps_current_and_next_keeping_the_previous() {
    // Constraint relaxation rewrites the current positions within a step; the previous ones
    // must stay for the next step's implied velocity.
    let ctx = context();
    let mut ring = Ring3::new(&ctx, "verlet", &["position"], &[TextureFormat::R32F], 2, 2).unwrap();
    let labels = |r: &Ring3| r.roles().map(|f| f.label().to_owned());
    ring.rotate();
    ring.swap_current_next();
    assert_eq!(labels(&ring), ["verlet:1", "verlet:0", "verlet:2"]);
    ring.swap_current_next();
    assert_eq!(labels(&ring), ["verlet:1", "verlet:2", "verlet:0"]);
    ring.swap_current_next();
    ring.rotate();
    assert_eq!(labels(&ring), ["verlet:0", "verlet:2", "verlet:1"]);
    no_gl_error(&ctx);
}

/// Two contexts on one thread: EGL has one current context per thread, and GL names are per
/// context (both contexts hand out the same names here), so using or dropping an object must
/// make its own context current first, or it would read or delete the other context's object.
#[test]
fn objects_of_two_contexts_on_one_thread_stay_apart() {
    let a = context();
    let ta = tex(&a, 1, 1, TextureFormat::Rgba32F);
    ta.upload_f32(&[1.0, 2.0, 3.0, 4.0]).unwrap();
    let b = Context::new(0).unwrap();
    assert!(b.is_current() && !a.is_current());
    let tb = tex(&b, 1, 1, TextureFormat::Rgba32F);
    tb.upload_f32(&[5.0, 6.0, 7.0, 8.0]).unwrap();
    assert_eq!(ta.read_f32().unwrap(), [1.0, 2.0, 3.0, 4.0]);
    assert!(a.is_current());
    assert_eq!(tb.read_f32().unwrap(), [5.0, 6.0, 7.0, 8.0]);
    assert!(b.is_current());
    // Dropped while b is current: deleted in a, so b's texture of the same name survives.
    drop(ta);
    assert!(a.is_current());
    assert_eq!(tb.read_f32().unwrap(), [5.0, 6.0, 7.0, 8.0]);
    no_gl_error(&b);
    no_gl_error(&a);
}

const POSITION: Attachment = Attachment::named("position");
const VELOCITY: Attachment = Attachment::named("velocity");
const SPIN: Attachment = Attachment::named("spin");

/// A pass of `write8.frag` (output k writes k + 1) into `fb`.
fn write8(ctx: &Context, fb: &Framebuffer) {
    let program = Program::new(
        ctx,
        FULLSCREEN_VERTEX,
        &test_shader("write8.frag"),
        &Defines::new(),
    )
    .unwrap();
    FullscreenPass::new(ctx)
        .unwrap()
        .draw(&program, &[], &[], fb);
}

fn all(t: &Texture, v: f32) -> bool {
    t.read_f32().unwrap().iter().all(|&x| x == v)
}

/// Attachment k is the shader's output k whatever it is called, and a handle reaches the
/// texture of its name in either order.
#[test]
fn attachments_are_reached_by_name_in_any_order() {
    let ctx = context();
    let f = [TextureFormat::Rgba32F; 2];
    let ab = PingPong::new(&ctx, "ab", &[POSITION, VELOCITY], &f, 3, 2).unwrap();
    let ba = PingPong::new(&ctx, "ba", &[VELOCITY, POSITION], &f, 3, 2).unwrap();
    for pp in [&ab, &ba] {
        write8(&ctx, pp.back());
    }
    assert!(all(ab.back().texture(POSITION), 1.0) && all(ab.back().texture(VELOCITY), 2.0));
    assert!(all(ba.back().texture(VELOCITY), 1.0) && all(ba.back().texture(POSITION), 2.0));
    assert_eq!(ba.front().names(), [Some(VELOCITY), Some(POSITION)]);
    let one = Framebuffer::named(
        &ctx,
        "one",
        vec![(SPIN, tex(&ctx, 3, 2, TextureFormat::Rgba32F))],
    )
    .unwrap();
    write8(&ctx, &one);
    assert!(std::ptr::eq(one.texture(SPIN), one.only_texture()));
    assert!(all(one.only_texture(), 1.0));
    no_gl_error(&ctx);
}

/// A single-target view of one attachment writes that texture and no other.
#[test]
fn single_targets_are_picked_by_name() {
    let ctx = context();
    let f = [TextureFormat::Rgba32F; 2];
    let pp = PingPong::new(&ctx, "s", &[POSITION, VELOCITY], &f, 2, 2)
        .unwrap()
        .with_single_targets(&ctx)
        .unwrap();
    pp.back().clear([0.0; 4]);
    write8(&ctx, pp.back_single(VELOCITY));
    assert_eq!(pp.back_single(VELOCITY).names(), [Some(VELOCITY)]);
    assert!(all(pp.back().texture(VELOCITY), 1.0) && all(pp.back().texture(POSITION), 0.0));
    no_gl_error(&ctx);
}

#[test]
fn two_attachments_of_one_name_are_refused() {
    let ctx = context();
    let t = || tex(&ctx, 2, 2, TextureFormat::Rgba32F);
    let e = Framebuffer::named(&ctx, "twice", vec![(POSITION, t()), (POSITION, t())])
        .unwrap_err()
        .to_string();
    assert!(e.contains("twice") && e.contains("`position`"), "{e}");
    no_gl_error(&ctx);
}

/// A handle of another kind of state fails loudly instead of reading what sits at its index.
#[test]
#[should_panic(expected = "has no attachment `spin` (its attachments: position, velocity)")]
fn a_handle_the_framebuffer_lacks_panics() {
    let ctx = context();
    let f = [TextureFormat::Rgba32F; 2];
    let pp = PingPong::new(&ctx, "particles", &[POSITION, VELOCITY], &f, 2, 2).unwrap();
    pp.front().texture(SPIN);
}

#[test]
#[should_panic(expected = "has 2 attachments: name the one meant")]
fn only_texture_of_two_panics() {
    let ctx = context();
    let f = [TextureFormat::Rgba32F; 2];
    let pp = PingPong::new(&ctx, "particles", &[POSITION, VELOCITY], &f, 2, 2).unwrap();
    pp.front().only_texture();
}

/// An exchange hands the textures over: each framebuffer then reads, and draws into, the
/// texture the other held (the collision and fluid steps hand their gathered statics to the
/// state this way); textures of another format or size are refused and nothing moves.
#[test]
fn exchanged_attachments_are_read_and_drawn_where_they_went() {
    let ctx = context();
    let t = |w| tex(&ctx, w, 2, TextureFormat::Rgba32F);
    let mut a = Framebuffer::named(&ctx, "a", vec![(POSITION, t(3)), (SPIN, t(3))]).unwrap();
    let mut b = Framebuffer::named(&ctx, "b", vec![(SPIN, t(3))]).unwrap();
    a.texture(SPIN).upload_f32(&[5.0; 24]).unwrap();
    b.texture(SPIN).upload_f32(&[7.0; 24]).unwrap();
    a.exchange(SPIN, &mut b, SPIN).unwrap();
    assert!(all(a.texture(SPIN), 7.0) && all(b.texture(SPIN), 5.0));
    // write8 writes output k as k + 1: a's second target is the texture that came from b.
    write8(&ctx, &a);
    assert!(all(a.texture(POSITION), 1.0) && all(a.texture(SPIN), 2.0));
    assert!(all(b.texture(SPIN), 5.0));
    write8(&ctx, &b);
    assert!(all(b.texture(SPIN), 1.0) && all(a.texture(SPIN), 2.0));
    for mut c in [
        Framebuffer::named(&ctx, "c", vec![(SPIN, t(4))]).unwrap(),
        Framebuffer::named(
            &ctx,
            "c",
            vec![(SPIN, tex(&ctx, 3, 2, TextureFormat::Rgba16F))],
        )
        .unwrap(),
    ] {
        let e = a.exchange(SPIN, &mut c, SPIN).unwrap_err().to_string();
        assert!(e.contains("different sizes or formats"), "{e}");
    }
    assert!(all(a.texture(SPIN), 2.0));
    no_gl_error(&ctx);
}
