//! Scalar volumes on a regular grid: the input of the isosurface stage
//! (`marching_cubes`) and of the SDF line stage.
//!
//! A [`Volume`] is a dense `f32` grid, x fastest, with an axis-aligned
//! geometry (spacing and origin). Every loader converts the file's scalar type
//! to `f32` in one bulk pass over the bytes, so a binary file loads at about
//! the speed it is read.
//!
//! Formats, one file each: headerless raw ([`RawSpec`]), NRRD (`.nrrd`,
//! `.nhdr`), MetaImage (`.mhd`, `.mha`), VTK legacy `STRUCTURED_POINTS`
//! (`.vtk`) and VTK XML ImageData (`.vti`) in `vtk.rs`, and SLC (`.slc`).
//! Procedural signed distance fields with analytic curvature are in [`sdf`].
//!
//! All parsers are hand-written and strict about what they use: no NRRD crate
//! exists, and the VTK crate (`vtkio`) is a pre-release whose errors carry no
//! file or element context. Bad input never panics; it is an
//! [`Error::InvalidInput`] naming the file, the element (`header line 4`,
//! `data file quarter.7`, ...) and the problem, an [`Error::Io`] naming a file
//! that cannot be read, or an [`Error::UnsupportedFormat`] for valid input
//! that shapecue does not read (a sheared grid, a 64-bit integer type, ...).
//!
//! Memory is bounded by the file: a header's sizes are checked against the
//! bytes before anything is allocated, compressed data are inflated no
//! further than the header calls for, and the binary detached data files of
//! NRRD and MetaImage headers are sized from their metadata and read as a
//! stream (only the bytes to skip and the samples), so a data file much
//! larger than its header says is refused unread.
//!
//! Grids whose axes point the negative way (a negative spacing, or a
//! direction matrix with `-1` on its diagonal) are flipped on load so that
//! spacing is always positive and every sample keeps its world position.

mod data_files;
mod mhd;
mod nrrd;
mod raw;
pub mod sdf;
mod slc;
mod vtk;

use std::borrow::Cow;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::error::{Error, Result};

/// A scalar volume on a regular grid.
///
/// Sample `(x, y, z)` is `values[x + nx*(y + ny*z)]` (x fastest) and lies at
/// world position `origin + spacing * (x, y, z)`.
#[derive(Clone, Debug)]
pub struct Volume {
    /// Number of samples along x, y and z (each at least 1).
    pub dims: [usize; 3],
    /// World units per voxel step along each axis (finite, > 0).
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// The samples, converted from the file's scalar type; NaN is allowed.
    pub values: Vec<f32>,
}

impl Volume {
    /// A volume with spacing 1 and origin 0.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidInput`] (naming `source`) when a dimension is 0, the
    /// product of the dimensions overflows, or `values` does not hold exactly
    /// that many samples.
    pub fn new(dims: [usize; 3], values: Vec<f32>, source: &str) -> Result<Volume> {
        let n = voxel_count(dims, source, "dimensions")?;
        if values.len() != n {
            return Err(Error::input(
                source,
                "values",
                format!(
                    "{} values for a {} grid of {n} samples",
                    values.len(),
                    dims_text(dims)
                ),
            ));
        }
        Ok(Volume {
            dims,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            values,
        })
    }

    /// Sets the spacing and origin.
    ///
    /// # Errors
    ///
    /// [`Error::InvalidArgument`] when a spacing is not finite and positive or
    /// an origin coordinate is not finite.
    pub fn with_geometry(mut self, spacing: [f64; 3], origin: [f64; 3]) -> Result<Volume> {
        if let Some(s) = spacing.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(Error::InvalidArgument(format!(
                "volume spacing {spacing:?}: {s} is not a finite positive number"
            )));
        }
        if !origin.iter().all(|o| o.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "volume origin {origin:?} is not finite"
            )));
        }
        self.spacing = spacing;
        self.origin = origin;
        Ok(self)
    }

    /// Index of sample `(x, y, z)` in [`Volume::values`].
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Sample `(x, y, z)`. Panics when out of range, like slice indexing.
    #[inline]
    pub fn value(&self, x: usize, y: usize, z: usize) -> f32 {
        self.values[self.index(x, y, z)]
    }

    /// Number of samples.
    pub fn voxel_count(&self) -> usize {
        self.values.len()
    }

    /// World position of index-space point `p` (fractional indices allowed).
    pub fn world(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| self.origin[i] + self.spacing[i] * p[i])
    }

    /// Smallest and largest sample, ignoring NaN; `None` when every sample
    /// is NaN.
    pub fn range(&self) -> Option<(f32, f32)> {
        let mut it = self.values.iter().copied().filter(|v| !v.is_nan());
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
    }

    /// Size of the samples in memory, in bytes.
    pub fn bytes(&self) -> u64 {
        (self.values.len() as u64) * std::mem::size_of::<f32>() as u64
    }
}

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

