//! Decoding samples: bulk conversion of binary values to `f32`, ASCII
//! numbers, gzip and zlib decompression within a memory bound, and the
//! payload of NRRD and MetaImage files (attached data or detached data
//! files, raw, compressed or ASCII, with their line and byte skips).

use std::borrow::Cow;
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use super::{
    ScalarType, byte_count, number, open_file, read_file, size_problem, skip_line, skip_lines,
    voxel_count,
};
use crate::error::{Error, Result};

/// Appends `bytes` (a whole number of values) converted to `f32`.
pub(super) fn convert_into(bytes: &[u8], scalar: ScalarType, big_endian: bool, out: &mut Vec<f32>) {
    // `as_chunks` gives fixed-size arrays: the loops below compile to
    // straight-line conversions the optimiser vectorises.
    macro_rules! conv {
        ($t:ty) => {{
            const N: usize = std::mem::size_of::<$t>();
            let (chunks, _) = bytes.as_chunks::<N>();
            if big_endian {
                out.extend(chunks.iter().map(|c| <$t>::from_be_bytes(*c) as f32));
            } else {
                out.extend(chunks.iter().map(|c| <$t>::from_le_bytes(*c) as f32));
            }
        }};
    }
    match scalar {
        ScalarType::U8 => out.extend(bytes.iter().map(|&b| f32::from(b))),
        ScalarType::I8 => out.extend(bytes.iter().map(|&b| f32::from(b as i8))),
        ScalarType::U16 => conv!(u16),
        ScalarType::I16 => conv!(i16),
        ScalarType::U32 => conv!(u32),
        ScalarType::I32 => conv!(i32),
        ScalarType::F32 => conv!(f32),
        ScalarType::F64 => conv!(f64),
    }
}

/// Parses `count` whitespace-separated numbers (ASCII payloads), appending
/// them to `out`. Extra tokens after them are left alone.
pub(super) fn parse_ascii_into(
    text: &[u8],
    count: usize,
    out: &mut Vec<f32>,
    source: &str,
    element: &str,
) -> Result<()> {
    let mut toks = text
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty());
    out.reserve(count.min(text.len() / 2 + 1));
    for i in 0..count {
        let tok = toks.next().ok_or_else(|| {
            Error::input(
                source,
                element,
                format!("expected {count} values, found {i}"),
            )
        })?;
        let v = std::str::from_utf8(tok)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
            .ok_or_else(|| {
                Error::input(
                    source,
                    element,
                    format!(
                        "value {i}: '{}' is not a number",
                        String::from_utf8_lossy(tok)
                    ),
                )
            })?;
        out.push(v as f32);
    }
    Ok(())
}

/// A compressed stream format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Compression {
    /// gzip (RFC 1952), as NRRD's `encoding: gzip`.
    Gzip,
    /// zlib (RFC 1950), as MetaImage's `CompressedData` and VTK XML blocks.
    Zlib,
}

/// Deflate's largest expansion (one 258-byte match in 2 bits): `n` bytes of
/// gzip or zlib data never inflate to more than `MAX_INFLATE * n` bytes.
pub(super) const MAX_INFLATE: usize = 1032;

/// The memory bound of compressed data: refuses, before anything is
/// inflated or allocated, a header that asks more bytes (`want`) of `have`
/// compressed bytes than deflate can produce from them.
pub(super) fn check_inflate(
    have: usize,
    want: usize,
    kind: Compression,
) -> std::result::Result<(), String> {
    if want > have.saturating_mul(MAX_INFLATE) {
        return Err(format!(
            "{have} bytes of {} data cannot hold the {want} bytes the header calls for \
             (deflate expands at most {MAX_INFLATE}:1)",
            kind.name()
        ));
    }
    Ok(())
}

impl Compression {
    /// The format's name in messages.
    pub(super) fn name(self) -> &'static str {
        match self {
            Compression::Gzip => "gzip",
            Compression::Zlib => "zlib",
        }
    }
}

/// Decompresses `data`, reading at most `limit` bytes of output so that a
/// lying header or a compression bomb cannot exhaust memory; the caller
/// checks the size it gets.
pub(super) fn decompress(
    data: impl Read,
    kind: Compression,
    limit: usize,
) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let limit = limit as u64;
    let res = match kind {
        Compression::Gzip => flate2::read::MultiGzDecoder::new(data)
            .take(limit)
            .read_to_end(&mut out),
        Compression::Zlib => flate2::read::ZlibDecoder::new(data)
            .take(limit)
            .read_to_end(&mut out),
    };
    match res {
        Ok(_) => Ok(out),
        Err(e) => Err(format!("{kind:?} data cannot be decompressed: {e}").to_lowercase()),
    }
}

