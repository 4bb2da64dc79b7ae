//! The libigl elephant LBS set: the file conventions (frame 0 is the rest
//! pose; bone transforms are rigid and keep the skeleton connected), the
//! cost of keeping four weights per vertex (CPU twin vs the dense f64
//! reference, relative to the bounding-box diagonal), the device `Skinner`
//! vs the CPU twin, and clear errors for corrupt DMAT/TGF files and
//! mismatched sets.

mod common;

use common::{gpu, max_abs_diff, scratch, shared, shared_data, to_f32};

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use shapecue::Error;
use shapecue::cpu::skinning::skin_lbs;
use shapecue::mesh::libigl::{
    LbsAnimation, SIGNIFICANT_WEIGHT, load_elephant_set, read_dmat, read_tgf,
};
use shapecue::mesh::skinned::SkinnedMesh;
use shapecue::stages::skinning::Skinner;

/// Where the elephant set is inside the shared data.
const ELEPHANT: &str = "animations/elephant";

/// The elephant set, loaded once, or `None` (after saying so) when absent.
fn elephant() -> Option<&'static LbsAnimation> {
    static SET: OnceLock<Option<LbsAnimation>> = OnceLock::new();
    SET.get_or_init(|| {
        let obj = shared(Path::new(ELEPHANT).join("elephant.obj"))?;
        Some(load_elephant_set(&obj).unwrap_or_else(|e| panic!("{e}")))
    })
    .as_ref()
}

