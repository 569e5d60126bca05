//! Colour attachments reached by name: a framebuffer built from named attachments gives its
//! textures for [`Attachment`] handles, so no code above this layer numbers attachments.
//!
//! A handle is a name, not an index: a framebuffer looks the name up among its own attachments
//! (at most eight, a few string compares) and panics if it has none of that name. A handle of one
//! kind of state used on a framebuffer of another therefore fails loudly instead of reading
//! whatever texture sits at the same index; and an attachment present in some framebuffers of a
//! kind only (the spin of spinning spheres) needs no index of its own.

use super::Framebuffer;

/// A colour attachment of a framebuffer, by name: made once by the module that owns a kind of
/// state (`pub const POSITION: Attachment = Attachment::named("position");`), given to
/// [`Framebuffer::named`] or [`PingPong::new`](super::PingPong::new) in the order of the
/// fragment shader's outputs, and to [`Framebuffer::texture`] to reach the texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Attachment(&'static str);

impl Attachment {
    /// The attachment called `name` (not empty: a compile error in a `const`).
    pub const fn named(name: &'static str) -> Self {
        assert!(!name.is_empty(), "an attachment needs a name");
        Attachment(name)
    }

    /// Its name.
    pub const fn name(self) -> &'static str {
        self.0
    }
}

impl From<&'static str> for Attachment {
    fn from(name: &'static str) -> Self {
        Attachment::named(name)
    }
}

impl std::fmt::Display for Attachment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Attachment {}
    impl Sealed for usize {}
}

/// What picks an attachment of a framebuffer: an [`Attachment`] handle; or an index, for the
/// gl layer's own tests and the callers not yet moved to handles (`tests/layout.rs` refuses a
/// literal index above `src/gl`).
pub trait AttachmentKey: sealed::Sealed + Copy + std::fmt::Debug {
    /// The index of the attachment in `fb`.
    ///
    /// # Panics
    /// If `fb` has no such attachment: a programming error, like an index out of bounds.
    fn index_in(self, fb: &Framebuffer) -> usize;
}

impl AttachmentKey for usize {
    fn index_in(self, fb: &Framebuffer) -> usize {
        assert!(
            self < fb.attachments(),
            "framebuffer {} has no attachment {self} (it has {})",
            fb.label(),
            fb.attachments()
        );
        self
    }
}

impl AttachmentKey for Attachment {
    fn index_in(self, fb: &Framebuffer) -> usize {
        match fb.names().iter().position(|n| *n == Some(self)) {
            Some(i) => i,
            None => panic!(
                "framebuffer {} has no attachment `{self}` (its attachments: {}); a handle of \
                 another kind of state, or a framebuffer built without names",
                fb.label(),
                describe(fb.names())
            ),
        }
    }
}

/// `position, velocity` or `unnamed 0, unnamed 1`.
fn describe(names: &[Option<Attachment>]) -> String {
    names
        .iter()
        .enumerate()
        .map(|(i, n)| match n {
            Some(a) => a.name().to_owned(),
            None => format!("unnamed {i}"),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Refuses two attachments of one name in one framebuffer (the second could never be reached).
pub(super) fn check_unique(label: &str, names: &[Option<Attachment>]) -> crate::error::Result<()> {
    for (i, a) in names.iter().enumerate() {
        if let Some(a) = a {
            if names[..i].contains(&Some(*a)) {
                return Err(crate::error::Error::InvalidInput(format!(
                    "framebuffer {label}: two attachments are named `{a}`; give each its own name"
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_compare_by_name() {
        const P: Attachment = Attachment::named("position");
        assert_eq!(P, Attachment::from("position"));
        assert_ne!(P, Attachment::named("velocity"));
        assert_eq!(P.to_string(), "position");
    }

    #[test]
    fn duplicate_names_are_refused_and_unnamed_ones_are_not() {
        let p = Some(Attachment::named("position"));
        let v = Some(Attachment::named("velocity"));
        assert!(check_unique("s", &[p, v]).is_ok());
        assert!(check_unique("s", &[None, None]).is_ok());
        let e = check_unique("s", &[p, v, p]).unwrap_err().to_string();
        assert!(e.contains("`position`"), "{e}");
        assert_eq!(describe(&[p, None]), "position, unnamed 1");
    }
}
