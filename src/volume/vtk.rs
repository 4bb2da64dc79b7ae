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

use base64::Engine as _;
use quick_xml::events::{BytesStart, Event};

use super::{
    Compression, MAX_INFLATE, ScalarType, Volume, byte_count, check_inflate, convert_into,
    decompress, diagonal, dims_text, number, numbers, oriented, parse_ascii_into, read_file,
    scalar_type, size_problem, voxel_count,
};
use crate::error::{Error, Result};

// ---------------------------------------------------------------------------
// Legacy
// ---------------------------------------------------------------------------

/// Loads a legacy `.vtk` file holding `STRUCTURED_POINTS` point scalars.
pub(super) fn load_legacy(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let src = source.as_str();
    let unsupported = |problem: String| Error::UnsupportedFormat {
        path: path.to_path_buf(),
        problem,
    };

    // Header lines, with their numbers, advancing `pos` past each.
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut next_line = |pos: &mut usize| -> Option<(usize, &[u8])> {
        let rest = bytes.get(*pos..).filter(|r| !r.is_empty())?;
        let len = rest.iter().position(|&b| b == b'\n');
        *pos += len.map_or(rest.len(), |l| l + 1);
        line_no += 1;
        let line = &rest[..len.unwrap_or(rest.len())];
        Some((line_no, line.strip_suffix(b"\r").unwrap_or(line)))
    };
    let text = |n: usize, line: &[u8]| -> Result<String> {
        std::str::from_utf8(line)
            .map(|l| l.trim().to_string())
            .map_err(|_| Error::input(src, format!("header line {n}"), "not text"))
    };

    let (n, first) =
        next_line(&mut pos).ok_or_else(|| Error::input(src, "header line 1", "empty file"))?;
    if !first.to_ascii_lowercase().starts_with(b"# vtk datafile") {
        return Err(Error::input(
            src,
            format!("header line {n}"),
            "not a legacy VTK file: expected '# vtk DataFile Version x.x'",
        ));
    }
    next_line(&mut pos).ok_or_else(|| Error::input(src, "header line 2", "missing title"))?;
    // VTK's reader skips blank lines before the keyword (ironProt.vtk has one).
    let (n, mode) = std::iter::from_fn(|| next_line(&mut pos))
        .find(|(_, l)| !l.trim_ascii().is_empty())
        .ok_or_else(|| Error::input(src, "header", "missing ASCII or BINARY"))?;
    let binary = match text(n, mode)?.to_ascii_uppercase().as_str() {
        "BINARY" => true,
        "ASCII" => false,
        other => {
            return Err(Error::input(
                src,
                format!("header line {n}"),
                format!("expected ASCII or BINARY, found '{other}'"),
            ));
        }
    };

    let mut structured = false;
    let mut dims: Option<[usize; 3]> = None;
    let mut spacing = [1.0; 3];
    let mut origin = [0.0; 3];
    let mut point_data: Option<usize> = None;
    let mut scalars: Option<(ScalarType, String)> = None;
    while let Some((n, line)) = next_line(&mut pos) {
        let el = format!("header line {n}");
        let line = text(n, line)?;
        let toks: Vec<&str> = line.split_whitespace().collect();
        let Some(kw) = toks.first().map(|k| k.to_ascii_uppercase()) else {
            continue;
        };
        let args = line[toks[0].len()..].trim();
        match kw.as_str() {
            "DATASET" => {
                let kind = toks.get(1).copied().unwrap_or("");
                if !kind.eq_ignore_ascii_case("STRUCTURED_POINTS") {
                    return Err(unsupported(format!(
                        "DATASET {kind}: shapecue reads STRUCTURED_POINTS volumes only"
                    )));
                }
                structured = true;
            }
            "DIMENSIONS" => dims = Some(numbers(args, "DIMENSIONS", src, &el)?),
            "SPACING" | "ASPECT_RATIO" => spacing = numbers(args, &kw, src, &el)?,
            "ORIGIN" => origin = numbers(args, "ORIGIN", src, &el)?,
            "POINT_DATA" => point_data = Some(number(args, "POINT_DATA", src, &el)?),
            "SCALARS" if point_data.is_some() => {
                let ty = toks.get(2).ok_or_else(|| {
                    Error::input(
                        src,
                        el.as_str(),
                        "expected 'SCALARS name type [components]'",
                    )
                })?;
                let scalar = scalar_type(ty, src, &el)?;
                if let Some(c) = toks.get(3) {
                    let c: usize = number(c, "SCALARS components", src, &el)?;
                    if c != 1 {
                        return Err(unsupported(format!(
                            "SCALARS with {c} components: shapecue reads one component"
                        )));
                    }
                }
                scalars = Some((scalar, el));
                break;
            }
            "METADATA" | "INFORMATION" | "NAME" | "DATA" => {}
            other => {
                let what = if point_data.is_some() {
                    format!("{other} before the point SCALARS")
                } else {
                    format!("{other} before POINT_DATA")
                };
                return Err(unsupported(format!(
                    "{el}: {what} is not supported (shapecue reads the first point scalars \
                     of a STRUCTURED_POINTS file)"
                )));
            }
        }
    }

    let missing = |what: &str| Error::input(src, "header", format!("missing {what}"));
    if !structured {
        return Err(missing("DATASET STRUCTURED_POINTS"));
    }
    let dims = dims.ok_or_else(|| missing("DIMENSIONS"))?;
    let count = voxel_count(dims, src, "DIMENSIONS")?;
    let n_points = point_data.ok_or_else(|| missing("POINT_DATA"))?;
    let (scalar, el) = scalars.ok_or_else(|| missing("SCALARS (under POINT_DATA)"))?;
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
    // The lookup table line is optional in practice; the data follow it.
    let rest = &bytes[pos.min(bytes.len())..];
    let skip_ws = if binary {
        0
    } else {
        rest.iter().take_while(|b| b.is_ascii_whitespace()).count()
    };
    if rest[skip_ws..]
        .get(..12)
        .is_some_and(|k| k.eq_ignore_ascii_case(b"LOOKUP_TABLE"))
    {
        next_line(&mut pos);
    }
    let data = bytes.get(pos..).unwrap_or_default();
    let mut values = Vec::new();
    if binary {
        let expected = byte_count(count, scalar, src, &el)?;
        let Some(data) = data.get(..expected) else {
            return Err(Error::input(
                src,
                "scalars",
                size_problem(&dims, scalar, data.len()),
            ));
        };
        values.reserve_exact(count);
        convert_into(data, scalar, true, &mut values);
    } else {
        parse_ascii_into(data, count, &mut values, src, "scalars")?;
    }
    oriented(dims, values, spacing, origin, src)
}

