// The colliders' shading: Lambert from one fixed light plus an ambient term, lit on the side
// facing the eye (planes and meshes are seen from both sides), and on planes a checker of cells
// of v_color.a metres, so that their extent and tilt read at a glance. Opaque: alpha 1, which the
// under operator's composite (premultiplied) takes as is.

uniform vec3 u_eye;
uniform vec3 u_light; // unit vector towards the light

in vec3 v_world;
in vec3 v_normal;
flat in vec4 v_color;
layout(location = 0) out vec4 o_color;

void main() {
    vec3 n = normalize(v_normal);
    vec3 c = v_color.rgb;
    if (v_color.a > 0.0) {
        // The cell of a 3D checker, sampled half a cell off the plane along its normal so that
        // a plane lying on a cell boundary does not flicker between two cells.
        ivec3 cell = ivec3(floor((v_world + n * 0.5 * v_color.a) / v_color.a));
        if (((cell.x + cell.y + cell.z) & 1) != 0) {
            c *= 0.7;
        }
    }
    if (dot(n, u_eye - v_world) < 0.0) {
        n = -n;
    }
    float diffuse = max(dot(n, u_light), 0.0);
    o_color = vec4(c * (0.25 + 0.75 * diffuse), 1.0);
}
