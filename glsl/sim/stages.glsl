// The multistage integrators the thesis names beside Euler and Verlet (§2.1: "Runge Kutta ...
// mit mehreren unterstützenden Gradienten, die aufsummiert und dann gemittelt werden ...
// Leapfrog, Verlet und Heun"), for the state y = (x, v) with y' = (v, a(x, v, t)):
//   HEUN      predictor-corrector (explicit trapezoid), order 2:
//             k1 = f(y), k2 = f(y + dt k1), y' = y + dt (k1 + k2) / 2
//   RK4       classical fourth-order Runge-Kutta, order 4:
//             k1 = f(y), k2 = f(y + dt/2 k1), k3 = f(y + dt/2 k2), k4 = f(y + dt k3),
//             y' = y + dt (k1 + 2 k2 + 2 k3 + k4) / 6
//   LEAPFROG  kick-drift-kick, order 2 (symplectic for forces of x alone):
//             v_half = v + dt/2 a(x, v), x' = x + dt v_half, v' = v_half + dt/2 a(x', v_half)
// The forces are functions of one particle's own state, the fields and the time, so every stage
// is evaluated in the one fragment, in registers: the stages need no texture of their own, and
// the state between steps is still only the position and velocity textures. The force's time
// (force_age) moves with the stage, for custom forces that depend on it.
// Included by sim/integrate.frag after sim/forces.glsl; uses its u_dt.

vec3 stage_acceleration(vec3 x, vec3 v, float im, float age) {
    force_age = age;
    return acceleration(x, v, im);
}

void stages(vec3 x, vec3 v, float im, float age, out vec3 xn, out vec3 vn) {
    float h = u_dt;
#if defined(HEUN)
    vec3 a1 = stage_acceleration(x, v, im, age);
    vec3 x2 = x + h * v;
    vec3 v2 = v + h * a1;
    vec3 a2 = stage_acceleration(x2, v2, im, age + h);
    xn = x + (0.5 * h) * (v + v2);
    vn = v + (0.5 * h) * (a1 + a2);
#elif defined(RK4)
    float hh = 0.5 * h;
    vec3 a1 = stage_acceleration(x, v, im, age);
    vec3 v2 = v + hh * a1;
    vec3 a2 = stage_acceleration(x + hh * v, v2, im, age + hh);
    vec3 v3 = v + hh * a2;
    vec3 a3 = stage_acceleration(x + hh * v2, v3, im, age + hh);
    vec3 v4 = v + h * a3;
    vec3 a4 = stage_acceleration(x + h * v3, v4, im, age + h);
    xn = x + (h / 6.0) * (v + 2.0 * v2 + 2.0 * v3 + v4);
    vn = v + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
#else // LEAPFROG
    vec3 vh = v + (0.5 * h) * stage_acceleration(x, v, im, age);
    xn = x + h * vh;
    vn = vh + (0.5 * h) * stage_acceleration(xn, vh, im, age + h);
#endif
    force_age = age;
}
