//! Volume loading on the shared data sets, bad input, and the procedural
//! SDFs; every encoding of every format, on synthetic files, is in
//! `tests/volume_formats.rs`.
//!
//! Tests on the shared data sets look for `../shared/data` next to the crate
//! (or `$SHAPECUE_SHARED_DATA`) and skip, with a message on stderr, when it
//! is absent. Expected values of the real files (sums, sample values) were
//! computed once by an independent Python reader (struct, zlib, base64) and
//! are hard-coded here.

mod common;
mod volume_files;

use common::{scratch, shared, write};
use volume_files::{
    as_i16_le, b64, err, f32_le, gzip, invalid, nrrd_header, ok, rounded, slc, unsupported, vti,
    zlib, zlib_blocks,
};

use std::path::{Path, PathBuf};

use shapecue::Error;
use shapecue::volume::sdf::{
    self, GYROID_PERIODS, SPHERE_RADIUS, Sdf, TORUS_R, TORUS_TUBE, sdf_by_name,
};
use shapecue::volume::{RawSpec, ScalarType, Volume, load};

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
    assert!(msg.contains("--dims") && !msg.contains("RawSpec"), "{msg}");
    // A folder is named as one.
    let (_, msg) = err(path.parent().unwrap(), None);
    assert!(msg.contains("a folder"), "{msg}");
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

#[test]
fn max_finite_abs_skips_nan_and_infinities_in_every_lane_and_the_tail() {
    for n in [1usize, 15, 16, 17, 33, 100] {
        for at in [0, n / 2, n - 1] {
            let mut v = vec![0.5f32; n];
            v[at] = -7.25;
            if n > 2 {
                v[(at + 1) % n] = f32::NAN;
                v[(at + 2) % n] = f32::NEG_INFINITY;
            }
            let vol = Volume::new([n, 1, 1], v, "lanes").unwrap();
            assert_eq!(vol.max_finite_abs(), 7.25, "n {n}, at {at}");
        }
    }
    let all_bad = Volume::new([3, 1, 1], vec![f32::NAN, f32::INFINITY, f32::NAN], "bad").unwrap();
    assert_eq!(all_bad.max_finite_abs(), 0.0);
}
