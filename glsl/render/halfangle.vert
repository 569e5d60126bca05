// Half-angle slicing's vertex stage (Kniss et al. 2003; Green 2008), both passes of a slice:
// particle u_first + gl_VertexID / 6 of the state sorted along the half-angle vector, fetched
// from its texel, coloured by its keyframes and sized as the general renderer sizes it
// (render/particle.vert with QUADS, whose corners and size this repeats), as a quad of two
// triangles.
//   default: the eye pass. A camera-facing quad of `size` pixels; each corner also carries
//     where it lies in the light buffer (v_light, in [0, 1]²): the corner's point in the scene,
//     on the quad in the camera's plane (a size of s pixels at clip depth w spans
//     s · 2w / (height · P11) scene units), seen along the light.
//   LIGHT_PASS: the same particle as a square facing the light, of the same size in scene units,
//     in the light buffer's orthographic view; its opacity is scaled by the light's density.
// SPRITES: sizes scaled by type and size over life, the atlas tile and angle passed on.

#include "common/state.glsl"
#include "render/keyframes.glsl"
#include "render/sprite.glsl"

uniform sampler2D u_position;
uniform sampler2D u_static;
uniform int u_width;
uniform int u_first;             // the slice's first particle in sorted order

uniform mat4 u_view_proj;
uniform vec2 u_viewport;         // frame size in pixels
uniform float u_proj_y;          // the projection's P11 = 1 / tan(fov / 2)
uniform vec3 u_camera_right;     // the camera's axes in the scene
uniform vec3 u_camera_up;
uniform mat4 u_light_view;       // scene to the light buffer's [-1, 1]² (orthographic)
uniform float u_light_scale;     // light-buffer NDC per scene unit: 1 / extent
uniform float u_point_size;
uniform float u_intensity;
uniform float u_density;

out vec4 v_color;         // straight colour and opacity
out vec2 v_coord;         // the corner's sprite coordinate (y down)
out vec2 v_light;         // eye pass: where the fragment lies in the light buffer
flat out vec2 v_rotation; // cos and sin of the sprite's angle
flat out vec2 v_tile;     // atlas tile origin in tile units

const vec2 CORNERS[6] = vec2[6](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.5, 0.5),
                                vec2(-0.5, -0.5), vec2(0.5, 0.5), vec2(-0.5, 0.5));

void main() {
    int index = u_first + gl_VertexID / 6;
    ivec2 t = particle_texel(index, u_width);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 s = texelFetch(u_static, t, 0);
    v_rotation = vec2(1.0, 0.0);
    v_tile = vec2(0.0);
    v_light = vec2(0.5);
    vec2 corner = CORNERS[gl_VertexID % 6];
    v_coord = vec2(corner.x + 0.5, 0.5 - corner.y);
    // Dead, unborn and non-finite particles are moved outside the clip volume.
    if (!all_finite(p) || !(p.w > 0.0)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        v_color = vec4(0.0);
        return;
    }
    float age = relative_age(p.w, s.z);
    int type = clamp(int(s.y + 0.5), 0, 3);
    float birth = birth_time(p.w, s.z, s.x);
    vec4 c = keyframe_color_of(type, age) * type_tint(type, birth);
    v_color = vec4(c.rgb, clamp(c.a * u_intensity, 0.0, 1.0));
    float age_s = age_seconds(p.w, s.z, s.x);
    float angle = sprite_angle(type, s.w, age_s);
    v_rotation = vec2(cos(angle), sin(angle));
    int tile = flipbook_tile(type, age, age_s);
    v_tile = vec2(float(tile & 1), float(tile >> 1));
#ifdef SPRITES
    float size = u_point_size * random_size(type, s.w) * type_scale(type, birth) * size_scale(type, age);
#else
    float size = u_point_size * random_size(type, s.w);
#endif
    vec4 clip = u_view_proj * vec4(p.xyz, 1.0);
    float world = size * 2.0 * abs(clip.w) / (u_viewport.y * u_proj_y);
    vec2 light = (u_light_view * vec4(p.xyz, 1.0)).xy;
#ifdef LIGHT_PASS
    v_color.a = clamp(v_color.a * u_density, 0.0, 1.0);
    gl_Position = vec4(light + corner * world * u_light_scale, 0.0, 1.0);
#else
    vec3 x = p.xyz + (u_camera_right * corner.x + u_camera_up * corner.y) * world;
    v_light = (u_light_view * vec4(x, 1.0)).xy * 0.5 + 0.5;
    clip.xy += corner * size * 2.0 / u_viewport * clip.w;
    gl_Position = clip;
#endif
}
