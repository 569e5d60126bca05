//! `[[emitters.*]]`: where and how particles are born.

use serde::{Deserialize, Serialize};

use super::one;
use super::{Forces, Keyframe};
use crate::scene::curve::Animated;

/// Emitters by kind.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Emitters {
    /// Latta §3.4.1: a CPU allocator hands out texel indices; new particles are drawn as points.
    /// Needs `rate`.
    #[serde(default)]
    pub allocator: Vec<Emitter>,
    /// UberFlow §4.1: birth times stamped in the state; unborn particles kept out of view; the
    /// particle resets at the end of its `cycle`. Needs `cycle`.
    #[serde(default)]
    pub timestamp: Vec<Emitter>,
    /// Latta §3.4.1's simplest case: every texel filled once at the start. Without `life` the
    /// particles are permanent and the scene runs no birth or death code.
    #[serde(default)]
    pub initial: Vec<Emitter>,
    /// The thesis §2: emitters that emit. A child emitter's particles are born from the live
    /// particles of a parent emitter (`parent`): a trail while the parent lives (`trail_rate`),
    /// a burst when it dies (`on_death`). Needs `per_parent`, and an emitter of another kind.
    #[serde(default)]
    pub child: Vec<Emitter>,
}

impl Emitters {
    /// All emitters in type order (a particle's type is its emitter's place in this list).
    pub fn all(&self) -> impl Iterator<Item = &Emitter> {
        EmitterKind::ALL.into_iter().flat_map(|k| self.of_kind(k))
    }

    /// Every emitter in type order with its kind and its place among its kind's.
    pub fn by_kind(&self) -> impl Iterator<Item = (EmitterKind, usize, &Emitter)> {
        (EmitterKind::ALL.into_iter()).flat_map(|k| {
            self.of_kind(k)
                .iter()
                .enumerate()
                .map(move |(i, e)| (k, i, e))
        })
    }

    /// The emitters of `kind` (`[[emitters.KIND]]`).
    pub fn of_kind(&self, kind: EmitterKind) -> &[Emitter] {
        match kind {
            EmitterKind::Allocator => &self.allocator,
            EmitterKind::Timestamp => &self.timestamp,
            EmitterKind::Initial => &self.initial,
            EmitterKind::Child => &self.child,
        }
    }

    /// The emitters of `kind`, to change.
    pub fn of_kind_mut(&mut self, kind: EmitterKind) -> &mut Vec<Emitter> {
        match kind {
            EmitterKind::Allocator => &mut self.allocator,
            EmitterKind::Timestamp => &mut self.timestamp,
            EmitterKind::Initial => &mut self.initial,
            EmitterKind::Child => &mut self.child,
        }
    }

    /// The scene key of the emitter of particle type `ty` (`emitters.timestamp.0`), if any.
    pub fn key(&self, ty: usize) -> Option<String> {
        let (kind, i, _) = self.by_kind().nth(ty)?;
        Some(format!("emitters.{}.{i}", kind.key()))
    }

    /// Number of emitters.
    pub fn len(&self) -> usize {
        EmitterKind::ALL.map(|k| self.of_kind(k).len()).iter().sum()
    }

    /// Number of emitters that are not child emitters (their types come first).
    pub fn parents(&self) -> usize {
        (EmitterKind::ALL.into_iter())
            .filter(|k| k.owns_texels())
            .map(|k| self.of_kind(k).len())
            .sum()
    }

    /// No emitter at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A kind of emitter: one `[[emitters.KIND]]` array. Matches over it are exhaustive, so a new
/// kind makes the compiler list every place to fill (docs/architecture.md walks through them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EmitterKind {
    /// Latta §3.4.1: births by a CPU allocator.
    Allocator,
    /// UberFlow §4.1: birth times stamped in the state, respawn every cycle.
    Timestamp,
    /// Every texel filled once at the start.
    Initial,
    /// The thesis §2: born from a parent emitter's particles.
    Child,
}

impl EmitterKind {
    /// Every kind, in type order: a scene's particle types are its emitters kind by kind in
    /// this order.
    pub const ALL: [EmitterKind; 4] = [
        EmitterKind::Allocator,
        EmitterKind::Timestamp,
        EmitterKind::Initial,
        EmitterKind::Child,
    ];

