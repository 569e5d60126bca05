// Vertex-texture-fetch render pass (thesis Listing 3; UberFlow §4.7 names the same path on
// hardware with vertex textures): one vertex per particle, no vertex attributes; the vertex
// fetches its particle's position from the position texture and projects it.
// Dead particles (life <= 0) are moved outside the clip volume, so they are not drawn.

#include "common/state.glsl"

uniform sampler2D u_position;
uniform sampler2D u_velocity;
uniform int u_width;
uniform mat4 u_view_proj;
uniform float u_point_size;
uniform float u_max_age;

out float v_age;

void main() {
    ivec2 t = particle_texel(gl_VertexID, u_width);
    vec4 p = texelFetch(u_position, t, 0);
    if (!(p.w > 0.0)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 1.0;
        v_age = 1.0;
        return;
    }
    // Total life L = max_age - wait (see sim/fire.frag); relative age in [0, 1].
    float wait = texelFetch(u_velocity, t, 0).w;
    float life = max(u_max_age - wait, 1e-6);
    v_age = clamp(1.0 - p.w / life, 0.0, 1.0);
    gl_Position = u_view_proj * vec4(p.xyz, 1.0);
    gl_PointSize = u_point_size;
}
