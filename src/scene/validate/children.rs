//! `[[emitters.child]]`: emitters that emit (the thesis §2: "sendet die Quelle der ersten Ebene
//! keine Partikel aus sondern weitere Partikelquellen"). Their texels are a fixed layout of the
//! state texture ([`ChildLayout`]): the parents first, then each child emitter's range, in which
//! every parent texel owns `per_parent` consecutive texels.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Emitter, Integrator, SceneFile, StateModel, UpdatePasses, VelocityFormat,
};

use Key::{Index as I, Name as N};

/// One child emitter's range of the state texture.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ChildRange {
    /// The first texel of the range.
    pub start: u32,
    /// Texels per parent texel: parent texel `p` owns `start + p · per_parent ..` of them.
    pub per_parent: u32,
    /// The parent emitter's type.
    pub parent: u32,
    /// This emitter's type (after every parent emitter's).
    pub kind: u32,
    /// Children born at a parent's death: the first `on_death` texels of each parent's block.
    pub on_death: u32,
    /// Trail children per second of a live parent, in the rest of the block in turn.
    pub trail_rate: f32,
}

/// Where parents and children live in the state texture.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChildLayout {
    /// Texels `0 .. parent_slots` hold the other emitters' particles (a parent texel may hold a
    /// particle of any of them; only those of a range's `parent` type have children there).
    pub parent_slots: u32,
    /// The child emitters' ranges, in order, from `parent_slots` on.
    pub ranges: Vec<ChildRange>,
}

impl ChildLayout {
    /// Texels that the layout uses; the rest of the texture stays dead.
    pub fn used(&self) -> u64 {
        self.parent_slots as u64
            + (self.ranges.iter())
                .map(|r| r.per_parent as u64 * self.parent_slots as u64)
                .sum::<u64>()
    }
}

impl SceneFile {
    /// The layout of the state texture for child emitters: with `N` texels and `K_c` texels per
    /// parent for child emitter `c`, `P = ⌊N / (1 + Σ K_c)⌋` parent texels, then `P · K_c`
    /// texels per child emitter. Without child emitters, every texel is a parent texel.
    pub fn child_layout(&self) -> ChildLayout {
        let n = self.particle_count();
        let children = &self.emitters.child;
        let per: u64 = children
            .iter()
            .map(|c| c.per_parent.unwrap_or(0) as u64)
            .sum();
        let parent_slots = (n / (1 + per)).min(u32::MAX as u64) as u32;
        let parents = self.emitters.parents() as u32;
        let mut start = parent_slots;
        let ranges = (children.iter().enumerate())
            .map(|(c, e)| {
                let r = ChildRange {
                    start,
                    per_parent: e.per_parent.unwrap_or(0),
                    parent: e.parent.unwrap_or(0),
                    kind: parents + c as u32,
                    on_death: e.on_death.unwrap_or(0),
                    trail_rate: e.trail_rate.unwrap_or(0.0),
                };
                start = start.saturating_add(r.per_parent.saturating_mul(parent_slots));
                r
            })
            .collect();
        ChildLayout {
            parent_slots,
            ranges,
        }
    }

    /// Texels the non-child emitters may use (their texel `k` is of type `k mod` their count,
    /// as before, within this range).
    pub fn parent_slots(&self) -> u64 {
        self.child_layout().parent_slots as u64
    }
}

/// What [`SceneFile::child_capacity_check`] predicts: a child emitter whose trail texels are
/// asked again before their children die, so that births will be dropped.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ChildCapacityWarning {
    /// The child emitter (its place among `[[emitters.child]]`).
    pub emitter: usize,
    /// Children of one parent's trail that a full turn of its texels must hold: trail_rate × the
    /// longest life.
    pub live: f64,
    /// The trail's texels per parent: per_parent − on_death.
    pub texels: u32,
    /// The smallest per_parent that holds them.
    pub per_parent: u32,
}

