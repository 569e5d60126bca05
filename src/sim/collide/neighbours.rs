//! Neighbour forces over the sorted grid (UberFlow §6: "any physical model that requires access
//! to adjacent particles"): the exact detection's search (`glsl/collide/cells.glsl`) feeds a
//! pass that sums, per particle, the forces of the particles it finds, into a force texture
//! (`glsl/collide/neighbour_force.frag`), and a pass that adds each particle's sum to its
//! velocity, v' = v + F / m dt (`glsl/collide/neighbour_apply.frag`). Two sources of force:
//!
//! - `[collisions] response = "dem"`: the contact force of NVIDIA's CUDA `particles` sample
//!   (`glsl/collide/dem.glsl`: spring, dashpot, shear, attraction), instead of the impulse;
//! - `[[forces.pair]]`: user GLSL files defining `pair_force`, called for each neighbour within
//!   their radius; spliced in front of the pass as `pair_force_<i>`, each its own source number,
//!   so that a compile error names the user's file and line.
//!
//! Once per step, before the impulse iterations (if the response is the impulse): keys, sort and
//! gather as an exact iteration does, the force pass, the velocity pass into the state (now in
//! cell order), the static texture copied in that order. With the dem response that is the
//! whole collision stage. The force texture stays readable in the gathered layout's order until
//! the next step ([`CollisionStage::read_neighbour_forces`]), for the CPU twin of the tests.

use super::{texture, CollisionStage};
use crate::error::{Error, Result};
use crate::gl::source::add_runtime_source;
use crate::gl::{
    Context, Defines, Framebuffer, PingPong, Program, Sampled, Texture, TextureFormat, Uniform,
    UniformList, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile, PAIR_SIGNATURE};
use crate::sim::state::{POSITION, STATIC, VELOCITY};
use crate::sim::user_glsl::{source_key, user_compile_error, Renamed};

/// The force pass, the velocity pass and the force texture.
#[derive(Debug)]
pub(super) struct Neighbours {
    /// (summed force in N, neighbours closer than 2 radius), in the gathered layout's order.
    force: Framebuffer,
    sum: Program,
    apply: Program,
    dem: Option<scene::Dem>,
    pair_radius: [f32; 4],
}

/// The text of each pair force: read and checked when the scene was loaded, or read now.
fn pair_sources(scene: &SceneFile) -> Result<Vec<String>> {
    (scene.forces.pair.iter().enumerate())
        .map(|(i, c)| match &c.source {
            Some(t) => Ok(t.clone()),
            None => scene::read_pair_glsl(&c.glsl).map_err(|m| {
                Error::InvalidInput(format!(
                    "forces.pair[{i}].glsl: {m}; the path is relative to the scene file"
                ))
            }),
        })
        .collect()
}

/// The fragment shader of the force pass: `collide/neighbour_force.frag`, or for a scene with
/// pair forces, a root that splices them in front of it (after `common/rng.glsl` and
/// `sim/fields.glsl`, as custom forces are), and the keys of the user files with their paths.
fn force_root(scene: &SceneFile) -> Result<(String, Vec<(String, String)>)> {
    let pair = &scene.forces.pair;
    if pair.is_empty() {
        return Ok(("collide/neighbour_force.frag".to_owned(), Vec::new()));
    }
    let mut root = String::from(
        "// The neighbour force pass with the scene's pair forces (src/sim/collide/neighbours.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/fields.glsl\"\n",
    );
    let mut files = Vec::new();
    for (i, (c, text)) in pair.iter().zip(pair_sources(scene)?).enumerate() {
        let key = source_key("pair-force", i, &c.glsl, &text);
        add_runtime_source(&key, &text);
        root +=
            &format!("#define pair_force pair_force_{i}\n#include \"{key}\"\n#undef pair_force\n");
        files.push((key, c.glsl.clone()));
    }
    root += &format!(
        "#define N_PAIR {}\n#include \"collide/neighbour_force.frag\"\n",
        pair.len()
    );
    let keys: Vec<&str> = files.iter().map(|(k, _)| k.as_str()).collect();
    let name = format!("pair-forces:{}", keys.join("+"));
    add_runtime_source(&name, &root);
    Ok((name, files))
}

