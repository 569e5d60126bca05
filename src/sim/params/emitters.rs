//! The emitters block: what the births (the CPU allocator's, `src/sim/particles/births.rs`) and
//! the spawn code of the passes (`glsl/sim/spawn.glsl`, `glsl/sim/children.glsl`) read, built
//! once from the scene's `[[emitters.*]]`.

use glam::Vec4;

use crate::scene::{self, ChildLayout, EmitterKind, SceneFile};
use crate::sim::emit::EmitterUniforms;

/// The emitters, in type order (a particle's type is its emitter's place in [`list`](Self::list)).
#[derive(Debug, Clone, PartialEq)]
pub struct Emitters {
    /// Every emitter as the scene gives it, curves and all: the births and the spawn uniforms
    /// take its values at their time ([`EmitterUniforms::at`]).
    pub list: Vec<scene::Emitter>,
    /// The allocator emitters: the first this many of `list` (the first kind of
    /// [`EmitterKind::ALL`]).
    pub allocator: usize,
    /// The child emitters: the last this many of `list`.
    pub children: usize,
    /// Some emitter value is a curve (`src/scene/curve.rs`): the spawn uniforms are set every
    /// step, and allocator births take the emitter at their time.
    pub animated: bool,
    /// Each emitter's spawn uniforms at time 0 (what scenes without curves upload once).
    pub spawn: Vec<EmitterUniforms>,
    /// Each emitter's burst times: `u_burst_time`.
    pub burst_time: Vec<Vec4>,
    /// Each emitter's births up to and including each burst: `u_burst_end`.
    pub burst_end: Vec<Vec4>,
    /// Each emitter's release spread and the side of its cube of slots: `u_release_spread`.
    pub release_spread: Vec<Vec4>,
    /// Each emitter's texels per release cloud (0: none): `u_release_cloud`.
    pub release_cloud: [f32; 4],
    /// Where parents and children live in the state texture.
    pub layout: ChildLayout,
    /// Each child emitter's start, texels per parent, parent type, births on death: `u_child`.
    pub child: Vec<[i32; 4]>,
    /// Each child emitter's trail rate, inherited velocity, type: `u_child_more`.
    pub child_more: Vec<Vec4>,
}

impl Emitters {
    /// The emitters block of `s`.
    pub fn of(s: &SceneFile) -> Self {
        let list: Vec<scene::Emitter> = s.emitters.all().cloned().collect();
        let (mut burst_time, mut burst_end) = (Vec::new(), Vec::new());
        let mut cloud = [0.0f32; 4];
        let mut release_spread = Vec::new();
        for (k, e) in list.iter().enumerate() {
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
        let layout = s.child_layout();
        let (mut child, mut child_more) = (Vec::new(), Vec::new());
        for (r, e) in layout
            .ranges
            .iter()
            .zip(s.emitters.of_kind(EmitterKind::Child))
        {
            child.push([r.start, r.per_parent, r.parent, r.on_death].map(|v| v as i32));
            let inherit = e.inherit_velocity.unwrap_or(1.0);
            child_more.push(Vec4::new(r.trail_rate, inherit, r.kind as f32, 0.0));
        }
        Emitters {
            spawn: list.iter().map(EmitterUniforms::new).collect(),
            allocator: s.emitters.of_kind(EmitterKind::Allocator).len(),
            children: s.emitters.of_kind(EmitterKind::Child).len(),
            animated: crate::scene::has_curves(s),
            list,
            burst_time,
            burst_end,
            release_spread,
            release_cloud: cloud,
            layout,
            child,
            child_more,
        }
    }

    /// The allocator emitters, in type order.
    pub fn allocator(&self) -> &[scene::Emitter] {
        &self.list[..self.allocator]
    }

    /// Each emitter's spawn uniforms at time `t`, its curves taken there.
    pub fn spawn_at(&self, t: f32) -> Vec<EmitterUniforms> {
        self.list
            .iter()
            .map(|e| EmitterUniforms::at(e, t))
            .collect()
    }
}
