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

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use super::{
    Compression, Encoding, Payload, ScalarType, Skip, Volume, diagonal, lines_with_end, number,
    oriented, pattern_files, read_file, scalar_type, three, voxel_count,
};
use crate::error::{Error, Result};

/// Where the samples are.
enum DataFiles {
    /// In the header file from this byte offset on.
    Local(usize),
    /// In these files; `subdim` is the number of fast axes each holds in full.
    Files { files: Vec<PathBuf>, subdim: usize },
}

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
            "ndims" => {
                let n: usize = number(value, "NDims", src, el)?;
                if n != 3 {
                    // Before DimSize, whose count depends on it.
                    return Err(Error::UnsupportedFormat {
                        path: path.to_path_buf(),
                        problem: format!("NDims {n}: shapecue reads 3-D volumes only"),
                    });
                }
                ndims = Some(n);
            }
            "dimsize" => dims = Some(three(value, "DimSize", src, el)?),
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
            "elementspacing" => spacing = Some(three(value, "ElementSpacing", src, el)?),
            "elementsize" => size = Some(three(value, "ElementSize", src, el)?),
            "offset" | "position" | "origin" => origin = three(value, key.trim(), src, el)?,
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
            "headersize" => {
                let n: i64 = number(value, "HeaderSize", src, el)?;
                skip = match usize::try_from(n) {
                    Ok(n) => Skip::Bytes(n),
                    Err(_) if n == -1 => Skip::ToEnd,
                    Err(_) => {
                        return Err(Error::input(
                            src,
                            el,
                            format!("HeaderSize {n} must be -1 or at least 0"),
                        ));
                    }
                };
            }
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
                data = Some(data_files(value, end, rest, dims, dir, src, el)?);
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
    let chunk_shape = match &data {
        DataFiles::Local(_) => dims.to_vec(),
        DataFiles::Files { files, subdim } => {
            let shape = dims[..*subdim].to_vec();
            let per_file: usize = shape.iter().product();
            if files.len() != total / per_file {
                return Err(Error::input(
                    src,
                    "ElementDataFile",
                    format!(
                        "{} data files for {} slabs of {per_file} samples",
                        files.len(),
                        total / per_file
                    ),
                ));
            }
            shape
        }
    };
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
    let values = match data {
        DataFiles::Local(offset) => {
            let local = bytes.get(offset..).unwrap_or_default();
            payload.read([Ok((Cow::Borrowed(local), "local data".to_string()))])?
        }
        DataFiles::Files { files, .. } => payload.read(files.iter().map(|f| {
            let data = read_file(f)?;
            Ok((Cow::Owned(data), format!("data file {}", f.display())))
        }))?,
    };
    let spacing = spacing.or(size).unwrap_or([1.0; 3]);
    let steps = match matrix {
        None => spacing,
        Some(m) => {
            let axes = [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]];
            let d = diagonal(axes).ok_or_else(|| Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!(
                    "TransformMatrix {m:?} is not axis-aligned: shapecue reads grids whose \
                     axes follow x, y and z (resample the volume first)"
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

/// Parses the `ElementDataFile` value; `end` is where the line after it
/// starts (the data of `LOCAL`), `rest` yields the lines after it (the
/// names of a `LIST`).
fn data_files<'a>(
    value: &str,
    end: usize,
    rest: impl Iterator<Item = &'a [u8]>,
    dims: Option<[usize; 3]>,
    dir: &Path,
    source: &str,
    el: &str,
) -> Result<DataFiles> {
    let toks: Vec<&str> = value.split_whitespace().collect();
    if value.eq_ignore_ascii_case("local") {
        return Ok(DataFiles::Local(end));
    }
    let subdim = |tok: Option<&&str>| -> Result<usize> {
        let d = match tok {
            None => 2,
            Some(t) => {
                // MetaIO writes the slab dimension as e.g. "2D".
                let t = t.trim_end_matches(['D', 'd']);
                number(t, "ElementDataFile slab dimension", source, el)?
            }
        };
        if (1..=3).contains(&d) {
            Ok(d)
        } else {
            Err(Error::input(
                source,
                el,
                format!("ElementDataFile slab dimension {d} must be 1, 2 or 3"),
            ))
        }
    };
    let slabs = |sub: usize| -> Result<usize> {
        let dims = dims.ok_or_else(|| {
            Error::input(
                source,
                el,
                "DimSize must come before a multi-file ElementDataFile",
            )
        })?;
        Ok(dims[sub..].iter().fold(1usize, |n, &d| n.saturating_mul(d)))
    };
    if toks.first().is_some_and(|t| t.eq_ignore_ascii_case("list")) {
        let sub = subdim(toks.get(1))?;
        let max = slabs(sub)?;
        let mut files = Vec::new();
        for line in rest {
            let name = String::from_utf8_lossy(line);
            let name = name.trim();
            if name.is_empty() {
                continue;
            }
            if files.len() == max {
                return Err(Error::input(
                    source,
                    el,
                    format!(
                        "the ElementDataFile LIST names more than the {max} files DimSize needs"
                    ),
                ));
            }
            files.push(dir.join(name));
        }
        return Ok(DataFiles::Files { files, subdim: sub });
    }
    if toks.len() >= 4 && toks.len() <= 5 && toks[0].contains('%') {
        let sub = subdim(toks.get(4))?;
        let int = |k: usize, what: &str| number::<i64>(toks[k], what, source, el);
        let files = pattern_files(
            toks[0],
            int(1, "ElementDataFile min")?,
            int(2, "ElementDataFile max")?,
            int(3, "ElementDataFile step")?,
            slabs(sub)?,
            dir,
        )
        .map_err(|p| Error::input(source, el, p))?;
        return Ok(DataFiles::Files { files, subdim: sub });
    }
    if value.is_empty() {
        return Err(Error::input(source, el, "empty ElementDataFile"));
    }
    Ok(DataFiles::Files {
        files: vec![dir.join(value)],
        subdim: 3,
    })
}
