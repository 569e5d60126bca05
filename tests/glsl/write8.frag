// Test pass: writes value (target index + 1) into each of eight render targets.

layout(location = 0) out vec4 o_0;
layout(location = 1) out vec4 o_1;
layout(location = 2) out vec4 o_2;
layout(location = 3) out vec4 o_3;
layout(location = 4) out vec4 o_4;
layout(location = 5) out vec4 o_5;
layout(location = 6) out vec4 o_6;
layout(location = 7) out vec4 o_7;

void main() {
    o_0 = vec4(1.0);
    o_1 = vec4(2.0);
    o_2 = vec4(3.0);
    o_3 = vec4(4.0);
    o_4 = vec4(5.0);
    o_5 = vec4(6.0);
    o_6 = vec4(7.0);
    o_7 = vec4(8.0);
}
