// The cost model's vertex probe: vertex k fetches texel k of u_source (row-major, 2^u_log_w
// texels a row, as a surface's or a strand's vertex fetches its particle) and lands outside the
// clip volume with the other two of its triangle, so that the clipper drops every triangle and
// no fragment is drawn: what a vertex of a triangle or a line costs. The fetch moves the
// position by a zero the compiler cannot see (u_zero), so that it stays.

uniform sampler2D u_source;
uniform int u_log_w;
uniform float u_zero;

void main() {
    int k = gl_VertexID;
    ivec2 t = ivec2(k & ((1 << u_log_w) - 1), k >> u_log_w);
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0) + texelFetch(u_source, t, 0) * u_zero;
}
