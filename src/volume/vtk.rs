//! VTK image readers: the legacy format (`DATASET STRUCTURED_POINTS`, ASCII
//! or BINARY) and the XML ImageData format (`.vti`).
//!
//! Hand-written rather than through `vtkio`: that crate's current line is a
//! pre-release whose nom errors carry no file or element context, and it
//! parses binary legacy arrays value by value. Here:
//!
//! * legacy: the header lines up to `SCALARS name type [1]` (and its
//!   optional `LOOKUP_TABLE`) under `POINT_DATA`; `DIMENSIONS`, `SPACING`
//!   (or `ASPECT_RATIO`), `ORIGIN`. Binary data is big-endian, as the VTK
//!   file-format document specifies. Arrays other than the first point
//!   scalars (`CELL_DATA`, `FIELD`, `VECTORS` before it) are not read.
//! * XML: `WholeExtent`, `Origin`, `Spacing`, a diagonal `Direction`, one
//!   `Piece`, and the `PointData` array named by its `Scalars` attribute (or
//!   its first array), in `ascii`, inline `binary` (base64) or `appended`
//!   (raw or base64) format, with a `UInt32` or `UInt64` header, optionally
//!   compressed in `vtkZLibDataCompressor` blocks (`[nblocks, block size,
//!   last block size, compressed sizes...]` then zlib streams). The XML
//!   before `<AppendedData>` goes through `quick-xml`; the appended section
//!   is raw bytes and is sliced directly.

use std::path::Path;

use super::{
    ScalarType, Volume, byte_count, convert_into, dims_text, number, numbers, oriented,
    parse_ascii_into, read_file, scalar_type, size_problem, voxel_count,
};
use crate::error::{Error, Result};

mod xml;

pub(super) use xml::load_xml;

// ---------------------------------------------------------------------------
// Legacy
// ---------------------------------------------------------------------------

/// Loads a legacy `.vtk` file holding `STRUCTURED_POINTS` point scalars.
pub(super) fn load_legacy(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let src = source.as_str();
    let mut lines = Lines {
        bytes: &bytes,
        pos: 0,
        line_no: 0,
    };
    let binary = legacy_mode(&mut lines, src)?;
    let mut header = legacy_header(&mut lines, src, path)?;
    let points = legacy_points(&mut header, src)?;
    skip_lookup_table(&mut lines, binary);
    let data = bytes.get(lines.pos..).unwrap_or_default();
    let values = legacy_values(data, binary, &points, src)?;
    oriented(points.dims, values, header.spacing, header.origin, src)
}

/// The error for a file that is valid but outside what shapecue reads.
fn unsupported(path: &Path, problem: String) -> Error {
    Error::UnsupportedFormat {
        path: path.to_path_buf(),
        problem,
    }
}

/// The header lines of a legacy file, numbered, read from its front.
struct Lines<'a> {
    bytes: &'a [u8],
    /// Where the next line starts.
    pos: usize,
    /// The number of the last line read.
    line_no: usize,
}

impl<'a> Lines<'a> {
    /// The next line and its number, without its line end; advances past it.
    fn next_line(&mut self) -> Option<(usize, &'a [u8])> {
        let rest = self.bytes.get(self.pos..).filter(|r| !r.is_empty())?;
        let len = rest.iter().position(|&b| b == b'\n');
        self.pos += len.map_or(rest.len(), |l| l + 1);
        self.line_no += 1;
        let line = &rest[..len.unwrap_or(rest.len())];
        Some((self.line_no, line.strip_suffix(b"\r").unwrap_or(line)))
    }
}

/// The trimmed text of header line `n`, or an error if it is not UTF-8.
fn header_text(n: usize, line: &[u8], src: &str) -> Result<String> {
    std::str::from_utf8(line)
        .map(|l| l.trim().to_string())
        .map_err(|_| Error::input(src, format!("header line {n}"), "not text"))
}

/// Reads the version line, the title and the mode line: true for BINARY.
fn legacy_mode(lines: &mut Lines<'_>, src: &str) -> Result<bool> {
    let (n, first) = lines
        .next_line()
        .ok_or_else(|| Error::input(src, "header line 1", "empty file"))?;
    if !first.to_ascii_lowercase().starts_with(b"# vtk datafile") {
        return Err(Error::input(
            src,
            format!("header line {n}"),
            "not a legacy VTK file: expected '# vtk DataFile Version x.x'",
        ));
    }
    lines
        .next_line()
        .ok_or_else(|| Error::input(src, "header line 2", "missing title"))?;
    // VTK's reader skips blank lines before the keyword (ironProt.vtk has one).
    let (n, mode) = std::iter::from_fn(|| lines.next_line())
        .find(|(_, l)| !l.trim_ascii().is_empty())
        .ok_or_else(|| Error::input(src, "header", "missing ASCII or BINARY"))?;
    match header_text(n, mode, src)?.to_ascii_uppercase().as_str() {
        "BINARY" => Ok(true),
        "ASCII" => Ok(false),
        other => Err(Error::input(
            src,
            format!("header line {n}"),
            format!("expected ASCII or BINARY, found '{other}'"),
        )),
    }
}

/// What the header lines of a legacy file declare, up to the point scalars.
struct LegacyHeader {
    structured: bool,
    dims: Option<[usize; 3]>,
    spacing: [f64; 3],
    origin: [f64; 3],
    point_data: Option<usize>,
    /// The scalar type and the element (header line) that declared it.
    scalars: Option<(ScalarType, String)>,
}

