//! The uniforms of the simulation programs that do not change during a run, as one list that
//! every draw of those programs carries (each takes the names its program declares). Textures
//! are not among them: every draw names its own.

use glam::{Vec3, Vec4};

use super::super::emit::EmitterUniforms;
use super::Fields;
use crate::gl::{Uniform, UniformList};
use crate::sim::params::{self, Integration, Params, Shape};

/// The uniforms that do not change during a run (emitters, masses, forces, colliders), the
/// masses, forces and colliders from the scene's parameter blocks `params`: one list for every
/// simulation program, each draw giving the names its program declares.
pub(super) fn constants(
    params: &Params,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) -> UniformList {
    let mut p = UniformList::new();
    p.i32("u_width", size[0] as i32);
    p.ivec2("u_size", size[0] as i32, size[1] as i32);
    p.u32("u_seed", seed);
    p.f32("u_dt", params.integration.dt);
    // Texel k of the other emitters is of type k mod their count; child emitters' types follow.
    let e = &params.emitters;
    p.i32("u_emitters", (types - e.children).max(1) as i32);
    set_children(&mut p, e);
    set_masses(&mut p, &params.integration);
    set_emitters(&mut p, e);
    set_forces(&mut p, &params.integration, fields);
    set_colliders(&mut p, &params.colliders, fields);
    p
}

/// The masses of glsl/common/mass.glsl, which integration and collisions share.
fn set_masses(p: &mut UniformList, m: &Integration) {
    p.vec4("u_inv_mass", Vec4::from(m.inv_mass));
    p.vec4("u_mass_lo", Vec4::from(m.mass_lo));
    p.vec4("u_mass_hi", Vec4::from(m.mass_hi));
    p.vec4("u_cycle", Vec4::from(m.cycle));
}

/// The emitters' bursts, shapes and release clouds.
fn set_emitters(p: &mut UniformList, e: &params::Emitters) {
    p.vec4s("u_burst_time", &e.burst_time);
    p.vec4s("u_burst_end", &e.burst_end);
    p.extend(spawn_uniforms(&e.spawn));
    p.vec4s("u_release_spread", &e.release_spread);
    p.vec4("u_release_cloud", Vec4::from(e.release_cloud));
}

