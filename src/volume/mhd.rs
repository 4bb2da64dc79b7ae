//! MetaImage reader (ITK MetaIO): `.mhd` headers with a detached data file
//! and `.mha` files with the data after the header (`ElementDataFile =
//! LOCAL`). Hand-written: the header is a few `Key = Value` lines and no
//! maintained crate reads it.
//!
//! Read: `NDims` (3), `DimSize`, `ElementType` (`MET_CHAR` ... `MET_UINT`,
//! `MET_FLOAT`, `MET_DOUBLE`), `ElementSpacing` (or `ElementSize`),
//! `Offset` (or `Position`, `Origin`), a diagonal `TransformMatrix` (or
//! `Rotation`, `Orientation`), the byte order (`BinaryDataByteOrderMSB`,
//! `ElementByteOrderMSB`, `ByteOrderMSB`), `BinaryData` (`False` = text),
//! `CompressedData` (zlib), `HeaderSize` (-1 = data at the end of the file),
//! `ElementNumberOfChannels` (1) and `ElementDataFile`, which ends the header:
//! `LOCAL`, one file, `LIST [subdim]` followed by one name per line, or
//! `fmt min max step [subdim]`. Keys are matched case-insensitively; other
//! keys (comments, anatomical orientation, ...) are ignored.

use std::path::Path;

use super::data_files::{DataFiles, METAIMAGE, detached};
use super::{
    Compression, Encoding, Payload, ScalarType, Skip, Volume, diagonal, dimension, lines_with_end,
    number, numbers, oriented, read_file, scalar_type, voxel_count,
};
use crate::error::{Error, Result};

/// Loads a `.mhd` or `.mha` file.
pub(super) fn load(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let src = source.as_str();
    let h = read_header(&bytes, path, src)?;

    let missing = |key: &str| Error::input(src, "header", format!("missing {key}"));
    if h.ndims.is_none() {
        return Err(missing("NDims"));
    }
    let dims = h.dims.ok_or_else(|| missing("DimSize"))?;
    let scalar = h.scalar.ok_or_else(|| missing("ElementType"))?;
    let data = h
        .data
        .as_ref()
        .ok_or_else(|| missing("ElementDataFile (it must be the last key)"))?;
    let total = voxel_count(dims, src, "DimSize")?;
    let encoding = encoding(&h, src)?;
    let chunk_shape = data.chunk_shape(&METAIMAGE, dims, total, src)?;
    let payload = Payload {
        source: src,
        dims,
        scalar,
        big_endian: h.big_endian,
        encoding,
        line_skip: 0,
        byte_skip: h.skip,
        chunk_shape,
    };
    let values = data.read(&METAIMAGE, &payload, &bytes)?;
    let steps = steps(&h, path)?;
    oriented(dims, values, steps, h.origin, src)
}

/// The header keys that are read, as far as the header sets them.
struct Header {
    ndims: Option<usize>,
    dims: Option<[usize; 3]>,
    scalar: Option<ScalarType>,
    spacing: Option<[f64; 3]>,
    size: Option<[f64; 3]>,
    origin: [f64; 3],
    matrix: Option<[f64; 9]>,
    big_endian: bool,
    binary: bool,
    compressed: bool,
    skip: Skip,
    data: Option<DataFiles>,
}

/// Reads the `Key = Value` lines up to and including `ElementDataFile`.
fn read_header(bytes: &[u8], path: &Path, src: &str) -> Result<Header> {
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut h = Header {
        ndims: None,
        dims: None,
        scalar: None,
        spacing: None,
        size: None,
        origin: [0.0; 3],
        matrix: None,
        big_endian: false,
        binary: true,
        compressed: false,
        skip: Skip::Bytes(0),
        data: None,
    };
    let mut lines = lines_with_end(bytes).enumerate();
    while let Some((i, (line, end))) = lines.next() {
        let element = format!("header line {}", i + 1);
        let el = element.as_str();
        let line = std::str::from_utf8(line).map_err(|_| {
            Error::input(
                src,
                el,
                "not text (the header must end with ElementDataFile)",
            )
        })?;
        if line.trim().is_empty() {
            continue;
        }
        let (key, value) = line.split_once('=').ok_or_else(|| {
            Error::input(src, el, format!("expected 'Key = Value', found '{line}'"))
        })?;
        let value = value.trim();
        if key.trim().eq_ignore_ascii_case("elementdatafile") {
            let rest = lines.by_ref().map(|(_, (l, _))| l);
            h.data = Some(if value.eq_ignore_ascii_case("local") {
                DataFiles::Attached(end)
            } else {
                detached(&METAIMAGE, value, rest, h.dims, dir, src, el)?
            });
            break;
        }
        key_value(&mut h, key.trim(), value, path, src, el)?;
    }
    Ok(h)
}

