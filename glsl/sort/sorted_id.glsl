// The particle at sorted position j: the identifier of entry j of the sort texture (key in x,
// identifier in y; PACKED: two entries per RGBA texel, the paper's final decode). ID_TABLE
// decodes the paper's 24-bit-safe identifiers (UberFlow §4.3.1): subtract the width of each
// binade until the rest falls inside one, then divide by the spacing there. Shared by the
// gather (sort/rearrange.frag) and the index lookup of the particle renderer (Latta §3.4.4).

int decode_id(float v) {
#ifdef ID_TABLE
    float rest = v - 1.0;
    float width = 1.0;
    int s = 0;
    for (int k = 0; k < 126 && rest >= width; k++) {
        rest -= width;
        width *= 2.0;
        s++;
    }
    float spacing = width / float(1 << FLOAT_MANTISSA);
    return (s << FLOAT_MANTISSA) + int(rest / spacing);
#else
    return int(v);
#endif
}

int sorted_id(sampler2D sorted, int sort_width, int j) {
    ivec2 s = ivec2(j % sort_width, j / sort_width);
#ifdef PACKED
    vec4 pair = texelFetch(sorted, ivec2(s.x / 2, s.y), 0);
    vec2 e = (s.x & 1) == 0 ? pair.xy : pair.zw;
#else
    vec2 e = texelFetch(sorted, s, 0).xy;
#endif
    return decode_id(e.y);
}
