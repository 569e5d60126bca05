// Addressing of particle state: particle i lives in texel (i mod width, i div width) of every
// state texture. A full-screen pass finds its own texel as ivec2(gl_FragCoord.xy) (texel centres,
// no half-texel arithmetic); vertex shaders find theirs from gl_VertexID.

uint particle_index(ivec2 texel, int width) {
    return uint(texel.y) * uint(width) + uint(texel.x);
}

ivec2 particle_texel(int index, int width) {
    return ivec2(index % width, index / width);
}
