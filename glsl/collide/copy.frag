// Copies a texture (the gathered static data back into the simulation's static texture): state
// changes only by drawing.

uniform sampler2D u_source;

layout(location = 0) out vec4 o_copy;

void main() {
    o_copy = texelFetch(u_source, ivec2(gl_FragCoord.xy), 0);
}
