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
        normals: None,
    };
    let dir = scratch("weld");
    for f in 0..3 {
        write_obj(&dir.join(format!("w_{f}.obj")), &split(&pose(&b, f)));
    }
    let weld = LoadOptions {
        weld: true,
        ..Default::default()
    };
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

// ---------------------------------------------------------------------------
// Checks before a run: frame ranges and topology of every scene up front
// ---------------------------------------------------------------------------

/// Writes `name` in `dir` and loads it as a scene.
fn scene_file(dir: &Path, name: &str, text: &str) -> shapecue::scene::file::Scene {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    shapecue::scene::file::Scene::load(&p).unwrap_or_else(|e| panic!("{e}\n{text}"))
}

/// Three scenes whose third is bad: the run's up-front check refuses it
/// (naming the scene file, the frame and its file, and the problem) before
/// the first scene starts, and nothing is written.
#[test]
fn a_bad_third_scene_fails_before_the_first_runs() {
    use shapecue::scene::exec::{ExecOptions, check_scenes};
    let dir = scratch("check-scenes");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    write_sequence(&frames, 4, "obj");
    let out = dir.join("out");
    let fine = |name: &str, prefix: &str| {
        scene_file(
            &dir,
            name,
            &format!(
                "[input]\ngenerate = \"sphere\"\nresolution = 50\n[effects]\nshading = {{}}\n\
                 [output]\ndir = \"out\"\nname = \"{prefix}\"\nsize = [16, 16]\n"
            ),
        )
    };
    let book = |name: &str, frames: &str| {
        scene_file(
            &dir,
            name,
            &format!(
                "[input]\nflipbook = \"frames/frame_*.obj\"\n{frames}[effects]\nshading = {{}}\n\
                 [output]\ndir = \"out\"\nname = \"{name}\"\nsize = [16, 16]\n"
            ),
        )
    };
    let opts = ExecOptions::default();
    let good = book("book.toml", "[frames]\nstart = 1\n");
    let scenes = vec![fine("a.toml", "a"), fine("b.toml", "b"), good];
    let checked = check_scenes(&scenes, &opts).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(checked.len(), 3);

    // A frame range past the flipbook's 4 frames.
    let scenes = vec![
        fine("a.toml", "a"),
        fine("b.toml", "b"),
        book("range.toml", "[frames]\nend = 6\n"),
    ];
    let e = check_scenes(&scenes, &opts)
        .err()
        .expect("a bad range")
        .to_string();
    assert!(
        e.contains("range.toml") && e.contains("[frames]") && e.contains("4 frame"),
        "{e}"
    );
    // Frame 2 with another vertex count.
    write_obj(&frames.join("frame_2.obj"), &icosphere(1.0, 2));
    let scenes = vec![
        fine("a.toml", "a"),
        fine("b.toml", "b"),
        book("book.toml", ""),
    ];
    let e = check_scenes(&scenes, &opts)
        .err()
        .expect("a bad frame")
        .to_string();
    assert!(
        e.contains("book.toml")
            && e.contains("flipbook frame 2")
            && e.contains("frame_2.obj")
            && e.contains("vertices"),
        "{e}"
    );
    // A glTF clip's frames (the bundled fuzz seed: a one-second clip, 31
    // frames at 30 fps) are counted before any scene runs, too.
    let seed = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/glb/seed-skinned.glb");
    std::fs::copy(&seed, dir.join("skinned.glb")).unwrap();
    let clip = |name: &str, end: usize| {
        scene_file(
            &dir,
            name,
            &format!(
                "[input]\ngltf = \"skinned.glb\"\n[frames]\nend = {end}\n[effects]\n\
                 shading = {{}}\n[output]\ndir = \"out\"\nname = \"{name}\"\n"
            ),
        )
    };
    let scenes = vec![fine("a.toml", "a"), clip("clip.toml", 31)];
    check_scenes(&scenes, &opts).unwrap_or_else(|e| panic!("{e}"));
    let scenes = vec![
        fine("a.toml", "a"),
        fine("b.toml", "b"),
        clip("long.toml", 40),
    ];
    let e = check_scenes(&scenes, &opts)
        .err()
        .expect("past the clip")
        .to_string();
    assert!(
        e.contains("long.toml") && e.contains("[frames]") && e.contains("31 frame"),
        "{e}"
    );
    // Frames outside the range are not checked.
    let scenes = vec![book("book.toml", "[frames]\nend = 2\n")];
    check_scenes(&scenes, &opts).unwrap_or_else(|e| panic!("{e}"));
    assert!(!out.exists(), "the checks write nothing");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Sequences too large to load twice are checked from their PLY headers:
/// a frame declaring another vertex count is refused without parsing it.
#[test]
fn large_sequences_are_checked_from_their_headers() {
    use shapecue::mesh::flipbook::FULL_CHECK_BYTES;
    let dir = scratch("check-headers");
    write_sequence(&dir, 3, "ply");
    // Frame 2 claims another vertex count; its body is left as it was (a
    // full load would report the mismatch differently).
    let p2 = dir.join("frame_2.ply");
    let bytes = std::fs::read(&p2).unwrap();
    let nv = base().positions.len();
    let text = String::from_utf8_lossy(&bytes);
    let from = format!("element vertex {nv}\n");
    assert!(text.contains(&from));
    let mut patched = bytes.clone();
    let at = text.find(&from).unwrap();
    let to = format!("element vertex {}\n", nv + 1);
    assert_eq!(to.len(), from.len(), "same length: the body stays in place");
    patched[at..at + to.len()].copy_from_slice(to.as_bytes());
    std::fs::write(&p2, &patched).unwrap();
    // Past the full-check size: sparse padding after the data (every frame,
    // so that the total is large; the loader ignores bytes past the faces).
    for f in 0..3 {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(dir.join(format!("frame_{f}.ply")))
            .unwrap();
        file.set_len(FULL_CHECK_BYTES / 2).unwrap();
    }
    assert_eq!(
        shapecue::mesh::header_counts(&p2).unwrap(),
        Some((nv + 1, base().faces.len()))
    );
    let fb = Flipbook::open("frame_*.ply", &dir, &LoadOptions::default()).unwrap();
    assert!(fb.check_frames(&[0, 1]).is_ok());
    let (i, e) = fb.check_frames(&[0, 1, 2]).unwrap_err();
    let e = e.to_string();
    assert_eq!(i, 2);
    assert!(
        e.contains("frame_2.ply")
            && e.contains(&format!("{} vertices", nv + 1))
            && e.contains("frame_0.ply"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
