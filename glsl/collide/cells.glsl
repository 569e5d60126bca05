// The exact detection's neighbour search (beyond UberFlow §4.4, fragment passes only). The state
// has been gathered in the order of a full sort by cell key (cells enumerated z, y, x), so the
// particles of one cell are consecutive, and so are those of three cells side by side along x.
// A particle reads its own key from the sorted keys, and for each of the 9 (y, z) rows of cells
// around it finds, by a binary search of the sorted keys, where the run of cells x-1..x+1 starts;
// it then walks that run (at most EXACT_SCAN particles) and visits every live particle in it.
// With a cell of at least 2r every pair closer than 2r is visited from both sides, unless a run
// holds more than EXACT_SCAN particles (then `exact_truncated` is set).
// The including shader defines `void visit(int j)`, called with each neighbour's sorted index.

uniform sampler2D u_keys;       // the sorted entries: (key, id) per texel, or with PACKED_KEYS
                                // (the packed network) (key, id, key, id)
uniform int u_key_width;        // entries per sorted row (the state width)
uniform int u_count;            // entries (the state size)
uniform ivec3 u_dims;           // cells per axis

#ifndef EXACT_SCAN
#define EXACT_SCAN 64
#endif

bool exact_truncated = false;

float sorted_key(int i) {
#ifdef PACKED_KEYS
    vec4 e = texelFetch(u_keys, ivec2((i % u_key_width) / 2, i / u_key_width), 0);
    return (i & 1) == 0 ? e.x : e.z;
#else
    return texelFetch(u_keys, ivec2(i % u_key_width, i / u_key_width), 0).x;
#endif
}

// First sorted index whose key is not below k (dead particles' +inf keys sort last).
int lower_bound(float k) {
    int lo = 0;
    int hi = u_count;
    for (int it = 0; it < 32; it++) {
        if (lo >= hi) break;
        int mid = (lo + hi) / 2;
        if (sorted_key(mid) < k) lo = mid + 1; else hi = mid;
    }
    return lo;
}

void visit(int j);

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
            int j = lower_bound(float(row + x0));
            int s = 0;
            for (; s < EXACT_SCAN; s++) {
                if (j + s >= u_count || !(sorted_key(j + s) <= k1)) break;
                if (j + s != self) visit(j + s);
            }
            if (s == EXACT_SCAN && j + s < u_count && sorted_key(j + s) <= k1) {
                exact_truncated = true;
            }
        }
    }
}
