// The CPU engine's points (UberFlow Table 2, E5): the CPU simulated and sorted the particles and
// uploaded one vertex per live particle, in drawing order, with glBufferSubData, as a CPU-based
// particle engine does: (x, y, z, relative age). Nothing is fetched from textures. Colour by the
// same keyframes of relative age as render/particle.vert, so both engines draw the same frame.

#include "render/keyframes.glsl"

layout(location = 0) in vec4 a_vertex;   // position, relative age in [0, 1]

uniform mat4 u_view_proj;
uniform float u_point_size;
uniform float u_intensity;

out vec4 v_color;   // straight (not premultiplied) colour and opacity

void main() {
    vec4 c = keyframe_color(a_vertex.w);
    v_color = vec4(c.rgb, clamp(c.a * u_intensity, 0.0, 1.0));
    gl_Position = u_view_proj * vec4(a_vertex.xyz, 1.0);
    gl_PointSize = u_point_size;
}
