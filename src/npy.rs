//! Reading and writing 1-D NumPy `.npy` arrays (format versions 1 to 3, little-endian), so that
//! keys and results can be exchanged with other tools.

use std::fs;
use std::path::Path;

use crate::error::{Error, Result};

const MAGIC: &[u8] = b"\x93NUMPY";

fn bad(path: &Path, msg: impl std::fmt::Display) -> Error {
    Error::InvalidInput(format!("{}: {msg}", path.display()))
}

/// The dtype and shape of an array's header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    /// NumPy's type string, e.g. `<f4`.
    pub descr: String,
    /// Whether the data is in Fortran order.
    pub fortran_order: bool,
    /// The shape.
    pub shape: Vec<usize>,
}

fn field<'a>(dict: &'a str, key: &str) -> Option<&'a str> {
    let at = dict.find(&format!("'{key}'"))?;
    let rest = &dict[at + key.len() + 2..];
    Some(rest.trim_start().strip_prefix(':')?.trim_start())
}

/// Parses an `.npy` file's bytes into its header and the offset of the data.
pub fn parse_header(path: &Path, bytes: &[u8]) -> Result<(Header, usize)> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(bad(
            path,
            "not a .npy file (no \\x93NUMPY magic): save the keys with numpy.save",
        ));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(bad(path, format!("unsupported .npy format version {v}"))),
    };
    let dict = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| bad(path, "truncated or unreadable .npy header"))?;
    let descr = field(dict, "descr")
        .and_then(|r| r.strip_prefix('\''))
        .and_then(|r| r.split('\'').next())
        .ok_or_else(|| bad(path, "the .npy header has no descr"))?
        .to_owned();
    let fortran_order = field(dict, "fortran_order").is_some_and(|r| r.starts_with("True"));
    let shape_text = field(dict, "shape")
        .and_then(|r| r.strip_prefix('('))
        .and_then(|r| r.split(')').next())
        .ok_or_else(|| bad(path, "the .npy header has no shape"))?;
    let shape = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<usize>()
                .map_err(|_| bad(path, format!("bad shape entry `{s}`")))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((
        Header {
            descr,
            fortran_order,
            shape,
        },
        start + len,
    ))
}

