// Beyond the papers: STEPS consecutive steps of one bitonic stage in one pass. Each fragment
// fetches the 2^STEPS entries its sub-network spans (its index XOR every combination of the
// steps' masks), runs the compare-exchanges locally and writes its own result. Same bytes
// written per pass as FP, STEPS times fewer passes: on a GPU whose passes cost what they write,
// about STEPS times faster. Twin: apply_group in src/sort/network.rs.

#include "common/compare.glsl"
#include "common/precision.glsl"

#ifndef STEPS
#define STEPS 3
#endif
#define SIZE (1 << STEPS)

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_block;
uniform int u_mask[STEPS];
uniform bool u_mirror[STEPS];

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    int index[SIZE];
    vec2 e[SIZE];
    for (int c = 0; c < SIZE; c++) {
        int j = i;
        for (int s = 0; s < STEPS; s++) {
            if (((c >> s) & 1) == 1) j ^= u_mask[s];
        }
        index[c] = j;
        e[c] = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
    }
    for (int s = 0; s < STEPS; s++) {
        vec2 before[SIZE] = e;
        for (int c = 0; c < SIZE; c++) {
            int other = c ^ (1 << s);
            int g = index[c];
            bool ascending = u_mirror[s] || u_block > u_width || ((g % u_width) & u_block) == 0;
            e[c] = compare_exchange(before[c], before[other], (g < index[other]) == ascending);
        }
    }
    o_entry = fp_store(vec4(e[0], 0.0, 0.0));
}
