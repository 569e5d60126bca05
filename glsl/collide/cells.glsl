// The exact detection's neighbour search (beyond UberFlow §4.4, fragment passes only). The state
// has been gathered in the order of a full sort by cell key (cells enumerated z, y, x), so the
// particles of one cell are consecutive, and so are those of three cells side by side along x.
// A particle reads its own key from the sorted keys, and for each of the 9 (y, z) rows of cells
// around it finds where the run of cells x-1..x+1 starts and ends; it then walks that run (at
// most EXACT_SCAN particles) and visits every live particle in it.
// With CELL_TABLE the run's bounds are two fetches of the cell-start table that a pass wrote
// after the sort (collide/cell_start.frag: start(c) = first sorted index whose key is not below
// c), start(row + x0) and start(row + x1 + 1): 18 fetches per particle. Without it (a lattice
// too large for the table: src/sim/collide/cells.rs) a binary search of the sorted keys finds
// the start, and the walk stops at the first key past the run. Keys are whole cell indices (or
// +inf), so both find the same run: the same neighbours, visited in the same order.
// With a cell of at least 2r every pair closer than 2r is visited from both sides, unless a run
// holds more than EXACT_SCAN particles (then `exact_truncated` is set).
// The including shader defines `void visit(int j)`, called with each neighbour's sorted index.

#include "collide/sorted_keys.glsl"

uniform ivec3 u_dims;           // cells per axis
#ifdef CELL_TABLE
uniform sampler2D u_cell_start; // first sorted index of each cell, rows of u_cell_width
uniform int u_cell_width;

int cell_start(int c) {
    return int(texelFetch(u_cell_start, ivec2(c % u_cell_width, c / u_cell_width), 0).x);
}
#endif

#ifndef EXACT_SCAN
#define EXACT_SCAN 64
#endif

bool exact_truncated = false;

void visit(int j);

// Whether the walk of a run ending at `end` (CELL_TABLE) or at the last key not above `k1` is
// still inside the run at sorted index i.
bool in_run(int i, int end, float k1) {
#ifdef CELL_TABLE
    return i < end;
#else
    return i < u_count && sorted_key(i) <= k1;
#endif
}

// Visits every particle of the 27 cells around the particle at sorted index `self` (not itself).
void search_neighbours(int self) {
    float own = sorted_key(self);
    if (!(own < 3.0e38)) return;   // dead: +inf key
    int k = int(own);
    ivec3 c = ivec3(k % u_dims.x, (k / u_dims.x) % u_dims.y, k / (u_dims.x * u_dims.y));
    int x0 = max(c.x - 1, 0);
    int x1 = min(c.x + 1, u_dims.x - 1);
    for (int dz = -1; dz <= 1; dz++) {
        int z = c.z + dz;
        if (z < 0 || z >= u_dims.z) continue;
        for (int dy = -1; dy <= 1; dy++) {
            int y = c.y + dy;
            if (y < 0 || y >= u_dims.y) continue;
            int row = (z * u_dims.y + y) * u_dims.x;
            float k1 = float(row + x1);
#ifdef CELL_TABLE
            int j = cell_start(row + x0);
            int end = cell_start(row + x1 + 1);
#else
            int j = lower_bound(float(row + x0));
            int end = u_count;
#endif
            int s = 0;
            for (; s < EXACT_SCAN; s++) {
                if (!in_run(j + s, end, k1)) break;
                if (j + s != self) visit(j + s);
            }
            if (s == EXACT_SCAN && in_run(j + s, end, k1)) {
                exact_truncated = true;
            }
        }
    }
}
