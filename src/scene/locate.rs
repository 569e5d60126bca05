//! Where in the file an error is: paths into the document, their spans, line and column.
//!
//! Validation runs on the typed [`SceneFile`](super::SceneFile), which has no spans; it reports a
//! path ([`Key`]s), and a second, untyped parse of the source finds where that path starts.

use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::Error;

/// One step of a path into the TOML document, for locating an error.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// A table key.
    Name(&'static str),
    /// An array index.
    Index(usize),
}

/// `at` as a dotted key path (`emitters.timestamp[0].life`), for errors without a file.
pub(super) fn key_path(at: &[Key]) -> String {
    let mut out = String::new();
    for k in at {
        match k {
            Key::Name(n) if out.is_empty() => out.push_str(n),
            Key::Name(n) => {
                out.push('.');
                out.push_str(n);
            }
            Key::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// A validation failure: where (a path into the document) and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid {
    /// Path to the offending value.
    pub at: Vec<Key>,
    /// What is wrong and what to do.
    pub message: String,
}

impl Invalid {
    /// The offending key as a dotted path (`fire.life`), for errors without a file.
    pub fn key(&self) -> String {
        key_path(&self.at)
    }
}

pub(super) fn line_column(src: &str, offset: usize) -> (usize, usize) {
    let mut end = offset.min(src.len());
    while !src.is_char_boundary(end) {
        end -= 1;
    }
    let before = &src[..end];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

pub(super) fn scene_error(path: &str, src: &str, offset: usize, message: String) -> Error {
    let (line, column) = line_column(src, offset);
    Error::Scene {
        path: path.to_owned(),
        line,
        column,
        message,
    }
}

/// The text of a scene file read as bytes, or an error at the line and column of the first byte
/// that is not UTF-8 (counted in the valid text before it).
pub(super) fn utf8(path: &str, bytes: Vec<u8>) -> Result<String, Error> {
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let before = std::str::from_utf8(&e.as_bytes()[..valid]).unwrap_or_default();
        let byte = e.as_bytes()[valid];
        scene_error(
            path,
            before,
            valid,
            format!("byte 0x{byte:02x} is not UTF-8: a scene file must be UTF-8 text"),
        )
    })
}

/// Finds where `at` starts in the untyped document (the deepest part that exists): a plain
/// value or an array of plain values at the value, like the parser's own type errors; a table or
/// an array of tables at its key (in its first header); an array element at the element.
/// The untyped document of a scene that already parsed once (for locating keys); a syntax error
/// is still reported at its place.
pub(super) fn document<'a>(path: &str, src: &'a str) -> Result<Spanned<DeTable<'a>>, Error> {
    DeTable::parse(src).map_err(|e| {
        scene_error(
            path,
            src,
            e.span().map_or(0, |s| s.start),
            e.message().into(),
        )
    })
}

pub(super) fn locate(doc: &Spanned<DeTable<'_>>, at: &[Key]) -> usize {
    fn holds_tables(v: &DeValue<'_>) -> bool {
        match v {
            DeValue::Table(_) => true,
            DeValue::Array(a) => a.iter().any(|e| holds_tables(e.get_ref())),
            _ => false,
        }
    }
    let mut span = doc.span().start;
    let mut value: Option<&DeValue<'_>> = None;
    let mut table = Some(doc.get_ref());
    for key in at {
        let next = match (key, table, value) {
            (Key::Name(n), Some(t), _) => {
                t.iter()
                    .find(|(k, _)| k.get_ref().as_ref() == *n)
                    .map(|(k, v)| {
                        let start = if holds_tables(v.get_ref()) {
                            k.span().start
                        } else {
                            v.span().start
                        };
                        (start, v)
                    })
            }
            (Key::Index(i), _, Some(DeValue::Array(a))) => a.get(*i).map(|v| (v.span().start, v)),
            _ => None,
        };
        let Some((start, v)) = next else { break };
        span = start;
        value = Some(v.get_ref());
        table = match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
    }
    span
}

/// Reports the first float that is NaN, infinite or beyond f32's range.
pub(super) fn find_non_finite(doc: &DeTable<'_>) -> Option<(usize, String)> {
    fn walk(v: &Spanned<DeValue<'_>>) -> Option<(usize, String)> {
        match v.get_ref() {
            DeValue::Float(f) => {
                let text = f.as_str();
                let value: f64 = text.replace('_', "").parse().unwrap_or(f64::NAN);
                (!value.is_finite() || value.abs() > f32::MAX as f64).then(|| {
                    (
                        v.span().start,
                        format!(
                            "`{text}` is not a finite 32-bit number: scene values must be finite"
                        ),
                    )
                })
            }
            DeValue::Array(a) => a.iter().find_map(walk),
            DeValue::Table(t) => t.iter().find_map(|(_, v)| walk(v)),
            _ => None,
        }
    }
    doc.iter().find_map(|(_, v)| walk(v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use Key::{Index as I, Name as N};

    #[test]
    fn line_and_column_count_from_one() {
        assert_eq!(line_column("ab\ncd", 0), (1, 1));
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
        // Columns count characters; an offset inside a character counts from its start.
        assert_eq!(line_column("é = 1", 3), (1, 3));
        assert_eq!(line_column("é = 1", 1), (1, 1));
        assert_eq!(line_column("a", 99), (1, 2));
    }

    #[test]
    fn locate_points_at_values_elements_and_table_keys() {
        let src = "[a]\nx = 1.0\nv = [1, 2]\n[[t]]\ny = 2\n";
        let doc = DeTable::parse(src).unwrap();
        let at = |keys: &[Key]| line_column(src, locate(&doc, keys));
        assert_eq!(at(&[N("a"), N("x")]), (2, 5));
        assert_eq!(at(&[N("a"), N("v"), I(1)]), (3, 9));
        assert_eq!(at(&[N("a"), N("missing")]), (1, 2));
        assert_eq!(at(&[N("t"), I(0), N("y")]), (5, 5));
        assert_eq!(at(&[N("t")]).0, 4);
    }

    #[test]
    fn bytes_that_are_not_utf8_are_located() {
        let err = utf8("s.toml", b"a = 1\nb = \"\xe9\"\n".to_vec()).unwrap_err();
        match err {
            Error::Scene {
                line,
                column,
                message,
                ..
            } => {
                assert_eq!((line, column), (2, 6));
                assert!(message.contains("must be UTF-8"), "{message}");
            }
            e => panic!("{e}"),
        }
        assert_eq!(utf8("s.toml", b"x = 1".to_vec()).unwrap(), "x = 1");
    }
}
