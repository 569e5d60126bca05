// The one mass formula of the particle system, shared by integration (sim/forces.glsl) and the
// collision response (collide/pair.glsl's callers): the inverse mass is u_inv_mass[type], or
// with MASS_RANGE (Latta §3.3, a mass per particle) 1 / mix(lo, hi, fract(4096 r)), r the random
// number of the particle's static texel. src/sim/particles/uniforms.rs sets the uniforms.

uniform vec4 u_inv_mass;
#ifdef MASS_RANGE
uniform vec4 u_mass_lo;
uniform vec4 u_mass_hi;
#endif

// The inverse mass of a particle of `type` whose static texel holds the random number `r`.
float particle_inv_mass(int type, float r) {
#ifdef MASS_RANGE
    return 1.0 / mix(u_mass_lo[type], u_mass_hi[type], fract(4096.0 * r));
#else
    return u_inv_mass[type];
#endif
}
