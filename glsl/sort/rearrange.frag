// Rearrangement (UberFlow §4.3.1): output texel j of the state takes the state of the particle
// whose identifier sits at sorted position j, for every state texture at once (MRT, TARGETS of
// them). PACKED reads the packed sort texture (the paper's final decode pass); ID_TABLE decodes
// the paper's 24-bit-safe identifiers (sort/sorted_id.glsl). BLOCKED reads the entries where
// our blocked sort's last merge left them (sort/blocked_entry.glsl): the pass that would have
// written them row-major first is left out. THROUGH (a mask of the targets) reads those
// targets' sources through the first lattice's sort as well (sort/first_id.glsl): at the place
// the first sort gave the particle whose identifier sits at sorted position j.

#ifndef TARGETS
#define TARGETS 1
#endif

// Included whatever BLOCKED says: an include is expanded once, where it first appears, and
// sort/first_id.glsl reads another sort's blocked layout with it.
#include "sort/blocked_entry.glsl"
#ifndef BLOCKED
uniform sampler2D u_sorted;
uniform int u_sort_width;
#endif
uniform int u_state_width;
uniform sampler2D u_state0;
uniform sampler2D u_state1;
uniform sampler2D u_state2;
uniform sampler2D u_state3;

layout(location = 0) out vec4 o_0;
#if TARGETS > 1
layout(location = 1) out vec4 o_1;
#endif
#if TARGETS > 2
layout(location = 2) out vec4 o_2;
#endif
#if TARGETS > 3
layout(location = 3) out vec4 o_3;
#endif

#include "sort/sorted_id.glsl"
#ifdef THROUGH
#include "sort/first_id.glsl"
#define SOURCE(k) (((THROUGH >> k) & 1) != 0 ? far : src)
#else
#define SOURCE(k) src
#endif

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int j = t.y * u_state_width + t.x;
#ifdef BLOCKED
    int id = decode_id(entry_at(j).y);
#else
    int id = sorted_id(u_sorted, u_sort_width, j);
#endif
    ivec2 src = ivec2(id % u_state_width, id / u_state_width);
#ifdef THROUGH
    int first = first_id(id);
    ivec2 far = ivec2(first % u_state_width, first / u_state_width);
#endif
    o_0 = texelFetch(u_state0, SOURCE(0), 0);
#if TARGETS > 1
    o_1 = texelFetch(u_state1, SOURCE(1), 0);
#endif
#if TARGETS > 2
    o_2 = texelFetch(u_state2, SOURCE(2), 0);
#endif
#if TARGETS > 3
    o_3 = texelFetch(u_state3, SOURCE(3), 0);
#endif
}
