//! Latta §3.4.1: births by the CPU allocator, drawn as single pixels into the state textures.

use super::super::allocator::AllocatorKind;
use super::super::emit::{EmitterUniforms, Rng};
use super::{Emission, ParticleSim, State};
use crate::error::{Error, Result};
use crate::gl::{
    Attribute, Buffer, BufferKind, BufferUsage, Draw, DrawState, Framebuffer, PassDraw, PointSize,
    Primitive, Program, VertexArray,
};

/// Floats per emitted vertex: index, position + life, velocity, static.
const EMIT_FLOATS: usize = 13;

/// Bytes of one birth's vertex in the buffer the emit pass draws from (uploaded each step
/// that has births).
pub const BIRTH_VERTEX_BYTES: usize = EMIT_FLOATS * 4;

impl ParticleSim {
    /// Latta §3.4.1: frees the indices of particles that died (on the CPU's clock, a few steps
    /// late so that both sides of the ping-pong hold them dead), allocates indices for this
    /// step's births and draws them as points.
    pub(super) fn emit(&mut self) -> Result<()> {
        let data = self.allocate_births()?;
        if data.is_empty() {
            return Ok(());
        }
        self.draw_births(&data)
    }

    /// Frees the dead particles' indices and allocates this step's births, each one's vertex
    /// ([`EMIT_FLOATS`] floats) in the returned data; none without an allocator.
    fn allocate_births(&mut self) -> Result<Vec<f32>> {
        let dt = self.params.time.dt as f64;
        let now = self.time;
        let Some(alloc) = self.allocator.as_mut() else {
            return Ok(Vec::new());
        };
        alloc.reclaim(now - 3.0 * dt);
        let mut data: Vec<f32> = Vec::new();
        let emitters = &self.params.emitters;
        for (k, e) in emitters.allocator().iter().enumerate() {
            // The births of the interval (now - dt, now], as bursts below; a curve's rate is
            // integrated over it, and its other values taken at `now`, the births' time.
            self.owed[k] += e.rate.as_ref().map_or(0.0, |r| r.integral(now - dt, now));
            let steady = self.owed[k].floor();
            self.owed[k] -= steady;
            // A burst belongs to the step whose interval (now - dt, now] holds its time; the
            // intervals tile the time line, so each burst fires once.
            let burst: u64 = (e.bursts.iter())
                .filter(|b| (b.time as f64) <= now && (b.time as f64) > now - dt)
                .map(|b| b.count as u64)
                .sum();
            let n = steady + burst as f64;
            let u = &match emitters.animated {
                true => EmitterUniforms::at(e, now as f32),
                false => emitters.spawn[k],
            };
            for _ in 0..n as u64 {
                let mut rng = Rng::new(self.emitted as u32, self.step as u32, self.seed);
                self.emitted += 1;
                let life = u.life(&mut rng);
                let Some(index) = alloc
                    .allocate_with_lifetime(now, life as f64)
                    .map_err(|e| Error::InvalidInput(e.to_string()))?
                else {
                    self.dropped += 1;
                    continue;
                };
                let x = u.position(&mut rng);
                let v = u.velocity(&mut rng);
                data.push(index as f32);
                data.extend_from_slice(&x.extend(life).to_array());
                data.extend_from_slice(&v.extend(0.0).to_array());
                data.extend_from_slice(&[now as f32, k as f32, life, rng.uniform()]);
            }
        }
        Ok(data)
    }

    /// Draws the births' vertices `data` as single pixels into the static, state and (Verlet)
    /// previous-position textures.
    fn draw_births(&self, data: &[f32]) -> Result<()> {
        let buffer = Buffer::with_data(
            &self.ctx,
            "births",
            BufferKind::Vertex,
            bytemuck::cast_slice(data),
            BufferUsage::StreamDraw,
        )?;
        let stride = (EMIT_FLOATS * 4) as i32;
        let attr = |location: u32, components: i32, offset: i32| Attribute {
            buffer: &buffer,
            location,
            components,
            stride,
            offset: offset * 4,
        };
        let vao = VertexArray::with_attributes(
            &self.ctx,
            "births",
            &[attr(0, 1, 0), attr(1, 4, 1), attr(2, 4, 5), attr(3, 4, 9)],
        )?;
        let count = (data.len() / EMIT_FLOATS) as u32;
        // Single pixels (emit.vert writes gl_PointSize = 1) replacing what the texel held.
        let state = DrawState {
            blend: None,
            point_size: PointSize::Program,
            ..DrawState::REPLACE
        };
        let draw = |program: &Program, target: &Framebuffer| {
            self.ctx.draw(&Draw {
                program,
                target,
                viewport: None,
                vertices: &vao,
                primitive: Primitive::Points,
                count,
                state: &state,
                textures: &super::draw_textures(program, &[], &self.fields),
                uniforms: &self.uniforms(program, []),
            })
        };
        if let Some(p) = &self.emit_static {
            draw(p, &self.statics);
        }
        if let Some(p) = &self.emit_state {
            draw(p, self.front());
        }
        if let (Some(p), State::Verlet(ring)) = (&self.emit_previous, &self.state) {
            draw(p, ring.previous());
        }
        Ok(())
    }
}

impl super::Features {
    /// The allocator's emission pass, drawn before the integration.
    pub(super) fn emit_pass(&self, verlet: bool) -> Option<String> {
        let Emission::Allocator(kind) = self.emission else {
            return None;
        };
        Some(format!(
            "emit: new particles drawn as single pixels into {} and static (CPU {} allocator)",
            if verlet {
                "current and previous positions"
            } else {
                "position and velocity"
            },
            match kind {
                AllocatorKind::Stack => "stack",
                AllocatorKind::MinHeap => "min-heap",
            }
        ))
    }
}

impl ParticleSim {
    /// The allocator's births: each program at most once a step (none without births).
    pub(super) fn birth_draws(&self) -> Vec<PassDraw> {
        [&self.emit_state, &self.emit_previous, &self.emit_static]
            .into_iter()
            .flatten()
            .map(|p| PassDraw::of("emit:", p, 1).varying())
            .collect()
    }
}
