// Rearrangement (UberFlow §4.3.1): output texel j of the state takes the state of the particle
// whose identifier sits at sorted position j, for every state texture at once (MRT, TARGETS of
// them). PACKED reads the packed sort texture (the paper's final decode pass). ID_TABLE decodes
// the paper's 24-bit-safe identifiers: subtract the width of each binade until the rest falls
// inside one, then divide by the spacing there.

#ifndef TARGETS
#define TARGETS 1
#endif

uniform sampler2D u_sorted;
uniform int u_sort_width;
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

int decode_id(float v) {
#ifdef ID_TABLE
    float rest = v - 1.0;
    float width = 1.0;
    int s = 0;
    for (int k = 0; k < 126 && rest >= width; k++) {
        rest -= width;
        width *= 2.0;
        s++;
    }
    float spacing = width / float(1 << FLOAT_MANTISSA);
    return (s << FLOAT_MANTISSA) + int(rest / spacing);
#else
    return int(v);
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int j = t.y * u_state_width + t.x;
    ivec2 s = ivec2(j % u_sort_width, j / u_sort_width);
#ifdef PACKED
    vec4 pair = texelFetch(u_sorted, ivec2(s.x / 2, s.y), 0);
    vec2 e = (s.x & 1) == 0 ? pair.xy : pair.zw;
#else
    vec2 e = texelFetch(u_sorted, s, 0).xy;
#endif
    int id = decode_id(e.y);
    ivec2 src = ivec2(id % u_state_width, id / u_state_width);
    o_0 = texelFetch(u_state0, src, 0);
#if TARGETS > 1
    o_1 = texelFetch(u_state1, src, 0);
#endif
#if TARGETS > 2
    o_2 = texelFetch(u_state2, src, 0);
#endif
#if TARGETS > 3
    o_3 = texelFetch(u_state3, src, 0);
#endif
}
