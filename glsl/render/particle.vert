// The general particle renderer's vertex stage. Where the state comes from is a compile-time
// choice:
//   VERTEX_BUFFER defined: attributes 0 and 1 of a buffer the state textures were copied into on
//     the GPU (glReadPixels into a pixel-pack buffer; UberFlow §4.7, Latta §3.4.5);
//   otherwise: vertex texture fetch of the particle's texel (thesis Listing 3).
// What is drawn per particle:
//   default: one vertex, a point or a point sprite of gl_PointSize pixels;
//   QUADS: six vertices (two triangles) by vertex replication, Latta §3.4.5: "the static vertex
//     data contains the index of a particle to be read from the texture; it can already be
//     replicated": vertex gl_VertexID fetches particle gl_VertexID / 6 and moves to corner
//     gl_VertexID % 6 of a camera-facing square of the point sprite's size in pixels;
//   TRIANGLES: three vertices, the equilateral triangle around the sprite's inscribed circle
//     (Latta §3.4.5-3.4.6: "point sprites, triangles or quads"; half a quad's six vertices,
//     3·sqrt(3)/4 = 1.3 times its pixels);
//   STRETCHED: the same six vertices, the square stretched along the particle's screen-space
//     motion from where it was u_stretch seconds ago, x - v·u_stretch, to where it is (motion
//     blur): length |v_screen|·u_stretch + size, width size. No point size limit applies.
// Everything after the fetch is shared, so both paths draw bit-identical images.
// LOOKUP defined (texture fetch only; Latta §3.4.4's index lookup): vertex k draws the particle
// at sorted position k / VERTICES, reading its identifier from the sort texture u_sorted
// (sort/sorted_id.glsl, with the sort's PACKED and ID_TABLE) and fetching the state there: the
// same texels a gather would have copied, so the same image, without the gather pass.
// FIRE_RAMP defined: the thesis's fire (Listing 3): the statics are the fire's velocities, whose
// w is the wait; the total life is u_max_age - wait and the fragment stage colours the relative
// age by the fire's ramp (render/fire_ramp.glsl); one size, no sprite.
// SOFT defined: the particle's view depth goes to the fragment stage (soft particles).
// SPRITES defined: the size is scaled by the particle's type and its size over life, and the
// fragment stage textures the sprite from the atlas tile of its type, rotated by
// angle0 + speed · age (render/sprite.glsl), or with ROTATE_SPIN by angle0 + the angle the
// simulation integrated from the particle's spin (w of the spin texture; texture fetch only).

#include "common/state.glsl"
#include "render/keyframes.glsl"
#include "render/sprite.glsl"

#ifdef VERTEX_BUFFER
layout(location = 0) in vec4 a_position;
layout(location = 1) in vec4 a_static;
#else
uniform sampler2D u_position;
uniform sampler2D u_static;
uniform int u_width;
#endif
#ifdef LOOKUP
uniform sampler2D u_sorted;      // the sort's (key, id) entries
uniform int u_sort_width;        // entries per row of the sort
#include "sort/sorted_id.glsl"
#endif
#ifdef ROTATE_SPIN
uniform sampler2D u_spin;        // spinning spheres: (angular velocity, angle about z)
#endif
#ifdef STRETCHED
uniform sampler2D u_motion;      // velocities, or (u_motion_previous) Verlet's previous positions
uniform int u_motion_previous;
uniform float u_motion_dt;       // the step between previous and current positions
uniform float u_stretch;         // exposure in seconds
#endif

uniform mat4 u_view_proj;
uniform vec2 u_viewport;         // frame size in pixels
uniform float u_point_size;
uniform float u_intensity;

out vec4 v_color;         // straight (not premultiplied) colour and opacity
out vec2 v_coord;         // quads: the corner's sprite coordinate, as gl_PointCoord (y down)
flat out vec2 v_rotation; // cos and sin of the sprite's screen-space angle
flat out vec2 v_tile;     // atlas tile origin in tile units
#ifdef SOFT
out float v_depth;        // the particle's view depth (clip w of its centre), for soft particles
#endif
#ifdef FIRE_RAMP
uniform float u_max_age;  // the fire's cycle: life plus wait
out float v_age;          // relative age, for the fire's ramp
#endif

#if defined(QUADS) || defined(STRETCHED)
const int VERTICES = 6;
// The two triangles' corners, in units of the size, y up.
const vec2 CORNERS[6] = vec2[6](vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(0.5, 0.5),
                                vec2(-0.5, -0.5), vec2(0.5, 0.5), vec2(-0.5, 0.5));
#elif defined(TRIANGLES)
const int VERTICES = 3;
// The equilateral triangle around the sprite's inscribed circle (radius 0.5): corners at
// distance 1 from the centre, in units of the size, y up.
const vec2 CORNERS[3] = vec2[3](vec2(0.0, 1.0), vec2(-0.8660254, -0.5), vec2(0.8660254, -0.5));
#else
const int VERTICES = 1;
#endif

