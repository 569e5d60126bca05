// Beyond the papers: several steps of one bitonic stage in one pass, on the packed layout (two
// entries per RGBA32F texel). The fragment owns one texel; it fetches the 2^LEVELS texels its
// sub-network spans (its entries XOR every combination of the LEVELS wide masks), runs the
// STEPS compare-exchanges locally (a distance-1 step costs no fetch: both entries share a
// texel) and writes its two entries. Twin: group_steps and apply_group in src/sort/network.rs.
//
// Why: on the H100 a pass is bound by texel fetches (about 13.5 G/s) and bytes written
// (56 GB/s). Per entry and network step, FP fetches 2 texels and writes 8 bytes; packed fetches
// 1 and writes 8; this fetches 2^LEVELS / (2 LEVELS) = 1 (LEVELS = 2) and writes 8 / STEPS.

#include "common/compare.glsl"
#include "common/precision.glsl"

#ifndef LEVELS
#define LEVELS 2
#endif
#ifndef STEPS
#define STEPS 3
#endif
#define SIZE (2 << LEVELS)

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_block;
#if LEVELS > 0
uniform int u_basis[LEVELS];
#endif
uniform bool u_mirror[STEPS];

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int first = t.y * u_width + 2 * t.x;
    int index[SIZE];
    vec2 e[SIZE];
    for (int c = 0; c < SIZE; c += 2) {
        int j = first;
#if LEVELS > 0
        for (int b = 0; b < LEVELS; b++) {
            if (((c >> (b + 1)) & 1) == 1) j ^= u_basis[b];
        }
#endif
        vec4 pair = texelFetch(u_keys, ivec2((j % u_width) / 2, j / u_width), 0);
        bool even = (j & 1) == 0;
        index[c] = j;
        index[c + 1] = j ^ 1;
        e[c] = even ? pair.xy : pair.zw;
        e[c + 1] = even ? pair.zw : pair.xy;
    }
    // Wide steps come first in a stage and take local bits 1..LEVELS; a distance-1 step closes
    // the stage and takes bit 0. Compile-time bits keep every array index constant once the
    // loops unroll, so the arrays stay in registers (a uniform index sends them to local memory).
    for (int s = 0; s < STEPS; s++) {
        vec2 before[SIZE] = e;
        int bit = s < LEVELS ? s + 1 : 0;
        for (int c = 0; c < SIZE; c++) {
            int other = c ^ (1 << bit);
            int g = index[c];
            bool ascending = u_mirror[s] || u_block > u_width || ((g % u_width) & u_block) == 0;
            e[c] = compare_exchange(before[c], before[other], (g < index[other]) == ascending);
        }
    }
    o_entry = fp_store(vec4(e[0], e[1]));
}
