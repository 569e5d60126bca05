// The last pass of our blocked sort (src/sort/blocked.rs): writes the sorted entries row-major
// into the sorter's RG32F texture again, so the gather and the collision search read them as
// they read every other variant's. Each texel finds its entry through the last pass's layout.

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#define MAX_BITS 24

#ifdef ROW_CELLS
// Rows-only compact exact entries (blocked.frag): the level gives the key back exactly (-inf,
// the cell, +inf, the key pass's NaN), the position in the block of u_block_bits bits the id
// (the entry's index in the sorted rows' row-major order).
uniform usampler3D u_blocks;
uniform int u_block_bits;
#elif defined(COMPACT)
// 4-byte entries (blocked.frag): the identifier in the low u_id_bits bits; the key comes back
// as its quantisation level's lower bound, the top level as +inf.
uniform usampler3D u_blocks;
uniform int u_id_bits;
uniform float u_key_lo;
uniform float u_key_scale;
#else
uniform sampler3D u_blocks;
#endif
uniform int u_in_log_w;
uniform int u_width_log;
uniform int u_bits;
// Storage bit of each logical bit in the last layout.
uniform int u_perm[MAX_BITS];

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int i = (f.y << u_width_log) | f.x;
#ifdef IDENTITY_LAYOUT
    // After merge passes the entries lie row-major: no bits to move.
    int s = i;
#else
    int s = 0;
    for (int q = 0; q < MAX_BITS; q++) {
        if (q >= u_bits) break;
        if (((i >> q) & 1) != 0) s |= 1 << u_perm[q];
    }
#endif
    int p = s >> BITS;
    int mask = (1 << u_in_log_w) - 1;
#ifdef ROW_CELLS
    uint e = texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 2), 0)[s & 3];
    uint level = e >> uint(u_block_bits);
    uint top = (1u << uint(32 - u_block_bits)) - 1u;
    uint bits = level == 0u ? 0xff800000u : (level == top ? 0x7fc00000u : (level == top - 1u ? 0x7f800000u : floatBitsToUint(float(level - 1u))));
    int block = (1 << u_block_bits) - 1;
    int id = (i & ~block) | int(e & uint(block));
    o_entry = vec4(uintBitsToFloat(bits), float(id), 0.0, 0.0);
#elif defined(COMPACT)
    uint e = texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 2), 0)[s & 3];
    uint level = e >> uint(u_id_bits);
    uint top = (1u << uint(32 - u_id_bits)) - 1u;
    float key = level == top ? uintBitsToFloat(0x7f800000u) : u_key_lo + float(level) / u_key_scale;
    o_entry = vec4(key, float(e & ((1u << uint(u_id_bits)) - 1u)), 0.0, 0.0);
#else
    vec4 t = texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 1), 0);
    o_entry = vec4((s & 1) == 0 ? t.xy : t.zw, 0.0, 0.0);
#endif
}
