// The fetch floor of a pass (`bench scene`): for one draw of a phase, a pass into targets of the
// same formats and size over the same viewport that fetches each texture the draw bound once, at
// the fragment's own texel (clamped to the texture's size, given as a uniform; a 3D texture at
// layer u_layer): the same textures the draw read where they still live, so the same data,
// compressed or not as the driver keeps it. It writes zeros, the cheapest bytes to write, unless the sum of the fetches
// equals u_sentinel (NaN at run time: never), so that no fetch can be left out and no write costs
// more than the pass's own. u_reveal writes the sum everywhere instead (a test's view of the
// fetches). No other arithmetic: a pass that reads each of its inputs at least once and writes
// the same bytes costs at least this.
//
// WALK: the draw walked the cells around each live particle (collide/cells.glsl: the exact
// detection's count, DEM, the fluid, the pair exchange); the floor reads the particle's position
// (u_position, the cell-sorted layout) and, for a live one only (as those passes stop at a dead
// one), its other textures and the walk over the same cells, with the same keys, table and
// uniforms, fetching each visited neighbour's position once, which every such pass reads of every
// neighbour it visits. The keys, table and positions are not among the F2 reads then: the walk
// reads them where the pass does.
//
// BLOCK: the draw was a block reduction (a tally's level, collide/tally.frag) whose fragments
// read BLOCK × BLOCK texels each; the floor fetches each texture at all of them.
//
// F2, U2, F3, U3: how many 2D float, 2D unsigned, 3D float and 3D unsigned textures the draw
// bound (at most 16, 4, 4, 2); TARGETS: its render targets (1 to 8); UINT: unsigned targets.

#ifndef TARGETS
#define TARGETS 1
#endif
#ifndef F2
#define F2 0
#endif
#ifndef U2
#define U2 0
#endif
#ifndef F3
#define F3 0
#endif
#ifndef U3
#define U3 0
#endif

uniform int u_layer;

#ifdef WALK
#include "collide/cells.glsl"
vec4 walked = vec4(0.0);

bool is_partner(vec4 q) {
    return true;
}

void partner_work(int j, ivec2 tj, vec4 q) {
    walked += q;
}
#endif
uniform float u_sentinel;
uniform bool u_reveal;

#ifdef UINT
layout(location = 0) out uvec4 o_targets[TARGETS];
#else
layout(location = 0) out vec4 o_targets[TARGETS];
#endif

// Each texture's size comes as a uniform, not from textureSize: on NVIDIA a texture query per
// fetch made this floor 1.6 times slower than the passes it floors (an H100 at 1024², cloth's
// and hair's integration), which read the state unclamped.
uniform ivec4 u_f2_size[16];
uniform ivec4 u_u2_size[4];
uniform ivec4 u_f3_size[4];
uniform ivec4 u_u3_size[2];
#define FETCH2(s, n) texelFetch(s, min(p, n.xy - 1), 0)
#define FETCH3(s, n) texelFetch(s, min(ivec3(p, u_layer), n.xyz - 1), 0)
#if F2 > 0
uniform sampler2D u_f2_0;
#endif
#if F2 > 1
uniform sampler2D u_f2_1;
#endif
#if F2 > 2
uniform sampler2D u_f2_2;
#endif
#if F2 > 3
uniform sampler2D u_f2_3;
#endif
#if F2 > 4
uniform sampler2D u_f2_4;
#endif
#if F2 > 5
uniform sampler2D u_f2_5;
#endif
#if F2 > 6
uniform sampler2D u_f2_6;
#endif
#if F2 > 7
uniform sampler2D u_f2_7;
#endif
#if F2 > 8
uniform sampler2D u_f2_8;
#endif
#if F2 > 9
uniform sampler2D u_f2_9;
#endif
#if F2 > 10
uniform sampler2D u_f2_10;
#endif
#if F2 > 11
uniform sampler2D u_f2_11;
#endif
#if F2 > 12
uniform sampler2D u_f2_12;
#endif
#if F2 > 13
uniform sampler2D u_f2_13;
#endif
#if F2 > 14
uniform sampler2D u_f2_14;
#endif
#if F2 > 15
uniform sampler2D u_f2_15;
#endif
#if U2 > 0
uniform usampler2D u_u2_0;
#endif
#if U2 > 1
uniform usampler2D u_u2_1;
#endif
#if U2 > 2
uniform usampler2D u_u2_2;
#endif
#if U2 > 3
uniform usampler2D u_u2_3;
#endif
#if F3 > 0
uniform sampler3D u_f3_0;
#endif
#if F3 > 1
uniform sampler3D u_f3_1;
#endif
#if F3 > 2
uniform sampler3D u_f3_2;
#endif
#if F3 > 3
uniform sampler3D u_f3_3;
#endif
#if U3 > 0
uniform usampler3D u_u3_0;
#endif
#if U3 > 1
uniform usampler3D u_u3_1;
#endif

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 f = vec4(0.0);
    uvec4 u = uvec4(0u);
