// Buoyancy of a hot particle (examples/heat/heat.toml): lift in proportion to how much hotter
// than the air it is (an ideal gas at the air's pressure), read from the user state by name.
vec3 force(vec3 x, vec3 v, float age, int type) {
    float excess = max(temperature.x / 300.0 - 1.0, 0.0);
    return vec3(0.0, 4.0 * excess, 0.0);
}
