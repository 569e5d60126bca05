//! Textures bound as data: a draw names which texture each sampler reads, and this layer picks
//! the texture units.
//!
//! Numbering units by hand in several modules let one pass leave a texture on a unit that a
//! later pass's sampler still pointed at (a staggered collision gather overwrote the unit the
//! response read its height field from). A [`Draw`](super::Draw) lists its textures and
//! [`Context::draw`](super::Context::draw) gives units 0..n to the list, in order, on every
//! draw; nothing above this module binds a unit. A sampler the program reads but the list
//! leaves out is refused (a panic: a programming error, like an index out of bounds), and so,
//! in debug builds, is a listed name the program does not declare.
//!
//! Telling a misspelt name from one the optimiser dropped: GL reports both as location −1, so the
//! program keeps the names its resolved sources declare (`uniform TYPE NAME...;`). A name that is
//! declared but inactive was dropped and is ignored, as GL ignores it; a name that is not
//! declared at all is an error.

use std::collections::HashSet;

use glow::HasContext;

use super::{Program, RecordedTexture, Texture, Texture3D};

/// A texture a sampler reads: 2D (`sampler2D`) or 3D (`sampler3D`).
#[derive(Debug, Clone, Copy)]
pub enum Sampled<'a> {
    /// A 2D texture.
    D2(&'a Texture),
    /// A 3D texture.
    D3(&'a Texture3D),
    /// A texture a recorded draw read, by name (a benchmark's floor reading the same data);
    /// the caller checks that it lives ([`Context::is_live`](super::Context::is_live)).
    Recorded(RecordedTexture),
}

impl Sampled<'_> {
    /// The texture's GL name.
    pub(super) fn raw(&self) -> glow::Texture {
        match self {
            Sampled::D2(t) => t.raw(),
            Sampled::D3(t) => t.raw(),
            Sampled::Recorded(r) => r.raw,
        }
    }
}

impl<'a> From<&'a Texture> for Sampled<'a> {
    fn from(t: &'a Texture) -> Self {
        Sampled::D2(t)
    }
}

impl<'a> From<&'a Texture3D> for Sampled<'a> {
    fn from(t: &'a Texture3D) -> Self {
        Sampled::D3(t)
    }
}

/// The uniform names `source` declares (`uniform TYPE A, B[N];` gives `A` and `B`).
pub(super) fn declared_uniforms(source: &str) -> HashSet<String> {
    let mut names = HashSet::new();
    for statement in source.split(';') {
        let s = statement
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join(" ");
        let mut words = s.split_whitespace().skip_while(|w| *w != "uniform");
        if words.next().is_none() {
            continue;
        }
        // Skip the precision qualifier, if any, and the type.
        let mut rest: Vec<&str> = words.collect();
        while matches!(rest.first(), Some(&("highp" | "mediump" | "lowp"))) {
            rest.remove(0);
        }
        if rest.is_empty() {
            continue;
        }
        for decl in rest[1..].join(" ").split(',') {
            let name = decl.split('[').next().unwrap_or("").trim();
            if !name.is_empty() {
                names.insert(name.to_owned());
            }
        }
    }
    names
}

/// The base name of a uniform as GL names it: `u_plane[3]` and `u_light.colour` are `u_plane`
/// and `u_light`.
pub(super) fn base_name(name: &str) -> &str {
    let end = name.find(['[', '.']).unwrap_or(name.len());
    &name[..end]
}

/// Whether a GL uniform type is a sampler.
pub(super) fn is_sampler(kind: u32) -> bool {
    matches!(
        kind,
        glow::SAMPLER_1D
            | glow::SAMPLER_2D
            | glow::SAMPLER_3D
            | glow::SAMPLER_CUBE
            | glow::SAMPLER_2D_ARRAY
            | glow::INT_SAMPLER_2D
            | glow::INT_SAMPLER_3D
            | glow::UNSIGNED_INT_SAMPLER_2D
            | glow::UNSIGNED_INT_SAMPLER_3D
            | glow::SAMPLER_BUFFER
    )
}

impl Program {
    /// Binds the textures of one draw: `list[k]`'s texture goes to unit k and its sampler is set
    /// to k. The program must be bound. Called by [`Context::draw`](super::Context::draw) only.
    ///
    /// Panics if a sampler the program reads is missing from `list`, and in debug builds if a
    /// name is not a uniform the program declares.
    pub(super) fn bind_textures(&self, list: &[(&str, Sampled<'_>)]) {
        let unlisted: Vec<&String> = self
            .samplers()
            .iter()
            .filter(|s| !list.iter().any(|(n, _)| n == s))
            .collect();
        assert!(
            unlisted.is_empty(),
            "program {} reads sampler(s) {unlisted:?} that this draw binds no texture to: \
             list every sampler in Draw::textures",
            self.name()
        );
        for (k, (name, texture)) in list.iter().enumerate() {
            match texture {
                Sampled::D2(t) => t.bind(k as u32),
                Sampled::D3(t) => t.bind(k as u32),
                Sampled::Recorded(r) => self.bind_recorded(k as u32, r),
            }
            if cfg!(debug_assertions) && !self.declares(name) {
                panic!(
                    "program {} has no sampler `{name}` (misspelt, or the wrong program)",
                    self.name()
                );
            }
            self.set(name, &super::Uniform::I32(k as i32));
        }
    }
}

impl Program {
    /// Binds recorded texture `r` to `unit`.
    fn bind_recorded(&self, unit: u32, r: &RecordedTexture) {
        let target = if r.shape.three_d {
            glow::TEXTURE_3D
        } else {
            glow::TEXTURE_2D
        };
        // SAFETY: the caller checked that the name is a live texture of this context.
        unsafe {
            self.ctx.gl().active_texture(glow::TEXTURE0 + unit);
            self.ctx.gl().bind_texture(target, Some(r.raw));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_are_found_and_comments_ignored() {
        let src = "uniform sampler2D u_position;\n// uniform float u_not;\n\
                   uniform vec4 u_plane[MAX_PLANES];\nuniform highp float u_a, u_b[2];\n\
                   float rng_uniform(inout uint s);";
        let d = declared_uniforms(src);
        let mut v: Vec<_> = d.into_iter().collect();
        v.sort();
        assert_eq!(v, ["u_a", "u_b", "u_plane", "u_position"]);
    }

    #[test]
    fn base_names_drop_index_and_field() {
        assert_eq!(base_name("u_plane[3]"), "u_plane");
        assert_eq!(base_name("u_l.c"), "u_l");
        assert_eq!(base_name("u_x"), "u_x");
    }
}