// ---------------------------------------------------------------------------
// XML ImageData
// ---------------------------------------------------------------------------

/// How a `DataArray` stores its values.
#[derive(Clone, Debug, PartialEq)]
enum Format {
    Ascii,
    /// Inline base64.
    Binary,
    /// In `<AppendedData>` at this offset.
    Appended(usize),
}

/// The `DataArray` that is read, and its inline text.
struct Array {
    name: String,
    scalar: ScalarType,
    format: Format,
    text: String,
}

/// Header fields from the XML.
struct Xml {
    big_endian: bool,
    header64: bool,
    zlib: bool,
    extent: Option<[i64; 6]>,
    origin: [f64; 3],
    spacing: [f64; 3],
    direction: [f64; 9],
    pieces: usize,
    piece_extent: Option<[i64; 6]>,
    array: Option<Array>,
    /// Offsets of every appended array, to bound base64 segments.
    offsets: Vec<usize>,
    /// `encoding` of `<AppendedData>` and where its data start (after `_`).
    appended: Option<(bool, usize)>,
}

/// Loads a VTK XML ImageData (`.vti`) file.
pub(super) fn load_xml(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let src = source.as_str();
    let unsupported = |problem: String| Error::UnsupportedFormat {
        path: path.to_path_buf(),
        problem,
    };

    // The XML part ends with the start tag of <AppendedData>; what follows
    // may be raw binary, which no XML parser accepts.
    const TAG: &[u8] = b"<AppendedData";
    let appended_at = bytes.windows(TAG.len()).position(|w| w == TAG);
    let xml_end = appended_at
        .and_then(|a| {
            bytes[a..]
                .iter()
                .position(|&b| b == b'>')
                .map(|e| a + e + 1)
        })
        .unwrap_or(bytes.len());
    let xml = std::str::from_utf8(&bytes[..xml_end]).map_err(|e| {
        Error::input(
            src,
            "XML",
            format!("not UTF-8 text at byte {}", e.valid_up_to()),
        )
    })?;
    let mut x = parse_xml(xml, src, path)?;
    if let Some((base64, _)) = x.appended {
        // Data start after the '_' that follows the start tag.
        let rest = &bytes[xml_end..];
        let underscore = rest.iter().position(|b| !b.is_ascii_whitespace());
        match underscore {
            Some(u) if rest[u] == b'_' => x.appended = Some((base64, xml_end + u + 1)),
            _ => {
                return Err(Error::input(
                    src,
                    "AppendedData",
                    "expected '_' before the appended data",
                ));
            }
        }
    }

    let e = x
        .extent
        .ok_or_else(|| Error::input(src, "ImageData", "missing WholeExtent"))?;
    let dims: [usize; 3] = std::array::from_fn(|i| {
        e[2 * i + 1]
            .checked_sub(e[2 * i])
            .and_then(|d| d.checked_add(1))
            .and_then(|d| usize::try_from(d).ok())
            .unwrap_or(0)
    });
    let count = voxel_count(dims, src, "WholeExtent")?;
    if x.pieces > 1 {
        return Err(unsupported(format!(
            "{} pieces: shapecue reads ImageData with one piece",
            x.pieces
        )));
    }
    if let Some(p) = x.piece_extent.filter(|p| *p != e) {
        return Err(unsupported(format!(
            "a Piece with Extent \"{}\" smaller than the WholeExtent \"{}\" is not supported",
            crate::error::values(p, " "),
            crate::error::values(e, " ")
        )));
    }
    let array = x
        .array
        .take()
        .ok_or_else(|| Error::input(src, "PointData", "no DataArray to read"))?;
    let el = format!("DataArray '{}'", array.name);
    let expected = byte_count(count, array.scalar, src, &el)?;
    let mut values = Vec::new();
    let raw: Vec<u8> = match &array.format {
        Format::Ascii => {
            parse_ascii_into(array.text.as_bytes(), count, &mut values, src, &el)?;
            Vec::new()
        }
        Format::Binary => base64_streams(array.text.as_bytes())
            .and_then(|d| binary_array(&d, &x, expected))
            .map_err(|p| Error::input(src, el.as_str(), p))?,
        Format::Appended(offset) => {
            let (base64, start) = x.appended.ok_or_else(|| {
                Error::input(src, el.as_str(), "format 'appended' without <AppendedData>")
            })?;
            let at = start.checked_add(*offset).filter(|&a| a <= bytes.len());
            let at = at.ok_or_else(|| {
                Error::input(
                    src,
                    el.as_str(),
                    format!("offset {offset} is past the end of the file"),
                )
            })?;
            let res = if base64 {
                // The segment ends at the next array's offset, or at the
                // end of the base64 text.
                let next = x
                    .offsets
                    .iter()
                    .filter(|&&o| o > *offset)
                    .min()
                    .map(|o| start.saturating_add(*o).min(bytes.len()));
                let end = next.unwrap_or_else(|| {
                    bytes[at..]
                        .iter()
                        .position(|&b| b == b'<')
                        .map_or(bytes.len(), |p| at + p)
                });
                base64_streams(&bytes[at..end.max(at)]).and_then(|d| binary_array(&d, &x, expected))
            } else {
                binary_array(&bytes[at..], &x, expected)
            };
            res.map_err(|p| Error::input(src, el.as_str(), p))?
        }
    };
    if array.format != Format::Ascii {
        if raw.len() != expected {
            return Err(Error::input(
                src,
                el.as_str(),
                size_problem(&dims, array.scalar, raw.len()),
            ));
        }
        values.reserve_exact(count);
        convert_into(&raw, array.scalar, x.big_endian, &mut values);
    }

    let axes = [
        [x.direction[0], x.direction[3], x.direction[6]],
        [x.direction[1], x.direction[4], x.direction[7]],
        [x.direction[2], x.direction[5], x.direction[8]],
    ];
    let d = diagonal(axes).ok_or_else(|| {
        unsupported(format!(
            "Direction \"{}\" is not axis-aligned: shapecue reads grids whose axes follow x, \
             y and z (resample the volume first)",
            crate::error::values(x.direction, " ")
        ))
    })?;
    let steps: [f64; 3] = std::array::from_fn(|i| x.spacing[i] * d[i]);
    // Sample (0,0,0) is the extent's first index, not necessarily 0.
    let origin: [f64; 3] = std::array::from_fn(|i| x.origin[i] + steps[i] * e[2 * i] as f64);
    oriented(dims, values, steps, origin, src)
}

