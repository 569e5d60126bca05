//! Any scene through the library: a built-in name or a `.toml` scene file, simulated and written
//! as PNG frames, with the list of passes it runs.
//!
//!     cargo run --release --example scene -- [SCENE] [OUT_DIR]   (default: fountain, scene-frames/)

use std::ops::ControlFlow;

use texflow::engine::{self, FolderSink, FrameLoop, LoopOptions};
use texflow::gl::Context;
use texflow::{scene, EngineKind};

fn main() -> texflow::Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "fountain".into());
    let out = args.next().unwrap_or_else(|| "scene-frames".into());

    // Built-in names come from examples/scenes/*.toml, compiled into the binary; anything else
    // is read as a file. Errors name the file, line and column.
    let scene = scene::load(&name)?;
    let ctx = Context::new(0)?;
    let mut engine = engine::build(&ctx, &scene, 7, EngineKind::Gpu)?;
    // The passes the engine holds, in the papers' words.
    print!("{}", engine.plan());
    // The same frame loop as `texflow render`: 120 frames, every 40th written (0, 40, 80), the
    // non-finite census of each written frame.
    let options = LoopOptions {
        frames: 120,
        every: 40,
        ..LoopOptions::default()
    };
    let run = FrameLoop::new(&ctx, engine.as_ref(), options)?;
    let mut sink = FolderSink::create(out.as_ref(), None)?;
    let summary = run.run(engine.as_mut(), &mut sink, |_| ControlFlow::Continue(()))?;
    for path in sink.written() {
        println!("wrote {}", path.display());
    }
    if summary.max_non_finite > 0 {
        eprintln!(
            "warning: {} particles had NaN or infinite values",
            summary.max_non_finite
        );
    }
    Ok(())
}
