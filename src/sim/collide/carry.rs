//! The user states (`[[state]]`) carried along the collision stage's sorts, and their exchange
//! with the neighbours (`pair`; UberFlow §6: "any physical model that requires access to
//! adjacent particles").
//!
//! Every sort that gathers position, velocity and static in cell order gathers each user state
//! too (one gather pass per state: a texture of its own format), and wherever the stage hands
//! the static texture over in the new order it copies the states back, so that after the stage
//! every state's texel still belongs to the particle of the same texel. (Copied, not handed
//! over: the integration pass writes the states through framebuffers that view their textures,
//! `Framebuffer::views`, which an exchange would leave pointing at the layout's.) The stage holds
//! the states' textures while it runs ([`CollisionStage::run`]) and hands them back after.
//!
//! The exchange runs once per step, after the step's first sort: for every state with `pair`, a
//! pass over the sorted layout (`glsl/collide/exchange.frag`) adds to each live particle's value
//! the sum of `pair` over the live neighbours closer than the state's `radius`, found by the
//! exact detection's search of the 27 cells around it (`glsl/collide/cells.glsl`). Every exchange
//! reads the values before any of them (they are swapped in after all are drawn).

use super::{texture, CollisionStage};
use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, PingPong, Program, Sampled, TextureFormat, Uniform, UniformList,
};
use crate::scene::{SceneFile, StateFormat};
use crate::sim::state::{POSITION, STATIC, VELOCITY};

/// One state's exchange pass: the state's index, its program, its reach and its target.
#[derive(Debug)]
struct Exchange {
    state: usize,
    program: Program,
    radius: f32,
    target: Framebuffer,
}

/// The states in each lattice's sorted order, and the exchange passes.
#[derive(Debug)]
pub(super) struct Carry {
    /// The simulation's user states while the stage runs (empty between runs).
    states: Vec<PingPong>,
    /// Each state gathered in the first lattice's order (after the exchange: its result).
    first: Vec<Framebuffer>,
    /// Each state gathered in the staggered lattice's order.
    second: Vec<Framebuffer>,
    exchange: Vec<Exchange>,
    /// Whether this step's exchange is still to run (after the step's first sort).
    due: bool,
    /// The time at the end of the step (`time` in the expressions).
    time: f32,
}

/// A single-texture target for state `k` of `scene`, in the state's format.
fn target(ctx: &Context, scene: &SceneFile, k: usize, what: &str) -> Result<Framebuffer> {
    let [w, h] = scene.particles.size;
    let s = &scene.state[k];
    let format = match s.format {
        StateFormat::Rgba32f => TextureFormat::Rgba32F,
        StateFormat::Rgba16f => TextureFormat::Rgba16F,
    };
    let label = format!("{what} {}", s.name);
    Framebuffer::new(ctx, &label, vec![texture(ctx, &label, w, h, format)?])
}

/// One target per state of `scene`.
fn targets(ctx: &Context, scene: &SceneFile, what: &str) -> Result<Vec<Framebuffer>> {
    (0..scene.state.len())
        .map(|k| target(ctx, scene, k, what))
        .collect()
}

/// The passes that carry `states` user states along the collision sorts and exchange those
/// named in `exchanges` (their search `trimmed` where the exact detection's cell is below 2
/// radius), as `texflow scene passes` lists them.
pub fn carry_passes(states: usize, exchanges: &[String], trimmed: bool) -> Vec<String> {
    let around = super::cells::walk_words(trimmed, "its radius");
    let mut out: Vec<String> = (exchanges.iter())
        .map(|name| {
            format!(
                "exchange {name} (after the step's first collision sort): {name} += the sum of \
                 `pair` over the live neighbours within its radius (search of {around}) [a \
                 sorted copy, swapped in after every exchange is drawn]"
            )
        })
        .collect();
    if states > 0 {
        out.push(format!(
            "carry {states} user state(s): gathered in cell order with every collision sort \
             (a pass each), copied back with the static texture"
        ));
    }
    out
}

/// The defines the exchange passes of `scene` are compiled with: the simulation's `defines`,
/// the sorted keys' layout and the search's bound, as the collision stage's passes.
pub(crate) fn exchange_defines(scene: &SceneFile, defines: &Defines) -> Defines {
    match &scene.collisions {
        Some(c) => {
            let size = scene.particles.size;
            super::exact::stage_defines(&super::exact::search_layout(defines, c, size), false)
        }
        None => defines.clone(),
    }
}