    /// Its key in a scene file (`[[emitters.KEY]]`).
    pub fn key(self) -> &'static str {
        match self {
            EmitterKind::Allocator => "allocator",
            EmitterKind::Timestamp => "timestamp",
            EmitterKind::Initial => "initial",
            EmitterKind::Child => "child",
        }
    }

    /// Whether it manages the state texture's texels itself (one such kind per scene; child
    /// emitters come beside it, in texels it leaves them).
    pub fn owns_texels(self) -> bool {
        match self {
            EmitterKind::Allocator | EmitterKind::Timestamp | EmitterKind::Initial => true,
            EmitterKind::Child => false,
        }
    }

    /// Whether each birth draws its life anew (so `life` may be a curve); the other kinds draw
    /// a texel's life once, into the static texture.
    pub fn life_per_birth(self) -> bool {
        match self {
            EmitterKind::Allocator => true,
            EmitterKind::Timestamp | EmitterKind::Initial | EmitterKind::Child => false,
        }
    }

    /// Whether its particles spawn after time 0 (so spawn values may be curves).
    pub fn spawns_over_time(self) -> bool {
        match self {
            EmitterKind::Allocator | EmitterKind::Timestamp | EmitterKind::Child => true,
            EmitterKind::Initial => false,
        }
    }

    /// Whether its particles are born over the run, so that each needs a `life` (initial
    /// particles may be permanent; a child's life is checked with its parent's keys).
    pub fn births_need_life(self) -> bool {
        match self {
            EmitterKind::Allocator | EmitterKind::Timestamp => true,
            EmitterKind::Initial | EmitterKind::Child => false,
        }
    }
}

/// Most emitters (particle types) in one scene: one atlas tile each.
pub const MAX_EMITTERS: usize = 4;

/// Where new particles appear.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// At the centre.
    #[default]
    Point,
    /// In an axis-aligned box of `size` around the centre.
    Box,
    /// In a ball of `radius`.
    Sphere,
    /// On a disc of `radius` in the plane normal to `normal`.
    Disc,
}

/// Allocator strategy (Latta §3.4.1): how free indices are handed out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AllocatorKind {
    /// LIFO: the most recently freed index comes back first. O(1) per operation.
    Stack,
    /// Always the smallest free index, so live particles stay in the first rows. O(log n).
    #[default]
    MinHeap,
}