impl std::fmt::Display for ChildCapacityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "child emitter {}: a trail texel's turn comes back before its child dies \
             (trail_rate × life = {:.1} children per parent, {} trail texels): births will be \
             dropped; use per_parent = {} or lower trail_rate or life",
            self.emitter, self.live, self.texels, self.per_parent
        )
    }
}

impl SceneFile {
    /// Predicts the child births that will be dropped: trail texel j is asked every
    /// (per_parent − on_death) / trail_rate seconds, and its child lives up to the longest
    /// life, so a trail needs trail_rate × life_max texels. Bursts are not predicted (they
    /// depend on how often a parent dies). A pure function of the scene: `scene check` prints
    /// it, and the run's count is `ParticleSim::dropped_child_births`.
    pub fn child_capacity_check(&self) -> Vec<ChildCapacityWarning> {
        let mut out = Vec::new();
        for (i, e) in self.emitters.child.iter().enumerate() {
            let rate = e.trail_rate.unwrap_or(0.0) as f64;
            let life = e.longest_life().map_or(0.0, |l| l as f64);
            let on_death = e.on_death.unwrap_or(0);
            let texels = e.per_parent.unwrap_or(0).saturating_sub(on_death);
            let live = rate * life;
            if rate > 0.0 && live > texels as f64 {
                out.push(ChildCapacityWarning {
                    emitter: i,
                    live,
                    texels,
                    per_parent: on_death.saturating_add(live.floor() as u32 + 1),
                });
            }
        }
        out
    }
}

/// Child emitters: a parent of another kind, their slots, their births, and the features they
/// cannot be combined with (those that move texels or keep no velocity).
pub(super) fn children(s: &SceneFile) -> Check {
    let em = &s.emitters;
    let parents = em.parents();
    for (i, e) in em.child.iter().enumerate() {
        let at = [N("emitters"), N("child"), I(i)];
        child(&at, e, parents)?;
        child_births(&at, e)?;
    }
    if em.child.is_empty() {
        return Ok(());
    }
    child_combinations(s)
}

/// `[[emitters.child]]` at `at`: no keys of the other kinds, the spawn keys, a parent, a life.
fn child(at: &[Key], e: &Emitter, parents: usize) -> Check {
    let key = |k| [at, &[N(k)]].concat();
    if let Some(k) = [
        ("rate", e.rate.is_some()),
        ("allocator", e.allocator.is_some()),
        ("cycle", e.cycle.is_some()),
        ("release_spread", e.release_spread.is_some()),
        ("release_cloud", e.release_cloud.is_some()),
        ("bursts", !e.bursts.is_empty()),
    ]
    .iter()
    .find(|k| k.1)
    {
        return fail(
            key(k.0),
            format!(
                "`{}` does not apply to child emitters: their births follow their parents \
                 (use trail_rate and on_death)",
                k.0
            ),
        );
    }
    super::emitters::check_spawn(at, e)?;
    if parents == 0 {
        return fail(
            at.to_vec(),
            "a child emitter needs a parent: add an allocator, timestamp or initial emitter",
        );
    }
    if e.parent.unwrap_or(0) as usize >= parents {
        return fail(
            key("parent"),
            format!(
                "parent {} is not an emitter of this scene: give the type number of one of \
                 its {parents} other emitter(s), 0 to {}",
                e.parent.unwrap_or(0),
                parents - 1
            ),
        );
    }
    if e.life.is_none() {
        return fail(
            at.to_vec(),
            "a child emitter needs `life` = [min, max] seconds",
        );
    }
    Ok(())
}

