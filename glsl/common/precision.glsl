// Precision emulation (UberFlow §4.3.1): with EMULATE_FLOAT defined, fp_store rounds what a pass
// writes to a float of FLOAT_MANTISSA stored mantissa bits and FLOAT_EXPONENT exponent bits
// (the ATI R300: 16 and 7), round to nearest even, overflow to infinity, no denormals.
// Twin of FloatFormat::round in src/sort/precision.rs.

#ifdef EMULATE_FLOAT
float fp_round(float x) {
    uint u = floatBitsToUint(x);
    if (((u >> 23) & 0xffu) == 0xffu) return x;
    const uint drop = uint(23 - FLOAT_MANTISSA);
    uint lsb = (u >> drop) & 1u;
    uint r = (u + ((1u << (drop - 1u)) - 1u + lsb)) & ~((1u << drop) - 1u);
    uint sign = u & 0x80000000u;
    int e = int((r >> 23) & 0xffu) - 127;
    const int bias = (1 << (FLOAT_EXPONENT - 1)) - 1;
    if (e > bias) return uintBitsToFloat(sign | 0x7f800000u);
    if (e < 1 - bias) return uintBitsToFloat(sign);
    return uintBitsToFloat(r);
}
vec4 fp_store(vec4 v) {
    return vec4(fp_round(v.x), fp_round(v.y), fp_round(v.z), fp_round(v.w));
}
#else
vec4 fp_store(vec4 v) {
    return v;
}
#endif