/// Compiles the force pass of `scene` with the simulation's `defines`; a compile error in a
/// user's file names it.
fn force_program(ctx: &Context, scene: &SceneFile, defines: &Defines) -> Result<Program> {
    let (root, files) = force_root(scene)?;
    let mut d = defines.clone();
    if dem(scene).is_some() {
        d.push(("DEM".into(), "1".into()));
    }
    d.push(("EXACT_SCAN".into(), scene::EXACT_SCAN.to_string()));
    let d = super::cells::partner_mask(&d, super::cells::PartnerWork::Forces);
    Program::new(ctx, FULLSCREEN_VERTEX, &root, &d).map_err(|e| {
        let renamed = Renamed {
            name: "pair_force",
            prefix: "pair_force_",
        };
        user_compile_error(e, &files, "pair force", PAIR_SIGNATURE, renamed)
    })
}

fn dem(scene: &SceneFile) -> Option<scene::Dem> {
    let c = scene.collisions.as_ref()?;
    (c.response == scene::Response::Dem)
        .then_some(c.dem)
        .flatten()
}

/// Compiles the pair forces of `scene` on `ctx`, as the collision stage does, so that `scene
/// check` refuses what `render` would.
pub fn check_pair_forces(ctx: &Context, scene: &SceneFile, defines: &Defines) -> Result<()> {
    if scene.forces.pair.is_empty() {
        return Ok(());
    }
    force_program(ctx, scene, defines).map(drop)
}

impl Neighbours {
    /// The passes of `scene`, if it has the dem response or pair forces.
    pub(super) fn new(ctx: &Context, scene: &SceneFile, defines: &Defines) -> Result<Option<Self>> {
        let dem = dem(scene);
        if dem.is_none() && scene.forces.pair.is_empty() {
            return Ok(None);
        }
        let [w, h] = scene.particles.size;
        let mut pair_radius = [0.0; 4];
        for (r, p) in pair_radius.iter_mut().zip(&scene.forces.pair) {
            *r = p.radius;
        }
        Ok(Some(Neighbours {
            force: Framebuffer::new(
                ctx,
                "neighbour force",
                vec![texture(
                    ctx,
                    "neighbour force",
                    w,
                    h,
                    TextureFormat::Rgba32F,
                )?],
            )?,
            sum: force_program(ctx, scene, defines)?,
            apply: Program::new(
                ctx,
                FULLSCREEN_VERTEX,
                "collide/neighbour_apply.frag",
                defines,
            )?,
            dem,
            pair_radius,
        }))
    }

    /// The force and kick passes' draws of one step, for the pass list.
    pub(super) fn pass_draws(&self) -> [crate::gl::PassDraw; 2] {
        [
            crate::gl::PassDraw::of("neighbour force", &self.sum, 1),
            crate::gl::PassDraw::of("neighbour kick", &self.apply, 1),
        ]
    }

    /// Whether the neighbour forces replace the impulse (`response = "dem"`).
    pub(super) fn replaces_impulse(&self) -> bool {
        self.dem.is_some()
    }
}

/// The passes of the neighbour forces, as `texflow scene passes` lists them.
pub fn neighbour_passes(
    dem: bool,
    pair: usize,
    sort: scene::CollisionSort,
    search: super::cells::CellTables,
) -> Vec<String> {
    let table = search.collisions;
    let mut what = Vec::new();
    if dem {
        what.push("the DEM contact force (spring, dashpot, shear, attraction) of every partner closer than 2r".to_owned());
    }
    if pair > 0 {
        what.push(format!(
            "{pair} user pair force(s) of every neighbour within their radius"
        ));
    }
    let mut out: Vec<String> = vec![
        "collision keys: cell index in the lattice (z, y, x)".into(),
        format!(
            "collision sort: {}",
            super::uberflow_sort(sort, None, false)
        ),
        "gather position, velocity, static in cell order".into(),
    ];
    if table {
        out.push(super::cells::table_line("collision", ""));
    }
    out.extend([
        format!(
            "neighbour force: sum over {} of {} ({}, at most {} particles per run{})",
            super::cells::walk_words(search.collisions_trimmed, "2r"),
            what.join(" and "),
            super::cells::search_words(table),
            scene::EXACT_SCAN,
            super::cells::partner_words(super::cells::PartnerWork::Forces)
        ),
        "neighbour kick: v += F / m dt, positions copied (they move in the next integration)"
            .into(),
    ]);
    out
}

