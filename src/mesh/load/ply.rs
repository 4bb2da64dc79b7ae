//! PLY in ASCII and both binary byte orders: the header through
//! `ply-rs-bw`, the ASCII body through its element reader
//! ([`ascii`]), the binary body read directly ([`binary`], from memory or
//! a file a chunk at a time, [`body`]); [`header`] checks what shapecue
//! needs and the memory bound, [`properties`] maps elements to positions and
//! index lists.

mod ascii;
mod binary;
mod body;
mod header;
mod properties;

use std::io::Read;
use std::path::Path;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{ElementDef, Encoding};

use super::{Error, Mesh, Result, fan, vertex_index};
use binary::parse_binary;
use body::{FileBody, SliceBody};
use header::{
    check_binary_counts, check_counts, check_header, check_header_text, first_line, header_len,
};
use properties::{FACE_LISTS, Skip};

/// The counts of the `vertex` and `face` elements of the header at the
/// start of `r` (0 for an element it lacks); `None` when the header
/// cannot be read. Reads the header only.
pub(super) fn header_counts(r: impl std::io::BufRead) -> Option<(usize, usize)> {
    let header = Parser::<Skip>::new()
        .read_header(&mut Reader::new(r))
        .ok()?;
    let count = |name: &str| header.elements.get(name).map_or(0, |d| d.count);
    Some((count("vertex"), count("face")))
}

/// Parses a PLY file (ASCII, binary little- or big-endian).
pub(super) fn parse(bytes: &[u8], source: &str) -> Result<Mesh> {
    check_header_text(bytes, source)?;
    let mut reader = Reader::new(bytes);
    let header = Parser::<Skip>::new()
        .read_header(&mut reader)
        .map_err(|e| Error::input(source, "header", first_line(&e)))?;
    check_header(&header, source)?;
    let payload = reader.get_ref().len();
    check_counts(&header, reader.get_ref(), source)?;
    let nv = header.elements.get("vertex").map_or(0, |d| d.count);
    if header.encoding != Encoding::Ascii {
        let big = header.encoding == Encoding::BinaryBigEndian;
        let body = reader.get_ref();
        return parse_binary(&header, &mut SliceBody(body), body.len(), big, nv, source);
    }
    ascii::parse_ascii(&header, reader, payload, nv, source)
}

/// The end-of-file problem of an element of `def` cut short.
fn eof_problem(def: &ElementDef) -> String {
    format!(
        "unexpected end of file: the header declares {} '{}' elements",
        def.count, def.name
    )
}

/// Checks the vertex indices of face `i` (at least three, each a vertex of
/// the file's `nv`) and appends its fan triangulation to `faces`; `poly` is
/// scratch space.
#[inline]
fn add_polygon(
    indices: impl ExactSizeIterator<Item = i64>,
    i: usize,
    nv: usize,
    source: &str,
    poly: &mut Vec<u32>,
    faces: &mut Vec<[u32; 3]>,
) -> Result<()> {
    let element = || format!("face {i}");
    if indices.len() < 3 {
        return Err(Error::input(
            source,
            element(),
            format!("{} vertex indices; a face needs at least 3", indices.len()),
        ));
    }
    poly.clear();
    for v in indices {
        poly.push(vertex_index(v, nv, source, element)?);
    }
    fan(poly, faces);
    Ok(())
}

/// Loads a PLY file: as [`parse`] of its bytes, with the same checks and
/// messages, but a binary payload is read a chunk at a time rather than
/// whole (a 2M-vertex file with curvature properties is 200 MB, and
/// reading it into fresh memory costs more than parsing it).
pub(super) fn load(path: &Path, source: &str) -> Result<Mesh> {
    let io = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        // A pipe or device: its length is not known ahead, so read it whole.
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io)?;
        return parse(&bytes, source);
    }
    let file_len = meta.len();
    // The header, and perhaps the start of the payload.
    let mut head = Vec::new();
    let body_at = loop {
        if let Some(n) = header_len(&head) {
            break n;
        }
        let got = (&mut file)
            .take(64 << 10)
            .read_to_end(&mut head)
            .map_err(io)?;
        if got == 0 {
            // No complete header: the whole file is here.
            return parse(&head, source);
        }
    };
    check_header_text(&head[..body_at], source)?;
    let header = Parser::<Skip>::new()
        .read_header(&mut Reader::new(&head[..body_at]))
        .map_err(|e| Error::input(source, "header", first_line(&e)))?;
    if header.encoding == Encoding::Ascii {
        file.read_to_end(&mut head).map_err(io)?;
        return parse(&head, source);
    }
    check_header(&header, source)?;
    let payload = usize::try_from(file_len.saturating_sub(body_at as u64)).unwrap_or(usize::MAX);
    check_binary_counts(&header, payload, source)?;
    let nv = header.elements.get("vertex").map_or(0, |d| d.count);
    let big = header.encoding == Encoding::BinaryBigEndian;
    let end = head.len() - body_at;
    head.copy_within(body_at.., 0);
    let mut body = FileBody {
        r: file,
        path,
        buf: head,
        start: 0,
        end,
        eof: false,
    };
    parse_binary(&header, &mut body, payload, big, nv, source)
}
