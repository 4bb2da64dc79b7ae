//! NRRD reader (`.nrrd` with attached data, `.nhdr` detached), hand-written
//! because no maintained Rust crate reads NRRD, let alone its multi-file
//! forms.
//!
//! Follows the NRRD0001–NRRD0005 format definition: `field: value` lines
//! (`key:=value` pairs and `#` comments are skipped) up to a blank line or
//! the end of a detached header. Read: `dimension` (3), `type` (every NRRD
//! spelling of the 8-to-32-bit integers, `float`, `double`), `encoding`
//! (`raw`, `gzip`/`gz`, `ascii`/`text`/`txt`), `endian`, `sizes`, `spacings`
//! or a diagonal `space directions`, `space origin`, `line skip`,
//! `byte skip` (-1 for "data at the end" with raw encoding) and
//! `data file` in its three forms: one file, `LIST [subdim]` followed by one
//! name per line, and `fmt min max step [subdim]` with one `%d` conversion.
//! Other fields describe the data (labels, units, kinds, ...) and are
//! ignored.

use std::path::Path;

use super::data_files::{DataFiles, NRRD, detached};
use super::{
    Compression, Encoding, Payload, ScalarType, Skip, Volume, diagonal, dimension, lines_with_end,
    number, numbers, oriented, read_file, scalar_type, voxel_count,
};
use crate::error::{Error, Result};

/// The fields shapecue uses, as read from the header.
#[derive(Default)]
struct Header {
    dimension: Option<usize>,
    scalar: Option<ScalarType>,
    encoding: Option<Encoding>,
    big_endian: Option<bool>,
    sizes: Option<[usize; 3]>,
    spacings: Option<[f64; 3]>,
    directions: Option<[[f64; 3]; 3]>,
    origin: Option<[f64; 3]>,
    line_skip: usize,
    byte_skip: Option<Skip>,
    data: Option<DataFiles>,
}

/// Loads a `.nrrd` or `.nhdr` file.
pub(super) fn load(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let dir = path.parent().unwrap_or(Path::new(""));
    let h = parse_header(&bytes, &source, dir)?;
    let src = source.as_str();
    let missing =
        |field: &str| Error::input(src, "header", format!("missing required field '{field}'"));
    if h.dimension.is_none() {
        return Err(missing("dimension"));
    }
    let dims = h.sizes.ok_or_else(|| missing("sizes"))?;
    let scalar = h.scalar.ok_or_else(|| missing("type"))?;
    let encoding = h.encoding.ok_or_else(|| missing("encoding"))?;
    let big_endian = match h.big_endian {
        Some(b) => b,
        // Single bytes and text have no byte order.
        None if scalar.size() == 1 || encoding == Encoding::Ascii => false,
        None => return Err(missing("endian")),
    };
    let total = voxel_count(dims, src, "sizes")?;
    let data = h.data.ok_or_else(|| {
        Error::input(
            src,
            "header",
            "no 'data file' field, and no blank line before attached data",
        )
    })?;
    let chunk_shape = data.chunk_shape(&NRRD, dims, total, src)?;
    let payload = Payload {
        source: src,
        dims,
        scalar,
        big_endian,
        encoding,
        line_skip: h.line_skip,
        byte_skip: h.byte_skip.unwrap_or(Skip::Bytes(0)),
        chunk_shape,
    };
    if payload.byte_skip == Skip::ToEnd && encoding != Encoding::Raw {
        return Err(Error::input(
            src,
            "byte skip",
            "-1 (data at the end of the file) is only valid with raw encoding",
        ));
    }
    let values = data.read(&NRRD, &payload, &bytes)?;
    let steps = match (h.directions, h.spacings) {
        (Some(axes), _) => diagonal(axes).ok_or_else(|| Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!(
                "space directions: {} are not axis-aligned: shapecue reads grids whose \
                 axes follow x, y and z (resample the volume first)",
                axes.iter()
                    .map(|a| format!("({})", crate::error::values(a, ",")))
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        })?,
        (None, Some(s)) => s,
        (None, None) => [1.0; 3],
    };
    oriented(dims, values, steps, h.origin.unwrap_or([0.0; 3]), src)
}

