// Test pass: evaluates the four samplers of sim/fields.glsl at one point per texel of u_points
// (xyz; the height field takes xz) and writes them through three render targets.

#include "sim/fields.glsl"

uniform sampler2D u_points;
uniform sampler2D u_height;
uniform vec4 u_height_extent;
uniform ivec2 u_height_res;
uniform sampler3D u_sdf;
uniform vec3 u_sdf_min;
uniform vec3 u_sdf_max;
uniform ivec3 u_sdf_res;
uniform sampler3D u_flow;
uniform vec3 u_flow_min;
uniform vec3 u_flow_max;
uniform ivec3 u_flow_res;

layout(location = 0) out vec4 o_height;
layout(location = 1) out vec4 o_sdf;
layout(location = 2) out vec4 o_flow;

void main() {
    vec3 p = texelFetch(u_points, ivec2(gl_FragCoord.xy), 0).xyz;
    o_height = heightfield_sample(u_height, u_height_extent, u_height_res, p.xz);
    o_sdf = vec4(sdf_sample(u_sdf, u_sdf_min, u_sdf_max, u_sdf_res, p),
                 sdf_normal(u_sdf, u_sdf_min, u_sdf_max, u_sdf_res, p));
    o_flow = vec4(flow_sample(u_flow, u_flow_min, u_flow_max, u_flow_res, p), 0.0);
}
