/* A bounded loop and a helper. */
float wave(float t) {
    float s = 0.0;
    for (int i = 0; i < 4; ++i) {
        s += sin(t * float(i + 1));
    }
    return s;
}

vec3 force(vec3 x, vec3 v, float age, int type) {
#if 1
    return vec3(wave(age), 0.0, -0.1 * v.z);
#else
    return vec3(0.0);
#endif
}
