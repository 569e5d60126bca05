//! Running one pass of the sorter: bind its program, set the step's uniforms, draw.

use super::{group_shape, GpProgram, Pass, ProgramKey, Sorter, Step};
use crate::gl::{Draw, DrawState, Primitive, Program, Sampled, Uniform};

impl Sorter {
    /// Runs pass `index` of the sequence into the back framebuffer and swaps.
    pub(super) fn run_pass(&mut self, index: usize) {
        self.ctx.count_fetches(self.pass_fetches(index));
        if let (Some(b), Pass::Blocked(i)) = (self.blocked.as_mut(), &self.passes[index]) {
            b.run(*i, self.state.front().only_texture(), &self.fullscreen);
            // Kept in the blocked layout: the row-major texture is stale until asked for.
            if self.in_place {
                self.row_major.set(false);
            }
            return;
        }
        let front = self.state.front().only_texture();
        let keys = [("u_keys", Sampled::from(front))];
        match &self.passes[index] {
            Pass::Fragment(step) => {
                let (p, mut uniforms) = self.step_program(step);
                uniforms.push(("u_width", Uniform::I32(self.width as i32)));
                self.fullscreen.draw(p, &keys, &uniforms, self.state.back());
            }
            Pass::Group(steps) => self.run_group(steps, &keys),
            Pass::Blocked(_) => unreachable!("blocked passes return above"),
            Pass::Unpack => {
                if let Some(b) = &self.blocked {
                    b.unpack(self.state.back(), &self.fullscreen);
                }
            }
            Pass::Geometry {
                geometry,
                offset,
                program,
            } => self.run_geometry(*geometry, *offset, *program, &keys),
        }
        self.state.swap();
    }

    /// The fragment program of one network step and the step's uniforms, which travel with
    /// its draw.
    fn step_program(&self, step: &Step) -> (&Program, Vec<(&'static str, Uniform)>) {
        let int = |v: u32| Uniform::I32(v as i32);
        match *step {
            Step::Bitonic {
                block,
                dist,
                mirror,
            } => (
                &self.programs[&ProgramKey::Fp],
                vec![
                    ("u_block", int(block)),
                    ("u_dist", int(dist)),
                    ("u_mirror", Uniform::I32(mirror as i32)),
                ],
            ),
            Step::OddEvenRecursion { step, count } => (
                &self.programs[&ProgramKey::OddEvenRecursion],
                vec![("u_step", int(step)), ("u_count", int(count))],
            ),
            Step::OddEvenEnd { step } => (
                &self.programs[&ProgramKey::OddEvenEnd],
                vec![("u_step", int(step))],
            ),
        }
    }

    /// A multistep pass: several network steps in one draw.
    fn run_group(&self, steps: &[Step], keys: &[(&str, Sampled)]) {
        let (levels, steps_n) = group_shape(steps);
        let p = &self.programs[&ProgramKey::Multistep {
            levels,
            steps: steps_n,
        }];
        let int = |v: u32| Uniform::I32(v as i32);
        let mut uniforms = vec![("u_width", int(self.width))];
        if let Step::Bitonic { block, .. } = steps[0] {
            uniforms.push(("u_block", int(block)));
        }
        // Wide masks in order are the basis of the sub-network (see multistep.frag).
        let wide = steps.iter().filter_map(Step::mask).filter(|&m| m >= 2);
        let basis: Vec<i32> = wide.map(|mask| mask as i32).collect();
        uniforms.push(("u_basis", Uniform::I32s(basis.into())));
        let mirror: Vec<i32> = steps
            .iter()
            .map(|step| matches!(step, Step::Bitonic { mirror: true, .. }) as i32)
            .collect();
        uniforms.push(("u_mirror", Uniform::I32s(mirror.into())));
        self.fullscreen.draw(p, keys, &uniforms, self.state.back());
    }

    /// A GP/FP pass: the step's quads, drawn with their texel offset.
    fn run_geometry(
        &self,
        geometry: usize,
        offset: (i32, i32),
        program: GpProgram,
        keys: &[(&str, Sampled)],
    ) {
        let p = &self.programs[&ProgramKey::Geometry(program)];
        let fb = self.state.back();
        let size = glam::Vec2::new(fb.width() as f32, fb.height() as f32);
        let offset = glam::IVec2::new(offset.0, offset.1);
        let g = &self.geometry[geometry];
        self.ctx.draw(&Draw {
            program: p,
            target: fb,
            viewport: None,
            vertices: &g.vao,
            primitive: Primitive::Triangles,
            count: g.vertices,
            state: &DrawState::REPLACE,
            textures: keys,
            uniforms: &[
                ("u_size", Uniform::Vec2(size)),
                ("u_offset", Uniform::IVec2(offset)),
            ],
        });
    }
}
