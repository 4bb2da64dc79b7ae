//! The ASCII body: one element per line, read through `ply-rs-bw`'s
//! element parser with the line number of every problem.

use std::io::{BufRead, ErrorKind};

use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Header, PropertyAccess, PropertyType};

use super::header::capacity;
use super::properties::{Face, Skip, Vertex};
use super::{add_polygon, eof_problem};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Reads the ASCII payload after `header` (`reader` holds the bytes after
/// it, `payload` of them; the file's `nv` vertices).
pub(super) fn parse_ascii(
    header: &Header,
    reader: Reader<&[u8]>,
    payload: usize,
    nv: usize,
    source: &str,
) -> Result<Mesh> {
    let mut stream = Stream {
        // `line()` is the number of the first payload line; `element`
        // increments before reading.
        line_no: reader.line().saturating_sub(1),
        reader,
        line: String::new(),
    };

    let mut positions = Vec::new();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    let mut with_normals = false;
    let mut faces = Vec::new();
    let mut poly: Vec<u32> = Vec::new();
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" => {
                positions.reserve(capacity(def, header.encoding, payload));
                with_normals = ["nx", "ny", "nz"]
                    .iter()
                    .all(|n| def.properties.contains_key(*n));
                stream.read_all(def, source, |_, v: Vertex| {
                    positions.push(v.0);
                    if with_normals {
                        normals.push(v.1);
                    }
                    Ok(())
                })?;
            }
            "face" => {
                faces.reserve(capacity(def, header.encoding, payload));
                stream.read_all(def, source, |i, f: Face| {
                    add_polygon(f.0.into_iter(), i, nv, source, &mut poly, &mut faces)
                })?;
            }
            _ => stream.read_all(def, source, |_, _: Skip| Ok(()))?,
        }
    }
    Ok(Mesh {
        positions,
        faces,
        normals: with_normals.then_some(normals),
    })
}

/// One-line description of a parser error met while reading element
/// `def` from line `ln`, whose text is `text`.
pub(super) fn describe(e: &ParseError, def: &ElementDef, (ln, text): (usize, &str)) -> String {
    match e.kind() {
        ErrorKind::UnexpectedEof => eof_problem(def),
        ErrorKind::InvalidInput => {
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

/// An ASCII payload: the bytes after the header and the number of the
/// next line (binary payloads are read by [`super::binary::parse_binary`]).
pub(super) struct Stream<'a> {
    reader: Reader<&'a [u8]>,
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
        // One element per line; blank lines are tolerated.
        loop {
            self.line.clear();
            self.line_no += 1;
            if self.reader.get_mut().read_line(&mut self.line)? == 0 {
                return Err(std::io::Error::from(ErrorKind::UnexpectedEof).into());
            }
            if !self.line.trim().is_empty() {
                let e = parser.read_ascii_element(&self.line, def)?;
                // The parser ignores values past the declared ones; a line
                // with more is a malformed file, not a comment.
                if extra_values(&self.line, def) {
                    return Err(std::io::Error::from(ErrorKind::InvalidInput).into());
                }
                return Ok(e);
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
                Error::input(
                    source,
                    format!("{} {i}", def.name),
                    describe(&e, def, (self.line_no, self.line.as_str())),
                )
            })?;
            sink(i, e)?;
        }
        Ok(())
    }
}

/// True when an ASCII element line holds more values than `def`
/// declares (a list property takes its count and that many values).
pub(super) fn extra_values(line: &str, def: &ElementDef) -> bool {
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
