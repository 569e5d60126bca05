// Pairing is not symmetric (A may pick B while B picks C): a partner is kept only if it picked
// this particle too, so that both sides of every collision apply the same impulse and momentum
// is conserved. Output: (partner index or -1, distance), into an RG32F target (whether it was
// mutual and the partner before the check are read back from it and the detection's output).

uniform sampler2D u_partner;
uniform int u_width;

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
    o_partner = vec2(mutual ? p.x : -1.0, p.y);
}
