use std::fmt::Write as _;

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
                // x y z [w] are kept; x y z r g b loses its colour. No
                // allocation per line: the first five tokens and the count.
                let mut rest = [""; 5];
                let mut len = 0;
                for t in toks {
                    if len < rest.len() {
                        rest[len] = t;
                    }
                    len += 1;
                }
                let n = if len == 4 { 4 } else { len.min(3) };
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
            write!(input, " {k}").expect("writing to a String cannot fail");
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
                    return Error::input(source, format!("vertex {nv}"), format!("line {ln}: {p}"));
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
