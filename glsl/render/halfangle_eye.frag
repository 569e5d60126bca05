// Half-angle slicing's eye pass (Kniss et al. 2003; Green 2008): a slice's particles lit by
// the light that reaches them, the transmittance the slices before left in the light buffer
// (bilinear between the four texels around the fragment's point in it):
//   colour = keyframe colour (times the sprite texel) · (ambient + light colour · T).
// u_premultiplied: the output is colour · alpha, alpha for the under operator (the eye looks
// the way the light goes, slices front to back); else straight colour for the over operator.
// SHADE_FLOOR: the benchmarks' shading floor, below.

#include "render/sprite_tile.glsl"
#include "render/shade_floor.glsl"

uniform sampler2D u_atlas;
uniform sampler2D u_light;        // transmittance in r
uniform vec3 u_light_colour;
uniform vec3 u_ambient;
uniform bool u_premultiplied;

// The transmittance at `uv` (the light buffer's [0, 1]²), bilinear between the four nearest
// texel centres, each fetched with texelFetch; outside the buffer the light is unattenuated (1).
// A nearest fetch shows each light texel's edge as a stripe where the smoke is dense.
float transmittance_at(ivec2 texel, ivec2 size) {
    bool inside = all(greaterThanEqual(texel, ivec2(0))) && all(lessThan(texel, size));
    return inside ? texelFetch(u_light, texel, 0).r : 1.0;
}

float light_bilinear(vec2 uv) {
    ivec2 size = textureSize(u_light, 0);
    vec2 x = uv * vec2(size) - 0.5;
    vec2 f = x - floor(x);
    ivec2 t = ivec2(floor(x));
    float a = mix(transmittance_at(t, size), transmittance_at(t + ivec2(1, 0), size), f.x);
    float b = mix(transmittance_at(t + ivec2(0, 1), size), transmittance_at(t + ivec2(1, 1), size), f.x);
    return mix(a, b, f.y);
}

in vec4 v_color;
in vec2 v_coord;
in vec2 v_light;
flat in vec2 v_rotation;
flat in vec2 v_tile;
layout(location = 0) out vec4 o_color;

void main() {
    vec4 c = v_color;
#ifdef SPRITES
    vec4 tex = sprite_texel(u_atlas, v_coord, v_rotation, v_tile);
    c = vec4(c.rgb * tex.rgb, c.a * tex.a);
#endif
    float transmittance = light_bilinear(v_light);
    vec3 lit = c.rgb * (u_ambient + u_light_colour * transmittance);
    o_color = u_premultiplied ? vec4(lit * c.a, c.a) : vec4(lit, c.a);
#ifdef SHADE_FLOOR
    // The benchmarks' shading floor: 0 leaves the target as it was under the pass's blend.
    o_color = shade_floor(o_color, vec4(0.0));
#endif
}
