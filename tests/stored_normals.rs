//! The vertex normals a mesh file stores: read as trimesh2 2.16 reads them
//! (OBJ `vn` lines one per vertex, PLY `nx ny nz`), checked, kept through
//! welding and memory orders, and used by the curvature (device and twin
//! alike) and so by every line family, unless `--normals computed`.

mod common;

use common::{cli, scratch, write};
use shapecue::mesh::{LoadOptions, Mesh, NormalsSource, icosphere, load};
use shapecue::spec::curvature::{CurvatureOptions, Precision};

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
const TETRA_FACES: &str = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn opts(normals: NormalsSource) -> LoadOptions {
    LoadOptions {
        normals,
        ..LoadOptions::default()
    }
}

#[test]
fn obj_normals_are_the_vn_lines_in_order_one_per_vertex() {
    let dir = scratch("obj-vn");
    // The faces' normal indices point elsewhere: trimesh2 ignores them, and
    // pairs the k-th `vn` line with the k-th vertex.
    let text = format!(
        "{TETRA}vn 0 0 -1\nvn 1 0 0\nvn 0 2 0\nvn 0.5 0.5 0.5\n\
         f 1//4 3//3 2//2\nf 1//1 2//1 4//1\nf 1//2 4//2 3//2\nf 2//3 3//3 4//3\n"
    );
    let p = write(&dir, "t.obj", text);
    let m = load(&p, &LoadOptions::default()).unwrap();
    assert_eq!(
        m.normals.as_deref(),
        Some(
            &[
                [0.0, 0.0, -1.0],
                [1.0, 0.0, 0.0],
                [0.0, 2.0, 0.0],
                [0.5, 0.5, 0.5]
            ][..]
        )
    );
    // Asked to compute them, the loader drops them.
    let m = load(&p, &opts(NormalsSource::Computed)).unwrap();
    assert_eq!(m.normals, None);
}

#[test]
fn normals_that_do_not_pair_with_the_vertices_are_dropped_as_trimesh2_drops_them() {
    let dir = scratch("obj-vn-count");
    let p = write(
        &dir,
        "t.obj",
        format!("{TETRA}vn 0 0 1\nvn 0 0 1\nvn 0 0 1\n{TETRA_FACES}"),
    );
    assert_eq!(load(&p, &LoadOptions::default()).unwrap().normals, None);
}

#[test]
fn a_malformed_vn_line_is_named() {
    let dir = scratch("obj-vn-bad");
    let p = write(
        &dir,
        "t.obj",
        format!("{TETRA}vn 0 0 1\nvn 0 x 1\n{TETRA_FACES}"),
    );
    let e = load(&p, &LoadOptions::default()).unwrap_err().to_string();
    assert!(
        e.contains("normal 1") && e.contains("line 6") && e.contains("'x'"),
        "{e}"
    );
}

