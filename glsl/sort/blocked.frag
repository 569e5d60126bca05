// Ours, beyond the papers: a bitonic network in registers, SIZE = 2^BITS entries per fragment
// (src/sort/blocked.rs). The fragment owns the entries whose logical index has its pixel's bits
// outside the pass's group and any combination inside it; it fetches each where the previous
// layout stored it, runs the pass's STEP_COUNT compare-exchanges locally and writes the SIZE
// entries, two per RGBA32F texel, one texel per layer of a 3D texture (multiple render targets).
//
// Why: a pass costs about the bytes it writes plus the texels it fetches; this writes each entry
// once and fetches it once for several network steps, where UberFlow's variants do one step.
// The compare-exchanges come written out (NETWORK) so that every array index is a constant and
// the entries stay in registers.
//
// COMPACT: 4-byte entries, lossy. The first pass quantises each key to the 32 - ID_BITS high bits
// of one uint, the identifier in the low ID_BITS, and the network compares those uints: four
// entries per RGBA32UI texel, half the bytes of an exact entry, twice the entries per fragment
// for the same eight render targets. Keys that fall in one quantisation step keep the order of
// their identifiers. +inf and NaN keys (dead particles, padding) take the top level, so they
// still sort after every live particle.
//
// ROW_CELLS (with COMPACT, rows-only sorts of cell keys): 4-byte entries that lose nothing. An
// entry never leaves its block of rows, so the identifier needs only its position in the block
// (u_block_bits bits, the column when rows are sorted one by one); the key, a whole cell index,
// takes a level of its own in the high bits: -inf 0, cell k k + 1, +inf top - 1, NaN top. The
// sorter takes it only where every cell has a level (src/sort/gpu/blocked.rs, row_cells_fit), so
// the uints order as the exact (key, id) entries do, ties by column as by id.

#include "common/compare.glsl"

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#ifdef COMPACT
#define LANES 4
#define ENTRY uint
#else
#define LANES 2
#define ENTRY vec2
#endif
#define LAYERS (SIZE / LANES)
#ifndef STEP_COUNT
#define STEP_COUNT 1
#define NETWORK CX(0, 0, 1)
#endif
#define MAX_PIXEL_BITS 24

#ifdef NATURAL_INPUT
// The key pass's row-major RG32F texture.
uniform sampler2D u_natural;
#elif defined(COMPACT)
uniform usampler3D u_blocks;
#else
uniform sampler3D u_blocks;
#endif
#ifdef COMPACT
// Identifier bits (the low bits of an entry); a key k takes level (k - u_key_lo) * u_key_scale,
// clamped to [0, 2^(32 - ID_BITS) - 2], and non-finite keys the level above.
uniform int u_id_bits;
uniform float u_key_lo;
uniform float u_key_scale;
#endif
#ifdef ROW_CELLS
// log2 of the entries of a sorted block (one row, or a set of rows).
uniform int u_block_bits;
#endif
// log2 of the width of what is read (texels of the natural texture, pixels of the blocks).
uniform int u_in_log_w;
// log2 of the width of the target.
uniform int u_log_w;
uniform int u_pixel_bits;
// For pixel bit q: the storage bit, in the previous layout, of the logical bit it stands for,
// and that logical bit.
uniform int u_pix_prev[MAX_PIXEL_BITS];
uniform int u_pix_logical[MAX_PIXEL_BITS];
// For slot c: the storage index in the previous layout, and the logical index, of its group
// bits.
uniform int u_prev_slot[SIZE];
uniform int u_slot_logical[SIZE];
// For each step: the logical bit that sets its direction, or -1 (every pair ascends).
uniform int u_dir[STEP_COUNT];

#ifdef COMPACT
layout(location = 0) out uvec4 o_blocks[LAYERS];
#define LESS(B, A) ((B) < (A))
#else
layout(location = 0) out vec4 o_blocks[LAYERS];
#define LESS(B, A) entry_less(B, A)
#endif

// One compare-exchange of step S between slots C < O (one line: GLSL 3.30 has no line
// continuation). The pair ascends where the direction bit of the logical index is 0.
#define CX(S, C, O) { bool up = u_dir[S] < 0 || (((logical | u_slot_logical[C]) >> u_dir[S]) & 1) == 0; ENTRY a = e[C]; ENTRY b = e[O]; bool sw = LESS(b, a) == up; e[C] = sw ? b : a; e[O] = sw ? a : b; }

