//! Where the samples of a NRRD or MetaImage header are: attached to the
//! header, or in detached data files named by one file name, a `LIST` of
//! names (one per line after the field) or a `printf`-style pattern
//! (`slice%03d.raw 1 93 1`). Both formats have the same three detached
//! forms with a `subdim` (the number of fast axes one file holds in full);
//! they differ only in the field's name, a few spellings and the words of
//! their messages, which [`Syntax`] holds, so one parser serves both.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use super::{Payload, dims_text, number};
use crate::error::{Error, Result};

/// Where the samples are.
#[derive(Debug)]
pub(super) enum DataFiles {
    /// In the header file from this byte offset on (NRRD's attached data
    /// after the blank line, MetaImage's `ElementDataFile = LOCAL`).
    Attached(usize),
    /// In these files, each holding an equal share along the slowest axes;
    /// `subdim` is the number of fast axes one file holds in full.
    Detached { files: Vec<PathBuf>, subdim: usize },
}

/// How one header format spells its data-file field and words its errors.
pub(super) struct Syntax {
    /// The field, as named in messages and as the element of a file-count
    /// error: `ElementDataFile`, `data file`.
    pub field: &'static str,
    /// The format's word for the subdimension: `slab dimension`, `subdim`.
    pub subdim: &'static str,
    /// The error when a multi-file form comes before the grid size.
    pub sizes_first: &'static str,
    /// What bounds a `LIST`, ending "more than the {max} files …".
    pub list_bound: &'static str,
    /// The error for an empty value.
    pub empty: &'static str,
    /// The name of attached data in messages: `local data`, `attached data`.
    pub attached: &'static str,
    /// MetaIO's spellings: `LIST` in any case and a subdimension written
    /// `2D`; a value with more than five words is one file name rather
    /// than a malformed pattern.
    pub metaio: bool,
}

/// MetaImage's `ElementDataFile`.
pub(super) const METAIMAGE: Syntax = Syntax {
    field: "ElementDataFile",
    subdim: "slab dimension",
    sizes_first: "DimSize must come before a multi-file ElementDataFile",
    list_bound: "DimSize needs",
    empty: "empty ElementDataFile",
    attached: "local data",
    metaio: true,
};

/// NRRD's `data file`.
pub(super) const NRRD: Syntax = Syntax {
    field: "data file",
    subdim: "subdim",
    sizes_first: "'sizes' must come before a multi-file 'data file'",
    list_bound: "the sizes need",
    empty: "empty data file name",
    attached: "attached data",
    metaio: false,
};

/// Parses the detached forms of the data-file field's `value` (the
/// attached forms are the caller's: NRRD's blank line, MetaImage's
/// `LOCAL`). `rest` yields the header lines after the field (the names of a
/// `LIST`); `dims`, the grid size, must be known for a multi-file form so
/// that the list or pattern can be bounded. Names are resolved against
/// `dir`; errors name `source` and the element `el`.
#[allow(clippy::too_many_arguments)]
pub(super) fn detached<'a>(
    syntax: &Syntax,
    value: &str,
    rest: impl Iterator<Item = &'a [u8]>,
    dims: Option<[usize; 3]>,
    dir: &Path,
    source: &str,
    el: &str,
) -> Result<DataFiles> {
    let field = Field {
        syntax,
        dims,
        source,
        el,
    };
    let toks: Vec<&str> = value.split_whitespace().collect();
    let is_list = toks.first().is_some_and(|t| {
        if syntax.metaio {
            t.eq_ignore_ascii_case("list")
        } else {
            *t == "LIST"
        }
    });
    if is_list {
        return field.list(&toks, rest, dir);
    }
    if toks.len() >= 4 && toks[0].contains('%') && (toks.len() <= 5 || !syntax.metaio) {
        return field.pattern(&toks, value, dir);
    }
    if value.is_empty() {
        return Err(Error::input(source, el, syntax.empty));
    }
    Ok(DataFiles::Detached {
        files: vec![dir.join(value)],
        subdim: 3,
    })
}

/// The data-file field being parsed: its syntax, the grid size if known,
/// and the header's name and element for messages.
struct Field<'s> {
    syntax: &'s Syntax,
    dims: Option<[usize; 3]>,
    source: &'s str,
    el: &'s str,
}

