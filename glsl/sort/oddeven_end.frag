// Latta's odd-even merge sort, "end" program (§3.4.4, Fig. 4): element i compares with i + step
// (keeps the smaller) or i - step (keeps the larger), by the parity of i / step.

#include "common/compare.glsl"
#include "common/precision.glsl"

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_step;

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    bool lower = ((i / u_step) & 1) == 0;
    int j = lower ? i + u_step : i - u_step;
    vec2 own = texelFetch(u_keys, t, 0).xy;
    vec2 other = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
    o_entry = fp_store(vec4(compare_exchange(own, other, lower), 0.0, 0.0));
}
