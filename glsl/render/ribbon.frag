// The ribbons' colour (render/ribbon.vert): the ends' keyframe colours interpolated along the
// segment, written for the scene's blend as the particles' fragment stage writes it
// (render/particle.frag): straight, PREMULTIPLIED for the under operator, or MULTIPLY.

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