/// Reads the header fields and the chosen array from the XML text.
fn parse_xml(xml: &str, src: &str, path: &Path) -> Result<Xml> {
    let unsupported = |problem: String| Error::UnsupportedFormat {
        path: path.to_path_buf(),
        problem,
    };
    let mut x = Xml {
        big_endian: false,
        header64: false,
        zlib: false,
        extent: None,
        origin: [0.0; 3],
        spacing: [1.0; 3],
        direction: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        pieces: 0,
        piece_extent: None,
        array: None,
        offsets: Vec::new(),
        appended: None,
    };
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut seen_root = false;
    let mut in_point_data = false;
    let mut wanted: Option<String> = None;
    // Text of the array being read, while inside it.
    let mut capturing = false;
    loop {
        let ev = reader.read_event().map_err(|e| {
            Error::input(
                src,
                "XML",
                format!("at byte {}: {e}", reader.error_position()),
            )
        })?;
        let (start, empty) = match &ev {
            Event::Start(s) => (Some(s), false),
            Event::Empty(s) => (Some(s), true),
            _ => (None, false),
        };
        if let Some(s) = start {
            let name = s.name().as_ref().to_string();
            let attr = |key: &str| attribute(s, key, src, &name);
            if !seen_root && name != "VTKFile" {
                return Err(Error::input(
                    src,
                    "XML",
                    "the root element is not <VTKFile>",
                ));
            }
            match name.as_str() {
                "VTKFile" => {
                    seen_root = true;
                    let ty = attr("type")?.unwrap_or_default();
                    if ty != "ImageData" {
                        return Err(unsupported(format!(
                            "VTK XML type '{ty}': shapecue reads ImageData (.vti) only"
                        )));
                    }
                    let either = |key: &str, default: &str, other: &str| -> Result<bool> {
                        match attr(key)?.as_deref() {
                            None => Ok(false),
                            Some(v) if v == default => Ok(false),
                            Some(v) if v == other => Ok(true),
                            Some(v) => Err(Error::input(
                                src,
                                "VTKFile",
                                format!("{key} '{v}' is neither {default} nor {other}"),
                            )),
                        }
                    };
                    x.big_endian = either("byte_order", "LittleEndian", "BigEndian")?;
                    x.header64 = either("header_type", "UInt32", "UInt64")?;
                    x.zlib = match attr("compressor")?.as_deref() {
                        None | Some("") => false,
                        Some("vtkZLibDataCompressor") => true,
                        Some(c) => {
                            return Err(unsupported(format!(
                                "compressor '{c}' is not supported (shapecue reads \
                                 uncompressed and vtkZLibDataCompressor data)"
                            )));
                        }
                    };
                }
                "ImageData" => {
                    let el = "ImageData";
                    let ext = attr("WholeExtent")?
                        .ok_or_else(|| Error::input(src, el, "missing WholeExtent"))?;
                    x.extent = Some(numbers(&ext, "extent", src, el)?);
                    if let Some(o) = attr("Origin")? {
                        x.origin = numbers(&o, "Origin", src, el)?;
                    }
                    if let Some(s) = attr("Spacing")? {
                        x.spacing = numbers(&s, "Spacing", src, el)?;
                    }
                    if let Some(d) = attr("Direction")? {
                        let toks: Vec<&str> = d.split_whitespace().collect();
                        if toks.len() != 9 {
                            return Err(Error::input(
                                src,
                                el,
                                format!("Direction: expected 9 values, found {}", toks.len()),
                            ));
                        }
                        for (v, t) in x.direction.iter_mut().zip(toks) {
                            *v = number(t, "Direction", src, el)?;
                        }
                    }
                }
                "Piece" => {
                    x.pieces += 1;
                    if let Some(e) = attr("Extent")? {
                        x.piece_extent = Some(numbers(&e, "extent", src, "Piece")?);
                    }
                }
                "PointData" => {
                    in_point_data = !empty;
                    wanted = attr("Scalars")?;
                }
                "DataArray" => {
                    let format = attr("format")?.unwrap_or_else(|| "ascii".into());
                    let offset = match attr("offset")? {
                        Some(o) => Some(number::<usize>(&o, "offset", src, "DataArray")?),
                        None => None,
                    };
                    if format == "appended" {
                        x.offsets.extend(offset);
                    }
                    let array_name = attr("Name")?.unwrap_or_default();
                    let chosen = in_point_data
                        && x.array.is_none()
                        && wanted.as_ref().is_none_or(|w| *w == array_name);
                    if chosen {
                        let el = format!("DataArray '{array_name}'");
                        let ty = attr("type")?
                            .ok_or_else(|| Error::input(src, el.as_str(), "missing type"))?;
                        let scalar = scalar_type(&ty, src, &el)?;
                        if let Some(c) = attr("NumberOfComponents")? {
                            let c: usize = number(&c, "NumberOfComponents", src, &el)?;
                            if c != 1 {
                                return Err(unsupported(format!(
                                    "{el} has {c} components: shapecue reads one"
                                )));
                            }
                        }
                        let format = match format.as_str() {
                            "ascii" => Format::Ascii,
                            "binary" => Format::Binary,
                            "appended" => Format::Appended(offset.ok_or_else(|| {
                                Error::input(src, el.as_str(), "appended without an offset")
                            })?),
                            f => {
                                return Err(Error::input(
                                    src,
                                    el,
                                    format!("unknown format '{f}' (ascii, binary or appended)"),
                                ));
                            }
                        };
                        x.array = Some(Array {
                            name: array_name,
                            scalar,
                            format,
                            text: String::new(),
                        });
                        capturing = !empty;
                    }
                }
                "AppendedData" => {
                    let base64 = match attr("encoding")?.as_deref() {
                        Some("raw") => false,
                        Some("base64") => true,
                        other => {
                            return Err(Error::input(
                                src,
                                "AppendedData",
                                format!("encoding {other:?} is neither 'raw' nor 'base64'"),
                            ));
                        }
                    };
                    x.appended = Some((base64, 0));
                    break;
                }
                _ => {}
            }
            continue;
        }
        match ev {
            Event::Text(t) if capturing => {
                if let Some(a) = x.array.as_mut() {
                    a.text.push_str(&t.into_inner());
                }
            }
            Event::End(e) => match e.name().as_ref() {
                "DataArray" => capturing = false,
                "PointData" => in_point_data = false,
                _ => {}
            },
            Event::Eof => break,
            _ => {}
        }
    }
    if !seen_root {
        return Err(Error::input(src, "XML", "no <VTKFile> element"));
    }
    Ok(x)
}

