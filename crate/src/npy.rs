//! Reading and writing NumPy `.npy` files (format versions 1–3, little-endian `f4`/`f8`/`i8`
//! and friends, C order), the exchange format of HumanML3D and of our exports.

use std::fmt;
use std::path::Path;

/// A dense n-dimensional array of numbers, C (row-major) order.
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray {
    /// Length of each axis.
    pub shape: Vec<usize>,
    /// All values, converted to `f64`.
    pub data: Vec<f64>,
}

/// Why a `.npy` file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error("not a .npy file (bad magic bytes)")]
    BadMagic,
    #[error("truncated .npy file")]
    Truncated,
    #[error("unsupported .npy header: {0}")]
    Header(String),
    #[error("unsupported dtype {0:?} (supported: little-endian f4, f8, i1..i8, u1..u8)")]
    Dtype(String),
    #[error("expected shape {expected}, found {found:?}")]
    Shape { expected: String, found: Vec<usize> },
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

impl NpyArray {
    /// An array of the given shape and values. Panics if the lengths disagree (a bug in the
    /// caller, never bad input).
    pub fn new(shape: Vec<usize>, data: Vec<f64>) -> NpyArray {
        assert_eq!(
            shape.iter().product::<usize>(),
            data.len(),
            "shape and data disagree"
        );
        NpyArray { shape, data }
    }

    /// Parses the bytes of a `.npy` file.
    pub fn from_bytes(bytes: &[u8]) -> Result<NpyArray, NpyError> {
        if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
            return Err(NpyError::BadMagic);
        }
        let major = bytes[6];
        let (header_len, start) = if major == 1 {
            (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10)
        } else {
            if bytes.len() < 12 {
                return Err(NpyError::Truncated);
            }
            (
                u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
                12,
            )
        };
        let header = bytes
            .get(start..start + header_len)
            .ok_or(NpyError::Truncated)?;
        let header = std::str::from_utf8(header).map_err(|e| NpyError::Header(e.to_string()))?;
        let descr = dict_value(header, "descr").ok_or_else(|| NpyError::Header(header.into()))?;
        let quote = descr.chars().next().unwrap_or('\'');
        let descr = descr[1..]
            .split(quote)
            .next()
            .unwrap_or_default()
            .to_string();
        let fortran =
            dict_value(header, "fortran_order").ok_or_else(|| NpyError::Header(header.into()))?;
        if fortran.starts_with("True") {
            return Err(NpyError::Header("Fortran order is not supported".into()));
        }
        let shape_text =
            dict_value(header, "shape").ok_or_else(|| NpyError::Header(header.into()))?;
        let inner = shape_text
            .trim()
            .strip_prefix('(')
            .and_then(|s| s.split(')').next())
            .ok_or_else(|| NpyError::Header(header.into()))?;
        let shape = inner
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(|s| {
                s.parse::<usize>()
                    .map_err(|_| NpyError::Header(header.into()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let count: usize = shape.iter().product();
        let body = &bytes[start + header_len..];
        let (size, read): (usize, fn(&[u8]) -> f64) = match descr.as_str() {
            "<f4" => (4, |b| f32::from_le_bytes(b.try_into().unwrap()) as f64),
            "<f8" => (8, |b| f64::from_le_bytes(b.try_into().unwrap())),
            "<i8" => (8, |b| i64::from_le_bytes(b.try_into().unwrap()) as f64),
            "<i4" => (4, |b| i32::from_le_bytes(b.try_into().unwrap()) as f64),
            "<i2" => (2, |b| i16::from_le_bytes(b.try_into().unwrap()) as f64),
            "|i1" => (1, |b| b[0] as i8 as f64),
            "<u8" => (8, |b| u64::from_le_bytes(b.try_into().unwrap()) as f64),
            "<u4" => (4, |b| u32::from_le_bytes(b.try_into().unwrap()) as f64),
            "<u2" => (2, |b| u16::from_le_bytes(b.try_into().unwrap()) as f64),
            "|u1" | "|b1" => (1, |b| b[0] as f64),
            other => return Err(NpyError::Dtype(other.into())),
        };
        let needed = count.checked_mul(size).ok_or(NpyError::Truncated)?;
        if body.len() < needed {
            return Err(NpyError::Truncated);
        }
        let data = body[..needed].chunks_exact(size).map(read).collect();
        Ok(NpyArray { shape, data })
    }

    /// Reads a `.npy` file.
    pub fn read(path: impl AsRef<Path>) -> Result<NpyArray, NpyError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|source| NpyError::Io {
            path: path.display().to_string(),
            source,
        })?;
        NpyArray::from_bytes(&bytes)
    }

    /// The file bytes, stored as little-endian `f4` (float32), as HumanML3D does.
    pub fn to_bytes_f32(&self) -> Vec<u8> {
        let mut out = header_bytes("<f4", &self.shape);
        out.reserve(self.data.len() * 4);
        for v in &self.data {
            out.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        out
    }

    /// Writes the array as a float32 `.npy` file.
    pub fn write_f32(&self, path: impl AsRef<Path>) -> Result<(), NpyError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_bytes_f32()).map_err(|source| NpyError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Fails with a clear message unless the array has `rank` axes and the given trailing
    /// axis lengths (`None` accepts any length).
    pub fn expect_shape(&self, expected: &[Option<usize>]) -> Result<(), NpyError> {
        let ok = self.shape.len() == expected.len()
            && self
                .shape
                .iter()
                .zip(expected)
                .all(|(s, e)| e.is_none_or(|e| e == *s));
        if ok {
            Ok(())
        } else {
            let text = expected
                .iter()
                .map(|e| e.map_or("N".to_string(), |v| v.to_string()))
                .collect::<Vec<_>>()
                .join(", ");
            Err(NpyError::Shape {
                expected: format!("({text})"),
                found: self.shape.clone(),
            })
        }
    }
}

impl fmt::Display for NpyArray {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "array of shape {:?}", self.shape)
    }
}

