// Exact detection, first pass: for every particle (in the cell-sorted layout) the number of live
// particles closer than 2r in the cells around it (collide/cells.glsl: the 27 cells, or on a cell
// below 2r those within u_search_radius = 2r), and the closest of
// them that it approaches ((x_i - x_j) . (v_i - v_j) < 0): the response matches mutual closest
// pairs, so a pair that the last iteration's exchange set apart leaves its particles to match
// their other contacts in this one.
// Output: (partners, 1 if a run of cells held more than EXACT_SCAN particles, sorted index of
// the closest approaching partner or -1, its distance).

#include "common/state.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_position;   // gathered: sorted order
uniform sampler2D u_velocity;
uniform float u_radius;

layout(location = 0) out vec4 o_count;


vec3 g_x;
vec3 g_v;
int g_found = 0;
int g_closest = -1;
float g_d2 = 1e30;

void visit(int j) {
    ivec2 tj = key_texel(j);
    vec4 q = texelFetch(u_position, tj, 0);
    vec3 d = g_x - q.xyz;
    float d2 = dot(d, d);
    // Life alone: a position that is not finite gives a d2 that is infinite or NaN, which
    // fails the distance test as particle_live would (fewer instructions a visit).
    if (q.w > 0.0 && d2 < 4.0 * u_radius * u_radius) {
        g_found++;
        // A tie keeps the first visited: it can cost a match, never the symmetry of one (the
        // approach test is symmetric too: both sides compute the same product).
        bool approaching = dot(d, g_v - texelFetch(u_velocity, tj, 0).xyz) < 0.0;
        if (approaching && d2 < g_d2) {
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
        g_v = texelFetch(u_velocity, t, 0).xyz;
        search_around(self, g_x);
    }
    o_count = vec4(float(g_found), exact_truncated ? 1.0 : 0.0, float(g_closest),
                   g_closest >= 0 ? sqrt(g_d2) : 0.0);
}
