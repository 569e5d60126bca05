// Exact detection, first pass: for every particle (in the cell-sorted layout) the number of live
// particles closer than 2r in the 27 cells around it (collide/cells.glsl).
// Output: (partners, 1 if a run of cells held more than EXACT_SCAN particles, sorted index of
// the closest partner or -1, its distance).

#include "common/state.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_position;   // gathered: sorted order
uniform float u_radius;

layout(location = 0) out vec4 o_count;


vec3 g_x;
int g_found = 0;
int g_closest = -1;
float g_d2 = 1e30;

void visit(int j) {
    vec4 q = texelFetch(u_position, ivec2(j % u_key_width, j / u_key_width), 0);
    vec3 d = g_x - q.xyz;
    float d2 = dot(d, d);
    if (particle_live(q) && d2 < 4.0 * u_radius * u_radius) {
        g_found++;
        // A tie keeps the first visited: it can cost a match, never the symmetry of one.
        if (d2 < g_d2) {
            g_d2 = d2;
            g_closest = j;
        }
    }
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int self = t.y * u_key_width + t.x;
    vec4 p = texelFetch(u_position, t, 0);
    if (particle_live(p)) {
        g_x = p.xyz;
        search_neighbours(self);
    }
    o_count = vec4(float(g_found), exact_truncated ? 1.0 : 0.0, float(g_closest),
                   g_closest >= 0 ? sqrt(g_d2) : 0.0);
}
