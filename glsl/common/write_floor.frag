// The floor of a pass: writes a constant into TARGETS render targets (1 to 8) and reads nothing.
// A pass of the same size and formats costs at least this (on the NVIDIA H200 a fragment pass is
// bound by the bytes it writes).

#ifndef TARGETS
#define TARGETS 1
#endif

uniform vec4 u_value;

#ifdef UINT
// Integer targets (the compact sort's entries).
layout(location = 0) out uvec4 o_targets[TARGETS];
#else
layout(location = 0) out vec4 o_targets[TARGETS];
#endif

void main() {
    for (int i = 0; i < TARGETS; i++) {
#ifdef UINT
        o_targets[i] = floatBitsToUint(u_value);
#else
        o_targets[i] = u_value;
#endif
    }
}
