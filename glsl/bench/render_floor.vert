// The render pass's floor: one point per particle like render/particle.vert,
// but placed by a hash of gl_VertexID instead of a texel fetch, so that no texture is read. The
// points fall uniformly over the frame; the draw state sets the smallest point size (1 pixel).

uniform uint u_seed;

void main() {
    uint h = uint(gl_VertexID) * 2654435761u ^ u_seed;
    h ^= h >> 16;
    h *= 2246822519u;
    h ^= h >> 13;
    vec2 p = (vec2(float(h & 0xffffu), float(h >> 16)) + 0.5) / 65536.0;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