impl Field<'_> {
    /// The subdimension written as `tok` (2 when absent), checked to be 1 to 3.
    fn subdim(&self, tok: Option<&&str>) -> Result<usize> {
        let (syntax, source, el) = (self.syntax, self.source, self.el);
        let field = syntax.field;
        let d = match tok {
            None => 2,
            Some(t) => {
                // MetaIO writes the slab dimension as e.g. "2D".
                let t = if syntax.metaio {
                    t.trim_end_matches(['D', 'd'])
                } else {
                    t
                };
                number(t, &format!("{field} {}", syntax.subdim), source, el)?
            }
        };
        if (1..=3).contains(&d) {
            Ok(d)
        } else {
            Err(Error::input(
                source,
                el,
                format!("{field} {} {d} must be 1, 2 or 3", syntax.subdim),
            ))
        }
    }

    /// How many slabs of `sub` fast axes the grid holds (the grid size must
    /// be known).
    fn slabs(&self, sub: usize) -> Result<usize> {
        let dims = self
            .dims
            .ok_or_else(|| Error::input(self.source, self.el, self.syntax.sizes_first))?;
        Ok(dims[sub..].iter().fold(1usize, |n, &d| n.saturating_mul(d)))
    }

    /// The `LIST [subdim]` form: one file name per following line, at most
    /// one per slab.
    fn list<'a>(
        &self,
        toks: &[&str],
        rest: impl Iterator<Item = &'a [u8]>,
        dir: &Path,
    ) -> Result<DataFiles> {
        let sub = self.subdim(toks.get(1))?;
        let max = self.slabs(sub)?;
        let mut files = Vec::new();
        for line in rest {
            let name = String::from_utf8_lossy(line);
            let name = name.trim();
            if name.is_empty() {
                continue;
            }
            if files.len() == max {
                return Err(Error::input(
                    self.source,
                    self.el,
                    format!(
                        "the {} LIST names more than the {max} files {}",
                        self.syntax.field, self.syntax.list_bound
                    ),
                ));
            }
            files.push(dir.join(name));
        }
        Ok(DataFiles::Detached { files, subdim: sub })
    }

    /// The `format min max step [subdim]` form: the files a pattern names.
    fn pattern(&self, toks: &[&str], value: &str, dir: &Path) -> Result<DataFiles> {
        let (source, el) = (self.source, self.el);
        if toks.len() > 5 {
            return Err(Error::input(
                source,
                el,
                format!("expected 'format min max step [subdim]', found '{value}'"),
            ));
        }
        let sub = self.subdim(toks.get(4))?;
        let field = self.syntax.field;
        let int =
            |k: usize, what: &str| number::<i64>(toks[k], &format!("{field} {what}"), source, el);
        let files = pattern_files(
            toks[0],
            int(1, "min")?,
            int(2, "max")?,
            int(3, "step")?,
            self.slabs(sub)?,
            dir,
        )
        .map_err(|p| Error::input(source, el, p))?;
        Ok(DataFiles::Detached { files, subdim: sub })
    }
}

impl DataFiles {
    /// The shape of the samples one chunk holds (the grid, or a slab of
    /// it), after checking that the data files cover the grid's `total`
    /// samples exactly.
    pub(super) fn chunk_shape(
        &self,
        syntax: &Syntax,
        dims: [usize; 3],
        total: usize,
        source: &str,
    ) -> Result<Vec<usize>> {
        match self {
            DataFiles::Attached(_) => Ok(dims.to_vec()),
            DataFiles::Detached { files, subdim } => {
                let shape = dims[..*subdim].to_vec();
                let per_file: usize = shape.iter().product();
                if files.len() != total / per_file {
                    // NRRD's message also names the grid and the subdim.
                    let detail = if syntax.metaio {
                        String::new()
                    } else {
                        format!(" ({} grid, {subdim} axes per file)", dims_text(dims))
                    };
                    return Err(Error::input(
                        source,
                        syntax.field,
                        format!(
                            "{} data files for {} slabs of {per_file} samples{detail}",
                            files.len(),
                            total / per_file,
                        ),
                    ));
                }
                Ok(shape)
            }
        }
    }

