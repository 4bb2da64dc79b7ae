//! Mesh loading (OBJ, PLY, OFF), validation, welding and the PLY writer.
//!
//! Tests on the shared data sets look for `../shared/data` next to the crate
//! and skip (with a message on stderr) when it is absent.

mod common;

use common::{scratch, shared, write};

use std::path::Path;

use shapecue::Error;
use shapecue::export::ply::{FIELD_PROPERTIES, read_ply_properties, write_ply};
use shapecue::mesh::{LoadOptions, Mesh, load};
use shapecue::spec::curvature::CurvatureField;

fn plain() -> LoadOptions {
    LoadOptions::default()
}

/// Loads and expects an `InvalidInput` error; returns its message.
fn load_err(path: &Path) -> String {
    match load(path, &plain()) {
        Ok(m) => panic!(
            "{}: expected an error, loaded {} vertices / {} faces",
            path.display(),
            m.n_vertices(),
            m.n_faces()
        ),
        Err(e @ Error::InvalidInput { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&path.display().to_string()),
                "message does not name the file: {msg}"
            );
            msg
        }
        Err(e) => panic!("{}: expected InvalidInput, got {e:?}", path.display()),
    }
}

// ---------------------------------------------------------------------------
// Shared data sets
// ---------------------------------------------------------------------------

fn check_counts(file: &str, weld: bool, nv: usize, nf: usize) {
    let Some(dir) = shared("meshes") else { return };
    let path = dir.join(file);
    let m = load(&path, &LoadOptions { weld }).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        (m.n_vertices(), m.n_faces()),
        (nv, nf),
        "{file} (weld: {weld})"
    );
    m.validate(file).unwrap();
}

#[test]
fn stanford_bunny_obj() {
    check_counts("stanford-bunny.obj", false, 35_947, 69_451);
}

#[test]
fn bunny_off() {
    check_counts("bunny.off", false, 3_485, 6_966);
}

#[test]
fn horse_ply_big_endian() {
    check_counts("horse.ply", false, 48_485, 96_966);
}

#[test]
fn lucy_ply_little_endian() {
    check_counts("lucy.ply", false, 49_987, 99_970);
}

#[test]
fn heptoroid_obj_unwelded_and_welded() {
    check_counts("Heptoroid.obj", false, 23_683, 35_840);
    check_counts("Heptoroid.obj", true, 17_878, 35_840);
}

#[test]
fn beetle_teapot_obj() {
    check_counts("beetle.obj", false, 1_148, 2_053);
    check_counts("teapot.obj", false, 3_644, 6_320);
}

#[test]
fn camelhead_fertility_off() {
    check_counts("camelhead.off", false, 11_381, 22_704);
    check_counts("fertility.off", false, 4_494, 9_000);
}

/// OBJ vertices keep the file's order (tobj alone would number them in order
/// of first use): the first and last `v` lines of the bunny are vertices 0
/// and n-1.
#[test]
fn obj_keeps_file_vertex_order() {
    let Some(dir) = shared("meshes") else { return };
    let path = dir.join("stanford-bunny.obj");
    let text = std::fs::read_to_string(&path).unwrap();
    let vs: Vec<[f64; 3]> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let c: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect();
    let m = load(&path, &plain()).unwrap();
    assert_eq!(m.positions, vs);
    let first_face = text.lines().find(|l| l.starts_with("f ")).unwrap();
    let idx: Vec<u32> = first_face[2..]
        .split_whitespace()
        .map(|t| t.parse::<u32>().unwrap() - 1)
        .collect();
    assert_eq!(m.faces[0].to_vec(), idx);
}

