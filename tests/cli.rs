//! The command line: outputs, stats, refusals and error messages.

mod common;

use common::{cli, run_cli, scratch};

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

#[test]
fn devices_lists_the_cpu_device() {
    let out = run_cli(["devices"]);
    assert!(out.status.success());
    let s = String::from_utf8_lossy(&out.stdout);
    assert!(
        s.contains("fp64") && s.contains("gl_sharing") && s.contains("int64"),
        "{s}"
    );
    let out = run_cli(["devices", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v.as_array().is_some_and(|a| !a.is_empty()));
}

#[test]
fn curvature_writes_ply_with_the_documented_properties_and_stats() {
    let d = scratch("ply");
    let ply = d.join("sub/torus.ply");
    let json = d.join("torus.json");
    // The paper's scheme, whose passes are listed below.
    let stats = curvature_torus(&ply, &json, 2000, &["--accumulate", "atomic"]);
    let (names, values, faces) = shapecue::export::ply::read_ply_properties(&ply).unwrap();
    assert_eq!(
        names.join(" "),
        "x y z nx ny nz area k1 k2 d1x d1y d1z d2x d2y d2z dk0 dk1 dk2 dk3"
    );
    assert!(!faces.is_empty());
    // torus R=1 r=0.4: k1 = 2.5 everywhere
    assert!(values.iter().all(|v| (v[7] - 2.5).abs() < 0.1), "k1 off");
    for key in [
        "device",
        "passes",
        "kernel_ms",
        "device_bytes",
        "counts",
        "vertices",
        "faces",
    ] {
        assert!(stats.get(key).is_some(), "stats lack {key}: {stats}");
    }
    let passes: Vec<&str> = stats["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["pass"].as_str().unwrap())
        .collect();
    assert_eq!(
        passes,
        [
            "clear",
            "normals_areas",
            "frames",
            "tensor",
            "principal",
            "dcurv"
        ]
    );
    assert_eq!(stats["counts"]["degenerate_faces"], 0);
    // existing output is not overwritten without --force
    let out = cli()
        .args([
            "curvature",
            "--generate",
            "torus",
            "--resolution",
            "2000",
            "-o",
        ])
        .arg(&ply)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
}

#[test]
fn output_equal_to_input_is_refused_and_the_input_survives() {
    let d = scratch("same");
    let obj = d.join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let out = cli()
        .arg("curvature")
        .arg(&obj)
        .arg("-o")
        .arg(&obj)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("input file"));
    assert_eq!(std::fs::read_to_string(&obj).unwrap(), TETRA);
}

#[test]
fn bad_input_names_the_file_and_element() {
    let d = scratch("bad");
    let obj = d.join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let out = cli().arg("curvature").arg(&obj).output().unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("bad.obj") && e.contains("face"), "{e}");
    let out = run_cli(["curvature", "/nonexistent/x.ply"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/x.ply"));
    let out = run_cli([
        "--device",
        "no-such-device",
        "curvature",
        "--generate",
        "plane",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-device"));
}

#[test]
fn cpu_reference_and_every_variant_run_from_the_cli() {
    let d = scratch("variants");
    let obj = d.join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    for extra in [
        vec!["--cpu"],
        vec!["--accumulate", "gather"],
        vec!["--precision", "f64"],
        vec!["--compat", "trimesh2"],
        vec!["--no-dcurv"],
    ] {
        let out = cli()
            .arg("curvature")
            .arg(&obj)
            .args(&extra)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Runs `shapecue curvature` on a generated torus of about `resolution`
/// vertices with `extra` arguments, writing `ply` and the stats `json`;
/// checks it succeeded and returns the stats.
fn curvature_torus(
    ply: &std::path::Path,
    json: &std::path::Path,
    resolution: usize,
    extra: &[&str],
) -> serde_json::Value {
    let out = cli()
        .args(["curvature", "--generate", "torus", "--resolution"])
        .arg(resolution.to_string())
        .arg("-o")
        .arg(ply)
        .arg("--stats")
        .arg(json)
        .args(extra)
        .output()
        .unwrap();
    common::assert_succeeded(&out);
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

/// [`curvature_torus`] of about 3,000 vertices, writing `<name>.ply` and
/// `<name>.json` in `d`: the PLY's path and the stats.
fn curvature_torus_3000(
    d: &std::path::Path,
    name: &str,
    extra: &[&str],
) -> (std::path::PathBuf, serde_json::Value) {
    let ply = d.join(format!("{name}.ply"));
    let stats = curvature_torus(&ply, &d.join(format!("{name}.json")), 3000, extra);
    (ply, stats)
}

/// `--order`: a generated grid keeps its order under auto; spatial
/// renumbers it for the device and still writes the input's vertex order,
/// with the same curvature and directions to rounding.
#[test]
fn curvature_order_writes_the_input_order_whatever_order_it_computes_in() {
    let d = scratch("order");
    let run = |order: &str| {
        let (ply, stats) = curvature_torus_3000(&d, order, &["--order", order]);
        let (_, values, faces) = shapecue::export::ply::read_ply_properties(&ply).unwrap();
        (values, faces, stats)
    };
    let (auto, auto_faces, auto_stats) = run("auto");
    let (spatial, spatial_faces, spatial_stats) = run("spatial");
    assert_eq!(auto_stats["order"], "input", "a generated grid is local");
    assert_eq!(spatial_stats["order"], "spatial");
    assert!(spatial_stats["phases_ms"]["reorder"].as_f64().unwrap() >= 0.0);
    assert_eq!(auto_faces, spatial_faces, "faces are written as given");
    assert_eq!(auto.len(), spatial.len());
    for (i, (a, b)) in auto.iter().zip(&spatial).enumerate() {
        assert_eq!(a[..3], b[..3], "vertex {i}: positions in input order");
        for k in [7, 8] {
            assert!(
                (a[k] - b[k]).abs() < 1e-4 * (1.0 + a[k].abs()),
                "vertex {i}: k{}",
                k - 6
            );
        }
        let d1 = a[9] * b[9] + a[10] * b[10] + a[11] * b[11];
        assert!(
            d1 > 0.999,
            "vertex {i}: d1 {:?} vs {:?}",
            &a[9..12],
            &b[9..12]
        );
    }
    let out = cli()
        .args(["curvature", "--generate", "torus", "--order", "sideways"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("auto, input, spatial"));
}

#[test]
fn curvature_defaults_to_the_faster_exact_scheme_of_the_device() {
    // PoCL and Intel's runtime are CPU devices: gather, whose output is the
    // same bytes as --accumulate gather; --accumulate atomic still runs.
    let d = scratch("default-accumulate");
    let run = |extra: &[&str], name: &str| {
        let (ply, stats) = curvature_torus_3000(&d, name, extra);
        (std::fs::read(&ply).unwrap(), stats)
    };
    let (auto, stats) = run(&[], "auto");
    let kind = stats["device"]["kind"].as_str().unwrap().to_string();
    let want = if kind == "CPU" { "gather" } else { "atomic" };
    assert_eq!(stats["accumulate"], want, "on a {kind} device");
    if kind == "CPU" {
        assert!(auto == run(&["--accumulate", "gather"], "gather").0);
    }
    let (_, atomic) = run(&["--accumulate", "atomic"], "atomic");
    assert_eq!(atomic["accumulate"], "atomic");
}

#[test]
fn isosurface_writes_ply_with_curvature_normals_and_stats() {
    let d = scratch("iso");
    let ply = d.join("torus.ply");
    let json = d.join("torus.json");
    let out = cli()
        .args([
            "isosurface",
            "--sdf",
            "torus",
            "--resolution",
            "40",
            "--curvature",
            "--normals",
            "-o",
        ])
        .arg(&ply)
        .arg("--stats")
        .arg(&json)
        .output()
        .unwrap();
    common::assert_succeeded(&out);
    let (names, rows, faces) = shapecue::export::ply::read_ply_properties(&ply).unwrap();
    assert_eq!(names.len(), 19);
    assert!(!faces.is_empty());
    // Normals from the gradient are unit length and point outward.
    let outward = rows
        .iter()
        .filter(|r| {
            let (x, y) = (r[0] as f64, r[1] as f64);
            let rho = (x * x + y * y).sqrt();
            let c = [x / rho * 0.6, y / rho * 0.6, 0.0];
            let d = [r[0] as f64 - c[0], r[1] as f64 - c[1], r[2] as f64];
            d[0] * r[3] as f64 + d[1] * r[4] as f64 + d[2] * r[5] as f64 > 0.0
        })
        .count();
    assert_eq!(outward, rows.len());
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    assert_eq!(s["quality"]["boundary_edges"], 0);
    assert_eq!(s["quality"]["euler"], 0);
    // The default, direct numbering, makes no soup; its vertices are shared.
    assert_eq!(s["extraction"]["fusion"], "direct");
    assert_eq!(s["extraction"]["soup_vertices"], 0);
    assert!(
        3 * s["extraction"]["soup_triangles"].as_u64().unwrap()
            > 5 * s["extraction"]["vertices"].as_u64().unwrap()
    );
    assert!(
        s["curvature"]["passes"]
            .as_array()
            .is_some_and(|p| !p.is_empty())
    );
    // Refuses to overwrite without --force.
    let again = cli()
        .args(["isosurface", "--sdf", "torus", "--resolution", "20", "-o"])
        .arg(&ply)
        .output()
        .unwrap();
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
}

#[test]
fn isosurface_bad_input_is_a_clear_error() {
    let d = scratch("isobad");
    let raw = d.join("v.raw");
    std::fs::write(&raw, vec![0u8; 100]).unwrap();
    let run = |args: &[&str]| {
        let out = cli().arg("isosurface").args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} should fail");
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let r = raw.to_str().unwrap();
    let e = run(&[r, "--dims", "8,8,8", "--type", "u8", "--iso", "1"]);
    assert!(
        e.contains("v.raw") && e.contains("512") && e.contains("100"),
        "{e}"
    );
    let e = run(&[r, "--dims", "4,5,5", "--type", "q7", "--iso", "1"]);
    assert!(e.contains("q7"), "{e}");
    let e = run(&[r, "--dims", "4,5", "--type", "u8", "--iso", "1"]);
    assert!(e.contains("three"), "{e}");
    let e = run(&[r, "--dims", "4,5,5", "--type", "u8"]);
    assert!(e.contains("--iso"), "{e}");
    let e = run(&["--sdf", "cube"]);
    assert!(e.contains("cube"), "{e}");
    let e = run(&[d.join("missing.nhdr").to_str().unwrap(), "--iso", "1"]);
    assert!(e.contains("missing.nhdr"), "{e}");
    let e = run(&["--sdf", "sphere", "--iso", "NaN"]);
    assert!(e.to_lowercase().contains("iso"), "{e}");
}

#[test]
fn render_explains_plans_and_names_scene_errors() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/torus.toml");
    let out = run_cli(["render", scene, "--explain"]);
    common::assert_succeeded(&out);
    let s = String::from_utf8_lossy(&out.stdout);
    // Curvature colours + AO + contours + suggestive contours: dcurv runs,
    // feature edges do not; 4 orbit views.
    assert!(
        s.contains("dcurv") && s.contains(" ao ") && !s.contains(" edges "),
        "{s}"
    );
    assert!(s.contains("1 frame(s) × 4 view(s)"), "{s}");
    // Plain words, not the program's internal names.
    assert!(
        s.contains("input: static mesh; cues: curvature_colors, ao"),
        "{s}"
    );
    for internal in ["Static", "CurvatureColors", "VertexNormals", "[", "Lut"] {
        assert!(!s.contains(internal), "{internal} in {s}");
    }
    let d = scratch("render-bad");
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        "[input]\ngenerate = \"torus\"\n[effects]\nshadows = {}\n",
    )
    .unwrap();
    let out = cli().args(["render"]).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("bad.toml") && e.contains("line 4") && e.contains("shadows"),
        "{e}"
    );
    // A missing scene file is named.
    let out = run_cli(["render", "no/such/scene.toml"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("no/such/scene.toml"));
}

#[test]
fn a_hard_link_to_the_input_is_refused_even_with_force() {
    let d = scratch("hardlink");
    let obj = d.join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let link = d.join("hard.ply");
    std::fs::hard_link(&obj, &link).unwrap();
    let out = cli()
        .arg("curvature")
        .arg(&obj)
        .arg("-o")
        .arg(&link)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("input file") && e.contains("another name"),
        "{e}"
    );
    assert_eq!(std::fs::read_to_string(&obj).unwrap(), TETRA);
}

#[test]
fn stats_equal_to_the_output_is_refused() {
    let d = scratch("stats-is-output");
    let ply = d.join("o.ply");
    let out = cli()
        .args([
            "curvature",
            "--generate",
            "plane",
            "--resolution",
            "100",
            "-o",
        ])
        .arg(&ply)
        .arg("--stats")
        .arg(&ply)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("same output file"), "{e}");
    assert!(!ply.exists());
}

/// A 4³ u8 volume as a detached NRRD header `v.nhdr` and its data file
/// `v.raw` in `d`: (header, data file).
fn tiny_nhdr(d: &std::path::Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let raw = d.join("v.raw");
    std::fs::write(&raw, (0..64u8).collect::<Vec<_>>()).unwrap();
    let nhdr = d.join("v.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\ndata file: v.raw\n",
    )
    .unwrap();
    (nhdr, raw)
}

#[test]
fn a_volume_data_file_is_an_input() {
    let d = scratch("nhdr-data");
    let (nhdr, raw) = tiny_nhdr(&d);
    let out = cli()
        .arg("isosurface")
        .arg(&nhdr)
        .args(["--iso", "30", "-o"])
        .arg(&raw)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("input file"), "{e}");
    assert_eq!(std::fs::read(&raw).unwrap().len(), 64);
}

/// Runs the CLI with its standard output closed before it writes (as
/// `| head -1` closes it after a line) and returns the exit status and stderr.
fn with_closed_stdout(args: &[&str]) -> (std::process::ExitStatus, String) {
    use std::io::Read;
    let mut child = cli()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (child.wait().unwrap(), err)
}

#[test]
fn a_closed_stdout_ends_quietly_with_status_0() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/torus.toml");
    for args in [
        vec!["render", scene, "--explain"],
        vec!["edges", "--memory-table"],
        vec!["devices"],
    ] {
        let (status, err) = with_closed_stdout(&args);
        assert_eq!(status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn a_missing_input_is_named_once_with_the_os_message_once() {
    let out = run_cli(["curvature", "/nonexistent/x.ply"]);
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(e.matches("/nonexistent/x.ply").count(), 1, "{e}");
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
}

/// Signed volume of a closed triangle mesh (positive when faces point out).
fn signed_volume(pos: &[Vec<f32>], faces: &[[u32; 3]]) -> f64 {
    let p = |i: u32| {
        let v = &pos[i as usize];
        [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])]
    };
    faces
        .iter()
        .map(|f| {
            let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// A density volume (a ball of high values, as CT and MRI data are) gives
/// outward faces by default (inside = above for volume files), and convex
/// (positive) mean curvature; `--inside below` turns it inside out. An iso
/// value outside the data is an error giving the data's range.
#[test]
fn density_volumes_are_outward_by_default_and_iso_outside_the_data_is_an_error() {
    let d = scratch("density-ball");
    let n = 24usize;
    let mut bytes = Vec::with_capacity(n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let c = |i: usize| i as f64 - 11.5;
                let r = (c(x).powi(2) + c(y).powi(2) + c(z).powi(2)).sqrt();
                bytes.push((255.0 * (1.0 - r / 12.0).clamp(0.0, 1.0)) as u8);
            }
        }
    }
    let raw = d.join("ball.raw");
    std::fs::write(&raw, &bytes).unwrap();
    let run = |out: &str, extra: &[&str]| {
        let o = cli()
            .arg("isosurface")
            .arg(&raw)
            .args([
                "--dims",
                "24,24,24",
                "--type",
                "u8",
                "--iso",
                "128",
                "--curvature",
                "-o",
            ])
            .arg(d.join(out))
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (names, rows, faces) =
            shapecue::export::ply::read_ply_properties(&d.join(out)).unwrap();
        let k1 = names.iter().position(|n| n == "k1").unwrap();
        let k2 = names.iter().position(|n| n == "k2").unwrap();
        let h: f64 = rows
            .iter()
            .map(|r| 0.5 * f64::from(r[k1] + r[k2]))
            .sum::<f64>()
            / rows.len() as f64;
        (signed_volume(&rows, &faces), h)
    };
    let (vol, h) = run("out.ply", &[]);
    assert!(vol > 0.0 && h > 0.0, "default: volume {vol}, mean H {h}");
    let (vol, h) = run("in.ply", &["--inside", "below"]);
    assert!(
        vol < 0.0 && h < 0.0,
        "inside below: volume {vol}, mean H {h}"
    );

    let o = cli()
        .arg("isosurface")
        .arg(&raw)
        .args(["--dims", "24,24,24", "--type", "u8", "--iso", "300", "-o"])
        .arg(d.join("none.ply"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("empty") && e.contains("0 to 236"), "{e}");
    assert!(!d.join("none.ply").exists());
}

/// Sizes are checked before anything is allocated: the error names the
/// option, the bytes implied and the limit, at once (these aborted after
/// trying to allocate, or ran for seconds first).
#[test]
fn sizes_are_checked_before_allocating() {
    let d = scratch("sizes");
    let run = |args: &[&str]| {
        let t = std::time::Instant::now();
        let o = cli().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} should fail");
        assert_eq!(
            o.status.code(),
            Some(1),
            "{args:?}: a clear error, not an abort"
        );
        assert!(
            t.elapsed().as_secs() < 20,
            "{args:?} took {:?}",
            t.elapsed()
        );
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let out = d.join("o.ply");
    let o = out.to_str().unwrap();
    let e = run(&[
        "isosurface",
        "--sdf",
        "sphere",
        "--resolution",
        "100000",
        "-o",
        o,
    ]);
    assert!(
        e.contains("--resolution") && e.contains("GiB") && e.contains("1024"),
        "{e}"
    );
    let e = run(&[
        "isosurface",
        "--sdf",
        "sphere",
        "--resolution",
        "0",
        "-o",
        o,
    ]);
    assert!(
        e.contains("--resolution") && e.contains("at least 2"),
        "{e}"
    );
    let e = run(&[
        "curvature",
        "--generate",
        "plane",
        "--resolution",
        "100000000000",
        "-o",
        o,
    ]);
    assert!(e.contains("--resolution") && e.contains("50000000"), "{e}");
    let e = run(&[
        "curvature",
        "--generate",
        "torus",
        "--runs",
        "0",
        "--report",
    ]);
    assert!(e.contains("--runs"), "{e}");
    let e = run(&["edges", "missing.obj", "--size", "0x10", "-o", o]);
    assert!(e.contains("--size"), "{e}");
    assert!(!out.exists());
}

/// `shapecue strokes` end to end: a procedural field and a mesh (turned
/// into a signed distance field first) give a PNG, an SVG, the strip PLY
/// and stats; a closed stdout stays quiet.
#[test]
fn strokes_from_a_field_and_from_a_mesh() {
    let d = scratch("strokes");
    let mesh = d.join("ball.ply");
    let written = shapecue::export::ply::write_ply(&mesh, &shapecue::mesh::icosphere(0.5, 3), None);
    assert_eq!(written.unwrap().double, None);
    for (input, tag) in [
        (vec!["--sdf".to_string(), "torus".to_string()], "torus"),
        (vec![mesh.display().to_string()], "mesh"),
    ] {
        let png = d.join(format!("{tag}.png"));
        let stats = d.join(format!("{tag}.json"));
        let o = cli()
            .arg("strokes")
            .args(&input)
            .args([
                "--resolution",
                "48",
                "--size",
                "200x200",
                "--seed-spacing",
                "0.08",
                "-o",
            ])
            .arg(&png)
            .arg("--svg")
            .arg(d.join(format!("{tag}.svg")))
            .arg("--geometry")
            .arg(d.join(format!("{tag}-strips.ply")))
            .arg("--stats")
            .arg(&stats)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{tag}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(png.exists() && d.join(format!("{tag}.svg")).exists());
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
        assert!(s["seeds"].as_u64().unwrap() > 0, "{tag}: {s}");
    }
    let (status, err) = with_closed_stdout(&[
        "strokes",
        "--sdf",
        "sphere",
        "--resolution",
        "32",
        "-o",
        d.join("quiet.png").to_str().unwrap(),
    ]);
    assert!(status.success(), "{err}");
}

/// An image name that is not `.png` is refused (the bytes would be PNG), a
/// width past the image is refused, and `--report` refuses an input or an
/// output it would ignore.
#[test]
fn jpeg_names_huge_widths_and_report_with_inputs_are_refused() {
    let d = scratch("refusals");
    let run = |args: &[&str]| {
        let o = cli().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} should fail");
        String::from_utf8_lossy(&o.stderr).to_string()
    };
    let jpg = d.join("o.jpg");
    let j = jpg.to_str().unwrap();
    let e = run(&["strokes", "--sdf", "sphere", "--resolution", "16", "-o", j]);
    assert!(e.contains(".png"), "{e}");
    let e = run(&["edges", "missing.obj", "-o", j]);
    assert!(e.contains(".png"), "{e}");
    assert!(!jpg.exists());
    let e = run(&["edges", "missing.obj", "--width", "1e30", "-o", "x.png"]);
    assert!(e.contains("--width") && e.contains("at most"), "{e}");
    let e = run(&["curvature", "some.obj", "--report"]);
    assert!(e.contains("--report"), "{e}");
    let e = run(&["isosurface", "--report", "-o", "x.ply"]);
    assert!(e.contains("--report"), "{e}");
}

/// `shapecue strokes` protects a volume's detached data file like the
/// isosurface command does, and checks outputs before any conversion.
#[test]
fn strokes_never_writes_over_a_volume_data_file() {
    let d = scratch("strokes-nhdr");
    let (nhdr, raw) = tiny_nhdr(&d);
    let out = cli()
        .arg("strokes")
        .arg(&nhdr)
        .args(["--iso", "30", "-o"])
        .arg(d.join("s.png"))
        .arg("--stats")
        .arg(&raw)
        .arg("--force")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("input file"), "{e}");
    assert_eq!(std::fs::read(&raw).unwrap(), (0..64u8).collect::<Vec<_>>());
}

#[test]
fn render_refuses_two_scenes_writing_the_same_files_before_either_runs() {
    let d = scratch("render-collide");
    let text = "[input]\ngenerate = \"torus\"\nresolution = 2000\n[[camera]]\norbit = 1\n\
                [effects]\nshading = {}\n[output]\nname = \"same\"\nsize = [32, 32]\n";
    let (a, b) = (d.join("a.toml"), d.join("b.toml"));
    std::fs::write(&a, text).unwrap();
    std::fs::write(&b, text).unwrap();
    let out = d.join("out");
    let r = run_cli([
        "render",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("a.toml") && err.contains("b.toml") && err.contains("same_report.json"),
        "{err}"
    );
    assert!(!out.exists(), "nothing ran, nothing was written");
    let _ = std::fs::remove_dir_all(&d);
}

/// Three scenes whose third is a flipbook with a frame of another
/// topology: the run fails before the first scene renders, naming the
/// scene file, the frame and its file, and writes nothing; with the frame
/// repaired, all three render, the flipbook from the input the check loaded.
#[test]
fn render_checks_the_third_scene_s_flipbook_before_the_first_runs() {
    let d = scratch("render-flipbook-check");
    let frames = d.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let m = shapecue::mesh::icosphere(1.0, 1);
    for f in 0..3 {
        let s = 1.0 + 0.1 * f as f64;
        let pos = m.positions.iter().map(|p| p.map(|c| c * s));
        std::fs::write(
            frames.join(format!("f_{f}.obj")),
            common::obj_text(pos, &m.faces),
        )
        .unwrap();
    }
    let fine = |name: &str| {
        format!(
            "[input]\ngenerate = \"sphere\"\nresolution = 50\n[effects]\nshading = {{}}\n\
             [output]\nname = \"{name}\"\nsize = [16, 16]\n"
        )
    };
    let paths: Vec<std::path::PathBuf> = ["a", "b", "c"]
        .iter()
        .map(|n| d.join(format!("{n}.toml")))
        .collect();
    std::fs::write(&paths[0], fine("a")).unwrap();
    std::fs::write(&paths[1], fine("b")).unwrap();
    std::fs::write(
        &paths[2],
        "[input]\nflipbook = \"frames/f_*.obj\"\n[effects]\nshading = {}\n\
         [output]\nname = \"c\"\nsize = [16, 16]\n",
    )
    .unwrap();
    let other = shapecue::mesh::icosphere(1.0, 2);
    std::fs::write(
        frames.join("f_2.obj"),
        common::obj_text(other.positions.iter().copied(), &other.faces),
    )
    .unwrap();
    let out = d.join("out");
    let args = |extra: &[&str]| {
        let mut v: Vec<String> = vec!["render".into()];
        v.extend(paths.iter().map(|p| p.display().to_string()));
        v.extend(["--out".into(), out.display().to_string()]);
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let r = run_cli(args(&[]));
    assert!(!r.status.success());
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("c.toml")
            && err.contains("flipbook frame 2")
            && err.contains("f_2.obj")
            && err.contains("vertices"),
        "{err}"
    );
    assert!(!out.exists(), "nothing ran, nothing was written");

    let s = 1.2;
    let pos = m.positions.iter().map(|p| p.map(|c| c * s));
    std::fs::write(frames.join("f_2.obj"), common::obj_text(pos, &m.faces)).unwrap();
    let r = run_cli(args(&[]));
    if common::cli_gl_missing(&r) {
        let _ = std::fs::remove_dir_all(&d);
        return;
    }
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    for f in [
        "a_report.json",
        "b_report.json",
        "c_f0002_v00.png",
        "c_report.json",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn meshes_too_large_or_small_to_draw_in_single_precision_are_refused_by_name() {
    // A unit sphere scaled by 1e30 and by 1e-30: curvature works on both (it
    // normalises); drawing refuses them with the range instead of a camera
    // of infinities.
    let d = scratch("undrawable");
    for (scale, word) in [(1e30, "below"), (1e-30, "at least")] {
        let m = shapecue::mesh::icosphere(1.0, 2);
        let scaled = m.positions.iter().map(|p| p.map(|c| c * scale));
        let obj = common::obj_text(scaled, &m.faces);
        let path = d.join(format!("s{scale:e}.obj"));
        std::fs::write(&path, obj).unwrap();
        let png = d.join("x.png");
        let r = run_cli([
            "edges",
            path.to_str().unwrap(),
            "--eye",
            &format!("{:e},{:e},{:e}", 3.0 * scale, 2.0 * scale, scale),
            "-o",
            png.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{err}");
        assert!(err.contains("rescale") && err.contains(word), "{err}");
        assert!(!err.contains("Vec3") && !err.contains("Camera {"), "{err}");
        assert!(!png.exists());
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Runs `shapecue curvature` on a small generated sphere (gather variant:
/// bitwise reproducible) with the program cache in `cache` (or off), and
/// returns the stats and the PLY bytes.
fn curvature_cached(
    cache: Option<&std::path::Path>,
    out_dir: &std::path::Path,
    tag: &str,
    extra: &[&str],
) -> (serde_json::Value, Vec<u8>) {
    curvature_cached_saving(cache, out_dir, tag, extra, true)
}

/// [`curvature_cached`], with saving on PoCL (`SHAPECUE_CACHE_POCL=1`) or
/// as an ordinary user runs it (`save_on_pocl` false).
fn curvature_cached_saving(
    cache: Option<&std::path::Path>,
    out_dir: &std::path::Path,
    tag: &str,
    extra: &[&str],
    save_on_pocl: bool,
) -> (serde_json::Value, Vec<u8>) {
    let (ply, json) = (
        out_dir.join(format!("{tag}.ply")),
        out_dir.join(format!("{tag}.json")),
    );
    let mut cmd = cli();
    cmd.args([
        "curvature",
        "--generate",
        "sphere",
        "--resolution",
        "800",
        "--accumulate",
        "gather",
        "-o",
    ])
    .arg(&ply)
    .arg("--stats")
    .arg(&json)
    .args(extra);
    match cache {
        Some(dir) => cmd
            .env("SHAPECUE_CACHE_DIR", dir)
            .env("SHAPECUE_CACHE_POCL", if save_on_pocl { "1" } else { "0" })
            .env_remove("SHAPECUE_NO_CACHE"),
        None => cmd.env("SHAPECUE_NO_CACHE", "1"),
    };
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{tag}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stats = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (stats, std::fs::read(&ply).unwrap())
}

fn cache_outcome(stats: &serde_json::Value) -> String {
    let p = stats["programs"].as_array().expect("stats list programs");
    assert_eq!(p.len(), 1, "{stats}");
    p[0]["cache"].as_str().unwrap().to_string()
}

fn cache_entries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

fn clbin_entries(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    cache_entries(dir)
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "clbin"))
        .collect()
}

/// The program-binary cache: a miss builds from source and saves one entry,
/// the next process builds from it; a corrupt or truncated entry is
/// detected, rebuilt from source and rewritten, never an error; the output
/// is the same bytes every time; `SHAPECUE_NO_CACHE=1` turns it off.
#[test]
fn program_cache_hits_and_survives_corrupt_and_truncated_files() {
    let d = scratch("progcache");
    let cache = d.join("cache");
    // The first build from source saves the binary (on PoCL only with
    // SHAPECUE_CACHE_POCL=1, which `curvature_cached` sets).
    let (s, reference) = curvature_cached(Some(&cache), &d, "first", &[]);
    assert_eq!(cache_outcome(&s), "miss");
    assert_eq!(s["programs"][0]["saved"], true, "{s}");
    let entries = cache_entries(&cache);
    assert_eq!(entries.len(), 1, "{entries:?}");
    assert!(entries[0].extension().is_some_and(|e| e == "clbin"));
    let (s, ply) = curvature_cached(Some(&cache), &d, "hit", &[]);
    assert_eq!(cache_outcome(&s), "hit");
    assert_eq!(s["programs"][0]["saved"], false);
    assert_eq!(ply, reference, "output from the cached binary differs");

    let good = std::fs::read(&entries[0]).unwrap();
    // One flipped byte in the driver's binary: the checksum catches it.
    let mut bad = good.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x5a;
    std::fs::write(&entries[0], &bad).unwrap();
    let (s, ply) = curvature_cached(Some(&cache), &d, "corrupt", &[]);
    let why = cache_outcome(&s);
    assert!(
        why.starts_with("rejected") && why.contains("checksum"),
        "{why}"
    );
    assert_eq!(ply, reference);
    assert_eq!(
        cache_outcome(&curvature_cached(Some(&cache), &d, "rewritten", &[]).0),
        "hit"
    );

    // Cut short (a crash mid-write of a cache that did not write atomically).
    std::fs::write(&entries[0], &good[..good.len() / 3]).unwrap();
    let (s, ply) = curvature_cached(Some(&cache), &d, "truncated", &[]);
    let why = cache_outcome(&s);
    assert!(
        why.starts_with("rejected") && why.contains("truncated"),
        "{why}"
    );
    assert_eq!(ply, reference);
    // Shorter than the header, and not a cache file at all.
    let junk = [
        &b"SCCL"[..],
        &b"not a cache file, but long enough to hold a header"[..],
    ];
    for (i, junk) in junk.into_iter().enumerate() {
        std::fs::write(&entries[0], junk).unwrap();
        let (s, ply) = curvature_cached(Some(&cache), &d, &format!("junk{i}"), &[]);
        assert!(cache_outcome(&s).starts_with("rejected"), "{s}");
        assert_eq!(ply, reference);
    }
    assert_eq!(
        cache_outcome(&curvature_cached(Some(&cache), &d, "again", &[]).0),
        "hit"
    );
    assert_eq!(
        cache_entries(&cache).len(),
        1,
        "one entry, no temporary files"
    );

    let (s, ply) = curvature_cached(None, &d, "off", &[]);
    assert_eq!(cache_outcome(&s), "off");
    assert_eq!(ply, reference);

    // A cache folder that cannot be created (a file is in the way): built
    // from source, no error.
    let blocked = d.join("a-file");
    std::fs::write(&blocked, b"x").unwrap();
    let (s, ply) = curvature_cached(Some(&blocked.join("cache")), &d, "blocked", &[]);
    assert!(cache_outcome(&s).starts_with("rejected") || cache_outcome(&s) == "miss");
    assert_eq!(ply, reference);
}

/// `shapecue build-kernels` saves the gather program on every runtime
/// (PoCL included, where an ordinary run does not save), says so, and finds
/// it built the second time; a `curvature` process then loads it from the
/// cache and writes the same bytes as one with the cache off. With the
/// cache off it is an error that says why.
#[test]
fn build_kernels_fills_the_cache_that_curvature_then_loads() {
    let d = scratch("build-kernels");
    let cache = d.join("cache");
    let build = |cache_env: Option<&std::path::Path>| {
        let mut cmd = cli();
        cmd.args(["build-kernels", "--accumulate", "gather"])
            .env_remove("SHAPECUE_CACHE_POCL");
        match cache_env {
            Some(dir) => cmd
                .env("SHAPECUE_CACHE_DIR", dir)
                .env_remove("SHAPECUE_NO_CACHE"),
            None => cmd.env("SHAPECUE_NO_CACHE", "1"),
        };
        cmd.output().unwrap()
    };
    let (_, reference) = curvature_cached(None, &d, "reference", &[]);
    // An ordinary run on an empty cache saves nothing on PoCL; elsewhere
    // it saves, and build-kernels then finds the program built.
    let (s, ply) = curvature_cached_saving(Some(&cache), &d, "plain", &[], false);
    assert_eq!(ply, reference);
    let pocl = s["device"]["platform"]
        .as_str()
        .is_some_and(|p| p.contains("Portable Computing Language"));
    if pocl {
        assert_eq!(cache_outcome(&s), "miss");
        assert_eq!(s["programs"][0]["saved"], false, "{s}");
        assert!(clbin_entries(&cache).is_empty());
    }
    let _ = std::fs::remove_dir_all(&cache);

    let out = build(Some(&cache));
    common::assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("gather f32 exact") && text.contains("saved in"),
        "{text}"
    );
    assert_eq!(clbin_entries(&cache).len(), 1, "{text}");
    let out = build(Some(&cache));
    common::assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("already built"), "{text}");
    assert_eq!(clbin_entries(&cache).len(), 1);

    let (s, ply) = curvature_cached_saving(Some(&cache), &d, "after", &[], false);
    assert_eq!(cache_outcome(&s), "hit", "{s}");
    assert_eq!(ply, reference, "output from the built kernels differs");

    let out = build(None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("kernel cache is off"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// Processes started together on an empty cache all succeed with the same
/// output, and leave one valid entry that the next process uses.
#[test]
fn concurrent_processes_share_the_program_cache() {
    let d = scratch("progcache-race");
    let cache = d.join("cache");
    let (_, reference) = curvature_cached(None, &d, "reference", &[]);
    let plys: Vec<Vec<u8>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|i| {
                let (cache, d) = (&cache, &d);
                s.spawn(move || curvature_cached(Some(cache), d, &format!("racer{i}"), &[]).1)
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for p in &plys {
        assert_eq!(p, &reference);
    }
    // Each racer saw no entry and saved the same bytes (renamed into place).
    // Within two more processes the entry is there, one file, no leftovers.
    let mut outcomes = Vec::new();
    for i in 0..3 {
        let (s, ply) = curvature_cached(Some(&cache), &d, &format!("after{i}"), &[]);
        assert_eq!(ply, reference);
        outcomes.push(cache_outcome(&s));
        if outcomes.last().is_some_and(|o| o == "hit") {
            break;
        }
    }
    assert_eq!(
        outcomes.last().map(String::as_str),
        Some("hit"),
        "{outcomes:?}"
    );
    let entries = cache_entries(&cache);
    assert_eq!(entries.len(), 1, "{entries:?}");
    assert_eq!(clbin_entries(&cache), entries);
}

/// `--runs N`: the output is written once and is the same as without it;
/// the stats give the count, kernel and wall medians and one median per
/// pass, in the order of `passes`; `--runs 0` is refused.
#[test]
fn curvature_runs_times_the_device_passes() {
    let d = scratch("runs");
    let (plain, reference) = curvature_cached(None, &d, "plain", &[]);
    for key in ["phases_ms", "command_ms", "programs"] {
        assert!(plain.get(key).is_some(), "stats lack {key}: {plain}");
    }
    for phase in [
        "load",
        "device",
        "program_prepare",
        "device_wait",
        "program_build",
        "topology",
        "normalise",
        "upload",
        "first_run",
        "read_back",
        "cache_write",
        "ply_write",
    ] {
        assert!(
            plain["phases_ms"][phase].as_f64().is_some_and(|v| v >= 0.0),
            "phase {phase}: {plain}"
        );
    }
    assert!(plain.get("kernel_median_ms").is_none());
    let (s, ply) = curvature_cached(None, &d, "runs", &["--runs", "3"]);
    assert_eq!(ply, reference, "--runs changed the output");
    assert_eq!(s["runs"], 3);
    for key in [
        "kernel_median_ms",
        "wall_median_ms",
        "kernel_min_ms",
        "wall_min_ms",
    ] {
        assert!(s[key].as_f64().is_some_and(|v| v > 0.0), "{key}: {s}");
    }
    assert!(s["kernel_min_ms"].as_f64() <= s["kernel_median_ms"].as_f64());
    let names = |k: &str| -> Vec<String> {
        s[k].as_array()
            .unwrap()
            .iter()
            .map(|p| p["pass"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(names("passes_median"), names("passes"));
    let out = run_cli(["curvature", "--generate", "sphere", "--runs", "0"]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--runs") && e.contains("1..="), "{e}");
    // The CPU reference times its runs too.
    let (s, _) = curvature_cached(None, &d, "cpu", &["--cpu", "--runs", "2"]);
    assert_eq!(s["runs"], 2);
    assert!(s["wall_median_ms"].as_f64().is_some_and(|v| v > 0.0), "{s}");
}

/// Faults: a write that fails midway (a full disk, simulated with a file
/// size limit, so the write fails with an OS error after the file was
/// opened), a device output, an output whose folder cannot exist, and a
/// device too small for the mesh (`SHAPECUE_DEVICE_MEMORY`): each a clear
/// error naming the file or the bytes, and nothing left behind.
#[test]
fn full_disks_bad_folders_and_small_devices_give_clear_errors_and_leave_nothing() {
    let d = scratch("faults");
    let exe = env!("CARGO_BIN_EXE_shapecue");
    // 16 KiB per file: the PLY of a 10,242-vertex sphere is ~1 MB. The CPU
    // reference computes it, because the limit binds every file the process
    // writes, and PoCL writes the kernel source (~56 KB) to its cache folder
    // when it builds the program, warm cache or not; the PLY writer is the
    // same for both.
    let ply = d.join("o.ply");
    let out = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -f 16; trap '' XFSZ; exec '{exe}' curvature --cpu --generate sphere \
             --resolution 20000 -o '{}'",
            ply.display()
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("o.ply") && err.contains("cannot write"),
        "{err}"
    );
    let left: Vec<_> = std::fs::read_dir(&d).unwrap().collect();
    assert!(left.is_empty(), "nothing left behind: {left:?}");

    let r = run_cli(["curvature", "--generate", "sphere", "-o", "/dev/full"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("/dev/full") && err.contains("not a regular file"),
        "{err}"
    );

    let blocker = d.join("a-file");
    std::fs::write(&blocker, "mine").unwrap();
    let inside = blocker.join("o.ply");
    let r = run_cli([
        "curvature",
        "--generate",
        "sphere",
        "-o",
        inside.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("a-file") && err.contains("not a folder"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&blocker).unwrap(), "mine");

    let small = cli()
        .env("SHAPECUE_DEVICE_MEMORY", "1M")
        .args([
            "curvature",
            "--generate",
            "sphere",
            "--resolution",
            "100000",
            "-o",
        ])
        .arg(&ply)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&small.stderr);
    assert!(!small.status.success());
    assert!(
        err.contains("bytes") && err.contains("1048576") && err.contains("SHAPECUE_DEVICE_MEMORY"),
        "{err}"
    );
    assert!(!ply.exists());
    let bad = cli()
        .env("SHAPECUE_DEVICE_MEMORY", "lots")
        .args(["curvature", "--generate", "sphere", "-o"])
        .arg(&ply)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("SHAPECUE_DEVICE_MEMORY"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// `curvature --report` has a row for every variant the library compares,
/// in order; a variant the device cannot run (native float atomics where the
/// device has no float atomic add) is a row saying why, and the table goes on.
#[test]
fn curvature_report_has_a_row_for_every_variant() {
    let out = run_cli([
        "curvature",
        "--report",
        "--resolution",
        "5000",
        "--runs",
        "1",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    common::assert_succeeded(&out);
    let rows: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("| variant |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .collect();
    let variants = shapecue::metrics::variants();
    assert_eq!(
        rows.len(),
        variants.len() + 1,
        "variants and the CPU reference: {text}"
    );
    let info = common::gpu().info.clone();
    for (row, o) in rows.iter().zip(&variants) {
        let label = shapecue::metrics::label(o);
        assert!(row.starts_with(&format!("| {label} |")), "{row}");
        use shapecue::spec::curvature::{Accumulate, Precision};
        let f64 = o.precision == Precision::F64;
        let (native, atomic) = (
            o.accumulate == Accumulate::AtomicNative,
            o.accumulate == Accumulate::Atomic,
        );
        let expected = (native && !info.float_atomics)
            || (f64 && !info.fp64)
            || (f64 && atomic && !info.int64_atomics);
        assert_eq!(row.contains("not on this device"), expected, "{row}");
        if native && expected && !f64 {
            assert!(row.contains("cl_ext_float_atomics"), "{row}");
        }
    }
    assert!(
        rows.last().unwrap().starts_with("| cpu reference"),
        "{text}"
    );
}

/// The device is opened, and the curvature program built, beside the mesh's
/// load: a device that does not exist is still a clear error naming it,
/// with no output written, and an input that cannot be read is reported
/// first, as it was when the device was opened after the load.
#[test]
fn curvature_device_errors_beside_the_load() {
    let d = scratch("device-beside-load");
    let out = d.join("out.ply");
    let o = run_cli([
        "--device".as_ref(),
        "no-such-device".as_ref(),
        "curvature".as_ref(),
        "--generate".as_ref(),
        "sphere".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("'no-such-device'"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    let o = run_cli([
        "--device".as_ref(),
        "no-such-device".as_ref(),
        "curvature".as_ref(),
        d.join("missing.obj").as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("missing.obj") && !err.contains("no-such-device"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
}
