//! Mesh loading (OBJ, PLY, OFF), validation and welding; the PLY reader's
//! own cases and the PLY writer are in `tests/mesh_ply.rs`.
//!
//! Tests on the shared data sets look for `../shared/data` next to the crate
//! and skip (with a message on stderr) when it is absent.

mod common;
mod mesh_files;

use common::{scratch, shared, write};
use mesh_files::{field_for, load_err, plain, square};

use shapecue::Error;
use shapecue::export::ply::write_ply;
use shapecue::mesh::{LoadOptions, Mesh, load};

// ---------------------------------------------------------------------------
// Shared data sets
// ---------------------------------------------------------------------------

fn check_counts(file: &str, weld: bool, nv: usize, nf: usize) {
    let Some(dir) = shared("meshes") else { return };
    let path = dir.join(file);
    let m = load(
        &path,
        &LoadOptions {
            weld,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
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

// ---------------------------------------------------------------------------
// Small hand-written files
// ---------------------------------------------------------------------------

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
            let _ = load(
                &p,
                &LoadOptions {
                    weld: true,
                    ..Default::default()
                },
            );
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
        normals: None,
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
    let welded = load(
        &p,
        &LoadOptions {
            weld: true,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(welded.n_vertices(), 4);
    assert_eq!(welded.faces, vec![[0, 1, 2], [0, 2, 3]]);
    let _ = std::fs::remove_dir_all(&dir);
}
