//! The fire of the GLSL thesis through the library API: a headless context on the first EGL
//! device, the built-in `fire` scene, a few frames written as PNG.
//!
//!     cargo run --release --example fire -- [OUT_DIR]      (default: fire-frames/)

use texflow::gl::Context;
use texflow::output::FrameWriter;
use texflow::{engine, scene, EngineKind};

fn main() -> texflow::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fire-frames".into());

    // A surfaceless OpenGL 3.3 core context on EGL device 0 (llvmpipe on a machine without GPU).
    let ctx = Context::new(0)?;
    println!("rendering on {}", ctx.limits().renderer);

    // The built-in scene, adjusted: 128x128 particles (one per state texel), 384x384 frames.
    let mut fire = scene::builtin("fire")?;
    fire.particles.size = [128, 128];
    fire.render.resolution = [384, 384];

    // Seed 7: the same seed gives the same frames on the same device. The fire is one
    // simulation of the GPU engine, drawn by its particle renderer with the fire's colour ramp.
    let mut engine = engine::build(&ctx, &fire, 7, EngineKind::Gpu)?;
    let frames = FrameWriter::create(out.as_ref())?;
    for frame in 0..90 {
        // One frame = `substeps` fixed steps of `dt` seconds, each one full-screen MRT pass.
        engine.advance_frame()?;
        if frame % 30 == 29 {
            let path = frames.write(frame, &engine.render()?)?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}