/// File extensions [`load`] recognises, for messages.
const EXTENSIONS: &str = ".raw (with a RawSpec), .nrrd, .nhdr, .mhd, .mha, .vtk, .vti and .slc";

/// Loads a volume. With `raw` given, the file is read as headerless samples
/// whatever its extension; otherwise the format follows the extension
/// (case-insensitive): `.nrrd`/`.nhdr` (NRRD), `.mhd`/`.mha` (MetaImage),
/// `.vtk` (legacy `STRUCTURED_POINTS`), `.vti` (XML ImageData), `.slc`.
///
/// # Errors
///
/// [`Error::Io`] when the file or a data file it names cannot be read,
/// [`Error::UnsupportedFormat`] for an unknown extension, a `.raw` file
/// without `raw`, or a feature shapecue does not read (named in the message),
/// and [`Error::InvalidInput`] for malformed headers and data whose size does
/// not match the header ("expected N bytes (X×Y×Z × T bytes), found M").
pub fn load(path: &Path, raw: Option<&RawSpec>) -> Result<Volume> {
    if let Some(spec) = raw {
        return raw::load(path, spec);
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("nrrd" | "nhdr") => nrrd::load(path),
        Some("mhd" | "mha") => mhd::load(path),
        Some("vtk") => vtk::load_legacy(path),
        Some("vti") => vtk::load_xml(path),
        Some("slc") => slc::load(path),
        Some("raw") => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: "a .raw file has no header: give its dimensions and scalar type \
                      (a RawSpec)"
                .into(),
        }),
        Some(other) => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("unknown extension '.{other}' (shapecue reads {EXTENSIONS})"),
        }),
        None => Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("no file extension (shapecue reads {EXTENSIONS})"),
        }),
    }
}

// ---------------------------------------------------------------------------
// Helpers shared by the loaders
// ---------------------------------------------------------------------------

/// [`load`], also returning every file it read: the header and, for NRRD
/// and MetaImage, each detached data file (so that a caller can refuse to
/// write over any of them).
///
/// # Errors
/// As [`load`].
pub fn load_with_files(path: &Path, raw: Option<&RawSpec>) -> Result<(Volume, Vec<PathBuf>)> {
    READ.with(|r| *r.borrow_mut() = Some(Vec::new()));
    let result = load(path, raw);
    let files = READ.with(|r| r.borrow_mut().take()).unwrap_or_default();
    Ok((result?, files))
}

thread_local! {
    /// The files [`read_file`] read while [`load_with_files`] records them.
    static READ: std::cell::RefCell<Option<Vec<PathBuf>>> = const { std::cell::RefCell::new(None) };
}

