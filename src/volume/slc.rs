//! SLC reader (the Stony Brook "slice" format of VolVis, read by VTK's
//! `vtkSLCReader`): an ASCII header, an RGB icon, then one run-length
//! encoded (or raw) 8-bit slice after another.
//!
//! Layout: `11111` (magic), `nx ny nz bits` (bits = 8), `sx sy sz`
//! (spacing), `unit origin modifier compression`, `icon_w icon_h X` followed
//! by the icon's red, green and blue planes (`icon_w*icon_h` bytes each), then
//! per slice `size X` and `size` bytes. With compression 1 a slice is runs:
//! a byte `c` with `c & 0x7f` = run length (0 ends the slice), high bit set =
//! that many literal bytes follow, clear = the next byte repeats.

use std::path::Path;

use super::{Volume, oriented, read_file, voxel_count};
use crate::error::{Error, Result};

/// A cursor over the mixed text and binary content.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    source: &'a str,
}

impl<'a> Cursor<'a> {
    /// The next whitespace-separated token.
    fn token(&mut self, what: &str) -> Result<&'a str> {
        let rest = &self.bytes[self.pos.min(self.bytes.len())..];
        let start = rest.iter().take_while(|b| b.is_ascii_whitespace()).count();
        let len = rest[start..]
            .iter()
            .take_while(|b| !b.is_ascii_whitespace() && **b != b'X')
            .count();
        self.pos += start + len;
        let tok = &rest[start..start + len];
        if tok.is_empty() {
            return Err(Error::input(
                self.source,
                what,
                "unexpected end of the header",
            ));
        }
        std::str::from_utf8(tok).map_err(|_| Error::input(self.source, what, "not text"))
    }

    fn number<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        let tok = self.token(what)?;
        tok.parse()
            .map_err(|_| Error::input(self.source, what, format!("'{tok}' is not a valid number")))
    }

    /// Skips whitespace and the `X` that precedes binary data.
    fn x(&mut self, what: &str) -> Result<()> {
        let rest = &self.bytes[self.pos.min(self.bytes.len())..];
        let ws = rest.iter().take_while(|b| b.is_ascii_whitespace()).count();
        if rest.get(ws) != Some(&b'X') {
            return Err(Error::input(
                self.source,
                what,
                "expected 'X' before binary data",
            ));
        }
        self.pos += ws + 1;
        Ok(())
    }

    /// The next `n` bytes.
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| {
            Error::input(
                self.source,
                what,
                format!(
                    "expected {n} bytes, found {}",
                    self.bytes.len().saturating_sub(self.pos)
                ),
            )
        })?;
        let out = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(out)
    }
}

/// Loads an `.slc` file.
pub(super) fn load(path: &Path) -> Result<Volume> {
    let bytes = read_file(path)?;
    let source = path.display().to_string();
    let src = source.as_str();
    let mut c = Cursor {
        bytes: &bytes,
        pos: 0,
        source: src,
    };
    let h = read_header(&mut c, path)?;
    let count = voxel_count(h.dims, src, "sizes")?;
    skip_icon(&mut c)?;
    let values = read_slices(&mut c, &h, count)?;
    oriented(h.dims, values, h.spacing, [0.0; 3], src)
}

/// The header fields that are used.
struct Header {
    dims: [usize; 3],
    spacing: [f64; 3],
    /// 0 (none) or 1 (run-length).
    compression: u32,
}