fn read_1d(path: &Path, dtypes: &[&str], what: &str) -> Result<(String, Vec<u8>)> {
    let bytes = fs::read(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    let (h, data) = parse_header(path, &bytes)?;
    if !dtypes.contains(&h.descr.as_str()) {
        return Err(bad(
            path,
            format!(
                "dtype {} is not {what}: convert with arr.astype(...) before saving",
                h.descr
            ),
        ));
    }
    if h.shape.len() != 1 {
        return Err(bad(
            path,
            format!("shape {:?} is not 1-D: flatten with arr.ravel()", h.shape),
        ));
    }
    let n = h.shape[0];
    if n == 0 {
        return Err(bad(path, "the array is empty: there is nothing to sort"));
    }
    let body = &bytes[data..];
    if body.len() < 4 * n {
        return Err(bad(
            path,
            format!(
                "the file holds {} bytes of data, shape ({n},) needs {}",
                body.len(),
                4 * n
            ),
        ));
    }
    Ok((h.descr, body[..4 * n].to_vec()))
}

/// Reads a 1-D little-endian float32 array.
pub fn read_f32(path: &Path) -> Result<Vec<f32>> {
    let (_, body) = read_1d(path, &["<f4"], "float32 (<f4)")?;
    Ok(body
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// Reads a little-endian float32 array of any shape (C order), e.g. a state dump (N×4).
pub fn read_f32_shaped(path: &Path) -> Result<(Vec<usize>, Vec<f32>)> {
    let bytes = fs::read(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    let (h, data) = parse_header(path, &bytes)?;
    if h.descr != "<f4" || h.fortran_order {
        return Err(bad(
            path,
            format!("dtype {} is not C-order float32 (<f4)", h.descr),
        ));
    }
    let n: usize = h.shape.iter().product();
    let body = &bytes[data..];
    if body.len() < 4 * n {
        return Err(bad(
            path,
            format!(
                "the file holds {} bytes of data, shape {:?} needs {}",
                body.len(),
                h.shape,
                4 * n
            ),
        ));
    }
    let v = body[..4 * n]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    Ok((h.shape, v))
}

/// Reads a 1-D little-endian int32 or uint32 array as u32 (negative int32 values are an error).
pub fn read_u32(path: &Path) -> Result<Vec<u32>> {
    let (descr, body) = read_1d(path, &["<i4", "<u4"], "int32 or uint32 (<i4, <u4)")?;
    let v: Vec<u32> = body
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if descr == "<i4" && v.iter().any(|&x| x > i32::MAX as u32) {
        return Err(bad(path, "negative ids are not indices"));
    }
    Ok(v)
}

fn encode(descr: &str, shape: &[usize], data: &[u8]) -> Vec<u8> {
    let dims = match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {dims}, }}");
    // Pad so that the data starts on a multiple of 64 bytes, ending the header with a newline.
    let total = MAGIC.len() + 4 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::output::write_atomic(path, bytes)
}

/// The bytes of a .npy file holding a float32 array of `shape` (row-major).
pub fn encode_f32(shape: &[usize], v: &[f32]) -> Vec<u8> {
    let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    encode("<f4", shape, &data)
}

/// The bytes of a .npy file holding a 1-D int32 array.
pub fn encode_i32(v: &[i32]) -> Vec<u8> {
    let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    encode("<i4", &[v.len()], &data)
}

/// Writes a 1-D float32 array (through a temporary file and a rename).
pub fn write_f32(path: &Path, v: &[f32]) -> Result<()> {
    let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    write_atomic(path, &encode("<f4", &[v.len()], &data))
}

/// Writes a 1-D int32 array.
pub fn write_i32(path: &Path, v: &[i32]) -> Result<()> {
    let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    write_atomic(path, &encode("<i4", &[v.len()], &data))
}

/// Writes a float32 array of any shape (row-major), e.g. N×4 state dumps.
pub fn write_f32_shaped(path: &Path, shape: &[usize], v: &[f32]) -> Result<()> {
    let data: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    write_atomic(path, &encode("<f4", shape, &data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_aligns() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.npy");
        let v = vec![1.5f32, -0.0, f32::INFINITY, 3.0];
        write_f32(&p, &v).unwrap();
        let bytes = fs::read(&p).unwrap();
        assert_eq!(
            (bytes.len() - 16) % 64,
            0,
            "data starts on a 64-byte boundary"
        );
        let back = read_f32(&p).unwrap();
        assert_eq!(
            back.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
        let q = dir.path().join("i.npy");
        write_i32(&q, &[0, 5, 7]).unwrap();
        assert_eq!(read_u32(&q).unwrap(), vec![0, 5, 7]);
        let r = dir.path().join("r.npy");
        write_f32_shaped(&r, &[2, 4], &[0.0; 8]).unwrap();
        let (h, off) = parse_header(&r, &fs::read(&r).unwrap()).unwrap();
        assert_eq!(
            (h.shape, h.descr.as_str(), off % 64),
            (vec![2, 4], "<f4", 0)
        );
    }

    #[test]
    fn reads_what_numpy_writes() {
        // numpy.save(np.array([1, 2], dtype=np.float32)) with numpy 1.x: version 1.0 header.
        let mut b =
            b"\x93NUMPY\x01\x00v\x00{'descr': '<f4', 'fortran_order': False, 'shape': (2,), }"
                .to_vec();
        b.resize(10 + 0x76 - 1, b' ');
        b.push(b'\n');
        b.extend_from_slice(&1f32.to_le_bytes());
        b.extend_from_slice(&2f32.to_le_bytes());
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("n.npy");
        fs::write(&p, &b).unwrap();
        assert_eq!(read_f32(&p).unwrap(), vec![1.0, 2.0]);
    }

    #[test]
    fn bad_files_get_clear_errors() {
        let dir = tempfile::tempdir().unwrap();
        let check = |name: &str, bytes: &[u8], needle: &str| {
            let p = dir.path().join(name);
            fs::write(&p, bytes).unwrap();
            let msg = read_f32(&p).unwrap_err().to_string();
            assert!(msg.contains(needle), "{name}: {msg}");
        };
        check("text.npy", b"1,2,3\n", "not a .npy file");
        let f64s = encode("<f8", &[1], &1f64.to_le_bytes());
        check("f64.npy", &f64s, "dtype <f8 is not float32");
        check("empty.npy", &encode("<f4", &[0], &[]), "empty");
        let mut two_d = encode("<f4", &[2], &[0; 8]);
        let at = two_d.windows(4).position(|w| w == b"(2,)").unwrap();
        two_d.splice(at..at + 4, b"(1,2)".iter().copied());
        check("2d.npy", &two_d, "not 1-D");
        let missing = read_f32(&dir.path().join("nope.npy")).unwrap_err();
        assert!(matches!(missing, Error::Io { .. }));
    }
}
