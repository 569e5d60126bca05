// The blocked sort's entries where its passes leave them (src/sort/gpu/blocked.rs): row-major
// in the blocked layout, SIZE = 2^BITS a pixel, LANES a texel, one texel per layer of a 3D
// texture. Shared by the merge passes (sort/merge_path.glsl) and the gather that reads a sort
// which kept its layout (sort/rearrange.frag with BLOCKED).

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#ifdef COMPACT
#define LANES 4
#define ENTRY uint
uniform usampler3D u_blocks;
#else
#define LANES 2
#define ENTRY vec2
uniform sampler3D u_blocks;
#endif

// log2 of the width of the blocks texture (read and written at the same size).
uniform int u_log_w;

// The entry at row-major index s of `blocks`, a blocks texture of width 2^log_w with 2^bits
// entries a pixel (this sort's, or another sort's: sort/first_id.glsl).
#ifdef COMPACT
ENTRY entry_in(usampler3D blocks, int log_w, int bits, int s) {
#else
ENTRY entry_in(sampler3D blocks, int log_w, int bits, int s) {
#endif
    int p = s >> bits;
    int mask = (1 << log_w) - 1;
    ivec3 t = ivec3(p & mask, p >> log_w, (s & ((1 << bits) - 1)) / LANES);
#ifdef COMPACT
    return texelFetch(blocks, t, 0)[s & 3];
#else
    vec4 v = texelFetch(blocks, t, 0);
    return (s & 1) == 0 ? v.xy : v.zw;
#endif
}

// The entry at row-major index s.
ENTRY entry_at(int s) {
    return entry_in(u_blocks, u_log_w, BITS, s);
}
