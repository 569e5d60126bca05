// Latta's odd-even merge sort, "recursion" program (§3.4.4, Fig. 4), on a 2D texture: the 1D
// index is split into u, v before each look-up. Inside merge blocks of u_count * u_step
// elements, m = (i / u_step) mod u_count with 1 <= m <= u_count - 2 compares odd m with m + 1
// (keeps the smaller) and even m with m - 1 (keeps the larger); the rest copy themselves.

#include "common/compare.glsl"
#include "common/precision.glsl"

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_step;
uniform int u_count;

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    vec2 own = texelFetch(u_keys, t, 0).xy;
    int m = (i / u_step) % u_count;
    if (m >= 1 && m <= u_count - 2) {
        bool odd = (m & 1) == 1;
        int j = odd ? i + u_step : i - u_step;
        vec2 other = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
        own = compare_exchange(own, other, odd);
    }
    o_entry = fp_store(vec4(own, 0.0, 0.0));
}
