// The colliders' view depth for soft particles (render.soft): 1 / gl_FragCoord.w is the clip w
// of the fragment, its depth along the view axis, which the particle fragment stage compares
// with its own (render/particle.frag, SOFT). Into an R32F target cleared to 1e30 (no geometry).

layout(location = 0) out vec4 o_depth;

void main() {
    o_depth = vec4(1.0 / gl_FragCoord.w);
}
