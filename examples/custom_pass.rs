//! A pass of your own over a ping-pong state (the public pass API, `gl::StatePass`; three.js's
//! `GPUComputationRenderer.addVariable` done in Rust). The state is a 64×64 position texture and
//! a velocity texture; the pass is one explicit Euler step under gravity with a bounce off the
//! plane y = 0, written as a fragment shader that reads the front by texel fetch and writes the
//! back through two outputs. After the steps the example reads the state back, prints how far
//! it is from the closed form of the motion before the first bounce, and writes a PNG of the
//! heights.
//!
//! `cargo run --release --example custom_pass -- custom-pass-out`

use texflow::gl::{Attachment, Context, PingPong, StatePass, TextureFormat, Uniform};

const SIDE: u32 = 64;

/// The state's attachments, in the order of the pass's outputs.
const POSITION: Attachment = Attachment::named("position");
const VELOCITY: Attachment = Attachment::named("velocity");

const STEP: &str = r#"
// x += v dt, v += g dt; a bounce off y = 0 reflects v.y.
#include "common/rng.glsl"
uniform sampler2D u_state0; // position
uniform sampler2D u_state1; // velocity
uniform float u_dt;
uniform vec3 u_gravity;
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;
void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 x = texelFetch(u_state0, t, 0);
    vec4 v = texelFetch(u_state1, t, 0);
    x.xyz += v.xyz * u_dt;
    v.xyz += u_gravity * u_dt;
    if (x.y < 0.0) { x.y = -x.y; v.y = abs(v.y); }
    o_position = x;
    o_velocity = v;
}
"#;

fn main() -> texflow::Result<()> {
    let out = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "custom-pass-out".into()),
    );
    std::fs::create_dir_all(&out).map_err(|e| texflow::Error::Io {
        path: out.clone(),
        source: e,
    })?;
    let ctx = Context::new(0)?;
    let formats = [TextureFormat::Rgba32F; 2];
    let mut state = PingPong::new(&ctx, "custom", &[POSITION, VELOCITY], &formats, SIDE, SIDE)?;
    // Every particle starts at height 1 + its column / SIDE with an upward speed of its row / SIDE.
    let n = (SIDE * SIDE) as usize;
    let (mut x, mut v) = (vec![0f32; 4 * n], vec![0f32; 4 * n]);
    for i in 0..n {
        let (col, row) = ((i as u32 % SIDE) as f32, (i as u32 / SIDE) as f32);
        x[4 * i + 1] = 1.0 + col / SIDE as f32;
        v[4 * i + 1] = row / SIDE as f32;
    }
    state.front().texture(POSITION).upload_f32(&x)?;
    state.front().texture(VELOCITY).upload_f32(&v)?;
    let pass = StatePass::new(&ctx, "examples/custom_pass.rs STEP", STEP, 2)?;
    let (dt, g, steps) = (1.0f32 / 256.0, -9.81f32, 64);
    for _ in 0..steps {
        pass.run(
            &mut state,
            &[
                ("u_dt", Uniform::F32(dt)),
                ("u_gravity", Uniform::Vec3(glam::Vec3::new(0.0, g, 0.0))),
            ],
        );
    }
    let y = state.front().texture(POSITION).read_f32()?;
    // Explicit Euler's closed form: y_n = y0 + n dt v0 + g dt² n(n-1)/2 (no particle has
    // reached y = 0 by t = 0.25 s: the lowest starts at 1 with v0 = 0 and falls 0.3 m).
    let t = steps as f32;
    let mut worst = 0f32;
    for i in 0..n {
        let y_exact = x[4 * i + 1] + t * dt * v[4 * i + 1] + g * dt * dt * t * (t - 1.0) / 2.0;
        worst = worst.max((y[4 * i + 1] - y_exact).abs());
    }
    println!("{steps} steps of {SIDE}x{SIDE} particles; largest error against the closed form: {worst:.2e}");
    let img = image::GrayImage::from_fn(SIDE, SIDE, |c, r| {
        let h = y[4 * (r * SIDE + c) as usize + 1];
        image::Luma([(h / 2.5 * 255.0).clamp(0.0, 255.0) as u8])
    });
    let png = out.join("heights.png");
    img.save(&png).map_err(|e| texflow::Error::Io {
        path: png.clone(),
        source: std::io::Error::other(e),
    })?;
    println!("wrote {}", png.display());
    ctx.check_error("the example")
}
