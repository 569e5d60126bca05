// The sorted keys of the exact neighbour search (collide/cells.glsl) and the binary search over
// them: the state has been gathered in the order of a full sort by cell key (cells enumerated
// z, y, x; dead particles' +inf keys last), so the first sorted index of a cell is the first
// whose key is not below the cell's. Shared by the search and by the cell-start pass
// (collide/cell_start.frag), which runs this search once per cell.

uniform sampler2D u_keys;       // the sorted entries: (key, id) per texel, or with PACKED_KEYS
                                // (the packed network) (key, id, key, id)
uniform int u_key_width;        // entries per sorted row (the state width)
uniform int u_count;            // entries (the state size)

// The texel of sorted index i in a layout of u_key_width entries a row. With KEY_WIDTH_SHIFT
// (the width a power of two, as every sorted state's is, known when the program is built) a mask
// and a shift: a division by a uniform costs a GPU tens of instructions, and the searches take
// one per visited neighbour (the million-particle dam's density pass 12.9 → 7.4 ms on an H100).
ivec2 key_texel(int i) {
#ifdef KEY_WIDTH_SHIFT
    return ivec2(i & ((1 << KEY_WIDTH_SHIFT) - 1), i >> KEY_WIDTH_SHIFT);
#else
    return ivec2(i % u_key_width, i / u_key_width);
#endif
}

// The order in which the exact count pass's fragments take the particles (WALK_TILES: a state
// whose sides are powers of two of at least 16, src/sim/collide/walk_order.rs): the fragment at
// pixel t works for the particle of sorted index walk_index(t) and writes its result there;
// walk_texel(i) is where the result of sorted index i lies. Tiles of 16 × 16 pixels, row-major,
// each holding 256 consecutive sorted indices in Morton order (every aligned block of 2^k × 2^k
// or 2^(k+1) × 2^k pixels of a tile holds consecutive indices). A GPU runs a fragment pass in
// warps of neighbouring pixels, so a warp's particles are neighbours in the sort, in the same few
// cells, and walk the same runs; in sorted order, a block of pixels four rows high takes four
// far-apart stretches of space.
#ifdef WALK_TILES
// Morton order of the 4 low bits of x and y: x's bits at the even places.
int walk_interleave(int x, int y) {
    ivec2 v = ivec2(x, y);
    v = (v | (v << 2)) & 0x33;
    v = (v | (v << 1)) & 0x55;
    return v.x | (v.y << 1);
}

int walk_deinterleave(int m) {
    ivec2 v = ivec2(m, m >> 1) & 0x55;
    v = (v | (v >> 1)) & 0x33;
    v = (v | (v >> 2)) & 0x0f;
    return v.x | (v.y << 4);
}
#endif

int walk_index(ivec2 t) {
#ifdef WALK_TILES
    // (Set only with KEY_WIDTH_SHIFT.)
    int tile = ((t.y >> 4) << (KEY_WIDTH_SHIFT - 4)) + (t.x >> 4);
    return (tile << 8) | walk_interleave(t.x & 15, t.y & 15);
#else
    return t.y * u_key_width + t.x;
#endif
}

ivec2 walk_texel(int i) {
#ifdef WALK_TILES
    int tile = i >> 8;
    int xy = walk_deinterleave(i & 255);
    int column = tile & ((1 << (KEY_WIDTH_SHIFT - 4)) - 1);
    return ivec2(column * 16 + (xy & 15), (tile >> (KEY_WIDTH_SHIFT - 4)) * 16 + (xy >> 4));
#else
    return key_texel(i);
#endif
}

float sorted_key(int i) {
    ivec2 t = key_texel(i);
#ifdef PACKED_KEYS
    vec4 e = texelFetch(u_keys, ivec2(t.x / 2, t.y), 0);
    return (i & 1) == 0 ? e.x : e.z;
#else
    return texelFetch(u_keys, t, 0).x;
#endif
}

// First sorted index in [lo, hi] whose key is not below k, where it is known to lie there.
int lower_bound_in(float k, int lo, int hi) {
    for (int it = 0; it < 32; it++) {
        if (lo >= hi) break;
        int mid = (lo + hi) / 2;
        if (sorted_key(mid) < k) lo = mid + 1; else hi = mid;
    }
    return lo;
}

// First sorted index whose key is not below k (dead particles' +inf keys sort last).
int lower_bound(float k) {
    return lower_bound_in(k, 0, u_count);
}
