// Test fixture: a shader with a deliberate error on line 7, after an include, so that the test
// can check that the driver's error is mapped back to this file and line.

#include "common/rng.glsl"

layout(location = 0) out vec4 o_color;
float broken = undeclared_name * 2.0;

void main() {
    o_color = vec4(broken);
}
