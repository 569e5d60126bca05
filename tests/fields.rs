//! The GLSL samplers of glsl/sim/fields.glsl against their CPU twins in `sim::fields`: the four
//! functions evaluated at a few hundred points, inside and outside the fields' bounds, by one
//! full-screen pass (tests/glsl/fields.frag) through three RGBA32F render targets.
//!
//! Both sides run the same f32 operations in the same order on the same texels, so they differ
//! by rounding only: the driver may compute `a / b` as `a * (1 / b)` (a few ulp instead of a
//! correctly rounded quotient), contract `a * b + c` into a fused multiply-add, and normalise
//! with an approximate reciprocal square root. The tolerances below follow from that model:
//!
//! - the grid coordinate `u = (x - lo) / (hi - lo) * (n - 1)` is off by at most `K eps u`
//!   (`eps = 2^-24`, `K = 8` ulp for subtraction, reciprocal, division and product), which moves
//!   an interpolated value by `K eps (n - 1)` times the largest jump `J` between neighbouring
//!   texels, once per axis;
//! - each of the (up to three) levels of `(1 - t) a + t b` rounds by at most `K eps M`, `M` the
//!   largest texel magnitude;
//! - so a value is within `tol = K eps ((n - 1) J axes + 3 M)`. For the fields here that is
//!   below 1e-5 of `M`: "float rounding only".
//! - A normalised vector `v / |v|` with `v` off by `tol` per component moves by at most
//!   `2 sqrt(3) tol / |v|`, plus the normalisation's own rounding (`K eps`).
//! - The distance field's normal divides differences of two samples by `2 h`: its gradient `g`
//!   is off by `tol / h` per component, and the normal by `2 sqrt(3) tol / (h |g|) + K eps`,
//!   with `|g|` taken from the CPU.

mod common;

use common::scene::Rng;
use common::{context, no_gl_error, test_shader, TestContext};
use glam::{Vec3, Vec4};
use texflow::gl::{
    Defines, Framebuffer, FullscreenPass, Program, Sampled, Texture, TextureDesc, TextureFormat,
    UniformList, FULLSCREEN_VERTEX,
};
use texflow::scene::{HeightFieldCollider, SdfCollider, Wind};
use texflow::sim::{DistanceField, FlowField, HeightField};

const EPS: f32 = 1.0 / (1u32 << 24) as f32;
const K: f32 = 8.0;

/// Largest magnitude `M` and largest jump `J` between texels adjacent along one axis, over the
/// first `used` channels of a field with `channels` floats a texel.
fn magnitude_and_jump(data: &[f32], size: [usize; 3], channels: usize, used: usize) -> (f32, f32) {
    let [nx, ny, nz] = size;
    let at = |i: usize, j: usize, k: usize, c: usize| data[((k * ny + j) * nx + i) * channels + c];
    let (mut m, mut jump) = (0.0f32, 0.0f32);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for c in 0..used {
                    let v = at(i, j, k, c);
                    m = m.max(v.abs());
                    if i + 1 < nx {
                        jump = jump.max((at(i + 1, j, k, c) - v).abs());
                    }
                    if j + 1 < ny {
                        jump = jump.max((at(i, j + 1, k, c) - v).abs());
                    }
                    if k + 1 < nz {
                        jump = jump.max((at(i, j, k + 1, c) - v).abs());
                    }
                }
            }
        }
    }
    (m, jump)
}

/// `K eps ((n - 1) J axes + 3 M)`: see the module doc.
fn value_tolerance(m: f32, jump: f32, n: u32, axes: f32) -> f32 {
    K * EPS * ((n - 1) as f32 * jump * axes + 3.0 * m)
}