/// The OBJ reader agrees with `tobj` on every shared OBJ mesh: the same
/// triangles (as triples of positions, bit for bit, in the same order), and
/// every vertex `tobj` keeps (it keeps those faces use) is one of ours.
#[test]
fn obj_reader_agrees_with_tobj() {
    let Some(dir) = shared("meshes") else { return };
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(files.len() >= 5, "{files:?}");
    let opts = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    for path in files {
        let ours = load(&path, &plain()).unwrap_or_else(|e| panic!("{e}"));
        let (models, _) = tobj::load_obj(&path, &opts).unwrap();
        let mut theirs: Vec<[[f64; 3]; 3]> = Vec::new();
        for m in &models {
            let p = &m.mesh.positions;
            let at = |i: u32| {
                let i = 3 * i as usize;
                [p[i], p[i + 1], p[i + 2]]
            };
            for t in m.mesh.indices.chunks_exact(3) {
                theirs.push([at(t[0]), at(t[1]), at(t[2])]);
            }
        }
        let mine: Vec<[[f64; 3]; 3]> = ours
            .faces
            .iter()
            .map(|f| f.map(|v| ours.positions[v as usize]))
            .collect();
        let name = path.display();
        assert_eq!(mine.len(), theirs.len(), "{name}: triangle count");
        if let Some(i) = (0..mine.len()).find(|&i| mine[i] != theirs[i]) {
            panic!(
                "{name}: triangle {i} is {:?} here and {:?} in tobj",
                mine[i], theirs[i]
            );
        }
        let used: std::collections::HashSet<[u64; 3]> =
            ours.positions.iter().map(|p| p.map(f64::to_bits)).collect();
        for m in &models {
            for p in m.mesh.positions.chunks_exact(3) {
                let bits = [p[0], p[1], p[2]].map(f64::to_bits);
                assert!(
                    used.contains(&bits),
                    "{name}: tobj vertex {p:?} is not ours"
                );
            }
        }
    }
}

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
// Small hand-written files
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

