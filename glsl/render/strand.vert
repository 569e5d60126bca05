// Hair drawn as strands (render.mode = "surface"): each row of the state texture is a strand,
// drawn as line segments between consecutive texels, their vertex numbers read from an index
// buffer built once on the CPU (src/render/connected.rs); each vertex fetches its position by
// its number (gl_VertexID, thesis Listing 3). The tangent is the difference between the next
// and the previous texel of the row, each clamped to the texel itself at the strand's ends.

#include "common/state.glsl"
// all_finite
#include "render/keyframes.glsl"

uniform sampler2D u_position;
uniform mat4 u_view_proj;

out vec3 v_tangent;
out float v_ok;  // 1 at a finite vertex, 0 at one that is not

vec3 at(ivec2 t) {
    ivec2 size = textureSize(u_position, 0);
    return texelFetch(u_position, ivec2(clamp(t.x, 0, size.x - 1), t.y), 0).xyz;
}

void main() {
    ivec2 size = textureSize(u_position, 0);
    ivec2 t = particle_texel(gl_VertexID, size.x);
    vec4 p = texelFetch(u_position, t, 0);
    v_tangent = at(t + ivec2(1, 0)) - at(t - ivec2(1, 0));
    // As the cloth's: a segment that touches a non-finite vertex is dropped, not drawn to the corner.
    v_ok = all_finite(p) ? 1.0 : 0.0;
    gl_Position = all_finite(p) ? u_view_proj * vec4(p.xyz, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
