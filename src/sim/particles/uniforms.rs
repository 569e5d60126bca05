//! The uniforms of the simulation programs that do not change during a run. Textures are not
//! among them: every draw names its own (`gl::Program::textures`).

use glam::{Vec3, Vec4};

use super::super::emit::EmitterUniforms;
use super::Fields;
use crate::gl::Program;
use crate::scene::{self, SceneFile};

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

/// Sets the uniforms that do not change during a run (emitters, masses, forces, colliders) on
/// `p`; uniforms the program lacks are skipped (the same set serves every simulation program).
pub(super) fn set_constants_for(
    p: &Program,
    s: &SceneFile,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) {
    p.bind();
    p.optional(|| set_constants(p, s, fields, size, seed, types));
}

fn set_constants(
    p: &Program,
    s: &SceneFile,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) {
    p.set_i32("u_width", size[0] as i32);
    p.set_ivec2("u_size", size[0] as i32, size[1] as i32);
    p.set_u32("u_seed", seed);
    p.set_f32("u_dt", s.time.dt);
    // Texel k of the other emitters is of type k mod their count; child emitters' types follow.
    p.set_i32("u_emitters", (types - s.emitters.child.len()).max(1) as i32);
    set_children(p, s);
    set_masses(p, s);
    set_emitters(p, s);
    set_forces(p, s, fields);
    set_colliders(p, s, fields);
}

