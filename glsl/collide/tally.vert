// Counts, over a run, the particles a pass flagged: the exact searches that walked a run of
// three cells past their bound (EXACT_SCAN, collide/cells.glsl; partner counts .y), or the paths
// that still entered a collider after the bound on bounces (sim/colliders.glsl, MAX_BOUNCES;
// velocity .w). One point per particle, drawn into a 1x1 R32F target with additive blending
// where the flag is set, clipped away elsewhere. A count kept on the GPU across steps, read back
// once at the end of a run.

uniform sampler2D u_counts;
uniform int u_width;
uniform int u_component;   // which component holds the flag

void main() {
    vec4 c = texelFetch(u_counts, ivec2(gl_VertexID % u_width, gl_VertexID / u_width), 0);
    gl_Position = c[u_component] > 0.5 ? vec4(0.0, 0.0, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
