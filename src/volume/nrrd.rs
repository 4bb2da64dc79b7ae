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

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use super::{
    Compression, Encoding, Payload, ScalarType, Skip, Volume, diagonal, lines_with_end, number,
    oriented, pattern_files, read_file, scalar_type, three, voxel_count,
};
use crate::error::{Error, Result};

/// Where the samples are.
enum DataFiles {
    /// After the header's blank line, at this byte offset.
    Attached(usize),
    /// In these files, each holding an equal share along the slowest axes;
    /// `subdim` is the number of fast axes one file holds in full.
    Detached { files: Vec<PathBuf>, subdim: usize },
}

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
    let chunk_shape = match &data {
        DataFiles::Attached(_) => dims.to_vec(),
        DataFiles::Detached { files, subdim } => {
            let shape = dims[..*subdim].to_vec();
            let per_file: usize = shape.iter().product();
            if files.len() != total / per_file {
                return Err(Error::input(
                    src,
                    "data file",
                    format!(
                        "{} data files for {} slabs of {} samples ({} grid, {subdim} axes per file)",
                        files.len(),
                        total / per_file,
                        per_file,
                        super::dims_text(dims),
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
    let values = match data {
        DataFiles::Attached(offset) => {
            let attached = bytes.get(offset..).unwrap_or_default();
            payload.read([Ok((Cow::Borrowed(attached), "attached data".to_string()))])?
        }
        DataFiles::Detached { files, .. } => payload.read(files.iter().map(|f| {
            let data = read_file(f)?;
            Ok((Cow::Owned(data), format!("data file {}", f.display())))
        }))?,
    };
    let steps = match (h.directions, h.spacings) {
        (Some(axes), _) => diagonal(axes).ok_or_else(|| Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!(
                "space directions {axes:?} are not axis-aligned: shapecue reads grids whose \
                 axes follow x, y and z (resample the volume first)"
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
    let is_nrrd = magic.len() == 8
        && magic.starts_with(b"NRRD000")
        && magic.last().is_some_and(u8::is_ascii_digit);
    if !is_nrrd {
        return Err(Error::input(
            source,
            "header line 1",
            format!(
                "not a NRRD file: expected 'NRRD000X', found '{}'",
                String::from_utf8_lossy(&magic[..magic.len().min(40)])
            ),
        ));
    }
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
        match field.as_str() {
            "dimension" => {
                let d: usize = number(value, "dimension", source, el)?;
                if d != 3 {
                    // Before `sizes`, whose count depends on it.
                    return Err(Error::UnsupportedFormat {
                        path: source.into(),
                        problem: format!("dimension {d}: shapecue reads 3-D volumes only"),
                    });
                }
                h.dimension = Some(d);
            }
            "type" => h.scalar = Some(scalar_type(value, source, el)?),
            "encoding" => h.encoding = Some(encoding(value, source, el)?),
            "endian" => {
                h.big_endian = Some(match value.to_ascii_lowercase().as_str() {
                    "little" => false,
                    "big" => true,
                    _ => {
                        return Err(Error::input(
                            source,
                            el,
                            format!("endian '{value}' is neither 'little' nor 'big'"),
                        ));
                    }
                })
            }
            "sizes" => h.sizes = Some(three(value, "sizes", source, el)?),
            "spacings" => h.spacings = Some(three(value, "spacings", source, el)?),
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
                let n: i64 = number(value, "byte skip", source, el)?;
                h.byte_skip = Some(match usize::try_from(n) {
                    Ok(n) => Skip::Bytes(n),
                    Err(_) if n == -1 => Skip::ToEnd,
                    Err(_) => {
                        return Err(Error::input(
                            source,
                            el,
                            format!("byte skip {n} must be -1 or at least 0"),
                        ));
                    }
                })
            }
            "data file" | "datafile" => {
                let rest = lines.by_ref().map(|(_, (l, _))| l);
                h.data = Some(data_files(value, rest, h.sizes, dir, source, el)?);
            }
            _ => {} // descriptive fields: content, kinds, labels, units, ...
        }
    }
    Ok(h)
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

/// Parses the `data file` field. `rest` yields the header lines after it
/// (the names of a `LIST`). `sizes` must come first (as the format requires
/// of every field before `data file`) so that a pattern can be bounded.
fn data_files<'a>(
    value: &str,
    rest: impl Iterator<Item = &'a [u8]>,
    sizes: Option<[usize; 3]>,
    dir: &Path,
    source: &str,
    el: &str,
) -> Result<DataFiles> {
    let toks: Vec<&str> = value.split_whitespace().collect();
    let subdim = |tok: Option<&&str>| -> Result<usize> {
        match tok {
            None => Ok(2),
            Some(t) => {
                let d: usize = number(t, "data file subdim", source, el)?;
                if (1..=3).contains(&d) {
                    Ok(d)
                } else {
                    Err(Error::input(
                        source,
                        el,
                        format!("data file subdim {d} must be 1, 2 or 3"),
                    ))
                }
            }
        }
    };
    let slabs = |sub: usize| -> Result<usize> {
        let sizes = sizes.ok_or_else(|| {
            Error::input(
                source,
                el,
                "'sizes' must come before a multi-file 'data file'",
            )
        })?;
        Ok(sizes[sub..]
            .iter()
            .fold(1usize, |n, &d| n.saturating_mul(d)))
    };
    if toks.first().is_some_and(|t| *t == "LIST") {
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
                    format!("the data file LIST names more than the {max} files the sizes need"),
                ));
            }
            files.push(dir.join(name));
        }
        return Ok(DataFiles::Detached { files, subdim: sub });
    }
    if toks.len() >= 4 && toks[0].contains('%') {
        if toks.len() > 5 {
            return Err(Error::input(
                source,
                el,
                format!("expected 'format min max step [subdim]', found '{value}'"),
            ));
        }
        let sub = subdim(toks.get(4))?;
        let int = |k: usize, what: &str| number::<i64>(toks[k], what, source, el);
        let files = pattern_files(
            toks[0],
            int(1, "data file min")?,
            int(2, "data file max")?,
            int(3, "data file step")?,
            slabs(sub)?,
            dir,
        )
        .map_err(|p| Error::input(source, el, p))?;
        return Ok(DataFiles::Detached { files, subdim: sub });
    }
    if value.is_empty() {
        return Err(Error::input(source, el, "empty data file name"));
    }
    Ok(DataFiles::Detached {
        files: vec![dir.join(value)],
        subdim: 3,
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
    three(&inner.replace(',', " "), what, source, el)
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
