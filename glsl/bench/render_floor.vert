// The render pass's floor: one point per particle like render/particle.vert,
// but placed by a hash of gl_VertexID instead of a texel fetch, so that no texture is read. The
// points fall uniformly over the frame; the draw state sets the smallest point size (1 pixel).
// With u_raster_width > 0 (the cost model's frame probe) point k is at pixel k of the frame in
// raster order instead (u_raster_width pixels a row, u_raster_height rows, wrapping): points
// that follow one another in a draw fall side by side, as a render's nearby particles do.

uniform uint u_seed;
uniform int u_raster_width;
uniform int u_raster_height;

void main() {
    vec2 p;
    if (u_raster_width > 0) {
        int k = gl_VertexID % (u_raster_width * u_raster_height);
        p = (vec2(k % u_raster_width, k / u_raster_width) + 0.5)
            / vec2(u_raster_width, u_raster_height);
    } else {
        uint h = uint(gl_VertexID) * 2654435761u ^ u_seed;
        h ^= h >> 16;
        h *= 2246822519u;
        h ^= h >> 13;
        p = (vec2(float(h & 0xffffu), float(h >> 16)) + 0.5) / 65536.0;
    }
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
