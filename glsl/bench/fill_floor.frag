// The fill floor of a particle render pass: drawn behind the renderer's own vertex stage
// (render/particle.vert with the pass's defines: the same points, sprites or quads at the same
// sizes and places) with the pass's blend, every fragment of the pass is rasterized, shaded by
// a constant and blended, and fetches nothing (no atlas, no shading). The render pass costs at
// least this; what it costs above is its fragment stage and what its colours make the blend
// write.
//
// The constant leaves the frame as it was under the pass's blend (opacity 0): a GPU may skip a
// blend that changes nothing, and the pass's own colours decide how many of its blends that is
// (NVIDIA H100, the fire at 2048²: its render takes 3.68 ms at intensity 0, 5.41 at its own
// 0.08 and 5.77 at 1.0), so a floor that wrote visible colour was no bound (6.19 ms, 1.14 times
// the render). Written unchanged, the floor is the least any pass drawing these fragments costs.

layout(location = 0) out vec4 o_color;

// CONNECTED: behind a surface's or strands' vertex stage (render/cloth.vert, strand.vert), opaque
// with a depth write: a constant written where the pass writes, and dropped where the pass drops
// (a primitive with a non-finite vertex), so that the floor draws no fragment the pass does not.
#ifdef CONNECTED
in float v_ok;
#endif

// What leaves the frame as it was under the pass's blend (render/particle.frag's outputs at
// opacity 0): 1 for a multiplying blend, 0 for every other.
#ifdef MULTIPLY
#define UNCHANGED vec4(1.0, 1.0, 1.0, 0.0)
#else
#define UNCHANGED vec4(0.0)
#endif

void main() {
#ifdef CONNECTED
    if (v_ok < 0.999) {
        discard;
    }
#endif
    o_color = UNCHANGED;
}
