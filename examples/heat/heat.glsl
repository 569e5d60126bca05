// The heat example's temperature (`[[state]]`, examples/heat/heat.toml): kelvin in x.

// The air around the flame.
float ambient() {
    return 300.0;
}

// Heating by the burner, K/s: strongest at its centre, gone 0.4 m above it.
float burner(vec3 x) {
    float r = length(vec2(x.x, x.z)) / 0.25;
    return 6000.0 * max(1.0 - r * r, 0.0) * max(1.0 - x.y / 0.4, 0.0);
}

// Newton's law of cooling, 1/s: a particle loses heat to the air faster as it thins out.
float cooling(float age) {
    return 2.5 + 2.5 * age;
}
