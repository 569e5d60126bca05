// The strands' shading: a thin cylinder's diffuse term (Kajiya and Kay: the sine of the angle
// between the tangent and the light, sqrt(1 - (t·l)²)) plus an ambient term, in the scene's
// colour. Opaque, with a depth write.

uniform vec3 u_light;  // unit vector towards the light
uniform vec3 u_color;
uniform float u_ambient;

in vec3 v_tangent;
in float v_ok;
layout(location = 0) out vec4 o_color;

void main() {
    if (v_ok < 0.999) {  // below 1 by more than interpolation's rounding
        discard;  // a primitive with a non-finite vertex
    }
    float len = length(v_tangent);
    float tl = len > 0.0 ? dot(v_tangent / len, u_light) : 0.0;
    float diffuse = sqrt(max(1.0 - tl * tl, 0.0));
    o_color = vec4(u_color * (u_ambient + (1.0 - u_ambient) * diffuse), 1.0);
}
