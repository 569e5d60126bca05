// Sort keys and identifiers (UberFlow §4.3.1): one pass writes for every particle its key and a
// unique identifier into R and G (PACKED: two consecutive entries per RGBA texel, §4.3.3).
// Keys: the signed distance to the viewer (u_direction = +1 front to back, -1 back to front), or
// with KEY_GRID the index of the particle's cell in a lattice of mesh size u_grid_spacing, cells
// enumerated in z, y, x order, or with KEY_AGE the particle's age (total life from the static
// texture minus the remaining life) times u_direction * u_age_sign: u_age_sign = +1 puts the
// youngest where the nearest would be (on top), -1 the oldest; or with KEY_AXIS the position
// along u_axis, dot(x, u_axis) (half-angle slicing, Kniss et al. 2003). Dead particles (u_cull_dead and life <= 0) get +inf; entries past
// the particle count are padding with a NaN key, which sorts after everything (ids break ties,
// so padding lands after every real particle, NaN keys included).
// Identifiers are the particle index, or with ID_TABLE the paper's 24-bit-safe enumeration
// looked up from a texture.
// REKEY (Latta's sort spread over frames, §3.4.4): keep the order the sort has reached and only
// recompute each entry's key from its particle's new position, so the next frames' passes start
// from an almost sorted sequence. Plain identifiers only.

#include "common/precision.glsl"

uniform sampler2D u_position;
uniform int u_state_width;
uniform int u_count;
uniform int u_sort_width;
uniform bool u_cull_dead;
uniform vec3 u_eye;
uniform float u_direction;
uniform vec3 u_grid_origin;
uniform float u_grid_spacing;
uniform ivec3 u_grid_dims;
#ifdef KEY_AGE
uniform sampler2D u_static;
uniform float u_age_sign;
#endif
#ifdef KEY_AXIS
uniform vec3 u_axis;
#endif
#ifdef ID_TABLE
uniform sampler2D u_id_table;
uniform int u_id_table_width;
#endif

layout(location = 0) out vec4 o_entry;

float identifier(int i) {
#ifdef ID_TABLE
    return texelFetch(u_id_table, ivec2(i % u_id_table_width, i / u_id_table_width), 0).r;
#else
    return float(i);
#endif
}

#ifdef REKEY
uniform sampler2D u_sorted;
#endif

vec2 entry(int i) {
#ifdef REKEY
#ifdef PACKED
    vec4 pair = texelFetch(u_sorted, ivec2((i % u_sort_width) / 2, i / u_sort_width), 0);
    float id = (i & 1) == 0 ? pair.y : pair.w;
#else
    float id = texelFetch(u_sorted, ivec2(i % u_sort_width, i / u_sort_width), 0).y;
#endif
    i = int(id);
#else
    float id = identifier(i);
#endif
    if (i >= u_count) return vec2(uintBitsToFloat(0x7fc00000u), id);
    vec4 p = texelFetch(u_position, ivec2(i % u_state_width, i / u_state_width), 0);
    if (u_cull_dead && !(p.w > 0.0)) return vec2(uintBitsToFloat(0x7f800000u), id);
#ifdef KEY_GRID
    ivec3 c = clamp(ivec3(floor((p.xyz - u_grid_origin) / u_grid_spacing)), ivec3(0), u_grid_dims - 1);
    return vec2(float((c.z * u_grid_dims.y + c.y) * u_grid_dims.x + c.x), id);
#elif defined(KEY_AGE)
    float total = texelFetch(u_static, ivec2(i % u_state_width, i / u_state_width), 0).z;
    return vec2(u_direction * u_age_sign * (total - p.w), id);
#elif defined(KEY_AXIS)
    return vec2(dot(p.xyz, u_axis), id);
#else
    return vec2(u_direction * distance(p.xyz, u_eye), id);
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
#ifdef PACKED
    int i = t.y * u_sort_width + 2 * t.x;
    o_entry = fp_store(vec4(entry(i), entry(i + 1)));
#else
    o_entry = fp_store(vec4(entry(t.y * u_sort_width + t.x), 0.0, 0.0));
#endif
}
