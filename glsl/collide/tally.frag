// One flagged particle: adds 1 to the tally (collide/tally.vert).

layout(location = 0) out vec4 o_count;

void main() {
    o_count = vec4(1.0);
}
