// The cost of a texel fetch, for the cost model of `texflow report cost`: every fragment fetches
// FETCHES RGBA32F texels at scattered places (a hash of its coordinates and the fetch number)
// and writes their sum into one RGBA32F target. Against FETCHES = 0 (the write floor), the extra
// time is FETCHES × fragments × the cost of one fetch.

#ifndef FETCHES
#define FETCHES 8
#endif

uniform sampler2D u_source;
uniform int u_log_w;

layout(location = 0) out vec4 o_sum;

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int mask = (1 << u_log_w) - 1;
    vec4 sum = vec4(0.0);
    for (int k = 0; k < FETCHES; k++) {
        // A different far-away texel per fetch (XOR with a power of two, as a sorting network's
        // partners are), so that no two fetches of a fragment share a cache line.
        int i = ((f.y << u_log_w) | f.x) ^ (1 << ((k * 5 + 3) % (2 * u_log_w)));
        sum += texelFetch(u_source, ivec2(i & mask, i >> u_log_w), 0);
    }
    o_sum = sum;
}
