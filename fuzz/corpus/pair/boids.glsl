// Boids (Reynolds 1987) as a texflow pair force ([[forces.pair]], docs/scenes.md): called once
// for every neighbour closer than the pair force's radius, which the exact collision detection
// finds on the sorted grid; the forces are summed, divided by the mass and added to the
// velocity. Three rules, each an acceleration times the boid's mass:
//   separation  away from any neighbour closer than SEPARATION, rising to SEPARATE m/s² at contact
//   alignment   towards the neighbour's velocity, ALIGN per second, own flock (type) only
//   cohesion    towards the neighbour, COHERE per second², own flock only
// Summed rather than averaged: a boid with more flockmates steers harder.

const float SEPARATION = 0.05;
const float SEPARATE = 3.0;
const float ALIGN = 0.6;
const float COHERE = 4.0;

vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,
                float mass_j, float distance) {
    vec3 a = vec3(0.0);
    if (distance > 0.0 && distance < SEPARATION) {
        a -= SEPARATE * (1.0 - distance / SEPARATION) * (xj - x) / distance;
    }
    if (type_j == type) {
        a += ALIGN * (vj - v) + COHERE * (xj - x);
    }
    return mass * a;
}
