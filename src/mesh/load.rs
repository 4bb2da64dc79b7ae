//! Mesh loaders: Wavefront OBJ (through `tobj`), PLY in ASCII and both binary
//! byte orders (through `ply-rs-bw`) and OFF (by hand).
//!
//! Every loader fan-triangulates polygons, keeps degenerate faces and faces
//! with repeated indices (they are valid input), and reports bad input as
//! [`Error::InvalidInput`] naming the file, the element (`vertex 12`,
//! `face 7`, `header`) and, for text formats, the line.

use std::path::Path;

use super::Mesh;
use crate::error::{Error, Result};

/// How [`load`] post-processes a mesh.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Merge vertices with bit-identical positions (see [`Mesh::weld`]), as
    /// needed for exports that split vertices per corner or per UV seam.
    pub weld: bool,
}

/// Loads a triangle mesh from an `.obj`, `.ply` or `.off` file (extension
/// matched case-insensitively), welds it if asked, and validates it.
///
/// Polygons are fan-triangulated. OBJ vertices keep the order of the file;
/// OBJ texture coordinates, normals, groups and materials are ignored, as are
/// any PLY and OFF properties other than positions and face indices.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read, [`Error::UnsupportedFormat`]
/// for an unknown extension, and [`Error::InvalidInput`] (naming the file and
/// the element) for malformed or truncated content, faces with fewer than
/// three indices, negative or out-of-range indices, non-finite coordinates or
/// a mesh without faces.
pub fn load(path: &Path, opts: &LoadOptions) -> Result<Mesh> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let parse: fn(&[u8], &str) -> Result<Mesh> = match ext.as_deref() {
        Some("obj") => obj::parse,
        Some("ply") => ply::parse,
        Some("off") => off::parse,
        Some(other) => {
            return Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: format!(
                    "unknown extension '.{other}' (shapecue reads .obj, .ply and .off)"
                ),
            });
        }
        None => {
            return Err(Error::UnsupportedFormat {
                path: path.to_path_buf(),
                problem: "no file extension (shapecue reads .obj, .ply and .off)".into(),
            });
        }
    };
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut mesh = parse(&bytes, &name)?;
    // Validate before welding: `Mesh::weld` indexes with the face indices.
    mesh.validate(&name)?;
    if opts.weld {
        mesh = mesh.weld().0;
    }
    Ok(mesh)
}

/// Appends the fan triangulation of `poly` (at least three indices) to `faces`.
fn fan(poly: &[u32], faces: &mut Vec<[u32; 3]>) {
    if let Some((&first, rest)) = poly.split_first() {
        for w in rest.windows(2) {
            faces.push([first, w[0], w[1]]);
        }
    }
}

/// Capacity to reserve for `declared` elements of a file of `len` bytes, so
/// that a lying header cannot make us allocate more than the file could hold.
fn capped(declared: usize, len: usize) -> usize {
    declared.min(len / 2)
}

/// Converts a vertex index read from a file, checking it against the number
/// of vertices the file declares. `element` names the face.
fn vertex_index(
    value: i64,
    n_vertices: usize,
    source: &str,
    element: impl FnOnce() -> String,
) -> Result<u32> {
    if value < 0 {
        return Err(Error::input(
            source,
            element(),
            format!("negative vertex index {value}"),
        ));
    }
    match u32::try_from(value) {
        Ok(v) if (v as usize) < n_vertices => Ok(v),
        _ => Err(Error::input(
            source,
            element(),
            format!("vertex index {value} out of range (the file has {n_vertices} vertices)"),
        )),
    }
}

/// Hand-written OFF reader (`OFF`, `COFF`, `NOFF`, `STOFF`, ... ASCII only).
mod off {
    use super::{Error, Mesh, Result, capped, fan, vertex_index};