/// An emitter: shape, velocity and life of newborn particles.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Emitter {
    /// Particles per second (allocator emitters); may be a curve (docs/scenes.md).
    pub rate: Option<Animated<f32>>,
    /// Index allocation strategy (allocator emitters).
    pub allocator: Option<AllocatorKind>,
    /// Length of one life cycle in seconds (timestamp emitters).
    pub cycle: Option<f32>,
    /// Timestamp emitters: every release (the particles born in one step, one row with
    /// `collisions.row_phases`) is moved as a whole to its own place: release k of a cycle to
    /// slot k of a cube of slots filling a box of this size [x, y, z] around `center` (UberFlow
    /// §5's "particles released in time-sequential order": releases that do not mix). Default:
    /// no offset.
    pub release_spread: Option<[f32; 3]>,
    /// With `release_spread`: split every release into clouds of this many consecutive texels,
    /// each in a slot of its own (a cloud's size then stays the same whatever the row width).
    pub release_cloud: Option<u32>,
    /// Emitter shape.
    #[serde(default)]
    pub shape: Shape,
    /// Centre; may be a curve.
    #[serde(default)]
    pub center: Animated<[f32; 3]>,
    /// Box size.
    #[serde(default)]
    pub size: [f32; 3],
    /// Sphere or disc radius; may be a curve.
    #[serde(default)]
    pub radius: Animated<f32>,
    /// Disc normal (default +y).
    pub normal: Option<[f32; 3]>,
    /// Mean direction of the velocity cone; may be a curve.
    pub direction: Animated<[f32; 3]>,
    /// Half-angle of the velocity cone, degrees; may be a curve.
    #[serde(default)]
    pub cone_degrees: Animated<f32>,
    /// Speed range [min, max] (one number: min = max); may be a curve.
    pub speed: Animated<[f32; 2]>,
    /// Life range [min, max], seconds; initial emitters may leave it out (permanent particles).
    /// May be a curve on allocator emitters (each birth draws from the range at its time).
    pub life: Option<Animated<[f32; 2]>>,
    /// Mass of this emitter's particles (its type); default `particles.mass`.
    pub mass: Option<f32>,
    /// Latta §3.3: a mass range [lo, hi] in kg; each particle's mass lies in it, drawn from the
    /// random number of its static texel (in place of `mass`).
    pub mass_range: Option<[f32; 2]>,
    /// Sprite size of this type relative to `render.point_size`; may be a curve, of which each
    /// particle keeps the value at its birth time (docs/scenes.md).
    #[serde(default = "one_animated")]
    pub sprite_scale: Animated<f32>,
    /// An RGBA factor of this type's keyframe colour and opacity (Latta §3.4.6: colour per
    /// particle type); may be a curve, of which each particle keeps the value at its birth time
    /// (docs/scenes.md). Default [1, 1, 1, 1].
    #[serde(default = "white", skip_serializing_if = "is_white")]
    pub tint: Animated<[f32; 4]>,
    /// Atlas tile of this type's sprites (0 soft blob, 1 snowflake, 2 smoke puff, 3 ring);
    /// default: the type's own number.
    pub tile: Option<u32>,
    /// Range [min, max] of the sprites' rotation speed in degrees per second, drawn per particle
    /// (Latta §3.4.6: "a rotation velocity (2D in screen space) ... determined randomly within a
    /// defined type-based range"); angle = angle0 + speed · age. Default no rotation.
    pub rotation_speed: Option<[f32; 2]>,
    /// Sprite size over life: two to four points [relative age, scale], ages ascending from 0
    /// to 1, linear between (Latta §3.4.6: attributes from the relative age and "a set of
    /// keyframes"). Default a constant 1.
    #[serde(default)]
    pub size_over_life: Vec<[f32; 2]>,
    /// Colour and opacity keyframes of this emitter's particle type (Latta §3.4.6: "defined for
    /// each particle type"); 1 to 8, or empty for the scene's `[render] keyframes`.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// Bursts: `count` particles born at once at `time` seconds, beside the steady `rate`
    /// (allocator emitters) or the phases spread over the `cycle` (timestamp emitters, whose
    /// bursts repeat every cycle: the time stamps are written once). At most [`MAX_BURSTS`].
    #[serde(default)]
    pub bursts: Vec<Burst>,
    /// Range [min, max] of a random size factor per particle, relative to the type's size
    /// (Latta §3.4.6: "The size of a particle is random within a range that is defined by the
    /// particle type"). Default [1, 1].
    pub size_range: Option<[f32; 2]>,
    /// An animated texture (the thesis §2.3): consecutive atlas tiles from `tile` shown in turn.
    pub flipbook: Option<Flipbook>,
    /// Forces on this emitter's particles only (its type), beside the scene's `[[forces.*]]`,
    /// which act on every particle: `[[emitters.<kind>.forces.gravity]]` and the other kinds,
    /// with the same keys. Gravity, damping, attractors, springs and vortices (at most
    /// [`MAX_EMITTER_FORCES`] of each of the last three); no wind or custom force.
    #[serde(default)]
    pub forces: Forces,
    /// Child emitters: the type number of the parent emitter (its place among the scene's other
    /// emitters, in the order allocator, timestamp, initial). Default 0.
    pub parent: Option<u32>,
    /// Child emitters: texels of the state reserved for the children of each parent texel.
    pub per_parent: Option<u32>,
    /// Child emitters: children born at a parent's last position when it dies (a burst).
    pub on_death: Option<u32>,
    /// Child emitters: children per second born from each live parent (a trail).
    pub trail_rate: Option<f32>,
    /// Child emitters: the fraction of the parent's velocity a child starts with, beside the
    /// velocity drawn from its own cone (`direction`, `cone_degrees`, `speed`). Default 1.
    pub inherit_velocity: Option<f32>,
}

fn one_animated() -> Animated<f32> {
    Animated::Constant(one())
}

fn white() -> Animated<[f32; 4]> {
    Animated::Constant([1.0; 4])
}

fn is_white(t: &Animated<[f32; 4]>) -> bool {
    *t == white()
}

/// Most attractors, springs or vortices (each kind) one emitter carries: every one is a few
/// uniform vectors of the integration pass, whose total the GL limits.
pub const MAX_EMITTER_FORCES: usize = 4;

/// Most keys of a curve the renderer evaluates per particle (`sprite_scale`, `tint`): each is a
/// uniform vector per particle type of the vertex stage.
pub const MAX_BIRTH_KEYS: usize = 4;

/// Most bursts per emitter.
pub const MAX_BURSTS: usize = 4;

/// `count` particles born at `time`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Burst {
    /// Seconds from the start of the run (timestamp emitters: within the first cycle).
    pub time: f32,
    /// Particles born.
    pub count: u32,
}

/// A flipbook: `frames` atlas tiles from the type's `tile` on (wrapping after the atlas's four),
/// advancing at `rate` tiles per second of the particle's age, looping; without a rate, spread
/// evenly over its life.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Flipbook {
    /// Number of tiles, 1 to 4.
    pub frames: u32,
    /// Tiles per second of age; default: `frames` over the particle's life.
    pub rate: Option<f32>,
}
