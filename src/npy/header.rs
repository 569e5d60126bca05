//! The `.npy` preamble and header: the magic, the format version, the header's length and the
//! Python dict literal `{'descr': ..., 'fortran_order': ..., 'shape': ...}`.
//!
//! The dict is parsed as a Python literal, not searched for substrings, so that every malformed
//! header is refused with a message that names what was found and what is accepted, and no
//! header can declare more elements than a `usize` holds.

use std::path::Path;

use super::{bad, MAGIC};
use crate::error::Result;

/// The dtype and shape of an array's header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// NumPy's type string, e.g. `<f4`; for a structured dtype the list as written in the
    /// header, e.g. `[('a', '<f4')]` (no reader accepts one).
    pub descr: String,
    /// Whether the data is in Fortran order.
    pub fortran_order: bool,
    /// The shape; as [`parse_header`] returns it, the product of its entries fits in a `usize`.
    pub shape: Vec<usize>,
}

impl Header {
    /// The number of elements the header declares (the product of the shape, 1 for `()`);
    /// `usize::MAX` where the product overflows, which [`parse_header`] never returns.
    pub fn elements(&self) -> usize {
        self.shape
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .unwrap_or(usize::MAX)
    }
}

/// What a .npy header's dict must hold.
const KEYS: &str = "a .npy header holds exactly 'descr', 'fortran_order' and 'shape'";

/// Nesting deeper than this is refused (a structured dtype nests a few levels; a fuzzed header
/// could nest deep enough to overflow the stack).
const MAX_DEPTH: usize = 32;

/// A Python literal of the kinds a header holds, with the text it was parsed from.
#[derive(Debug, Clone, PartialEq)]
enum Lit {
    Str(String),
    /// An integer's digits, with its sign (a Python 2 `L` suffix dropped).
    Int(String),
    Bool(bool),
    None,
    Tuple(Vec<(Lit, String)>),
    List(Vec<(Lit, String)>),
    Dict(Vec<((Lit, String), (Lit, String))>),
}

/// A recursive-descent parser of Python literals over the header's text.
struct Parser<'a> {
    s: &'a str,
    at: usize,
}

impl<'a> Parser<'a> {
    fn skip_ws(&mut self) {
        let rest = &self.s[self.at..];
        self.at += rest.len() - rest.trim_start().len();
    }

    fn peek(&self) -> Option<char> {
        self.s[self.at..].chars().next()
    }

    fn eat(&mut self, c: char) -> bool {
        self.skip_ws();
        if self.peek() == Some(c) {
            self.at += c.len_utf8();
            true
        } else {
            false
        }
    }

    /// What stands at the cursor, for messages.
    fn found(&self) -> String {
        match self.s[self.at..].chars().take(12).collect::<String>() {
            s if s.is_empty() => "the end of the header".into(),
            s => format!("`{s}`"),
        }
    }

    fn expected(&self, what: &str) -> String {
        format!(
            "expected {what} at byte {} of the header, found {}",
            self.at,
            self.found()
        )
    }

    /// One literal and the text it spans.
    fn value(&mut self, depth: usize) -> Result<(Lit, String), String> {
        if depth > MAX_DEPTH {
            return Err(format!("the header nests deeper than {MAX_DEPTH} levels"));
        }
        self.skip_ws();
        let start = self.at;
        let lit = match self.peek() {
            Some('{') => self.dict(depth)?,
            Some(open @ ('(' | '[')) => self.sequence(open, depth)?,
            Some(q @ ('\'' | '"')) => self.string(q)?,
            Some(c) if c.is_ascii_digit() || c == '-' || c == '+' => self.int(c)?,
            Some(c) if c.is_ascii_alphabetic() => self.word()?,
            _ => return Err(self.expected("a Python literal")),
        };
        Ok((lit, self.s[start..self.at].trim().to_owned()))
    }

    /// A dict after its `{`: key-value pairs up to the `}`.
    fn dict(&mut self, depth: usize) -> Result<Lit, String> {
        self.at += 1;
        let mut items = Vec::new();
        // Python allows a trailing comma, and numpy writes one.
        while !self.eat('}') {
            let key = self.value(depth + 1)?;
            if !self.eat(':') {
                return Err(self.expected("`:` after a key"));
            }
            items.push((key, self.value(depth + 1)?));
            if self.eat('}') {
                break;
            }
            if !self.eat(',') {
                return Err(self.expected("`,` or `}`"));
            }
        }
        Ok(Lit::Dict(items))
    }

