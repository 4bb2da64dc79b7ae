//! Flipbook sequences: natural frame order, exact position round trip (OBJ)
//! and float round trip (PLY), one topology enforced across frames, and
//! clear errors for an empty glob, a corrupt frame and a mismatched frame.

mod common;

use common::scratch;

use std::fmt::Write as _;
use std::path::Path;

use shapecue::Error;
use shapecue::export::ply::write_ply;
use shapecue::mesh::flipbook::Flipbook;
use shapecue::mesh::{LoadOptions, Mesh, icosphere};

/// Writes `m` as OBJ; `{}` prints the shortest text that parses back to
/// the same f64, so positions round-trip exactly.
fn write_obj(path: &Path, m: &Mesh) {
    let mut s = String::new();
    for p in &m.positions {
        writeln!(s, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for f in &m.faces {
        writeln!(s, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1).unwrap();
    }
    std::fs::write(path, s).expect("write OBJ");
}

/// Frame `f` of the test animation: a sphere that grows, squashes and moves.
fn pose(base: &Mesh, f: usize) -> Mesh {
    let t = f as f64;
    base.map_positions(|p| {
        [
            p[0] * (1.0 + 0.1 * t) + 0.5 * t,
            p[1] * (1.0 - 0.03 * t),
            p[2] + 0.25 * (t * p[0]).sin(),
        ]
    })
}

fn base() -> Mesh {
    icosphere(1.0, 1)
}

/// Writes frames 0..n as `dir/frame_<f>.<ext>` (unpadded numbers, so
/// lexical order would put frame_10 before frame_2).
fn write_sequence(dir: &Path, n: usize, ext: &str) -> Vec<Mesh> {
    let b = base();
    (0..n)
        .map(|f| {
            let m = pose(&b, f);
            let path = dir.join(format!("frame_{f}.{ext}"));
            match ext {
                "obj" => write_obj(&path, &m),
                _ => drop(write_ply(&path, &m, None).expect("write PLY")),
            }
            m
        })
        .collect()
}

fn input_err(r: shapecue::Result<impl std::fmt::Debug>) -> String {
    match r {
        Err(e @ Error::InvalidInput { .. }) => e.to_string(),
        other => panic!("expected an InvalidInput error, got {other:?}"),
    }
}

#[test]
fn frames_in_natural_order_round_trip_exactly() {
    let dir = scratch("order");
    let seq = write_sequence(&dir, 12, "obj");
    let fb = Flipbook::open("frame_*.obj", &dir, &LoadOptions::default()).unwrap();
    let names: Vec<String> = fb
        .frames
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    let expected: Vec<String> = (0..12).map(|f| format!("frame_{f}.obj")).collect();
    assert_eq!(names, expected);
    assert_eq!(fb.len(), 12);
    assert_eq!(fb.n_vertices, seq[0].n_vertices());
    assert_eq!(fb.faces, seq[0].faces);
    for (f, m) in seq.iter().enumerate() {
        assert_eq!(fb.frame(f).unwrap(), m.positions, "frame {f}");
    }
    assert_eq!(fb.mesh(11).unwrap(), seq[11]);
    // Frame 0 differs from the last: the frames really are different poses.
    assert_ne!(seq[0].positions, seq[11].positions);
    // An absolute pattern ignores the base folder.
    let abs = dir.join("frame_1*.obj");
    let fb = Flipbook::open(
        abs.to_str().unwrap(),
        Path::new("/nonexistent"),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(fb.len(), 3); // frame_1, frame_10, frame_11
    assert!(fb.frames[0].ends_with("frame_1.obj") && fb.frames[2].ends_with("frame_11.obj"));
    // A frame past the end is an argument error, not a panic.
    assert!(matches!(fb.frame(3), Err(Error::InvalidArgument(_))));
}

#[test]
fn ply_frames_round_trip_in_float_and_metacharacters_in_base_are_literal() {
    // The base folder's name has glob metacharacters: they must be literal.
    let dir = scratch("ply[1]");
    let sub = dir.join("seq");
    std::fs::create_dir_all(&sub).unwrap();
    let seq = write_sequence(&sub, 4, "ply");
    let fb = Flipbook::open("seq/frame_?.ply", &dir, &LoadOptions::default()).unwrap();
    assert_eq!(fb.len(), 4);
    for (f, m) in seq.iter().enumerate() {
        let got = fb.frame(f).unwrap();
        for (p, q) in got.iter().zip(&m.positions) {
            for k in 0..3 {
                // PLY stores float: the f64 rounded to f32.
                assert_eq!(p[k], q[k] as f32 as f64, "frame {f}");
            }
        }
    }
}

#[test]
fn topology_mismatch_names_the_file_and_face() {
    let dir = scratch("topology");
    let seq = write_sequence(&dir, 4, "obj");
    // frame_2: face 5 with a flipped orientation.
    let mut flipped = seq[2].clone();
    flipped.faces[5].swap(1, 2);
    write_obj(&dir.join("frame_2.obj"), &flipped);
    // frame_3: another vertex count.
    write_obj(&dir.join("frame_3.obj"), &icosphere(1.0, 2));
    let fb = Flipbook::open("frame_*.obj", &dir, &LoadOptions::default()).unwrap();
    assert!(fb.frame(1).is_ok());
    let e = input_err(fb.frame(2));
    assert!(e.contains("frame_2.obj") && e.contains("face 5"), "{e}");
    let e = input_err(fb.frame(3));
    assert!(
        e.contains("frame_3.obj") && e.contains("vertices") && e.contains("frame_0.obj"),
        "{e}"
    );
    // Same vertex count, fewer faces.
    let mut fewer = seq[1].clone();
    fewer.faces.pop();
    write_obj(&dir.join("frame_1.obj"), &fewer);
    let e = input_err(fb.frame(1));
    assert!(e.contains("frame_1.obj") && e.contains("triangles"), "{e}");
}

#[test]
fn empty_glob_and_bad_pattern_name_the_pattern() {
    let dir = scratch("empty");
    write_sequence(&dir, 2, "obj");
    let e = input_err(Flipbook::open("hand_*.obj", &dir, &LoadOptions::default()));
    assert!(
        e.contains("hand_*.obj") && e.contains("no file matches"),
        "{e}"
    );
    // Folders are not frames.
    std::fs::create_dir_all(dir.join("sub_1.obj")).unwrap();
    let e = input_err(Flipbook::open("sub_*.obj", &dir, &LoadOptions::default()));
    assert!(e.contains("sub_*.obj"), "{e}");
    let e = input_err(Flipbook::open(
        "frame_[*.obj",
        &dir,
        &LoadOptions::default(),
    ));
    assert!(e.contains("frame_[*.obj") && e.contains("malformed"), "{e}");
}

#[test]
fn corrupt_frames_are_errors_naming_the_file() {
    let dir = scratch("corrupt");
    write_sequence(&dir, 5, "obj");
    std::fs::write(
        dir.join("frame_3.obj"),
        "v 1 2 abc\nv 0 0 0\nv 1 0 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(dir.join("frame_4.obj"), b"").unwrap();
    let fb = Flipbook::open("frame_*.obj", &dir, &LoadOptions::default()).unwrap();
    let e = input_err(fb.frame(3));
    assert!(e.contains("frame_3.obj") && e.contains("abc"), "{e}");
    let e = input_err(fb.frame(4));
    assert!(e.contains("frame_4.obj"), "{e}");
    // A frame deleted after opening: an I/O error naming it.
    std::fs::remove_file(dir.join("frame_2.obj")).unwrap();
    let e = fb.frame(2).unwrap_err().to_string();
    assert!(e.contains("frame_2.obj"), "{e}");
    // A corrupt first frame fails `open`, naming it.
    std::fs::write(dir.join("frame_0.obj"), "f 1 2 3\n").unwrap();
    let e = input_err(Flipbook::open("frame_*.obj", &dir, &LoadOptions::default()));
    assert!(e.contains("frame_0.obj"), "{e}");
}

#[test]
fn welding_uses_the_first_frame_map() {
    // An unwelded export: every face has its own three vertices.
    let b = base();
    let split = |m: &Mesh| Mesh {
        positions: m
            .faces
            .iter()
            .flat_map(|f| f.map(|v| m.positions[v as usize]))
            .collect(),
        faces: (0..m.faces.len() as u32)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect(),
    };
    let dir = scratch("weld");
    for f in 0..3 {
        write_obj(&dir.join(format!("w_{f}.obj")), &split(&pose(&b, f)));
    }
    let weld = LoadOptions { weld: true };
    let fb = Flipbook::open("w_*.obj", &dir, &weld).unwrap();
    assert_eq!(fb.n_vertices, b.n_vertices());
    for f in 0..3 {
        let m = fb.mesh(f).unwrap();
        let (welded, _) = split(&pose(&b, f)).weld();
        assert_eq!(m, welded, "frame {f}");
    }
    // Frame 2 tears one corner away from the vertices it was welded with.
    let mut torn = split(&pose(&b, 2));
    torn.positions[7][0] += 0.5;
    write_obj(&dir.join("w_2.obj"), &torn);
    let e = input_err(fb.frame(2));
    // Which of the torn vertices is named depends on which came first.
    assert!(
        e.contains("w_2.obj") && e.contains("welded with vertex"),
        "{e}"
    );
    // Without welding, the same frame is fine.
    let fb = Flipbook::open("w_*.obj", &dir, &LoadOptions::default()).unwrap();
    assert_eq!(fb.frame(2).unwrap(), torn.positions);
}
