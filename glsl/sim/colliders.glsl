// Colliders (Latta §3.4.2, UberFlow §4.6). Only the kinds a scene has are compiled in:
// N_PLANES, N_SPHERES, N_BOXES, HEIGHTFIELD, SDF. Each has a signed distance d (negative inside)
// and an outward normal n, and a response (friction mu, resilience eps) in a vec2.
//
// Explicit integrators (Latta's order): the velocity v_bc after forces gives the expected
// position p_bc (eq. 6); if p_bc is inside a collider the velocity takes the response of eq. 5,
// v = (1 - mu) v_t - eps v_n, with no friction when |v| is below u_slow_speed; a particle whose
// previous position is already inside (Fig. 2b) is pushed out at once and its velocity follows
// eq. 7. The height field follows UberFlow §4.6 instead: the particle is reset to the crossing
// point of its path with the surface, its velocity reflected, and it travels the rest of the step.
// Verlet (Latta §3.4.3, eq. 9): the velocity is implied, (x - x_prev) / dt; a step that ends
// inside takes eq. 4-5 on that implied velocity and restarts from x with the response (below).
// Last, any position still inside (sharp edges, two colliders) is projected out to SKIN above the
// surface, so no particle is ever left inside.

// Included unconditionally: the resolver splices each file once, whatever #if surrounds it.
#include "sim/fields.glsl"
#ifdef SPIN
#include "collide/spin.glsl"
#endif

const float SKIN = 1e-4;

uniform float u_slow_speed;
#if N_PLANES > 0
uniform vec4 u_plane[N_PLANES];      // unit normal, offset (n . x = offset on the plane)
uniform vec2 u_plane_resp[N_PLANES];
#endif
#if N_SPHERES > 0
uniform vec4 u_sphere[N_SPHERES];    // centre, radius
uniform vec2 u_sphere_resp[N_SPHERES];
#endif
#if N_BOXES > 0
uniform vec3 u_box_min[N_BOXES];
uniform vec3 u_box_max[N_BOXES];
uniform vec2 u_box_resp[N_BOXES];
#endif
#ifdef HEIGHTFIELD
uniform sampler2D u_height;
uniform vec4 u_height_extent;        // min x, min z, max x, max z
uniform ivec2 u_height_res;
uniform vec2 u_height_resp;
#endif
#ifdef SDF
uniform sampler3D u_sdf;
uniform vec3 u_sdf_min;
uniform vec3 u_sdf_max;
uniform ivec3 u_sdf_res;
uniform vec2 u_sdf_resp;
#endif

#if N_PLANES > 0
float plane_distance(int i, vec3 p, out vec3 n) {
    n = u_plane[i].xyz;
    return dot(n, p) - u_plane[i].w;
}
#endif

#if N_SPHERES > 0
float sphere_distance(int i, vec3 p, out vec3 n) {
    vec3 d = p - u_sphere[i].xyz;
    float r = length(d);
    n = r > 0.0 ? d / r : vec3(0.0, 1.0, 0.0);
    return r - u_sphere[i].w;
}
#endif

#if N_BOXES > 0
// Solid axis-aligned box: exact distance outside; inside, the distance to the nearest face.
float box_distance(int i, vec3 p, out vec3 n) {
    vec3 c = 0.5 * (u_box_min[i] + u_box_max[i]);
    vec3 h = 0.5 * (u_box_max[i] - u_box_min[i]);
    vec3 rel = p - c;
    vec3 q = abs(rel) - h;
    vec3 s = vec3(rel.x < 0.0 ? -1.0 : 1.0, rel.y < 0.0 ? -1.0 : 1.0, rel.z < 0.0 ? -1.0 : 1.0);
    if (max(q.x, max(q.y, q.z)) > 0.0) {
        vec3 o = max(q, 0.0);
        float d = length(o);
        n = s * o / d;
        return d;
    }
    if (q.x >= q.y && q.x >= q.z) {
        n = vec3(s.x, 0.0, 0.0);
        return q.x;
    }
    if (q.y >= q.z) {
        n = vec3(0.0, s.y, 0.0);
        return q.y;
    }
    n = vec3(0.0, 0.0, s.z);
    return q.z;
}
#endif