/// How the samples of NRRD and MetaImage data files are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Encoding {
    /// Binary samples.
    Raw,
    /// Binary samples, compressed.
    Compressed(Compression),
    /// Whitespace-separated numbers.
    Ascii,
}

/// Where the bytes of a data chunk start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Skip {
    /// After this many bytes (of the decompressed data when compressed).
    Bytes(usize),
    /// At the end of the file: the last bytes are the samples (NRRD
    /// `byte skip: -1`, MetaImage `HeaderSize = -1`); raw encoding only.
    ToEnd,
}

impl Skip {
    /// Parses a header's skip `field` (NRRD `byte skip`, MetaImage
    /// `HeaderSize`): a byte count, or -1 for the end of the file.
    pub(super) fn parse(value: &str, field: &str, source: &str, element: &str) -> Result<Skip> {
        let n: i64 = number(value, field, source, element)?;
        match usize::try_from(n) {
            Ok(n) => Ok(Skip::Bytes(n)),
            Err(_) if n == -1 => Ok(Skip::ToEnd),
            Err(_) => Err(Error::input(
                source,
                element,
                format!("{field} {n} must be -1 or at least 0"),
            )),
        }
    }
}

/// The payload of a NRRD or MetaImage file: samples stored in one or more
/// chunks (the attached data, or data files that each hold an equal share).
pub(super) struct Payload<'a> {
    /// The header's name, for messages.
    pub(super) source: &'a str,
    pub(super) dims: [usize; 3],
    pub(super) scalar: ScalarType,
    pub(super) big_endian: bool,
    pub(super) encoding: Encoding,
    /// Text lines to skip at the start of each chunk (before decompression).
    pub(super) line_skip: usize,
    /// Bytes to skip at the start of each chunk (after decompression).
    pub(super) byte_skip: Skip,
    /// The shape of the samples of one chunk, for messages (the grid, or a
    /// slab of it).
    pub(super) chunk_shape: Vec<usize>,
}

