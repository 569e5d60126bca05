// Half-angle slicing's light pass (Kniss et al. 2003; Green 2008): a slice's particles, seen
// from the light, attenuate the light buffer. The output is the opacity in every channel; the
// blend (ZERO, ONE_MINUS_SRC_COLOR) multiplies the stored transmittance by 1 - opacity.
// SHADE_FLOOR: the benchmarks' shading floor, below.

#include "render/sprite_tile.glsl"
#include "render/shade_floor.glsl"

uniform sampler2D u_atlas;

in vec4 v_color;
in vec2 v_coord;
in vec2 v_light;
flat in vec2 v_rotation;
flat in vec2 v_tile;
layout(location = 0) out vec4 o_color;

void main() {
    float a = v_color.a;
#ifdef SPRITES
    a *= sprite_texel(u_atlas, v_coord, v_rotation, v_tile).a;
#endif
    o_color = vec4(a);
#ifdef SHADE_FLOOR
    // The benchmarks' shading floor: 0 leaves the target as it was under the pass's blend.
    o_color = shade_floor(o_color, vec4(0.0));
#endif
}
