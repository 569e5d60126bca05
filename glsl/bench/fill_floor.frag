// The fill floor of a particle render pass: drawn behind the renderer's own vertex stage
// (render/particle.vert with the pass's defines: the same points, sprites or quads at the same
// sizes and places) with the pass's blend, it writes a constant into every fragment the pass
// covers and fetches nothing (no atlas, no shading). The render pass costs at least this; what
// it costs above is its fragment stage: the atlas fetch, the rotation, the colour.

layout(location = 0) out vec4 o_color;

void main() {
    o_color = vec4(0.02, 0.01, 0.005, 0.1);
}