#ifdef NATURAL_INPUT
vec4 fetch_texel(int s) {
    int mask = (1 << u_in_log_w) - 1;
    return texelFetch(u_natural, ivec2(s & mask, s >> u_in_log_w), 0);
}
#elif defined(COMPACT)
uvec4 fetch_texel(int s) {
    int p = s >> BITS;
    int mask = (1 << u_in_log_w) - 1;
    return texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 2), 0);
}
#else
vec4 fetch_texel(int s) {
    int p = s >> BITS;
    int mask = (1 << u_in_log_w) - 1;
    return texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 1), 0);
}
#endif

#ifdef ROW_CELLS
// The exact entry of the key at row-major index s: the twin of row_cell_entry in
// src/sort/gpu/blocked.rs.
uint row_cell_entry(float key, int s) {
    uint top = (1u << uint(32 - u_block_bits)) - 1u;
    uint u = floatBitsToUint(key);
    uint level;
    if ((u & 0x7fffffffu) > 0x7f800000u) {
        level = top;
    } else if (u == 0x7f800000u) {
        level = top - 1u;
    } else if (u == 0xff800000u) {
        level = 0u;
    } else {
        level = uint(clamp(key, 0.0, float(top - 3u))) + 1u;
    }
    return (level << uint(u_block_bits)) | uint(s & ((1 << u_block_bits) - 1));
}
#elif defined(COMPACT)
// The entry of a (key, id) pair of the key pass: the twin of compact_level in
// src/sort/gpu/blocked.rs. Non-finite keys by their bits (isnan and isinf are left to the driver):
// -inf takes level 0, +inf and NaN the top level.
uint compact_entry(vec2 k) {
    uint top = (1u << uint(32 - u_id_bits)) - 1u;
    uint u = floatBitsToUint(k.x);
    uint level;
    if ((u & 0x7f800000u) == 0x7f800000u) {
        level = u == 0xff800000u ? 0u : top;
    } else {
        float q = floor((k.x - u_key_lo) * u_key_scale);
        level = q >= float(top - 1u) ? top - 1u : (q > 0.0 ? uint(q) : 0u);
    }
    return (level << uint(u_id_bits)) | uint(k.y);
}
#endif

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int pixel = (f.y << u_log_w) | f.x;
    int prev = 0;
    int logical = 0;
    for (int q = 0; q < MAX_PIXEL_BITS; q++) {
        if (q >= u_pixel_bits) break;
        if (((pixel >> q) & 1) != 0) {
            prev |= 1 << u_pix_prev[q];
            logical |= 1 << u_pix_logical[q];
        }
    }
    ENTRY e[SIZE];
#if defined(ROW_CELLS) && defined(NATURAL_INPUT)
    for (int c = 0; c < SIZE; c++) {
        int s = prev | u_prev_slot[c];
        e[c] = row_cell_entry(fetch_texel(s).x, s);
    }
#elif defined(COMPACT) && defined(NATURAL_INPUT)
    for (int c = 0; c < SIZE; c++) {
        e[c] = compact_entry(fetch_texel(prev | u_prev_slot[c]).xy);
    }
#elif defined(COMPACT)
    for (int c = 0; c < SIZE; c++) {
        int s = prev | u_prev_slot[c];
        e[c] = fetch_texel(s)[s & 3];
    }
#elif defined(PINNED) && !defined(NATURAL_INPUT)
    // Logical bit 0 is the lane in both layouts: one fetch gives two entries of the fragment.
    for (int c = 0; c < SIZE; c += 2) {
        vec4 t = fetch_texel(prev | u_prev_slot[c]);
        e[c] = t.xy;
        e[c + 1] = t.zw;
    }
#else
    for (int c = 0; c < SIZE; c++) {
        int s = prev | u_prev_slot[c];
        vec4 t = fetch_texel(s);
#ifdef NATURAL_INPUT
        e[c] = t.xy;
#else
        e[c] = (s & 1) == 0 ? t.xy : t.zw;
#endif
    }
#endif
    // NETWORK is the pass's compare-exchanges written out, CX(step, c, o) each (the sorter
    // generates it): straight-line code with constant indices, which no compiler leaves in
    // local memory, where loops of 16 entries and several steps were not always unrolled.
    NETWORK
#ifdef COMPACT
    for (int l = 0; l < LAYERS; l++) {
        o_blocks[l] = uvec4(e[4 * l], e[4 * l + 1], e[4 * l + 2], e[4 * l + 3]);
    }
#else
    for (int l = 0; l < LAYERS; l++) {
        o_blocks[l] = vec4(e[2 * l], e[2 * l + 1]);
    }
#endif
}
