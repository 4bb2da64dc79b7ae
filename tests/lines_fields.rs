//! The per-view outputs dataset builders keep beside the lines
//! (`shapecue lines --views/--cameras --fields --npz`), read back with
//! `ndarray-npy` and checked against a sphere's closed forms: n·v, κr sin²θ,
//! D_w κr and q1 per vertex in world units (the sphere far from the origin
//! and larger than one, so the device's normalized coordinates must be
//! mapped back), and each segment piece's face and barycentric
//! coordinates, which rebuild its ends.

mod common;

use common::{assert_succeeded, cli_no_gl, obj_text, scratch, write};
use ndarray::{Array1, Array2, Array3};
use ndarray_npy::NpzReader;
use std::fs::File;
use std::path::Path;

const R: f64 = 5.0;
const C: [f64; 3] = [100.0, -50.0, 20.0];

fn read1(path: &Path, name: &str) -> Vec<f32> {
    let mut z = NpzReader::new(File::open(path).unwrap()).unwrap();
    let a: Array1<f32> = z.by_name(&format!("{name}.npy")).unwrap();
    a.to_vec()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] - b[i])
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    a.map(|x| x / l)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| a[i] * b[i]).sum()
}

#[test]
fn view_fields_and_segment_provenance_match_a_sphere() {
    let d = scratch("lines-fields");
    let mut m = shapecue::mesh::icosphere(R, 4);
    for p in &mut m.positions {
        *p = std::array::from_fn(|i| p[i] + C[i]);
    }
    let mesh = write(&d, "ball.obj", obj_text(m.positions.clone(), &m.faces));
    let eye = [C[0] + 4.0 * R, C[1] + 1.5 * R, C[2] + 2.0 * R];
    let cams = format!(
        r#"{{"cameras": [{{"eye": [{}, {}, {}], "target": [{}, {}, {}]}},
                        {{"eye": [{}, {}, {}], "target": [{}, {}, {}], "ortho": 14}}]}}"#,
        eye[0],
        eye[1],
        eye[2],
        C[0],
        C[1],
        C[2],
        C[0],
        C[1],
        C[2] + 30.0,
        C[0],
        C[1],
        C[2]
    );
    let cams = write(&d, "cams.json", cams);
    let out = d.join("out");
    let o = cli_no_gl(&d)
        .args(["lines", mesh.to_str().unwrap(), "--cameras"])
        .arg(&cams)
        .args(["--out", out.to_str().unwrap(), "--fields", "--npz"])
        .args(["--lines", "contours,suggestive,isophotes"])
        .output()
        .unwrap();
    assert_succeeded(&o);
    for (view, ortho_dir) in [(0, None), (1, Some([0.0, 0.0, 1.0]))] {
        let f = out.join(format!("ball_f0000_v{view:02}_fields.npz"));
        let [ndv, kr, dwkr, q1] = ["ndotv", "kr", "dwkr", "q1"].map(|n| read1(&f, n));
        assert_eq!(ndv.len(), m.positions.len());
        let mut worst = [0f64; 4];
        for (i, p) in m.positions.iter().enumerate() {
            let n = unit(sub(*p, C));
            let v = ortho_dir.unwrap_or_else(|| unit(sub(eye, *p)));
            let nd = dot(n, v);
            worst[0] = worst[0].max((f64::from(ndv[i]) - nd).abs());
            // A sphere: k1 = k2 = 1/R, so κr sin²θ = (1 − (n·v)²)/R,
            // D_w κr = 0, and Q = (1/R)(I + (sec θ − 1) w wᵀ): q1 = sec²θ/R².
            let kr_want = (1.0 - nd * nd) / R;
            worst[1] = worst[1].max((f64::from(kr[i]) - kr_want).abs() * R);
            worst[2] = worst[2].max(f64::from(dwkr[i]).abs() * R * R);
            if nd > 0.3 {
                let q1_want = 1.0 / (R * nd).powi(2);
                worst[3] = worst[3].max((f64::from(q1[i]) / q1_want - 1.0).abs());
            }
            assert!(q1[i].is_finite() && q1[i] >= 0.0, "q1 at {i}: {}", q1[i]);
        }
        // Vertex normals and curvature of a level-4 icosphere.
        assert!(worst[0] < 5e-3, "view {view}: n·v off by {}", worst[0]);
        assert!(worst[1] < 0.03, "view {view}: κr off by {} / R", worst[1]);
        assert!(
            worst[2] < 0.1,
            "view {view}: D_w κr up to {} / R²",
            worst[2]
        );
        assert!(worst[3] < 0.05, "view {view}: q1 off by {}", worst[3]);

        let s = out.join(format!("ball_f0000_v{view:02}_segments.npz"));
        let mut z = NpzReader::new(File::open(&s).unwrap()).unwrap();
        let a: Array2<f32> = z.by_name("a.npy").unwrap();
        let b: Array2<f32> = z.by_name("b.npy").unwrap();
        let face: Array1<i64> = z.by_name("face.npy").unwrap();
        let bary: Array3<f32> = z.by_name("bary.npy").unwrap();
        assert!(a.nrows() > 100, "view {view}: {} pieces", a.nrows());
        let mut off = 0f64;
        for k in 0..a.nrows() {
            assert!(face[k] >= 0, "piece {k} lies on a face");
            let t = m.faces[face[k] as usize].map(|v| m.positions[v as usize]);
            for (e, end) in [&a, &b].into_iter().enumerate() {
                let w = [0, 1, 2].map(|j| f64::from(bary[[k, e, j]]));
                assert!(w.iter().all(|x| *x > -1e-3), "piece {k}: {w:?}");
                for c in 0..3 {
                    let p: f64 = (0..3).map(|j| w[j] * t[j][c]).sum();
                    off = off.max((p - f64::from(end[[k, c]])).abs());
                }
            }
        }
        assert!(off < 1e-4 * R, "view {view}: ends rebuilt within {off}");
    }
}