/// Reads a whole file, naming it in the error.
fn read_file(path: &Path) -> Result<Vec<u8>> {
    record_read(path);
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Notes `path` as read while [`load_with_files`] records.
fn record_read(path: &Path) {
    READ.with(|r| {
        if let Some(files) = r.borrow_mut().as_mut() {
            files.push(path.to_path_buf());
        }
    });
}

/// Opens a file to read part of it, naming it in the error; returns the
/// reader and the file's size (from its metadata, before reading).
fn open_file(path: &Path) -> Result<(std::io::BufReader<std::fs::File>, u64)> {
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
fn skip_line(r: &mut impl std::io::BufRead) -> std::io::Result<Option<u64>> {
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
fn dims_text(dims: [usize; 3]) -> String {
    format!("{}×{}×{}", dims[0], dims[1], dims[2])
}

/// The number of samples of a grid: every dimension at least 1, no overflow.
fn voxel_count(dims: [usize; 3], source: &str, element: &str) -> Result<usize> {
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
fn byte_count(count: usize, scalar: ScalarType, source: &str, element: &str) -> Result<usize> {
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
fn size_problem(shape: &[usize], scalar: ScalarType, found: usize) -> String {
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

/// Appends `bytes` (a whole number of values) converted to `f32`.
fn convert_into(bytes: &[u8], scalar: ScalarType, big_endian: bool, out: &mut Vec<f32>) {
    // `as_chunks` gives fixed-size arrays: the loops below compile to
    // straight-line conversions the optimiser vectorises.
    macro_rules! conv {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let (chunks, _) = bytes.as_chunks::<N>();
            if big_endian {
                out.extend(chunks.iter().map(|c| <$t>::from_be_bytes(*c) as f32));
            } else {
                out.extend(chunks.iter().map(|c| <$t>::from_le_bytes(*c) as f32));
            }
        }};
    }
    match scalar {
        ScalarType::U8 => out.extend(bytes.iter().map(|&b| f32::from(b))),
        ScalarType::I8 => out.extend(bytes.iter().map(|&b| f32::from(b as i8))),
        ScalarType::U16 => conv!(u16),
        ScalarType::I16 => conv!(i16),
        ScalarType::U32 => conv!(u32),
        ScalarType::I32 => conv!(i32),
        ScalarType::F32 => conv!(f32),
        ScalarType::F64 => conv!(f64),
    }
}

/// Parses `count` whitespace-separated numbers (ASCII payloads), appending
/// them to `out`. Extra tokens after them are left alone.
fn parse_ascii_into(
    text: &[u8],
    count: usize,
    out: &mut Vec<f32>,
    source: &str,
    element: &str,
) -> Result<()> {
    let mut toks = text
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty());
    out.reserve(count.min(text.len() / 2 + 1));
    for i in 0..count {
        let tok = toks.next().ok_or_else(|| {
            Error::input(
                source,
                element,
                format!("expected {count} values, found {i}"),
            )
        })?;
        let v = std::str::from_utf8(tok)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
            .ok_or_else(|| {
                Error::input(
                    source,
                    element,
                    format!(
                        "value {i}: '{}' is not a number",
                        String::from_utf8_lossy(tok)
                    ),
                )
            })?;
        out.push(v as f32);
    }
    Ok(())
}

/// A compressed stream format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Compression {
    /// gzip (RFC 1952), as NRRD's `encoding: gzip`.
    Gzip,
    /// zlib (RFC 1950), as MetaImage's `CompressedData` and VTK XML blocks.
    Zlib,
}

/// Deflate's largest expansion (one 258-byte match in 2 bits): `n` bytes of
/// gzip or zlib data never inflate to more than `MAX_INFLATE * n` bytes.
const MAX_INFLATE: usize = 1032;

/// The memory bound of compressed data: refuses, before anything is
/// inflated or allocated, a header that asks more bytes (`want`) of `have`
/// compressed bytes than deflate can produce from them.
fn check_inflate(have: usize, want: usize, kind: Compression) -> std::result::Result<(), String> {
    if want > have.saturating_mul(MAX_INFLATE) {
        return Err(format!(
            "{have} bytes of {} data cannot hold the {want} bytes the header calls for \
             (deflate expands at most {MAX_INFLATE}:1)",
            kind.name()
        ));
    }
    Ok(())
}

impl Compression {
    /// The format's name in messages.
    fn name(self) -> &'static str {
        match self {
            Compression::Gzip => "gzip",
            Compression::Zlib => "zlib",
        }
    }
}

/// Decompresses `data`, reading at most `limit` bytes of output so that a
/// lying header or a compression bomb cannot exhaust memory; the caller
/// checks the size it gets.
fn decompress(
    data: impl Read,
    kind: Compression,
    limit: usize,
) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let limit = limit as u64;
    let res = match kind {
        Compression::Gzip => flate2::read::MultiGzDecoder::new(data)
            .take(limit)
            .read_to_end(&mut out),
        Compression::Zlib => flate2::read::ZlibDecoder::new(data)
            .take(limit)
            .read_to_end(&mut out),
    };
    match res {
        Ok(_) => Ok(out),
        Err(e) => Err(format!("{kind:?} data cannot be decompressed: {e}").to_lowercase()),
    }
}

