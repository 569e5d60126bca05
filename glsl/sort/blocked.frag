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

#include "common/compare.glsl"

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#define LAYERS (SIZE / 2)
#ifndef STEP_COUNT
#define STEP_COUNT 1
#define NETWORK CX(0, 0, 1)
#endif
#define MAX_PIXEL_BITS 24

#ifdef NATURAL_INPUT
// The key pass's row-major RG32F texture.
uniform sampler2D u_natural;
#else
uniform sampler3D u_blocks;
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

layout(location = 0) out vec4 o_blocks[LAYERS];

// One compare-exchange of step S between slots C < O (one line: GLSL 3.30 has no line
// continuation). The pair ascends where the direction bit of the logical index is 0.
#define CX(S, C, O) { bool up = u_dir[S] < 0 || (((logical | u_slot_logical[C]) >> u_dir[S]) & 1) == 0; vec2 a = e[C]; vec2 b = e[O]; bool sw = entry_less(b, a) == up; e[C] = sw ? b : a; e[O] = sw ? a : b; }

vec4 fetch_texel(int s) {
#ifdef NATURAL_INPUT
    int mask = (1 << u_in_log_w) - 1;
    return texelFetch(u_natural, ivec2(s & mask, s >> u_in_log_w), 0);
#else
    int p = s >> BITS;
    int mask = (1 << u_in_log_w) - 1;
    return texelFetch(u_blocks, ivec3(p & mask, p >> u_in_log_w, (s & (SIZE - 1)) >> 1), 0);
#endif
}

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
    vec2 e[SIZE];
#if defined(PINNED) && !defined(NATURAL_INPUT)
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
    for (int l = 0; l < LAYERS; l++) {
        o_blocks[l] = vec4(e[2 * l], e[2 * l + 1]);
    }
}
