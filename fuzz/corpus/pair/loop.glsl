float k() { return 2.0; }
vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,
                float mass_j, float distance) {
    vec3 s = vec3(0.0);
    for (int i = 0; i < 4; i++) s += k() * (xj - x);
    return s;
}