/// Reads the header fields up to the blank line (or the end of the file).
fn parse_header(bytes: &[u8], source: &str, dir: &Path) -> Result<Header> {
    let mut lines = lines_with_end(bytes).enumerate();
    let magic = lines.next().map(|(_, (l, _))| l).unwrap_or_default();
    check_magic(magic, source)?;
    let mut h = Header::default();
    while let Some((i, (line, end))) = lines.next() {
        let element = format!("header line {}", i + 1);
        let el = element.as_str();
        if line.is_empty() {
            // The blank line ends the header; attached data follows it.
            if h.data.is_none() {
                h.data = Some(DataFiles::Attached(end));
            }
            break;
        }
        let line = std::str::from_utf8(line)
            .map_err(|_| Error::input(source, el, "not text (a blank line must end the header)"))?;
        if line.starts_with('#') {
            continue;
        }
        if line.contains(":=") && !line.contains(": ") {
            continue; // key:=value pair
        }
        let (key, value) = line.split_once(": ").ok_or_else(|| {
            Error::input(
                source,
                el,
                format!("expected 'field: value', found '{line}'"),
            )
        })?;
        let value = value.trim();
        let field = key.trim().to_ascii_lowercase();
        if field == "data file" || field == "datafile" {
            let rest = lines.by_ref().map(|(_, (l, _))| l);
            h.data = Some(detached(&NRRD, value, rest, h.sizes, dir, source, el)?);
        } else {
            read_field(&mut h, &field, value, source, el)?;
        }
    }
    Ok(h)
}

/// Checks the first line is a NRRD magic, `NRRD000X`.
fn check_magic(magic: &[u8], source: &str) -> Result<()> {
    let is_nrrd = magic.len() == 8
        && magic.starts_with(b"NRRD000")
        && magic.last().is_some_and(u8::is_ascii_digit);
    if is_nrrd {
        return Ok(());
    }
    Err(Error::input(
        source,
        "header line 1",
        format!(
            "not a NRRD file: expected 'NRRD000X', found '{}'",
            String::from_utf8_lossy(&magic[..magic.len().min(40)])
        ),
    ))
}

/// Reads one `field: value` line (other than `data file`) into `h`.
fn read_field(h: &mut Header, field: &str, value: &str, source: &str, el: &str) -> Result<()> {
    match field {
        "dimension" => {
            // Before `sizes`, whose count depends on it.
            h.dimension = Some(dimension(value, "dimension", Path::new(source), el)?);
        }
        "type" => h.scalar = Some(scalar_type(value, source, el)?),
        "encoding" => h.encoding = Some(encoding(value, source, el)?),
        "endian" => h.big_endian = Some(endian(value, source, el)?),
        "sizes" => h.sizes = Some(numbers(value, "sizes", source, el)?),
        "spacings" => h.spacings = Some(numbers(value, "spacings", source, el)?),
        "space directions" => h.directions = Some(directions(value, source, el)?),
        "space origin" => h.origin = Some(vector(value, "space origin", source, el)?),
        "space dimension" => {
            let d: usize = number(value, "space dimension", source, el)?;
            if d != 3 {
                return Err(Error::input(
                    source,
                    el,
                    format!("space dimension {d}: shapecue reads 3-D volumes only"),
                ));
            }
        }
        "line skip" | "lineskip" => h.line_skip = number(value, "line skip", source, el)?,
        "byte skip" | "byteskip" => {
            h.byte_skip = Some(Skip::parse(value, "byte skip", source, el)?)
        }
        _ => {} // descriptive fields: content, kinds, labels, units, ...
    }
    Ok(())
}

/// Parses an `endian` value: true for big-endian.
fn endian(value: &str, source: &str, el: &str) -> Result<bool> {
    match value.to_ascii_lowercase().as_str() {
        "little" => Ok(false),
        "big" => Ok(true),
        _ => Err(Error::input(
            source,
            el,
            format!("endian '{value}' is neither 'little' nor 'big'"),
        )),
    }
}

