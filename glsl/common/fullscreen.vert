// The full-screen pass (thesis §3.5): one attribute-less triangle whose vertices
// (-1,-1), (3,-1), (-1,3) cover the viewport, so each texel runs the fragment program once.

void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