/// Three fields over overlapping, non-dyadic regions (node positions are not exact binary
/// fractions, so the grid coordinates round on both sides).
fn three_fields() -> (HeightField, DistanceField, FlowField) {
    let hf = HeightField::new(&HeightFieldCollider {
        extent: [-2.1, -1.7, 2.3, 1.9],
        resolution: 37,
        base: 0.2,
        amplitude: 0.9,
        frequency: 1.3,
        friction: 0.0,
        resilience: 1.0,
        image: None,
        npy: None,
        heights: None,
    })
    .unwrap();
    let sdf = DistanceField::new(&SdfCollider {
        bounds: [[-1.5, -1.2, -1.0], [1.7, 1.3, 1.4]],
        resolution: 29,
        spheres: vec![[-0.4, 0.1, 0.2, 0.55], [0.9, 0.6, -0.3, 0.3]],
        boxes: vec![[0.1, -0.9, -0.6, 1.1, -0.2, 0.7]],
        mesh: None,
        triangles: vec![],
        field: None,
        distances: None,
        friction: 0.0,
        resilience: 1.0,
    })
    .unwrap();
    let flow = FlowField::new(&Wind {
        velocity: [0.7, -0.1, 0.3],
        turbulence: 1.1,
        resolution: 13,
        bounds: [[-2.0, -1.1, -1.5], [2.0, 1.9, 1.5]],
        drag: 1.0,
        form: Default::default(),
        curl: 0.0,
        curl_scale: 1.0,
        field: None,
        data: None,
    })
    .unwrap();
    (hf, sdf, flow)
}

/// `n` points: mostly random in a box larger than every field's bounds; also the distance
/// field's nodes (the CPU returns the texel there; a driver whose division is not correctly
/// rounded may land an ulp beside the node), points on its faces, and far away.
fn sample_points(sdf: &DistanceField, n: usize) -> Vec<Vec3> {
    let mut rng = Rng(2004);
    let mut points = Vec::with_capacity(n);
    for i in 0..12 {
        let (a, b, c) = (i * 7 % 29, i * 11 % 29, i * 5 % 29);
        points.push(sdf.node(a, b, c));
    }
    let [lo, hi] = sdf.bounds();
    for _ in 0..12 {
        let mut p = Vec3::new(
            rng.range(lo.x, hi.x),
            rng.range(lo.y, hi.y),
            rng.range(lo.z, hi.z),
        );
        let axis = (rng.next() * 3.0) as usize % 3;
        p[axis] = if rng.next() < 0.5 { lo[axis] } else { hi[axis] };
        points.push(p);
    }
    points.push(Vec3::splat(1e3));
    points.push(Vec3::new(-1e3, 0.3, 7.0));
    // Then alternately: near the distance field's bounds (5% margin), and in a box around all
    // three fields' bounds.
    let (near_lo, near_hi) = (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo));
    while points.len() < n {
        let (a, b) = if points.len() % 2 == 0 {
            (near_lo, near_hi)
        } else {
            (Vec3::new(-3.0, -2.5, -2.5), Vec3::new(3.0, 2.5, 2.5))
        };
        points.push(Vec3::new(
            rng.range(a.x, b.x),
            rng.range(a.y, b.y),
            rng.range(a.z, b.z),
        ));
    }
    let outside = points
        .iter()
        .filter(|p| p.cmplt(lo).any() || p.cmpgt(hi).any())
        .count();
    assert!(outside > n / 4 && outside < 3 * n / 4, "{outside} outside");
    points
}

/// The shader's uniforms: the three fields' bounds and resolutions.
fn field_uniforms(hf: &HeightField, sdf: &DistanceField, flow: &FlowField) -> UniformList {
    let mut program = UniformList::new();
    program.vec4("u_height_extent", Vec4::from_array(hf.extent()));
    let [hx, hz] = hf.resolution();
    program.ivec2("u_height_res", hx as i32, hz as i32);
    let [smin, smax] = sdf.bounds();
    program.vec3("u_sdf_min", smin);
    program.vec3("u_sdf_max", smax);
    let [sx, sy, sz] = sdf.resolution().map(|n| n as i32);
    program.ivec3("u_sdf_res", sx, sy, sz);
    let [fmin, fmax] = flow.bounds();
    program.vec3("u_flow_min", fmin);
    program.vec3("u_flow_max", fmax);
    let [fx, fy, fz] = flow.resolution().map(|n| n as i32);
    program.ivec3("u_flow_res", fx, fy, fz);
    program
}

