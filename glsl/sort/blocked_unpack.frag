// The last pass of our blocked sort (src/sort/blocked.rs): writes the sorted entries row-major
// into the sorter's RG32F texture again, so the gather and the collision search read them as
// they read every other variant's. Each texel finds its entry through the last pass's layout.

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#define MAX_BITS 24

uniform sampler3D u_blocks;
uniform int u_in_log_w;
uniform int u_width_log;
uniform int u_bits;
// Storage bit of each logical bit in the last layout.
uniform int u_perm[MAX_BITS];

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int i = (f.y << u_width_log) | f.x;
    int s = 0;
    for (int q = 0; q < MAX_BITS; q++) {
        if (q >= u_bits) break;
        if (((i >> q) & 1) != 0) s |= 1 << u_perm[q];
    }
    int p = s >> BITS;
    int mask = (1 << u_in_log_w) - 1;
    vec4 t = texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 1), 0);
    o_entry = vec4((s & 1) == 0 ? t.xy : t.zw, 0.0, 0.0);
}
