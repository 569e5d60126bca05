vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,
                float mass_j, float distance) {
    return vec3(0.0);
}
