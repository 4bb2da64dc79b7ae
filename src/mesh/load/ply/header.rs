//! The header: its text, what shapecue needs of it, and the element counts
//! the bytes after it can hold (the memory bound, checked before anything
//! is reserved or parsed).

use ply_rs_bw::parser::ParseError;
use ply_rs_bw::ply::{ElementDef, Encoding, Header, PropertyType, ScalarType};

use super::FACE_LISTS;
use crate::error::{Error, Result};

/// First line of a parser error's message (the rest is a dump of the
/// parser's state).
pub(super) fn first_line(e: &ParseError) -> String {
    let msg = e.to_string();
    let line = msg.lines().next().unwrap_or("").trim();
    line.strip_prefix("Line")
        .map_or_else(|| line.to_string(), |r| format!("line{r}"))
}

/// Size in bytes of one binary value of type `t`.
pub(super) fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// The fewest bytes one element of `def` can take: in binary, its scalars
/// and the counts of its lists (an empty list is only its count); in ASCII,
/// one character and a separator per scalar or list count.
pub(super) fn min_element_bytes(def: &ElementDef, encoding: Encoding) -> usize {
    def.properties
        .values()
        .map(|p| match (encoding, &p.data_type) {
            (Encoding::Ascii, _) => 2,
            (_, PropertyType::Scalar(t) | PropertyType::List(t, _)) => scalar_size(t),
        })
        .sum()
}

/// The memory bound: how many elements of `def` to reserve room for when
/// `payload` bytes follow the header. A lying count cannot make the loader
/// allocate more than the bytes could hold (at the smallest element size);
/// a file that really ends early is reported at the element where it ends.
pub(super) fn capacity(def: &ElementDef, encoding: Encoding, payload: usize) -> usize {
    let min = min_element_bytes(def, encoding).max(1);
    def.count.min(payload / min + 1)
}

/// Refuses, before anything is reserved or parsed, element counts that the
/// `body` (the bytes after the header) cannot hold: in binary, each element
/// takes exactly the bytes of its scalars (and at least the count of each
/// list); in ASCII, one non-blank line (so at least two bytes). The error
/// names the first element that cannot be in the
/// file, as a truncated file's does, with the count and what the bytes hold.
pub(super) fn check_counts(header: &Header, body: &[u8], source: &str) -> Result<()> {
    let payload = body.len();
    let ascii = header.encoding == Encoding::Ascii;
    if ascii {
        // One non-blank line per element (blank lines are skipped), at
        // least two bytes each: counting them is exact and allocates nothing.
        let lines = body
            .split(|&b| b == b'\n')
            .filter(|l| !l.trim_ascii().is_empty())
            .count();
        let mut room = lines;
        for (name, def) in &header.elements {
            if def.count > room {
                return Err(Error::input(
                    source,
                    format!("{name} {}", room),
                    format!(
                        "unexpected end of file: the header declares {} '{name}' elements (one \
                         line each), but the {payload} bytes after the header hold {lines} \
                         lines, {room} of them left for '{name}'",
                        def.count
                    ),
                ));
            }
            room -= def.count;
        }
        return Ok(());
    }
    check_binary_counts(header, payload, source)
}

/// The binary half of [`check_counts`], for a payload of `payload` bytes.
pub(super) fn check_binary_counts(header: &Header, payload: usize, source: &str) -> Result<()> {
    let mut room = payload as u128;
    for (name, def) in &header.elements {
        let min = min_element_bytes(def, header.encoding) as u128;
        if min == 0 {
            // Elements without properties take no bytes.
            continue;
        }
        let fit = room / min;
        if def.count as u128 > fit {
            let exact = def
                .properties
                .values()
                .all(|p| matches!(p.data_type, PropertyType::Scalar(_)));
            let each = if exact { "" } else { "at least " };
            let used = payload as u128 - room;
            let before = if used > 0 {
                format!(" besides the {used} bytes the elements before it take at least")
            } else {
                String::new()
            };
            return Err(Error::input(
                source,
                format!("{name} {fit}"),
                format!(
                    "unexpected end of file: the header declares {} '{name}' elements of \
                     {each}{min} bytes each, but the {payload} bytes after the header hold at \
                     most {fit}{before}",
                    def.count
                ),
            ));
        }
        room -= def.count as u128 * min;
    }
    Ok(())
}

pub(super) fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

/// A property type as a PLY header writes it (`float`, `list uchar int`).
pub(super) fn ply_type_name(t: &PropertyType) -> String {
    let scalar = |t: &ScalarType| match t {
        ScalarType::Char => "char",
        ScalarType::UChar => "uchar",
        ScalarType::Short => "short",
        ScalarType::UShort => "ushort",
        ScalarType::Int => "int",
        ScalarType::UInt => "uint",
        ScalarType::Float => "float",
        ScalarType::Double => "double",
    };
    match t {
        PropertyType::Scalar(x) => scalar(x).to_string(),
        PropertyType::List(c, x) => format!("list {} {}", scalar(c), scalar(x)),
    }
}

/// Checks that the header has what shapecue needs, before reading the payload.
pub(super) fn check_header(header: &Header, source: &str) -> Result<()> {
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
            Some((_, PropertyType::List(count, item))) if is_integer(count) && is_integer(item) => {
            }
            Some((n, t)) => {
                return Err(err(format!(
                    "property '{n}' of element 'face' must be a list of integers, found {}",
                    ply_type_name(t)
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
pub(super) fn check_header_text(bytes: &[u8], source: &str) -> Result<()> {
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
        let text = std::str::from_utf8(line.strip_suffix(b"\r").unwrap_or(line)).unwrap_or("");
        if text == "end_header" {
            break;
        }
        if let Some(problem) = property_problem(text) {
            return Err(Error::input(
                source,
                format!("header line {}", i + 1),
                problem,
            ));
        }
    }
    Ok(())
}

/// The PLY scalar types, in both of the format's spellings.
const PLY_TYPES: [&str; 16] = [
    "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16",
    "uint16", "int32", "uint32", "float32", "float64",
];

/// What is wrong with a `property` line's types (the parser only says it
/// could not parse the line), `None` for any other line or a good one.
fn property_problem(line: &str) -> Option<String> {
    let w: Vec<&str> = line.split_whitespace().collect();
    if w.first() != Some(&"property") {
        return None;
    }
    let known = |t: &str| PLY_TYPES.contains(&t);
    let types = PLY_TYPES.join(", ");
    match w.get(1) {
        Some(&"list") => {
            if w.len() != 5 {
                return Some(format!(
                    "'{line}': a list property is 'property list COUNT_TYPE VALUE_TYPE NAME'"
                ));
            }
            w[2..4]
                .iter()
                .find(|t| !known(t))
                .map(|t| format!("'{line}': unknown type '{t}' (PLY's types are {types})"))
        }
        Some(t) if !known(t) => Some(format!(
            "'{line}': unknown type '{t}' (PLY's types are {types})"
        )),
        Some(_) if w.len() != 3 => Some(format!("'{line}': a property is 'property TYPE NAME'")),
        None => Some(format!("'{line}': a property is 'property TYPE NAME'")),
        _ => None,
    }
}

/// The length of the header at the start of `bytes` (through the newline
/// after `end_header`), `None` when `bytes` does not hold all of it.
pub(super) fn header_len(bytes: &[u8]) -> Option<usize> {
    let mut at = 0;
    for line in bytes.split_inclusive(|&b| b == b'\n') {
        at += line.len();
        let text = line.strip_suffix(b"\n")?;
        if text.strip_suffix(b"\r").unwrap_or(text) == b"end_header" {
            return Some(at);
        }
    }
    None
}