/// The masses of glsl/common/mass.glsl, which integration and collisions share.
fn set_masses(p: &Program, s: &SceneFile) {
    let mut inv_mass = [1.0 / s.particles.mass; 4];
    let mut cycle = [1.0f32; 4];
    let (mut lo, mut hi) = ([s.particles.mass; 4], [s.particles.mass; 4]);
    for (k, e) in s.emitters.all().enumerate() {
        let [l, h] = mass_range(s, e);
        (lo[k], hi[k]) = (l, h);
        inv_mass[k] = 1.0 / (0.5 * (l + h));
        cycle[k] = e.cycle.unwrap_or(1.0);
    }
    p.set_vec4("u_inv_mass", Vec4::from(inv_mass));
    p.set_vec4("u_mass_lo", Vec4::from(lo));
    p.set_vec4("u_mass_hi", Vec4::from(hi));
    p.set_vec4("u_cycle", Vec4::from(cycle));
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
fn set_forces(p: &Program, s: &SceneFile, fields: &Fields) {
    let f = &s.forces;
    let gravity: Vec3 = f.gravity.iter().map(|g| v3(g.acceleration)).sum();
    p.set_vec3("u_gravity", gravity);
    p.set_f32("u_damping", f.damping.iter().map(|d| d.rate).sum());
    // The scene's forces (owner -1: every type), then each emitter's (owner: its type), in the
    // order Features counts them.
    let lists = || {
        std::iter::once((-1, f)).chain(
            s.emitters
                .all()
                .enumerate()
                .map(|(k, e)| (k as i32, &e.forces)),
        )
    };
    let owned = |list: fn(&scene::Forces) -> usize| {
        lists().flat_map(move |(owner, fs)| (0..list(fs)).map(move |j| (owner, fs, j)))
    };
    let (mut attractor, mut attractor_shape, mut attractor_owner) = (vec![], vec![], vec![]);
    for (owner, fs, j) in owned(|f| f.attractor.len()) {
        let a = &fs.attractor[j];
        attractor.push(v3(a.position).extend(a.strength));
        attractor_shape.push(Vec4::new(
            (a.falloff == scene::Falloff::Constant) as u8 as f32,
            a.max_distance.unwrap_or(-1.0),
            a.softening,
            0.0,
        ));
        attractor_owner.push(owner);
    }
    p.set_vec4_array("u_attractor", &attractor);
    p.set_vec4_array("u_attractor_shape", &attractor_shape);
    p.set_i32_array("u_attractor_owner", &attractor_owner);
    let (mut spring, mut spring_owner) = (vec![], vec![]);
    for (owner, fs, j) in owned(|f| f.spring.len()) {
        let sp = &fs.spring[j];
        spring.push(v3(sp.anchor).extend(sp.stiffness));
        spring_owner.push(owner);
    }
    p.set_vec4_array("u_spring", &spring);
    p.set_i32_array("u_spring_owner", &spring_owner);
    let (mut vortex, mut axis, mut shape, mut vortex_owner) = (vec![], vec![], vec![], vec![]);
    for (owner, fs, j) in owned(|f| f.vortex.len()) {
        let v = &fs.vortex[j];
        vortex.push(v3(v.point).extend(v.strength));
        axis.push(v3(v.axis).normalize());
        shape.push(vortex_shape(v));
        vortex_owner.push(owner);
    }
    p.set_vec4_array("u_vortex", &vortex);
    p.set_vec3_array("u_vortex_axis", &axis);
    p.set_vec4_array("u_vortex_shape", &shape);
    p.set_i32_array("u_vortex_owner", &vortex_owner);
    let mut damping = [0.0f32; 4];
    let mut type_gravity = Vec::new();
    for (k, e) in s.emitters.all().enumerate().take(4) {
        let g: Vec3 = e.forces.gravity.iter().map(|g| v3(g.acceleration)).sum();
        type_gravity.push(g);
        damping[k] = e.forces.damping.iter().map(|d| d.rate).sum();
    }
    p.set_vec3_array("u_type_gravity", &type_gravity);
    p.set_vec4("u_type_damping", Vec4::from(damping));
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

/// The colliders: planes, spheres, boxes, height and distance fields with their responses.
fn set_colliders(p: &Program, s: &SceneFile, fields: &Fields) {
    let c = &s.colliders;
    p.set_f32("u_slow_speed", c.slow_speed);
    let resp = |mu: f32, eps: f32| glam::Vec2::new(mu, eps);
    let plane = |pl: &scene::PlaneCollider| {
        let n = v3(pl.normal).normalize();
        n.extend(n.dot(v3(pl.point)))
    };
    p.set_vec4_array("u_plane", &c.plane.iter().map(plane).collect::<Vec<_>>());
    let plane_resp: Vec<_> = c
        .plane
        .iter()
        .map(|pl| resp(pl.friction, pl.resilience))
        .collect();
    p.set_vec2_array("u_plane_resp", &plane_resp);
    let sphere: Vec<_> = c
        .sphere
        .iter()
        .map(|sp| v3(sp.center_at(0.0)).extend(sp.radius))
        .collect();
    p.set_vec4_array("u_sphere", &sphere);
    let sphere_resp: Vec<_> = c
        .sphere
        .iter()
        .map(|sp| resp(sp.friction, sp.resilience))
        .collect();
    p.set_vec2_array("u_sphere_resp", &sphere_resp);
    p.set_vec3_array(
        "u_box_min",
        &c.boxes.iter().map(|b| v3(b.min)).collect::<Vec<_>>(),
    );
    p.set_vec3_array(
        "u_box_max",
        &c.boxes.iter().map(|b| v3(b.max)).collect::<Vec<_>>(),
    );
    let box_resp: Vec<_> = c
        .boxes
        .iter()
        .map(|b| resp(b.friction, b.resilience))
        .collect();
    p.set_vec2_array("u_box_resp", &box_resp);
    if let (Some(h), Some((_, field))) = (c.heightfield.first(), &fields.height) {
        p.set_vec4("u_height_extent", Vec4::from(h.extent));
        let [nx, nz] = field.resolution();
        p.set_ivec2("u_height_res", nx as i32, nz as i32);
        p.set_vec2("u_height_resp", resp(h.friction, h.resilience));
    }
    if let (Some(d), Some((_, field))) = (c.sdf.first(), &fields.sdf) {
        // The built field's, not the key's: a field from a file takes its shape from the file
        // (`resolution` is 0 there), and each axis may have its own.
        let [lo, hi] = field.bounds();
        p.set_vec3("u_sdf_min", lo);
        p.set_vec3("u_sdf_max", hi);
        let [rx, ry, rz] = field.resolution().map(|r| r as i32);
        p.set_ivec3("u_sdf_res", rx, ry, rz);
        p.set_vec2("u_sdf_resp", resp(d.friction, d.resilience));
    }
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

/// An emitter's mass range `[lo, hi]` (Latta §3.3): `mass_range`, else `[m, m]` with its type's
/// mass `mass` or `particles.mass`. The inverse mass of a particle is
/// `1 / mix(lo, hi, fract(4096 r))`, `r` the random number of its static texel.
pub fn mass_range(s: &SceneFile, e: &crate::scene::Emitter) -> [f32; 2] {
    e.mass_range.unwrap_or_else(|| {
        let m = e.mass.unwrap_or(s.particles.mass);
        [m, m]
    })
}

/// `u_vortex_shape[i]`: the Latta form (0/1), constant falloff (0/1), max distance (< 0: none),
/// softening.
pub fn vortex_shape(v: &crate::scene::Vortex) -> Vec4 {
    Vec4::new(
        (v.form == scene::VortexForm::Latta) as u8 as f32,
        (v.falloff == scene::Falloff::Constant) as u8 as f32,
        v.max_distance.unwrap_or(-1.0),
        v.softening,
    )
}
