// The slices' chain floor's vertex stage: one point at the centre of the target, one pixel (no
// program point size), so that a pass of the chain costs its dependency and its fixed cost and
// next to nothing else.

void main() {
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
