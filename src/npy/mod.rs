//! Reading and writing 1-D NumPy `.npy` arrays (format versions 1 to 3, little-endian), so that
//! keys and results can be exchanged with other tools.
//!
//! Every file is read whole and checked before a value is taken from it: the header must be
//! well formed (see [`parse_header`]), the dtype and the order the ones the reader accepts, and
//! the data exactly as long as the shape declares. Anything else is an
//! [`Error::InvalidInput`] that names what was found and what is accepted.

use std::path::Path;

use crate::error::{Error, Result};

mod header;

pub use header::{parse_header, Header};

const MAGIC: &[u8] = b"\x93NUMPY";

fn bad(path: &Path, msg: impl std::fmt::Display) -> Error {
    Error::InvalidInput(format!("{}: {msg}", path.display()))
}

fn read_file(path: &Path) -> Result<Vec<u8>> {
    use crate::input::{read_bounded, Refused, MAX_NPY_BYTES};
    read_bounded(path, MAX_NPY_BYTES).map_err(|r| match r {
        Refused::Io(source) => Error::Io {
            path: path.to_owned(),
            source,
        },
        r => bad(path, r),
    })
}

/// The message for a dtype the reader does not take: what it is, what is accepted, and how
/// to convert (`what` names the accepted dtypes, `to` is the one to convert to).
fn wrong_dtype(descr: &str, what: &str, to: &str) -> String {
    let why = if descr.starts_with('[') {
        format!(
            "it is a structured dtype (named fields); save one field as a plain array, e.g. arr['name'].astype('{to}')"
        )
    } else if descr.starts_with('>') {
        format!("it is big-endian; convert with arr.astype('{to}') before saving")
    } else {
        "convert with arr.astype(...) before saving".to_owned()
    };
    format!("dtype {descr} is not {what}: {why}")
}

/// The data of a header with `itemsize`-byte elements: exactly as many bytes as the shape
/// declares, or an error.
fn data<'b>(path: &Path, h: &Header, body: &'b [u8], itemsize: usize) -> Result<&'b [u8]> {
    let shape = match h.shape.as_slice() {
        [n] => format!("({n},)"),
        s => format!("{s:?}"),
    };
    // parse_header checked the element count; the byte count can still overflow.
    let want = h.elements().checked_mul(itemsize).ok_or_else(|| {
        bad(
            path,
            format!(
                "shape {shape} of {} needs more bytes than a {}-bit size holds: the header is corrupt",
                h.descr,
                usize::BITS
            ),
        )
    })?;
    if body.len() != want {
        return Err(bad(
            path,
            format!(
                "the file holds {} bytes of data, shape {shape} of {} needs exactly {want}",
                body.len(),
                h.descr
            ),
        ));
    }
    Ok(body)
}

/// The 4-byte little-endian elements of a 1-D array of one of `dtypes`.
fn decode_1d<'b>(
    path: &Path,
    bytes: &'b [u8],
    dtypes: &[&str],
    what: &str,
) -> Result<(String, &'b [u8])> {
    let (h, at) = parse_header(path, bytes)?;
    if !dtypes.contains(&h.descr.as_str()) {
        return Err(bad(path, wrong_dtype(&h.descr, what, dtypes[0])));
    }
    // Fortran order is accepted: a 1-D array has the same bytes in either order.
    if h.shape.len() != 1 {
        return Err(bad(
            path,
            format!("shape {:?} is not 1-D: flatten with arr.ravel()", h.shape),
        ));
    }
    if h.shape[0] == 0 {
        return Err(bad(path, "the array is empty: there is nothing to sort"));
    }
    let body = data(path, &h, &bytes[at..], 4)?;
    Ok((h.descr, body))
}

fn f32s(body: &[u8]) -> Vec<f32> {
    body.chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Decodes the bytes of a 1-D little-endian float32 `.npy` file; `path` names it in errors.
pub fn decode_f32(path: &Path, bytes: &[u8]) -> Result<Vec<f32>> {
    let (_, body) = decode_1d(path, bytes, &["<f4"], "float32 (<f4)")?;
    Ok(f32s(body))
}

/// Reads a 1-D little-endian float32 array.
pub fn read_f32(path: &Path) -> Result<Vec<f32>> {
    decode_f32(path, &read_file(path)?)
}

/// Decodes the bytes of a little-endian float32 `.npy` file of any shape (C order); `path`
/// names it in errors.
pub fn decode_f32_shaped(path: &Path, bytes: &[u8]) -> Result<(Vec<usize>, Vec<f32>)> {
    let (h, at) = parse_header(path, bytes)?;
    if h.descr != "<f4" {
        return Err(bad(
            path,
            wrong_dtype(&h.descr, "C-order float32 (<f4)", "<f4"),
        ));
    }
    if h.fortran_order {
        return Err(bad(
            path,
            format!(
                "the array (shape {:?}) is in Fortran order, C order is accepted: save numpy.ascontiguousarray(arr)",
                h.shape
            ),
        ));
    }
    let v = f32s(data(path, &h, &bytes[at..], 4)?);
    Ok((h.shape, v))
}

/// Reads a little-endian float32 array of any shape (C order), e.g. a state dump (N×4).
pub fn read_f32_shaped(path: &Path) -> Result<(Vec<usize>, Vec<f32>)> {
    decode_f32_shaped(path, &read_file(path)?)
}

/// Decodes the bytes of a 1-D little-endian int32 or uint32 `.npy` file as u32 (negative int32
/// values are an error); `path` names it in errors.
pub fn decode_u32(path: &Path, bytes: &[u8]) -> Result<Vec<u32>> {
    let (descr, body) = decode_1d(path, bytes, &["<i4", "<u4"], "int32 or uint32 (<i4, <u4)")?;
    let v: Vec<u32> = body
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if descr == "<i4" && v.iter().any(|&x| x > i32::MAX as u32) {
        return Err(bad(path, "negative ids are not indices"));
    }
    Ok(v)
}

/// Reads a 1-D little-endian int32 or uint32 array as u32 (negative int32 values are an error).
pub fn read_u32(path: &Path) -> Result<Vec<u32>> {
    decode_u32(path, &read_file(path)?)
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
    // Exclusive temporary file with an unpredictable name, then a rename (src/output).
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
mod proptests;
#[cfg(test)]
mod tests;
