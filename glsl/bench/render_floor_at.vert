// The render pass's floor where the particles are: the same positions as the pass draws (from a
// vertex buffer filled once, so no texture is fetched), the same camera and point size, a
// constant colour (common/write_floor.frag). Dead particles (w <= 0) are culled as the pass
// culls them. What is left of the pass above this floor is its texel fetches and its shading.

layout(location = 0) in vec4 a_position;   // xyz, remaining life

uniform mat4 u_view_proj;
uniform float u_point_size;

void main() {
    bool live = a_position.w > 0.0;
    gl_Position = live ? u_view_proj * vec4(a_position.xyz, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = u_point_size;
}