#ifdef HEIGHTFIELD
// Vertical distance to the landscape and its normal there.
float height_distance(vec3 p, out vec3 n) {
    vec4 h = heightfield_sample(u_height, u_height_extent, u_height_res, p.xz);
    n = h.yzw;
    return p.y - h.x;
}
#endif

#ifdef SDF
// Outside the field's bounds there is no collider.
float sdf_distance(vec3 p, out vec3 n) {
    if (any(lessThan(p, u_sdf_min)) || any(greaterThan(p, u_sdf_max))) {
        n = vec3(0.0, 1.0, 0.0);
        return 1e30;
    }
    n = sdf_normal(u_sdf, u_sdf_min, u_sdf_max, u_sdf_res, p);
    return sdf_sample(u_sdf, u_sdf_min, u_sdf_max, u_sdf_res, p);
}
#endif

// Latta eq. 4-5, with the slow-speed threshold. With SPIN, friction is Coulomb's on the slip of
// the contact point and turns the sphere (collide/spin.glsl).
vec3 collision_response(vec3 v, vec3 n, vec2 resp) {
    float vn = dot(v, n);
    if (vn >= 0.0) return v;
    vec3 v_n = vn * n;
    vec3 v_t = v - v_n;
    float mu = length(v) < u_slow_speed ? 0.0 : resp.x;
#ifdef SPIN
    return spin_collider_response(v, n, vn, mu, resp.y);
#else
    return (1.0 - mu) * v_t - resp.y * v_n;
#endif
}

// Latta eq. 7: the way out of a collider a particle is caught in.
vec3 caught_response(vec3 v, vec3 n) {
    float vn = dot(v, n);
    return vn < 0.0 ? v - 2.0 * vn * n : v;
}

#ifndef VERLET
// Set by `collide` when a path still entered a collider after MAX_BOUNCES bounces (the pass
// flags the particle, and the run counts it: src/sim/particles/bounces.rs).
bool bounces_truncated = false;

#if N_PLANES + N_SPHERES + N_BOXES > 0
// Bounces per step after Latta's response: a path of 5 m in a box of 1 m meets about a dozen
// walls; past the bound the rest of the path is left to keep_outside (and counted).
const int MAX_BOUNCES = 16;

// The earliest point where the straight path a -> b enters a plane, sphere or box while vb
// moves into it (vb . n < 0 with n the outward normal there; a path that starts inside one, or
// leaves it, enters nothing): its fraction s of the path, the normal and the response. Spheres
// and boxes by their exact intersection with the segment, so a path through one counts too.
bool first_entry(vec3 a, vec3 b, vec3 vb, out float s, out vec3 n, out vec2 resp) {
    s = 2.0;
    vec3 dir = b - a;
#if N_PLANES > 0
    for (int i = 0; i < N_PLANES; i++) {
        vec3 m = u_plane[i].xyz;
        float d0 = dot(m, a) - u_plane[i].w;
        float d1 = dot(m, b) - u_plane[i].w;
        if (d0 >= 0.0 && d1 < 0.0 && dot(vb, m) < 0.0) {
            float t = d0 / (d0 - d1);
            if (t < s) {
                s = t;
                n = m;
                resp = u_plane_resp[i];
            }
        }
    }
#endif
#if N_SPHERES > 0
    for (int i = 0; i < N_SPHERES; i++) {
        vec3 o = a - u_sphere[i].xyz;
        float r = u_sphere[i].w;
        float qa = dot(dir, dir);
        float qb = dot(o, dir);
        float qc = dot(o, o) - r * r;
        float disc = qb * qb - qa * qc;
        if (qc >= 0.0 && qb < 0.0 && qa > 0.0 && disc >= 0.0) {
            float t = (-qb - sqrt(disc)) / qa;
            vec3 m = normalize(o + t * dir);
            if (t <= 1.0 && t < s && dot(vb, m) < 0.0) {
                s = t;
                n = m;
                resp = u_sphere_resp[i];
            }
        }
    }
#endif
#if N_BOXES > 0
    for (int i = 0; i < N_BOXES; i++) {
        vec3 m;
        if (!(box_distance(i, a, m) >= 0.0)) continue;
        vec3 lo = u_box_min[i];
        vec3 hi = u_box_max[i];
        float t0 = 0.0;
        float t1 = 1.0;
        int axis = -1;
        bool hit = true;
        for (int k = 0; k < 3; k++) {
            if (dir[k] == 0.0) {
                hit = hit && a[k] >= lo[k] && a[k] <= hi[k];
                continue;
            }
            float u0 = (lo[k] - a[k]) / dir[k];
            float u1 = (hi[k] - a[k]) / dir[k];
            if (min(u0, u1) >= t0) {
                t0 = min(u0, u1);
                axis = k;
            }
            t1 = min(t1, max(u0, u1));
        }
        if (hit && axis >= 0 && t0 <= t1 && t0 < s) {
            m = vec3(0.0);
            m[axis] = dir[axis] > 0.0 ? -1.0 : 1.0;
            if (dot(vb, m) < 0.0) {
                s = t0;
                n = m;
                resp = u_box_resp[i];
            }
        }
    }
#endif
    return s <= 1.0;
}

