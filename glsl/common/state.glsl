// Addressing of particle state: particle i lives in texel (i mod width, i div width) of every
// state texture. A full-screen pass finds its own texel as ivec2(gl_FragCoord.xy) (texel centres,
// no half-texel arithmetic); vertex shaders find theirs from gl_VertexID.

uint particle_index(ivec2 texel, int width) {
    return uint(texel.y) * uint(width) + uint(texel.x);
}

ivec2 particle_texel(int index, int width) {
    return ivec2(index % width, index / width);
}

// A live particle (docs/pipeline.md): life w > 0 and a finite position; dead particles are parked
// at +inf. A test on the bits: NVIDIA's compiler drops NaN-sensitive float comparisons. The twin
// of sim::particle_live in Rust.
bool particle_live(vec4 p) {
    uvec3 e = floatBitsToUint(p.xyz) & 0x7f800000u;
    return p.w > 0.0 && all(notEqual(e, uvec3(0x7f800000u)));
}
