// A constant force per type.
vec3 force(vec3 x, vec3 v, float age, int type) {
    return vec3(0.0, 3.0, 0.0) * float(type + 1);
}
