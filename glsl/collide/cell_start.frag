// The cell-start table of the exact neighbour search (as cellStart in NVIDIA's CUDA particles
// sample, here a fragment pass): one texel per cell c of the lattice, rows of u_cell_width
// cells, holding the first sorted index whose key is not below c (collide/sorted_keys.glsl:
// the binary search the search would run, once per cell instead of once per row, particle and
// pass). The search for cell c runs between the starts of its block of u_block cells and of
// the next (collide/cell_block.frag wrote them): the same index, found in a few fetches.
// Texel u_cells is the sentinel, the end of the last cell: the live particles' count.
// Texels past it repeat the sentinel. Indices below 2^24 are exact in R32F.

#include "collide/sorted_keys.glsl"

uniform int u_cell_width;   // cells per row of the table
uniform int u_cells;        // cells in the lattice
uniform sampler2D u_blocks; // the start of every block of u_block cells (cell_block.frag)
uniform int u_block_width;  // blocks per row of u_blocks
uniform int u_block;        // cells per block

layout(location = 0) out vec4 o_start;

int block_start(int b) {
    return int(texelFetch(u_blocks, ivec2(b % u_block_width, b / u_block_width), 0).x);
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int c = min(t.y * u_cell_width + t.x, u_cells);
    int b = c / u_block;
    int start = lower_bound_in(float(c), block_start(b), block_start(b + 1));
    o_start = vec4(float(start), 0.0, 0.0, 0.0);
}
