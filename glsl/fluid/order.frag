// The coherent re-sort's check (src/sim/fluid/resort.rs): 1 where an entry is greater than its
// successor, for the tally to count; the step falls back to the full sort if any is found.

#include "common/compare.glsl"

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_count;

layout(location = 0) out vec4 o_flag;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    float bad = 0.0;
    if (i + 1 < u_count) {
        int j = i + 1;
        vec2 own = texelFetch(u_keys, t, 0).xy;
        vec2 next = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
        bad = entry_less(next, own) ? 1.0 : 0.0;
    }
    o_flag = vec4(bad, 0.0, 0.0, 1.0);
}