/// Reads the header, up to the compression field, refusing other than
/// 8 bits per voxel and unknown compressions.
fn read_header(c: &mut Cursor<'_>, path: &Path) -> Result<Header> {
    let magic: u32 = c.number("magic number")?;
    if magic != 11111 {
        return Err(Error::input(
            c.source,
            "magic number",
            format!("{magic} is not 11111: not an SLC file"),
        ));
    }
    let dims = [
        c.number::<usize>("x size")?,
        c.number::<usize>("y size")?,
        c.number::<usize>("z size")?,
    ];
    let bits: u32 = c.number("bits per voxel")?;
    if bits != 8 {
        return Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("{bits} bits per voxel: shapecue reads 8-bit SLC files"),
        });
    }
    let spacing = [
        c.number::<f64>("x spacing")?,
        c.number::<f64>("y spacing")?,
        c.number::<f64>("z spacing")?,
    ];
    for what in ["unit type", "data origin", "data modifier"] {
        c.number::<i64>(what)?;
    }
    let compression: u32 = c.number("compression")?;
    if compression > 1 {
        return Err(Error::UnsupportedFormat {
            path: path.to_path_buf(),
            problem: format!("compression {compression} (0 and 1 = run-length are read)"),
        });
    }
    Ok(Header {
        dims,
        spacing,
        compression,
    })
}

/// Skips the icon: its size, an `X`, and its RGB bytes.
fn skip_icon(c: &mut Cursor<'_>) -> Result<()> {
    let icon_w: usize = c.number("icon width")?;
    let icon_h: usize = c.number("icon height")?;
    c.x("icon")?;
    let icon = icon_w
        .checked_mul(icon_h)
        .and_then(|n| n.checked_mul(3))
        .ok_or_else(|| Error::input(c.source, "icon", "icon size overflows"))?;
    c.take(icon, "icon")?;
    Ok(())
}

/// Reads the slices, each its size, an `X` and its (run-length) bytes.
fn read_slices(c: &mut Cursor<'_>, h: &Header, count: usize) -> Result<Vec<f32>> {
    let (src, dims) = (c.source, h.dims);
    let plane = dims[0] * dims[1];
    // Never reserve more than the file could decode to (runs of 127).
    let mut values: Vec<f32> = Vec::with_capacity(count.min(c.bytes.len().saturating_mul(64)));
    let mut slice = Vec::with_capacity(plane.min(c.bytes.len().saturating_mul(64)));
    for z in 0..dims[2] {
        let el = format!("slice {z}");
        let size: usize = c.number(&el)?;
        c.x(&el)?;
        let data = c.take(size, &el)?;
        slice.clear();
        if h.compression == 1 {
            decode_rle(data, plane, &mut slice).map_err(|p| Error::input(src, el.as_str(), p))?;
        } else {
            slice.extend_from_slice(data);
        }
        if slice.len() != plane {
            return Err(Error::input(
                src,
                el,
                format!(
                    "decodes to {} bytes, expected {plane} ({}×{})",
                    slice.len(),
                    dims[0],
                    dims[1]
                ),
            ));
        }
        values.extend(slice.iter().map(|&b| f32::from(b)));
    }
    Ok(values)
}

/// Decodes one run-length encoded slice of at most `max` bytes.
fn decode_rle(data: &[u8], max: usize, out: &mut Vec<u8>) -> std::result::Result<(), String> {
    let mut it = data.iter().copied();
    while let Some(c) = it.next() {
        let run = usize::from(c & 0x7f);
        if run == 0 {
            return Ok(());
        }
        if out.len() + run > max {
            return Err(format!("run-length data decode to more than {max} bytes"));
        }
        if c & 0x80 != 0 {
            for _ in 0..run {
                out.push(
                    it.next()
                        .ok_or("run-length data end inside a literal run")?,
                );
            }
        } else {
            let v = it.next().ok_or("run-length data end inside a repeat run")?;
            out.extend(std::iter::repeat_n(v, run));
        }
    }
    Err("run-length data end without the terminating 0".into())
}

#[cfg(test)]
mod tests {
    use super::decode_rle;

    #[test]
    fn run_length() {
        let mut out = Vec::new();
        decode_rle(&[0x83, 1, 2, 3, 0x02, 9, 0], 10, &mut out).unwrap();
        assert_eq!(out, [1, 2, 3, 9, 9]);
        out.clear();
        assert!(decode_rle(&[0x05, 1, 0], 4, &mut out).is_err());
        out.clear();
        assert!(decode_rle(&[0x83, 1], 10, &mut out).is_err());
        out.clear();
        assert!(decode_rle(&[0x01, 1], 10, &mut out).is_err());
    }
}
