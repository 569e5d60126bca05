//! Any scene through the library: a built-in name or a `.toml` scene file, simulated and written
//! as PNG frames, with the list of passes it runs.
//!
//!     cargo run --release --example scene -- [SCENE] [OUT_DIR]   (default: fountain, scene-frames/)

use texflow::gl::Context;
use texflow::render::FrameWriter;
use texflow::{scene, SceneRunner};

fn main() -> texflow::Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "fountain".into());
    let out = args.next().unwrap_or_else(|| "scene-frames".into());

    // Built-in names come from examples/scenes/*.toml, compiled into the binary; anything else
    // is read as a file. Errors name the file, line and column.
    let scene = scene::load(&name)?;
    print!("{}", scene::plan::plan(&scene));

    let ctx = Context::new(0)?;
    let mut run = SceneRunner::new(&ctx, &scene, 7)?;
    let frames = FrameWriter::create(out.as_ref())?;
    for frame in 0..120 {
        run.advance_frame()?;
        if frame % 40 == 39 {
            println!("wrote {}", frames.write(frame, &run.render()?)?.display());
        }
    }
    Ok(())
}
