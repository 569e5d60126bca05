// Collision detection (UberFlow §4.4): the state has been gathered in the order of the cell
// sort, so particles of one cell sit next to each other along a row. Each fragment fetches its
// particle and u_neighbours particles to its left and right in the same row, keeps the closest
// one within the collision distance 2r, and writes that partner's texel index.
// Output: (partner index or -1, distance), into an RG32F target.
//
// Each candidate takes as few instructions as give the same partner (on the NVIDIA H100 neither
// they nor the fetches bound this pass: fewer of either did not make it faster, see
// docs/performance.md, "What bounds UberFlow's detection"):
// - a live test on life alone: a candidate whose position is not finite has a distance that is
//   infinite or NaN, which never passes `d < best` (best is finite), as particle_live would
//   have refused it;
// - the distance only where the squared one could beat the best: a candidate whose squared
//   distance exceeds best² by more than the relative error of a float square root never gives
//   `distance(...) < best`, so skipping it changes nothing; the rest compare exactly as before.

#include "common/state.glsl"

uniform sampler2D u_position;   // gathered: sorted order
uniform int u_width;
uniform int u_neighbours;
uniform float u_radius;

layout(location = 0) out vec2 o_partner;

// Above the relative error of d² against distance()² (a few ulps each, 1e-6 at most).
const float MARGIN = 1.0001;

float g_best;
float g_bound;
int g_column = -1;

void consider(vec3 p, ivec2 at) {
    vec4 q = texelFetch(u_position, at, 0);
    vec3 e = p - q.xyz;
    if (!(q.w > 0.0 && dot(e, e) <= g_bound)) return;
    float d = distance(p, q.xyz);
    if (d < g_best) {
        g_best = d;
        g_bound = d * d * MARGIN;
        g_column = at.x;
    }
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    g_best = 2.0 * u_radius;
    g_bound = g_best * g_best * MARGIN;
    if (particle_live(p)) {
        // The paper's order: nearest first, the left one before the right one.
        for (int m = 1; m <= MAX_NEIGHBOURS; m++) {
            if (m > u_neighbours) break;
            if (t.x - m >= 0) consider(p.xyz, ivec2(t.x - m, t.y));
            if (t.x + m < u_width) consider(p.xyz, ivec2(t.x + m, t.y));
        }
    }
    o_partner = vec2(g_column < 0 ? -1.0 : float(t.y * u_width + g_column), g_best);
}