    /// A tuple or a list, after its opening `open`.
    fn sequence(&mut self, open: char, depth: usize) -> Result<Lit, String> {
        self.at += 1;
        let close = if open == '(' { ')' } else { ']' };
        let mut items = Vec::new();
        while !self.eat(close) {
            items.push(self.value(depth + 1)?);
            if self.eat(close) {
                break;
            }
            if !self.eat(',') {
                return Err(self.expected(&format!("`,` or `{close}`")));
            }
        }
        Ok(if open == '(' {
            Lit::Tuple(items)
        } else {
            Lit::List(items)
        })
    }

    /// A string quoted by `q`, up to the next `q` (escapes are not read).
    fn string(&mut self, q: char) -> Result<Lit, String> {
        self.at += 1;
        let body = &self.s[self.at..];
        let end = body
            .find(q)
            .ok_or_else(|| format!("a string in the header has no closing {q}"))?;
        self.at += end + 1;
        Ok(Lit::Str(body[..end].to_owned()))
    }

    /// An integer starting with `c` (a digit or a sign).
    fn int(&mut self, c: char) -> Result<Lit, String> {
        let body = &self.s[self.at..];
        let sign = usize::from(c == '-' || c == '+');
        let digits = body[sign..]
            .find(|c: char| !c.is_ascii_digit())
            .unwrap_or(body.len() - sign);
        if digits == 0 {
            return Err(self.expected("a number"));
        }
        let text = &body[..sign + digits];
        self.at += sign + digits;
        // Python 2's long integers (`2L`), which old numpy versions wrote in shapes.
        if matches!(self.peek(), Some('L' | 'l')) {
            self.at += 1;
        }
        Ok(Lit::Int(text.trim_start_matches('+').to_owned()))
    }

    /// `True`, `False` or `None`; any other word is refused.
    fn word(&mut self) -> Result<Lit, String> {
        let body = &self.s[self.at..];
        let len = body
            .find(|c: char| !c.is_ascii_alphanumeric() && c != '_')
            .unwrap_or(body.len());
        let lit = match &body[..len] {
            "True" => Lit::Bool(true),
            "False" => Lit::Bool(false),
            "None" => Lit::None,
            word => {
                return Err(format!(
                    "`{word}` in the header is not a Python literal (True, False, None, a number, a string, a tuple or a list)"
                ))
            }
        };
        self.at += len;
        Ok(lit)
    }
}

/// The header's text (at most this many characters) in messages.
fn clip(text: &str) -> String {
    const MAX: usize = 60;
    if text.chars().count() <= MAX {
        text.to_owned()
    } else {
        format!("{}...", text.chars().take(MAX).collect::<String>())
    }
}

/// The preamble: the format version and the header's text, and the offset of the data.
fn preamble(path: &Path, bytes: &[u8]) -> Result<(String, usize)> {
    check_magic(path, bytes)?;
    let (major, width) = version(path, bytes)?;
    let start = 8 + width;
    let len = match bytes.get(8..start) {
        Some(&[a, b]) => u16::from_le_bytes([a, b]) as usize,
        Some(&[a, b, c, d]) => u32::from_le_bytes([a, b, c, d]) as usize,
        _ => {
            return Err(bad(
                path,
                format!(
                    "the .npy file is truncated: it ends inside the {width}-byte header length of version {major}.0"
                ),
            ))
        }
    };
    let header = start
        .checked_add(len)
        .and_then(|end| bytes.get(start..end))
        .ok_or_else(|| {
            bad(
                path,
                format!(
                    "the .npy header is truncated: its length field says {len} bytes, the file has {} after the preamble",
                    bytes.len() - start
                ),
            )
        })?;
    // Versions 1 and 2 are latin-1 (every byte a char), version 3 is UTF-8.
    let text = if major == 3 {
        std::str::from_utf8(header)
            .map_err(|e| {
                bad(
                    path,
                    format!("the .npy header is not UTF-8, as version 3.0 requires ({e})"),
                )
            })?
            .to_owned()
    } else {
        header.iter().map(|&b| char::from(b)).collect()
    };
    Ok((text, start + len))
}

/// Refuses bytes that do not start with the .npy magic, saying what they start with.
fn check_magic(path: &Path, bytes: &[u8]) -> Result<()> {
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        if MAGIC.starts_with(bytes) {
            return Err(bad(
                path,
                format!(
                    "the file is truncated: it has {} bytes, not even the 6 of the .npy magic \\x93NUMPY",
                    bytes.len()
                ),
            ));
        }
        let head: String = bytes
            .iter()
            .take(MAGIC.len())
            .flat_map(|b| std::ascii::escape_default(*b))
            .map(char::from)
            .collect();
        return Err(bad(
            path,
            format!(
                "not a .npy file: it starts with `{head}`, a .npy file with \\x93NUMPY: save the keys with numpy.save"
            ),
        ));
    }
    Ok(())
}