fn diagonal(a: &LbsAnimation) -> f64 {
    let (lo, hi) = a.rest.bounds();
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

fn dist(p: [f64; 3], q: [f64; 3]) -> f64 {
    (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn set_loads_with_the_documented_shapes() {
    let Some(a) = elephant() else { return };
    assert_eq!(a.rest.n_vertices(), 6034);
    assert_eq!(a.rest.n_faces(), 12_064);
    assert_eq!(a.skeleton.joints.len(), 25);
    assert_eq!(a.n_bones, 24);
    assert_eq!((a.weights_dense.rows, a.weights_dense.cols), (6034, 24));
    assert_eq!((a.anim.rows, a.anim.cols), (288, 457));
    assert_eq!(a.frames, 457);
    // Rows of W sum to 1.
    let worst = (0..6034)
        .map(|v| ((0..24).map(|b| a.weights_dense.get(v, b)).sum::<f64>() - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "a weight row sums to 1 ± {worst}");
}

#[test]
fn frame_zero_is_the_rest_pose_and_later_frames_are_rigid_bone_motions() {
    let Some(a) = elephant() else { return };
    let u0 = a.dense_frame(0).unwrap();
    let e0 = u0
        .iter()
        .zip(&a.rest.positions)
        .map(|(p, q)| dist(*p, *q))
        .fold(0.0, f64::max);
    eprintln!("elephant frame 0 dense vs rest: max {e0:.2e}");
    assert!(e0 < 1e-9, "frame 0 is not the rest pose: {e0}");

    // The column-major reading of each frame gives rigid transforms (R orthonormal,
    // det +1) that keep the skeleton connected: a bone and its parent move their
    // shared joint to the same place. A wrong reshape would give neither.
    let parents = a.skeleton.bone_parents();
    let joints = &a.skeleton.joints;
    let diag = diagonal(a);
    let (mut worst_rigid, mut worst_joint, mut moved) = (0.0f64, 0.0f64, 0.0f64);
    for f in 0..a.frames {
        let aff = a.frame_affines(f).unwrap();
        for m in &aff {
            for i in 0..3 {
                for j in 0..3 {
                    let dot: f64 = (0..3).map(|k| m[k][i] * m[k][j]).sum();
                    let want = if i == j { 1.0 } else { 0.0 };
                    worst_rigid = worst_rigid.max((dot - want).abs());
                }
            }
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            assert!(det > 0.0, "frame {f}: a reflection");
        }
        let apply = |m: &[[f64; 4]; 3], p: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
        };
        for (b, bone) in a.skeleton.bones.iter().enumerate() {
            let head = joints[bone[0] as usize];
            if let Some(p) = parents[b] {
                worst_joint = worst_joint.max(dist(apply(&aff[b], head), apply(&aff[p], head)));
            }
            moved = moved.max(dist(apply(&aff[b], head), head));
        }
    }
    eprintln!(
        "elephant bones over {} frames: max |RᵀR − I| {worst_rigid:.2e}, max joint gap \
         {:.2e} of the diagonal, max joint travel {:.3} of the diagonal",
        a.frames,
        worst_joint / diag,
        moved / diag
    );
    assert!(
        worst_rigid < 1e-6,
        "bone transforms are not rigid: {worst_rigid}"
    );
    assert!(
        worst_joint / diag < 1e-6,
        "the skeleton comes apart: {worst_joint}"
    );
    assert!(moved / diag > 0.05, "the animation barely moves: {moved}");

    // Frame matrices in Mat4 form: identity at frame 0.
    for m in a.frame_matrices(0).unwrap() {
        assert!(m.abs_diff_eq(glam::Mat4::IDENTITY, 1e-6), "{m}");
    }
    assert!(matches!(
        a.frame_matrices(a.frames),
        Err(Error::InvalidArgument(_))
    ));
    assert!(a.dense_frame(a.frames).is_err());
}

#[test]
fn top4_truncation_error_against_dense_lbs() {
    let Some(a) = elephant() else { return };
    let (sk, stats) = a.to_skinned();
    eprintln!(
        "elephant top-4 truncation: {} of {} vertices have more than 4 non-zero weights \
         (at most {}), {} more than 4 above {SIGNIFICANT_WEIGHT}; dropped weight max {:.4}, \
         mean {:.2e}",
        stats.vertices_over_4,
        a.rest.n_vertices(),
        stats.max_influences,
        stats.significant_over_4,
        stats.max_dropped,
        stats.mean_dropped
    );
    assert!(sk.weights.iter().all(|w| {
        let s: f32 = w.iter().sum();
        (s - 1.0).abs() < 1e-6
    }));
    assert!(
        sk.joints
            .iter()
            .flatten()
            .all(|&j| (j as usize) < a.n_bones)
    );
    assert!(stats.max_dropped < 1.0 && stats.mean_dropped <= stats.max_dropped);
    // The rest pose of the SkinnedMesh is the identity.
    let ident = sk.joint_matrices(None, 0.0).unwrap();
    assert!(
        ident
            .iter()
            .all(|m| m.abs_diff_eq(glam::Mat4::IDENTITY, 0.0))
    );

    let rest = to_f32(&a.rest.positions);
    let diag = diagonal(a);
    let (mut max_d, mut sum_sq, mut n) = (0.0f64, 0.0f64, 0usize);
    let mut worst_frame = 0;
    let mut max_motion = 0.0f64;
    for f in 0..a.frames {
        let dense = a.dense_frame(f).unwrap();
        let mats = SkinnedMesh::flatten(&a.frame_matrices(f).unwrap());
        let top4 = skin_lbs(&rest, &sk.joints, &sk.weights, &mats);
        for ((p, q), r) in top4.iter().zip(&dense).zip(&a.rest.positions) {
            let d = dist(p.map(f64::from), *q);
            if d > max_d {
                max_d = d;
                worst_frame = f;
            }
            sum_sq += d * d;
            n += 1;
            max_motion = max_motion.max(dist(*q, *r));
        }
    }
    let rms = (sum_sq / n as f64).sqrt();
    eprintln!(
        "elephant top-4 CPU skinning vs dense f64 LBS over {} frames (bbox diagonal {diag:.2}): \
         max {:.3e} (frame {worst_frame}), RMS {:.3e} of the diagonal; max dense motion {:.3} \
         of the diagonal",
        a.frames,
        max_d / diag,
        rms / diag,
        max_motion / diag
    );
    // Measured: max 2.8e-2, RMS 1.7e-3 of the diagonal. The elephant's
    // weights are diffuse (about 1,600 vertices have more than four above
    // 1e-3, one loses half its weight), so four influences cost a few
    // percent of the size at worst; these bounds catch a regression.
    assert!(max_d / diag < 4e-2, "top-4 max error {}", max_d / diag);
    assert!(rms / diag < 2.5e-3, "top-4 RMS error {}", rms / diag);
    assert!(
        max_d < 0.1 * max_motion,
        "the error is not small against the motion"
    );
}

#[test]
fn device_matches_cpu_twin_on_elephant_frames() {
    let Some(a) = elephant() else { return };
    let (sk, _) = a.to_skinned();
    let rest = to_f32(&a.rest.positions);
    let diag = diagonal(a) as f32;
    let mut skinner = Skinner::new(gpu(), &sk).unwrap();
    for f in [0, 57, 150, 300, a.frames - 1] {
        let mats = SkinnedMesh::flatten(&a.frame_matrices(f).unwrap());
        skinner.pose(&mats).unwrap();
        let dev = skinner.read().unwrap();
        let cpu = skin_lbs(&rest, &sk.joints, &sk.weights, &mats);
        let d = max_abs_diff(&dev, &cpu) / diag;
        eprintln!("elephant frame {f}: device vs CPU twin max {d:.2e} of the diagonal");
        assert!(d < 1e-5, "frame {f}: device vs CPU {d}");
    }
}

/// Reads and expects an `InvalidInput` error naming the file; returns it.
fn dmat_err(path: &Path) -> String {
    match read_dmat(path) {
        Err(e @ Error::InvalidInput { .. }) => {
            let msg = e.to_string();
            assert!(msg.contains(&path.display().to_string()), "{msg}");
            msg
        }
        other => panic!("{}: expected an error, got {other:?}", path.display()),
    }
}

fn binary_dmat(cols: usize, rows: usize, values: &[f64]) -> Vec<u8> {
    let mut b = format!("0 0\n{cols} {rows}\n").into_bytes();
    for v in values {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

#[test]
fn corrupt_dmat_files_are_errors_not_panics() {
    let dir = scratch("dmat");
    let w = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    // Real data when present, else a synthetic binary matrix of the same kind.
    let real = shared_data().join(ELEPHANT).join("elephant-weights.dmat");
    let bytes = std::fs::read(&real).unwrap_or_else(|_| {
        // 4 columns: the NaN test below writes into column 3.
        binary_dmat(
            4,
            50,
            &(0..200).map(|k| k as f64 / 200.0).collect::<Vec<_>>(),
        )
    });
    let good = read_dmat(&w("good.dmat", &bytes)).unwrap();
    let header_len = bytes
        .iter()
        .enumerate()
        .filter(|(_, c)| **c == b'\n')
        .nth(1)
        .unwrap()
        .0
        + 1;

    // Truncated anywhere: an error, never a panic.
    for cut in [
        0,
        2,
        4,
        header_len - 1,
        header_len,
        header_len + 5,
        bytes.len() / 2,
        bytes.len() - 1,
    ] {
        let e = dmat_err(&w(&format!("cut{cut}.dmat"), &bytes[..cut]));
        assert!(
            e.contains("truncated") || e.contains("header") || e.contains("end of file"),
            "cut at {cut}: {e}"
        );
    }
    let e = dmat_err(&w("cut.dmat", &bytes[..bytes.len() - 8]));
    assert!(e.contains("truncated"), "{e}");
    // Trailing data (a wrong header or a concatenated file).
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 16]);
    let e = dmat_err(&w("long.dmat", &long));
    assert!(e.contains("16 bytes after"), "{e}");
    // Wrong headers.
    for (name, head) in [
        ("h1.dmat", &b"0 x\n"[..]),
        ("h2.dmat", b"1 2 3\n"),
        ("h3.dmat", b"-1 2\n1\n2\n"),
        ("h4.dmat", b"0 0\n"),
        ("h5.dmat", b"0 0\n99999999999 99999999999\n"),
        ("h6.dmat", b"0 0\n18446744073709551615 3\n"),
    ] {
        let e = dmat_err(&w(name, head));
        assert!(e.contains("header line"), "{name}: {e}");
    }
    // No line end in a long file.
    let e = dmat_err(&w("noline.dmat", &[b'1'; 1000]));
    assert!(e.contains("header line 1"), "{e}");
    // NaN in the data: the entry is named.
    let mut nan = bytes.clone();
    let k = 3 * good.rows + 7; // row 7, column 3
    nan[header_len + 8 * k..header_len + 8 * k + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let e = dmat_err(&w("nan.dmat", &nan));
    assert!(
        e.contains("entry (row 7, column 3)") && e.contains("NaN"),
        "{e}"
    );
    // Random byte flips in the header and payload start: never a panic.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for trial in 0..64 {
        let mut b = bytes[..bytes.len().min(4096)].to_vec();
        for _ in 0..4 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state % 64) as usize % b.len();
            b[at] = (state >> 32) as u8;
        }
        let _ = read_dmat(&w(&format!("flip{trial}.dmat"), &b));
    }

    // Text DMAT: values column-major, errors with line and entry.
    let t = read_dmat(&w("t.dmat", b"2 3\n1 2 3\n4 5 6\n")).unwrap();
    assert_eq!((t.rows, t.cols, t.get(2, 0), t.get(0, 1)), (3, 2, 3.0, 4.0));
    let e = dmat_err(&w("tnan.dmat", b"2 3\n1 2 3\n4 nan 6\n"));
    assert!(
        e.contains("entry (row 1, column 1)") && e.contains("line 3"),
        "{e}"
    );
    let e = dmat_err(&w("tbad.dmat", b"2 3\n1 2 3\n4 x 6\n"));
    assert!(e.contains("'x'") && e.contains("line 3"), "{e}");
    let e = dmat_err(&w("tshort.dmat", b"2 3\n1 2 3\n4 5\n"));
    assert!(e.contains("truncated") && e.contains("found 5"), "{e}");
    let e = dmat_err(&w("tlong.dmat", b"2 3\n1 2 3\n4 5 6 7\n"));
    assert!(e.contains("more than"), "{e}");
    let e = dmat_err(&w("tbin.dmat", b"2 3\n\xff\xfe\n"));
    assert!(e.contains("not text"), "{e}");
    // Missing file: an I/O error naming it.
    let missing = dir.join("missing.dmat");
    let e = read_dmat(&missing).unwrap_err().to_string();
    assert!(e.contains("missing.dmat"), "{e}");
}

/// Writes a tiny libigl set (a tetrahedron, 3 joints, 2 bones) as text files.
fn tiny_set(dir: &Path, tgf: &str, weights: &str, anim: &str) -> PathBuf {
    let obj = dir.join("tiny.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    std::fs::write(dir.join("tiny.tgf"), tgf).unwrap();
    std::fs::write(dir.join("tiny-weights.dmat"), weights).unwrap();
    std::fs::write(dir.join("tiny-anim.dmat"), anim).unwrap();
    obj
}

/// Text DMAT of a `rows × cols` matrix given column-major.
fn text_dmat(rows: usize, cols: usize, v: &[f64]) -> String {
    let mut s = format!("{cols} {rows}\n");
    for x in v {
        s.push_str(&format!("{x}\n"));
    }
    s
}

/// Animation column of 2 bones: bone 0 identity, bone 1 a translation by t,
/// in libigl's layout (column-major 8 × 3 `Tf`, block b = rows 4b..4b+4).
fn anim_column(t: [f64; 3]) -> Vec<f64> {
    let mut tf = [[0.0f64; 3]; 8]; // Tf[row][col]
    for b in 0..2 {
        for k in 0..3 {
            tf[4 * b + k][k] = 1.0;
        }
    }
    tf[7] = t;
    (0..3).flat_map(|c| (0..8).map(move |r| tf[r][c])).collect()
}

#[test]
fn tiny_set_skins_as_expected_and_mismatches_are_errors() {
    let dir = scratch("tiny");
    let tgf = "1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2\n2 3\n#\n";
    // Vertex v: weights (1 − v/4, v/4) on bones 0 and 1.
    let w: Vec<f64> = (0..2)
        .flat_map(|b| {
            (0..4).map(move |v| {
                if b == 0 {
                    1.0 - v as f64 / 4.0
                } else {
                    v as f64 / 4.0
                }
            })
        })
        .collect();
    let mut anim = anim_column([0.0; 3]);
    anim.extend(anim_column([4.0, 0.0, 0.0]));
    let obj = tiny_set(&dir, tgf, &text_dmat(4, 2, &w), &text_dmat(24, 2, &anim));
    let a = load_elephant_set(&obj).unwrap();
    assert_eq!((a.frames, a.n_bones), (2, 2));
    assert_eq!(a.dense_frame(0).unwrap(), a.rest.positions);
    // Frame 1 moves vertex v by (4 · v/4, 0, 0) = (v, 0, 0).
    let u1 = a.dense_frame(1).unwrap();
    for (v, (p, q)) in u1.iter().zip(&a.rest.positions).enumerate() {
        assert_eq!(*p, [q[0] + v as f64, q[1], q[2]], "vertex {v}");
    }
    // Two bones: top-4 keeps everything, and the CPU twin agrees.
    let (sk, stats) = a.to_skinned();
    assert_eq!(stats.vertices_over_4, 0);
    assert_eq!(stats.max_dropped, 0.0);
    let mats = SkinnedMesh::flatten(&a.frame_matrices(1).unwrap());
    let cpu = skin_lbs(&to_f32(&a.rest.positions), &sk.joints, &sk.weights, &mats);
    for (p, q) in cpu.iter().zip(&u1) {
        for k in 0..3 {
            assert!((f64::from(p[k]) - q[k]).abs() < 1e-6);
        }
    }
    assert_eq!(sk.parents, vec![None, Some(0), None]);

    let err = |obj: &Path| match load_elephant_set(obj) {
        Err(e @ Error::InvalidInput { .. }) => e.to_string(),
        other => panic!("expected an error, got {other:?}"),
    };
    // Three bones in the skeleton, two weight columns.
    let obj3 = tiny_set(
        &dir,
        "1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2\n2 3\n1 3\n",
        &text_dmat(4, 2, &w),
        &text_dmat(24, 2, &anim),
    );
    let e = err(&obj3);
    assert!(
        e.contains("tiny-weights.dmat") && e.contains("3 bones"),
        "{e}"
    );
    // Weights for 3 vertices.
    let obj = tiny_set(
        &dir,
        tgf,
        &text_dmat(3, 2, &w[..6]),
        &text_dmat(24, 2, &anim),
    );
    let e = err(&obj);
    assert!(
        e.contains("tiny-weights.dmat") && e.contains("4 vertices"),
        "{e}"
    );
    // An animation with 12 rows for 2 bones.
    let obj = tiny_set(&dir, tgf, &text_dmat(4, 2, &w), &text_dmat(12, 4, &anim));
    let e = err(&obj);
    assert!(e.contains("tiny-anim.dmat") && e.contains("24"), "{e}");
    // A bone naming a joint that does not exist.
    let obj = tiny_set(
        &dir,
        "1 0 0 0\n2 0 1 0\n#\n1 2\n2 3\n",
        &text_dmat(4, 2, &w),
        &text_dmat(24, 2, &anim),
    );
    let e = err(&obj);
    assert!(
        e.contains("tiny.tgf") && e.contains("bone 1") && e.contains("line 5"),
        "{e}"
    );
    let e = read_tgf(&dir.join("nothing.tgf")).unwrap_err().to_string();
    assert!(e.contains("nothing.tgf"), "{e}");
    // Missing siblings are all named.
    std::fs::remove_file(dir.join("tiny.tgf")).unwrap();
    std::fs::remove_file(dir.join("tiny-anim.dmat")).unwrap();
    let e = err(&obj);
    assert!(
        e.contains("tiny.tgf") && e.contains("tiny-anim.dmat") && !e.contains("weights"),
        "{e}"
    );
}