#ifdef WALK
    // The particle the pass's fragment here took (in the walk's order: collide/sorted_keys.glsl).
    int self = walk_index(p);
    vec4 own = texelFetch(u_position, key_texel(self), 0);
    f += own;
    if (own.w > 0.0) {
#endif
#ifdef BLOCK
    // A block reduction (collide/tally.frag): each fragment read BLOCK × BLOCK texels of its
    // input, at its own pixel times BLOCK plus (i, j); the floor reads them all too.
    ivec2 pixel = p;
    for (int b = 0; b < BLOCK * BLOCK; b++) {
    p = pixel * BLOCK + ivec2(b % BLOCK, b / BLOCK);
#endif
#if F2 > 0
    f += FETCH2(u_f2_0, u_f2_size[0]);
#endif
#if F2 > 1
    f += FETCH2(u_f2_1, u_f2_size[1]);
#endif
#if F2 > 2
    f += FETCH2(u_f2_2, u_f2_size[2]);
#endif
#if F2 > 3
    f += FETCH2(u_f2_3, u_f2_size[3]);
#endif
#if F2 > 4
    f += FETCH2(u_f2_4, u_f2_size[4]);
#endif
#if F2 > 5
    f += FETCH2(u_f2_5, u_f2_size[5]);
#endif
#if F2 > 6
    f += FETCH2(u_f2_6, u_f2_size[6]);
#endif
#if F2 > 7
    f += FETCH2(u_f2_7, u_f2_size[7]);
#endif
#if F2 > 8
    f += FETCH2(u_f2_8, u_f2_size[8]);
#endif
#if F2 > 9
    f += FETCH2(u_f2_9, u_f2_size[9]);
#endif
#if F2 > 10
    f += FETCH2(u_f2_10, u_f2_size[10]);
#endif
#if F2 > 11
    f += FETCH2(u_f2_11, u_f2_size[11]);
#endif
#if F2 > 12
    f += FETCH2(u_f2_12, u_f2_size[12]);
#endif
#if F2 > 13
    f += FETCH2(u_f2_13, u_f2_size[13]);
#endif
#if F2 > 14
    f += FETCH2(u_f2_14, u_f2_size[14]);
#endif
#if F2 > 15
    f += FETCH2(u_f2_15, u_f2_size[15]);
#endif
#if U2 > 0
    u += FETCH2(u_u2_0, u_u2_size[0]);
#endif
#if U2 > 1
    u += FETCH2(u_u2_1, u_u2_size[1]);
#endif
#if U2 > 2
    u += FETCH2(u_u2_2, u_u2_size[2]);
#endif
#if U2 > 3
    u += FETCH2(u_u2_3, u_u2_size[3]);
#endif
#if F3 > 0
    f += FETCH3(u_f3_0, u_f3_size[0]);
#endif
#if F3 > 1
    f += FETCH3(u_f3_1, u_f3_size[1]);
#endif
#if F3 > 2
    f += FETCH3(u_f3_2, u_f3_size[2]);
#endif
#if F3 > 3
    f += FETCH3(u_f3_3, u_f3_size[3]);
#endif
#if U3 > 0
    u += FETCH3(u_u3_0, u_u3_size[0]);
#endif
#if U3 > 1
    u += FETCH3(u_u3_1, u_u3_size[1]);
#endif
#ifdef BLOCK
    }
#endif
#ifdef WALK
    search_around(self, own.xyz);
    f += walked;
    }
#endif
    vec4 sum = f + uintBitsToFloat(u);
    bool show = (sum.x + sum.y + sum.z + sum.w == u_sentinel) != u_reveal;
    for (int i = 0; i < TARGETS; i++) {
#ifdef UINT
        o_targets[i] = show ? u + floatBitsToUint(f) : uvec4(0u);
#else
        o_targets[i] = show ? sum : vec4(0.0);
#endif
    }
}
