// The slices' chain floor of a lit render (half-angle slicing): each slice's eye pass reads the
// light buffer the light pass before it wrote, and each light pass overwrites what the eye pass
// before it read. The floor keeps those dependencies and nothing else: READ (an eye pass) fetches
// one texel of the light buffer, and every pass writes one pixel that its blend leaves as it was
// (opacity and colour 0 under the over, under and light blends alike).

layout(location = 0) out vec4 o_color;

// 0, from a uniform: a constant would let the compiler drop the fetch and with it the dependency.
uniform float u_zero;

#ifdef READ
uniform sampler2D u_read;
#endif

void main() {
#ifdef READ
    o_color = u_zero * texelFetch(u_read, ivec2(0), 0);
#else
    o_color = vec4(u_zero);
#endif
}
