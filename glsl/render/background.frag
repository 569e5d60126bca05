// Composites the background under everything drawn so far (the under operator's last step:
// colour += (1 - alpha) · background), drawn over a full-screen triangle with blending
// (1 - DST_ALPHA, ONE). Leaves the frame opaque.

uniform vec3 u_background;

layout(location = 0) out vec4 o_color;

void main() {
    o_color = vec4(u_background, 1.0);
}