/// Reads one `Key = Value` line (other than `ElementDataFile`) into `h`.
fn key_value(
    h: &mut Header,
    key: &str,
    value: &str,
    path: &Path,
    src: &str,
    el: &str,
) -> Result<()> {
    let flag = || boolean(value, key, src, el);
    match key.to_ascii_lowercase().as_str() {
        "objecttype" if !value.eq_ignore_ascii_case("image") => {
            return Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!("ObjectType {value}: shapecue reads images only"),
            });
        }
        // Before DimSize, whose count depends on it.
        "ndims" => h.ndims = Some(dimension(value, "NDims", path, el)?),
        "dimsize" => h.dims = Some(numbers(value, "DimSize", src, el)?),
        "elementtype" => h.scalar = Some(element_type(value, src, el)?),
        "elementspacing" => h.spacing = Some(numbers(value, "ElementSpacing", src, el)?),
        "elementsize" => h.size = Some(numbers(value, "ElementSize", src, el)?),
        "offset" | "position" | "origin" => h.origin = numbers(value, key, src, el)?,
        "transformmatrix" | "rotation" | "orientation" => {
            let toks: Vec<&str> = value.split_whitespace().collect();
            if toks.len() != 9 {
                return Err(Error::input(
                    src,
                    el,
                    format!("{key}: expected 9 values, found {}", toks.len()),
                ));
            }
            let mut m = [0.0; 9];
            for (v, t) in m.iter_mut().zip(toks) {
                *v = number(t, key, src, el)?;
            }
            h.matrix = Some(m);
        }
        "binarydatabyteordermsb" | "elementbyteordermsb" | "byteordermsb" => h.big_endian = flag()?,
        "binarydata" => h.binary = flag()?,
        "compresseddata" => h.compressed = flag()?,
        "headersize" => h.skip = Skip::parse(value, "HeaderSize", src, el)?,
        "elementnumberofchannels" => {
            let n: usize = number(value, "ElementNumberOfChannels", src, el)?;
            if n != 1 {
                return Err(Error::UnsupportedFormat {
                    path: path.to_path_buf(),
                    problem: format!(
                        "ElementNumberOfChannels {n}: shapecue reads scalar volumes only"
                    ),
                });
            }
        }
        _ => {}
    }
    Ok(())
}

/// The scalar type of an `ElementType = MET_...` value.
fn element_type(value: &str, src: &str, el: &str) -> Result<ScalarType> {
    let name = value.to_ascii_lowercase();
    let name = name.strip_prefix("met_").ok_or_else(|| {
        Error::input(
            src,
            el,
            format!("ElementType '{value}' does not start with MET_"),
        )
    })?;
    scalar_type(name, src, el).map_err(|_| {
        Error::input(
            src,
            el,
            format!(
                "ElementType '{value}' is not supported (MET_CHAR, MET_UCHAR, \
                 MET_SHORT, MET_USHORT, MET_INT, MET_UINT, MET_FLOAT, MET_DOUBLE are)"
            ),
        )
    })
}

/// How the samples are stored; `HeaderSize = -1` needs raw binary data.
fn encoding(h: &Header, src: &str) -> Result<Encoding> {
    let encoding = match (h.binary, h.compressed) {
        (false, _) => Encoding::Ascii,
        (true, true) => Encoding::Compressed(Compression::Zlib),
        (true, false) => Encoding::Raw,
    };
    if h.skip == Skip::ToEnd && encoding != Encoding::Raw {
        return Err(Error::input(
            src,
            "HeaderSize",
            "-1 (data at the end of the file) is only valid with uncompressed binary data",
        ));
    }
    Ok(encoding)
}

/// The steps along x, y and z: the spacing, signed by a diagonal matrix.
fn steps(h: &Header, path: &Path) -> Result<[f64; 3]> {
    let spacing = h.spacing.or(h.size).unwrap_or([1.0; 3]);
    let Some(m) = h.matrix else {
        return Ok(spacing);
    };
    let axes = [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]];
    let d = diagonal(axes).ok_or_else(|| Error::UnsupportedFormat {
        path: path.to_path_buf(),
        problem: format!(
            "TransformMatrix = {} is not axis-aligned: shapecue reads grids whose \
             axes follow x, y and z (resample the volume first)",
            crate::error::values(m, " ")
        ),
    })?;
    Ok(std::array::from_fn(|i| spacing[i] * d[i]))
}

/// Parses `True`/`False` (also `1`/`0`).
fn boolean(value: &str, key: &str, source: &str, el: &str) -> Result<bool> {
    match value.to_ascii_lowercase().as_str() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => Err(Error::input(
            source,
            el,
            format!("{key}: '{value}' is neither True nor False"),
        )),
    }
}
