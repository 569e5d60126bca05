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
// The walk fetches the positions (u_position, declared here for every including shader); the
// including shader defines what a visit does with one:
//   bool is_partner(vec4 q)                   whether a neighbour at position q is worked;
//   void partner_work(int j, ivec2 tj, vec4 q) the work of partner j at texel tj, position q.
// A visit fetches the neighbour's position once, tests it and works a partner with it (a visit
// that fetched it twice, to test and to work, took 1.25-1.33 times as long in the DEM's force on
// an NVIDIA H100); with PARTNER_MASK the work comes after the tests of 32 (below).

#include "collide/sorted_keys.glsl"

uniform ivec3 u_dims;           // cells per axis
#ifdef CELL_TABLE
uniform sampler2D u_cell_start; // first sorted index of each cell, rows of 2^TABLE_WIDTH_SHIFT

// TABLE_WIDTH_SHIFT: log2 of the table's widest row (src/sim/collide/cells.rs); a table of one
// narrower row holds every cell index below its width, so the mask and shift find it too.
int cell_start(int c) {
    ivec2 t = ivec2(c & ((1 << TABLE_WIDTH_SHIFT) - 1), c >> TABLE_WIDTH_SHIFT);
    return int(texelFetch(u_cell_start, t, 0).x);
}
#endif

#ifndef EXACT_SCAN
#define EXACT_SCAN 64
#endif

bool exact_truncated = false;

uniform sampler2D u_position;   // the cell-sorted layout: position (xyz, life) of sorted index i

vec4 walk_position(ivec2 t) {
    return texelFetch(u_position, t, 0);
}

bool is_partner(vec4 q);
void partner_work(int j, ivec2 tj, vec4 q);

// The walk fetches WALK_BATCH neighbours' positions before it tests the first, so that a
// fragment waits for them once, not once each. On an NVIDIA H100, 4 and 8 took 1.03-1.14 times
// as long as 2 for `dem` and the fluids at 256², and 0.97-1.05 times at 1024²; 2 against one at
// a time was 2 % faster.
#ifndef WALK_BATCH
#define WALK_BATCH 2
#endif

void visit(int j) {
    ivec2 tj = key_texel(j);
    vec4 q = walk_position(tj);
    if (is_partner(q)) partner_work(j, tj, q);
}

#ifdef PARTNER_MASK
// The partner work of one run with PARTNER_MASK, 32 particles at a time: the visits only test,
// and set bit b of a mask for each partner at j + b; the work then takes those partners (their
// positions fetched again) in the same order, lowest bit first, before the next 32 are tested.
// A GPU runs a fragment pass in warps of neighbouring fragments in lockstep; where one visit in
// a few is a partner, some fragment of a warp has one at nearly every visit, so a walk that
// worked as it visited would have the whole warp pay a partner's work at every visit. Here the
// warp pays it as many times as the most partners one of its fragments has among 32.
void partner_take(int j) {
    ivec2 tj = key_texel(j);
    partner_work(j, tj, walk_position(tj));
}

// Whether sorted index i, not the searching particle's own, is a partner (one test, its
// position fetched here).
bool partner_at(int self, int i) {
    return i != self && is_partner(walk_position(key_texel(i)));
}

void take_mask(int j, uint mask) {
    while (mask != 0u) {
        uint low = mask & (~mask + 1u);
        // The lowest set bit's place: a power of two converts to float exactly, and its exponent is
        // the place (GLSL 3.30 has no findLSB).
        int s = int(floatBitsToUint(float(low)) >> 23) - 127;
        mask ^= low;
        partner_take(j + s);
    }
}
#endif

// Walks the run of cells row + x0 .. row + x1 (one row of the lattice along x), visiting every
// particle in it but the one at sorted index `self`, at most EXACT_SCAN of them.
void walk_run(int self, int row, int x0, int x1) {
#ifdef CELL_TABLE
    int j = cell_start(row + x0);
    int end = cell_start(row + x1 + 1);
    int n = min(end - j, EXACT_SCAN);
    int s = 0;
#ifdef PARTNER_MASK
    for (; s < n; s += 32) {
        uint mask = 0u;
        int e = min(n - s, 32);
        int b = 0;
        for (; b + WALK_BATCH <= e; b += WALK_BATCH) {
            vec4 q[WALK_BATCH];
            for (int k = 0; k < WALK_BATCH; k++) q[k] = walk_position(key_texel(j + s + b + k));
            for (int k = 0; k < WALK_BATCH; k++) {
                if (j + s + b + k != self && is_partner(q[k])) mask |= 1u << uint(b + k);
            }
        }
        for (; b < e; b++) {
            if (partner_at(self, j + s + b)) mask |= 1u << uint(b);
        }
        take_mask(j + s, mask);
    }
#else
    for (; s + WALK_BATCH <= n; s += WALK_BATCH) {
        vec4 q[WALK_BATCH];
        for (int k = 0; k < WALK_BATCH; k++) q[k] = walk_position(key_texel(j + s + k));
        for (int k = 0; k < WALK_BATCH; k++) {
            int i = j + s + k;
            if (i != self && is_partner(q[k])) partner_work(i, key_texel(i), q[k]);
        }
    }
    for (; s < n; s++) {
        if (j + s != self) visit(j + s);
    }
#endif
    if (end - j > EXACT_SCAN) exact_truncated = true;
#else
    // The run ends at the first key past its last cell.
    float k1 = float(row + x1);
    int j = lower_bound(float(row + x0));
    int s = 0;
#ifdef PARTNER_MASK
    bool more = true;
    while (more && s < EXACT_SCAN) {
        uint mask = 0u;
        int base = s;
        int e = min(base + 32, EXACT_SCAN);
        for (; s < e; s++) {
            if (!(j + s < u_count && sorted_key(j + s) <= k1)) {
                more = false;
                break;
            }
            if (partner_at(self, j + s)) mask |= 1u << uint(s - base);
        }
        take_mask(j + base, mask);
    }
#else
    for (; s < EXACT_SCAN; s++) {
        if (!(j + s < u_count && sorted_key(j + s) <= k1)) break;
        if (j + s != self) visit(j + s);
    }
#endif
    if (s == EXACT_SCAN && j + s < u_count && sorted_key(j + s) <= k1) {
        exact_truncated = true;
    }
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
            walk_run(self, (z * u_dims.y + y) * u_dims.x, x0, x1);
        }
    }
}

