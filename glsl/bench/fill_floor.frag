// The fill floor of a particle render pass: drawn behind the renderer's own vertex stage
// (render/particle.vert with the pass's defines: the same points, sprites or quads at the same
// sizes and places) with the pass's blend, it writes a constant into every fragment where the pass
// can change the frame and fetches nothing (no atlas, no shading). The render pass costs at least
// this; what it costs above is its fragment stage: the atlas fetch, the rotation, the colour.
//
// A sprite's fragments outside its inscribed circle have opacity 0 in render/particle.frag (the
// rotated tile's corners; the thesis's soft round sprite at its rim), which leaves the frame as it
// was under every blend the renderer sets, and a GPU may drop them (NVIDIA does: writing them all
// made this floor 1.27 times the fire's render). The floor leaves them out too.

#if !defined(FIRE_RAMP) && defined(SPRITES) && (defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES))
in vec2 v_coord;
#endif

layout(location = 0) out vec4 o_color;

void main() {
#if defined(FIRE_RAMP)
#ifdef FIRE_SOFT
    vec2 d = gl_PointCoord - 0.5;
    if (dot(d, d) >= 0.25) discard;
#endif
#elif defined(SPRITES) && (defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES))
    vec2 d = v_coord - 0.5;
    if (dot(d, d) > 0.25) discard;
#elif defined(SPRITES)
    vec2 d = gl_PointCoord - 0.5;
    if (dot(d, d) > 0.25) discard;
#endif
    o_color = vec4(0.02, 0.01, 0.005, 0.1);
}