/// The raw text after `'key':` in a header dict, up to the end of the header.
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let pos = header
        .find(&format!("'{key}'"))
        .or_else(|| header.find(&format!("\"{key}\"")))?;
    let rest = &header[pos + key.len() + 2..];
    let colon = rest.find(':')?;
    Some(rest[colon + 1..].trim_start())
}

fn header_bytes(descr: &str, shape: &[usize]) -> Vec<u8> {
    let shape_text = match shape.len() {
        1 => format!("({},)", shape[0]),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut dict =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape_text}, }}");
    // Pad so that the data starts on a 64-byte boundary, as NumPy does.
    let total = 10 + dict.len() + 1;
    dict.push_str(&" ".repeat((64 - total % 64) % 64));
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_f32() {
        let a = NpyArray::new(vec![2, 3], vec![0.5, -1.0, 2.0, 3.25, 4.0, 5.0]);
        let bytes = a.to_bytes_f32();
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0, "NumPy aligns the data start");
        assert_eq!(NpyArray::from_bytes(&bytes).unwrap(), a);
    }

    #[test]
    fn one_dimensional_shape_has_trailing_comma() {
        let a = NpyArray::new(vec![3], vec![1.0, 2.0, 3.0]);
        let bytes = a.to_bytes_f32();
        let text = String::from_utf8_lossy(&bytes[10..]);
        assert!(text.contains("(3,)"));
        assert_eq!(NpyArray::from_bytes(&bytes).unwrap().shape, vec![3]);
    }

    #[test]
    fn rejects_garbage_and_truncation() {
        assert!(matches!(
            NpyArray::from_bytes(b"hello world"),
            Err(NpyError::BadMagic)
        ));
        let bytes = NpyArray::new(vec![4], vec![1.0; 4]).to_bytes_f32();
        assert!(matches!(
            NpyArray::from_bytes(&bytes[..bytes.len() - 1]),
            Err(NpyError::Truncated)
        ));
    }

    #[test]
    fn shape_check_names_the_problem() {
        let a = NpyArray::new(vec![2, 5], vec![0.0; 10]);
        assert!(a.expect_shape(&[None, Some(5)]).is_ok());
        let err = a.expect_shape(&[None, Some(263)]).unwrap_err().to_string();
        assert!(err.contains("(N, 263)") && err.contains("[2, 5]"), "{err}");
    }
}
