// Collision detection (UberFlow §4.4): the state has been gathered in the order of the cell
// sort, so particles of one cell sit next to each other along a row. Each fragment fetches its
// particle and NEIGHBOURS particles to its left and right in the same row, keeps the closest
// one within the collision distance 2r, and writes that partner's texel index.
// Output: (partner index or -1, distance), into an RG32F target.
//
// Every neighbour is fetched before any is weighed (NEIGHBOURS is a constant: the loops unroll):
// the fetches then issue together instead of each waiting on the last one's comparison, which
// made this pass five times its write floor on an NVIDIA H100. They are weighed in the same
// order as before (nearest first, left before right), so ties go the same way.

#include "common/state.glsl"

#ifndef NEIGHBOURS
#define NEIGHBOURS 8
#endif

uniform sampler2D u_position;   // gathered: sorted order
uniform int u_width;
uniform float u_radius;

layout(location = 0) out vec2 o_partner;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    float best = 2.0 * u_radius;
    float partner = -1.0;
    if (particle_live(p)) {
        // Left and right of distance m at 2m - 2 and 2m - 1; clamped into the row (those
        // outside it are skipped below).
        vec4 q[2 * NEIGHBOURS];
        for (int m = 1; m <= NEIGHBOURS; m++) {
            q[2 * m - 2] = texelFetch(u_position, ivec2(max(t.x - m, 0), t.y), 0);
            q[2 * m - 1] = texelFetch(u_position, ivec2(min(t.x + m, u_width - 1), t.y), 0);
        }
        for (int m = 1; m <= NEIGHBOURS; m++) {
            for (int s = 0; s < 2; s++) {
                int x = t.x + (2 * s - 1) * m;
                vec4 o = q[2 * m - 2 + s];
                if (x < 0 || x >= u_width || !particle_live(o)) continue;
                float d = distance(p.xyz, o.xyz);
                if (d < best) {
                    best = d;
                    partner = float(t.y * u_width + x);
                }
            }
        }
    }
    o_partner = vec2(partner, best);
}