impl CollisionStage {
    /// The stage carrying the user states of `scene` along its sorts, with the exchange passes
    /// `exchanges` (each state's index and program, compiled by the simulation with
    /// [`exchange_defines`]).
    pub(crate) fn carry_states(
        mut self,
        scene: &SceneFile,
        exchanges: Vec<(usize, Program)>,
    ) -> Result<Self> {
        if scene.state.is_empty() {
            return Ok(self);
        }
        let ctx = &self.ctx;
        let mut exchange = Vec::new();
        for (i, program) in exchanges {
            exchange.push(Exchange {
                state: i,
                program,
                radius: scene.state[i].radius.unwrap_or(0.0),
                target: target(ctx, scene, i, "exchange")?,
            });
        }
        self.carry = Some(Carry {
            states: Vec::new(),
            first: targets(ctx, scene, "lattice state")?,
            second: match self.second.is_some() {
                true => targets(ctx, scene, "staggered state")?,
                false => Vec::new(),
            },
            exchange,
            due: false,
            time: 0.0,
        });
        Ok(self)
    }

    /// Takes the user states for a run of the stage at `time` (the end of the step).
    pub(crate) fn hold_states(&mut self, states: &mut Vec<PingPong>, time: f32) {
        if let Some(c) = &mut self.carry {
            c.states = std::mem::take(states);
            c.due = true;
            c.time = time;
        }
    }

    /// Gives the user states back after a run.
    pub(crate) fn release_states(&mut self, states: &mut Vec<PingPong>) {
        if let Some(c) = &mut self.carry {
            *states = std::mem::take(&mut c.states);
        }
    }

    /// Gathers the user states in the first lattice's order (after its sort), or with
    /// `staggered` from that order into the second lattice's.
    pub(super) fn gather_states(&self, staggered: bool) -> Result<()> {
        let Some(c) = &self.carry else {
            return Ok(());
        };
        for (k, pp) in c.states.iter().enumerate() {
            match (staggered, &self.second) {
                (false, _) => self
                    .first
                    .sorted
                    .gather(&[pp.front().only_texture()], &c.first[k])?,
                (true, Some(g2)) => g2
                    .sorted
                    .gather(&[c.first[k].only_texture()], &c.second[k])?,
                (true, None) => {}
            }
        }
        Ok(())
    }

    /// This step's exchange, if it is due: one pass per state with `pair` over the first
    /// lattice's layout, then each result takes the place of its state's gathered value.
    pub(super) fn exchange(&mut self, constants: &UniformList) {
        let Some(c) = &mut self.carry else {
            return;
        };
        // States without `pair` exchange nothing (and may ride UberFlow's sorts, unsearched).
        if !std::mem::take(&mut c.due) || c.exchange.is_empty() {
            return;
        }
        let g = &self.first;
        // A field, not `searched()`: the states are borrowed mutably.
        let cells = g
            .sorted
            .search()
            .expect("an exchange needs the exact detection");
        let names: Vec<String> = (0..c.first.len())
            .map(|k| format!("u_user_state_{k}"))
            .collect();
        for e in &c.exchange {
            let p = &e.program;
            let clock = constants.for_draw(
                p,
                cells.uniforms().into_iter().chain([
                    ("u_pair_radius", Uniform::F32(e.radius)),
                    // A trimmed walk (a cell below 2 radius) goes as far as the exchange's reach.
                    ("u_search_radius", Uniform::F32(e.radius)),
                    ("u_dt", Uniform::F32(self.dt)),
                    ("u_time", Uniform::F32(c.time)),
                ]),
            );
            let mut textures: Vec<(&str, Sampled)> = cells.textures(g.sorted.keys());
            textures.extend([
                ("u_position", g.sorted.layout().texture(POSITION).into()),
                ("u_velocity", g.sorted.layout().texture(VELOCITY).into()),
                ("u_static", g.sorted.layout().texture(STATIC).into()),
            ]);
            textures.extend(
                (names.iter().map(String::as_str))
                    .zip(c.first.iter().map(|f| f.only_texture().into())),
            );
            self.pass.draw(p, &textures, &clock, &e.target);
        }
        for e in &mut c.exchange {
            std::mem::swap(&mut e.target, &mut c.first[e.state]);
        }
    }

    /// Copies the user states back from the layout the response wrote the state in (the first
    /// lattice's, or with `staggered` the second's), where the static texture is handed over.
    pub(super) fn carry_back(&mut self, staggered: bool) {
        let Some(c) = &mut self.carry else {
            return;
        };
        let layout = if staggered { &c.second } else { &c.first };
        let p = &self.copy;
        for (pp, from) in c.states.iter_mut().zip(layout) {
            self.pass.draw(
                p,
                &[("u_source", from.only_texture().into())],
                &[],
                pp.back(),
            );
            pp.swap();
        }
    }
}