/// The three fields sampled at `points` (a `w` × `h` texture) by tests/glsl/fields.frag: the
/// height, sdf and flow targets read back.
fn sample_on_gpu(
    ctx: &TestContext,
    points: &[Vec3],
    (w, h): (u32, u32),
    (hf, sdf, flow): (&HeightField, &DistanceField, &FlowField),
) -> Vec<Vec<f32>> {
    let desc = |label| TextureDesc {
        width: w,
        height: h,
        format: TextureFormat::Rgba32F,
        label,
    };
    let point_tex = Texture::new(ctx, desc("points")).unwrap();
    let flat: Vec<f32> = points
        .iter()
        .flat_map(|p| p.extend(1.0).to_array())
        .collect();
    point_tex.upload_f32(&flat).unwrap();
    let height_tex = hf.upload(ctx).unwrap();
    let sdf_tex = sdf.upload(ctx).unwrap();
    let flow_tex = flow.upload(ctx).unwrap();
    assert_eq!(sdf_tex.size(), [29, 29, 29]);
    assert_eq!(sdf_tex.read_f32().unwrap(), sdf.texels());
    assert_eq!(flow_tex.read_f32().unwrap(), flow.texels());
    let targets = ["height", "sdf", "flow"]
        .into_iter()
        .map(|l| Texture::new(ctx, desc(l)).unwrap())
        .collect();
    let fb = Framebuffer::new(ctx, "fields", targets).unwrap();

    let program = Program::new(
        ctx,
        FULLSCREEN_VERTEX,
        &test_shader("fields.frag"),
        &Defines::new(),
    )
    .unwrap();
    let uniforms = field_uniforms(hf, sdf, flow);
    let textures = [
        ("u_points", Sampled::from(&point_tex)),
        ("u_height", (&height_tex).into()),
        ("u_sdf", (&sdf_tex).into()),
        ("u_flow", (&flow_tex).into()),
    ];
    FullscreenPass::new(ctx)
        .unwrap()
        .draw(&program, &textures, uniforms.values(), &fb);
    let out: Vec<Vec<f32>> = fb
        .textures()
        .iter()
        .map(|t| t.read_f32().unwrap())
        .collect();
    no_gl_error(ctx);
    out
}

/// The value tolerances (module doc) of the height, sdf and flow fields, each checked to be
/// float rounding only.
fn field_tolerances(hf: &HeightField, sdf: &DistanceField, flow: &FlowField) -> [f32; 3] {
    let [hx, hz] = hf.resolution();
    let (hm, hj) = magnitude_and_jump(hf.texels(), [hx as usize, hz as usize, 1], 4, 4);
    let tol_h = value_tolerance(hm, hj, hx.max(hz), 2.0);
    let (sm, sj) = magnitude_and_jump(sdf.texels(), [29; 3], 1, 1);
    let tol_s = value_tolerance(sm, sj, 29, 3.0);
    let (fm, fj) = magnitude_and_jump(flow.texels(), [13; 3], 4, 3);
    let tol_f = value_tolerance(fm, fj, 13, 3.0);
    for (what, tol, m) in [
        ("height", tol_h, hm),
        ("sdf", tol_s, sm),
        ("flow", tol_f, fm),
    ] {
        assert!(
            tol <= 1e-5 * m,
            "{what}: tolerance {tol} is not float rounding of {m}"
        );
    }
    [tol_h, tol_s, tol_f]
}

/// The worst error / tolerance seen so far: height, height normal, sdf, sdf normal, flow.
#[derive(Default)]
struct Worst {
    h: f32,
    hn: f32,
    s: f32,
    sn: f32,
    f: f32,
}

/// The GPU's height sample `gh` (height, normal) at `p` against the CPU's.
fn check_height(hf: &HeightField, p: Vec3, gh: Vec4, tol_h: f32, worst: &mut Worst) {
    let (height, normal) = hf.sample(p.x, p.z);
    let e = (gh.x - height).abs();
    assert!(
        e <= tol_h,
        "height at {p}: GPU {} CPU {height} (tol {tol_h})",
        gh.x
    );
    worst.h = worst.h.max(e / tol_h);
    // The interpolated normal has length >= the cosine of the largest angle between
    // neighbouring texel normals; 0.5 is far below it for these gentle hills.
    let tol_n = 2.0 * 3f32.sqrt() * tol_h / 0.5 + K * EPS;
    let e = (Vec3::new(gh.y, gh.z, gh.w) - normal).abs().max_element();
    assert!(e <= tol_n, "height normal at {p}: GPU {gh} CPU {normal}");
    worst.hn = worst.hn.max(e / tol_n);
}

