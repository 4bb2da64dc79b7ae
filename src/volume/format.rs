//! What every volume reader shares about a file's format: the scalar types and their names, the raw spec,
//! sizes and the size-mismatch message, header numbers and fields, the
//! geometry of a direction matrix, and reading files (recorded for
//! [`load_with_files`]). The samples themselves are decoded in `decode.rs`.

use std::path::{Path, PathBuf};
use std::str::FromStr;

use super::Volume;
use crate::error::{Error, Result};

/// A scalar type a volume file can store. Every one converts to `f32`
/// (integers above 2^24 round to the nearest `f32`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScalarType {
    /// Unsigned 8-bit integer.
    U8,
    /// Signed 8-bit integer.
    I8,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 32-bit integer.
    U32,
    /// Signed 32-bit integer.
    I32,
    /// 32-bit IEEE float.
    F32,
    /// 64-bit IEEE float.
    F64,
}

impl ScalarType {
    /// Size of one value in bytes.
    pub fn size(self) -> usize {
        match self {
            ScalarType::U8 | ScalarType::I8 => 1,
            ScalarType::U16 | ScalarType::I16 => 2,
            ScalarType::U32 | ScalarType::I32 | ScalarType::F32 => 4,
            ScalarType::F64 => 8,
        }
    }

    /// The short name (`u8`, `i16`, `f32`, ...), as [`FromStr`] accepts it.
    pub fn name(self) -> &'static str {
        match self {
            ScalarType::U8 => "u8",
            ScalarType::I8 => "i8",
            ScalarType::U16 => "u16",
            ScalarType::I16 => "i16",
            ScalarType::U32 => "u32",
            ScalarType::I32 => "i32",
            ScalarType::F32 => "f32",
            ScalarType::F64 => "f64",
        }
    }
}

impl std::fmt::Display for ScalarType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ScalarType {
    type Err = Error;

    /// Parses a scalar type name, case-insensitively, in the spellings of
    /// Rust (`u8`, `f32`), C (`unsigned char`, `short`, `float`, `double`),
    /// `<stdint.h>` (`uint16_t`), NRRD (`uchar`, `ushort`, `signed char`),
    /// VTK legacy (`unsigned_short`), VTK XML (`UInt16`, `Float32`) and
    /// MetaImage without its prefix (`ushort`). Plain `char` is signed, as in
    /// VTK.
    fn from_str(s: &str) -> Result<Self> {
        // One spelling per form: lower case, '_' as ' ', single spaces.
        let norm = s
            .to_ascii_lowercase()
            .replace('_', " ")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        let norm = norm.strip_suffix(" t").unwrap_or(&norm);
        Ok(match norm {
            "u8" | "uint8" | "uchar" | "unsigned char" | "unsigned int8" | "byte" => ScalarType::U8,
            "i8" | "int8" | "char" | "signed char" | "schar" => ScalarType::I8,
            "u16" | "uint16" | "ushort" | "unsigned short" | "unsigned short int" => {
                ScalarType::U16
            }
            "i16" | "int16" | "short" | "short int" | "signed short" | "signed short int" => {
                ScalarType::I16
            }
            "u32" | "uint32" | "uint" | "unsigned" | "unsigned int" => ScalarType::U32,
            "i32" | "int32" | "int" | "signed int" | "signed" => ScalarType::I32,
            "f32" | "float" | "float32" | "single" => ScalarType::F32,
            "f64" | "double" | "float64" => ScalarType::F64,
            _ => {
                let hint = if ["64", "long", "block", "bit"]
                    .iter()
                    .any(|k| norm.contains(k))
                {
                    " (64-bit integer, bit and block types are not supported)"
                } else {
                    ""
                };
                return Err(Error::InvalidArgument(format!(
                    "unknown scalar type '{s}'{hint}: expected u8, i8, u16, i16, u32, i32, \
                     f32 or f64 (or a C, NRRD or VTK spelling such as uchar, short, float)"
                )));
            }
        })
    }
}

