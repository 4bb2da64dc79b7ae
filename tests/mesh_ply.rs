//! The PLY reader's own cases (both byte orders, any property types, lists,
//! header problems, agreement with `ply-rs-bw`) and the PLY writer.
//!
//! Tests on the shared data sets look for `../shared/data` next to the crate
//! and skip (with a message on stderr) when it is absent.

mod common;
mod mesh_files;

use common::{scratch, shared, write};
use mesh_files::{field_for, load_err, plain, square};

use shapecue::Error;
use shapecue::export::ply::{FIELD_PROPERTIES, read_ply_properties, write_ply};
use shapecue::mesh::load;
use shapecue::spec::curvature::CurvatureField;

// ---------------------------------------------------------------------------
// Reader: shared data sets
// ---------------------------------------------------------------------------

/// The binary PLY reader agrees with `ply-rs-bw`'s generic reader on the
/// shared binary PLY meshes: the same positions and triangles.
#[test]
fn binary_ply_reader_agrees_with_ply_rs() {
    use ply_rs_bw::ply::{DefaultElement, Property};
    let Some(dir) = shared("meshes") else { return };
    for file in ["horse.ply", "lucy.ply"] {
        let path = dir.join(file);
        let ours = load(&path, &plain()).unwrap_or_else(|e| panic!("{e}"));
        let mut f = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
        let ply = ply_rs_bw::parser::Parser::<DefaultElement>::new()
            .read_ply(&mut f)
            .unwrap();
        assert_ne!(
            ply.header.encoding,
            ply_rs_bw::ply::Encoding::Ascii,
            "{file}"
        );
        let num = |p: &Property| match *p {
            Property::Float(v) => f64::from(v),
            Property::Double(v) => v,
            ref other => panic!("{file}: coordinate {other:?}"),
        };
        let positions: Vec<[f64; 3]> = ply.payload["vertex"]
            .iter()
            .map(|v| [num(&v["x"]), num(&v["y"]), num(&v["z"])])
            .collect();
        let mut faces = Vec::new();
        for face in &ply.payload["face"] {
            let idx: Vec<u32> = match face
                .get("vertex_indices")
                .or_else(|| face.get("vertex_index"))
            {
                Some(Property::ListInt(v)) => v.iter().map(|&i| i as u32).collect(),
                Some(Property::ListUInt(v)) => v.clone(),
                other => panic!("{file}: face list {other:?}"),
            };
            for k in 1..idx.len() - 1 {
                faces.push([idx[0], idx[k], idx[k + 1]]);
            }
        }
        assert_eq!(ours.positions, positions, "{file}");
        assert_eq!(ours.faces, faces, "{file}");
    }
}

/// The two PLY byte orders agree with a re-encoding of the same mesh.
#[test]
fn horse_round_trips_through_the_writer() {
    let Some(dir) = shared("meshes") else { return };
    let m = load(&dir.join("horse.ply"), &plain()).unwrap();
    let tmp = scratch("horse");
    let out = tmp.join("horse-le.ply");
    write_ply(&out, &m, None).unwrap();
    let back = load(&out, &plain()).unwrap();
    assert_eq!(back.faces, m.faces);
    // horse.ply stores float32, so the positions survive exactly.
    assert_eq!(back.positions, m.positions);
    let _ = std::fs::remove_dir_all(&tmp);
}

// ---------------------------------------------------------------------------
// Reader: small hand-written files
// ---------------------------------------------------------------------------