void main() {
#ifdef VERTEX_BUFFER
    vec4 p = a_position;
    vec4 s = a_static;
#else
#ifdef LOOKUP
    int index = sorted_id(u_sorted, u_sort_width, gl_VertexID / VERTICES);
#else
    int index = gl_VertexID / VERTICES;
#endif
    ivec2 t = particle_texel(index, u_width);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 s = texelFetch(u_static, t, 0);
#endif
    v_coord = vec2(0.5);
    // Drawn only when alive (remaining life above 0: not dead, not unborn) and at a finite
    // position (dead particles sit at +inf). Everything else is moved outside the clip volume.
    // Finiteness is tested on the bits: float comparisons with NaN are not reliable under
    // drivers' fast-math (NVIDIA drew NaN particles with a comparison-only test).
    if (!all_finite(p) || !(p.w > 0.0)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        gl_PointSize = 1.0;
        v_color = vec4(0.0);
        v_rotation = vec2(1.0, 0.0);
        v_tile = vec2(0.0);
#ifdef FIRE_RAMP
        v_age = 1.0;
#endif
#ifdef SOFT
        v_depth = 0.0;
#endif
        return;
    }
#ifdef FIRE_RAMP
    float life = max(u_max_age - s.w, 1e-6);
    v_age = clamp(1.0 - p.w / life, 0.0, 1.0);
    v_color = vec4(0.0);
    v_rotation = vec2(1.0, 0.0);
    v_tile = vec2(0.0);
    gl_Position = u_view_proj * vec4(p.xyz, 1.0);
    gl_PointSize = u_point_size;
    return;
#endif
    float age = relative_age(p.w, s.z);
    int type = clamp(int(s.y + 0.5), 0, 3);
    // The type's tint and scale at the particle's birth (render/birth_curves.glsl).
    float birth = birth_time(p.w, s.z, s.x);
    vec4 c = keyframe_color_of(type, age) * type_tint(type, birth);
    v_color = vec4(c.rgb, clamp(c.a * u_intensity, 0.0, 1.0));
    float age_s = age_seconds(p.w, s.z, s.x);
#ifdef USER_COLOR
    // render.color: the user's expression of the keyframes' colour and the user states, at the
    // particle's texel (texture fetch only; src/render/user_color.rs writes user_color).
    v_color = clamp(user_color(t, v_color, p.xyz, p.w, type, age_s), 0.0, 1.0);
#endif
    float angle = sprite_angle(type, s.w, age_s);
#ifdef ROTATE_SPIN
    // Counter-clockwise on screen for a camera on +z looking at -z (azimuth 0).
    angle = 6.28318530718 * s.w + texelFetch(u_spin, t, 0).w;
#endif
#ifdef USER_ROTATION
    // render.rotation: the user's expression of this angle and the user states, in degrees.
    angle = radians(user_rotation(t, degrees(angle), p.xyz, p.w, type, age_s));
#endif
    v_rotation = vec2(cos(angle), sin(angle));
    int tile = flipbook_tile(type, age, age_s);
    v_tile = vec2(float(tile & 1), float(tile >> 1));
    vec4 clip = u_view_proj * vec4(p.xyz, 1.0);
#ifdef SOFT
    v_depth = clip.w;
#endif
#ifdef SPRITES
    float size = u_point_size * random_size(type, s.w) * type_scale(type, birth) * size_scale(type, age);
#else
    float size = u_point_size * random_size(type, s.w);
#endif
#ifdef USER_SIZE
    // render.size: the user's expression of this size and the user states, in pixels.
    size = max(user_size(t, size, p.xyz, p.w, type, age_s), 0.0);
#endif
    gl_PointSize = size;
#if defined(QUADS) || defined(STRETCHED) || defined(TRIANGLES)
    vec2 corner = CORNERS[gl_VertexID % VERTICES];
    v_coord = vec2(corner.x + 0.5, 0.5 - corner.y);
#endif
#if defined(QUADS) || defined(TRIANGLES)
    // A square of `size` pixels around the projected centre: NDC spans 2 over the viewport.
    clip.xy += corner * size * 2.0 / u_viewport * clip.w;
#elif defined(STRETCHED)
    // The velocity: the motion texture, or (Verlet) the difference of the positions.
    vec4 m = texelFetch(u_motion, t, 0);
    vec3 v = u_motion_previous != 0 ? (p.xyz - m.xyz) / u_motion_dt : m.xyz;
    if (!all_finite(vec4(v, 0.0))) {
        v = vec3(0.0);
    }
    // Head and tail in window pixels; a tail behind the eye is not stretched to.
    vec2 head = (clip.xy / clip.w * 0.5 + 0.5) * u_viewport;
    vec4 tail_clip = u_view_proj * vec4(p.xyz - v * u_stretch, 1.0);
    vec2 tail = tail_clip.w > 0.0 ? (tail_clip.xy / tail_clip.w * 0.5 + 0.5) * u_viewport : head;
    vec2 d = head - tail;
    float len = length(d);
    vec2 along = len > 1e-4 ? d / len : vec2(1.0, 0.0);
    vec2 across = vec2(-along.y, along.x);
    // The streak from tail to head, capped by half the size at both ends; the sprite is laid
    // along the motion (its own rotation does not apply).
    vec2 pixel = mix(tail, head, corner.x + 0.5) + along * corner.x * size + across * corner.y * size;
    clip.xy = (pixel / u_viewport * 2.0 - 1.0) * clip.w;
    v_rotation = vec2(1.0, 0.0);
#endif
    gl_Position = clip;
}