/// How to read a headerless (raw) volume file.
#[derive(Clone, Debug)]
pub struct RawSpec {
    /// Number of samples along x, y and z; x varies fastest in the file.
    pub dims: [usize; 3],
    /// The type of each sample.
    pub scalar: ScalarType,
    /// Multi-byte values are big-endian (most significant byte first).
    pub big_endian: bool,
    /// World units per voxel step.
    pub spacing: [f64; 3],
    /// World position of the first sample.
    pub origin: [f64; 3],
    /// Bytes to skip at the start of the file.
    pub header_bytes: usize,
}

impl RawSpec {
    /// A little-endian spec without a header, with spacing 1 and origin 0.
    pub fn new(dims: [usize; 3], scalar: ScalarType) -> RawSpec {
        RawSpec {
            dims,
            scalar,
            big_endian: false,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            header_bytes: 0,
        }
    }
}

thread_local! {
    /// The files [`read_file`] read while `load_with_files` records them.
    pub(super) static READ: std::cell::RefCell<Option<Vec<PathBuf>>> = const { std::cell::RefCell::new(None) };
}

/// Reads a whole file, naming it in the error.
pub(super) fn read_file(path: &Path) -> Result<Vec<u8>> {
    record_read(path);
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Notes `path` as read while [`load_with_files`] records.
pub(super) fn record_read(path: &Path) {
    READ.with(|r| {
        if let Some(files) = r.borrow_mut().as_mut() {
            files.push(path.to_path_buf());
        }
    });
}

/// Opens a file to read part of it, naming it in the error; returns the
/// reader and the file's size (from its metadata, before reading).
pub(super) fn open_file(path: &Path) -> Result<(std::io::BufReader<std::fs::File>, u64)> {
    record_read(path);
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let size = file.metadata().map_err(io)?.len();
    Ok((std::io::BufReader::new(file), size))
}

/// Reads past one newline-terminated line of `r`, keeping nothing; the
/// bytes it took, or `None` when the stream ends first.
pub(super) fn skip_line(r: &mut impl std::io::BufRead) -> std::io::Result<Option<u64>> {
    let mut taken = 0u64;
    loop {
        let buf = r.fill_buf()?;
        if buf.is_empty() {
            return Ok(None);
        }
        match buf.iter().position(|&b| b == b'\n') {
            Some(i) => {
                r.consume(i + 1);
                return Ok(Some(taken + i as u64 + 1));
            }
            None => {
                let n = buf.len();
                r.consume(n);
                taken += n as u64;
            }
        }
    }
}

/// `X×Y×Z` for messages.
pub(super) fn dims_text(dims: [usize; 3]) -> String {
    format!("{}×{}×{}", dims[0], dims[1], dims[2])
}

/// The number of samples of a grid: every dimension at least 1, no overflow.
pub(super) fn voxel_count(dims: [usize; 3], source: &str, element: &str) -> Result<usize> {
    if dims.contains(&0) {
        return Err(Error::input(
            source,
            element,
            format!(
                "grid {}: every dimension must be at least 1",
                dims_text(dims)
            ),
        ));
    }
    dims.iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .ok_or_else(|| {
            Error::input(
                source,
                element,
                format!("grid {} has too many samples", dims_text(dims)),
            )
        })
}

/// The number of bytes of `count` values of `scalar`, without overflow.
pub(super) fn byte_count(
    count: usize,
    scalar: ScalarType,
    source: &str,
    element: &str,
) -> Result<usize> {
    count.checked_mul(scalar.size()).ok_or_else(|| {
        Error::input(
            source,
            element,
            format!("{count} values of {scalar} do not fit in memory"),
        )
    })
}

/// The size-mismatch message every loader uses:
/// `expected N bytes (X×Y×Z × T bytes), found M`. `shape` is the grid (or
/// slab) the bytes hold.
pub(super) fn size_problem(shape: &[usize], scalar: ScalarType, found: usize) -> String {
    let count: usize = shape.iter().product();
    let shape = shape
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join("×");
    format!(
        "expected {} bytes ({shape} × {} bytes), found {found}",
        count * scalar.size(),
        scalar.size()
    )
}

/// The rest of `bytes` after `n` newline-terminated lines, or `None` when
/// there are fewer lines.
pub(super) fn skip_lines(bytes: &[u8], n: usize) -> Option<&[u8]> {
    let mut rest = bytes;
    for _ in 0..n {
        let nl = rest.iter().position(|&b| b == b'\n')?;
        rest = &rest[nl + 1..];
    }
    Some(rest)
}

/// Splits `bytes` into lines (without `\n` or `\r\n`), each with the offset
/// of the byte after it (where the next line starts).
pub(super) fn lines_with_end(bytes: &[u8]) -> impl Iterator<Item = (&[u8], usize)> {
    let mut pos = 0;
    std::iter::from_fn(move || {
        if pos >= bytes.len() {
            return None;
        }
        let rest = &bytes[pos..];
        let (line, next) = match rest.iter().position(|&b| b == b'\n') {
            Some(nl) => (&rest[..nl], pos + nl + 1),
            None => (rest, bytes.len()),
        };
        pos = next;
        Some((line.strip_suffix(b"\r").unwrap_or(line), next))
    })
}

/// The per-axis steps of a direction matrix whose rows are the axis
/// vectors, when it is diagonal (off-diagonal entries below 1e-9 of the
/// largest entry); `None` when the grid is rotated or sheared.
pub(super) fn diagonal(axes: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let scale = axes.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let off_diagonal_zero = (0..3)
        .flat_map(|i| (0..3).filter(move |&j| j != i).map(move |j| (i, j)))
        .all(|(i, j)| axes[i][j].abs() <= 1e-9 * scale);
    off_diagonal_zero.then(|| std::array::from_fn(|i| axes[i][i]))
}

/// Builds a volume from samples with per-axis steps that may be negative:
/// such an axis is reversed (and its origin moved to the other end) so that
/// the spacing is positive and every sample keeps its world position.
pub(super) fn oriented(
    dims: [usize; 3],
    values: Vec<f32>,
    steps: [f64; 3],
    mut origin: [f64; 3],
    source: &str,
) -> Result<Volume> {
    let geometry_err = |what: &str, v: [f64; 3]| {
        Error::input(
            source,
            "geometry",
            format!(
                "{what} ({}) must be finite and non-zero",
                crate::error::values(v, ", ")
            ),
        )
    };
    if !steps.iter().all(|s| s.is_finite() && *s != 0.0) {
        return Err(geometry_err("spacing", steps));
    }
    if !origin.iter().all(|o| o.is_finite()) {
        return Err(geometry_err("origin", origin));
    }
    // Checks the dimensions against the values before indexing with them.
    let mut values = Volume::new(dims, values, source)?.values;
    let [nx, ny, nz] = dims;
    let mut spacing = steps;
    for axis in 0..3 {
        if steps[axis] > 0.0 {
            continue;
        }
        origin[axis] += steps[axis] * (dims[axis] - 1) as f64;
        spacing[axis] = -steps[axis];
        match axis {
            0 => values.chunks_exact_mut(nx).for_each(<[f32]>::reverse),
            1 => {
                for slab in values.chunks_exact_mut(nx * ny) {
                    for y in 0..ny / 2 {
                        let (a, b) = slab.split_at_mut((ny - 1 - y) * nx);
                        a[y * nx..(y + 1) * nx].swap_with_slice(&mut b[..nx]);
                    }
                }
            }
            _ => {
                let plane = nx * ny;
                for z in 0..nz / 2 {
                    let (a, b) = values.split_at_mut((nz - 1 - z) * plane);
                    a[z * plane..(z + 1) * plane].swap_with_slice(&mut b[..plane]);
                }
            }
        }
    }
    Volume::new(dims, values, source)?
        .with_geometry(spacing, origin)
        .map_err(|e| Error::input(source, "geometry", e.to_string()))
}

/// Parses a scalar type named in a header.
pub(super) fn scalar_type(value: &str, source: &str, element: &str) -> Result<ScalarType> {
    value.parse().map_err(|e| match e {
        Error::InvalidArgument(problem) => Error::input(source, element, problem),
        other => other,
    })
}

/// Parses one header number, naming the element and the field in the error.
pub(super) fn number<T: FromStr>(tok: &str, what: &str, source: &str, element: &str) -> Result<T> {
    tok.trim().parse::<T>().map_err(|_| {
        Error::input(
            source,
            element,
            format!("{what}: '{tok}' is not a valid number"),
        )
    })
}

/// Parses exactly `N` whitespace-separated numbers.
pub(super) fn numbers<T: FromStr + Copy + Default, const N: usize>(
    value: &str,
    what: &str,
    source: &str,
    element: &str,
) -> Result<[T; N]> {
    let toks: Vec<&str> = value.split_whitespace().collect();
    if toks.len() != N {
        return Err(Error::input(
            source,
            element,
            format!(
                "{what}: expected {N} values, found {} ('{value}')",
                toks.len()
            ),
        ));
    }
    let mut out = [T::default(); N];
    for (o, t) in out.iter_mut().zip(&toks) {
        *o = number(t, what, source, element)?;
    }
    Ok(out)
}

/// Parses the number of dimensions a header declares (`field`), which must
/// be 3: other counts are valid input that shapecue does not read.
pub(super) fn dimension(value: &str, field: &str, path: &Path, element: &str) -> Result<usize> {
    let n: usize = number(value, field, &path.display().to_string(), element)?;
    if n != 3 {
        return Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("{field} {n}: shapecue reads 3-D volumes only"),
        });
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_type_spellings() {
        for (s, t) in [
            ("u8", ScalarType::U8),
            ("unsigned char", ScalarType::U8),
            ("UInt8", ScalarType::U8),
            ("uint8_t", ScalarType::U8),
            ("signed char", ScalarType::I8),
            ("short", ScalarType::I16),
            ("signed short int", ScalarType::I16),
            ("unsigned_short", ScalarType::U16),
            ("ushort", ScalarType::U16),
            ("Int32", ScalarType::I32),
            ("uint", ScalarType::U32),
            ("float", ScalarType::F32),
            ("Float64", ScalarType::F64),
            ("double", ScalarType::F64),
        ] {
            assert_eq!(s.parse::<ScalarType>().ok(), Some(t), "{s}");
            assert_eq!(t.name().parse::<ScalarType>().ok(), Some(t));
        }
        let e = "int64".parse::<ScalarType>().unwrap_err().to_string();
        assert!(e.contains("int64") && e.contains("64-bit"), "{e}");
        assert!("complex".parse::<ScalarType>().is_err());
    }

    #[test]
    fn negative_axes_are_flipped() {
        let values: Vec<f32> = (0..24).map(|v| v as f32).collect();
        let dims = [2, 3, 4];
        let v = oriented(dims, values.clone(), [-1.0, -2.0, -0.5], [0.0; 3], "t").unwrap();
        assert_eq!(v.spacing, [1.0, 2.0, 0.5]);
        assert_eq!(v.origin, [-1.0, -4.0, -1.5]);
        // Each sample keeps its world position.
        let orig = Volume::new(dims, values, "t").unwrap();
        for z in 0..4 {
            for y in 0..3 {
                for x in 0..2 {
                    let w = [-(x as f64), -2.0 * y as f64, -0.5 * z as f64];
                    let p = [
                        (w[0] - v.origin[0]) / v.spacing[0],
                        (w[1] - v.origin[1]) / v.spacing[1],
                        (w[2] - v.origin[2]) / v.spacing[2],
                    ];
                    let q = p.map(|c| c.round() as usize);
                    assert_eq!(v.value(q[0], q[1], q[2]), orig.value(x, y, z));
                }
            }
        }
        assert!(oriented(dims, vec![0.0; 24], [1.0, 0.0, 1.0], [0.0; 3], "t").is_err());
    }

    #[test]
    fn diagonal_matrices() {
        let m = [[2.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 3.0]];
        assert_eq!(diagonal(m), Some([2.0, -1.0, 3.0]));
        let r = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(diagonal(r), None);
    }
}
