vec3 force(vec3 x, vec3 v, float age, int type) {
    return -x;
}
