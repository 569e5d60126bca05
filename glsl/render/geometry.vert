// The scene's colliders (render.geometry): triangles from a vertex buffer built once on the CPU
// (src/render/geometry.rs), projected with the particles' camera.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color; // rgb, and the checker cell in metres (0: plain)

uniform mat4 u_view_proj;

out vec3 v_world;
out vec3 v_normal;
flat out vec4 v_color;

void main() {
    v_world = a_position;
    v_normal = a_normal;
    v_color = a_color;
    gl_Position = u_view_proj * vec4(a_position, 1.0);
}
