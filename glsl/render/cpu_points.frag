// The CPU engine's points: the keyframe colour in the form the blend function needs, as
// render/particle.frag writes it for points:
//   default:       straight colour, alpha (additive; alpha over)
//   PREMULTIPLIED: colour · alpha, alpha (the under operator, front to back)
//   MULTIPLY:      mix(1, colour, alpha) (multiplicative)

in vec4 v_color;
layout(location = 0) out vec4 o_color;

void main() {
    vec4 c = v_color;
#if defined(PREMULTIPLIED)
    o_color = vec4(c.rgb * c.a, c.a);
#elif defined(MULTIPLY)
    o_color = vec4(mix(vec3(1.0), c.rgb, c.a), c.a);
#else
    o_color = c;
#endif
}