/// How the samples of NRRD and MetaImage data files are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    /// Binary samples.
    Raw,
    /// Binary samples, compressed.
    Compressed(Compression),
    /// Whitespace-separated numbers.
    Ascii,
}

/// Where the bytes of a data chunk start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Skip {
    /// After this many bytes (of the decompressed data when compressed).
    Bytes(usize),
    /// At the end of the file: the last bytes are the samples (NRRD
    /// `byte skip: -1`, MetaImage `HeaderSize = -1`); raw encoding only.
    ToEnd,
}

impl Skip {
    /// Parses a header's skip `field` (NRRD `byte skip`, MetaImage
    /// `HeaderSize`): a byte count, or -1 for the end of the file.
    fn parse(value: &str, field: &str, source: &str, element: &str) -> Result<Skip> {
        let n: i64 = number(value, field, source, element)?;
        match usize::try_from(n) {
            Ok(n) => Ok(Skip::Bytes(n)),
            Err(_) if n == -1 => Ok(Skip::ToEnd),
            Err(_) => Err(Error::input(
                source,
                element,
                format!("{field} {n} must be -1 or at least 0"),
            )),
        }
    }
}

/// The payload of a NRRD or MetaImage file: samples stored in one or more
/// chunks (the attached data, or data files that each hold an equal share).
struct Payload<'a> {
    /// The header's name, for messages.
    source: &'a str,
    dims: [usize; 3],
    scalar: ScalarType,
    big_endian: bool,
    encoding: Encoding,
    /// Text lines to skip at the start of each chunk (before decompression).
    line_skip: usize,
    /// Bytes to skip at the start of each chunk (after decompression).
    byte_skip: Skip,
    /// The shape of the samples of one chunk, for messages (the grid, or a
    /// slab of it).
    chunk_shape: Vec<usize>,
}

