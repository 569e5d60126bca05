// Collision detection (UberFlow §4.4): the state has been gathered in the order of the cell
// sort, so particles of one cell sit next to each other along a row. Each fragment fetches its
// particle and u_neighbours particles to its left and right in the same row, keeps the closest
// one within the collision distance 2r, and writes that partner's texel index.
// Output: (partner index or -1, distance), into an RG32F target.

#include "common/state.glsl"

uniform sampler2D u_position;   // gathered: sorted order
uniform int u_width;
uniform int u_neighbours;
uniform float u_radius;

layout(location = 0) out vec2 o_partner;


void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    float best = 2.0 * u_radius;
    float partner = -1.0;
    if (particle_live(p)) {
        for (int m = 1; m <= MAX_NEIGHBOURS; m++) {
            if (m > u_neighbours) break;
            for (int side = -1; side <= 1; side += 2) {
                int x = t.x + side * m;
                if (x < 0 || x >= u_width) continue;
                vec4 q = texelFetch(u_position, ivec2(x, t.y), 0);
                if (!particle_live(q)) continue;
                float d = distance(p.xyz, q.xyz);
                if (d < best) {
                    best = d;
                    partner = float(t.y * u_width + x);
                }
            }
        }
    }
    o_partner = vec2(partner, best);
}