/// The emitters' spawn uniforms (glsl/sim/spawn.glsl): set once as constants, and for
/// emitters with curves given again in every integration draw at the step's time.
pub(super) fn spawn_uniforms(em: &[EmitterUniforms]) -> [(&'static str, Uniform); 5] {
    let field = |f: fn(&EmitterUniforms) -> Vec4| Uniform::Vec4s(em.iter().map(f).collect());
    [
        ("u_em_center", field(|e| e.center)),
        ("u_em_size", field(|e| e.size)),
        ("u_em_normal", field(|e| e.normal)),
        ("u_em_dir", field(|e| e.dir)),
        ("u_em_range", field(|e| e.range)),
    ]
}

/// The forces: summed gravity and damping, attractors, springs and vortices with their owners,
/// each type's own gravity and damping, the wind field and the spin's constants.
fn set_forces(p: &mut UniformList, m: &Integration, fields: &Fields) {
    p.vec3("u_gravity", m.gravity.unwrap_or(Vec3::ZERO));
    p.f32("u_damping", m.damping.unwrap_or(0.0));
    let attractor: Vec<Vec4> = m.attractors.iter().map(|a| a.at).collect();
    p.vec4s("u_attractor", &attractor);
    let attractor_shape: Vec<Vec4> = m.attractors.iter().map(|a| a.shape).collect();
    p.vec4s("u_attractor_shape", &attractor_shape);
    let attractor_owner: Vec<i32> = m.attractors.iter().map(|a| a.owner).collect();
    p.i32s("u_attractor_owner", &attractor_owner);
    let spring: Vec<Vec4> = m.springs.iter().map(|sp| sp.at).collect();
    p.vec4s("u_spring", &spring);
    let spring_owner: Vec<i32> = m.springs.iter().map(|sp| sp.owner).collect();
    p.i32s("u_spring_owner", &spring_owner);
    let vortex: Vec<Vec4> = m.vortices.iter().map(|v| v.at).collect();
    p.vec4s("u_vortex", &vortex);
    let axis: Vec<Vec3> = m.vortices.iter().map(|v| v.axis).collect();
    p.vec3s("u_vortex_axis", &axis);
    let shape: Vec<Vec4> = m.vortices.iter().map(|v| v.shape).collect();
    p.vec4s("u_vortex_shape", &shape);
    let owner: Vec<i32> = m.vortices.iter().map(|v| v.owner).collect();
    p.i32s("u_vortex_owner", &owner);
    p.vec3s("u_type_gravity", &m.type_gravity);
    p.vec4("u_type_damping", Vec4::from(m.type_damping));
    if let (Some(w), Some((_, field))) = (&m.wind, &fields.flow) {
        p.vec3("u_flow_min", w.bounds[0]);
        p.vec3("u_flow_max", w.bounds[1]);
        let [rx, ry, rz] = field.resolution().map(|r| r as i32);
        p.ivec3("u_flow_res", rx, ry, rz);
        p.f32("u_drag", w.drag);
    }
    if let Some(k) = m.spin {
        // Spinning spheres (glsl/collide/spin.glsl): their radius and the pairs' friction.
        p.f32("u_spin_radius", k.x);
        p.f32("u_friction", k.y);
    }
}

/// The colliders: planes, spheres, boxes, height and distance fields with their responses, the
/// `i`th of its kind in `u_KIND[i]`. The fields' textures give their sizes (and the distance
/// field's bounds: a field from a file takes its shape from the file, `resolution` 0 there).
fn set_colliders(p: &mut UniformList, c: &params::Colliders, fields: &Fields) {
    p.f32("u_slow_speed", c.slow_speed);
    // Each kind's colliders in `u_KIND[i]`, in the order of the block.
    let (mut plane, mut plane_resp) = (Vec::new(), Vec::new());
    let (mut sphere, mut sphere_resp) = (Vec::new(), Vec::new());
    let (mut box_min, mut box_max, mut box_resp) = (Vec::new(), Vec::new(), Vec::new());
    let (mut heights, mut sdfs) = (0, 0);
    for col in &c.list {
        let resp = col.resp;
        match &col.shape {
            Shape::Plane(pl) => {
                plane.push(*pl);
                plane_resp.push(resp);
            }
            Shape::Sphere(sp) => {
                sphere.push(*sp);
                sphere_resp.push(resp);
            }
            Shape::Box(lo, hi) => {
                box_min.push(*lo);
                box_max.push(*hi);
                box_resp.push(resp);
            }
            Shape::HeightField(extent) => {
                if let (0, Some((_, field))) = (heights, &fields.height) {
                    p.vec4("u_height_extent", *extent);
                    let [nx, nz] = field.resolution();
                    p.ivec2("u_height_res", nx as i32, nz as i32);
                    p.vec2("u_height_resp", resp);
                }
                heights += 1;
            }
            Shape::Sdf(..) => {
                if let (0, Some((_, field))) = (sdfs, &fields.sdf) {
                    let [lo, hi] = field.bounds();
                    p.vec3("u_sdf_min", lo);
                    p.vec3("u_sdf_max", hi);
                    let [rx, ry, rz] = field.resolution().map(|r| r as i32);
                    p.ivec3("u_sdf_res", rx, ry, rz);
                    p.vec2("u_sdf_resp", resp);
                }
                sdfs += 1;
            }
        }
    }
    p.vec4s("u_plane", &plane);
    p.vec2s("u_plane_resp", &plane_resp);
    p.vec4s("u_sphere", &sphere);
    p.vec2s("u_sphere_resp", &sphere_resp);
    p.vec3s("u_box_min", &box_min);
    p.vec3s("u_box_max", &box_max);
    p.vec2s("u_box_resp", &box_resp);
}

/// The child emitters' layout (glsl/sim/children.glsl).
fn set_children(p: &mut UniformList, e: &params::Emitters) {
    p.i32("u_child_start", e.layout.parent_slots as i32);
    p.i32("u_children", e.layout.ranges.len() as i32);
    p.ivec4s("u_child", &e.child);
    p.vec4s("u_child_more", &e.child_more);
}
