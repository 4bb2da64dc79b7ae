//! Volume loading (raw, NRRD, MetaImage, VTK legacy and XML, SLC), bad
//! input, and the procedural SDFs.
//!
//! Tests on the shared data sets look for `../shared/data` next to the crate
//! (or `$SHAPECUE_SHARED_DATA`) and skip, with a message on stderr, when it
//! is absent. Expected values of the real files (sums, sample values) were
//! computed once by an independent Python reader (struct, zlib, base64) and
//! are hard-coded here.

mod common;

use common::{scratch, shared, write};

use std::io::Write;
use std::path::{Path, PathBuf};

use shapecue::Error;
use shapecue::volume::sdf::{
    self, GYROID_PERIODS, SPHERE_RADIUS, Sdf, TORUS_R, TORUS_TUBE, sdf_by_name,
};
use shapecue::volume::{RawSpec, ScalarType, Volume, load};

fn ok(path: &Path) -> Volume {
    load(path, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Loads and expects an error; returns it and its message.
fn err(path: &Path, raw: Option<&RawSpec>) -> (Error, String) {
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
fn invalid(path: &Path, needles: &[&str]) -> String {
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
fn unsupported(path: &Path, needles: &[&str]) -> String {
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

fn sum(v: &Volume) -> f64 {
    v.values.iter().map(|&x| f64::from(x)).sum()
}

/// What an independent reading of a shared file gave.
struct Expect {
    dims: [usize; 3],
    spacing: [f64; 3],
    range: (f32, f32),
    sum: f64,
    samples: [([usize; 3], f32); 2],
}

fn check(v: &Volume, e: &Expect) {
    assert_eq!(v.dims, e.dims);
    assert_eq!(v.voxel_count(), e.dims.iter().product::<usize>());
    assert_eq!(v.bytes(), 4 * v.voxel_count() as u64);
    assert_eq!(v.spacing, e.spacing);
    assert_eq!(v.origin, [0.0; 3]);
    assert_eq!(v.range(), Some(e.range));
    let s = sum(v);
    assert!(
        (s - e.sum).abs() <= 1e-9 * e.sum.abs(),
        "sum {s}, expected {}",
        e.sum
    );
    for ([x, y, z], val) in e.samples {
        assert_eq!(v.value(x, y, z), val, "sample ({x}, {y}, {z})");
    }
}

// ---------------------------------------------------------------------------
// Shared data sets
// ---------------------------------------------------------------------------

#[test]
fn bucky_raw_through_rawspec() {
    let Some(dir) = shared("volumes") else { return };
    let path = dir.join("Bucky.raw");
    let v = load(&path, Some(&RawSpec::new([32; 3], ScalarType::U8))).unwrap();
    check(
        &v,
        &Expect {
            dims: [32; 3],
            spacing: [1.0; 3],
            range: (0.0, 255.0),
            sum: 1_174_726.0,
            samples: [([16, 16, 16], 1.0), ([5, 10, 20], 119.0)],
        },
    );
    // Without a spec a .raw file cannot be read.
    let (e, msg) = err(&path, None);
    assert!(matches!(e, Error::UnsupportedFormat { .. }), "{msg}");
    assert!(msg.contains("RawSpec"), "{msg}");
    // A wrong spec is reported with both sizes.
    let (_, msg) = err(&path, Some(&RawSpec::new([32, 32, 33], ScalarType::U8)));
    assert!(
        msg.contains("expected 33792 bytes (32×32×33 × 1 bytes), found 32768"),
        "{msg}"
    );
    let (_, msg) = err(&path, Some(&RawSpec::new([32; 3], ScalarType::U16)));
    assert!(msg.contains("expected 65536 bytes"), "{msg}");
}

#[test]
fn headsq_multi_file_nrrd() {
    let Some(dir) = shared("volumes") else { return };
    let v = ok(&dir.join("headsq/quarter.nhdr"));
    check(
        &v,
        &Expect {
            dims: [64, 64, 93],
            spacing: [3.2, 3.2, 1.5],
            range: (0.0, 3926.0),
            sum: 193_392_317.0,
            samples: [([32, 32, 46], 122.0), ([10, 40, 80], 101.0)],
        },
    );
    assert_eq!(v.world([1.0, 2.0, 2.0]), [3.2, 6.4, 3.0]);
}

#[test]
fn head_mr_metaimage() {
    let Some(dir) = shared("volumes") else { return };
    check(
        &ok(&dir.join("HeadMRVolume.mhd")),
        &Expect {
            dims: [48, 62, 42],
            spacing: [4.0; 3],
            range: (0.0, 255.0),
            sum: 3_058_332.0,
            samples: [([24, 31, 21], 79.0), ([10, 40, 30], 92.0)],
        },
    );
}

#[test]
fn iron_protein_legacy_vtk() {
    let Some(dir) = shared("volumes") else { return };
    check(
        &ok(&dir.join("ironProt.vtk")),
        &Expect {
            dims: [68; 3],
            spacing: [1.0; 3],
            range: (0.0, 255.0),
            sum: 4_131_089.0,
            samples: [([34, 34, 34], 131.0), ([20, 30, 40], 0.0)],
        },
    );
}

#[test]
fn hydrogen_vti_zlib_blocks() {
    let Some(dir) = shared("volumes") else { return };
    check(
        &ok(&dir.join("hydrogen.vti")),
        &Expect {
            dims: [64; 3],
            spacing: [1.0; 3],
            range: (0.0, 1.0),
            sum: 4856.008970333924,
            samples: [([32, 32, 32], 0.0), ([10, 20, 40], 0.004857)],
        },
    );
}

#[test]
fn neghip_slc() {
    let Some(dir) = shared("volumes") else { return };
    check(
        &ok(&dir.join("neghip.slc")),
        &Expect {
            dims: [66; 3],
            spacing: [1.0; 3],
            range: (0.0, 255.0),
            sum: 4_824_177.0,
            samples: [([33, 33, 33], 0.0), ([20, 30, 40], 255.0)],
        },
    );
}

// ---------------------------------------------------------------------------
// Synthetic files: every encoding, written here and read back
// ---------------------------------------------------------------------------

/// A 2×3×4 grid with distinct values (negative ones too).
const DIMS: [usize; 3] = [2, 3, 4];

fn grid_values() -> Vec<f32> {
    (0..24).map(|i| i as f32 * 1.5 - 7.0).collect()
}

fn as_i16_le(v: &[f32]) -> Vec<u8> {
    v.iter()
        .flat_map(|&x| (x.round() as i16).to_le_bytes())
        .collect()
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn zlib(data: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(data).unwrap();
    e.finish().unwrap()
}

fn b64(data: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(data)
}

fn rounded() -> Vec<f32> {
    grid_values().iter().map(|x| x.round()).collect()
}

#[test]
fn volume_type() {
    let v = Volume::new(DIMS, grid_values(), "t").unwrap();
    assert_eq!(v.index(1, 2, 3), 1 + 2 * (2 + 3 * 3));
    assert_eq!(v.value(1, 2, 3), grid_values()[23]);
    assert_eq!(v.range(), Some((-7.0, 27.5)));
    let v = v.with_geometry([0.5, 1.0, 2.0], [1.0, 0.0, -1.0]).unwrap();
    assert_eq!(v.world([2.0, 0.5, 1.5]), [2.0, 0.5, 2.0]);
    assert!(v.clone().with_geometry([0.0, 1.0, 1.0], [0.0; 3]).is_err());
    assert!(
        v.clone()
            .with_geometry([1.0, f64::NAN, 1.0], [0.0; 3])
            .is_err()
    );
    assert!(
        v.clone()
            .with_geometry([1.0; 3], [f64::INFINITY, 0.0, 0.0])
            .is_err()
    );
    let mut nan = vec![f32::NAN; 24];
    assert_eq!(Volume::new(DIMS, nan.clone(), "t").unwrap().range(), None);
    nan[5] = 2.0;
    assert_eq!(
        Volume::new(DIMS, nan, "t").unwrap().range(),
        Some((2.0, 2.0))
    );
    for (dims, n) in [([2, 3, 3], 24), ([0, 3, 4], 0), ([usize::MAX, 2, 2], 24)] {
        let e = Volume::new(dims, vec![0.0; n], "src")
            .unwrap_err()
            .to_string();
        assert!(e.contains("src"), "{e}");
    }
}

#[test]
fn raw_every_type_and_header() {
    let dir = scratch("raw");
    let vals = rounded();
    for (t, bytes) in [
        (ScalarType::I16, as_i16_le(&vals)),
        (
            ScalarType::F32,
            vals.iter().flat_map(|&x| x.to_le_bytes()).collect(),
        ),
        (
            ScalarType::F64,
            vals.iter()
                .flat_map(|&x| f64::from(x).to_be_bytes())
                .collect(),
        ),
        (
            ScalarType::I32,
            vals.iter()
                .flat_map(|&x| (x as i32).to_le_bytes())
                .collect(),
        ),
        (
            ScalarType::I8,
            vals.iter().flat_map(|&x| (x as i8).to_le_bytes()).collect(),
        ),
    ] {
        let mut file = b"HEADER".to_vec();
        file.extend(&bytes);
        let p = write(&dir, &format!("v-{t}.bin"), &file);
        let spec = RawSpec {
            big_endian: t == ScalarType::F64,
            header_bytes: 6,
            spacing: [1.0, 2.0, 3.0],
            origin: [-1.0, 0.0, 1.0],
            ..RawSpec::new(DIMS, t)
        };
        let v = load(&p, Some(&spec)).unwrap();
        assert_eq!(v.values, vals, "{t}");
        assert_eq!((v.spacing, v.origin), (spec.spacing, spec.origin));
        // One byte short.
        let p = write(&dir, "short.bin", &file[..file.len() - 1]);
        let (_, msg) = err(&p, Some(&spec));
        let n = 24 * t.size();
        assert!(
            msg.contains(&format!(
                "expected {n} bytes (2×3×4 × {} bytes), found {}",
                t.size(),
                n - 1
            )),
            "{msg}"
        );
    }
    let p = write(&dir, "tiny.raw", [1u8, 2]);
    let spec = RawSpec {
        header_bytes: 10,
        ..RawSpec::new([1, 1, 1], ScalarType::U8)
    };
    let (_, msg) = err(&p, Some(&spec));
    assert!(msg.contains("10-byte header"), "{msg}");
    let huge = RawSpec::new([usize::MAX / 2, 3, 1], ScalarType::F64);
    let (_, msg) = err(&p, Some(&huge));
    assert!(
        msg.contains("too many samples") || msg.contains("fit"),
        "{msg}"
    );
    let (_, msg) = err(&p, Some(&RawSpec::new([0, 1, 1], ScalarType::U8)));
    assert!(msg.contains("at least 1"), "{msg}");
    let bad_geometry = RawSpec {
        spacing: [1.0, -1.0, 1.0],
        ..RawSpec::new([2, 1, 1], ScalarType::U8)
    };
    let (_, msg) = err(&p, Some(&bad_geometry));
    assert!(msg.contains("spacing"), "{msg}");
}

fn nrrd_header(extra: &str) -> String {
    format!("NRRD0004\n# test\ndimension: 3\nsizes: 2 3 4\n{extra}")
}

#[test]
fn nrrd_encodings_and_geometry() {
    let dir = scratch("nrrd");
    let vals = grid_values();
    // Attached raw, big-endian float, negative z direction (flipped on load).
    let mut f = nrrd_header(
        "type: float\nendian: big\nencoding: raw\n\
         space directions: (0.5,0,0) (0,2,0) (0,0,-1)\nspace origin: (1,2,3)\n\n",
    )
    .into_bytes();
    f.extend(vals.iter().flat_map(|x| x.to_be_bytes()));
    let v = ok(&write(&dir, "a.nrrd", &f));
    assert_eq!(v.spacing, [0.5, 2.0, 1.0]);
    assert_eq!(v.origin, [1.0, 2.0, 0.0]);
    for z in 0..4 {
        assert_eq!(v.value(1, 2, 3 - z), vals[1 + 2 * (2 + 3 * z)]);
    }
    // gzip, spacings, int16, byte skip after decompression.
    let mut payload = vec![9u8; 5];
    payload.extend(as_i16_le(&vals));
    let mut f = nrrd_header(
        "type: signed short int\nendian: little\nencoding: gzip\nbyte skip: 5\n\
         spacings: 1 1 2.5\n\n",
    )
    .into_bytes();
    f.extend(gzip(&payload));
    let v = ok(&write(&dir, "g.nrrd", &f));
    assert_eq!(v.values, rounded());
    assert_eq!(v.spacing, [1.0, 1.0, 2.5]);
    // ASCII with line skip, detached.
    let text: String = vals.iter().map(|v| format!("{v} ")).collect();
    write(&dir, "t.txt", format!("skip me\n{text}\n"));
    let v = ok(&write(
        &dir,
        "t.nhdr",
        nrrd_header("type: double\nencoding: text\nline skip: 1\ndata file: t.txt\n"),
    ));
    assert_eq!(v.values, vals);
    // Byte skip -1: the data are the last bytes of the file.
    let mut raw = b"junk".to_vec();
    raw.extend(vals.iter().map(|&x| (x + 7.0) as u8));
    write(&dir, "u8.raw", &raw);
    let v = ok(&write(
        &dir,
        "u8.nhdr",
        nrrd_header("type: uchar\nencoding: raw\nbyte skip: -1\ndatafile: u8.raw\n"),
    ));
    assert_eq!(v.value(1, 0, 0), f32::from((vals[1] + 7.0) as u8));
}

#[test]
fn nrrd_multi_file_forms() {
    let dir = scratch("nrrd-multi");
    let vals = rounded();
    // One file per z slice (6 samples each), named by a pattern.
    for z in 0..4 {
        write(
            &dir,
            &format!("s{:02}.raw", 10 + 2 * z),
            as_i16_le(&vals[6 * z..6 * z + 6]),
        );
    }
    let v = ok(&write(
        &dir,
        "p.nhdr",
        nrrd_header("type: short\nendian: little\nencoding: raw\ndata file: s%02d.raw 10 16 2\n"),
    ));
    assert_eq!(v.values, vals);
    // Same, with a LIST.
    let v = ok(&write(
        &dir,
        "l.nhdr",
        nrrd_header(
            "type: short\nendian: little\nencoding: raw\ndata file: LIST\n\
             s10.raw\ns12.raw\ns14.raw\ns16.raw\n",
        ),
    ));
    assert_eq!(v.values, vals);
    // subdim 1: one file per row of 2 samples.
    for r in 0..12 {
        write(&dir, &format!("r{r}"), as_i16_le(&vals[2 * r..2 * r + 2]));
    }
    let v = ok(&write(
        &dir,
        "r.nhdr",
        nrrd_header("type: short\nendian: little\nencoding: raw\ndata file: r%d 0 11 1 1\n"),
    ));
    assert_eq!(v.values, vals);
    // Too few files for the sizes, and a missing file.
    invalid(
        &write(
            &dir,
            "few.nhdr",
            nrrd_header(
                "type: short\nendian: little\nencoding: raw\ndata file: s%02d.raw 10 14 2\n",
            ),
        ),
        &["3 data files", "4 slabs"],
    );
    let p = write(
        &dir,
        "gone.nhdr",
        nrrd_header("type: short\nendian: little\nencoding: raw\ndata file: s%02d.raw 10 17 1\n"),
    );
    let _ = err(&p, None); // 8 files for 4 slices
    let p = write(
        &dir,
        "gone2.nhdr",
        nrrd_header("type: short\nendian: little\nencoding: raw\ndata file: s%02d.raw 12 18 2\n"),
    );
    let (e, msg) = err(&p, None);
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
    assert!(
        msg.contains(&dir.join("s18.raw").display().to_string()),
        "{msg}"
    );
    // A slice of the wrong size is named.
    write(&dir, "s16.raw", [0u8; 11]);
    invalid(
        &dir.join("p.nhdr"),
        &["s16.raw", "expected 12 bytes (2×3 × 2 bytes), found 11"],
    );
}

#[test]
fn metaimage_variants() {
    let dir = scratch("mhd");
    let vals = rounded();
    // .mha, LOCAL, zlib-compressed, big-endian int16, offset, diagonal matrix.
    let be: Vec<u8> = vals
        .iter()
        .flat_map(|&x| (x as i16).to_be_bytes())
        .collect();
    let mut f = b"ObjectType = Image\nNDims = 3\nDimSize = 2 3 4\nElementType = MET_SHORT\n\
BinaryData = True\nBinaryDataByteOrderMSB = True\nCompressedData = True\n\
TransformMatrix = 1 0 0 0 1 0 0 0 1\nOffset = 1 2 3\nElementSpacing = 0.5 0.5 2\n\
ElementDataFile = LOCAL\n"
        .to_vec();
    f.extend(zlib(&be));
    let v = ok(&write(&dir, "a.mha", &f));
    assert_eq!(v.values, vals);
    assert_eq!((v.spacing, v.origin), ([0.5, 0.5, 2.0], [1.0, 2.0, 3.0]));
    // Detached, uchar, HeaderSize.
    let mut raw = vec![0u8; 3];
    raw.extend(vals.iter().map(|&x| (x + 7.0) as u8));
    write(&dir, "b.raw", &raw);
    let v = ok(&write(
        &dir,
        "b.mhd",
        "NDims = 3\nDimSize = 2 3 4\nElementType = MET_UCHAR\nHeaderSize = 3\n\
         ElementDataFile = b.raw\n",
    ));
    assert_eq!(v.value(1, 2, 3), vals[23] + 7.0);
    // Missing data file: an Io error naming it.
    let p = write(
        &dir,
        "c.mhd",
        "NDims = 3\nDimSize = 2 3 4\nElementType = MET_UCHAR\nElementDataFile = nothere.raw\n",
    );
    let (e, msg) = err(&p, None);
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
    assert!(msg.contains("nothere.raw"), "{msg}");
    // Unknown element type, 2-D, rotated.
    invalid(
        &write(
            &dir,
            "d.mhd",
            "NDims = 3\nDimSize = 2 3 4\nElementType = MET_LONG_LONG\nElementDataFile = b.raw\n",
        ),
        &["MET_LONG_LONG"],
    );
    unsupported(
        &write(
            &dir,
            "e.mhd",
            "NDims = 2\nDimSize = 2 3\nElementType = MET_UCHAR\nElementDataFile = b.raw\n",
        ),
        &["NDims 2"],
    );
    unsupported(
        &write(
            &dir,
            "f.mhd",
            "NDims = 3\nDimSize = 2 3 4\nElementType = MET_UCHAR\nHeaderSize = 3\n\
             TransformMatrix = 0 1 0 1 0 0 0 0 1\nElementDataFile = b.raw\n",
        ),
        &["axis-aligned"],
    );
}

#[test]
fn legacy_vtk_ascii_and_binary() {
    let dir = scratch("vtk");
    let vals = grid_values();
    let text: String = vals.iter().map(|v| format!("{v}\n")).collect();
    let f = format!(
        "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 3 4\n\
         SPACING 1 2 3\nORIGIN -1 0 1\nPOINT_DATA 24\nSCALARS s float 1\nLOOKUP_TABLE default\n{text}"
    );
    let v = ok(&write(&dir, "a.vtk", f));
    assert_eq!(v.values, vals);
    assert_eq!((v.spacing, v.origin), ([1.0, 2.0, 3.0], [-1.0, 0.0, 1.0]));
    let mut f = b"# vtk DataFile Version 2.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n\
DIMENSIONS 2 3 4\nASPECT_RATIO 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 24\nSCALARS s short\n\
LOOKUP_TABLE default\n"
        .to_vec();
    f.extend(rounded().iter().flat_map(|&x| (x as i16).to_be_bytes()));
    let v = ok(&write(&dir, "b.vtk", &f));
    assert_eq!(v.values, rounded());
    // Truncated binary payload.
    let p = write(&dir, "c.vtk", &f[..f.len() - 3]);
    invalid(&p, &["expected 48 bytes (2×3×4 × 2 bytes), found 45"]);
    let f = String::from_utf8_lossy(&f).replace("STRUCTURED_POINTS", "POLYDATA");
    unsupported(&write(&dir, "d.vtk", f), &["POLYDATA"]);
}

/// A `.vti` file around one `DataArray`; `appended` is the raw bytes after `_`.
fn vti(attrs: &str, array: &str, appended: Option<(&str, &[u8])>) -> Vec<u8> {
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
fn f32_le() -> Vec<u8> {
    grid_values().iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// zlib blocks of `block` bytes with a UInt32 block header.
fn zlib_blocks(data: &[u8], block: usize) -> (Vec<u8>, Vec<u8>) {
    let blocks: Vec<Vec<u8>> = data.chunks(block).map(zlib).collect();
    let last = data.len() % block;
    let mut header = vec![blocks.len() as u32, block as u32, last as u32];
    header.extend(blocks.iter().map(|b| b.len() as u32));
    let header = header.iter().flat_map(|h| h.to_le_bytes()).collect();
    (header, blocks.concat())
}

#[test]
fn vti_every_layout() {
    let dir = scratch("vti");
    let vals = grid_values();
    let data = f32_le();
    let mut len32 = (data.len() as u32).to_le_bytes().to_vec();
    len32.extend(&data);
    let mut len64 = (data.len() as u64).to_le_bytes().to_vec();
    len64.extend(&data);
    let (zh, zb) = zlib_blocks(&data, 40);
    let ascii: String = vals.iter().map(|v| format!("{v} ")).collect();
    let files = [
        // ASCII.
        vti(
            "",
            &format!("<DataArray type=\"Float32\" Name=\"s\" format=\"ascii\">{ascii}</DataArray>"),
            None,
        ),
        // Inline base64, uncompressed, one stream.
        vti(
            "header_type=\"UInt32\"",
            &format!(
                "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">\n  {}\n</DataArray>",
                b64(&len32)
            ),
            None,
        ),
        // Inline zlib: header and blocks encoded separately.
        vti(
            "compressor=\"vtkZLibDataCompressor\"",
            &format!(
                "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">{}{}</DataArray>",
                b64(&zh),
                b64(&zb)
            ),
            None,
        ),
        // Appended raw with a UInt64 header, after another appended array.
        vti(
            "header_type=\"UInt64\"",
            "<DataArray type=\"Float32\" Name=\"s\" format=\"appended\" offset=\"11\"/>",
            Some(("raw", &[b"0123456789A".as_slice(), &len64].concat())),
        ),
        // Appended base64, zlib, after another array.
        vti(
            "compressor=\"vtkZLibDataCompressor\"",
            "<DataArray type=\"Float32\" Name=\"s\" format=\"appended\" offset=\"8\"/>\
             <DataArray type=\"Float32\" Name=\"t\" format=\"appended\" offset=\"0\"/>",
            Some((
                "base64",
                format!("AAAAAA=={}{}", b64(&zh), b64(&zb)).as_bytes(),
            )),
        ),
    ];
    for (i, f) in files.iter().enumerate() {
        let v = ok(&write(&dir, &format!("{i}.vti"), f));
        assert_eq!(v.dims, DIMS, "file {i}");
        // Direction -1 on z: z is flipped; the extent starts at x = 1.
        assert_eq!(v.spacing, [0.5, 1.0, 1.0]);
        assert_eq!(v.origin, [0.5, 0.0, -3.0]);
        for z in 0..4 {
            assert_eq!(v.value(0, 1, z), vals[2 * (1 + 3 * (3 - z))], "file {i}");
        }
    }
    let bad = [
        (
            vti(
                "compressor=\"vtkLZ4DataCompressor\"",
                "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">AAAA</DataArray>",
                None,
            ),
            "vtkLZ4DataCompressor",
        ),
        (
            vti(
                "",
                &format!(
                    "<DataArray type=\"Float32\" Name=\"s\" NumberOfComponents=\"3\" \
                     format=\"binary\">{}</DataArray>",
                    b64(&len32)
                ),
                None,
            ),
            "3 components",
        ),
    ];
    for (i, (f, needle)) in bad.iter().enumerate() {
        unsupported(&write(&dir, &format!("bad{i}.vti"), f), &[needle]);
    }
    // Truncated inline data and a wrong byte count.
    let short = vti(
        "",
        &format!(
            "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">{}</DataArray>",
            b64(&len32[..len32.len() - 4])
        ),
        None,
    );
    invalid(
        &write(&dir, "short.vti", short),
        &["expected 96 bytes (2×3×4 × 4 bytes), found 92"],
    );
    let wrong = vti(
        "",
        &format!(
            "<DataArray type=\"Float64\" Name=\"s\" format=\"binary\">{}</DataArray>",
            b64(&len32)
        ),
        None,
    );
    invalid(&write(&dir, "wrong.vti", wrong), &["96 bytes", "192"]);
}

fn slc(dims: [usize; 3], slices: &[Vec<u8>]) -> Vec<u8> {
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

#[test]
fn slc_synthetic() {
    let dir = scratch("slc");
    // 3×2 slices: a literal run of 3, then a repeat run of 3.
    let s0 = vec![0x83, 1, 2, 3, 0x03, 7, 0];
    let s1 = vec![0x06, 5, 0];
    let v = ok(&write(&dir, "a.slc", slc([3, 2, 2], &[s0.clone(), s1])));
    assert_eq!(v.values, [1., 2., 3., 7., 7., 7., 5., 5., 5., 5., 5., 5.]);
    assert_eq!(v.spacing, [1.0, 2.0, 0.5]);
    invalid(
        &write(
            &dir,
            "b.slc",
            slc([3, 2, 2], &[s0.clone(), vec![0x05, 5, 0]]),
        ),
        &["slice 1", "decodes to 5 bytes, expected 6"],
    );
    invalid(&write(&dir, "c.slc", slc([3, 2, 2], &[s0])), &["slice 1"]);
}

// ---------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------

#[test]
fn nrrd_bad_headers() {
    let dir = scratch("nrrd-bad");
    let data = "\n".to_string() + &"x".repeat(48);
    let cases: &[(&str, &[&str])] = &[
        (
            "type: complex\nencoding: raw\n",
            &["complex", "unknown scalar type"],
        ),
        ("type: int64\nencoding: raw\n", &["int64", "64-bit"]),
        (
            "type: short\nendian: little\nencoding: bzip2\n",
            &["bzip2", "not supported"],
        ),
        ("type: short\nendian: middle\nencoding: raw\n", &["middle"]),
        ("type: short\nencoding: raw\n", &["endian"]),
        ("endian: little\nencoding: raw\n", &["type"]),
        (
            "type: short\nendian: little\nencoding: raw\nbyte skip: -2\n",
            &["-2"],
        ),
        (
            "type: short\nendian: little\nencoding: raw\nspacings: 1 x 1\n",
            &["'x'"],
        ),
        (
            "type: short\nendian: little\nencoding: gzip\n",
            &["cannot be decompressed"],
        ),
        (
            "type: short\nendian: little\nencoding: raw\nspace directions: (1,0,0) (0,1,0)\n",
            &["3 vectors"],
        ),
        (
            "type: short\nendian: little\nencoding: raw\nno colon here\n",
            &["header line 8"],
        ),
    ];
    for (i, (fields, needles)) in cases.iter().enumerate() {
        let p = write(&dir, &format!("{i}.nrrd"), nrrd_header(fields) + &data);
        invalid(&p, needles);
    }
    // Sizes: zero, non-numeric, too large.
    for (i, (sizes, needle)) in [
        ("0 3 4", "at least 1"),
        ("2 x 4", "'x'"),
        ("2 3", "expected 3 values"),
        ("4294967296 4294967296 4294967296", "too many samples"),
        ("99999999999999999999 1 1", "not a valid number"),
        ("-1 2 2", "not a valid number"),
    ]
    .iter()
    .enumerate()
    {
        let p = write(
            &dir,
            &format!("s{i}.nrrd"),
            format!("NRRD0004\ndimension: 3\nsizes: {sizes}\ntype: uchar\nencoding: raw\n{data}"),
        );
        invalid(&p, &[needle]);
    }
    // Truncated attached data: expected vs found.
    invalid(
        &write(
            &dir,
            "t.nrrd",
            nrrd_header("type: short\nendian: little\nencoding: raw\n\n") + &"x".repeat(40),
        ),
        &[
            "attached data",
            "expected 48 bytes (2×3×4 × 2 bytes), found 40",
        ],
    );
    // Not NRRD, 2-D, sheared.
    invalid(&write(&dir, "n.nrrd", "P5\n"), &["NRRD000X"]);
    unsupported(
        &write(
            &dir,
            "d2.nrrd",
            "NRRD0004\ndimension: 2\nsizes: 2 3\ntype: uchar\nencoding: raw\n\n123456",
        ),
        &["dimension 2"],
    );
    unsupported(
        &write(
            &dir,
            "sh.nrrd",
            nrrd_header(
                "type: uchar\nencoding: raw\nspace directions: (1,0.5,0) (0,1,0) (0,0,1)\n",
            ) + &"\n".repeat(25),
        ),
        &["not axis-aligned"],
    );
}

#[test]
fn other_bad_inputs() {
    let dir = scratch("bad");
    unsupported(&write(&dir, "a.xyz", "x"), &[".xyz"]);
    unsupported(&write(&dir, "noext", "x"), &["no file extension"]);
    let (e, msg) = err(&dir.join("absent.nrrd"), None);
    assert!(
        matches!(e, Error::Io { .. }) && msg.contains("absent.nrrd"),
        "{msg}"
    );
    invalid(
        &write(
            &dir,
            "big.vtk",
            "# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n\
             DIMENSIONS 4294967296 4294967296 4294967296\nPOINT_DATA 1\nSCALARS s float\n",
        ),
        &["too many samples"],
    );
    invalid(
        &write(
            &dir,
            "big.vti",
            vti(
                "",
                "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">AAAA</DataArray>",
                None,
            )
            .iter()
            .map(|&b| b as char)
            .collect::<String>()
            .replace(
                "WholeExtent=\"1 2",
                "WholeExtent=\"-9223372036854775808 9223372036854775807",
            ),
        ),
        &["WholeExtent"],
    );
    invalid(
        &write(
            &dir,
            "big.mhd",
            "NDims = 3\nDimSize = 4294967296 4294967296 4294967296\nElementType = MET_FLOAT\n\
             ElementDataFile = x.raw\n",
        ),
        &["too many samples"],
    );
    invalid(
        &write(
            &dir,
            "big.slc",
            "11111\n4294967296 4294967296 4294967296 8\n1 1 1\n1 6 0 1\n",
        ),
        &["too many samples"],
    );
    invalid(
        &write(&dir, "nan.mhd", "NDims = 3\nDimSize = 2 two 2\n"),
        &["'two'"],
    );
}

/// Small valid files of every format (header and data).
fn small_files(dir: &Path) -> Vec<PathBuf> {
    let vals = rounded();
    let mut out = Vec::new();
    let mut f = nrrd_header("type: short\nendian: little\nencoding: raw\n\n").into_bytes();
    f.extend(as_i16_le(&vals));
    out.push(write(dir, "a.nrrd", f));
    let mut f = nrrd_header("type: short\nendian: little\nencoding: gzip\n\n").into_bytes();
    f.extend(gzip(&as_i16_le(&vals)));
    out.push(write(dir, "g.nrrd", f));
    for z in 0..4 {
        write(
            dir,
            &format!("s{z}.raw"),
            as_i16_le(&vals[6 * z..6 * z + 6]),
        );
    }
    out.push(write(
        dir,
        "p.nhdr",
        nrrd_header("type: short\nendian: little\nencoding: raw\ndata file: s%d.raw 0 3 1\n"),
    ));
    let mut f = b"NDims = 3\nDimSize = 2 3 4\nElementType = MET_SHORT\nCompressedData = True\n\
ElementDataFile = LOCAL\n"
        .to_vec();
    f.extend(zlib(&as_i16_le(&vals)));
    out.push(write(dir, "m.mha", f));
    let text: String = vals.iter().map(|v| format!("{v} ")).collect();
    out.push(write(
        dir,
        "a.vtk",
        format!(
            "# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 3 4\n\
             POINT_DATA 24\nSCALARS s float\nLOOKUP_TABLE default\n{text}"
        ),
    ));
    let mut f = b"# vtk DataFile Version 3.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\n\
DIMENSIONS 2 3 4\nPOINT_DATA 24\nSCALARS s short\nLOOKUP_TABLE default\n"
        .to_vec();
    f.extend(vals.iter().flat_map(|&x| (x as i16).to_be_bytes()));
    out.push(write(dir, "b.vtk", f));
    let data = f32_le();
    let (zh, zb) = zlib_blocks(&data, 40);
    out.push(write(
        dir,
        "z.vti",
        vti(
            "compressor=\"vtkZLibDataCompressor\"",
            &format!(
                "<DataArray type=\"Float32\" Name=\"s\" format=\"binary\">{}{}</DataArray>",
                b64(&zh),
                b64(&zb)
            ),
            None,
        ),
    ));
    let mut len32 = (data.len() as u32).to_le_bytes().to_vec();
    len32.extend(&data);
    out.push(write(
        dir,
        "r.vti",
        vti(
            "",
            "<DataArray type=\"Float32\" Name=\"s\" format=\"appended\" offset=\"0\"/>",
            Some(("raw", &len32)),
        ),
    ));
    out.push(write(
        dir,
        "a.slc",
        slc(
            [3, 2, 2],
            &[vec![0x83, 1, 2, 3, 0x03, 7, 0], vec![0x06, 5, 0]],
        ),
    ));
    out
}

#[test]
fn no_panic_on_truncated_or_corrupted_files() {
    let dir = scratch("cut");
    let files = small_files(&dir);
    // Damaged copies go to their own folder, next to copies of the detached
    // slices of p.nhdr.
    let cut = dir.join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    for z in 0..4 {
        let s = format!("s{z}.raw");
        std::fs::copy(dir.join(&s), cut.join(&s)).unwrap();
    }
    for path in &files {
        let full = std::fs::read(path).unwrap();
        ok(path);
        let name = path.file_name().unwrap();
        let target = cut.join(name);
        // Every prefix: an error or (for trailing bytes that are not data) a volume.
        for n in 0..full.len() {
            std::fs::write(&target, &full[..n]).unwrap();
            if let Ok(v) = load(&target, None) {
                assert_eq!(v.voxel_count(), 24, "{} cut at {n}", path.display());
            }
        }
        // Every byte replaced by a few troublesome values.
        for i in 0..full.len() {
            for b in [0u8, b'9', b'-', 0xff, b'\n'] {
                let mut c = full.clone();
                c[i] = b;
                std::fs::write(&target, &c).unwrap();
                let _ = load(&target, None);
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Procedural fields
// ---------------------------------------------------------------------------

#[test]
fn sphere_field() {
    let v = sdf::sdf(Sdf::Sphere, 65);
    assert_eq!(v.dims, [65; 3]);
    assert_eq!(v.spacing, [2.0 / 64.0; 3]);
    assert_eq!(v.origin, [-1.0; 3]);
    assert_eq!(v.value(32, 32, 32), -SPHERE_RADIUS as f32);
    assert_eq!(v.value(0, 32, 32), (1.0 - SPHERE_RADIUS) as f32);
    let mut worst = 0.0f64;
    for z in 0..65 {
        for y in 0..65 {
            for x in 0..65 {
                let p = v.world([x as f64, y as f64, z as f64]);
                let exact = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - SPHERE_RADIUS;
                worst = worst.max((f64::from(v.value(x, y, z)) - exact).abs());
            }
        }
    }
    assert!(worst < 1e-6, "worst error {worst}");
    assert_eq!(sdf::sphere_curvature([0.8, 0.0, 0.0]), (1.25, 1.25));
}

#[test]
fn torus_field() {
    // res 41: spacing 0.05, so (0.6, 0, 0) is sample (32, 20, 20).
    let v = sdf::sdf(Sdf::Torus, 41);
    assert!((v.value(32, 20, 20) - (-TORUS_TUBE as f32)).abs() < 1e-6);
    assert!((v.value(20, 8, 20) - (-TORUS_TUBE as f32)).abs() < 1e-6);
    // Independent check: distance to a dense sampling of the surface.
    let n = 720;
    let surface: Vec<[f64; 3]> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (u, w) = (
                std::f64::consts::TAU * i as f64 / n as f64,
                std::f64::consts::TAU * j as f64 / n as f64,
            );
            let r = TORUS_R + TORUS_TUBE * w.cos();
            [r * u.cos(), r * u.sin(), TORUS_TUBE * w.sin()]
        })
        .collect();
    for (x, y, z) in [
        (3, 7, 11),
        (32, 20, 20),
        (25, 30, 18),
        (10, 20, 24),
        (40, 0, 40),
    ] {
        let p = v.world([x as f64, y as f64, z as f64]);
        let d = surface
            .iter()
            .map(|s| ((s[0] - p[0]).powi(2) + (s[1] - p[1]).powi(2) + (s[2] - p[2]).powi(2)).sqrt())
            .fold(f64::INFINITY, f64::min);
        let got = f64::from(v.value(x, y, z));
        assert!((got.abs() - d).abs() < 2e-3, "({x},{y},{z}): {got} vs {d}");
    }
    let (k1, k2) = sdf::torus_curvature([TORUS_R + TORUS_TUBE, 0.0, 0.0]);
    assert!((k1 - 4.0).abs() < 1e-12 && (k2 - 1.0 / 0.85).abs() < 1e-12);
    let (k1, k2) = sdf::torus_curvature([TORUS_R - TORUS_TUBE, 0.0, 0.0]);
    assert!((k1 - 4.0).abs() < 1e-12 && (k2 + 1.0 / 0.35).abs() < 1e-12);
}

#[test]
fn gyroid_field_and_names() {
    let v = sdf_by_name("Gyroid", 64).unwrap();
    let (lo, hi) = v.range().unwrap();
    assert!(hi > 1.3 && hi <= 1.5, "{hi}");
    assert!((lo + hi).abs() < 1e-6, "range ({lo}, {hi}) not symmetric");
    assert_eq!("torus".parse::<Sdf>().unwrap(), Sdf::Torus);
    let e = sdf_by_name("cube", 64).unwrap_err().to_string();
    assert!(e.contains("cube") && e.contains("sphere"), "{e}");
    assert!(sdf_by_name("sphere", 1).is_err());
    assert!(sdf_by_name("sphere", usize::MAX / 2).is_err());
    assert_eq!(sdf::sdf(Sdf::Sphere, 0).dims, [2; 3]);
}

/// Counts the cells of `v` whose 8 corners are not all on one side of 0
/// (`value < 0` is inside), and the grid edges whose ends differ.
fn crossings(v: &Volume) -> (usize, usize) {
    let [nx, ny, nz] = v.dims;
    let inside: Vec<bool> = v.values.iter().map(|&x| x < 0.0).collect();
    let at = |x: usize, y: usize, z: usize| inside[x + nx * (y + ny * z)];
    let mut cells = 0;
    let mut edges = 0;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let s = at(x, y, z);
                edges += usize::from(x + 1 < nx && at(x + 1, y, z) != s)
                    + usize::from(y + 1 < ny && at(x, y + 1, z) != s)
                    + usize::from(z + 1 < nz && at(x, y, z + 1) != s);
                if x + 1 < nx && y + 1 < ny && z + 1 < nz {
                    let corners = [
                        s,
                        at(x + 1, y, z),
                        at(x, y + 1, z),
                        at(x + 1, y + 1, z),
                        at(x, y, z + 1),
                        at(x + 1, y, z + 1),
                        at(x, y + 1, z + 1),
                        at(x + 1, y + 1, z + 1),
                    ];
                    cells += usize::from(corners.iter().any(|&c| c != s));
                }
            }
        }
    }
    (cells, edges)
}

/// The gyroid period count gives about 2.5 M marching-cubes triangles at
/// 256³: a closed triangulated surface has about twice as many triangles as
/// vertices, and marching cubes puts one vertex on each crossed grid edge.
#[test]
fn gyroid_calibration() {
    let v = sdf::sdf(Sdf::Gyroid, 256);
    let (cells, edges) = crossings(&v);
    eprintln!(
        "gyroid P = {GYROID_PERIODS}: {cells} cells with a sign change, {edges} crossed edges, \
         about {} triangles",
        2 * edges
    );
    assert!((1_250_000..=1_400_000).contains(&cells), "{cells} cells");
    assert!(
        (2_300_000..=2_800_000).contains(&(2 * edges)),
        "{edges} edges"
    );
}