impl Payload<'_> {
    /// Decodes the chunks (their bytes and their name for messages), in
    /// order, into the samples of the whole grid.
    fn read<'c>(
        &self,
        chunks: impl IntoIterator<Item = Result<(Cow<'c, [u8]>, String)>>,
    ) -> Result<Vec<f32>> {
        self.gather(|per_chunk, values| {
            for chunk in chunks {
                let (bytes, element) = chunk?;
                self.read_chunk(&bytes, &element, per_chunk, values)?;
            }
            Ok(())
        })
    }

    /// Decodes detached data files, in order, into the samples of the whole
    /// grid (see [`Payload::read_data_file`]).
    fn read_files(&self, files: &[PathBuf]) -> Result<Vec<f32>> {
        self.gather(|per_chunk, values| {
            files
                .iter()
                .try_for_each(|f| self.read_data_file(f, per_chunk, values))
        })
    }

    /// The samples of the whole grid, appended by `fill` (given the samples
    /// per chunk), checked to be exactly the grid's count.
    fn gather(&self, fill: impl FnOnce(usize, &mut Vec<f32>) -> Result<()>) -> Result<Vec<f32>> {
        let total = voxel_count(self.dims, self.source, "sizes")?;
        let mut values = Vec::new();
        fill(self.chunk_shape.iter().product(), &mut values)?;
        if values.len() != total {
            // The callers size the chunks and files from the header; this is
            // a guard, not an expected path.
            return Err(Error::input(
                self.source,
                "data",
                format!("{} samples read for a grid of {total}", values.len()),
            ));
        }
        Ok(values)
    }

    /// Decodes one detached data file of `count` samples, appending them
    /// to `out`. Binary data are streamed: the file's size is checked with
    /// its metadata before anything is read, and only the lines to skip,
    /// the bytes to skip and the samples are read (a raw file of the wrong
    /// size is refused unread; with a byte skip of -1 only its last bytes
    /// are read); compressed data are inflated one byte past what the
    /// header calls for and no further, so a compression bomb cannot
    /// exhaust memory. ASCII data are read whole: their length does not
    /// tell how many values they hold.
    fn read_data_file(&self, path: &Path, count: usize, out: &mut Vec<f32>) -> Result<()> {
        let el = format!("data file {}", path.display());
        let compression = match self.encoding {
            Encoding::Ascii => {
                let data = read_file(path)?;
                return self.read_chunk(&data, &el, count, out);
            }
            Encoding::Raw => None,
            Encoding::Compressed(kind) => Some(kind),
        };
        let src = self.source;
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let (mut r, size) = open_file(path)?;
        let mut skipped = 0u64;
        for _ in 0..self.line_skip {
            skipped += skip_line(&mut r).map_err(io)?.ok_or_else(|| {
                Error::input(
                    src,
                    &el,
                    format!(
                        "file ends before the {} lines to skip ('line skip')",
                        self.line_skip
                    ),
                )
            })?;
        }
        let rest = size.saturating_sub(skipped);
        let expected = byte_count(count, self.scalar, src, &el)?;
        let wrong_size = |found: u64| {
            let lines = if skipped > 0 {
                format!(", {skipped} of them in skipped lines")
            } else {
                String::new()
            };
            Error::input(
                src,
                &el,
                format!(
                    "{} (the file has {size} bytes{lines})",
                    size_problem(&self.chunk_shape, self.scalar, found as usize)
                ),
            )
        };
        let data = match compression {
            None => {
                let (offset, found) = match self.byte_skip {
                    Skip::Bytes(n) => (n as u64, rest.saturating_sub(n as u64)),
                    // The last bytes: a larger file is fine, a smaller one not.
                    Skip::ToEnd => (
                        rest.saturating_sub(expected as u64),
                        rest.min(expected as u64),
                    ),
                };
                if found != expected as u64 {
                    return Err(wrong_size(found));
                }
                // `offset` is at most the file's size: it fits in an i64.
                r.seek_relative(offset as i64).map_err(io)?;
                let mut buf = vec![0u8; expected];
                r.read_exact(&mut buf).map_err(io)?;
                buf
            }
            Some(kind) => {
                let skip = match self.byte_skip {
                    Skip::Bytes(n) => n,
                    Skip::ToEnd => {
                        return Err(Error::input(
                            src,
                            &el,
                            "a byte skip of -1 (data at the end of the file) cannot be used \
                             with compressed data",
                        ));
                    }
                };
                let limit = skip.saturating_add(expected).saturating_add(1);
                let have = usize::try_from(rest).unwrap_or(usize::MAX);
                check_inflate(have, limit - 1, kind).map_err(|p| Error::input(src, &el, p))?;
                let mut d = decompress(r, kind, limit).map_err(|p| Error::input(src, &el, p))?;
                let want = skip.saturating_add(expected);
                if d.len() > want {
                    return Err(Error::input(
                        src,
                        &el,
                        format!(
                            "the {} data inflate to more than the {want} bytes the header calls \
                             for (decompression stopped there)",
                            kind.name()
                        ),
                    ));
                }
                if d.len() < want {
                    let found = d.len().saturating_sub(skip);
                    return Err(Error::input(
                        src,
                        &el,
                        size_problem(&self.chunk_shape, self.scalar, found),
                    ));
                }
                d.drain(..skip);
                d
            }
        };
        convert_into(&data, self.scalar, self.big_endian, out);
        Ok(())
    }

    /// Decodes one chunk of `count` samples, appending them to `out`.
    fn read_chunk(&self, bytes: &[u8], el: &str, count: usize, out: &mut Vec<f32>) -> Result<()> {
        let src = self.source;
        let mut data = skip_lines(bytes, self.line_skip).ok_or_else(|| {
            Error::input(
                src,
                el,
                format!(
                    "file ends before the {} lines to skip ('line skip')",
                    self.line_skip
                ),
            )
        })?;
        let expected = byte_count(count, self.scalar, src, el)?;
        let decompressed;
        match self.encoding {
            Encoding::Ascii => {
                if let Skip::Bytes(n) = self.byte_skip {
                    data = data.get(n..).unwrap_or_default();
                }
                return parse_ascii_into(data, count, out, src, el);
            }
            Encoding::Compressed(kind) => {
                let skip = match self.byte_skip {
                    Skip::Bytes(n) => n,
                    Skip::ToEnd => {
                        return Err(Error::input(
                            src,
                            el,
                            "a byte skip of -1 (data at the end of the file) cannot be used \
                             with compressed data",
                        ));
                    }
                };
                let limit = skip.saturating_add(expected).saturating_add(1);
                check_inflate(data.len(), limit - 1, kind).map_err(|p| Error::input(src, el, p))?;
                decompressed =
                    decompress(data, kind, limit).map_err(|p| Error::input(src, el, p))?;
                data = decompressed.get(skip..).unwrap_or_default();
            }
            Encoding::Raw => {
                data = match self.byte_skip {
                    Skip::Bytes(n) => data.get(n..).unwrap_or_default(),
                    Skip::ToEnd => data
                        .get(data.len().saturating_sub(expected)..)
                        .unwrap_or(data),
                };
            }
        }
        if data.len() != expected {
            return Err(Error::input(
                src,
                el,
                size_problem(&self.chunk_shape, self.scalar, data.len()),
            ));
        }
        convert_into(data, self.scalar, self.big_endian, out);
        Ok(())
    }
}

