// Lookup fields (src/sim/fields/): a height field (2D, RGBA32F: height, normal xyz), a signed
// distance field (3D, R32F) and a wind flow field (3D, RGBA32F: velocity xyz, 0). Read with
// texelFetch only and interpolated by hand, so that these functions are the twins of the CPU
// samplers in src/sim/fields/, operation for operation:
//
// - an axis from lo to hi with n >= 2 nodes has node i at lo + i (hi - lo) / (n - 1); texel i
//   holds the value there (height field: texel (i, j) = (x, z); 3D fields: (i, j, k) = (x, y, z));
// - a position maps to u = (x - lo) / (hi - lo) * (n - 1), clamped to [0, n - 1], between the
//   nodes i0 = floor(u) and i1 = min(i0 + 1, n - 1) with the weight t = u - i0; outside the
//   bounds the field is thus constant along each axis from its boundary values;
// - linear interpolation is a + t (b - a): exact at a node (t = 0) and between equal texels
//   (also when the compiler fuses it into fma(t, b - a, a)); along x, then y, then z.

// Nodes i0, i1 around coordinate x on an axis of n >= 2 nodes from lo to hi, and the weight t.
void field_cell(float x, float lo, float hi, int n, out int i0, out int i1, out float t) {
    float top = float(n - 1);
    float u = clamp((x - lo) / (hi - lo) * top, 0.0, top);
    i0 = int(floor(u));
    i1 = min(i0 + 1, n - 1);
    t = u - float(i0);
}

vec4 field_lerp(vec4 a, vec4 b, float t) {
    return a + t * (b - a);
}

// Trilinear interpolation of a 3D field at p (all four channels; unused ones cost nothing after
// the compiler's dead-code elimination).
vec4 field_trilinear(sampler3D tex, vec3 bmin, vec3 bmax, ivec3 res, vec3 p) {
    int i0; int i1; int j0; int j1; int k0; int k1;
    float tx; float ty; float tz;
    field_cell(p.x, bmin.x, bmax.x, res.x, i0, i1, tx);
    field_cell(p.y, bmin.y, bmax.y, res.y, j0, j1, ty);
    field_cell(p.z, bmin.z, bmax.z, res.z, k0, k1, tz);
    vec4 c00 = field_lerp(texelFetch(tex, ivec3(i0, j0, k0), 0),
                          texelFetch(tex, ivec3(i1, j0, k0), 0), tx);
    vec4 c10 = field_lerp(texelFetch(tex, ivec3(i0, j1, k0), 0),
                          texelFetch(tex, ivec3(i1, j1, k0), 0), tx);
    vec4 c01 = field_lerp(texelFetch(tex, ivec3(i0, j0, k1), 0),
                          texelFetch(tex, ivec3(i1, j0, k1), 0), tx);
    vec4 c11 = field_lerp(texelFetch(tex, ivec3(i0, j1, k1), 0),
                          texelFetch(tex, ivec3(i1, j1, k1), 0), tx);
    vec4 c0 = field_lerp(c00, c10, ty);
    vec4 c1 = field_lerp(c01, c11, ty);
    return field_lerp(c0, c1, tz);
}

// Height and unit normal at xz: (height, normal.x, normal.y, normal.z). extent is
// (min x, min z, max x, max z), res the texture size (nodes along x, along z). The texel normals
// all have normal.y > 0, so the interpolated normal is never zero.
vec4 heightfield_sample(sampler2D tex, vec4 extent, ivec2 res, vec2 xz) {
    int i0; int i1; int j0; int j1;
    float tx; float tz;
    field_cell(xz.x, extent.x, extent.z, res.x, i0, i1, tx);
    field_cell(xz.y, extent.y, extent.w, res.y, j0, j1, tz);
    vec4 c0 = field_lerp(texelFetch(tex, ivec2(i0, j0), 0), texelFetch(tex, ivec2(i1, j0), 0), tx);
    vec4 c1 = field_lerp(texelFetch(tex, ivec2(i0, j1), 0), texelFetch(tex, ivec2(i1, j1), 0), tx);
    vec4 v = field_lerp(c0, c1, tz);
    return vec4(v.x, normalize(v.yzw));
}

// Signed distance at p (negative inside), trilinear.
float sdf_sample(sampler3D tex, vec3 bmin, vec3 bmax, ivec3 res, vec3 p) {
    return field_trilinear(tex, bmin, bmax, res, p).x;
}

// Unit gradient of the interpolated distance by central differences with a step of one cell per
// axis; (0, 1, 0) where the gradient is zero (the field is constant there).
vec3 sdf_normal(sampler3D tex, vec3 bmin, vec3 bmax, ivec3 res, vec3 p) {
    vec3 h = (bmax - bmin) / vec3(res - ivec3(1));
    vec3 ex = vec3(h.x, 0.0, 0.0);
    vec3 ey = vec3(0.0, h.y, 0.0);
    vec3 ez = vec3(0.0, 0.0, h.z);
    vec3 g = vec3(
        (sdf_sample(tex, bmin, bmax, res, p + ex) - sdf_sample(tex, bmin, bmax, res, p - ex))
            / (2.0 * h.x),
        (sdf_sample(tex, bmin, bmax, res, p + ey) - sdf_sample(tex, bmin, bmax, res, p - ey))
            / (2.0 * h.y),
        (sdf_sample(tex, bmin, bmax, res, p + ez) - sdf_sample(tex, bmin, bmax, res, p - ez))
            / (2.0 * h.z));
    return dot(g, g) > 0.0 ? normalize(g) : vec3(0.0, 1.0, 0.0);
}

// Wind velocity at p, trilinear.
vec3 flow_sample(sampler3D tex, vec3 bmin, vec3 bmax, ivec3 res, vec3 p) {
    return field_trilinear(tex, bmin, bmax, res, p).xyz;
}
