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
    let passes = pass_names(&stats["passes"]);
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

/// The `pass` of each entry of a `--stats` list of passes, in order.
fn pass_names(list: &serde_json::Value) -> Vec<&str> {
    list.as_array()
        .expect("a list of passes")
        .iter()
        .map(|p| p["pass"].as_str().expect("a pass name"))
        .collect()
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
        vec!["report", "memory"],
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
    // --resolution is the older name of --vertices (both spellings work).
    assert!(e.contains("--vertices") && e.contains("50000000"), "{e}");
    let e = run(&["report", "curvature", "--runs", "0"]);
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

/// `isosurface --runs N`: N more extractions through the library's call
/// after the one written; the stats give their count and medians, per pass
/// too, and the summary says so.
#[test]
fn isosurface_runs_time_the_extraction() {
    let d = scratch("iso-runs");
    let stats = d.join("s.json");
    let out = run_cli([
        "isosurface",
        "--sdf",
        "sphere",
        "--resolution",
        "16",
        "--curvature",
        "--runs",
        "2",
        "--stats",
        stats.to_str().unwrap(),
    ]);
    common::assert_succeeded(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("2 timed extractions: median"), "{text}");
    let s: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(s["runs"], 2, "{s}");
    assert!(s["kernel_median_ms"].as_f64().unwrap() > 0.0, "{s}");
    assert!(!s["passes_median"].as_array().unwrap().is_empty(), "{s}");
    // The gyroid at 16³ has exact hits, so the scan runs twice: one entry
    // per pass all the same, with the time of all its runs.
    let out = run_cli([
        "isosurface",
        "--sdf",
        "gyroid",
        "--resolution",
        "16",
        "--runs",
        "2",
        "--stats",
        d.join("g.json").to_str().unwrap(),
        "-o",
        d.join("g.ply").to_str().unwrap(),
    ]);
    common::assert_succeeded(&out);
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("g.json")).unwrap()).unwrap();
    assert!(s["extraction"]["exact_hits"].as_u64().unwrap() > 0, "{s}");
    let names = pass_names(&s["passes_median"]);
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "{names:?}");
    assert!(names.contains(&"scan_exclusive"), "{names:?}");
}
