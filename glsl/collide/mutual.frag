// Pairing is not symmetric (A may pick B while B picks C): a partner is kept only if it picked
// this particle too, so that both sides of every collision apply the same impulse and momentum
// is conserved. Reads the detection's lanes (collide/detect.frag: the partners and distances of
// columns 4x .. 4x + 3 at texel x). Output: (partner index or -1, distance), into an RG32F
// target (whether it was mutual and the partner before the check are read back from it and the
// detection's output).

uniform sampler2D u_partners;
uniform sampler2D u_distances;
uniform int u_width;

layout(location = 0) out vec2 o_partner;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    ivec2 lane = ivec2(t.x / 4, t.y);
    float p = texelFetch(u_partners, lane, 0)[t.x % 4];
    float d = texelFetch(u_distances, lane, 0)[t.x % 4];
    float self_index = float(t.y * u_width + t.x);
    bool mutual = false;
    if (p >= 0.0) {
        int j = int(p);
        ivec2 at = ivec2(j % u_width, j / u_width);
        mutual = texelFetch(u_partners, ivec2(at.x / 4, at.y), 0)[at.x % 4] == self_index;
    }
    o_partner = vec2(mutual ? p : -1.0, d);
}
