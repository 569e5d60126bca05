// Collision detection (UberFlow §4.4): the state has been gathered in the order of the cell
// sort, so particles of one cell sit next to each other along a row. Each particle looks at
// u_neighbours particles to its left and right in the same row and keeps the closest one within
// the collision distance 2r: its partner's texel index and their distance.
//
// Ours, beyond the paper: one fragment serves LANES = 4 neighbouring particles of a row, so the
// window of 4 + 2k positions they share is fetched once (20 fetches for 4 particles at k = 8,
// where a fragment each fetches 17 for one: fetches, not bytes written, bound this pass on the
// NVIDIA H100). Each particle takes the same partner as when it searched alone: the closest,
// and among candidates at the same distance the first in the paper's order (nearest first, the
// left one before the right one), which the rank below encodes.
// Output, for the particles of columns 4x .. 4x + 3 of a row, into two RGBA32F targets at texel
// x: their partners (index or -1) and their distances.

#include "common/state.glsl"

#define LANES 4

uniform sampler2D u_position;   // gathered: sorted order
uniform int u_width;
uniform int u_neighbours;
uniform float u_radius;

layout(location = 0) out vec4 o_partners;
layout(location = 1) out vec4 o_distances;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int x0 = t.x * LANES;
    vec4 p[LANES];
    bool live[LANES];
    float best[LANES];
    float partner[LANES];
    int rank[LANES];
    for (int l = 0; l < LANES; l++) {
        int x = x0 + l;
        p[l] = x < u_width ? texelFetch(u_position, ivec2(x, t.y), 0) : vec4(0.0);
        live[l] = x < u_width && particle_live(p[l]);
        best[l] = 2.0 * u_radius;
        partner[l] = -1.0;
        rank[l] = 0;
    }
    // The window: every column within u_neighbours of one of the lanes.
    for (int o = -MAX_NEIGHBOURS; o < LANES + MAX_NEIGHBOURS; o++) {
        if (o < -u_neighbours) continue;
        if (o >= LANES + u_neighbours) break;
        int x = x0 + o;
        if (x < 0 || x >= u_width) continue;
        // The lanes' own positions come from registers (constant indices only).
        vec4 q = o == 0 ? p[0] : o == 1 ? p[1] : o == 2 ? p[2] : o == 3 ? p[3]
                                              : texelFetch(u_position, ivec2(x, t.y), 0);
        if (!particle_live(q)) continue;
        float index = float(t.y * u_width + x);
        for (int l = 0; l < LANES; l++) {
            int m = o - l;
            if (m == 0 || abs(m) > u_neighbours || !live[l]) continue;
            // The paper's order: m = -1, +1, -2, +2, ...
            int r = 2 * abs(m) + (m > 0 ? 1 : 0);
            float d = distance(p[l].xyz, q.xyz);
            if (d < best[l] || (d == best[l] && partner[l] >= 0.0 && r < rank[l])) {
                best[l] = d;
                partner[l] = index;
                rank[l] = r;
            }
        }
    }
    o_partners = vec4(partner[0], partner[1], partner[2], partner[3]);
    o_distances = vec4(best[0], best[1], best[2], best[3]);
}
