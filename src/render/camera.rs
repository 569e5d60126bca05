//! An orbit camera built with glam.

use glam::{Mat4, Vec3};

/// A camera orbiting `target` at `distance`: `azimuth` around +y (0 looks from +z towards -z),
/// `elevation` above the xz plane. Angles in degrees.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Camera {
    /// The point looked at.
    pub target: Vec3,
    /// Distance from the target.
    pub distance: f32,
    /// Orbit angle around +y, degrees.
    pub azimuth: f32,
    /// Angle above the horizon, degrees.
    pub elevation: f32,
    /// Vertical field of view, degrees.
    pub fov_y: f32,
    /// Near clip distance.
    pub near: f32,
    /// Far clip distance.
    pub far: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            target: Vec3::ZERO,
            distance: 4.0,
            azimuth: 0.0,
            elevation: 10.0,
            fov_y: 45.0,
            near: 0.05,
            far: 100.0,
        }
    }
}

impl From<&crate::scene::CameraSection> for Camera {
    /// The camera a scene file describes, at time 0 (its orbit is the caller's to apply).
    fn from(c: &crate::scene::CameraSection) -> Camera {
        Camera {
            target: Vec3::from(c.target),
            distance: c.distance,
            azimuth: c.azimuth,
            elevation: c.elevation,
            fov_y: c.fov,
            ..Camera::default()
        }
    }
}

impl Camera {
    /// This camera (a scene's, at time 0) turned by its orbit: `degrees_per_s`
    /// (`render.camera.orbit`) around +y for `t` simulated seconds. The one place the orbit is
    /// computed: the engines, and through them the viewer, the benchmarks and the report.
    pub fn orbited(self, degrees_per_s: f32, t: f32) -> Camera {
        Camera {
            azimuth: self.azimuth + degrees_per_s * t,
            ..self
        }
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        let (az, el) = (self.azimuth.to_radians(), self.elevation.to_radians());
        self.target + self.distance * Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
    }

    /// View matrix (right-handed, +y up).
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye(), self.target, Vec3::Y)
    }

    /// Projection matrix for an image of `aspect` = width / height (GL clip space).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh_gl(self.fov_y.to_radians(), aspect, self.near, self.far)
    }

    /// Projection times view.
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// The pixel (x right, y down, as in the PNG) where `p` lands in a `width`×`height` image, or
    /// `None` if it is outside the view volume.
    pub fn project_to_pixel(&self, p: Vec3, width: u32, height: u32) -> Option<(u32, u32)> {
        let clip = self.view_projection(width as f32 / height as f32) * p.extend(1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.truncate() / clip.w;
        if ndc.abs().max_element() > 1.0 {
            return None;
        }
        let x = ((ndc.x * 0.5 + 0.5) * width as f32).floor() as u32;
        let y_up = ((ndc.y * 0.5 + 0.5) * height as f32).floor() as u32;
        Some((x.min(width - 1), height - 1 - y_up.min(height - 1)))
    }
}

/// A viewer's change to a scene's camera (the live window's mouse): turned by `azimuth` and
/// `elevation` degrees and moved `zoom` times as far. The identity changes nothing, so a frame
/// drawn with it is the headless frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewOffset {
    /// Degrees added to the orbit angle around +y.
    pub azimuth: f32,
    /// Degrees added to the angle above the horizon (the sum kept within ±89°).
    pub elevation: f32,
    /// Factor on the distance from the target.
    pub zoom: f32,
}

impl Default for ViewOffset {
    fn default() -> Self {
        ViewOffset {
            azimuth: 0.0,
            elevation: 0.0,
            zoom: 1.0,
        }
    }
}

impl ViewOffset {
    /// `camera` as this offset changes it.
    pub fn apply(&self, mut camera: Camera) -> Camera {
        if *self == ViewOffset::default() {
            return camera;
        }
        camera.azimuth += self.azimuth;
        camera.elevation = (camera.elevation + self.elevation).clamp(-89.0, 89.0);
        camera.distance *= self.zoom;
        camera
    }
}