/// The GPU's distance sample `gs` (distance, normal) at `p` against the CPU's.
fn check_sdf(sdf: &DistanceField, p: Vec3, gs: Vec4, tol_s: f32, worst: &mut Worst) {
    let cell = sdf.cell_size().min_element();
    let d = sdf.sample(p);
    let e = (gs.x - d).abs();
    assert!(e <= tol_s, "sdf at {p}: GPU {} CPU {d} (tol {tol_s})", gs.x);
    worst.s = worst.s.max(e / tol_s);
    let n_cpu = sdf.normal(p);
    let g = sdf.gradient(p).length();
    let n_gpu = Vec3::new(gs.y, gs.z, gs.w);
    if g == 0.0 {
        assert_eq!(n_gpu, Vec3::Y, "sdf normal fallback at {p}");
    } else {
        let tol_sn = 2.0 * 3f32.sqrt() * tol_s / (cell * g) + K * EPS;
        let e = (n_gpu - n_cpu).abs().max_element();
        assert!(
            e <= tol_sn,
            "sdf normal at {p}: GPU {n_gpu} CPU {n_cpu} (tol {tol_sn})"
        );
        worst.sn = worst.sn.max(e / tol_sn);
    }
}

#[test]
fn glsl_samplers_match_their_cpu_twins() {
    let ctx = context();
    let (hf, sdf, flow) = three_fields();
    let (w, h) = (24u32, 16u32);
    let n = (w * h) as usize;
    let points = sample_points(&sdf, n);
    let out = sample_on_gpu(&ctx, &points, (w, h), (&hf, &sdf, &flow));
    let [tol_h, tol_s, tol_f] = field_tolerances(&hf, &sdf, &flow);

    let mut worst = Worst::default();
    let mut identical = 0;
    for (idx, p) in points.iter().enumerate() {
        let at = |t: usize| Vec4::from_slice(&out[t][idx * 4..idx * 4 + 4]);
        let (gh, gs, gf) = (at(0), at(1), at(2));
        identical += usize::from(gh.x == hf.sample(p.x, p.z).0)
            + usize::from(gs.x == sdf.sample(*p))
            + usize::from(gf.truncate() == flow.sample(*p));
        check_height(&hf, *p, gh, tol_h, &mut worst);
        check_sdf(&sdf, *p, gs, tol_s, &mut worst);
        let v = flow.sample(*p);
        let e = (gf.truncate() - v).abs().max_element();
        assert!(e <= tol_f, "flow at {p}: GPU {gf} CPU {v} (tol {tol_f})");
        assert_eq!(gf.w, 0.0);
        worst.f = worst.f.max(e / tol_f);
    }
    let Worst { h, hn, s, sn, f } = worst;
    eprintln!(
        "{}: {identical} of {} values bit-identical; worst error / tolerance: height {h:.3}, height normal {hn:.3}, sdf \
         {s:.3}, sdf normal {sn:.3}, flow {f:.3} (tolerances: height \
         {tol_h:.2e}, sdf {tol_s:.2e}, flow {tol_f:.2e})",
        ctx.limits().renderer,
        3 * n
    );
}

#[test]
fn texture3d_round_trips_and_checks_its_size() {
    let ctx = context();
    let data: Vec<f32> = (0..3 * 4 * 5).map(|i| i as f32 * 0.25 - 7.0).collect();
    let t = texflow::gl::Texture3D::new(&ctx, "r", TextureFormat::R32F, [3, 4, 5], Some(&data))
        .unwrap();
    assert_eq!(t.size(), [3, 4, 5]);
    assert_eq!(t.read_f32().unwrap(), data);
    let rgba: Vec<f32> = (0..4 * 2 * 2 * 3).map(|i| i as f32).collect();
    let t =
        texflow::gl::Texture3D::new(&ctx, "rgba", TextureFormat::Rgba32F, [2, 2, 3], None).unwrap();
    t.upload_f32(&rgba).unwrap();
    assert_eq!(t.read_f32().unwrap(), rgba);
    assert!(t.upload_f32(&rgba[1..]).is_err());
    let max = ctx.limits().max_3d_texture_size;
    for (size, needle) in [
        ([0, 4, 4], "empty"),
        ([4, max + 1, 4], "GL_MAX_3D_TEXTURE_SIZE"),
    ] {
        let msg = texflow::gl::Texture3D::new(&ctx, "big", TextureFormat::R32F, size, None)
            .unwrap_err()
            .to_string();
        assert!(msg.contains(needle), "{msg}");
    }
    let msg = texflow::gl::Texture3D::new(&ctx, "bytes", TextureFormat::Rgba8, [2, 2, 2], None)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("float"), "{msg}");
    no_gl_error(&ctx);
}
