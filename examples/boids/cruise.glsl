// Boids fly: a custom force ([[forces.custom]]) that pulls every boid's speed towards CRUISE m/s
// at RATE per second (mass 1 kg, so the force is the acceleration).
const float CRUISE = 0.5;
const float RATE = 2.0;

vec3 force(vec3 x, vec3 v, float age, int type) {
    float s = length(v);
    return s > 1e-4 ? RATE * (CRUISE - s) * v / s : vec3(0.0);
}