#[test]
fn off_pentagon_comments_and_counts_on_header_line() {
    let dir = scratch("off-pentagon");
    let p = write(
        &dir,
        "pentagon.off",
        "OFF 5 1 0 # counts on the keyword line\n# a comment\n\n\
         0 0 0\n1 0 0\n1.5 1 0 # trailing comment\n0.5 1.5 0\n-0.5 1 0\n\
         5 0 1 2 3 4\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.n_vertices(), 5);
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn coff_and_noff_ignore_extra_columns() {
    let dir = scratch("coff");
    let p = write(
        &dir,
        "colours.OFF",
        "COFF\n3 1 3\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n\
         3 0 1 2 10 20 30\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.positions[1], [1.0, 0.0, 0.0]);
    assert_eq!(m.faces, vec![[0, 1, 2]]);
    let p = write(
        &dir,
        "normals.off",
        "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
    );
    assert_eq!(load(&p, &plain()).unwrap().faces, vec![[0, 1, 2]]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn obj_relative_indices_groups_and_attributes() {
    let dir = scratch("obj-relative");
    let p = write(
        &dir,
        "square.obj",
        "mtllib missing.mtl\no square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 0.5 0.5 0.5\n\
         vt 0 0\nvn 0 0 1\ng first\nusemtl none\nf -4/1/1 -3/1/1 -2/1/1\n\
         g second\nf 1//1 3//1 4//1 # comment\nl 1 2\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.n_vertices(), 4);
    assert_eq!(m.positions[3], [0.0, 1.0, 0.0]);
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);

    // Vertices keep the file's order even when first used out of order, and
    // unreferenced vertices are kept.
    let p = write(
        &dir,
        "order.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf 3 2 1\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.positions[0], [0.0, 0.0, 0.0]);
    assert_eq!(m.positions[3], [5.0, 5.0, 5.0]);
    assert_eq!(m.faces, vec![[2, 1, 0]]);

    // A hexagon is fan-triangulated.
    let p = write(
        &dir,
        "hexagon.obj",
        "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn degenerate_faces_and_repeated_indices_are_kept() {
    let dir = scratch("degenerate");
    let p = write(
        &dir,
        "deg.off",
        "OFF\n3 3 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n3 0 0 1\n4 0 1 1 2\n",
    );
    let m = load(&p, &plain()).unwrap();
    assert_eq!(m.faces, vec![[0, 1, 2], [0, 0, 1], [0, 1, 1], [0, 1, 2]]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn crlf_line_endings_and_face_element_first() {
    let dir = scratch("crlf");
    let files = [
        (
            "crlf.off",
            "OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n",
        ),
        ("crlf.obj", "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n"),
        (
            "crlf.ply",
            "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\n\
             property float y\r\nproperty float z\r\nelement face 1\r\n\
             property list uchar int vertex_indices\r\nend_header\r\n\
             0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n",
        ),
        // The face element may come before the vertex element.
        (
            "face-first.ply",
            "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\n\
             element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
             end_header\n3 0 1 2\n0 0 0\n1 0 0\n0 1 0\n",
        ),
    ];
    for (name, text) in files {
        let m = load(&write(&dir, name, text), &plain()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.positions[1], [1.0, 0.0, 0.0], "{name}");
        assert_eq!(m.faces, vec![[0, 1, 2]], "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn extension_is_case_insensitive() {
    let dir = scratch("case");
    let p = write(&dir, "tri.Obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_eq!(load(&p, &plain()).unwrap().n_faces(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

#[test]
fn truncated_off_names_the_missing_vertex() {
    let dir = scratch("truncated-off");
    let p = write(&dir, "short.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n");
    let msg = load_err(&p);
    assert!(msg.contains("vertex 3"), "{msg}");
    assert!(msg.contains("end of file"), "{msg}");

    let p = write(
        &dir,
        "short-faces.off",
        "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    let msg = load_err(&p);
    assert!(msg.contains("face 1"), "{msg}");

    let p = write(&dir, "no-counts.off", "OFF\n");
    assert!(load_err(&p).contains("header"));
    let p = write(&dir, "empty.off", "");
    assert!(load_err(&p).contains("header"));
    let p = write(
        &dir,
        "short-face.off",
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
    );
    assert!(load_err(&p).contains("face 0"));
    let _ = std::fs::remove_dir_all(&dir);
}

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

/// Headers claiming 2^31 vertices (or faces) in files of about a hundred
/// bytes are refused before any element is read: the message names the
/// file, the element, the declared count and how many the bytes can hold
/// (element lines in ASCII, bytes per element in binary).
#[test]
fn huge_counts_in_tiny_files_are_refused_from_the_header() {
    let dir = scratch("huge-counts");
    let xyz = "property float x\nproperty float y\nproperty float z\n";
    let face = "property list uchar int vertex_indices\n";
    let tri_le: Vec<u8> = [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let binary = |order: &str, nv: u64, nf: u64, body: &[u8]| {
        let mut b = format!(
            "ply\nformat binary_{order}_endian 1.0\nelement vertex {nv}\n{xyz}\
             element face {nf}\n{face}end_header\n"
        )
        .into_bytes();
        b.extend_from_slice(body);
        b
    };
    let ascii = |nv: u64, nf: u64| {
        format!(
            "ply\nformat ascii 1.0\nelement vertex {nv}\n{xyz}element face {nf}\n{face}\
             end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
        )
        .into_bytes()
    };
    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        (
            "v.off",
            b"OFF\n2147483648 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
            &[
                "vertex 4",
                "declares 2147483648 vertices",
                "holds only 4 lines",
            ],
        ),
        (
            "f.off",
            b"OFF\n3 2147483648 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec(),
            &["face 1", "3 vertices and 2147483648 faces", "only 4 lines"],
        ),
        (
            "v-ascii.ply",
            ascii(1 << 31, 1),
            &["vertex 4", "2147483648 'vertex' elements", "hold 4 lines"],
        ),
        (
            "f-ascii.ply",
            ascii(3, 1 << 31),
            &["face 1", "2147483648 'face' elements", "1 of them left"],
        ),
        (
            "v-le.ply",
            binary("little", 1 << 31, 0, &tri_le),
            &[
                "vertex 3",
                "2147483648 'vertex' elements of 12 bytes each",
                "the 36 bytes after the header hold at most 3",
            ],
        ),
        (
            "v-be.ply",
            binary("big", 1 << 31, 0, &[0; 40]),
            &["vertex 3", "of 12 bytes each", "hold at most 3"],
        ),
        (
            "f-le.ply",
            binary("little", 3, 1 << 31, &tri_le),
            &[
                "face 0",
                "2147483648 'face' elements of at least 1 bytes each",
                "besides the 36 bytes",
            ],
        ),
    ];
    for (name, bytes, needles) in cases {
        assert!(bytes.len() < 300, "{name}: {} bytes", bytes.len());
        let msg = load_err(&write(&dir, name, &bytes));
        for n in needles {
            assert!(msg.contains(n), "{name}: {n:?} not in {msg}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The counts a PLY or OFF header declares, read without loading the
/// file (as a flipbook's large frames are checked); OBJ has no header.
#[test]
fn header_counts_read_the_header_only() {
    use shapecue::mesh::header_counts;
    let dir = scratch("header-counts");
    let off = write(
        &dir,
        "c.off",
        "# comment\nOFF\n# another\n2147483648 7 0\n0 0 0\n",
    );
    assert_eq!(header_counts(&off).unwrap(), Some((1 << 31, 7)));
    let inline = write(&dir, "i.off", "OFF 3 1 0\n0 0 0\n");
    assert_eq!(header_counts(&inline).unwrap(), Some((3, 1)));
    let ply = write(
        &dir,
        "h.ply",
        "ply\nformat binary_little_endian 1.0\nelement vertex 4294967295\n\
         property float x\nproperty float y\nproperty float z\nend_header\n",
    );
    assert_eq!(header_counts(&ply).unwrap(), Some((4_294_967_295, 0)));
    let obj = write(&dir, "o.obj", "v 0 0 0\n");
    assert_eq!(header_counts(&obj).unwrap(), None);
    let bad = write(&dir, "b.off", "OFF\nmany 1 0\n");
    assert_eq!(header_counts(&bad).unwrap(), None);
    assert!(matches!(
        header_counts(&dir.join("gone.ply")),
        Err(Error::Io { .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn index_out_of_range_names_face_and_index() {
    let dir = scratch("out-of-range");
    let files = [
        (
            "bad.off",
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 7\n",
        ),
        ("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 8\n"),
        (
            "bad.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 2\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 7 1\n",
        ),
    ];
    for (name, text) in files {
        let msg = load_err(&write(&dir, name, text));
        assert!(msg.contains("face 1"), "{name}: {msg}");
        assert!(msg.contains('7') || msg.contains('8'), "{name}: {msg}");
    }
    // Relative OBJ index before the first vertex.
    let msg = load_err(&write(
        &dir,
        "rel.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
    ));
    assert!(msg.contains("face 0") && msg.contains("-4"), "{msg}");
    // OBJ index 0.
    let msg = load_err(&write(
        &dir,
        "zero.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
    ));
    assert!(msg.contains("face 0"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn negative_indices_are_rejected() {
    let dir = scratch("negative");
    let msg = load_err(&write(
        &dir,
        "neg.off",
        "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
    ));
    assert!(msg.contains("face 0") && msg.contains("negative"), "{msg}");
    let msg = load_err(&write(
        &dir,
        "neg.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
         end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
    ));
    assert!(msg.contains("face 0") && msg.contains("negative"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn faces_with_fewer_than_three_indices_are_rejected() {
    let dir = scratch("short-faces");
    let files = [
        (
            "two.off",
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n",
        ),
        ("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n"),
        (
            "two.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 2\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n",
        ),
    ];
    for (name, text) in files {
        let msg = load_err(&write(&dir, name, text));
        assert!(msg.contains("face 1"), "{name}: {msg}");
        assert!(msg.contains("at least 3"), "{name}: {msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn non_finite_coordinates_name_the_vertex() {
    let dir = scratch("nan");
    let files = [
        ("nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
        ("nan.obj", "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n"),
        (
            "nan.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
             end_header\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
        ),
        ("inf.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n"),
    ];
    for (name, text) in files {
        let msg = load_err(&write(&dir, name, text));
        assert!(msg.contains("vertex 1"), "{name}: {msg}");
    }
    // A coordinate that is not a number at all.
    let msg = load_err(&write(
        &dir,
        "word.off",
        "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n",
    ));
    assert!(msg.contains("vertex 1") && msg.contains("line 4"), "{msg}");
    let msg = load_err(&write(
        &dir,
        "word.obj",
        "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
    ));
    assert!(msg.contains("vertex 1") && msg.contains("line 2"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn no_faces_is_an_error() {
    let dir = scratch("no-faces");
    for (name, text) in [
        ("empty.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"),
        ("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
        ("empty.obj", ""),
        (
            "points.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
             property float z\nend_header\n0 0 0\n",
        ),
    ] {
        let msg = load_err(&write(&dir, name, text));
        assert!(msg.contains("no faces"), "{name}: {msg}");
    }
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
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unknown_extension_and_missing_file() {
    let dir = scratch("unknown");
    let p = write(&dir, "mesh.stl", "solid x\nendsolid x\n");
    assert!(matches!(
        load(&p, &plain()),
        Err(Error::UnsupportedFormat { .. })
    ));
    let p = write(&dir, "noextension", "OFF\n");
    assert!(matches!(
        load(&p, &plain()),
        Err(Error::UnsupportedFormat { .. })
    ));
    let missing = dir.join("does-not-exist.obj");
    match load(&missing, &plain()) {
        Err(e @ Error::Io { .. }) => {
            assert!(e.to_string().contains("does-not-exist.obj"), "{e}")
        }
        other => panic!("expected Error::Io, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every prefix of a valid file, and files with bytes overwritten, give a
/// mesh or an error: never a panic.
#[test]
fn no_panic_on_truncated_or_corrupted_input() {
    let dir = scratch("fuzz");
    let mesh = square();
    let ply = dir.join("src.ply");
    write_ply(&ply, &mesh, Some(&field_for(&mesh))).unwrap();
    let sources: Vec<(&str, Vec<u8>)> = vec![
        ("ply", std::fs::read(&ply).unwrap()),
        (
            "ply",
            b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
              property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
              end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"
                .to_vec(),
        ),
        (
            "off",
            b"OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n".to_vec(),
        ),
        (
            "obj",
            b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf -4 -2 -1\n"
                .to_vec(),
        ),
    ];
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for (k, (ext, bytes)) in sources.iter().enumerate() {
        let p = dir.join(format!("case{k}.{ext}"));
        for cut in 0..bytes.len() {
            std::fs::write(&p, &bytes[..cut]).unwrap();
            let _ = load(&p, &plain());
        }
        for _ in 0..300 {
            let mut b = bytes.clone();
            for _ in 0..1 + rand() % 4 {
                let i = (rand() % b.len() as u64) as usize;
                b[i] = match rand() % 4 {
                    0 => b'-',
                    1 => b'9',
                    2 => 0xff,
                    _ => rand() as u8,
                };
            }
            std::fs::write(&p, &b).unwrap();
            let _ = load(&p, &LoadOptions { weld: true });
        }
    }
    // Headers that declare far more elements than the file holds.
    for text in [
        "OFF\n99999999999 99999999999 0\n0 0 0\n",
        "ply\nformat binary_little_endian 1.0\nelement vertex 99999999999\n\
         property float x\nproperty float y\nproperty float z\nend_header\n",
    ] {
        let ext = if text.starts_with("OFF") {
            "off"
        } else {
            "ply"
        };
        let msg = load_err(&write(&dir, &format!("huge.{ext}"), text));
        assert!(msg.contains("vertex"), "{msg}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// Welding
// ---------------------------------------------------------------------------

#[test]
fn welding_merges_duplicated_positions() {
    // Two triangles of a square, each with its own copies of the corners.
    let m = Mesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, -0.0],
        ],
        faces: vec![[0, 1, 2], [3, 4, 5]],
    };
    let (w, remap) = m.weld();
    assert_eq!(w.n_vertices(), 4);
    assert_eq!(w.faces, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(remap, vec![0, 1, 2, 0, 2, 3]);
    // Welding is idempotent.
    assert_eq!(w.weld().0, w);

    // The same through the loader's option.
    let dir = scratch("weld");
    let p = write(
        &dir,
        "split.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n",
    );
    assert_eq!(load(&p, &plain()).unwrap().n_vertices(), 6);
    let welded = load(&p, &LoadOptions { weld: true }).unwrap();
    assert_eq!(welded.n_vertices(), 4);
    assert_eq!(welded.faces, vec![[0, 1, 2], [0, 2, 3]]);
    let _ = std::fs::remove_dir_all(&dir);
}

// ---------------------------------------------------------------------------
// PLY writer
// ---------------------------------------------------------------------------

fn square() -> Mesh {
    Mesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.25],
            [1.0, 1.0, -0.5],
            [0.0, 1.0, 1e-3],
        ],
        faces: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// A field with a distinct, exactly representable value in every slot.
fn field_for(m: &Mesh) -> CurvatureField {
    let n = m.n_vertices();
    let v = |i: usize, k: usize| (i * 100 + k) as f64 * 0.5;
    CurvatureField {
        normals: (0..n).map(|i| [v(i, 0), v(i, 1), v(i, 2)]).collect(),
        areas: (0..n).map(|i| v(i, 3)).collect(),
        k1: (0..n).map(|i| v(i, 4)).collect(),
        k2: (0..n).map(|i| -v(i, 5)).collect(),
        d1: (0..n).map(|i| [v(i, 6), v(i, 7), v(i, 8)]).collect(),
        d2: (0..n).map(|i| [v(i, 9), v(i, 10), v(i, 11)]).collect(),
        dk: (0..n)
            .map(|i| [v(i, 12), v(i, 13), v(i, 14), v(i, 15)])
            .collect(),
    }
}

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
/// the vertex properties, and say why; a non-finite value is an error naming
/// the property and the vertex, never a silent `inf` in the file.
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
    f.k1[5] = 1e-40;
    let w = write_ply(&dir.join("tiny.ply"), &m, Some(&f)).unwrap();
    assert!(w.double.unwrap().contains("'k1'"));

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
