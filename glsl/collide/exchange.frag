// A user state's exchange with its neighbours (`[[state]]` with `pair`; UberFlow §6: "any
// physical model that requires access to adjacent particles"): after the collision sort and
// the gather of the state and the user states in cell order, every live particle adds to its
// state the sum of the `pair` expression over the live particles closer than u_pair_radius
// that the exact search visits: the 27 cells around it, or under a fluid on cells of h the
// cells within u_search_radius = u_pair_radius (collide/cells.glsl, SEARCH_TRIM). Output: this
// state's new value, in the sorted layout's order (src/sim/collide/carry.rs draws it).
// The root (src/sim/particles/user_state.rs) defines, before including this file:
//   user_pair()              the `pair` expression as a vec4 function;
//   user_load_self(t)        the globals the states' names read, at sorted texel t;
//   user_load_other(t)       the same values of the neighbour at t into `other`;
//   USER_SELF                this state's value at the fragment (before the exchange);
//   `other` (the neighbour's inputs and states) and `r` (the distance), globals.

#include "collide/cells.glsl"

uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform float u_pair_radius;
uniform float u_dt;
uniform float u_time;

layout(location = 0) out vec4 o_state;

vec4 g_exchange = vec4(0.0);

bool is_partner(vec4 q) {
    return particle_live(q) && length(q.xyz - x) < u_pair_radius;
}

void partner_work(int j, ivec2 tj, vec4 q) {
    float d = length(q.xyz - x);
    vec4 st = texelFetch(u_static, tj, 0);
    other.x = q.xyz;
    other.v = texelFetch(u_velocity, tj, 0).xyz;
    other.life = q.w;
    other.age = user_age(q, st, u_time);
    other.type = int(st.y);
    other.random = st.w;
    other.index = j;
    user_load_other(tj);
    r = d;
    g_exchange += user_pair();
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 st = texelFetch(u_static, t, 0);
    index = t.y * u_key_width + t.x;
    x = p.xyz;
    v = texelFetch(u_velocity, t, 0).xyz;
    life = p.w;
    age = user_age(p, st, u_time);
    type = int(st.y);
    random = st.w;
    time = u_time;
    dt = u_dt;
    user_load_self(t);
    if (particle_live(p)) {
        search_around(index, x);
    }
    o_state = USER_SELF + g_exchange;
}
