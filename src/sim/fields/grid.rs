//! The grid every field is built on: its axes (nodes, cells) and a 3D grid of texels, with the
//! conventions of the `sim::fields` module doc.

use glam::{Vec3, Vec4};

use crate::error::{Error, Result};
use crate::gl::{Context, Texture3D, TextureFormat};

/// One axis of a field's grid: `n` nodes from `min` to `max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Axis {
    pub(super) min: f32,
    pub(super) max: f32,
    pub(super) n: u32,
}

impl Axis {
    pub(super) fn new(what: &str, min: f32, max: f32, n: u32) -> Result<Self> {
        if n < 2 {
            return Err(Error::InvalidInput(format!(
                "{what}: resolution {n} is too small, a field needs at least 2 nodes per axis"
            )));
        }
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(Error::InvalidInput(format!(
                "{what}: the range {min}..{max} must be finite with min < max"
            )));
        }
        Ok(Axis { min, max, n })
    }

    /// Position of node `i`, computed in double precision so that the last node is `max`.
    pub(super) fn node(&self, i: usize) -> f32 {
        let (lo, hi) = (self.min as f64, self.max as f64);
        (lo + i as f64 * (hi - lo) / (self.n - 1) as f64) as f32
    }

    /// Node spacing in double precision.
    pub(super) fn spacing_f64(&self) -> f64 {
        (self.max as f64 - self.min as f64) / (self.n - 1) as f64
    }

    /// The nodes `i0`, `i1` around `x` and the weight `t` (see `sim::fields`); the twin of
    /// `field_cell` in GLSL.
    pub(super) fn cell(&self, x: f32) -> (usize, usize, f32) {
        let top = (self.n - 1) as f32;
        let u = ((x - self.min) / (self.max - self.min) * top).clamp(0.0, top);
        let i0 = u.floor() as usize;
        (i0, (i0 + 1).min(self.n as usize - 1), u - i0 as f32)
    }
}

/// `a + t (b - a)` per component (exactly `a` at `t = 0` and where `a == b`), the twin of
/// `field_lerp` in GLSL. (Not glam's `Vec4::lerp`, which computes `a (1 - t) + b t`: not exact
/// between equal texels.)
pub(super) fn lerp(a: Vec4, b: Vec4, t: f32) -> Vec4 {
    a + t * (b - a)
}

/// A 3D grid of `C`-channel texels with the conventions of `sim::fields`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Grid3 {
    axes: [Axis; 3],
    channels: usize,
    pub(super) data: Vec<f32>,
}

/// The three axes of a grid over `bounds` with `res` nodes per axis, checked.
pub(super) fn axes(what: &str, bounds: [[f32; 3]; 2], res: [u32; 3]) -> Result<[Axis; 3]> {
    Ok([
        Axis::new(&format!("{what} x"), bounds[0][0], bounds[1][0], res[0])?,
        Axis::new(&format!("{what} y"), bounds[0][1], bounds[1][1], res[1])?,
        Axis::new(&format!("{what} z"), bounds[0][2], bounds[1][2], res[2])?,
    ])
}

impl Grid3 {
    /// The grid on `axes` with texel `(i, j, k)` the first `channels` of `f` at its node.
    pub(super) fn from_axes(axes: [Axis; 3], channels: usize, f: impl Fn(Vec3) -> Vec4) -> Self {
        let [nx, ny, nz] = axes.map(|a| a.n as usize);
        let mut data = Vec::with_capacity(nx * ny * nz * channels);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let p = Vec3::new(axes[0].node(i), axes[1].node(j), axes[2].node(k));
                    data.extend_from_slice(&f(p).to_array()[..channels]);
                }
            }
        }
        Grid3 {
            axes,
            channels,
            data,
        }
    }

    /// The grid on `axes` with the given texels (x fastest, `channels` each), checked for length.
    pub(super) fn from_data(
        what: &str,
        axes: [Axis; 3],
        channels: usize,
        data: Vec<f32>,
    ) -> Result<Self> {
        let want = axes.iter().map(|a| a.n as usize).product::<usize>() * channels;
        if data.len() != want {
            return Err(Error::InvalidInput(format!(
                "{what}: {} values given, the grid needs {want}",
                data.len()
            )));
        }
        Ok(Grid3 {
            axes,
            channels,
            data,
        })
    }

    pub(super) fn res(&self) -> [u32; 3] {
        self.axes.map(|a| a.n)
    }

    pub(super) fn bounds(&self) -> [Vec3; 2] {
        let [x, y, z] = self.axes;
        [
            Vec3::new(x.min, y.min, z.min),
            Vec3::new(x.max, y.max, z.max),
        ]
    }

    pub(super) fn node(&self, [i, j, k]: [usize; 3]) -> Vec3 {
        Vec3::new(
            self.axes[0].node(i),
            self.axes[1].node(j),
            self.axes[2].node(k),
        )
    }

    /// Texel `(i, j, k)` with its channels in x, y, z, w (missing channels 0).
    pub(super) fn texel(&self, i: usize, j: usize, k: usize) -> Vec4 {
        let [nx, ny, _] = self.res().map(|n| n as usize);
        let at = ((k * ny + j) * nx + i) * self.channels;
        let mut v = [0.0; 4];
        v[..self.channels].copy_from_slice(&self.data[at..at + self.channels]);
        Vec4::from_array(v)
    }

    /// Trilinear interpolation: the twin of `field_trilinear` in GLSL.
    pub(super) fn trilinear(&self, p: Vec3) -> Vec4 {
        let (i0, i1, tx) = self.axes[0].cell(p.x);
        let (j0, j1, ty) = self.axes[1].cell(p.y);
        let (k0, k1, tz) = self.axes[2].cell(p.z);
        let t = |a, b, c| self.texel(a, b, c);
        let c00 = lerp(t(i0, j0, k0), t(i1, j0, k0), tx);
        let c10 = lerp(t(i0, j1, k0), t(i1, j1, k0), tx);
        let c01 = lerp(t(i0, j0, k1), t(i1, j0, k1), tx);
        let c11 = lerp(t(i0, j1, k1), t(i1, j1, k1), tx);
        let c0 = lerp(c00, c10, ty);
        let c1 = lerp(c01, c11, ty);
        lerp(c0, c1, tz)
    }

    pub(super) fn upload(&self, ctx: &Context, label: &str) -> Result<Texture3D> {
        let format = match self.channels {
            1 => TextureFormat::R32F,
            _ => TextureFormat::Rgba32F,
        };
        Texture3D::new(ctx, label, format, self.res(), Some(&self.data))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_cells_clamp_and_reach_the_last_node() {
        let a = Axis::new("a", -1.0, 3.0, 5).unwrap();
        assert_eq!(a.cell(-1.0), (0, 1, 0.0));
        assert_eq!(a.cell(-7.0), (0, 1, 0.0));
        assert_eq!(a.cell(1.0), (2, 3, 0.0));
        assert_eq!(a.cell(1.5), (2, 3, 0.5));
        assert_eq!(a.cell(2.75), (3, 4, 0.75));
        assert_eq!(a.cell(3.0), (4, 4, 0.0));
        assert_eq!(a.cell(30.0), (4, 4, 0.0));
        assert_eq!(a.node(4), 3.0);
        assert!(Axis::new("a", 0.0, 1.0, 1).is_err());
        assert!(Axis::new("a", 1.0, 1.0, 4).is_err());
        assert!(Axis::new("a", 0.0, f32::NAN, 4).is_err());
    }
}