// After Latta's response (which replays the step from x), what the path x -> xb still enters
// bounces there, UberFlow's way (§4.6): back to the entry point, the response of eq. 4-5, and
// the rest of the step's time along the new velocity; again for what that enters, up to
// MAX_BOUNCES times. A slow particle's replayed path enters nothing, so this changes only fast
// ones (a path longer than the gap between colliders), which keep their speed up to the
// resilience. False if an entry was still ahead at the bound.
bool bounce_on(vec3 x, inout vec3 vb, inout vec3 xb) {
    vec3 a = x;
    float t = u_dt;
    float s;
    vec3 n;
    vec2 resp;
    for (int k = 0; k < MAX_BOUNCES; k++) {
        if (!first_entry(a, xb, vb, s, n, resp)) return true;
        a = a + s * (xb - a);
        vb = collision_response(vb, n, resp);
        t *= 1.0 - s;
        xb = a + vb * t;
    }
    return !first_entry(a, xb, vb, s, n, resp);
}
#endif

// One collider for the explicit integrators: d_prev and n_prev at the previous position x,
// d_exp and n_exp at the expected one xb. Updates x (push-out), vb and xb.
void collide_explicit(float d_prev, vec3 n_prev, float d_exp, vec3 n_exp, vec2 resp,
                      inout vec3 x, vec3 v, inout vec3 vb, inout vec3 xb) {
    if (d_exp >= 0.0) return;
    if (d_prev < 0.0) {
        x -= (d_prev - SKIN) * n_prev;
        vb = caught_response(vb, n_prev);
    } else {
        vb = collision_response(vb, n_exp, resp);
    }
    xb = advance(x, v, vb);
}