/// Parses an `encoding` value.
fn encoding(value: &str, source: &str, el: &str) -> Result<Encoding> {
    Ok(match value.to_ascii_lowercase().as_str() {
        "raw" => Encoding::Raw,
        "gzip" | "gz" => Encoding::Compressed(Compression::Gzip),
        "ascii" | "text" | "txt" => Encoding::Ascii,
        other => {
            return Err(Error::input(
                source,
                el,
                format!("encoding '{other}' is not supported (shapecue reads raw, gzip and ascii)"),
            ));
        }
    })
}

/// Parses `(x,y,z)`.
fn vector(value: &str, what: &str, source: &str, el: &str) -> Result<[f64; 3]> {
    let inner = value
        .trim()
        .strip_prefix('(')
        .and_then(|v| v.strip_suffix(')'))
        .ok_or_else(|| {
            Error::input(
                source,
                el,
                format!("{what}: expected a vector '(x,y,z)', found '{value}'"),
            )
        })?;
    numbers(&inner.replace(',', " "), what, source, el)
}

/// Parses `space directions`: three vectors (one per axis).
fn directions(value: &str, source: &str, el: &str) -> Result<[[f64; 3]; 3]> {
    // Vectors may contain spaces after the commas: split on ')' instead.
    let parts: Vec<String> = value
        .split_inclusive(')')
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(str::to_string)
        .collect();
    if value.to_ascii_lowercase().contains("none") {
        return Err(Error::input(
            source,
            el,
            "space directions: a 'none' axis (non-spatial axis) is not supported",
        ));
    }
    if parts.len() != 3 {
        return Err(Error::input(
            source,
            el,
            format!("space directions: expected 3 vectors, found '{value}'"),
        ));
    }
    let mut axes = [[0.0; 3]; 3];
    for (axis, part) in axes.iter_mut().zip(&parts) {
        *axis = vector(part, "space directions", source, el)?;
    }
    Ok(axes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn header_fields() {
        let text = b"NRRD0004\n# comment\nkey:=v\ndimension: 3\ntype: unsigned short\n\
sizes: 2 3 4\nspace directions: (2,0,0) (0, 3, 0) (0,0,-1)\nspace origin: (1,2,3)\n\
endian: big\nencoding: gz\n\nDATA";
        let h = parse_header(text, "t", Path::new("")).unwrap();
        assert_eq!(h.scalar, Some(ScalarType::U16));
        assert_eq!(h.sizes, Some([2, 3, 4]));
        assert_eq!(h.big_endian, Some(true));
        assert_eq!(h.encoding, Some(Encoding::Compressed(Compression::Gzip)));
        assert_eq!(
            h.directions,
            Some([[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, -1.0]])
        );
        assert_eq!(h.origin, Some([1.0, 2.0, 3.0]));
        match h.data {
            Some(DataFiles::Attached(o)) => assert_eq!(&text[o..], b"DATA"),
            _ => panic!("expected attached data"),
        }
    }

    #[test]
    fn list_and_pattern_data_files() {
        let text = b"NRRD0004\nsizes: 2 2 3\ndata file: LIST\na\nb\n\nc\n";
        let h = parse_header(text, "t", Path::new("d")).unwrap();
        match h.data {
            Some(DataFiles::Detached { files, subdim }) => {
                assert_eq!(subdim, 2);
                assert_eq!(files, ["d/a", "d/b", "d/c"].map(PathBuf::from));
            }
            _ => panic!("expected a list"),
        }
        let text = b"NRRD0004\nsizes: 2 2 3\ndata file: s%02d 1 5 2 2\n";
        let h = parse_header(text, "t", Path::new("")).unwrap();
        match h.data {
            Some(DataFiles::Detached { files, .. }) => {
                assert_eq!(files, ["s01", "s03", "s05"].map(PathBuf::from));
            }
            _ => panic!("expected a pattern"),
        }
        let text = b"NRRD0004\nsizes: 2 2 3\ndata file: s%02d 1 5 1\n";
        assert!(parse_header(text, "t", Path::new("")).is_err());
    }
}
