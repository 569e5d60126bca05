// Child trails drawn as ribbons (render.trails = "ribbon"): a camera-facing quad (two
// triangles) between consecutive children of one parent's trail. A trail's texels are a ring
// (sim/child_birth.glsl: trail child n goes to texel on_death + n mod count of its parent's
// block), so ring neighbour a -> b holds children n and n + 1. The index buffer, built once on
// the CPU (src/render/ribbons.rs), names per vertex ((a·2 + wrap)·4 + range)·8 + corner:
// b is a + 1, or at the ring's end (wrap) its first texel. Both ends are fetched (vertex
// texture fetch); the quad is drawn only if both are alive and finite and b was born after a
// by at most one trail interval (u_gap): a pair across the ring's newest/oldest seam, a dead
// end or a child of an earlier parent in the same slot is moved outside the clip volume.
// Each end takes its own keyframe colour by relative age; the width is render.ribbon_width
// metres across the segment and the view, or (0) the end's point size in pixels on screen.

#include "common/state.glsl"
#include "render/keyframes.glsl"
#include "render/sprite.glsl"

uniform sampler2D u_position;
uniform sampler2D u_static;
uniform int u_width;
uniform int u_ring[4];         // per range: trail texels per parent
uniform float u_gap[4];        // per range: the longest age difference of consecutive children
uniform mat4 u_view_proj;
uniform vec2 u_viewport;       // frame size in pixels
uniform vec3 u_eye;
uniform float u_point_size;
uniform float u_intensity;
uniform float u_ribbon_width;  // metres; 0: the point size in pixels
uniform int u_sprites;         // 1: sizes scaled by type and size over life, as sprites'

out vec4 v_color;  // straight colour and opacity

// Corners: (end: 0 at a, 1 at b; side: -1 or 1).
const vec2 CORNERS[6] = vec2[6](vec2(0.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
                                vec2(0.0, -1.0), vec2(1.0, 1.0), vec2(0.0, 1.0));

void main() {
    int id = gl_VertexID;
    vec2 corner = CORNERS[id % 8];
    int range = (id / 8) % 4;
    int wrap = (id / 32) % 2;
    int a = id / 64;
    int b = wrap != 0 ? a - (u_ring[range] - 1) : a + 1;
    ivec2 ta = particle_texel(a, u_width);
    ivec2 tb = particle_texel(b, u_width);
    vec4 pa = texelFetch(u_position, ta, 0);
    vec4 pb = texelFetch(u_position, tb, 0);
    vec4 sa = texelFetch(u_static, ta, 0);
    vec4 sb = texelFetch(u_static, tb, 0);
    vec4 ca = u_view_proj * vec4(pa.xyz, 1.0);
    vec4 cb = u_view_proj * vec4(pb.xyz, 1.0);
    // Seconds since birth: the total life less the remaining one (a born first is older).
    float older = (sa.z - pa.w) - (sb.z - pb.w);
    bool ok = all_finite(pa) && all_finite(pb) && pa.w > 0.0 && pb.w > 0.0 && older >= 0.0 &&
              older <= u_gap[range] && ca.w > 0.0 && cb.w > 0.0;
    if (!ok) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        v_color = vec4(0.0);
        return;
    }
    bool at_b = corner.x > 0.5;
    vec4 p = at_b ? pb : pa;
    vec4 s = at_b ? sb : sa;
    vec4 clip = at_b ? cb : ca;
    float age = relative_age(p.w, s.z);
    int type = clamp(int(s.y + 0.5), 0, 3);
    float birth = birth_time(p.w, s.z, s.x);
    vec4 c = keyframe_color_of(type, age) * type_tint(type, birth);
    v_color = vec4(c.rgb, clamp(c.a * u_intensity, 0.0, 1.0));
    if (u_ribbon_width > 0.0) {
        vec3 across = cross(pb.xyz - pa.xyz, u_eye - p.xyz);
        float len = length(across);
        across = len > 0.0 ? across / len : vec3(0.0);
        clip = u_view_proj * vec4(p.xyz + across * corner.y * 0.5 * u_ribbon_width, 1.0);
    } else {
        float size = u_point_size * random_size(type, s.w);
        if (u_sprites != 0) {
            size *= type_scale(type, birth) * size_scale(type, age);
        }
        vec2 d = (cb.xy / cb.w - ca.xy / ca.w) * u_viewport;
        float len = length(d);
        vec2 across = len > 1e-4 ? vec2(-d.y, d.x) / len : vec2(0.0, 1.0);
        // NDC spans 2 over the viewport.
        clip.xy += across * corner.y * 0.5 * size * 2.0 / u_viewport * clip.w;
    }
    gl_Position = clip;
}
