// Repulsion that falls off with distance.
vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,
                float mass_j, float distance) {
    /* away from the neighbour */
    return normalize(x - xj) / max(distance * distance, 1e-4);
}
