//! NumPy `.npy` files (format version 1.0), so that `numpy.load("counts.npy")` gives a case's
//! histogram as an array in one line.
//!
//! The format (numpy's `numpy/lib/format.py`, "Format Version 1.0"): the magic `\x93NUMPY`, the
//! version bytes 1 and 0, the header length as a little-endian u16, then the header, an ASCII
//! Python dict literal `{'descr': '<u8', 'fortran_order': False, 'shape': (R, C), }` padded
//! with spaces and ended by `\n` so that the data starts at a multiple of 64 bytes; then the
//! data, C order (row-major), little-endian. A dependency (npyz, ndarray-npy) would bring a
//! Python-literal parser (pest) for these few lines.
//!
//! ```
//! use lobes::report::npy;
//! let bytes = npy::encode(&[2, 3], &[1u64, 2, 3, 4, 5, 6]);
//! assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
//! assert_eq!(bytes.len(), 128 + 6 * 8); // the data starts at a multiple of 64 bytes
//! let (shape, data) = npy::decode::<u64>(&bytes).unwrap();
//! assert_eq!((shape, data), (vec![2, 3], vec![1, 2, 3, 4, 5, 6]));
//! ```

const MAGIC: &[u8] = b"\x93NUMPY\x01\x00";
/// The data starts at a multiple of this many bytes (numpy aligns to 64).
const ALIGN: usize = 64;

/// An element type of an `.npy` array: its numpy `descr` and little-endian bytes.
pub trait Element: Copy {
    /// The numpy type string (`<u8`, `<f8`, `<f4`: little-endian, 8 or 4 bytes).
    const DESCR: &'static str;
    const SIZE: usize;
    fn write_le(self, out: &mut Vec<u8>);
    fn read_le(bytes: &[u8]) -> Self;
}

macro_rules! element {
    ($t:ty, $descr:literal) => {
        impl Element for $t {
            const DESCR: &'static str = $descr;
            const SIZE: usize = size_of::<$t>();
            fn write_le(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn read_le(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().expect("one element's bytes"))
            }
        }
    };
}
element!(u64, "<u8");
element!(f64, "<f8");
element!(f32, "<f4");

/// The header dict of an array of `T` with `shape`.
fn header<T: Element>(shape: &[usize]) -> String {
    // a 1-tuple needs its comma: (5,)
    let dims: String = shape.iter().map(|d| format!("{d}, ")).collect();
    let dims = if shape.len() == 1 { dims.trim_end().to_string() } else { dims.trim_end_matches(", ").to_string() };
    format!("{{'descr': '{}', 'fortran_order': False, 'shape': ({dims}), }}", T::DESCR)
}

/// An `.npy` file of `data` (row-major) with `shape`.
///
/// # Panics
/// If `data` does not have the product of `shape` elements.
pub fn encode<T: Element>(shape: &[usize], data: &[T]) -> Vec<u8> {
    assert_eq!(shape.iter().product::<usize>(), data.len(), "the shape {shape:?} does not hold {} elements", data.len());
    let mut head = header::<T>(shape);
    let unpadded = MAGIC.len() + 2 + head.len() + 1;
    head.extend(std::iter::repeat_n(' ', unpadded.next_multiple_of(ALIGN) - unpadded));
    head.push('\n');
    let mut out = Vec::with_capacity(MAGIC.len() + 2 + head.len() + data.len() * T::SIZE);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&u16::try_from(head.len()).expect("a short header").to_le_bytes());
    out.extend_from_slice(head.as_bytes());
    for &x in data {
        x.write_le(&mut out);
    }
    out
}

/// Why bytes are not an `.npy` file that [`decode`] reads.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("not a NumPy .npy file (version 1.0, C order, {expected}): {reason}")]
pub struct NpyError {
    expected: &'static str,
    reason: String,
}

/// Reads an `.npy` file of `T` that [`encode`] writes: its shape and data (row-major).
pub fn decode<T: Element>(bytes: &[u8]) -> Result<(Vec<usize>, Vec<T>), NpyError> {
    let bad = |reason: String| NpyError { expected: T::DESCR, reason };
    if !bytes.starts_with(MAGIC) || bytes.len() < MAGIC.len() + 2 {
        return Err(bad("no \\x93NUMPY v1.0 magic".into()));
    }
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let start = MAGIC.len() + 2 + len;
    let head = bytes.get(MAGIC.len() + 2..start).and_then(|h| std::str::from_utf8(h).ok()).ok_or_else(|| bad("the header is cut short".into()))?;
    let field = |key: &str, end: char| -> Result<&str, NpyError> {
        let at = head.find(&format!("'{key}': ")).ok_or_else(|| bad(format!("no '{key}' in the header {head:?}")))? + key.len() + 4;
        let rest = &head[at..];
        Ok(&rest[..rest.find(end).map_or(rest.len(), |e| e + 1)])
    };
    if field("descr", ',')? != format!("'{}',", T::DESCR) || field("fortran_order", ',')? != "False," {
        return Err(bad(format!("the header is {head:?}")));
    }
    let shape = field("shape", ')')?
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
        .map(|d| d.parse::<usize>().map_err(|e| bad(format!("shape dimension {d:?}: {e}"))))
        .collect::<Result<Vec<_>, _>>()?;
    let data = &bytes[start..];
    let n: usize = shape.iter().product();
    if data.len() != n * T::SIZE {
        return Err(bad(format!("{} data bytes for the shape {shape:?} of {n} elements", data.len())));
    }
    Ok((shape, data.chunks_exact(T::SIZE).map(T::read_le).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header bytes as numpy 1.26 writes them for `np.save(f, np.zeros((2, 3), '<u8'))`:
    /// the dict, padded with spaces to 118 characters and a newline (data at byte 128).
    #[test]
    fn the_header_is_numpys() {
        let bytes = encode(&[2, 3], &[0u64; 6]);
        assert_eq!(u16::from_le_bytes([bytes[8], bytes[9]]), 118);
        let head = std::str::from_utf8(&bytes[10..128]).unwrap();
        assert!(head.starts_with("{'descr': '<u8', 'fortran_order': False, 'shape': (2, 3), }"), "{head}");
        assert!(head.ends_with(" \n"));
        assert_eq!(bytes.len(), 128 + 48);
        assert_eq!(header::<f64>(&[5]), "{'descr': '<f8', 'fortran_order': False, 'shape': (5,), }");
        assert_eq!(header::<f32>(&[32, 32, 2]), "{'descr': '<f4', 'fortran_order': False, 'shape': (32, 32, 2), }");
    }

    #[test]
    fn arrays_read_back_and_wrong_types_are_refused() {
        let x = [0.5f64, -1.0, f64::MAX, 1e-300];
        let bytes = encode(&[4, 1], &x);
        assert_eq!(bytes.len() % 8, 0);
        assert_eq!(&bytes[bytes.len() - 8..], &1e-300f64.to_le_bytes());
        assert_eq!(decode::<f64>(&bytes).unwrap(), (vec![4, 1], x.to_vec()));
        assert_eq!(decode::<f32>(&encode(&[3], &[1f32, 2.0, 3.0])).unwrap(), (vec![3], vec![1.0, 2.0, 3.0]));
        assert!(decode::<u64>(&bytes).unwrap_err().to_string().contains("'<f8'"));
        assert!(decode::<f64>(&bytes[..bytes.len() - 1]).is_err());
        assert!(decode::<f64>(b"PK\x03\x04").is_err());
    }
}
