// Test pass: adds 1 to every channel of two state textures through MRT.

uniform sampler2D u_a;
uniform sampler2D u_b;

layout(location = 0) out vec4 o_a;
layout(location = 1) out vec4 o_b;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    o_a = texelFetch(u_a, t, 0) + vec4(1.0);
    o_b = texelFetch(u_b, t, 0) + vec4(1.0);
}
