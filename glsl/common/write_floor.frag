// The floor of a pass: writes a constant into TARGETS render targets (1 to 8) and reads nothing.
// A pass of the same size and formats costs at least this (on the NVIDIA H200 a fragment pass is
// bound by the bytes it writes).

#ifndef TARGETS
#define TARGETS 1
#endif

uniform vec4 u_value;

layout(location = 0) out vec4 o_targets[TARGETS];

void main() {
    for (int i = 0; i < TARGETS; i++) {
        o_targets[i] = u_value;
    }
}
