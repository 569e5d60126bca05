vec3 force(vec3 x, vec3 v, float age, int type) {
    return vec3(age, 0.0, 0.0);
}
