// The sort order of (key, id) entries: keys by key_order_bits (NaN after +inf, -0.0 equal to
// +0.0), then ids (non-negative floats) by their bits. Bit patterns, not float comparisons: GLSL
// leaves NaN comparisons, denormal flushing and isnan() to the driver, so a float compare could
// give the two fragments of a pair different answers and duplicate one entry while losing the
// other. Twin of src/sort/network.rs.

uint key_order_bits(float key) {
    uint u = floatBitsToUint(key);
    if (u == 0x80000000u) u = 0u;
    if ((u & 0x7fffffffu) > 0x7f800000u) u = 0x7fc00000u;
    return (u & 0x80000000u) != 0u ? ~u : (u | 0x80000000u);
}

bool entry_less(vec2 a, vec2 b) {
    uint ka = key_order_bits(a.x);
    uint kb = key_order_bits(b.x);
    if (ka != kb) return ka < kb;
    return floatBitsToUint(a.y) < floatBitsToUint(b.y);
}

// The entry a fragment keeps: the smaller of the two if keep_min, else the larger.
vec2 compare_exchange(vec2 own, vec2 other, bool keep_min) {
    return entry_less(own, other) == keep_min ? own : other;
}