void collide(inout vec3 x, vec3 v, inout vec3 vb, inout vec3 xb) {
    vec3 n0, n1;
    float d0, d1;
#if N_PLANES > 0
    for (int i = 0; i < N_PLANES; i++) {
        d0 = plane_distance(i, x, n0);
        d1 = plane_distance(i, xb, n1);
        collide_explicit(d0, n0, d1, n1, u_plane_resp[i], x, v, vb, xb);
    }
#endif
#if N_SPHERES > 0
    for (int i = 0; i < N_SPHERES; i++) {
        d0 = sphere_distance(i, x, n0);
        d1 = sphere_distance(i, xb, n1);
        collide_explicit(d0, n0, d1, n1, u_sphere_resp[i], x, v, vb, xb);
    }
#endif
#if N_BOXES > 0
    for (int i = 0; i < N_BOXES; i++) {
        d0 = box_distance(i, x, n0);
        d1 = box_distance(i, xb, n1);
        collide_explicit(d0, n0, d1, n1, u_box_resp[i], x, v, vb, xb);
    }
#endif
#ifdef SDF
    d0 = sdf_distance(x, n0);
    d1 = sdf_distance(xb, n1);
    collide_explicit(d0, n0, d1, n1, u_sdf_resp, x, v, vb, xb);
#endif
#ifdef HEIGHTFIELD
    d1 = height_distance(xb, n1);
    if (d1 < 0.0) {
        d0 = height_distance(x, n0);
        if (d0 < 0.0) {
            x.y -= d0 - SKIN;
            vb = caught_response(vb, n0);
            xb = advance(x, v, vb);
        } else {
            // UberFlow §4.6: back to the crossing point, reflect, travel the rest of the step.
            float s = d0 / (d0 - d1);
            vec3 xc = mix(x, xb, s);
            vec3 nc;
            height_distance(xc, nc);
            vb = collision_response(vb, nc, u_height_resp);
            xb = xc + vb * ((1.0 - s) * u_dt);
        }
    }
#endif
#if N_PLANES + N_SPHERES + N_BOXES > 0
    bounces_truncated = !bounce_on(x, vb, xb);
#endif
}
#else
// Verlet: Latta eq. 4-5 on the implied velocity v = (xn - x) / dt of a step that ends inside
// a collider; the new position becomes x + v' dt, so the next step's implied velocity
// (x_next - x_prev) / dt is the response v' (the previous position is rewritten in effect: the
// next step reads x as its previous position). Resilience and friction then act as on the
// explicit integrators' velocity.
void constrain(float d, vec3 n, vec2 resp, vec3 x, inout vec3 xn) {
    if (d >= 0.0) return;
    vec3 v = (xn - x) / u_dt;
    xn = x + collision_response(v, n, resp) * u_dt;
}

void collide(vec3 x, inout vec3 xn) {
    vec3 n;
    float d;
#if N_PLANES > 0
    for (int i = 0; i < N_PLANES; i++) {
        d = plane_distance(i, xn, n);
        constrain(d, n, u_plane_resp[i], x, xn);
    }
#endif
#if N_SPHERES > 0
    for (int i = 0; i < N_SPHERES; i++) {
        d = sphere_distance(i, xn, n);
        constrain(d, n, u_sphere_resp[i], x, xn);
    }
#endif
#if N_BOXES > 0
    for (int i = 0; i < N_BOXES; i++) {
        d = box_distance(i, xn, n);
        constrain(d, n, u_box_resp[i], x, xn);
    }
#endif
#ifdef SDF
    d = sdf_distance(xn, n);
    constrain(d, n, u_sdf_resp, x, xn);
#endif
#ifdef HEIGHTFIELD
    d = height_distance(xn, n);
    // Vertical distance to distance along the normal.
    constrain(d * n.y, n, u_height_resp, x, xn);
#endif
}
#endif

// Last resort: project any position still inside a collider out to SKIN above its surface and
// take away the velocity into the surface. One push-out can move a particle into another
// collider (a sphere sunk into a plane), so the sweep repeats, up to KEEP_OUTSIDE_SWEEPS times,
// until one moves nothing. Colliders that share a face (a box resting on the ground plane) would
// push a particle between them for ever: a push that would undo the previous one (its direction
// against the previous push's) instead carries the particle on through this collider along the
// previous push's direction until it is out, onto the surface of the union. Only a bounded
// collider (sphere, box, distance field) can be left that way; a plane or the height field is
// left along its own normal, and the bounded one it conflicts with is crossed in the next sweep.
const int KEEP_OUTSIDE_SWEEPS = 4;
// Steps of the walk through a collider: each advances by the distance to its nearest surface,
// a lower bound on the way out along any direction, so it never overshoots the exit; from SKIN
// inside it doubles until the far half, then leaves (about log2(size / SKIN) steps).
const int EXIT_STEPS = 24;

