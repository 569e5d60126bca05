// The general particle renderer's vertex stage: one vertex per particle, drawn as a point or a
// point sprite. Where the state comes from is a compile-time choice:
//   VERTEX_BUFFER defined: attributes 0 and 1 of a buffer the state textures were copied into on
//     the GPU (glReadPixels into a pixel-pack buffer; UberFlow §4.7, Latta §3.4.5);
//   otherwise: vertex texture fetch of texel gl_VertexID (thesis Listing 3).
// Everything after the fetch is shared, so both paths draw bit-identical images.
// SPRITES defined: the size is scaled by the particle's type and the fragment stage textures the
// sprite from the atlas tile of its type, rotated by an angle from its random number.

#include "common/state.glsl"
#include "render/keyframes.glsl"

#ifdef VERTEX_BUFFER
layout(location = 0) in vec4 a_position;
layout(location = 1) in vec4 a_static;
#else
uniform sampler2D u_position;
uniform sampler2D u_static;
uniform int u_width;
#endif

uniform mat4 u_view_proj;
uniform float u_point_size;
uniform float u_intensity;
uniform vec4 u_type_scale;
uniform ivec4 u_type_tile;    // atlas tile of each type

out vec4 v_color;        // straight (not premultiplied) colour and opacity
flat out vec2 v_rotation; // cos and sin of the sprite's screen-space angle
flat out vec2 v_tile;     // atlas tile origin in tile units

void main() {
#ifdef VERTEX_BUFFER
    vec4 p = a_position;
    vec4 s = a_static;
#else
    ivec2 t = particle_texel(gl_VertexID, u_width);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 s = texelFetch(u_static, t, 0);
#endif
    // Drawn only when alive (remaining life above 0: not dead, not unborn) and at a finite
    // position (dead particles sit at +inf). Everything else is moved outside the clip volume.
    // Finiteness is tested on the bits: float comparisons with NaN are not reliable under
    // drivers' fast-math (NVIDIA drew NaN particles with a comparison-only test).
    if (!all_finite(p) || !(p.w > 0.0)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 1.0;
        v_color = vec4(0.0);
        v_rotation = vec2(1.0, 0.0);
        v_tile = vec2(0.0);
        return;
    }
    float age = relative_age(p.w, s.z);
    vec4 c = keyframe_color(age);
    v_color = vec4(c.rgb, clamp(c.a * u_intensity, 0.0, 1.0));
    int type = clamp(int(s.y + 0.5), 0, 3);
    float angle = 6.28318530718 * s.w;
    v_rotation = vec2(cos(angle), sin(angle));
    int tile = u_type_tile[type];
    v_tile = vec2(float(tile & 1), float(tile >> 1));
    gl_Position = u_view_proj * vec4(p.xyz, 1.0);
#ifdef SPRITES
    gl_PointSize = u_point_size * u_type_scale[type];
#else
    gl_PointSize = u_point_size;
#endif
}
