// The fill floor of a particle render pass: drawn behind the renderer's own vertex stage
// (render/particle.vert with the pass's defines: the same points, sprites or quads at the same
// sizes and places) with the pass's blend, it writes a constant into every fragment where the pass
// can change the frame and fetches nothing (no atlas, no shading). The render pass costs at least
// this; what it costs above is its fragment stage: the atlas fetch, the rotation, the colour.
//
// A sprite's fragments outside its inscribed circle have opacity 0 in render/particle.frag (the
// rotated tile's corners; the thesis's soft round sprite at its rim): they leave the frame as it
// was under every blend the renderer sets, and a GPU may skip such blends (NVIDIA: writing the
// corners opaque made this floor 1.27 times the fire's render). The floor writes the same
// no-change there, so that it writes the pass's fragments, no more and no fewer. (On an H100
// that cost what discarding them did, 24.73 against 24.74 ms for the fire at 4096², and the
// floor stays 1.14 times the fire's render there: not yet explained.)

#if !defined(FIRE_RAMP) && defined(SPRITES) && (defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES))
in vec2 v_coord;
#endif

layout(location = 0) out vec4 o_color;

// What leaves the frame as it was under the pass's blend (render/particle.frag's outputs at
// opacity 0): 1 for a multiplying blend, 0 for every other.
#ifdef MULTIPLY
#define UNCHANGED vec4(1.0, 1.0, 1.0, 0.0)
#else
#define UNCHANGED vec4(0.0)
#endif

void main() {
    bool inside = true;
#if defined(FIRE_RAMP)
#ifdef FIRE_SOFT
    vec2 d = gl_PointCoord - 0.5;
    inside = dot(d, d) < 0.25;
#endif
#elif defined(SPRITES) && (defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES))
    vec2 d = v_coord - 0.5;
    inside = dot(d, d) <= 0.25;
#elif defined(SPRITES)
    vec2 d = gl_PointCoord - 0.5;
    inside = dot(d, d) <= 0.25;
#endif
    o_color = inside ? vec4(0.02, 0.01, 0.005, 0.1) : UNCHANGED;
}