    /// Parses an ASCII OFF file. Per-vertex and per-face extras (colours,
    /// normals, texture coordinates) after the required columns are ignored.
    pub(super) fn parse(bytes: &[u8], source: &str) -> Result<Mesh> {
        let text = String::from_utf8_lossy(bytes);
        // Non-empty lines with comments removed, with their 1-based numbers.
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("")))
            .filter(|(_, l)| !l.trim().is_empty());

        let header_err = |problem: String| Error::input(source, "header", problem);
        let (ln, first) = lines
            .next()
            .ok_or_else(|| header_err("empty file (expected 'OFF')".into()))?;
        let mut toks = first.split_whitespace().peekable();
        // The keyword is optional in some writers: a line starting with a
        // number holds the counts.
        if let Some(kw) = toks.peek().copied()
            && kw.parse::<u64>().is_err()
        {
            check_keyword(kw).map_err(|p| header_err(format!("line {ln}: {p}")))?;
            toks.next();
            if toks
                .peek()
                .is_some_and(|t| t.eq_ignore_ascii_case("BINARY"))
            {
                return Err(header_err(format!(
                    "line {ln}: binary OFF is not supported; convert it to ASCII OFF or PLY"
                )));
            }
        }
        let mut counts: Vec<&str> = toks.collect();
        let mut counts_line = ln;
        if counts.is_empty() {
            let (ln, l) = lines.next().ok_or_else(|| {
                header_err("unexpected end of file: missing vertex and face counts".into())
            })?;
            counts = l.split_whitespace().collect();
            counts_line = ln;
        }
        let count = |k: usize, what: &str| -> Result<usize> {
            let tok = counts.get(k).ok_or_else(|| {
                header_err(format!("line {counts_line}: missing the {what} count"))
            })?;
            tok.parse::<usize>().map_err(|_| {
                header_err(format!(
                    "line {counts_line}: {what} count '{tok}' is not a non-negative integer"
                ))
            })
        };
        let nv = count(0, "vertex")?;
        let nf = count(1, "face")?;

        let mut positions = Vec::with_capacity(capped(nv, bytes.len()));
        for i in 0..nv {
            let element = || format!("vertex {i}");
            let (ln, l) = lines.next().ok_or_else(|| {
                Error::input(
                    source,
                    element(),
                    format!("unexpected end of file: the header declares {nv} vertices"),
                )
            })?;
            let mut toks = l.split_whitespace();
            let mut p = [0.0f64; 3];
            for (k, c) in p.iter_mut().enumerate() {
                let tok = toks.next().ok_or_else(|| {
                    Error::input(
                        source,
                        element(),
                        format!("line {ln}: expected 3 coordinates, found {k}"),
                    )
                })?;
                *c = tok.parse().map_err(|_| {
                    Error::input(
                        source,
                        element(),
                        format!("line {ln}: cannot parse coordinate '{tok}' as a number"),
                    )
                })?;
            }
            positions.push(p);
        }

        let mut faces = Vec::with_capacity(capped(nf, bytes.len()));
        let mut poly: Vec<u32> = Vec::new();
        for j in 0..nf {
            let element = || format!("face {j}");
            let (ln, l) = lines.next().ok_or_else(|| {
                Error::input(
                    source,
                    element(),
                    format!("unexpected end of file: the header declares {nf} faces"),
                )
            })?;
            let mut toks = l.split_whitespace();
            let n_tok = toks.next().unwrap_or("");
            let n: i64 = n_tok.parse().map_err(|_| {
                Error::input(
                    source,
                    element(),
                    format!("line {ln}: cannot parse vertex count '{n_tok}' as an integer"),
                )
            })?;
            if n < 3 {
                return Err(Error::input(
                    source,
                    element(),
                    format!("line {ln}: {n} vertex indices; a face needs at least 3"),
                ));
            }
            poly.clear();
            for k in 0..n {
                let tok = toks.next().ok_or_else(|| {
                    Error::input(
                        source,
                        element(),
                        format!("line {ln}: the face declares {n} vertex indices but has {k}"),
                    )
                })?;
                let v: i64 = tok.parse().map_err(|_| {
                    Error::input(
                        source,
                        element(),
                        format!("line {ln}: cannot parse vertex index '{tok}' as an integer"),
                    )
                })?;
                poly.push(vertex_index(v, nv, source, element)?);
            }
            fan(&poly, &mut faces);
        }
        Ok(Mesh { positions, faces })
    }

    /// Accepts `[ST][C][N]OFF` (texture coordinates, colours, normals);
    /// rejects the 4-D and n-D variants.
    fn check_keyword(kw: &str) -> std::result::Result<(), String> {
        let Some(prefix) = kw.strip_suffix("OFF") else {
            return Err(format!("expected the keyword 'OFF', found '{kw}'"));
        };
        let rest = prefix.strip_prefix("ST").unwrap_or(prefix);
        let rest = rest.strip_prefix('C').unwrap_or(rest);
        let rest = rest.strip_prefix('N').unwrap_or(rest);
        match rest {
            "" => Ok(()),
            r if r.contains('4') || r.ends_with('n') => Err(format!(
                "'{kw}': only 3-D OFF files are supported (4-D and n-D variants are not)"
            )),
            _ => Err(format!("unknown OFF variant '{kw}'")),
        }
    }
}