#ifdef SEARCH_TRIM
// The trimmed walk (SEARCH_TRIM, the fluid's search): only the cells that can hold a particle
// closer than u_search_radius to the searching particle's position x. A row (y, z) is skipped
// where the distance d from x to its slab across y and z is not below the radius r; else its run
// along x is trimmed to the cells of x ± sqrt(r² - d²). With a lattice of cell h and a radius
// of 2h that is about 84 cells of h³ around a particle in 22 runs (108 if every run spanned
// x ± r) instead of the 27 cells of (2h)³ (216 h³) of the plain search, every particle closer
// than the radius among them. Cells clamp (a particle outside the lattice is in its edge cell),
// and a clamped index range still holds every such cell, since floor and clamp keep the order.
// The margin of 1e-4 cells covers the key pass's rounding of a position near a cell's face.
// (Loops of a fixed count, two cells out, ran 3 % slower on an NVIDIA H100 for the
// million-particle dam.)
uniform vec3 u_cell_origin;     // corner of cell (0, 0, 0)
uniform float u_cell_size;      // the lattice's mesh size
uniform float u_search_radius;  // every particle closer than this is visited

// Distance along one axis from coordinate a (in cell ca) to the slab of cell index i.
float slab_distance(float a, int ca, int i, float origin) {
    if (i < ca) return a - (origin + float(i + 1) * u_cell_size);
    if (i > ca) return (origin + float(i) * u_cell_size) - a;
    return 0.0;
}

// Visits every particle (not itself) of the cells that can hold one closer than u_search_radius
// to x, the position of the particle at sorted index `self`.
void search_within(int self, vec3 x) {
    float own = sorted_key(self);
    if (!(own < 3.0e38)) return;   // dead: +inf key
    float r = u_search_radius + 1.0e-4 * u_cell_size;
    vec3 top = vec3(u_dims);
    // Clamped before the conversion to int: a position far outside stays in range.
    vec3 u = (x - u_cell_origin) / u_cell_size;
    float ru = r / u_cell_size;
    ivec3 last = u_dims - 1;
    ivec3 lo = clamp(ivec3(floor(clamp(u - ru, vec3(-1.0), top))), ivec3(0), last);
    ivec3 hi = clamp(ivec3(floor(clamp(u + ru, vec3(-1.0), top))), ivec3(0), last);
    ivec3 c = clamp(ivec3(floor(clamp(u, vec3(-1.0), top))), ivec3(0), last);
    float r2 = r * r;
    for (int z = lo.z; z <= hi.z; z++) {
        float sz = slab_distance(x.z, c.z, z, u_cell_origin.z);
        for (int y = lo.y; y <= hi.y; y++) {
            float sy = slab_distance(x.y, c.y, y, u_cell_origin.y);
            float d2 = sy * sy + sz * sz;
            if (d2 >= r2) continue;
            // A particle of this row closer than r lies within sqrt(r² - d2) of x along x.
            float half_x = sqrt(r2 - d2) / u_cell_size;
            int x0 = clamp(int(floor(clamp(u.x - half_x, -1.0, top.x))), 0, last.x);
            int x1 = clamp(int(floor(clamp(u.x + half_x, -1.0, top.x))), 0, last.x);
            walk_run(self, (z * u_dims.y + y) * u_dims.x, x0, x1);
        }
    }
}
#endif

// The search a pass runs for the particle at sorted index `self` at position x: the trimmed
// walk with SEARCH_TRIM, else the 27 cells.
void search_around(int self, vec3 x) {
#ifdef SEARCH_TRIM
    search_within(self, x);
#else
    search_neighbours(self);
#endif
}
