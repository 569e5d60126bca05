//! The uniforms of the simulation programs that do not change during a run. Textures are not
//! among them: every draw names its own (`gl::Program::textures`).

use glam::{Vec3, Vec4};

use super::super::emit::EmitterUniforms;
use super::Fields;
use crate::gl::Program;
use crate::scene::SceneFile;
use crate::sim::params::{self, Integration, Params, Shape};

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

/// Sets the uniforms that do not change during a run (emitters, masses, forces, colliders) on
/// `p`, the masses, forces and colliders from the scene's parameter blocks `params`; uniforms
/// the program lacks are skipped (the same set serves every simulation program).
pub(super) fn set_constants_for(
    p: &Program,
    s: &SceneFile,
    params: &Params,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) {
    p.bind();
    p.optional(|| set_constants(p, s, params, fields, size, seed, types));
}

fn set_constants(
    p: &Program,
    s: &SceneFile,
    params: &Params,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) {
    p.set_i32("u_width", size[0] as i32);
    p.set_ivec2("u_size", size[0] as i32, size[1] as i32);
    p.set_u32("u_seed", seed);
    p.set_f32("u_dt", params.integration.dt);
    // Texel k of the other emitters is of type k mod their count; child emitters' types follow.
    p.set_i32("u_emitters", (types - s.emitters.child.len()).max(1) as i32);
    set_children(p, s);
    set_masses(p, &params.integration);
    set_emitters(p, s);
    set_forces(p, s, &params.integration, fields);
    set_colliders(p, &params.colliders, fields);
}

/// The masses of glsl/common/mass.glsl, which integration and collisions share.
fn set_masses(p: &Program, m: &Integration) {
    p.set_vec4("u_inv_mass", Vec4::from(m.inv_mass));
    p.set_vec4("u_mass_lo", Vec4::from(m.mass_lo));
    p.set_vec4("u_mass_hi", Vec4::from(m.mass_hi));
    p.set_vec4("u_cycle", Vec4::from(m.cycle));
}

/// The emitters' bursts, shapes and release clouds.
fn set_emitters(p: &Program, s: &SceneFile) {
    let (mut burst_time, mut burst_end) = (Vec::new(), Vec::new());
    for e in s.emitters.all() {
        let (mut time, mut end) = ([0f32; 4], [0f32; 4]);
        let mut total = 0u64;
        for b in 0..4 {
            if let Some(burst) = e.bursts.get(b) {
                time[b] = burst.time;
                total += burst.count as u64;
            }
            end[b] = total as f32;
        }
        burst_time.push(Vec4::from(time));
        burst_end.push(Vec4::from(end));
    }
    p.set_vec4_array("u_burst_time", &burst_time);
    p.set_vec4_array("u_burst_end", &burst_end);
    spawn_uniforms(p, s, 0.0);
    let mut cloud = [0.0f32; 4];
    let mut release_spread = Vec::new();
    for (k, e) in s.emitters.all().enumerate() {
        let r = e.release_spread.unwrap_or([0.0; 3]);
        // Places per cycle: one per release (a step), or one per cloud of texels; a cube of
        // slots holds them all.
        let places = match e.release_cloud {
            Some(c) => (s.particle_count() as f32 / c as f32).ceil(),
            None => (e.cycle.unwrap_or(1.0) / s.time.dt).round(),
        };
        let side = places.max(1.0).cbrt().ceil();
        release_spread.push(Vec4::new(r[0], r[1], r[2], side));
        cloud[k] = e.release_cloud.unwrap_or(0) as f32;
    }
    p.set_vec4_array("u_release_spread", &release_spread);
    p.set_vec4("u_release_cloud", Vec4::from(cloud));
}

/// The emitters' spawn uniforms (glsl/sim/spawn.glsl) with their curves at time `t`.
fn spawn_uniforms(p: &Program, s: &SceneFile, t: f32) {
    let em: Vec<EmitterUniforms> = s
        .emitters
        .all()
        .map(|e| EmitterUniforms::at(e, t))
        .collect();
    let field = |f: fn(&EmitterUniforms) -> Vec4| em.iter().map(f).collect::<Vec<_>>();
    p.set_vec4_array("u_em_center", &field(|e| e.center));
    p.set_vec4_array("u_em_size", &field(|e| e.size));
    p.set_vec4_array("u_em_normal", &field(|e| e.normal));
    p.set_vec4_array("u_em_dir", &field(|e| e.dir));
    p.set_vec4_array("u_em_range", &field(|e| e.range));
}

/// Sets the spawn uniforms of the bound program `p` at time `t` (scenes with curves, every
/// step); a program without them is left alone.
pub(super) fn set_spawn(p: &Program, s: &SceneFile, t: f32) {
    p.optional(|| spawn_uniforms(p, s, t));
}