/// The neighbour force pass's inputs and output, read back by
/// [`CollisionStage::read_neighbour_forces`]: RGBA texels, four floats per particle, all in the
/// gathered layout's order.
#[derive(Debug, Clone)]
pub struct NeighbourReadback {
    /// Positions (xyz, life).
    pub positions: Vec<f32>,
    /// Velocities.
    pub velocities: Vec<f32>,
    /// Static texels (birth, type, life, random): the type and, with the scene, the mass.
    pub statics: Vec<f32>,
    /// (summed force in N, neighbours closer than 2 radius).
    pub forces: Vec<f32>,
}

impl CollisionStage {
    /// The neighbour forces of one step: keys, sort, gather, force pass, velocity pass into
    /// `state` (then swapped), the statics in the new order handed over.
    pub(super) fn run_neighbours(
        &mut self,
        state: &mut PingPong,
        statics: &mut Framebuffer,
        dt: f32,
        fields: &[(&str, Sampled<'_>)],
        constants: &UniformList,
    ) -> Result<()> {
        self.sort_first(state, statics)?;
        self.exchange(constants);
        let Some(n) = &self.neighbours else {
            return Ok(());
        };
        let g = &self.first;
        let cells = self.searched();
        let own = [
            ("u_position", g.sorted.layout().texture(POSITION).into()),
            ("u_velocity", g.sorted.layout().texture(VELOCITY).into()),
            ("u_static", g.sorted.layout().texture(STATIC).into()),
        ];
        let p = &n.sum;
        // Contacts and pair forces alike: a pair force's reach is at most the cell, so at most
        // 2 radius where the walk trims.
        let mut uniforms = self.contact_search();
        if let Some(d) = n.dem {
            let dem = glam::Vec4::new(d.spring, d.damping, d.shear, d.attraction);
            uniforms.push(("u_dem", Uniform::Vec4(dem)));
        }
        // A pair force's radii (the list keeps what the program declares).
        uniforms.push(("u_pair_radius", Uniform::Vec4(n.pair_radius.into())));
        let mut textures: Vec<(&str, Sampled)> = cells.textures(g.sorted.keys());
        textures.extend(own.iter().copied());
        // A pair force may sample the fields (sim/fields.glsl), as a custom force may.
        textures.extend(fields.iter().filter(|(name, _)| p.declares(name)).copied());
        let uniforms = constants.for_draw(p, uniforms);
        self.pass.draw(p, &textures, &uniforms, &n.force);
        let a = &n.apply;
        let mut textures: Vec<(&str, Sampled)> = own.to_vec();
        textures.push(("u_force", n.force.only_texture().into()));
        let dt = constants.for_draw(a, [("u_dt", Uniform::F32(dt))]);
        self.pass.draw(a, &textures, &dt, state.back());
        state.swap();
        self.take_statics(false, statics)?;
        self.carry_back(false);
        Ok(())
    }

    /// The last step's neighbour force pass: its inputs (the gathered layout, whose statics the
    /// step handed to the simulation: `statics`, its static texture) and the summed force per
    /// particle; `None` without neighbour forces.
    pub fn read_neighbour_forces(&self, statics: &Texture) -> Result<Option<NeighbourReadback>> {
        let Some(n) = &self.neighbours else {
            return Ok(None);
        };
        let l = self.first.sorted.layout();
        Ok(Some(NeighbourReadback {
            positions: l.texture(POSITION).read_f32()?,
            velocities: l.texture(VELOCITY).read_f32()?,
            statics: statics.read_f32()?,
            forces: n.force.only_texture().read_f32()?,
        }))
    }

    /// With the dem response, the last step's partner counts as the exact detection's count
    /// pass gives them, (partners closer than 2 radius, 0, -1, 0) per particle, from the force
    /// texture's contact count (the dem response runs no count pass); else `None`.
    pub(super) fn neighbour_counts(&self) -> Result<Option<Vec<f32>>> {
        match &self.neighbours {
            Some(n) if n.replaces_impulse() => {
                let f = n.force.only_texture().read_f32()?;
                Ok(Some(
                    f.chunks(4).flat_map(|t| [t[3], 0.0, -1.0, 0.0]).collect(),
                ))
            }
            _ => Ok(None),
        }
    }

    /// Whether the impulse response runs after the neighbour forces (not with `dem`).
    pub(super) fn impulse_runs(&self) -> bool {
        !self
            .neighbours
            .as_ref()
            .is_some_and(Neighbours::replaces_impulse)
    }
}