/// The rest of `bytes` after `n` newline-terminated lines, or `None` when
/// there are fewer lines.
fn skip_lines(bytes: &[u8], n: usize) -> Option<&[u8]> {
    let mut rest = bytes;
    for _ in 0..n {
        let nl = rest.iter().position(|&b| b == b'\n')?;
        rest = &rest[nl + 1..];
    }
    Some(rest)
}

/// Splits `bytes` into lines (without `\n` or `\r\n`), each with the offset
/// of the byte after it (where the next line starts).
fn lines_with_end(bytes: &[u8]) -> impl Iterator<Item = (&[u8], usize)> {
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
fn diagonal(axes: [[f64; 3]; 3]) -> Option<[f64; 3]> {
    let scale = axes.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let off_diagonal_zero = (0..3)
        .flat_map(|i| (0..3).filter(move |&j| j != i).map(move |j| (i, j)))
        .all(|(i, j)| axes[i][j].abs() <= 1e-9 * scale);
    off_diagonal_zero.then(|| std::array::from_fn(|i| axes[i][i]))
}

/// Builds a volume from samples with per-axis steps that may be negative:
/// such an axis is reversed (and its origin moved to the other end) so that
/// the spacing is positive and every sample keeps its world position.
fn oriented(
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
            format!("{what} {v:?} must be finite and non-zero"),
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
fn scalar_type(value: &str, source: &str, element: &str) -> Result<ScalarType> {
    value.parse().map_err(|e| match e {
        Error::InvalidArgument(problem) => Error::input(source, element, problem),
        other => other,
    })
}

/// Parses one header number, naming the element and the field in the error.
fn number<T: FromStr>(tok: &str, what: &str, source: &str, element: &str) -> Result<T> {
    tok.trim().parse::<T>().map_err(|_| {
        Error::input(
            source,
            element,
            format!("{what}: '{tok}' is not a valid number"),
        )
    })
}

/// Parses exactly `N` whitespace-separated numbers.
fn numbers<T: FromStr + Copy + Default, const N: usize>(
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
fn dimension(value: &str, field: &str, path: &Path, element: &str) -> Result<usize> {
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
    fn conversion_of_every_type() {
        let mut out = Vec::new();
        convert_into(&[0xff, 0x01], ScalarType::I8, false, &mut out);
        convert_into(&[0xff, 0x01], ScalarType::U8, false, &mut out);
        convert_into(&[0x01, 0x02], ScalarType::U16, true, &mut out);
        convert_into(&[0x01, 0x02], ScalarType::U16, false, &mut out);
        convert_into(&(-3i16).to_le_bytes(), ScalarType::I16, false, &mut out);
        convert_into(&7u32.to_be_bytes(), ScalarType::U32, true, &mut out);
        convert_into(&(-9i32).to_le_bytes(), ScalarType::I32, false, &mut out);
        convert_into(&1.5f32.to_be_bytes(), ScalarType::F32, true, &mut out);
        convert_into(&(-2.25f64).to_le_bytes(), ScalarType::F64, false, &mut out);
        assert_eq!(
            out,
            [
                -1.0, 1.0, 255.0, 1.0, 258.0, 513.0, -3.0, 7.0, -9.0, 1.5, -2.25
            ]
        );
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