    /// Decodes the samples: attached ones from `header` (the header file's
    /// bytes), detached ones from their files, in order, each file's size
    /// checked before it is read and only the bytes needed read
    /// ([`Payload::read_files`]).
    pub(super) fn read(
        &self,
        syntax: &Syntax,
        payload: &Payload,
        header: &[u8],
    ) -> Result<Vec<f32>> {
        match self {
            DataFiles::Attached(offset) => {
                let attached = header.get(*offset..).unwrap_or_default();
                payload.read([Ok((Cow::Borrowed(attached), syntax.attached.to_string()))])
            }
            DataFiles::Detached { files, .. } => payload.read_files(files),
        }
    }
}

/// The data files of a `printf`-style pattern with one integer conversion
/// (`slice%03d.raw 1 93 1`), expanded; at most `max_files` of them. Names
/// are resolved against `dir`.
fn pattern_files(
    fmt: &str,
    min: i64,
    max: i64,
    step: i64,
    max_files: usize,
    dir: &Path,
) -> std::result::Result<Vec<PathBuf>, String> {
    if step == 0 {
        return Err("the step of a data file pattern cannot be 0".into());
    }
    // Compared, not subtracted: `max - min` overflows for far-apart bounds.
    if max != min && (max > min) != (step > 0) {
        return Err(format!(
            "a data file pattern from {min} to {max} cannot use step {step}"
        ));
    }
    let count = (max.abs_diff(min) / step.unsigned_abs()).saturating_add(1);
    if count > max_files as u64 {
        return Err(format!(
            "the data file pattern names {count} files, more than the grid has slices ({max_files})"
        ));
    }
    let (pre, spec, post) = split_format(fmt)?;
    (0..count)
        .map(|k| {
            let i = min + step * k as i64;
            Ok(dir.join(format!("{pre}{}{post}", spec.format(i))))
        })
        .collect()
}

/// One `%[0][width]d` (or `i`, `u`) conversion of a file name pattern.
struct IntFormat {
    zero: bool,
    width: usize,
}

impl IntFormat {
    fn format(&self, i: i64) -> String {
        if self.zero {
            format!("{i:0width$}", width = self.width)
        } else {
            format!("{i:width$}", width = self.width)
        }
    }
}

/// Splits a `printf` pattern into the text before its one integer
/// conversion, the conversion and the text after it (`%%` is a literal `%`).
fn split_format(fmt: &str) -> std::result::Result<(String, IntFormat, String), String> {
    let bad = || {
        format!(
            "data file pattern '{fmt}' must contain exactly one integer conversion such as %d or %03d"
        )
    };
    let mut pre = String::new();
    let mut post = String::new();
    let mut conv = None;
    let mut chars = fmt.chars().peekable();
    while let Some(c) = chars.next() {
        let out = if conv.is_some() { &mut post } else { &mut pre };
        if c != '%' {
            out.push(c);
            continue;
        }
        if chars.peek() == Some(&'%') {
            chars.next();
            out.push('%');
            continue;
        }
        if conv.is_some() {
            return Err(bad());
        }
        let zero = chars.next_if_eq(&'0').is_some();
        let mut width = 0usize;
        while let Some(d) = chars.peek().and_then(|c| c.to_digit(10)) {
            chars.next();
            width = width.saturating_mul(10).saturating_add(d as usize);
        }
        if width > 64 || !matches!(chars.next(), Some('d' | 'i' | 'u')) {
            return Err(bad());
        }
        conv = Some(IntFormat { zero, width });
    }
    conv.map(|c| (pre, c, post)).ok_or_else(bad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_patterns() {
        let dir = Path::new("d");
        let names = |f, a, b, s| {
            pattern_files(f, a, b, s, 100, dir).map(|v| {
                v.iter()
                    .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
                    .collect::<Vec<_>>()
            })
        };
        assert_eq!(names("q.%d", 1, 3, 1).unwrap(), ["q.1", "q.2", "q.3"]);
        assert_eq!(
            names("s%03d.raw", 9, 11, 2).unwrap(),
            ["s009.raw", "s011.raw"]
        );
        assert_eq!(names("%%%i", 2, 1, -1).unwrap(), ["%2", "%1"]);
        assert!(names("q.%d", 1, 3, 0).is_err());
        assert!(names("q.%d", 3, 1, 1).is_err());
        assert!(names("q.%s", 1, 3, 1).is_err());
        assert!(names("q.%d.%d", 1, 3, 1).is_err());
        assert!(names("q", 1, 3, 1).is_err());
        assert!(names("q.%d", 0, i64::MAX, 1).is_err());
    }
}