/// `[[emitters.child]]` at `at`: texels per parent, births at death and along the trail.
fn child_births(at: &[Key], e: &Emitter) -> Check {
    let key = |k| [at, &[N(k)]].concat();
    let k = match e.per_parent {
        None | Some(0) => {
            return fail(
                key("per_parent"),
                "a child emitter needs per_parent, the texels reserved for each parent's \
                 children (at least 1)",
            )
        }
        Some(k) => k,
    };
    let b = e.on_death.unwrap_or(0);
    if b > k {
        return fail(
            key("on_death"),
            format!(
                "on_death {b} children do not fit the {k} texels per parent: raise \
                 per_parent to at least {b}"
            ),
        );
    }
    match e.trail_rate {
        // The shader numbers trail births in 32-bit integers: age × rate stays below 2³¹
        // for ages up to 2·10⁵ s (two days) at the largest rate.
        Some(r) if !(r.is_finite() && (0.0..=1e4).contains(&r)) => {
            return fail(
                key("trail_rate"),
                format!("trail_rate {r} must be a number of children per second in [0, 1e4]"),
            )
        }
        Some(r) if r > 0.0 && b == k => {
            return fail(
                key("trail_rate"),
                format!(
                    "the trail has no texels: on_death takes all {k} per parent; raise \
                     per_parent above {b}"
                ),
            )
        }
        None | Some(0.0) if b == 0 => {
            return fail(
                at.to_vec(),
                "a child emitter with neither trail_rate nor on_death never emits: give one",
            )
        }
        _ => {}
    }
    if let Some(f) = e
        .inherit_velocity
        .filter(|f| !(f.is_finite() && f.abs() <= 10.0))
    {
        return fail(
            key("inherit_velocity"),
            format!(
                "inherit_velocity {f} must be a factor within [-10, 10] (1: the parent's velocity)"
            ),
        );
    }
    Ok(())
}

/// With child emitters: room for a parent and its children, and no feature that moves texels
/// or keeps no velocity.
fn child_combinations(s: &SceneFile) -> Check {
    let at = |k| path(&[N("emitters"), N("child"), I(0), N(k)]);
    let layout = s.child_layout();
    if layout.parent_slots == 0 {
        return fail(
            at("per_parent"),
            format!(
                "the {} texels of particles.size cannot hold one parent and its children: \
                 give more particles.size or a smaller per_parent",
                s.particle_count()
            ),
        );
    }
    let why = "child emitters bind texels to their parents' texels and count dropped births \
               in velocity.w";
    let refuse = |key: Vec<Key>, what: &str| fail(key, format!("{why}: {what}"));
    if s.integrator == Integrator::Verlet {
        return refuse(
            path(&[N("integrator")]),
            "Verlet keeps no velocity; use euler, uberflow, heun, rk4 or leapfrog",
        );
    }
    if s.simulation == StateModel::Stateless {
        return refuse(
            path(&[N("simulation")]),
            "the stateless simulation has no previous state to read; use stateful",
        );
    }
    if s.passes == UpdatePasses::Separate {
        return refuse(path(&[N("passes")]), "use passes = \"mrt\"");
    }
    if s.particles.velocity_format == VelocityFormat::Rgba16f {
        return refuse(
            path(&[N("particles"), N("velocity_format")]),
            "half floats count exactly only to 2048; use velocity_format = \"rgba32f\"",
        );
    }
    if s.collisions.is_some() {
        return refuse(
            path(&[N("collisions")]),
            "collisions reorder the texels every step; remove [collisions]",
        );
    }
    if s.constraints.is_some() {
        return refuse(path(&[N("constraints")]), "remove [constraints]");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::scene::load;

    #[test]
    fn child_capacity_check_warns_when_a_trail_outlives_its_turn() {
        let mut s = load("fireworks").unwrap();
        assert_eq!(
            s.child_capacity_check(),
            vec![],
            "60/s × 0.5 s = 30 in 32 texels"
        );
        s.emitters.child[1].per_parent = Some(20);
        let w = s.child_capacity_check();
        assert_eq!(w.len(), 1);
        assert_eq!((w[0].emitter, w[0].texels, w[0].per_parent), (1, 20, 31));
        assert!((w[0].live - 30.0).abs() < 1e-9);
        assert!(w[0].to_string().contains("per_parent = 31"), "{}", w[0]);
    }
}
