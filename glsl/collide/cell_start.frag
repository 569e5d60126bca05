// The cell-start table of the exact neighbour search (as cellStart in NVIDIA's CUDA particles
// sample, here a fragment pass): one texel per cell c of the lattice, rows of u_cell_width
// cells, holding the first sorted index whose key is not below c (collide/sorted_keys.glsl:
// the binary search the search would run, once per cell instead of 9 times per particle and
// pass). Texel u_cells is the sentinel, the end of the last cell: the live particles' count.
// Texels past it repeat the sentinel. Indices below 2^24 are exact in R32F.

#include "collide/sorted_keys.glsl"

uniform int u_cell_width;   // cells per row of the table
uniform int u_cells;        // cells in the lattice

layout(location = 0) out vec4 o_start;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int c = min(t.y * u_cell_width + t.x, u_cells);
    o_start = vec4(float(lower_bound(float(c))), 0.0, 0.0, 0.0);
}
