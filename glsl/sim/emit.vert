// Allocator emission (Latta §3.4.1): each new particle is one point drawn into its texel of the
// state textures, carrying the initial data the CPU drew (src/sim/emit.rs).

layout(location = 0) in float a_index;
layout(location = 1) in vec4 a_position;  // xyz, life
layout(location = 2) in vec4 a_velocity;
layout(location = 3) in vec4 a_static;    // birth time, type, life, random

uniform ivec2 u_size;

flat out vec4 v_position;
flat out vec4 v_velocity;
flat out vec4 v_static;

void main() {
    int i = int(a_index);
    vec2 texel = vec2(float(i % u_size.x), float(i / u_size.x)) + 0.5;
    gl_Position = vec4(texel / vec2(u_size) * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 1.0;
    v_position = a_position;
    v_velocity = a_velocity;
    v_static = a_static;
}