/// Reads the keyword lines after the mode line, up to the point `SCALARS`.
fn legacy_header(lines: &mut Lines<'_>, src: &str, path: &Path) -> Result<LegacyHeader> {
    let mut h = LegacyHeader {
        structured: false,
        dims: None,
        spacing: [1.0; 3],
        origin: [0.0; 3],
        point_data: None,
        scalars: None,
    };
    while let Some((n, line)) = lines.next_line() {
        let el = format!("header line {n}");
        let line = header_text(n, line, src)?;
        let toks: Vec<&str> = line.split_whitespace().collect();
        let Some(kw) = toks.first().map(|k| k.to_ascii_uppercase()) else {
            continue;
        };
        let args = line[toks[0].len()..].trim();
        match kw.as_str() {
            "DATASET" => {
                let kind = toks.get(1).copied().unwrap_or("");
                if !kind.eq_ignore_ascii_case("STRUCTURED_POINTS") {
                    return Err(unsupported(
                        path,
                        format!("DATASET {kind}: shapecue reads STRUCTURED_POINTS volumes only"),
                    ));
                }
                h.structured = true;
            }
            "DIMENSIONS" => h.dims = Some(numbers(args, "DIMENSIONS", src, &el)?),
            "SPACING" | "ASPECT_RATIO" => h.spacing = numbers(args, &kw, src, &el)?,
            "ORIGIN" => h.origin = numbers(args, "ORIGIN", src, &el)?,
            "POINT_DATA" => h.point_data = Some(number(args, "POINT_DATA", src, &el)?),
            "SCALARS" if h.point_data.is_some() => {
                h.scalars = Some((scalars_line(&toks, src, &el, path)?, el));
                break;
            }
            "METADATA" | "INFORMATION" | "NAME" | "DATA" => {}
            other => {
                let what = if h.point_data.is_some() {
                    format!("{other} before the point SCALARS")
                } else {
                    format!("{other} before POINT_DATA")
                };
                return Err(unsupported(
                    path,
                    format!(
                        "{el}: {what} is not supported (shapecue reads the first point scalars \
                         of a STRUCTURED_POINTS file)"
                    ),
                ));
            }
        }
    }
    Ok(h)
}

/// The scalar type of a `SCALARS name type [components]` line (one component).
fn scalars_line(toks: &[&str], src: &str, el: &str, path: &Path) -> Result<ScalarType> {
    let ty = toks
        .get(2)
        .ok_or_else(|| Error::input(src, el, "expected 'SCALARS name type [components]'"))?;
    let scalar = scalar_type(ty, src, el)?;
    if let Some(c) = toks.get(3) {
        let c: usize = number(c, "SCALARS components", src, el)?;
        if c != 1 {
            return Err(unsupported(
                path,
                format!("SCALARS with {c} components: shapecue reads one component"),
            ));
        }
    }
    Ok(scalar)
}

/// The grid and scalars a legacy file holds, checked against each other.
struct LegacyPoints {
    dims: [usize; 3],
    count: usize,
    scalar: ScalarType,
    /// The header line of the `SCALARS` keyword.
    el: String,
}

/// Checks the header declared everything, with as many points as voxels.
fn legacy_points(h: &mut LegacyHeader, src: &str) -> Result<LegacyPoints> {
    let missing = |what: &str| Error::input(src, "header", format!("missing {what}"));
    if !h.structured {
        return Err(missing("DATASET STRUCTURED_POINTS"));
    }
    let dims = h.dims.ok_or_else(|| missing("DIMENSIONS"))?;
    let count = voxel_count(dims, src, "DIMENSIONS")?;
    let n_points = h.point_data.ok_or_else(|| missing("POINT_DATA"))?;
    let (scalar, el) = h
        .scalars
        .take()
        .ok_or_else(|| missing("SCALARS (under POINT_DATA)"))?;
    if n_points != count {
        return Err(Error::input(
            src,
            "POINT_DATA",
            format!(
                "{n_points} points for DIMENSIONS {} ({count} points)",
                dims_text(dims)
            ),
        ));
    }
    Ok(LegacyPoints {
        dims,
        count,
        scalar,
        el,
    })
}

/// Skips the `LOOKUP_TABLE` line, optional in practice, before the data.
fn skip_lookup_table(lines: &mut Lines<'_>, binary: bool) {
    let rest = &lines.bytes[lines.pos.min(lines.bytes.len())..];
    let skip_ws = if binary {
        0
    } else {
        rest.iter().take_while(|b| b.is_ascii_whitespace()).count()
    };
    if rest[skip_ws..]
        .get(..12)
        .is_some_and(|k| k.eq_ignore_ascii_case(b"LOOKUP_TABLE"))
    {
        lines.next_line();
    }
}

/// Reads the point scalars: big-endian binary values or ASCII numbers.
fn legacy_values(data: &[u8], binary: bool, p: &LegacyPoints, src: &str) -> Result<Vec<f32>> {
    let mut values = Vec::new();
    if binary {
        let expected = byte_count(p.count, p.scalar, src, &p.el)?;
        let Some(data) = data.get(..expected) else {
            return Err(Error::input(
                src,
                "scalars",
                size_problem(&p.dims, p.scalar, data.len()),
            ));
        };
        values.reserve_exact(p.count);
        convert_into(data, p.scalar, true, &mut values);
    } else {
        parse_ascii_into(data, p.count, &mut values, src, "scalars")?;
    }
    Ok(values)
}