/// The unescaped value of attribute `key` of `tag`, if present.
fn attribute(tag: &BytesStart<'_>, key: &str, src: &str, element: &str) -> Result<Option<String>> {
    let bad = |e: String| Error::input(src, element, format!("attribute {key}: {e}"));
    match tag.try_get_attribute(key).map_err(|e| bad(e.to_string()))? {
        None => Ok(None),
        Some(a) => a
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map(|v| Some(v.into_owned()))
            .map_err(|e| bad(e.to_string())),
    }
}

/// Decodes base64 text that may be several concatenated encodings (VTK
/// encodes the block header and the data separately, each with its own
/// padding): the text is split after each run of `=` and each part decoded
/// on its own. Whitespace is ignored.
fn base64_streams(text: &[u8]) -> std::result::Result<Vec<u8>, String> {
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    const ENGINE: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new()
            .with_decode_padding_mode(DecodePaddingMode::Indifferent)
            .with_decode_allow_trailing_bits(true),
    );
    let clean: Vec<u8> = text
        .iter()
        .copied()
        .filter(|b| !b.is_ascii_whitespace())
        .collect();
    let mut out = Vec::with_capacity(clean.len() / 4 * 3);
    let mut start = 0;
    while start < clean.len() {
        let mut end = clean[start..]
            .iter()
            .position(|&b| b == b'=')
            .map_or(clean.len(), |p| start + p);
        end += clean[end..].iter().take_while(|&&b| b == b'=').count();
        ENGINE
            .decode_vec(&clean[start..end], &mut out)
            .map_err(|e| format!("invalid base64 data at character {start}: {e}"))?;
        start = end;
    }
    Ok(out)
}