impl Payload<'_> {
    /// Decodes the chunks (their bytes and their name for messages), in
    /// order, into the samples of the whole grid.
    pub(super) fn read<'c>(
        &self,
        chunks: impl IntoIterator<Item = Result<(Cow<'c, [u8]>, String)>>,
    ) -> Result<Vec<f32>> {
        self.gather(|per_chunk, values| {
            for chunk in chunks {
                let (bytes, element) = chunk?;
                self.read_chunk(&bytes, &element, per_chunk, values)?;
            }
            Ok(())
        })
    }

    /// Decodes detached data files, in order, into the samples of the whole
    /// grid (see [`Payload::read_data_file`]).
    pub(super) fn read_files(&self, files: &[PathBuf]) -> Result<Vec<f32>> {
        self.gather(|per_chunk, values| {
            files
                .iter()
                .try_for_each(|f| self.read_data_file(f, per_chunk, values))
        })
    }

    /// The samples of the whole grid, appended by `fill` (given the samples
    /// per chunk), checked to be exactly the grid's count.
    fn gather(&self, fill: impl FnOnce(usize, &mut Vec<f32>) -> Result<()>) -> Result<Vec<f32>> {
        let total = voxel_count(self.dims, self.source, "sizes")?;
        let mut values = Vec::new();
        fill(self.chunk_shape.iter().product(), &mut values)?;
        if values.len() != total {
            // The callers size the chunks and files from the header; this is
            // a guard, not an expected path.
            return Err(Error::input(
                self.source,
                "data",
                format!("{} samples read for a grid of {total}", values.len()),
            ));
        }
        Ok(values)
    }

    /// Decodes one detached data file of `count` samples, appending them
    /// to `out`. Binary data are streamed: the file's size is checked with
    /// its metadata before anything is read, and only the lines to skip,
    /// the bytes to skip and the samples are read (a raw file of the wrong
    /// size is refused unread; with a byte skip of -1 only its last bytes
    /// are read); compressed data are inflated one byte past what the
    /// header calls for and no further, so a compression bomb cannot
    /// exhaust memory. ASCII data are read whole: their length does not
    /// tell how many values they hold.
    fn read_data_file(&self, path: &Path, count: usize, out: &mut Vec<f32>) -> Result<()> {
        let el = format!("data file {}", path.display());
        let compression = match self.encoding {
            Encoding::Ascii => {
                let data = read_file(path)?;
                return self.read_chunk(&data, &el, count, out);
            }
            Encoding::Raw => None,
            Encoding::Compressed(kind) => Some(kind),
        };
        let (mut r, size) = self.open_data_file(path)?;
        let skipped = self.skip_data_lines(&mut r, path, &el)?;
        let file = DataFile {
            path,
            el,
            size,
            skipped,
        };
        let expected = byte_count(count, self.scalar, self.source, &file.el)?;
        let data = match compression {
            None => self.read_raw(&file, r, expected)?,
            Some(kind) => self.read_compressed(&file, r, kind, expected)?,
        };
        convert_into(&data, self.scalar, self.big_endian, out);
        Ok(())
    }

    /// Opens a data file that exists and is no folder; with its size.
    fn open_data_file(&self, path: &Path) -> Result<(BufReader<File>, u64)> {
        let src = self.source;
        // The header names the file: errors name both.
        let named = || format!("data file {}", path.display());
        match std::fs::metadata(path) {
            Ok(m) if m.is_dir() => Err(Error::input(
                src,
                named(),
                "is a folder, not a file of samples",
            )),
            Err(e) => Err(Error::input(src, named(), format!("cannot be read: {e}"))),
            Ok(_) => open_file(path),
        }
    }

    /// Skips the `line_skip` text lines of a data file; the bytes skipped.
    fn skip_data_lines(&self, r: &mut BufReader<File>, path: &Path, el: &str) -> Result<u64> {
        let mut skipped = 0u64;
        for _ in 0..self.line_skip {
            skipped += skip_line(r)
                .map_err(|e| io_error(path, e))?
                .ok_or_else(|| {
                    Error::input(
                        self.source,
                        el,
                        format!(
                            "file ends before the {} lines to skip ('line skip')",
                            self.line_skip
                        ),
                    )
                })?;
        }
        Ok(skipped)
    }

    /// Reads the `expected` bytes of samples of an uncompressed data file,
    /// after its byte skip (or at its end), refusing a file of the wrong size.
    fn read_raw(&self, f: &DataFile, mut r: BufReader<File>, expected: usize) -> Result<Vec<u8>> {
        let rest = f.size.saturating_sub(f.skipped);
        let (offset, found) = match self.byte_skip {
            Skip::Bytes(n) => (n as u64, rest.saturating_sub(n as u64)),
            // The last bytes: a larger file is fine, a smaller one not.
            Skip::ToEnd => (
                rest.saturating_sub(expected as u64),
                rest.min(expected as u64),
            ),
        };
        if found != expected as u64 {
            return Err(self.wrong_size(f, found));
        }
        // `offset` is at most the file's size: it fits in an i64.
        r.seek_relative(offset as i64)
            .map_err(|e| io_error(f.path, e))?;
        let mut buf = vec![0u8; expected];
        r.read_exact(&mut buf).map_err(|e| io_error(f.path, e))?;
        Ok(buf)
    }

    /// The error for a raw data file holding `found` bytes of samples.
    fn wrong_size(&self, f: &DataFile, found: u64) -> Error {
        let (size, skipped) = (f.size, f.skipped);
        let lines = if skipped > 0 {
            format!(", {skipped} of them in skipped lines")
        } else {
            String::new()
        };
        Error::input(
            self.source,
            &f.el,
            format!(
                "{} (the file has {size} bytes{lines})",
                size_problem(&self.chunk_shape, self.scalar, found as usize)
            ),
        )
    }

    /// The byte skip of compressed data (`el` names the element in errors):
    /// a count, since data "at the end of the file" has no place in a stream
    /// that must be inflated from its start.
    fn compressed_skip(&self, el: &str) -> Result<usize> {
        match self.byte_skip {
            Skip::Bytes(n) => Ok(n),
            Skip::ToEnd => Err(Error::input(
                self.source,
                el,
                "a byte skip of -1 (data at the end of the file) cannot be used \
                 with compressed data",
            )),
        }
    }

    /// Inflates a compressed data file, within the memory bound, to its
    /// byte skip and the `expected` bytes of samples, and returns the latter.
    fn read_compressed(
        &self,
        f: &DataFile,
        r: BufReader<File>,
        kind: Compression,
        expected: usize,
    ) -> Result<Vec<u8>> {
        let (src, el) = (self.source, f.el.as_str());
        let skip = self.compressed_skip(el)?;
        let rest = f.size.saturating_sub(f.skipped);
        let limit = skip.saturating_add(expected).saturating_add(1);
        let have = usize::try_from(rest).unwrap_or(usize::MAX);
        check_inflate(have, limit - 1, kind).map_err(|p| Error::input(src, el, p))?;
        let mut d = decompress(r, kind, limit).map_err(|p| Error::input(src, el, p))?;
        let want = skip.saturating_add(expected);
        if d.len() > want {
            return Err(Error::input(
                src,
                el,
                format!(
                    "the {} data inflate to more than the {want} bytes the header calls \
                     for (decompression stopped there)",
                    kind.name()
                ),
            ));
        }
        if d.len() < want {
            let found = d.len().saturating_sub(skip);
            return Err(Error::input(
                src,
                el,
                size_problem(&self.chunk_shape, self.scalar, found),
            ));
        }
        d.drain(..skip);
        Ok(d)
    }

    /// Decodes one chunk of `count` samples, appending them to `out`.
    fn read_chunk(&self, bytes: &[u8], el: &str, count: usize, out: &mut Vec<f32>) -> Result<()> {
        let src = self.source;
        let mut data = skip_lines(bytes, self.line_skip).ok_or_else(|| {
            Error::input(
                src,
                el,
                format!(
                    "file ends before the {} lines to skip ('line skip')",
                    self.line_skip
                ),
            )
        })?;
        let expected = byte_count(count, self.scalar, src, el)?;
        let decompressed;
        match self.encoding {
            Encoding::Ascii => {
                if let Skip::Bytes(n) = self.byte_skip {
                    data = data.get(n..).unwrap_or_default();
                }
                return parse_ascii_into(data, count, out, src, el);
            }
            Encoding::Compressed(kind) => {
                let skip = self.compressed_skip(el)?;
                let limit = skip.saturating_add(expected).saturating_add(1);
                check_inflate(data.len(), limit - 1, kind).map_err(|p| Error::input(src, el, p))?;
                decompressed =
                    decompress(data, kind, limit).map_err(|p| Error::input(src, el, p))?;
                data = decompressed.get(skip..).unwrap_or_default();
            }
            Encoding::Raw => {
                data = match self.byte_skip {
                    Skip::Bytes(n) => data.get(n..).unwrap_or_default(),
                    Skip::ToEnd => data
                        .get(data.len().saturating_sub(expected)..)
                        .unwrap_or(data),
                };
            }
        }
        if data.len() != expected {
            return Err(Error::input(
                src,
                el,
                size_problem(&self.chunk_shape, self.scalar, data.len()),
            ));
        }
        convert_into(data, self.scalar, self.big_endian, out);
        Ok(())
    }
}

