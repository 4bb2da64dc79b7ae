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
    let dir = path.parent().unwrap_or(Path::new(""));

    let mut ndims: Option<usize> = None;
    let mut dims: Option<[usize; 3]> = None;
    let mut scalar: Option<ScalarType> = None;
    let mut spacing: Option<[f64; 3]> = None;
    let mut size: Option<[f64; 3]> = None;
    let mut origin = [0.0; 3];
    let mut matrix: Option<[f64; 9]> = None;
    let mut big_endian = false;
    let mut binary = true;
    let mut compressed = false;
    let mut skip = Skip::Bytes(0);
    let mut data: Option<DataFiles> = None;

    let mut lines = lines_with_end(&bytes).enumerate();
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
        let flag = || boolean(value, key.trim(), src, el);
        match key.trim().to_ascii_lowercase().as_str() {
            "objecttype" if !value.eq_ignore_ascii_case("image") => {
                return Err(Error::UnsupportedFormat {
                    path: path.to_path_buf(),
                    problem: format!("ObjectType {value}: shapecue reads images only"),
                });
            }
            // Before DimSize, whose count depends on it.
            "ndims" => ndims = Some(dimension(value, "NDims", path, el)?),
            "dimsize" => dims = Some(numbers(value, "DimSize", src, el)?),
            "elementtype" => {
                let name = value.to_ascii_lowercase();
                let name = name.strip_prefix("met_").ok_or_else(|| {
                    Error::input(
                        src,
                        el,
                        format!("ElementType '{value}' does not start with MET_"),
                    )
                })?;
                scalar = Some(scalar_type(name, src, el).map_err(|_| {
                    Error::input(
                        src,
                        el,
                        format!(
                            "ElementType '{value}' is not supported (MET_CHAR, MET_UCHAR, \
                             MET_SHORT, MET_USHORT, MET_INT, MET_UINT, MET_FLOAT, MET_DOUBLE are)"
                        ),
                    )
                })?);
            }
            "elementspacing" => spacing = Some(numbers(value, "ElementSpacing", src, el)?),
            "elementsize" => size = Some(numbers(value, "ElementSize", src, el)?),
            "offset" | "position" | "origin" => origin = numbers(value, key.trim(), src, el)?,
            "transformmatrix" | "rotation" | "orientation" => {
                let toks: Vec<&str> = value.split_whitespace().collect();
                if toks.len() != 9 {
                    return Err(Error::input(
                        src,
                        el,
                        format!("{}: expected 9 values, found {}", key.trim(), toks.len()),
                    ));
                }
                let mut m = [0.0; 9];
                for (v, t) in m.iter_mut().zip(toks) {
                    *v = number(t, key.trim(), src, el)?;
                }
                matrix = Some(m);
            }
            "binarydatabyteordermsb" | "elementbyteordermsb" | "byteordermsb" => {
                big_endian = flag()?
            }
            "binarydata" => binary = flag()?,
            "compresseddata" => compressed = flag()?,
            "headersize" => skip = Skip::parse(value, "HeaderSize", src, el)?,
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
            "elementdatafile" => {
                let rest = lines.by_ref().map(|(_, (l, _))| l);
                data = Some(if value.eq_ignore_ascii_case("local") {
                    DataFiles::Attached(end)
                } else {
                    detached(&METAIMAGE, value, rest, dims, dir, src, el)?
                });
                break;
            }
            _ => {}
        }
    }

    let missing = |key: &str| Error::input(src, "header", format!("missing {key}"));
    if ndims.is_none() {
        return Err(missing("NDims"));
    }
    let dims = dims.ok_or_else(|| missing("DimSize"))?;
    let scalar = scalar.ok_or_else(|| missing("ElementType"))?;
    let data = data.ok_or_else(|| missing("ElementDataFile (it must be the last key)"))?;
    let total = voxel_count(dims, src, "DimSize")?;
    let encoding = match (binary, compressed) {
        (false, _) => Encoding::Ascii,
        (true, true) => Encoding::Compressed(Compression::Zlib),
        (true, false) => Encoding::Raw,
    };
    if skip == Skip::ToEnd && encoding != Encoding::Raw {
        return Err(Error::input(
            src,
            "HeaderSize",
            "-1 (data at the end of the file) is only valid with uncompressed binary data",
        ));
    }
    let chunk_shape = data.chunk_shape(&METAIMAGE, dims, total, src)?;
    let payload = Payload {
        source: src,
        dims,
        scalar,
        big_endian,
        encoding,
        line_skip: 0,
        byte_skip: skip,
        chunk_shape,
    };
    let values = data.read(&METAIMAGE, &payload, &bytes)?;
    let spacing = spacing.or(size).unwrap_or([1.0; 3]);
    let steps = match matrix {
        None => spacing,
        Some(m) => {
            let axes = [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]];
            let d = diagonal(axes).ok_or_else(|| Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!(
                    "TransformMatrix = {} is not axis-aligned: shapecue reads grids whose \
                     axes follow x, y and z (resample the volume first)",
                    crate::error::values(m, " ")
                ),
            })?;
            std::array::from_fn(|i| spacing[i] * d[i])
        }
    };
    oriented(dims, values, steps, origin, src)
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