/// Extracts the bytes of one binary array: a `UInt32`/`UInt64` byte count
/// then the data, or, compressed, the block table then zlib blocks.
/// `expected` is the size the extent and type call for; it bounds what is
/// decompressed.
fn binary_array(data: &[u8], x: &Xml, expected: usize) -> std::result::Result<Vec<u8>, String> {
    let hs = if x.header64 { 8 } else { 4 };
    let header = |k: usize| -> std::result::Result<usize, String> {
        let b = k
            .checked_mul(hs)
            .and_then(|o| data.get(o..o.checked_add(hs)?))
            .ok_or_else(|| format!("data end inside the header (header value {k})"))?;
        let v = match (x.header64, x.big_endian) {
            (true, false) => u64::from_le_bytes(b.try_into().unwrap_or_default()),
            (true, true) => u64::from_be_bytes(b.try_into().unwrap_or_default()),
            (false, false) => u32::from_le_bytes(b.try_into().unwrap_or_default()).into(),
            (false, true) => u32::from_be_bytes(b.try_into().unwrap_or_default()).into(),
        };
        usize::try_from(v).map_err(|_| format!("header value {v} is too large"))
    };
    if !x.zlib {
        let n = header(0)?;
        let body = data.get(hs..).unwrap_or_default();
        if n != expected {
            return Err(format!(
                "the array header says {n} bytes, but the extent and type call for {expected}"
            ));
        }
        // A short body is reported by the caller with the sizes.
        return Ok(body[..n.min(body.len())].to_vec());
    }
    let blocks = header(0)?;
    let block_size = header(1)?;
    let last = header(2)?;
    if blocks > data.len() / hs {
        return Err(format!(
            "the header declares {blocks} compressed blocks, more than fit"
        ));
    }
    let total = match blocks {
        0 => Some(0),
        b => (b - 1)
            .checked_mul(block_size)
            .and_then(|t| t.checked_add(if last == 0 { block_size } else { last })),
    };
    let total = total.ok_or_else(|| "the compressed block sizes overflow".to_string())?;
    if total != expected {
        return Err(format!(
            "the compression header says {total} bytes, but the extent and type call for \
             {expected}"
        ));
    }
    let mut at = (3 + blocks) * hs;
    // The memory bound: the blocks are inflated one by one, each checked
    // against the deflate ratio, so room is reserved only for what the
    // compressed bytes can hold.
    let mut out = Vec::with_capacity(expected.min(data.len().saturating_mul(MAX_INFLATE)));
    for b in 0..blocks {
        let size = header(3 + b)?;
        let block = at
            .checked_add(size)
            .and_then(|end| data.get(at..end))
            .ok_or_else(|| format!("compressed block {b} ends past the end of the data"))?;
        at += size;
        let want = if b + 1 == blocks && last != 0 {
            last
        } else {
            block_size
        };
        check_inflate(block.len(), want, Compression::Zlib)
            .map_err(|e| format!("block {b}: {e}"))?;
        let d = decompress(block, Compression::Zlib, want.saturating_add(1))
            .map_err(|e| format!("block {b}: {e}"))?;
        if d.len() != want {
            return Err(format!(
                "block {b} decompresses to {} bytes, expected {want}",
                d.len()
            ));
        }
        out.extend_from_slice(&d);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concatenated_base64() {
        // "ab" and "cde" encoded separately, with whitespace.
        assert_eq!(base64_streams(b"YWI=\n Y2Rl").unwrap(), b"abcde");
        assert_eq!(base64_streams(b"YQ==YWI=").unwrap(), b"aab");
        assert!(base64_streams(b"Y*").is_err());
    }
}