#[test]
fn ply_normals_are_read_from_ascii_and_binary_files() {
    let dir = scratch("ply-normals");
    let verts = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let normals = [[-1f32, -1., -1.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let faces = [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let head = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
             property uchar red\nelement face 4\nproperty list uchar int vertex_indices\n\
             end_header\n"
        )
    };
    let mut ascii = head("ascii");
    for (p, n) in verts.iter().zip(&normals) {
        ascii += &format!("{} {} {} {} {} {} 7\n", p[0], p[1], p[2], n[0], n[1], n[2]);
    }
    for f in &faces {
        ascii += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    let mut binary = head("binary_little_endian").into_bytes();
    for (p, n) in verts.iter().zip(&normals) {
        for c in p.iter().chain(n) {
            binary.extend(c.to_le_bytes());
        }
        binary.push(7);
    }
    for f in &faces {
        binary.push(3);
        for v in f {
            binary.extend((*v as i32).to_le_bytes());
        }
    }
    for (name, bytes) in [("a.ply", ascii.into_bytes()), ("b.ply", binary)] {
        let m = load(&write(&dir, name, bytes), &LoadOptions::default()).unwrap();
        assert_eq!(m.normals.as_deref(), Some(&normals[..]), "{name}");
        assert_eq!(m.faces, faces, "{name}");
    }
}

#[test]
fn a_normal_without_direction_is_refused_naming_its_vertex() {
    let dir = scratch("zero-normal");
    // Vertex 4 is used by no face: its zero normal does not matter.
    let text =
        format!("{TETRA}v 5 5 5\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 0\nvn 0 0 0\n{TETRA_FACES}");
    let p = write(&dir, "t.obj", text);
    let e = load(&p, &LoadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("vertex 3") && e.contains("computed"), "{e}");
    assert!(load(&p, &opts(NormalsSource::Computed)).is_ok());
    let nan = format!("{TETRA}vn 0 0 1\nvn nan 0 1\nvn 0 0 1\nvn 0 0 1\n{TETRA_FACES}");
    let e = load(&write(&dir, "n.obj", nan), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertex 1"), "{e}");
}

#[test]
fn welding_sums_the_normals_of_the_merged_copies() {
    let m = Mesh {
        positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0; 3]],
        faces: vec![[0, 1, 2], [3, 2, 1]],
        normals: Some(vec![
            [1.0, 0.0, 0.0],
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
        ]),
    };
    let (w, remap) = m.weld();
    assert_eq!(remap, [0, 1, 2, 0]);
    assert_eq!(
        w.normals.unwrap(),
        [[1.0, 1.0, 0.0], [0.0; 3], [0.0, 0.0, 1.0]]
    );
}

/// A sphere whose stored normals lean away from the true ones by a smooth
/// field, so that they change the curvature measurably.
fn leaning_sphere() -> Mesh {
    let mut m = icosphere(1.0, 3);
    m.normals = Some(
        m.positions
            .iter()
            .map(|p| {
                let lean = [(3.0 * p[1]).sin(), (2.0 * p[2]).cos(), p[0].sin()];
                std::array::from_fn(|k| (p[k] + 0.15 * lean[k]) as f32)
            })
            .collect(),
    );
    m
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_device_starts_from_the_stored_normals_as_its_twin_does() {
    let gpu = common::gpu();
    let o = CurvatureOptions {
        precision: Precision::F32,
        ..CurvatureOptions::default()
    };
    let m = leaning_sphere();
    let dev = shapecue::stages::curvature::estimate(gpu.clone(), &m, o).unwrap();
    let (twin, _) = shapecue::cpu::curvature::estimate(&m, &o);
    for (name, a, b) in [
        ("k1", &dev.field.k1, &twin.k1),
        ("k2", &dev.field.k2, &twin.k2),
    ] {
        let d = max_diff(a, b);
        assert!(d < 1e-4, "{name}: device and twin differ by {d:.3e}");
    }
    // The stored normals matter: the same sphere without them is another
    // field, and with its true normals it is the unit sphere's.
    let mut plain = m.clone();
    plain.normals = None;
    let computed = shapecue::stages::curvature::estimate(gpu.clone(), &plain, o).unwrap();
    let d = max_diff(&dev.field.k1, &computed.field.k1);
    assert!(d > 0.05, "stored normals changed k1 by only {d:.3e}");
    let mut exact = m.clone();
    exact.normals = Some(m.positions.iter().map(|p| p.map(|c| c as f32)).collect());
    let unit = shapecue::stages::curvature::estimate(gpu, &exact, o).unwrap();
    for k in unit.field.k1.iter().chain(&unit.field.k2) {
        assert!((k - 1.0).abs() < 0.02, "true normals give curvature {k}");
    }
}

#[test]
fn lines_say_which_normals_they_used_and_computed_ignores_the_file() {
    let dir = scratch("lines-normals");
    let m = leaning_sphere();
    let n = m.normals.as_ref().unwrap();
    let mut with = common::obj_text(m.positions.iter().copied(), &m.faces);
    let without = with.clone();
    for v in n {
        with += &format!("vn {} {} {}\n", v[0], v[1], v[2]);
    }
    let with = write(&dir, "with.obj", with);
    let without = write(&dir, "without.obj", without);
    let run = |mesh: &std::path::Path, normals: &str, out: &str| {
        let (_, said) = common::succeeded(
            cli()
                .args([
                    "lines",
                    "--lines",
                    "contours,ridges,valleys",
                    "--normals",
                    normals,
                ])
                .arg(mesh)
                .arg("-o")
                .arg(dir.join(out)),
        );
        (said, std::fs::read(dir.join(out)).unwrap())
    };
    let (said, file) = run(&with, "file", "file.svg");
    assert!(said.contains("normals from the file"), "{said}");
    let (said, computed) = run(&with, "computed", "computed.svg");
    assert!(said.contains("normals from the faces"), "{said}");
    let (_, stripped) = run(&without, "file", "stripped.svg");
    assert_eq!(
        computed, stripped,
        "--normals computed must ignore the vn lines"
    );
    assert_ne!(file, computed, "the stored normals must change the drawing");
}

/// Isophotes and boundaries alone start from the curvature's normals, as
/// with any other family (rtsc's): the same rows either way.
#[test]
fn every_family_starts_from_the_same_normals() {
    let dir = scratch("same-normals");
    let spot = concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj");
    let rows = |lines: &str, out: &str| {
        let json = dir.join(out);
        let o = cli()
            .args(["lines", spot, "--lines", lines, "--eye", "3,1,2", "-o"])
            .arg(dir.join(format!("{out}.svg")))
            .arg("--segments")
            .arg(&json)
            .output()
            .unwrap();
        common::assert_succeeded(&o);
        let doc: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        let mut v: Vec<String> = doc["segments"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s["family"] == "isophotes")
            .map(|s| format!("{} {}", s["a"], s["b"]))
            .collect();
        v.sort();
        v
    };
    let alone = rows("isophotes", "alone.json");
    let with = rows("isophotes,contours", "with.json");
    assert!(!alone.is_empty());
    assert_eq!(alone, with);
}
