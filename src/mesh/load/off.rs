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
    let (nv, nf) = read_counts(&mut lines, source)?;

    // The memory bound: one line per element, so counts that the lines
    // after the counts line cannot hold are refused before anything is
    // reserved or parsed (counting lines allocates nothing). Every element
    // line takes at least two bytes, a vertex line at least six (`0 0 0`)
    // and a face line eight (`3 0 1 2`), so the reservations below are
    // also bounded by the file size.
    check_counts(nv, nf, lines.clone().count(), bytes.len(), source)?;
    let mut positions = Vec::with_capacity(capped(nv, bytes.len(), 6));
    for i in 0..nv {
        positions.push(vertex(lines.next(), i, nv, source)?);
    }
    let mut faces = Vec::with_capacity(capped(nf, bytes.len(), 8));
    let mut poly: Vec<u32> = Vec::new();
    for j in 0..nf {
        face(lines.next(), j, (nv, nf), source, &mut poly)?;
        fan(&poly, &mut faces);
    }
    Ok(Mesh {
        positions,
        faces,
        normals: None,
    })
}

/// Reads the header: the optional `OFF` keyword and the vertex and face
/// counts, on its line or the next.
fn read_counts<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    source: &str,
) -> Result<(usize, usize)> {
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
        let tok = counts
            .get(k)
            .ok_or_else(|| header_err(format!("line {counts_line}: missing the {what} count")))?;
        tok.parse::<usize>().map_err(|_| {
            header_err(format!(
                "line {counts_line}: {what} count '{tok}' is not a non-negative integer"
            ))
        })
    };
    Ok((count(0, "vertex")?, count(1, "face")?))
}

/// Reads vertex `i` from its line (`None` past the end of the file).
fn vertex(line: Option<(usize, &str)>, i: usize, nv: usize, source: &str) -> Result<[f64; 3]> {
    let element = || format!("vertex {i}");
    let (ln, l) = line.ok_or_else(|| {
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
    Ok(p)
}

/// Reads face `j` from its line (`None` past the end of the file) into
/// `poly`, its indices checked against the `nv` of the counts `(nv, nf)`.
fn face(
    line: Option<(usize, &str)>,
    j: usize,
    (nv, nf): (usize, usize),
    source: &str,
    poly: &mut Vec<u32>,
) -> Result<()> {
    let element = || format!("face {j}");
    let (ln, l) = line.ok_or_else(|| {
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
    Ok(())
}

/// The vertex and face counts of the OFF header at the start of `head`
/// (the keyword is optional, the counts may follow it on its line);
/// `None` when they cannot be read from it.
pub(super) fn header_counts(head: &[u8]) -> Option<(usize, usize)> {
    let text = String::from_utf8_lossy(head);
    let mut lines = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .filter(|l| !l.trim().is_empty());
    let mut toks: Vec<&str> = lines.next()?.split_whitespace().collect();
    if toks.first().is_some_and(|t| t.parse::<u64>().is_err()) {
        toks.remove(0);
        if toks.is_empty() {
            toks = lines.next()?.split_whitespace().collect();
        }
    }
    Some((toks.first()?.parse().ok()?, toks.get(1)?.parse().ok()?))
}

/// Refuses vertex and face counts that the `lines` element lines after
/// the counts line (of a file of `size` bytes) cannot hold, naming the
/// first element the file lacks, as the error of a truncated file does.
fn check_counts(nv: usize, nf: usize, lines: usize, size: usize, source: &str) -> Result<()> {
    let (element, declared) = if nv > lines {
        (format!("vertex {lines}"), format!("{nv} vertices"))
    } else if nf > lines - nv {
        (
            format!("face {}", lines - nv),
            format!("{nv} vertices and {nf} faces"),
        )
    } else {
        return Ok(());
    };
    Err(Error::input(
        source,
        element,
        format!(
            "unexpected end of file: the header declares {declared} (one line each), but \
             the {size}-byte file holds only {lines} lines after the counts"
        ),
    ))
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
