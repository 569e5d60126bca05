// Test fixture: includes tests/glsl/broken_helper.glsl, whose line 5 does not compile.

#include "tests/glsl/broken_helper.glsl"

layout(location = 0) out vec4 o_color;

void main() {
    o_color = vec4(helper(1.0));
}
