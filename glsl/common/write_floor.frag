// The floor of a pass: writes a constant into TARGETS render targets and reads nothing. A pass of
// the same size and formats costs at least this (shared/gpu/README.md: on the H100 a fragment
// pass is bound by the bytes it writes).

#ifndef TARGETS
#define TARGETS 1
#endif

uniform vec4 u_value;

layout(location = 0) out vec4 o_0;
#if TARGETS > 1
layout(location = 1) out vec4 o_1;
#endif
#if TARGETS > 2
layout(location = 2) out vec4 o_2;
#endif
#if TARGETS > 3
layout(location = 3) out vec4 o_3;
#endif

void main() {
    o_0 = u_value;
#if TARGETS > 1
    o_1 = u_value;
#endif
#if TARGETS > 2
    o_2 = u_value;
#endif
#if TARGETS > 3
    o_3 = u_value;
#endif
}
