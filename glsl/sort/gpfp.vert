// GP/FP geometry (UberFlow §4.3.3, Fig. 1-2): quads covering groups of columns (row passes) or
// rows (merge passes), built once per pass shape into vertex buffers (the paper's display
// lists). a_attr = (sign of the partner offset, comparison: +1 keep the smaller / -1 the larger,
// partner texel coordinates for the reversing passes, interpolated across the quad).

layout(location = 0) in vec2 a_position;
layout(location = 1) in vec4 a_attr;

uniform vec2 u_size;

out vec4 v_attr;

void main() {
    gl_Position = vec4(a_position / u_size * 2.0 - 1.0, 0.0, 1.0);
    v_attr = a_attr;
}
