//! Volume loading of synthetic files: every encoding of every format (raw,
//! NRRD, MetaImage, VTK legacy and XML, SLC), written here and read back,
//! and the `Volume` type itself.

mod common;
mod volume_files;

use common::{scratch, write};
use volume_files::{
    DIMS, as_i16_le, b64, err, f32_le, grid_values, gzip, invalid, nrrd_header, ok, rounded, slc,
    unsupported, vti, zlib, zlib_blocks,
};

use shapecue::Error;
use shapecue::volume::{RawSpec, ScalarType, Volume, load};

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
    assert!(matches!(e, Error::InvalidInput { .. }), "{e:?}");
    assert!(
        msg.contains(&dir.join("s18.raw").display().to_string()) && msg.contains("gone2.nhdr"),
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
    // Missing data file: named with the header that names it.
    let p = write(
        &dir,
        "c.mhd",
        "NDims = 3\nDimSize = 2 3 4\nElementType = MET_UCHAR\nElementDataFile = nothere.raw\n",
    );
    let (e, msg) = err(&p, None);
    assert!(matches!(e, Error::InvalidInput { .. }), "{e:?}");
    assert!(
        msg.contains("c.mhd") && msg.contains("nothere.raw") && msg.contains("cannot be read"),
        "{msg}"
    );
    // A data file that is a folder: said so, not "found 4096 bytes".
    std::fs::create_dir_all(dir.join("folder.raw")).unwrap();
    let p = write(
        &dir,
        "f.mhd",
        "NDims = 3\nDimSize = 2 3 4\nElementType = MET_UCHAR\nElementDataFile = folder.raw\n",
    );
    let (_, msg) = err(&p, None);
    assert!(
        msg.contains("f.mhd") && msg.contains("is a folder"),
        "{msg}"
    );
    assert!(!msg.contains("4096"), "{msg}");
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
