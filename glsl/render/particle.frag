// The general particle renderer's fragment stage. Points take the keyframe colour; sprites
// (SPRITES) rotate the sprite coordinate (gl_PointCoord, or for QUADS and STRETCHED the corner's
// interpolated coordinate) about the sprite centre by the particle's angle (Latta §3.4.6:
// point sprites are axis-aligned, so the rotation happens on the texture coordinates) and sample
// the atlas tile of the particle's type; the same transform does the tile selection.
// The output suits the blend function the renderer sets:
//   default:      straight colour, alpha (additive SRC_ALPHA, ONE; over SRC_ALPHA, 1 - SRC_ALPHA)
//   PREMULTIPLIED: colour · alpha, alpha (the under operator, 1 - DST_ALPHA, ONE)
//   MULTIPLY:     mix(1, colour, alpha): the destination is multiplied by it (DST_COLOR, ZERO)
// SOFT: soft particles, the opacity scaled by (geometry depth - particle depth) / u_soft, clamped
// to [0, 1], the geometry's view depth fetched at the fragment's pixel (render/geometry_depth.frag).
// FIRE_RAMP: the thesis's fire, coloured by its age ramp and faded in and out over the life
// (additive, so the order of particles is irrelevant); FIRE_SOFT makes each point a round sprite
// whose opacity falls to 0 at its rim, (1 - r^2)^2.
// SHADE_FLOOR: the benchmarks' shading floor, below.

#include "render/shade_floor.glsl"

uniform sampler2D u_atlas;

in vec4 v_color;
in vec2 v_coord;
flat in vec2 v_rotation;
flat in vec2 v_tile;
layout(location = 0) out vec4 o_color;

#ifdef SOFT
uniform sampler2D u_scene_depth; // the drawn geometry's view depth per pixel (1e30: none)
uniform float u_soft;            // metres over which the opacity fades in front of it
in float v_depth;
#endif

#ifdef FIRE_RAMP
#include "render/fire_ramp.glsl"
uniform float u_intensity;
in float v_age;
#endif

// The pass's colour, the blend's input.
vec4 shade() {
#ifdef FIRE_RAMP
    // Fade in over the first tenth of the life (no hard edge at the emitter), then out.
    float fade = smoothstep(0.0, 0.1, v_age) * pow(1.0 - v_age, 1.5);
#ifdef FIRE_SOFT
    vec2 rim = gl_PointCoord * 2.0 - 1.0;
    float k = max(1.0 - dot(rim, rim), 0.0);
    fade *= k * k;
#endif
    return vec4(fire_ramp(v_age), u_intensity * fade);
#endif
    vec4 c = v_color;
#ifdef SPRITES
#if defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES)
    vec2 d = v_coord - 0.5;
#else
    vec2 d = gl_PointCoord - 0.5;
#endif
    vec2 r = vec2(v_rotation.x * d.x - v_rotation.y * d.y, v_rotation.y * d.x + v_rotation.x * d.y);
    vec4 tex = texture(u_atlas, (v_tile + clamp(r + 0.5, 0.0, 1.0)) * 0.5);
    // Outside the tile's inscribed circle a rotated corner would leave the tile: nothing there.
    float inside = dot(r, r) <= 0.25 ? 1.0 : 0.0;
    c = vec4(c.rgb * tex.rgb, c.a * tex.a * inside);
#endif
#ifdef SOFT
    // Soft particles: the opacity falls to 0 as the particle nears the geometry behind it.
    float scene_depth = texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r;
    c.a *= clamp((scene_depth - v_depth) / u_soft, 0.0, 1.0);
#endif
#if defined(PREMULTIPLIED)
    return vec4(c.rgb * c.a, c.a);
#elif defined(MULTIPLY)
    return vec4(mix(vec3(1.0), c.rgb, c.a), c.a);
#else
    return c;
#endif
}

void main() {
    o_color = shade();
#ifdef SHADE_FLOOR
    // The benchmarks' shading floor: every fragment shaded as above, then made the colour that
    // leaves the frame as it was under the pass's blend (1 where it multiplies, else 0).
#ifdef MULTIPLY
    const vec4 UNCHANGED = vec4(1.0, 1.0, 1.0, 0.0);
#else
    const vec4 UNCHANGED = vec4(0.0);
#endif
    o_color = shade_floor(o_color, UNCHANGED);
#endif
}
