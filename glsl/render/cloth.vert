// The cloth drawn as a surface (render.mode = "surface"): two triangles per cell of the sheet's
// grid, their vertex numbers read from an index buffer built once on the CPU
// (src/render/connected.rs); each vertex is a texel of the position texture, fetched by its
// number (gl_VertexID, as the particle renderer fetches a particle: thesis Listing 3). The normal
// is the cross product of the differences between the right and left and the up and down
// neighbours, each clamped to the texel itself at the grid's edges.

#include "common/state.glsl"
// all_finite
#include "render/keyframes.glsl"

uniform sampler2D u_position;
uniform mat4 u_view_proj;

out vec3 v_world;
out vec3 v_normal;
out float v_ok;  // 1 at a finite vertex, 0 at one that is not

vec3 at(ivec2 t) {
    ivec2 size = textureSize(u_position, 0);
    return texelFetch(u_position, clamp(t, ivec2(0), size - 1), 0).xyz;
}

void main() {
    ivec2 size = textureSize(u_position, 0);
    ivec2 t = particle_texel(gl_VertexID, size.x);
    vec4 p = texelFetch(u_position, t, 0);
    vec3 du = at(t + ivec2(1, 0)) - at(t - ivec2(1, 0));
    vec3 dv = at(t + ivec2(0, 1)) - at(t - ivec2(0, 1));
    v_normal = cross(du, dv);
    v_world = p.xyz;
    // A vertex at a non-finite position (a torn sheet) is moved outside the clip volume, and the
    // fragment stage drops every fragment of a triangle that touches one (v_ok below 1): clipping
    // alone would still draw the triangle's part inside the frame, a wedge towards the corner.
    v_ok = all_finite(p) ? 1.0 : 0.0;
    gl_Position = all_finite(p) ? u_view_proj * vec4(p.xyz, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