/// PLY reader on top of `ply-rs-bw`, reading one element at a time so that
/// errors name the element.
mod ply {
    use std::io::{BufRead, ErrorKind};

    use ply_rs_bw::parser::{ParseError, Parser, Reader};
    use ply_rs_bw::ply::{
        ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType,
        ScalarType,
    };

    use super::{Error, Mesh, Result, capped, fan, vertex_index};

    /// Names accepted for the face index list.
    const FACE_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

    /// A vertex: only x, y and z are kept, converted to f64.
    struct Vertex([f64; 3]);

    impl PropertyAccess for Vertex {
        fn new() -> Self {
            Vertex([0.0; 3])
        }
        fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
            let k = match name {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                _ => return PropertyAccessResult::Ignored,
            };
            self.0[k] = match property {
                Property::Char(v) => v.into(),
                Property::UChar(v) => v.into(),
                Property::Short(v) => v.into(),
                Property::UShort(v) => v.into(),
                Property::Int(v) => v.into(),
                Property::UInt(v) => v.into(),
                Property::Float(v) => v.into(),
                Property::Double(v) => v,
                _ => return PropertyAccessResult::UnsupportedType,
            };
            PropertyAccessResult::Set
        }
    }

    /// A face: only the index list is kept, widened to i64 so that negative
    /// values can be reported.
    struct Face(Vec<i64>);

    impl PropertyAccess for Face {
        fn new() -> Self {
            Face(Vec::new())
        }
        fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
            if !FACE_LISTS.contains(&name) {
                return PropertyAccessResult::Ignored;
            }
            self.0 = match property {
                Property::ListChar(v) => v.into_iter().map(i64::from).collect(),
                Property::ListUChar(v) => v.into_iter().map(i64::from).collect(),
                Property::ListShort(v) => v.into_iter().map(i64::from).collect(),
                Property::ListUShort(v) => v.into_iter().map(i64::from).collect(),
                Property::ListInt(v) => v.into_iter().map(i64::from).collect(),
                Property::ListUInt(v) => v.into_iter().map(i64::from).collect(),
                _ => return PropertyAccessResult::UnsupportedType,
            };
            PropertyAccessResult::Set
        }
    }

    /// An element shapecue does not use: parsed (to advance the stream) and dropped.
    struct Skip;

    impl PropertyAccess for Skip {
        fn new() -> Self {
            Skip
        }
    }

    /// First line of a parser error's message (the rest is a dump of the
    /// parser's state).
    fn first_line(e: &ParseError) -> String {
        let msg = e.to_string();
        let line = msg.lines().next().unwrap_or("").trim();
        line.strip_prefix("Line")
            .map_or_else(|| line.to_string(), |r| format!("line{r}"))
    }

    /// One-line description of a parser error met while reading element
    /// `def`; `ascii_line` is the line number and text of an ASCII element.
    fn describe(e: &ParseError, def: &ElementDef, ascii_line: Option<(usize, &str)>) -> String {
        match (e.kind(), ascii_line) {
            (ErrorKind::UnexpectedEof, _) => format!(
                "unexpected end of file: the header declares {} '{}' elements",
                def.count, def.name
            ),
            (ErrorKind::InvalidInput, Some((ln, text))) => {
                let props: Vec<&str> = def.properties.keys().map(String::as_str).collect();
                let text: String = text.trim().chars().take(80).collect();
                format!(
                    "line {ln}: '{text}' does not match the declared properties ({})",
                    props.join(" ")
                )
            }
            _ => e
                .to_string()
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
        }
    }

    /// The payload stream: the bytes after the header and, for ASCII files,
    /// the number of the next line.
    struct Stream<'a> {
        reader: Reader<&'a [u8]>,
        encoding: Encoding,
        line_no: usize,
        line: String,
    }

    impl Stream<'_> {
        /// Reads the next element described by `def`.
        fn element<E: PropertyAccess>(
            &mut self,
            parser: &Parser<E>,
            def: &ElementDef,
        ) -> std::result::Result<E, ParseError> {
            match self.encoding {
                Encoding::BinaryLittleEndian => {
                    parser.read_little_endian_element(self.reader.get_mut(), def)
                }
                Encoding::BinaryBigEndian => {
                    parser.read_big_endian_element(self.reader.get_mut(), def)
                }
                Encoding::Ascii => {
                    // One element per line; blank lines are tolerated.
                    loop {
                        self.line.clear();
                        self.line_no += 1;
                        if self.reader.get_mut().read_line(&mut self.line)? == 0 {
                            return Err(std::io::Error::from(ErrorKind::UnexpectedEof).into());
                        }
                        if !self.line.trim().is_empty() {
                            let e = parser.read_ascii_element(&self.line, def)?;
                            // The parser ignores values past the declared ones;
                            // a line with more is a malformed file, not a
                            // comment.
                            if extra_values(&self.line, def) {
                                return Err(std::io::Error::from(ErrorKind::InvalidInput).into());
                            }
                            return Ok(e);
                        }
                    }
                }
            }
        }

        /// Reads all `def.count` elements of one kind, passing each to `sink`.
        fn read_all<E: PropertyAccess>(
            &mut self,
            def: &ElementDef,
            source: &str,
            mut sink: impl FnMut(usize, E) -> Result<()>,
        ) -> Result<()> {
            let parser = Parser::<E>::new();
            for i in 0..def.count {
                let e = self.element(&parser, def).map_err(|e| {
                    let ascii = (self.encoding == Encoding::Ascii)
                        .then_some((self.line_no, self.line.as_str()));
                    Error::input(
                        source,
                        format!("{} {i}", def.name),
                        describe(&e, def, ascii),
                    )
                })?;
                sink(i, e)?;
            }
            Ok(())
        }
    }

    /// True when an ASCII element line holds more values than `def`
    /// declares (a list property takes its count and that many values).
    fn extra_values(line: &str, def: &ElementDef) -> bool {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        let mut used = 0usize;
        for p in def.properties.values() {
            match p.data_type {
                PropertyType::Scalar(_) => used += 1,
                PropertyType::List(..) => {
                    let n = tokens
                        .get(used)
                        .and_then(|t| t.parse::<usize>().ok())
                        .unwrap_or(0);
                    used = used.saturating_add(1).saturating_add(n);
                }
            }
        }
        tokens.len() > used
    }

    fn is_integer(t: &ScalarType) -> bool {
        !matches!(t, ScalarType::Float | ScalarType::Double)
    }

    /// Checks that the header has what shapecue needs, before reading the payload.
    fn check_header(header: &Header, source: &str) -> Result<()> {
        let err = |p: String| Error::input(source, "header", p);
        let Some(vertex) = header.elements.get("vertex") else {
            return Err(err("no 'vertex' element".into()));
        };
        for axis in ["x", "y", "z"] {
            match vertex.properties.get(axis).map(|p| &p.data_type) {
                Some(PropertyType::Scalar(_)) => {}
                Some(PropertyType::List(..)) => {
                    return Err(err(format!(
                        "property '{axis}' of element 'vertex' is a list, not a number"
                    )));
                }
                None => return Err(err(format!("element 'vertex' has no property '{axis}'"))),
            }
        }
        if let Some(face) = header.elements.get("face") {
            let list = FACE_LISTS
                .iter()
                .find_map(|n| face.properties.get(*n).map(|p| (n, &p.data_type)));
            match list {
                Some((_, PropertyType::List(count, item)))
                    if is_integer(count) && is_integer(item) => {}
                Some((n, t)) => {
                    return Err(err(format!(
                        "property '{n}' of element 'face' must be a list of integers, found {t:?}"
                    )));
                }
                None if face.count == 0 => {}
                None => {
                    return Err(err(
                        "element 'face' has no 'vertex_indices' (or 'vertex_index') list".into(),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The header is text: a line that is not UTF-8 is named by its number
    /// (the parser would only say that the stream is not valid UTF-8).
    fn check_header_text(bytes: &[u8], source: &str) -> Result<()> {
        for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
            if let Err(e) = std::str::from_utf8(line) {
                let col = e.valid_up_to();
                return Err(Error::input(
                    source,
                    format!("header line {}", i + 1),
                    format!(
                        "byte 0x{:02x} at column {} is not text (the header must be ASCII)",
                        line[col],
                        col + 1
                    ),
                ));
            }
            if line.strip_suffix(b"\r").unwrap_or(line) == b"end_header" {
                break;
            }
        }
        Ok(())
    }

    /// Parses a PLY file (ASCII, binary little- or big-endian).
    pub(super) fn parse(bytes: &[u8], source: &str) -> Result<Mesh> {
        check_header_text(bytes, source)?;
        let mut reader = Reader::new(bytes);
        let header = Parser::<Skip>::new()
            .read_header(&mut reader)
            .map_err(|e| Error::input(source, "header", first_line(&e)))?;
        check_header(&header, source)?;
        let mut stream = Stream {
            // `line()` is the number of the first payload line; `element`
            // increments before reading.
            line_no: reader.line().saturating_sub(1),
            reader,
            encoding: header.encoding,
            line: String::new(),
        };
        let nv = header.elements.get("vertex").map_or(0, |d| d.count);

        let mut positions = Vec::new();
        let mut faces = Vec::new();
        let mut poly: Vec<u32> = Vec::new();
        for (name, def) in &header.elements {
            match name.as_str() {
                "vertex" => {
                    positions.reserve(capped(def.count, bytes.len()));
                    stream.read_all(def, source, |_, v: Vertex| {
                        positions.push(v.0);
                        Ok(())
                    })?;
                }
                "face" => {
                    faces.reserve(capped(def.count, bytes.len()));
                    stream.read_all(def, source, |i, f: Face| {
                        let element = || format!("face {i}");
                        if f.0.len() < 3 {
                            return Err(Error::input(
                                source,
                                element(),
                                format!("{} vertex indices; a face needs at least 3", f.0.len()),
                            ));
                        }
                        poly.clear();
                        for &v in &f.0 {
                            poly.push(vertex_index(v, nv, source, element)?);
                        }
                        fan(&poly, &mut faces);
                        Ok(())
                    })?;
                }
                _ => stream.read_all(def, source, |_, _: Skip| Ok(()))?,
            }
        }
        Ok(Mesh { positions, faces })
    }
}

/// OBJ reader: a light pre-pass, then `tobj`.
///
/// The pre-pass keeps only `v` and `f` lines (so texture coordinates, normals,
/// groups and materials cannot split vertices, split the mesh into models or
/// trip `tobj` on them), drops per-vertex colours, rejects faces with fewer
/// than three corners, and prepends one polygon through every vertex in file
/// order. `tobj` numbers vertices in order of first use, so that polygon makes
/// its numbering the file's; its triangles are then dropped.
mod obj {
    use super::{Error, Mesh, Result};

    /// Strips an end-of-line comment.
    fn uncomment(line: &str) -> &str {
        line.split('#').next().unwrap_or("")
    }

    pub(super) fn parse(bytes: &[u8], source: &str) -> Result<Mesh> {
        let text = String::from_utf8_lossy(bytes);
        let mut kept = String::with_capacity(text.len());
        let (mut nv, mut nf) = (0usize, 0usize);
        for (i, line) in text.lines().enumerate() {
            let line = uncomment(line);
            let mut toks = line.split_whitespace();
            match toks.next() {
                Some("v") => {
                    nv += 1;
                    let rest: Vec<&str> = toks.collect();
                    // x y z [w] are kept; x y z r g b loses its colour.
                    let n = if rest.len() == 4 {
                        4
                    } else {
                        rest.len().min(3)
                    };
                    kept.push('v');
                    for t in &rest[..n] {
                        kept.push(' ');
                        kept.push_str(t);
                    }
                    kept.push('\n');
                }
                Some("f") => {
                    let corners = toks.count();
                    if corners < 3 {
                        return Err(Error::input(
                            source,
                            format!("face {nf}"),
                            format!(
                                "line {}: {corners} vertex indices; a face needs at least 3",
                                i + 1
                            ),
                        ));
                    }
                    nf += 1;
                    kept.push_str(line);
                    kept.push('\n');
                }
                _ => {}
            }
        }

        let skip = if nv >= 3 { nv - 2 } else { 0 };
        let mut input = String::with_capacity(kept.len() + 8 * nv + 2);
        if skip > 0 {
            input.push('f');
            for k in 1..=nv {
                input.push(' ');
                input.push_str(&k.to_string());
            }
            input.push('\n');
        }
        input.push_str(&kept);
        drop(kept);

        let options = tobj::LoadOptions {
            single_index: false,
            triangulate: true,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _materials) = tobj::load_obj_buf(&mut input.as_bytes(), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| locate(&text, source, e))?;

        let mut positions = Vec::with_capacity(nv);
        let mut faces = Vec::with_capacity(nf);
        let mut first = true;
        for model in models {
            let m = &model.mesh;
            let offset = u32::try_from(positions.len()).map_err(|_| too_big(source))?;
            positions.extend(m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
            let mut tris = m.indices.chunks_exact(3);
            if first && skip > 0 {
                // The triangles of the prepended polygon.
                tris.by_ref().take(skip).for_each(drop);
            }
            first = false;
            for t in tris {
                let f = [t[0], t[1], t[2]].map(|v| v.checked_add(offset));
                match f {
                    [Some(a), Some(b), Some(c)] => faces.push([a, b, c]),
                    _ => return Err(too_big(source)),
                }
            }
        }
        Ok(Mesh { positions, faces })
    }

    fn too_big(source: &str) -> Error {
        Error::input(source, "mesh", "too many vertices for 32-bit indices")
    }

    /// Turns a `tobj` error (which carries no position) into one naming the
    /// offending element, by re-scanning the text for the first bad line.
    fn locate(text: &str, source: &str, err: tobj::LoadError) -> Error {
        let total = text
            .lines()
            .filter(|l| uncomment(l).split_whitespace().next() == Some("v"))
            .count();
        let (mut nv, mut nf) = (0usize, 0usize);
        for (i, line) in text.lines().enumerate() {
            let ln = i + 1;
            let mut toks = uncomment(line).split_whitespace();
            match toks.next() {
                Some("v") => {
                    let rest: Vec<&str> = toks.collect();
                    let n = if rest.len() == 4 {
                        4
                    } else {
                        rest.len().min(3)
                    };
                    let problem = if rest.len() < 3 {
                        Some(format!("expected 3 coordinates, found {}", rest.len()))
                    } else if let Some(bad) = rest[..n].iter().find(|t| t.parse::<f64>().is_err()) {
                        Some(format!("cannot parse '{bad}' as a number"))
                    } else if n == 4 && rest[3].parse::<f64>() == Ok(0.0) {
                        Some("homogeneous coordinate w is 0".into())
                    } else {
                        None
                    };
                    if let Some(p) = problem {
                        return Error::input(
                            source,
                            format!("vertex {nv}"),
                            format!("line {ln}: {p}"),
                        );
                    }
                    nv += 1;
                }
                Some("f") => {
                    for tok in toks {
                        if let Some(p) = check_corner(tok, nv, total) {
                            return Error::input(
                                source,
                                format!("face {nf}"),
                                format!("line {ln}: {p}"),
                            );
                        }
                    }
                    nf += 1;
                }
                _ => {}
            }
        }
        Error::input(source, "file", format!("OBJ parser: {err}"))
    }

    /// Describes what is wrong with one face corner `v[/vt[/vn]]`, if anything.
    fn check_corner(tok: &str, seen: usize, total: usize) -> Option<String> {
        let parts: Vec<&str> = tok.split('/').collect();
        if parts.len() > 3 {
            return Some(format!("malformed corner '{tok}'"));
        }
        for p in &parts[1..] {
            if !p.is_empty() && p.parse::<isize>().is_err() {
                return Some(format!("malformed corner '{tok}'"));
            }
        }
        let Ok(v) = parts[0].parse::<i64>() else {
            return Some(format!("cannot parse vertex index in '{tok}'"));
        };
        if v == 0 {
            Some("vertex index 0 (OBJ indices start at 1)".into())
        } else if v < 0 && v.unsigned_abs() > seen as u64 {
            Some(format!(
                "relative vertex index {v} points before the first vertex ({seen} vertices so far)"
            ))
        } else if v > 0 && v as u64 > total as u64 {
            Some(format!(
                "vertex index {v} out of range (the file has {total} vertices)"
            ))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ply;

    const HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n";

    #[test]
    fn ascii_ply_line_with_an_extra_value_is_an_error_naming_the_line() {
        let good = format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        assert_eq!(ply::parse(good.as_bytes(), "t.ply").unwrap().faces.len(), 1);
        let bad = format!("{HEAD}0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n");
        let e = ply::parse(bad.as_bytes(), "t.ply").unwrap_err().to_string();
        assert!(
            e.contains("t.ply") && e.contains("vertex 1") && e.contains("line 11"),
            "{e}"
        );
        let bad_face = format!("{HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2 2\n");
        let e = ply::parse(bad_face.as_bytes(), "t.ply")
            .unwrap_err()
            .to_string();
        assert!(e.contains("face 0"), "{e}");
    }

    #[test]
    fn non_text_header_names_the_line() {
        let mut bytes = b"ply\nformat ascii 1.0\ncomment caf".to_vec();
        bytes.extend_from_slice(&[0xe9, b'\n']);
        bytes.extend_from_slice(&HEAD.as_bytes()[20..]);
        let e = ply::parse(&bytes, "t.ply").unwrap_err().to_string();
        assert!(e.contains("header line 3") && e.contains("0xe9"), "{e}");
    }
}
