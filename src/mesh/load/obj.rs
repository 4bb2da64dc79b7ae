use super::{Error, Mesh, Result};

/// Strips an end-of-line comment.
fn uncomment(line: &str) -> &str {
    line.split('#').next().unwrap_or("")
}

/// Why [`scan`] stopped.
enum Stop {
    /// Something is wrong on this line (1-based); [`locate`] says what.
    Line(usize),
    /// A positive index beyond the file's vertices: found once all vertices
    /// are counted, so [`locate`] finds the face.
    Range,
    /// More vertices than 32-bit indices address.
    TooBig,
}

pub(super) fn parse(bytes: &[u8], source: &str) -> Result<Mesh> {
    scan(bytes).map_err(|stop| match stop {
        Stop::TooBig => too_big(source),
        Stop::Line(ln) => locate(&String::from_utf8_lossy(bytes), source, Some(ln)),
        Stop::Range => locate(&String::from_utf8_lossy(bytes), source, None),
    })
}

/// ASCII whitespace as `split_whitespace` sees it in a line (the line
/// break is already cut off).
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\x0b' | b'\x0c')
}

/// The whitespace-separated tokens of a line.
fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| is_space(b)).filter(|t| !t.is_empty())
}

fn number(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// An optionally signed decimal integer of at most 18 digits.
fn integer(tok: &[u8]) -> Option<i64> {
    let (neg, digits) = match tok.split_first() {
        Some((b'-', d)) => (true, d),
        Some((b'+', d)) => (false, d),
        _ => (false, tok),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v = 0i64;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(d - b'0');
    }
    Some(if neg { -v } else { v })
}

/// The vertex index of a face corner `v[/vt[/vn]]` (texture and normal
/// indices are checked and dropped), 0-based, given the vertices read so
/// far; `None` when the corner is malformed or points before the first
/// vertex. A positive index may point past the vertices read so far (OBJ
/// allows it); the caller checks it once the file is read.
fn corner(tok: &[u8], seen: usize) -> Option<i64> {
    let mut parts = tok.split(|&b| b == b'/');
    let v = integer(parts.next()?)?;
    let mut extra = 0;
    for p in parts {
        extra += 1;
        if extra > 2 || (!p.is_empty() && integer(p).is_none()) {
            return None;
        }
    }
    match v {
        0 => None,
        v if v > 0 => Some(v - 1),
        v => {
            let i = seen as i64 + v;
            (i >= 0).then_some(i)
        }
    }
}

/// One pass over the bytes: `v`, `vn` and `f` statements, everything else
/// (texture coordinates, groups, objects, materials, lines, comments)
/// skipped. Polygons are fan-triangulated. Normals are kept as trimesh2
/// 2.16 reads them: the `vn` lines in order, one per vertex, and only when
/// there are exactly as many as vertices (the faces' normal indices are not
/// used).
fn scan(bytes: &[u8]) -> std::result::Result<Mesh, Stop> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut normals: Vec<[f32; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut max_index = -1i64;
    let mut poly: Vec<i64> = Vec::new();
    let mut start = 0usize;
    let mut ln = 0usize;
    while start < bytes.len() {
        let end = memchr::memchr(b'\n', &bytes[start..]).map_or(bytes.len(), |i| start + i);
        let mut line = &bytes[start..end];
        start = end + 1;
        ln += 1;
        if let Some(hash) = memchr::memchr(b'#', line) {
            line = &line[..hash];
        }
        let first = line.iter().position(|&b| !is_space(b));
        let Some(first) = first else { continue };
        let line = &line[first..];
        let statement = line.len() == 1 || is_space(line[1]);
        match line[0] {
            b'v' if statement => {
                let mut t = tokens(&line[1..]);
                let mut p = [0.0; 3];
                for x in &mut p {
                    *x = t.next().and_then(number).ok_or(Stop::Line(ln))?;
                }
                // A fourth value alone is the weight w (ignored, but it
                // must be a non-zero number); more values are a colour.
                if let (Some(w), None) = (t.next(), t.next())
                    && number(w).is_none_or(|w| w == 0.0)
                {
                    return Err(Stop::Line(ln));
                }
                positions.push(p);
            }
            b'v' if line.get(1) == Some(&b'n') && (line.len() == 2 || is_space(line[2])) => {
                let mut t = tokens(&line[2..]);
                let mut n = [0f32; 3];
                for x in &mut n {
                    *x = t.next().and_then(number).ok_or(Stop::Line(ln))? as f32;
                }
                normals.push(n);
            }
            b'f' if statement => {
                poly.clear();
                for tok in tokens(&line[1..]) {
                    let v = corner(tok, positions.len()).ok_or(Stop::Line(ln))?;
                    max_index = max_index.max(v);
                    poly.push(v);
                }
                if poly.len() < 3 {
                    return Err(Stop::Line(ln));
                }
                // Indices are below 2^60 here; the range check below makes
                // them fit u32.
                for k in 1..poly.len() - 1 {
                    faces.push([poly[0], poly[k], poly[k + 1]].map(|v| v as u32));
                }
            }
            _ => {}
        }
    }
    if u32::try_from(positions.len()).is_err() {
        return Err(Stop::TooBig);
    }
    if max_index >= positions.len() as i64 {
        return Err(Stop::Range);
    }
    let normals = (normals.len() == positions.len()).then_some(normals);
    Ok(Mesh {
        positions,
        faces,
        normals,
    })
}

fn too_big(source: &str) -> Error {
    Error::input(source, "mesh", "too many vertices for 32-bit indices")
}

/// Finds the first bad statement and names it: its element (`vertex 12`,
/// `face 7`), its line and the problem. `line` is where [`scan`] stopped,
/// when it knows; a problem this re-reading cannot name is reported there.
fn locate(text: &str, source: &str, line: Option<usize>) -> Error {
    let total = text
        .lines()
        .filter(|l| uncomment(l).split_whitespace().next() == Some("v"))
        .count();
    let (mut nv, mut nf, mut nn) = (0usize, 0usize, 0usize);
    for (i, line) in text.lines().enumerate() {
        let mut toks = uncomment(line).split_whitespace();
        let (element, problem) = match toks.next() {
            Some("v") => (
                ("vertex", &mut nv),
                vertex_problem(&toks.collect::<Vec<_>>()),
            ),
            Some("vn") => (
                ("normal", &mut nn),
                normal_problem(&toks.collect::<Vec<_>>()),
            ),
            Some("f") => {
                let corners: Vec<&str> = toks.collect();
                (("face", &mut nf), face_problem(&corners, nv, total))
            }
            _ => continue,
        };
        let (name, count) = element;
        if let Some(p) = problem {
            return Error::input(
                source,
                format!("{name} {count}"),
                format!("line {}: {p}", i + 1),
            );
        }
        *count += 1;
    }
    match line {
        Some(ln) => Error::input(
            source,
            "file",
            format!("line {ln}: cannot read this statement"),
        ),
        None => Error::input(source, "file", "a face index is out of range"),
    }
}

/// What is wrong with a `v` statement's values, if anything: three
/// coordinates and an optional non-zero weight w.
fn vertex_problem(rest: &[&str]) -> Option<String> {
    let n = if rest.len() == 4 {
        4
    } else {
        rest.len().min(3)
    };
    if rest.len() < 3 {
        Some(format!("expected 3 coordinates, found {}", rest.len()))
    } else if let Some(bad) = rest[..n].iter().find(|t| t.parse::<f64>().is_err()) {
        Some(format!("cannot parse '{bad}' as a number"))
    } else if n == 4 && rest[3].parse::<f64>() == Ok(0.0) {
        Some("homogeneous coordinate w is 0".into())
    } else {
        None
    }
}

/// What is wrong with a `vn` statement's values, if anything.
fn normal_problem(rest: &[&str]) -> Option<String> {
    if rest.len() < 3 {
        return Some(format!("expected 3 numbers, found {}", rest.len()));
    }
    rest[..3]
        .iter()
        .find(|t| t.parse::<f64>().is_err())
        .map(|bad| format!("cannot parse '{bad}' as a number"))
}

/// What is wrong with an `f` statement's corners, if anything, `seen` of
/// the file's `total` vertices read before it.
fn face_problem(corners: &[&str], seen: usize, total: usize) -> Option<String> {
    if let Some(p) = corners
        .iter()
        .find_map(|tok| check_corner(tok, seen, total))
    {
        return Some(p);
    }
    (corners.len() < 3)
        .then(|| format!("{} vertex indices; a face needs at least 3", corners.len()))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text.as_bytes(), "t.obj").unwrap_err().to_string()
    }

    #[test]
    fn corners_and_integers() {
        assert_eq!(integer(b"12"), Some(12));
        assert_eq!(integer(b"-3"), Some(-3));
        assert_eq!(integer(b"+3"), Some(3));
        assert_eq!(integer(b"-"), None);
        assert_eq!(integer(b"1x"), None);
        assert_eq!(integer(b"1234567890123456789"), None);
        assert_eq!(corner(b"3", 0), Some(2));
        assert_eq!(corner(b"3/1/2", 0), Some(2));
        assert_eq!(corner(b"3//2", 0), Some(2));
        assert_eq!(corner(b"3/", 0), Some(2));
        assert_eq!(corner(b"-1", 5), Some(4));
        assert_eq!(corner(b"-6", 5), None);
        assert_eq!(corner(b"0", 5), None);
        assert_eq!(corner(b"1/2/3/4", 5), None);
        assert_eq!(corner(b"1/x", 5), None);
    }

    #[test]
    fn forward_references_weights_and_colours() {
        let m = parse(
            b"f 1 2 3\nv 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\n\tv  0 1 0\r\nvt 1 1\nf 3 2 1\n",
            "t.obj",
        )
        .unwrap();
        assert_eq!(
            m.positions,
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        );
        assert_eq!(m.faces, vec![[0, 1, 2], [2, 1, 0]]);
    }

    #[test]
    fn bad_statements_are_named() {
        let e = err("v 0 0 0\nv 1 0\nf 1 2 3\n");
        assert!(e.contains("vertex 1") && e.contains("line 2"), "{e}");
        let e = err("v 0 0 0 0\nf 1 1 1\n");
        assert!(e.contains("vertex 0") && e.contains("w is 0"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2/x 3\n");
        assert!(e.contains("face 1") && e.contains("line 5"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n");
        assert!(e.contains("face 0") && e.contains("out of range"), "{e}");
        let e = err("v 0 0 0\nv\nf 1 2 1\n");
        assert!(e.contains("vertex 1") && e.contains("found 0"), "{e}");
        let e = err("v 0 0 0\nv 1 0 0\nf 1 2\n");
        assert!(e.contains("face 0") && e.contains("at least 3"), "{e}");
        // Not whitespace to this reader: a no-break space between numbers.
        let e = err("v 0 0 0\nv 1\u{a0}0 0\nv 0 1 0\nf 1 2 3\n");
        assert!(e.contains("line 2"), "{e}");
    }
}
