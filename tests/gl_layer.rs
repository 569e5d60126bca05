//! The GL layer's contracts on a real driver: MRT with eight targets, distinct framebuffer
//! errors, and shader errors that name the glsl/ file and line.

mod common;

use common::{context, no_gl_error};
use texflow::gl::{
    Defines, Framebuffer, FullscreenPass, Program, Texture, TextureDesc, TextureFormat,
    FULLSCREEN_VERTEX,
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
    let program =
        Program::new(&ctx, FULLSCREEN_VERTEX, "test/write8.frag", &Defines::new()).unwrap();
    FullscreenPass::new(&ctx).unwrap().draw(&program, &fb);
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

#[test]
fn shader_errors_name_the_glsl_file_and_line() {
    let ctx = context();
    match Program::new(&ctx, FULLSCREEN_VERTEX, "test/broken.frag", &Defines::new()) {
        Err(Error::ShaderCompile { file, line, log }) => {
            assert_eq!((file.as_str(), line), ("test/broken.frag", 7), "{log}");
            assert!(log.contains("glsl/test/broken.frag:7"), "{log}");
        }
        other => panic!("expected a compile error, got {other:?}"),
    }
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
