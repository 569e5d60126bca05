//! Scan conversion of a triangle mesh into the distance field's 3D texture on the GPU (UberFlow
//! §4.6: "we first scan-convert the original scene into a signed distance representation. The
//! distance field is stored in a 3D texture map"), by fragment passes as in 2004: the triangles
//! go into a float texture, and one full-screen pass per z slice, drawn into a framebuffer whose
//! attachment is that layer of the 3D texture, writes every node of the slice
//! (`glsl/sim/sdf_slice.frag`: the distance to the nearest triangle, by brute force, with the
//! winding number's sign).
//!
//! Each pass reads only the triangle texture and writes only its own layer: the slices are
//! independent, and their order does not matter.

use glam::Vec3;

use crate::error::Result;
use crate::gl::{
    Context, Framebuffer, FullscreenPass, Program, Sampled, Texture, Texture3D, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};
use crate::scene::Triangle;

/// The triangles as an RGBA32F texture of 3 × `triangles.len()` texels: texel `(v, t)` holds
/// vertex `v` of triangle `t` in xyz (w = 0).
fn triangle_texture(ctx: &Context, triangles: &[Triangle]) -> Result<Texture> {
    let tex = Texture::new(
        ctx,
        TextureDesc {
            width: 3,
            height: triangles.len() as u32,
            format: TextureFormat::Rgba32F,
            label: "sdf:triangles",
        },
    )?;
    let data: Vec<f32> = triangles
        .iter()
        .flatten()
        .flat_map(|v| [v[0], v[1], v[2], 0.0])
        .collect();
    tex.upload_f32(&data)?;
    Ok(tex)
}

/// Scan-converts `triangles` into a new R32F 3D texture labelled `sdf` with `res` nodes per axis
/// from `bounds[0]` to `bounds[1]` (the conventions of `sim::fields`): one pass per slice.
pub(super) fn scan_convert(
    ctx: &Context,
    triangles: &[Triangle],
    bounds: [Vec3; 2],
    res: [u32; 3],
) -> Result<Texture3D> {
    let field = Texture3D::new(ctx, "sdf", TextureFormat::R32F, res, None)?;
    let tris = triangle_texture(ctx, triangles)?;
    let program = Program::new(ctx, FULLSCREEN_VERTEX, "sim/sdf_slice.frag", &Vec::new())?;
    let pass = FullscreenPass::new(ctx)?;
    let [nx, ny, nz] = res.map(|n| n as i32);
    let textures = [("u_triangles", Sampled::from(&tris))];
    for k in 0..res[2] {
        let slice = Framebuffer::layer(ctx, &format!("sdf:slice {k}"), &field, k)?;
        let uniforms = [
            ("u_slice", Uniform::I32(k as i32)),
            ("u_triangle_count", Uniform::I32(triangles.len() as i32)),
            ("u_min", Uniform::Vec3(bounds[0])),
            ("u_max", Uniform::Vec3(bounds[1])),
            ("u_res", Uniform::IVec3(glam::IVec3::new(nx, ny, nz))),
        ];
        pass.draw(&program, &textures, &uniforms, &slice);
    }
    ctx.check_error("scan-converting the mesh into the distance field")?;
    Ok(field)
}
