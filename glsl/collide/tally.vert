// Counts, over a run, the particles whose exact search walked a run of three cells past its
// bound (EXACT_SCAN, collide/cells.glsl): one point per particle, drawn into a 1x1 R32F target
// with additive blending where the count pass flagged it (partner counts .y), clipped away
// elsewhere. A count kept on the GPU across steps, read back once at the end of a run.

uniform sampler2D u_counts;
uniform int u_width;

void main() {
    vec4 c = texelFetch(u_counts, ivec2(gl_VertexID % u_width, gl_VertexID / u_width), 0);
    gl_Position = c.y > 0.5 ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
