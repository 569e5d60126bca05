//! The particle state's attachments by name, shared by every pass that reads or writes the
//! state: the integration and its single-target passes, the collision stage's layouts, the
//! sort's gathers. One name per kind of texel, whichever framebuffer holds it.

use crate::gl::Attachment;

/// Position (xyz) and remaining life (w).
pub const POSITION: Attachment = Attachment::named("position");
/// Velocity (xyz).
pub const VELOCITY: Attachment = Attachment::named("velocity");
/// Spinning spheres: angular velocity and the angle about z.
pub const SPIN: Attachment = Attachment::named("spin");
/// The static texel: birth time or phase, type, total life, random number.
pub const STATIC: Attachment = Attachment::named("static");
