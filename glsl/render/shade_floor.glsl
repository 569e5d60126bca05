// The benchmarks' shading floor (fragment stages built with SHADE_FLOOR): a pass's colour, after
// every fetch and computation that made it, replaced by `unchanged`, the colour that leaves the
// target as it was under the pass's blend, through a zero the compiler cannot prove
// (gl_FragCoord.w = 1 / w_clip > 0), so that the shading stays.
vec4 shade_floor(vec4 colour, vec4 unchanged) {
    return unchanged + (colour - unchanged) * min(gl_FragCoord.w, 0.0);
}
