// Exact detection, first pass: for every particle (in the cell-sorted layout) the number of live
// particles closer than 2r in the 27 cells around it (collide/cells.glsl).
// Output: (partners, 1 if a run of cells held more than EXACT_SCAN particles, 0, 0).

#include "collide/cells.glsl"

uniform sampler2D u_position;   // gathered: sorted order
uniform float u_radius;

layout(location = 0) out vec4 o_count;

bool live(vec4 p) {
    // Bit test: NVIDIA's compiler drops NaN-sensitive float comparisons.
    return p.w > 0.0 && (floatBitsToUint(p.x) & 0x7f800000u) != 0x7f800000u;
}

vec3 g_x;
int g_found = 0;

void visit(int j) {
    vec4 q = texelFetch(u_position, ivec2(j % u_key_width, j / u_key_width), 0);
    vec3 d = g_x - q.xyz;
    if (live(q) && dot(d, d) < 4.0 * u_radius * u_radius) g_found++;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int self = t.y * u_key_width + t.x;
    vec4 p = texelFetch(u_position, t, 0);
    if (live(p)) {
        g_x = p.xyz;
        search_neighbours(self);
    }
    o_count = vec4(float(g_found), exact_truncated ? 1.0 : 0.0, 0.0, 0.0);
}
