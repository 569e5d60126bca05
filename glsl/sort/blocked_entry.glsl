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

// The entry at row-major index s.
ENTRY entry_at(int s) {
    int p = s >> BITS;
    int mask = (1 << u_log_w) - 1;
    ivec3 t = ivec3(p & mask, p >> u_log_w, (s & (SIZE - 1)) / LANES);
#ifdef COMPACT
    return texelFetch(u_blocks, t, 0)[s & 3];
#else
    vec4 v = texelFetch(u_blocks, t, 0);
    return (s & 1) == 0 ? v.xy : v.zw;
#endif
}
