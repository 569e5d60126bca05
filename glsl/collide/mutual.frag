// Pairing is not symmetric (A may pick B while B picks C): a partner is kept only if it picked
// this particle too, so that both sides of every collision apply the same impulse and momentum
// is conserved. Output: (partner index or -1, distance), into an RG32F target (whether it was
// mutual and the partner before the check are read back from it and the detection's output).
// FIRST_ID (the first lattice, when the staggered one reads the state through both sorts): the
// partner is written as its texel in the state the first sort read (sort/first_id.glsl), where
// the response reads it.

uniform sampler2D u_partner;
uniform int u_width;
#ifdef FIRST_ID
#include "sort/first_id.glsl"
#endif

layout(location = 0) out vec2 o_partner;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_partner, t, 0);
    float self_index = float(t.y * u_width + t.x);
    bool mutual = false;
    if (p.x >= 0.0) {
        int j = int(p.x);
        vec4 q = texelFetch(u_partner, ivec2(j % u_width, j / u_width), 0);
        mutual = q.x == self_index;
    }
#ifdef FIRST_ID
    float partner = mutual ? float(first_id(int(p.x))) : -1.0;
#else
    float partner = mutual ? p.x : -1.0;
#endif
    o_partner = vec2(partner, p.y);
}
