// The first level of the cell-start table (collide/cell_start.frag): one texel per block of
// u_block cells, holding the first sorted index whose key is not below the block's first cell
// (a binary search of all the sorted keys), the texels from the block of the sentinel on the
// live particles' count. The table's pass then searches each cell's start only between its
// block's and the next block's: a few keys instead of all of them, the same index.

#include "collide/sorted_keys.glsl"

uniform int u_block_width;  // blocks per row of this texture
uniform int u_cells;        // cells in the lattice
uniform int u_block;        // cells per block

layout(location = 0) out vec4 o_start;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int b = min(t.y * u_block_width + t.x, u_cells / u_block + 1);
    o_start = vec4(float(lower_bound(float(min(b * u_block, u_cells)))), 0.0, 0.0, 0.0);
}