/// The forces: summed gravity and damping, attractors, springs and vortices with their owners,
/// each type's own gravity and damping, the wind field and the spin's constants.
fn set_forces(p: &Program, s: &SceneFile, m: &Integration, fields: &Fields) {
    p.set_vec3("u_gravity", m.gravity.unwrap_or(Vec3::ZERO));
    p.set_f32("u_damping", m.damping.unwrap_or(0.0));
    let attractor: Vec<Vec4> = m.attractors.iter().map(|a| a.at).collect();
    p.set_vec4_array("u_attractor", &attractor);
    let attractor_shape: Vec<Vec4> = m.attractors.iter().map(|a| a.shape).collect();
    p.set_vec4_array("u_attractor_shape", &attractor_shape);
    let attractor_owner: Vec<i32> = m.attractors.iter().map(|a| a.owner).collect();
    p.set_i32_array("u_attractor_owner", &attractor_owner);
    let spring: Vec<Vec4> = m.springs.iter().map(|sp| sp.at).collect();
    p.set_vec4_array("u_spring", &spring);
    let spring_owner: Vec<i32> = m.springs.iter().map(|sp| sp.owner).collect();
    p.set_i32_array("u_spring_owner", &spring_owner);
    let vortex: Vec<Vec4> = m.vortices.iter().map(|v| v.at).collect();
    p.set_vec4_array("u_vortex", &vortex);
    let axis: Vec<Vec3> = m.vortices.iter().map(|v| v.axis).collect();
    p.set_vec3_array("u_vortex_axis", &axis);
    let shape: Vec<Vec4> = m.vortices.iter().map(|v| v.shape).collect();
    p.set_vec4_array("u_vortex_shape", &shape);
    let owner: Vec<i32> = m.vortices.iter().map(|v| v.owner).collect();
    p.set_i32_array("u_vortex_owner", &owner);
    p.set_vec3_array("u_type_gravity", &m.type_gravity);
    p.set_vec4("u_type_damping", Vec4::from(m.type_damping));
    let f = &s.forces;
    if let (Some(w), Some((_, field))) = (f.wind.first(), &fields.flow) {
        p.set_vec3("u_flow_min", v3(w.bounds[0]));
        p.set_vec3("u_flow_max", v3(w.bounds[1]));
        let [rx, ry, rz] = field.resolution().map(|r| r as i32);
        p.set_ivec3("u_flow_res", rx, ry, rz);
        p.set_f32("u_drag", w.drag);
    }
    if let Some(k) = s.collisions.as_ref().filter(|k| k.spin) {
        // Spinning spheres (glsl/collide/spin.glsl): their radius and the pairs' friction.
        p.set_f32("u_spin_radius", k.radius);
        p.set_f32("u_friction", k.friction);
    }
}

/// The colliders: planes, spheres, boxes, height and distance fields with their responses, the
/// `i`th of its kind in `u_KIND[i]`. The fields' textures give their sizes (and the distance
/// field's bounds: a field from a file takes its shape from the file, `resolution` 0 there).
fn set_colliders(p: &Program, c: &params::Colliders, fields: &Fields) {
    p.set_f32("u_slow_speed", c.slow_speed);
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
                    p.set_vec4("u_height_extent", *extent);
                    let [nx, nz] = field.resolution();
                    p.set_ivec2("u_height_res", nx as i32, nz as i32);
                    p.set_vec2("u_height_resp", resp);
                }
                heights += 1;
            }
            Shape::Sdf(..) => {
                if let (0, Some((_, field))) = (sdfs, &fields.sdf) {
                    let [lo, hi] = field.bounds();
                    p.set_vec3("u_sdf_min", lo);
                    p.set_vec3("u_sdf_max", hi);
                    let [rx, ry, rz] = field.resolution().map(|r| r as i32);
                    p.set_ivec3("u_sdf_res", rx, ry, rz);
                    p.set_vec2("u_sdf_resp", resp);
                }
                sdfs += 1;
            }
        }
    }
    p.set_vec4_array("u_plane", &plane);
    p.set_vec2_array("u_plane_resp", &plane_resp);
    p.set_vec4_array("u_sphere", &sphere);
    p.set_vec2_array("u_sphere_resp", &sphere_resp);
    p.set_vec3_array("u_box_min", &box_min);
    p.set_vec3_array("u_box_max", &box_max);
    p.set_vec2_array("u_box_resp", &box_resp);
}

/// The child emitters' layout (glsl/sim/children.glsl).
fn set_children(p: &Program, s: &SceneFile) {
    let layout = s.child_layout();
    p.set_i32("u_child_start", layout.parent_slots as i32);
    p.set_i32("u_children", layout.ranges.len() as i32);
    let (mut child, mut more) = (Vec::new(), Vec::new());
    for (r, e) in layout.ranges.iter().zip(&s.emitters.child) {
        child.push([r.start, r.per_parent, r.parent, r.on_death].map(|v| v as i32));
        let inherit = e.inherit_velocity.unwrap_or(1.0);
        more.push(Vec4::new(r.trail_rate, inherit, r.kind as f32, 0.0));
    }
    p.set_ivec4_array("u_child", &child);
    p.set_vec4_array("u_child_more", &more);
}