/// The format version's major number and the width of its header-length field.
fn version(path: &Path, bytes: &[u8]) -> Result<(u8, usize)> {
    let (major, minor) = match bytes.get(6..8) {
        Some(v) => (v[0], v[1]),
        None => {
            return Err(bad(
                path,
                "the .npy file is truncated: it ends before its format version",
            ))
        }
    };
    let width = match (major, minor) {
        (1, 0) => 2,
        (2 | 3, 0) => 4,
        _ => {
            return Err(bad(
                path,
                format!(
                    "unsupported .npy format version {major}.{minor}: versions 1.0, 2.0 and 3.0 are accepted"
                ),
            ))
        }
    };
    Ok((major, width))
}

/// Parses an `.npy` file's bytes into its header and the offset of the data.
pub fn parse_header(path: &Path, bytes: &[u8]) -> Result<(Header, usize)> {
    let (text, data) = preamble(path, bytes)?;
    let in_header = |msg: String| bad(path, format!("bad .npy header: {msg}"));
    let mut p = Parser { s: &text, at: 0 };
    let (dict, dict_text) = p.value(0).map_err(in_header)?;
    p.skip_ws();
    if p.at < text.len() {
        return Err(in_header(format!(
            "text after the dict: {}",
            clip(&text[p.at..])
        )));
    }
    let Lit::Dict(items) = dict else {
        return Err(in_header(format!(
            "{} is not a Python dict: {KEYS}",
            clip(&dict_text)
        )));
    };
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    for ((key, key_text), value) in items {
        let slot = match &key {
            Lit::Str(k) if k == "descr" => &mut descr,
            Lit::Str(k) if k == "fortran_order" => &mut fortran,
            Lit::Str(k) if k == "shape" => &mut shape,
            _ => {
                return Err(in_header(format!(
                    "unexpected key {}: {KEYS}",
                    clip(&key_text)
                )))
            }
        };
        if slot.replace(value).is_some() {
            return Err(in_header(format!(
                "the key {key_text} is given twice: {KEYS}"
            )));
        }
    }
    let missing = |key: &str| in_header(format!("the header has no '{key}' key: {KEYS}"));
    let descr = match descr.ok_or_else(|| missing("descr"))? {
        (Lit::Str(s), _) => s,
        // A structured dtype: kept as written, so that the reader can say what it found.
        (Lit::List(_), text) => text,
        (_, text) => {
            return Err(in_header(format!(
                "'descr' is {}: a dtype string such as '<f4' is accepted",
                clip(&text)
            )))
        }
    };
    let fortran_order = match fortran.ok_or_else(|| missing("fortran_order"))? {
        (Lit::Bool(b), _) => b,
        (_, text) => {
            return Err(in_header(format!(
                "'fortran_order' is {}: True or False is accepted",
                clip(&text)
            )))
        }
    };
    let (entries, shape_text) = match shape.ok_or_else(|| missing("shape"))? {
        // `(2)` is an int in Python, but is read as `(2,)` here, as this reader always has.
        (Lit::Tuple(entries), text) => (entries, text),
        (_, text) => {
            return Err(in_header(format!(
                "'shape' is {}: a tuple of sizes such as (1000,) is accepted",
                clip(&text)
            )))
        }
    };
    let shape = sizes(entries, &shape_text, &in_header)?;
    Ok((
        Header {
            descr,
            fortran_order,
            shape,
        },
        data,
    ))
}

/// The sizes of a shape tuple (`shape_text` as written), each a non-negative integer, whose
/// product fits in a `usize`.
fn sizes(
    entries: Vec<(Lit, String)>,
    shape_text: &str,
    in_header: &dyn Fn(String) -> crate::error::Error,
) -> Result<Vec<usize>> {
    let shape = entries
        .into_iter()
        .map(|(entry, text)| match entry {
            Lit::Int(n) if n.starts_with('-') => Err(in_header(format!(
                "shape {} has the negative size {n}",
                clip(shape_text)
            ))),
            Lit::Int(n) => n.parse::<usize>().map_err(|_| {
                in_header(format!(
                    "shape {}: the size {} does not fit in {} bits",
                    clip(shape_text),
                    clip(&n),
                    usize::BITS
                ))
            }),
            _ => Err(in_header(format!(
                "shape {}: the entry {} is not a size (a non-negative integer)",
                clip(shape_text),
                clip(&text)
            ))),
        })
        .collect::<Result<Vec<_>>>()?;
    if shape
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .is_none()
    {
        return Err(in_header(format!(
            "shape {} has more elements than a {}-bit count holds: the header is corrupt",
            clip(shape_text),
            usize::BITS
        )));
    }
    Ok(shape)
}
