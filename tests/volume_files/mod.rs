//! The volume tests' own helpers, included by `tests/volume.rs` and
//! `tests/volume_formats.rs` with `mod volume_files;`: loading with the
//! expected outcome, and small synthetic files of every format (a 2×3×4
//! grid, the encoders and the file layouts).

// Each test binary uses only part of these.
#![allow(dead_code)]

use std::io::Write;
use std::path::Path;

use shapecue::Error;
use shapecue::volume::{RawSpec, Volume, load};

pub fn ok(path: &Path) -> Volume {
    load(path, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Loads and expects an error; returns it and its message.
pub fn err(path: &Path, raw: Option<&RawSpec>) -> (Error, String) {
    match load(path, raw) {
        Ok(v) => panic!(
            "{}: expected an error, loaded {:?} samples",
            path.display(),
            v.dims
        ),
        Err(e) => {
            let msg = e.to_string();
            (e, msg)
        }
    }
}

/// Expects an `InvalidInput` naming the file and containing every `needle`.
pub fn invalid(path: &Path, needles: &[&str]) -> String {
    let (e, msg) = err(path, None);
    assert!(
        matches!(e, Error::InvalidInput { .. }),
        "expected InvalidInput, got {e:?}"
    );
    assert!(
        msg.contains(&path.display().to_string()),
        "message does not name the file: {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "message lacks '{n}': {msg}");
    }
    msg
}

/// Expects an `UnsupportedFormat` containing every `needle`.
pub fn unsupported(path: &Path, needles: &[&str]) -> String {
    let (e, msg) = err(path, None);
    assert!(
        matches!(e, Error::UnsupportedFormat { .. }),
        "expected UnsupportedFormat, got {e:?}"
    );
    for n in needles {
        assert!(msg.contains(n), "message lacks '{n}': {msg}");
    }
    msg
}

// ---------------------------------------------------------------------------
// Synthetic files
// ---------------------------------------------------------------------------

/// A 2×3×4 grid with distinct values (negative ones too).
pub const DIMS: [usize; 3] = [2, 3, 4];

pub fn grid_values() -> Vec<f32> {
    (0..24).map(|i| i as f32 * 1.5 - 7.0).collect()
}

pub fn as_i16_le(v: &[f32]) -> Vec<u8> {
    v.iter()
        .flat_map(|&x| (x.round() as i16).to_le_bytes())
        .collect()
}

pub fn gzip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

pub fn zlib(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

pub fn b64(data: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(data)
}

pub fn rounded() -> Vec<f32> {
    grid_values().iter().map(|x| x.round()).collect()
}

pub fn nrrd_header(extra: &str) -> String {
    format!("NRRD0004\n# test\ndimension: 3\nsizes: 2 3 4\n{extra}")
}

/// A `.vti` file around one `DataArray`; `appended` is the raw bytes after `_`.
pub fn vti(attrs: &str, array: &str, appended: Option<(&str, &[u8])>) -> Vec<u8> {
    let mut f = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" {attrs}>\n\
         <ImageData WholeExtent=\"1 2 0 2 0 3\" Origin=\"0 0 0\" Spacing=\"0.5 1 1\" \
         Direction=\"1 0 0 0 1 0 0 0 -1\">\n<Piece Extent=\"1 2 0 2 0 3\">\n\
         <PointData Scalars=\"s\">\n<DataArray type=\"Int32\" Name=\"other\" format=\"ascii\">\
         1 2</DataArray>\n{array}\n</PointData>\n</Piece>\n</ImageData>\n"
    )
    .into_bytes();
    if let Some((encoding, data)) = appended {
        f.extend(format!("<AppendedData encoding=\"{encoding}\">\n  _").as_bytes());
        f.extend(data);
        f.extend(b"\n</AppendedData>\n");
    }
    f.extend(b"</VTKFile>\n");
    f
}

/// The 24 test values as little-endian f32 bytes.
pub fn f32_le() -> Vec<u8> {
    grid_values().iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// zlib blocks of `block` bytes with a UInt32 block header.
pub fn zlib_blocks(data: &[u8], block: usize) -> (Vec<u8>, Vec<u8>) {
    let blocks: Vec<Vec<u8>> = data.chunks(block).map(zlib).collect();
    let last = data.len() % block;
    let mut header = vec![blocks.len() as u32, block as u32, last as u32];
    header.extend(blocks.iter().map(|b| b.len() as u32));
    let header = header.iter().flat_map(|h| h.to_le_bytes()).collect();
    (header, blocks.concat())
}

pub fn slc(dims: [usize; 3], slices: &[Vec<u8>]) -> Vec<u8> {
    let mut f = format!(
        "11111\n{} {} {} 8\n1.000000 2.000000 0.500000\n1 6 0 1\n2 1 X",
        dims[0], dims[1], dims[2]
    )
    .into_bytes();
    f.extend([0u8; 6]);
    for s in slices {
        f.extend(format!("{} X", s.len()).as_bytes());
        f.extend(s);
    }
    f
}