// Colliders numbered in the order of the sweep: planes, spheres, boxes, distance field, height
// field.
const int K_SPHERES = N_PLANES;
const int K_BOXES = K_SPHERES + N_SPHERES;
#ifdef SDF
const int K_SDF_END = K_BOXES + N_BOXES + 1;
#else
const int K_SDF_END = K_BOXES + N_BOXES;
#endif
#ifdef HEIGHTFIELD
const int N_COLLIDERS = K_SDF_END + 1;
#else
const int N_COLLIDERS = K_SDF_END;
#endif

// Collider k's distance at p, the direction u that a push-out moves along (the normal; up for
// the height field, whose distance is vertical), the normal n, and whether it is bounded.
float push_distance(int k, vec3 p, out vec3 u, out vec3 n, out bool bounded) {
    bounded = true;
    float d = 1e30;
    n = vec3(0.0, 1.0, 0.0);
#if N_PLANES > 0
    if (k < K_SPHERES) {
        bounded = false;
        d = plane_distance(k, p, n);
        u = n;
        return d;
    }
#endif
#if N_SPHERES > 0
    if (k < K_BOXES) {
        d = sphere_distance(k - K_SPHERES, p, n);
        u = n;
        return d;
    }
#endif
#if N_BOXES > 0
    if (k < K_BOXES + N_BOXES) {
        d = box_distance(k - K_BOXES, p, n);
        u = n;
        return d;
    }
#endif
#ifdef SDF
    if (k < K_SDF_END) {
        d = sdf_distance(p, n);
        u = n;
        return d;
    }
#endif
#ifdef HEIGHTFIELD
    bounded = false;
    d = height_distance(p, n);
#endif
    u = vec3(0.0, 1.0, 0.0);
    return d;
}

// Collider k's resilience (eps of its response).
float push_resilience(int k) {
#if N_PLANES > 0
    if (k < K_SPHERES) return u_plane_resp[k].y;
#endif
#if N_SPHERES > 0
    if (k < K_BOXES) return u_sphere_resp[k - K_SPHERES].y;
#endif
#if N_BOXES > 0
    if (k < K_BOXES + N_BOXES) return u_box_resp[k - K_BOXES].y;
#endif
#ifdef SDF
    if (k < K_SDF_END) return u_sdf_resp.y;
#endif
#ifdef HEIGHTFIELD
    return u_height_resp.y;
#else
    return 0.0;
#endif
}

void keep_outside_with(inout vec3 x, inout vec3 v, bool bounce);

// The projection after integration: what still moves inward loses its normal velocity (the
// colliders' response already ran on the step's path).
void keep_outside(inout vec3 x, inout vec3 v) {
    keep_outside_with(x, v, false);
}

// The projection after a collision response (UberFlow §4.6, the boundary after the response):
// a particle that the exchange or the separation sent into a collider bounces with the
// collider's resilience, so elastic walls keep the kinetic energy an elastic exchange kept.
void keep_outside_bouncing(inout vec3 x, inout vec3 v) {
    keep_outside_with(x, v, true);
}

void keep_outside_with(inout vec3 x, inout vec3 v, bool bounce) {
    vec3 u, n;
    bool bounded;
    vec3 last = vec3(0.0);
    for (int sweep = 0; sweep < KEEP_OUTSIDE_SWEEPS; sweep++) {
        bool moved = false;
        for (int k = 0; k < N_COLLIDERS; k++) {
            float d = push_distance(k, x, u, n, bounded);
            if (d >= 0.0) continue;
            if (bounded && dot(u, last) < 0.0) {
                for (int j = 0; j < EXIT_STEPS && d < 0.0; j++) {
                    x += (SKIN - d) * last;
                    d = push_distance(k, x, u, n, bounded);
                }
            } else {
                x -= (d - SKIN) * u;
                last = u;
            }
            v -= (bounce ? 1.0 + push_resilience(k) : 1.0) * min(dot(v, n), 0.0) * n;
            moved = true;
        }
        if (!moved) break;
    }
}