/// A detached data file being read: its path, its name for messages, its
/// size and the bytes of the lines skipped at its start.
struct DataFile<'p> {
    path: &'p Path,
    el: String,
    size: u64,
    skipped: u64,
}

/// The error for a failed read of `path`.
fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_of_every_type() {
        let mut out = Vec::new();
        convert_into(&[0xff, 0x01], ScalarType::I8, false, &mut out);
        convert_into(&[0xff, 0x01], ScalarType::U8, false, &mut out);
        convert_into(&[0x01, 0x02], ScalarType::U16, true, &mut out);
        convert_into(&[0x01, 0x02], ScalarType::U16, false, &mut out);
        convert_into(&(-3i16).to_le_bytes(), ScalarType::I16, false, &mut out);
        convert_into(&7u32.to_be_bytes(), ScalarType::U32, true, &mut out);
        convert_into(&(-9i32).to_le_bytes(), ScalarType::I32, false, &mut out);
        convert_into(&1.5f32.to_be_bytes(), ScalarType::F32, true, &mut out);
        convert_into(&(-2.25f64).to_le_bytes(), ScalarType::F64, false, &mut out);
        assert_eq!(
            out,
            [
                -1.0, 1.0, 255.0, 1.0, 258.0, 513.0, -3.0, 7.0, -9.0, 1.5, -2.25
            ]
        );
    }
}
