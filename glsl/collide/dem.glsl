// The discrete-element contact force of NVIDIA's CUDA `particles` sample (collideSpheres), on
// sphere A from sphere B, both of radius r, in contact when closer than 2r. With d = x_B - x_A,
// n = d / |d| and u = v_B - v_A:
//   F = -spring (2r - |d|) n      the spring pushes A out of B
//     + damping u                 the dashpot pulls A's velocity towards B's
//     + shear (u - (u . n) n)     more damping of the tangential relative velocity
//     + attraction d              a pull towards B while in contact
// The sample adds F to the velocity as it is; here it is a force in N, divided by the mass and
// multiplied by dt (collide/neighbour_apply.frag). F is odd in d and u, so the force on B is -F:
// the pair's momentum is kept. Coincident centres give no spring direction: no force.

uniform vec4 u_dem;   // spring (N/m), damping (kg/s), shear (kg/s), attraction (N/m)

vec3 dem_force(vec3 xa, vec3 va, vec3 xb, vec3 vb, float radius) {
    vec3 d = xb - xa;
    float dist = length(d);
    if (!(dist < 2.0 * radius) || dist == 0.0) return vec3(0.0);
    vec3 n = d / dist;
    vec3 u = vb - va;
    vec3 tangential = u - dot(u, n) * n;
    return -u_dem.x * (2.0 * radius - dist) * n + u_dem.y * u + u_dem.z * tangential + u_dem.w * d;
}