#[test]
fn ascii_ply_quad_becomes_two_triangles() {
    let dir = scratch("ascii-quad");
    let p = write(
        &dir,
        "quad.ply",
        "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\n\
         property double x\nproperty double y\nproperty double z\nproperty uchar red\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 255\n1 0 0 0\n1 1 0 0\n0 1 0 0\n4 0 1 2 3\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.positions[2], [1.0, 1.0, 0.0]);
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Binary PLY in both byte orders, with integer coordinates, an extra
/// element, `vertex_index` as the list name and ushort/uint list types.
#[test]
fn binary_ply_any_types_both_byte_orders() {
    let dir = scratch("binary-types");
    for big in [false, true] {
        let enc = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut b = format!(
            "ply\nformat {enc} 1.0\nelement vertex 4\nproperty short x\nproperty int y\n\
             property float confidence\nproperty double z\nelement face 2\n\
             property uchar flags\nproperty list ushort uint vertex_index\n\
             element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
        )
        .into_bytes();
        let verts: [(i16, i32, f64); 4] = [(0, 0, 0.5), (2, 0, 0.0), (2, 3, 0.0), (0, 3, -1.0)];
        for (x, y, z) in verts {
            if big {
                b.extend(x.to_be_bytes());
                b.extend(y.to_be_bytes());
                b.extend(1.0f32.to_be_bytes());
                b.extend(z.to_be_bytes());
            } else {
                b.extend(x.to_le_bytes());
                b.extend(y.to_le_bytes());
                b.extend(1.0f32.to_le_bytes());
                b.extend(z.to_le_bytes());
            }
        }
        for face in [&[0u32, 1, 2][..], &[0, 2, 3]] {
            b.push(7);
            let n = face.len() as u16;
            b.extend(if big {
                n.to_be_bytes()
            } else {
                n.to_le_bytes()
            });
            for &v in face {
                b.extend(if big {
                    v.to_be_bytes()
                } else {
                    v.to_le_bytes()
                });
            }
        }
        b.extend([0u8; 8]);
        let p = write(&dir, &format!("types-{enc}.ply"), &b);
        let m = load(&p, &plain()).unwrap_or_else(|e| panic!("{enc}: {e}"));
        assert_eq!(
            m.positions,
            vec![
                [0.0, 0.0, 0.5],
                [2.0, 0.0, 0.0],
                [2.0, 3.0, 0.0],
                [0.0, 3.0, -1.0]
            ],
            "{enc}"
        );
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]], "{enc}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Binary vertices with a list property (rows of varying size), a face
/// list whose count type is signed, and the errors of a negative count and
/// of a list cut short.
#[test]
fn binary_ply_lists_in_vertices_and_bad_counts() {
    let dir = scratch("binary-lists");
    let head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
                property list uchar float uv\nproperty float y\nproperty float z\n\
                element face 1\nproperty list char int vertex_indices\nend_header\n";
    let mut body = Vec::new();
    for (k, p) in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .enumerate()
    {
        body.extend(p[0].to_le_bytes());
        body.push(k as u8); // k texture coordinates
        for _ in 0..k {
            body.extend(0.5f32.to_le_bytes());
        }
        body.extend(p[1].to_le_bytes());
        body.extend(p[2].to_le_bytes());
    }
    let face = |count: i8, idx: &[i32]| {
        let mut b = vec![count as u8];
        for v in idx {
            b.extend(v.to_le_bytes());
        }
        b
    };
    let file = |tail: &[u8]| [head.as_bytes(), &body, tail].concat();
    let p = write(&dir, "good.ply", file(&face(3, &[0, 1, 2])));
    let m = load(&p, &plain()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.positions[2], [0.0, 1.0, 0.0]);
    assert_eq!(m.faces, vec![[0, 1, 2]]);

    let msg = load_err(&write(&dir, "negative.ply", file(&face(-1, &[0, 1, 2]))));
    assert!(msg.contains("face 0") && msg.contains("negative"), "{msg}");
    let msg = load_err(&write(&dir, "short.ply", file(&face(4, &[0, 1, 2]))));
    assert!(
        msg.contains("face 0") && msg.contains("end of file"),
        "{msg}"
    );
    let msg = load_err(&write(&dir, "range.ply", file(&face(3, &[0, 1, 3]))));
    assert!(
        msg.contains("face 0") && msg.contains("out of range"),
        "{msg}"
    );
    let cut = file(&face(3, &[0, 1, 2]));
    // Vertices take 13, 17 and 21 bytes: 45 bytes pass the header's size
    // check (13 per vertex, 1 per face at least) and end inside vertex 2.
    let msg = load_err(&write(&dir, "cut-vertex.ply", &cut[..head.len() + 45]));
    assert!(
        msg.contains("vertex 2") && msg.contains("end of file"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// Reader: errors
// ---------------------------------------------------------------------------

/// A binary PLY cut short names the element it was reading.
#[test]
fn truncated_binary_ply_names_the_element() {
    let dir = scratch("truncated-ply");
    let mesh = square();
    let full = dir.join("full.ply");
    write_ply(&full, &mesh, None).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    let header_len = find(&bytes, b"end_header\n").unwrap() + b"end_header\n".len();

    // Cut inside vertex 2 (12 bytes per vertex).
    let p = write(&dir, "cut-vertex.ply", &bytes[..header_len + 2 * 12 + 5]);
    let msg = load_err(&p);
    assert!(msg.contains("vertex 2"), "{msg}");
    assert!(msg.contains("end of file"), "{msg}");

    // Cut inside face 1 (13 bytes per face).
    let p = write(&dir, "cut-face.ply", &bytes[..bytes.len() - 3]);
    let msg = load_err(&p);
    assert!(msg.contains("face 1"), "{msg}");

    // Cut inside the header.
    let p = write(&dir, "cut-header.ply", &bytes[..header_len - 5]);
    assert!(load_err(&p).contains("header"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ply_header_problems() {
    let dir = scratch("ply-header");
    let no_z = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0\n1 0\n0 1\n3 0 1 2\n";
    let msg = load_err(&write(&dir, "noz.ply", no_z));
    assert!(msg.contains("header") && msg.contains("'z'"), "{msg}");
    let float_list = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                      property float y\nproperty float z\nelement face 1\n\
                      property list uchar float vertex_indices\nend_header\n\
                      0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert!(load_err(&write(&dir, "flist.ply", float_list)).contains("header"));
    let bad_value = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
                     property float y\nproperty float z\nend_header\n0 0 0\n1 zz 0\n0 1 0\n";
    let msg = load_err(&write(&dir, "word.ply", bad_value));
    assert!(msg.contains("vertex 1") && msg.contains("line 9"), "{msg}");
    assert!(load_err(&write(&dir, "garbage.ply", "not a ply file\n")).contains("header"));
    // An unknown property type is named with its line, in both formats.
    for format in ["ascii", "binary_little_endian"] {
        let bad_type = format!(
            "ply\nformat {format} 1.0\nelement vertex 3\nproperty float x\n\
             property float y\nproperty real z\nend_header\n"
        );
        let msg = load_err(&write(&dir, "real.ply", &bad_type));
        assert!(
            msg.contains("header line 6") && msg.contains("unknown type 'real'"),
            "{msg}"
        );
        assert!(!msg.contains("Couldn't parse"), "{msg}");
    }
    let bad_list = "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar vertex_indices\n\
                    end_header\n3 0 1 2\n";
    let msg = load_err(&write(&dir, "list.ply", bad_list));
    assert!(
        msg.contains("header line 4") && msg.contains("list"),
        "{msg}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// PLY writer
// ---------------------------------------------------------------------------

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

#[test]
fn writer_round_trip_with_field() {
    let dir = scratch("write-field");
    let m = square();
    let f = field_for(&m);
    let p = dir.join("out.ply");
    write_ply(&p, &m, Some(&f)).unwrap();

    let bytes = std::fs::read(&p).unwrap();
    let head = String::from_utf8_lossy(&bytes[..find(&bytes, b"end_header").unwrap()]);
    assert!(head.contains("format binary_little_endian 1.0"), "{head}");
    assert!(
        head.contains("property list uchar int vertex_indices"),
        "{head}"
    );

    let (names, rows, faces) = read_ply_properties(&p).unwrap();
    let expected = [
        "x", "y", "z", "nx", "ny", "nz", "area", "k1", "k2", "d1x", "d1y", "d1z", "d2x", "d2y",
        "d2z", "dk0", "dk1", "dk2", "dk3",
    ];
    assert_eq!(names, expected);
    assert_eq!(&names[3..], FIELD_PROPERTIES);
    assert_eq!(faces, m.faces);
    assert_eq!(rows.len(), m.n_vertices());
    for (i, row) in rows.iter().enumerate() {
        let mut want: Vec<f64> = m.positions[i].to_vec();
        want.extend(f.normals[i]);
        want.extend([f.areas[i], f.k1[i], f.k2[i]]);
        want.extend(f.d1[i]);
        want.extend(f.d2[i]);
        want.extend(f.dk[i]);
        let want: Vec<f32> = want.iter().map(|&x| x as f32).collect();
        assert_eq!(row, &want, "vertex {i}");
    }

    // The file is also a mesh the loader reads back.
    let back = load(&p, &plain()).unwrap();
    assert_eq!(back.faces, m.faces);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn writer_without_field_and_errors() {
    let dir = scratch("write-plain");
    let m = square();
    let p = dir.join("plain.ply");
    write_ply(&p, &m, None).unwrap();
    let (names, rows, faces) = read_ply_properties(&p).unwrap();
    assert_eq!(names, ["x", "y", "z"]);
    assert_eq!(rows[3], vec![0.0, 1.0, 1e-3f64 as f32]);
    assert_eq!(faces, m.faces);
    let bytes = std::fs::read(&p).unwrap();
    let header_len = find(&bytes, b"end_header\n").unwrap() + b"end_header\n".len();
    assert_eq!(bytes.len(), header_len + 4 * 12 + 2 * 13);

    // A field of the wrong length is refused.
    let mut f = field_for(&m);
    f.k2.pop();
    assert!(matches!(
        write_ply(&dir.join("bad.ply"), &m, Some(&f)),
        Err(Error::InvalidArgument(_))
    ));
    // An unwritable path is an Error::Write naming it.
    let bad = dir.join("no-such-folder").join("out.ply");
    match write_ply(&bad, &m, None) {
        Err(e @ Error::Write { .. }) => assert!(e.to_string().contains("no-such-folder")),
        other => panic!("expected Error::Write, got {other:?}"),
    }
    // Reading a missing file is an Error::Io.
    assert!(matches!(
        read_ply_properties(&dir.join("missing.ply")),
        Err(Error::Io { .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Values a float cannot hold (a sphere scaled by 1e30 has areas of ~1e60,
/// one scaled by 1e-40 curvatures of ~1e40) make the writer use double for
/// the vertex properties, and say why; values too small for a float's normal
/// range are written as the nearest float (the file stays float, as the
/// docs say); a non-finite value is an error naming the property and the
/// vertex, never a silent `inf` in the file.
#[test]
fn ply_values_outside_float_range_are_written_as_double() {
    let dir = scratch("ply-double");
    let m = shapecue::mesh::icosphere(1.0, 1);
    let mut f = field_for(&m);
    let p = dir.join("plain.ply");
    assert_eq!(write_ply(&p, &m, Some(&f)).unwrap().double, None);
    assert!(
        std::fs::read(&p)
            .unwrap()
            .starts_with(b"ply\nformat binary_little_endian 1.0\n")
    );

    f.areas[3] = 1e60;
    let p = dir.join("huge.ply");
    let w = write_ply(&p, &m, Some(&f)).unwrap();
    let why = w.double.expect("written as double");
    assert!(why.contains("'area'") && why.contains("vertex 3"), "{why}");
    let bytes = std::fs::read(&p).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("property double area") && !text.contains("property float"));
    // The value is in the file as the f64 it was.
    let needle = 1e60f64.to_le_bytes();
    assert!(bytes.windows(8).any(|w| w == needle));
    // Started again from the first byte: nothing of the float attempt is
    // left, before or after the header.
    assert!(bytes.starts_with(b"ply\n"));
    let body = text.find("end_header\n").unwrap() + "end_header\n".len();
    assert_eq!(
        bytes.len() - body,
        m.n_vertices() * 19 * 8 + m.n_faces() * 13
    );
    let (names, rows, faces) = read_ply_properties(&p).unwrap();
    assert_eq!(
        (names.len(), rows.len(), faces),
        (19, m.n_vertices(), m.faces.clone())
    );

    f.areas[3] = 1.0;
    f.k1[5] = 1e40;
    let w = write_ply(&dir.join("large.ply"), &m, Some(&f)).unwrap();
    assert!(w.double.unwrap().contains("'k1'"));
    // A subnormal (and a value below float's subnormals): still float.
    f.k1[5] = 1e-40;
    f.k2[6] = -1e-300;
    let p = dir.join("tiny.ply");
    assert_eq!(write_ply(&p, &m, Some(&f)).unwrap().double, None);
    let (names, rows, _) = read_ply_properties(&p).unwrap();
    let k1 = names.iter().position(|n| n == "k1").unwrap();
    let k2 = names.iter().position(|n| n == "k2").unwrap();
    assert_eq!(rows[5][k1], 1e-40f32);
    assert_eq!(rows[6][k2], 0.0);

    f.k1[5] = f64::INFINITY;
    let e = write_ply(&dir.join("inf.ply"), &m, Some(&f))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'k1'") && e.contains("vertex 5"), "{e}");
    assert!(!dir.join("inf.ply").exists(), "nothing written on error");
}

/// The writer converts and checks vertices in blocks: on a mesh of several
/// blocks every value lands in its own vertex and property (float and
/// double files), and the value that forces double, or stops the write, is
/// named with its own vertex even far past the first block, the first one in
/// file order when there are several.
#[test]
fn ply_writer_blocks_keep_every_value_in_place() {
    let dir = scratch("ply-blocks");
    let m = shapecue::mesh::icosphere(1.0, 5);
    let n = m.n_vertices();
    assert!(n > 3 * 1024, "{n} vertices: several blocks");
    let mut f = field_for(&m);
    let expect = |f: &CurvatureField, i: usize| -> Vec<f32> {
        let mut row: Vec<f64> = m.positions[i].to_vec();
        row.extend(f.vertex(i).row());
        row.into_iter().map(|x| x as f32).collect()
    };
    let p = dir.join("float.ply");
    assert_eq!(write_ply(&p, &m, Some(&f)).unwrap().double, None);
    let (names, rows, faces) = read_ply_properties(&p).unwrap();
    assert_eq!((names.len(), rows.len()), (19, n));
    assert_eq!(faces, m.faces);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row, &expect(&f, i), "vertex {i}");
    }

    f.dk[5000][2] = 1e300;
    f.k2[7000] = -1e-300;
    let p = dir.join("double.ply");
    let why = write_ply(&p, &m, Some(&f)).unwrap().double.unwrap();
    assert!(
        why.contains("'dk2'") && why.contains("vertex 5000"),
        "{why}"
    );
    let (_, rows, faces) = read_ply_properties(&p).unwrap();
    assert_eq!(faces, m.faces);
    assert_eq!(rows[5000][3 + 14], f32::INFINITY, "1e300 read back as f32");
    for i in (0..n).filter(|&i| i != 5000 && i != 7000) {
        assert_eq!(rows[i], expect(&f, i), "vertex {i}");
    }

    f.d1[6000][1] = f64::NAN;
    let e = write_ply(&dir.join("nan.ply"), &m, Some(&f))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'d1y'") && e.contains("vertex 6000"), "{e}");
    f.d1[6000][1] = 0.0;
    f.normals[2047][0] = f64::NEG_INFINITY;
    let e = write_ply(&dir.join("inf.ply"), &m, Some(&f))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'nx'") && e.contains("vertex 2047"), "{e}");
    assert!(!dir.join("inf.ply").exists() && !dir.join("nan.ply").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
