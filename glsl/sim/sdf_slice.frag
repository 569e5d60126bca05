// UberFlow §4.6, boundary conditions: "we first scan-convert the original scene into a signed
// distance representation. The distance field is stored in a 3D texture map". One full-screen
// pass per z slice k of the field (src/sim/fields/scan.rs), drawn into layer k of the 3D texture:
// the fragment at texel (i, j) computes the signed distance of node (i, j, k) to a triangle mesh,
// by brute force over the triangles (a few hundred at most), read with texelFetch.
//
// - Distance: the least distance to a triangle, through the closest point on each triangle
//   (Ericson, Real-Time Collision Detection §5.1.5: the Voronoi regions of vertices, edges and
//   face tested in turn).
// - Sign: the generalised winding number w = sum of the solid angles the triangles subtend at
//   the node, over 4 pi (van Oosterom and Strackee's formula for one triangle's solid angle).
//   w is 1 inside a closed mesh with outward faces, -1 with inward ones, 0 outside; the node is
//   inside where |w| > 1/2, which does not depend on where a ray would cross an edge.
// The CPU twin is DistanceField::analytic_distance (src/sim/fields/mesh.rs), in double precision.

uniform sampler2D u_triangles;  // texel (v, t): vertex v (0..2) of triangle t, xyz
uniform int u_triangle_count;
uniform vec3 u_min;             // the field's bounds (the nodes of the first and last texels)
uniform vec3 u_max;
uniform ivec3 u_res;            // nodes per axis
uniform int u_slice;            // k: the slice this pass writes

layout(location = 0) out vec4 o_distance;

const float PI = 3.14159265358979;

// The point of triangle (a, b, c) closest to p.
vec3 closest_on_triangle(vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 ab = b - a;
    vec3 ac = c - a;
    vec3 ap = p - a;
    float d1 = dot(ab, ap);
    float d2 = dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        return a;
    }
    vec3 bp = p - b;
    float d3 = dot(ab, bp);
    float d4 = dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        return b;
    }
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        return a + (d1 / (d1 - d3)) * ab;
    }
    vec3 cp = p - c;
    float d5 = dot(ab, cp);
    float d6 = dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        return c;
    }
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        return a + (d2 / (d2 - d6)) * ac;
    }
    float va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    }
    float denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

// Solid angle of triangle (a, b, c) (vertices relative to the node), signed by its orientation:
// tan(omega / 2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|).
float solid_angle(vec3 a, vec3 b, vec3 c) {
    float la = length(a);
    float lb = length(b);
    float lc = length(c);
    float num = dot(a, cross(b, c));
    float den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    // On a vertex or edge both vanish: the node is on the surface, where the sign is moot.
    if (num == 0.0 && den == 0.0) {
        return 0.0;
    }
    return 2.0 * atan(num, den);
}

void main() {
    ivec3 node = ivec3(ivec2(gl_FragCoord.xy), u_slice);
    vec3 h = (u_max - u_min) / vec3(u_res - ivec3(1));
    vec3 p = u_min + vec3(node) * h;
    float d2 = 3.4e38;
    float omega = 0.0;
    for (int t = 0; t < u_triangle_count; t++) {
        vec3 a = texelFetch(u_triangles, ivec2(0, t), 0).xyz;
        vec3 b = texelFetch(u_triangles, ivec2(1, t), 0).xyz;
        vec3 c = texelFetch(u_triangles, ivec2(2, t), 0).xyz;
        vec3 q = p - closest_on_triangle(p, a, b, c);
        d2 = min(d2, dot(q, q));
        omega += solid_angle(a - p, b - p, c - p);
    }
    float w = omega / (4.0 * PI);
    float d = sqrt(d2);
    o_distance = vec4(abs(w) > 0.5 ? -d : d, 0.0, 0.0, 0.0);
}
