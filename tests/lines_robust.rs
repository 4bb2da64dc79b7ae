//! Line drawings of awkward meshes, as real collections hold them: several
//! components, open boundaries, isolated vertices, degenerate and duplicate
//! faces, non-manifold edges, huge and tiny scales. `shapecue lines` with
//! exact visibility (SVG and segments, no GL) gives a drawing with finite
//! coordinates for each, or, for a broken file, an error naming the file and
//! the element, never a crash.

mod common;

use common::{cli_no_gl, obj_text, scratch, write};
use shapecue::mesh::{Mesh, icosphere, torus};
use std::path::Path;

type Faces = Vec<[u32; 3]>;

fn parts(m: &Mesh) -> (Vec<[f64; 3]>, Faces) {
    (m.positions.clone(), m.faces.clone())
}

/// `b` appended to `a`, moved by `shift`.
fn join(a: &Mesh, b: &Mesh, shift: [f64; 3]) -> (Vec<[f64; 3]>, Faces) {
    let n = a.positions.len() as u32;
    let mut p = a.positions.clone();
    p.extend(
        b.positions
            .iter()
            .map(|q| std::array::from_fn(|k| q[k] + shift[k])),
    );
    let mut f = a.faces.clone();
    f.extend(b.faces.iter().map(|t| t.map(|v| v + n)));
    (p, f)
}

/// The meshes: name and OBJ text.
fn cases() -> Vec<(&'static str, String)> {
    let ball = icosphere(1.0, 3);
    let ring = torus(1.0, 0.35, 48, 24);
    let obj = |(p, f): (Vec<[f64; 3]>, Faces)| obj_text(p, &f);
    let mut out = vec![("components", obj(join(&ball, &ring, [3.0, 0.2, 0.1])))];
    // An open boundary: the upper half of the sphere.
    let (p, f) = parts(&ball);
    let upper: Faces = (f.iter())
        .filter(|t| t.iter().all(|&v| p[v as usize][2] > -1e-9))
        .copied()
        .collect();
    out.push(("hemisphere", obj((p.clone(), upper))));
    // Isolated vertices far away (a fitted camera must ignore them).
    let mut q = p.clone();
    q.extend([[1e4, 0.0, 0.0], [0.0, -3e3, 7.0]]);
    out.push(("isolated", obj((q, f.clone()))));
    // Degenerate faces (a repeated index, three collinear points) and a
    // face given twice.
    let mut q = p.clone();
    let n = q.len() as u32;
    q.extend([[0.0, 0.0, 2.0], [0.5, 0.0, 2.0], [1.0, 0.0, 2.0]]);
    let mut g = f.clone();
    g.extend([[0, 0, 1], [n, n + 1, n + 2], f[5], f[5]]);
    out.push(("degenerate", obj((q, g))));
    // A non-manifold edge: a fin on one edge of the sphere.
    let mut q = p.clone();
    let [a, b, _] = f[0];
    let n = q.len() as u32;
    let (pa, pb) = (p[a as usize], p[b as usize]);
    q.push(std::array::from_fn(|k| 0.5 * (pa[k] + pb[k]) * 1.8));
    let mut g = f.clone();
    g.push([a, b, n]);
    out.push(("non-manifold", obj((q, g))));
    for (name, s) in [("huge", 1e6), ("tiny", 1e-6)] {
        let q: Vec<[f64; 3]> = ring.positions.iter().map(|v| v.map(|c| c * s)).collect();
        out.push((name, obj((q, ring.faces.clone()))));
    }
    out
}

fn lines(dir: &Path, mesh: &Path, tag: &str) -> std::process::Output {
    cli_no_gl(dir)
        .arg("lines")
        .arg(mesh)
        .args(["--lines", "contours,suggestive,ridges,valleys,boundaries"])
        .arg("-o")
        .arg(dir.join(format!("{tag}.svg")))
        .arg("--segments")
        .arg(dir.join(format!("{tag}.json")))
        .output()
        .unwrap()
}

#[test]
fn awkward_meshes_give_finite_drawings() {
    let d = scratch("awkward");
    for (name, text) in cases() {
        let mesh = write(&d, &format!("{name}.obj"), text);
        let out = lines(&d, &mesh, name);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {err}");
        let svg = std::fs::read_to_string(d.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains("<g id=\"contours\""), "{name}");
        assert!(!svg.contains("NaN") && !svg.contains("inf"), "{name}");
        let doc: serde_json::Value =
            serde_json::from_slice(&std::fs::read(d.join(format!("{name}.json"))).unwrap())
                .unwrap();
        let segs = doc["segments"].as_array().unwrap();
        // Every mesh here has contours in view.
        assert!(segs.iter().any(|s| s["family"] == "contours"), "{name}");
        for s in segs {
            for end in ["a", "b"] {
                let p = s[end].as_array().unwrap();
                assert!(p.iter().all(|c| c.as_f64().is_some()), "{name}: {s}");
            }
        }
        if name == "hemisphere" {
            assert!(segs.iter().any(|s| s["family"] == "boundaries"), "{name}");
        }
    }
}

#[test]
fn a_broken_file_is_an_error_naming_the_element() {
    let d = scratch("broken");
    let m = icosphere(1.0, 2);
    let mut p = m.positions.clone();
    p[7] = [f64::NAN, 0.0, 0.0];
    let nan = write(&d, "nan.obj", obj_text(p, &m.faces));
    let out = lines(&d, &nan, "nan");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("nan.obj") && err.contains("vertex 7"), "{err}");
    let mut f = m.faces.clone();
    f.push([0, 1, 9999]);
    let bad = write(&d, "index.obj", obj_text(m.positions.clone(), &f));
    let out = lines(&d, &bad, "index");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("index.obj") && err.contains("face 320") && err.contains("10000"),
        "{err}"
    );
    assert!(!d.join("nan.svg").exists() && !d.join("index.svg").exists());
}

/// A triangle soup (no two faces share a vertex, as STL files give) draws
/// nothing, and says why and what to do; `--weld` draws what the welded
/// mesh draws.
#[test]
fn a_triangle_soup_says_so_and_draws_once_welded() {
    let dir = scratch("soup");
    let m = icosphere(1.0, 3);
    let positions: Vec<[f64; 3]> = m
        .faces
        .iter()
        .flat_map(|f| f.map(|v| m.positions[v as usize]))
        .collect();
    let faces: Faces = (0..m.faces.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    let soup = write(&dir, "soup.obj", obj_text(positions, &faces));
    let run = |extra: &[&str], out: &str| {
        let (o, said) = common::succeeded(
            cli_no_gl(&dir)
                .args(["lines", "--lines", "contours,k-zero"])
                .arg(&soup)
                .args(extra)
                .arg("-o")
                .arg(dir.join(out)),
        );
        (said, String::from_utf8_lossy(&o.stderr).into_owned())
    };
    let (said, warned) = run(&[], "soup.svg");
    assert!(said.contains("no segments"), "{said}");
    assert!(
        warned.contains("no two of its 1280 faces share a vertex") && warned.contains("--weld"),
        "{warned}"
    );
    let (said, warned) = run(&["--weld"], "welded.svg");
    assert!(
        !said.contains("no segments") && warned.is_empty(),
        "{said}{warned}"
    );
}
