//! Many views of one mesh in one run: the Fibonacci camera set, camera
//! files, and `shapecue lines MESH --views N | --cameras FILE --out DIR`
//! with no OpenGL (`__EGL_VENDOR_LIBRARY_DIRS` at an empty folder): an SVG,
//! a segments document per view, the manifest, and the executor's report
//! showing the pose passes ran once and the view passes once per view.

mod common;

use common::{assert_succeeded, cli_no_gl, scratch};
use serde_json::Value;
use shapecue::api::{
    CameraDefaults, CameraKind, LinesPictureOptions, fibonacci_directions, fibonacci_views,
    lines_views_scene, output_paths, parse_camera_file,
};
use shapecue::spec::cameras::ideal_spacing;
use std::path::Path;
use std::process::Output;

/// The command with no EGL vendor to load.
fn no_gl(dir: &Path, args: &[&str]) -> Output {
    cli_no_gl(dir).args(args).output().unwrap()
}

fn ok(out: &Output) {
    assert_succeeded(out);
}

fn failed_with(out: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "should have failed: {err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in: {err}");
    }
}

fn spot() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/data/spot.obj").to_string()
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn angle(a: [f32; 3], b: [f32; 3]) -> f64 {
    let d: f64 = (0..3).map(|i| f64::from(a[i]) * f64::from(b[i])).sum();
    d.clamp(-1.0, 1.0).acos()
}

#[test]
fn fibonacci_directions_are_unit_distinct_and_spread() {
    let n = 64;
    let d = fibonacci_directions(n);
    assert_eq!(d.len(), n);
    assert_eq!(d, fibonacci_directions(n), "deterministic");
    for v in &d {
        let len = v.iter().map(|x| x * x).sum::<f32>().sqrt();
        assert!((len - 1.0).abs() < 1e-6, "{v:?} is not unit");
    }
    // Each point's nearest neighbour lies near the spacing of an even
    // hexagonal spread of 64 points: neither clumped nor with holes.
    let ideal = ideal_spacing(n);
    let nearest: Vec<f64> = (0..n)
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| angle(d[i], d[j]))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let lo = nearest.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = nearest.iter().copied().fold(0.0, f64::max);
    assert!(lo > 0.7 * ideal, "closest pair {lo} rad, ideal {ideal}");
    assert!(hi < 1.3 * ideal, "loneliest point {hi} rad, ideal {ideal}");
    // Both hemispheres of every axis hold half the points.
    for k in 0..3 {
        let above = d.iter().filter(|v| v[k] > 0.0).count();
        assert!((24..=40).contains(&above), "axis {k}: {above} of 64 above");
    }
}

#[test]
fn view_names_sort_in_view_order() {
    let (_, mesh) = shapecue::mesh::Generated::Sphere.mesh(500);
    let views = fibonacci_views(120, CameraDefaults::default()).unwrap();
    let opts = LinesPictureOptions {
        image: false,
        svg: true,
        ..Default::default()
    };
    let mut scene = lines_views_scene(std::sync::Arc::new(mesh), &opts, views);
    scene.prefix = "ball".into();
    let (images, report) = output_paths(&scene, &[0], Path::new("out"));
    assert_eq!(images.len(), 120);
    assert_eq!(images[7].2, Path::new("out/ball_f0000_v007.svg"));
    assert_eq!(images[119].2, Path::new("out/ball_f0000_v119.svg"));
    assert_eq!(report, Path::new("out/ball_report.json"));
    assert!(fibonacci_views(0, CameraDefaults::default()).is_err());
    assert!(fibonacci_views(10_001, CameraDefaults::default()).is_err());
}

#[test]
fn camera_file_parses_with_defaults_and_ortho_heights() {
    let text = r#"{"cameras": [
        {"eye": [0, 0, 3], "target": [0, 0, 0]},
        {"eye": [4, 0, 0], "target": [1, 0, 0], "up": [0, 0, 1], "fov": 30},
        {"eye": [0, 2, 2], "target": [0, 0, 0], "ortho": 2.5}
    ]}"#;
    let defaults = CameraDefaults {
        fov: 35.0,
        ortho: false,
    };
    let v = parse_camera_file(text, "cams.json", defaults).unwrap();
    assert_eq!(v.len(), 3);
    let look = |i: usize| match &v[i].kind {
        CameraKind::LookAt { eye, target } => (*eye, target.unwrap()),
        k => panic!("camera {i} is {k:?}"),
    };
    assert_eq!(look(0), ([0.0, 0.0, 3.0], [0.0, 0.0, 0.0]));
    assert_eq!((v[0].fov, v[0].ortho, v[0].up), (35.0, false, None));
    assert_eq!(look(1), ([4.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    assert_eq!((v[1].fov, v[1].up), (30.0, Some([0.0, 0.0, 1.0])));
    // An orthographic view shows the height the perspective view of its
    // fov shows at the target: 2.5 at a distance of √8.
    assert!(v[2].ortho);
    let shown = 2.0 * 8f32.sqrt() * (0.5 * v[2].fov.to_radians()).tan();
    assert!((shown - 2.5).abs() < 1e-5, "{shown}");
}

#[test]
fn bad_camera_files_name_the_file_and_the_camera() {
    let cam = r#"{"eye": [0, 0, 3], "target": [0, 0, 0]}"#;
    let cases: Vec<(String, &[&str])> = vec![
        ("{\"cameras\": [".into(), &["cams.json", "not JSON"]),
        ("[1, 2]".into(), &["cams.json", "\"cameras\" list"]),
        ("{\"cameras\": []}".into(), &["cams.json", "empty"]),
        (
            format!(r#"{{"cameras": [{cam}, {{"eye": [1, 1, 1], "target": [1, 1, 1]}}]}}"#),
            &["cams.json", "camera 1", "eye and target are at one point"],
        ),
        (
            format!(r#"{{"cameras": [{cam}, {cam}, {{"eye": [0, 0, 3]}}]}}"#),
            &["camera 2", "target"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 1e39], "target": [0, 0, 0]}]}"#.into(),
            &["camera 0", "eye has 1e+39", "single precision"],
        ),
        (
            format!(
                r#"{{"cameras": [{cam}, {{"eye": [0, 3, 0], "target": [0, 0, 0], "up": [0, 2, 0]}}]}}"#
            ),
            &["camera 1", "up lies along the view"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 0, 0]}]}"#.into(),
            &["camera 0", "up is zero"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "fov": 30, "ortho": 2}]}"#
                .into(),
            &["camera 0", "not both"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "ortho": 0}]}"#.into(),
            &["camera 0", "positive height"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "fov": 180}]}"#.into(),
            &["camera 0", "fov 180"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "zoom": 2}]}"#.into(),
            &[
                "camera 0",
                "unknown key \"zoom\"",
                "eye, target, up, fov and ortho",
            ],
        ),
        (
            r#"{"cameras": [{"eye": 0.0, "target": [0, 0, 0]}]}"#.into(),
            &["camera 0", "eye must be three numbers [x, y, z], not 0.0"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "fov": "wide"}]}"#.into(),
            &["camera 0", "fov must be a number, not \"wide\""],
        ),
        (
            r#"{"cameras": [3]}"#.into(),
            &["camera 0", "3 is not a camera"],
        ),
        (
            format!(r#"{{"cameras": [{}]}}"#, vec![cam; 10_001].join(",")),
            &["10001 cameras", "10000"],
        ),
    ];
    for (text, words) in cases {
        let e = parse_camera_file(&text, "cams.json", CameraDefaults::default())
            .expect_err(&text[..text.len().min(120)])
            .to_string();
        for w in words {
            assert!(e.contains(w), "{w:?} not in {e:?}");
        }
        assert!(
            !e.contains("Some(") && !e.contains("[f32") && !e.contains('`'),
            "{e}"
        );
        assert!(!e.contains("cameras: cameras"), "{e}");
    }
}

#[test]
fn views_write_svgs_segments_and_manifest_with_no_gl() {
    let d = scratch("views-spot");
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let run = no_gl(
        &d,
        &["lines", &spot(), "--views", "8", "--out", o, "--segments"],
    );
    ok(&run);
    let manifest = read_json(&out.join("manifest.json"));
    let views = manifest["views"].as_array().unwrap();
    assert_eq!(views.len(), 8);
    let mut eyes = Vec::new();
    for (i, v) in views.iter().enumerate() {
        assert_eq!(v["index"].as_u64(), Some(i as u64));
        let files: Vec<&str> = (v["files"].as_array().unwrap().iter())
            .map(|f| f["name"].as_str().unwrap())
            .collect();
        let svg = format!("spot_f0000_v{i:02}.svg");
        let seg = format!("spot_f0000_v{i:02}_segments.json");
        assert_eq!(files, [svg.as_str(), seg.as_str()]);
        assert!(
            std::fs::read_to_string(out.join(&svg))
                .unwrap()
                .contains("<svg")
        );
        let doc = read_json(&out.join(&seg));
        assert_eq!(doc["visibility"], "exact");
        let pieces = doc["segments"].as_array().unwrap();
        assert!(!pieces.is_empty(), "view {i} found no lines");
        for key in ["family", "strength", "a", "b", "visible", "faces", "chain"] {
            assert!(
                pieces[0].get(key).is_some(),
                "no {key} in view {i}'s segments"
            );
        }
        assert!(!doc["chains"].as_array().unwrap().is_empty());
        // Every fitted camera looks at the mesh's centre from its own side.
        assert_eq!(v["camera"]["target"], views[0]["camera"]["target"]);
        eyes.push(v["camera"]["eye"].clone());
    }
    for i in 0..8 {
        for j in 0..i {
            assert_ne!(eyes[i], eyes[j], "views {i} and {j} share an eye");
        }
    }
    let svgs = (std::fs::read_dir(&out).unwrap())
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "svg")
        })
        .count();
    assert_eq!(svgs, 8);
    assert!(
        !out.join("spot_f0000_v00.png").exists(),
        "no PNG without --png"
    );
    let t = &manifest["timing"];
    assert!(t["pose_ms"].as_f64().unwrap() > 0.0 && t["views_ms"].as_f64().unwrap() > 0.0);
    assert!(t["views_per_second"].as_f64().unwrap() > 0.0);
    assert_eq!(manifest["options"]["views"], 8);
    passes_ran_once_per_pose_and_view(&read_json(&out.join("spot_report.json")), 8);
}

/// One run: the curvature and the other pose passes once, the view passes
/// once per view, and no frame drawn.
fn passes_ran_once_per_pose_and_view(report: &Value, views: u64) {
    assert_eq!(report["views"], views);
    let runs = |pass: &str| {
        (report["passes"].as_array().unwrap().iter())
            .find(|p| p["pass"] == pass)
            .unwrap_or_else(|| panic!("no {pass} pass in {report}"))["runs"]
            .as_u64()
            .unwrap()
    };
    for pass in ["one_rings", "vertex_normals", "curvature", "dcurv", "bvh"] {
        assert_eq!(runs(pass), 1, "{pass}");
    }
    for pass in ["contours", "suggestive_contours", "visibility", "svg"] {
        assert_eq!(runs(pass), views, "{pass}");
    }
    assert!(
        (report["passes"].as_array().unwrap().iter()).all(|p| p["pass"] != "render"),
        "no frame is drawn for SVG alone"
    );
}

#[test]
fn camera_file_views_have_its_eyes() {
    let d = scratch("views-cameras");
    let cams = d.join("cams.json");
    std::fs::write(
        &cams,
        r#"{"cameras": [
            {"eye": [0.25, 0.5, 3], "target": [0, 0.1, 0.2]},
            {"eye": [3, 1, 0.5], "target": [0, 0.1, 0.2], "up": [0, 1, 0], "ortho": 2.5}
        ]}"#,
    )
    .unwrap();
    let out = d.join("out");
    let args = [
        "lines",
        &spot(),
        "--cameras",
        cams.to_str().unwrap(),
        "--out",
    ];
    let run = no_gl(&d, &[&args[..], &[out.to_str().unwrap()]].concat());
    ok(&run);
    let manifest = read_json(&out.join("manifest.json"));
    let views = manifest["views"].as_array().unwrap();
    assert_eq!(views.len(), 2);
    let xyz = |v: &Value| -> Vec<f64> {
        (v.as_array().unwrap().iter())
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    assert_eq!(xyz(&views[0]["camera"]["eye"]), [0.25, 0.5, 3.0]);
    assert_eq!(xyz(&views[1]["camera"]["eye"]), [3.0, 1.0, 0.5]);
    assert!(views[0]["camera"]["ortho"].is_null());
    let h = views[1]["camera"]["ortho"].as_f64().unwrap();
    assert!((h - 2.5).abs() < 1e-4, "{h}");
    assert!(out.join("spot_f0000_v01.svg").exists());
    assert!(!out.join("spot_f0000_v00_segments.json").exists());
}

#[test]
fn existing_outputs_are_refused_without_force() {
    let d = scratch("views-force");
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let args = ["lines", &spot(), "--views", "2", "--out", o, "--segments"];
    ok(&no_gl(&d, &args));
    let manifest = out.join("manifest.json");
    let before = std::fs::read_to_string(&manifest).unwrap();
    failed_with(&no_gl(&d, &args), &["exists", "--force"]);
    // The manifest and the segments are checked as the images are.
    for name in [
        "spot_f0000_v00.svg",
        "spot_f0000_v01.svg",
        "spot_report.json",
    ] {
        std::fs::remove_file(out.join(name)).unwrap();
    }
    failed_with(&no_gl(&d, &args), &["exists", "--force"]);
    std::fs::remove_file(&manifest).unwrap();
    failed_with(&no_gl(&d, &args), &["_segments.json exists"]);
    assert!(!manifest.exists(), "a refused run writes no manifest");
    std::fs::write(&manifest, &before).unwrap();
    ok(&no_gl(&d, &[&args[..], &["--force"]].concat()));
    assert!(out.join("spot_f0000_v01.svg").exists());
}

#[test]
fn a_failed_run_leaves_no_manifest_nor_folder() {
    // A PNG needs OpenGL, which this run cannot load: the run fails before
    // any view, and what it made goes again.
    let d = scratch("views-fail");
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let run = no_gl(&d, &["lines", &spot(), "--views", "2", "--out", o, "--png"]);
    assert!(!run.status.success());
    assert!(!out.join("manifest.json").exists());
    assert!(!out.exists(), "the folder the run made is removed");
}

#[test]
fn one_picture_and_many_views_are_exclusive() {
    let d = scratch("views-flags");
    let svg = d.join("one.svg");
    let out = d.join("out");
    let (s, o) = (svg.to_str().unwrap(), out.to_str().unwrap());
    let spot = spot();
    failed_with(
        &no_gl(&d, &["lines", &spot, "--views", "4", "--out", o, "-o", s]),
        &["-o", "--views"],
    );
    failed_with(
        &no_gl(&d, &["lines", &spot, "--views", "4", "-o", s]),
        &["-o"],
    );
    failed_with(
        &no_gl(&d, &["lines", &spot, "--views", "4"]),
        &["--out DIR"],
    );
    failed_with(&no_gl(&d, &["lines", &spot, "--out", o]), &["--views N"]);
    failed_with(
        &no_gl(&d, &["lines", &spot, "--views", "0", "--out", o]),
        &["--views 0"],
    );
    let seg = ["lines", &spot, "--views", "2", "--out", o, "--segments", s];
    failed_with(&no_gl(&d, &seg), &["--segments", "alone"]);
    assert!(!svg.exists() && !out.exists());
    // --explain prints the plan with its run counts and writes nothing.
    let ex = no_gl(
        &d,
        &["lines", &spot, "--views", "5", "--out", o, "--explain"],
    );
    ok(&ex);
    let text = String::from_utf8_lossy(&ex.stdout);
    assert!(text.contains("1 frame(s) × 5 view(s)"), "{text}");
    let runs = |pass: &str| -> String {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(pass))
            .unwrap();
        line.split_whitespace().nth(2).unwrap().to_string()
    };
    assert_eq!(runs("curvature"), "1");
    assert_eq!(runs("contours"), "5");
    assert!(!out.exists());
}

/// The `.npy` header of `name` in an NPZ's bytes: its dtype and shape text.
fn npy_header(npz: &[u8], name: &str) -> String {
    let entry = format!("{name}.npy");
    let at = (npz.windows(entry.len()))
        .position(|w| w == entry.as_bytes())
        .unwrap_or_else(|| panic!("no {entry}"));
    let magic = b"\x93NUMPY";
    let start = at
        + (npz[at..].windows(magic.len()))
            .position(|w| w == magic)
            .expect("an .npy after its name");
    let head = &npz[start..(start + 200).min(npz.len())];
    String::from_utf8_lossy(head).into_owned()
}

#[test]
fn npz_segments_hold_the_pieces_of_the_json_document() {
    let d = scratch("views-npz");
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let args = [
        "lines",
        &spot(),
        "--views",
        "2",
        "--out",
        o,
        "--segments",
        "--npz",
    ];
    ok(&no_gl(&d, &args));
    let manifest = read_json(&out.join("manifest.json"));
    assert_eq!(manifest["family_codes"]["0"], "contours");
    for i in 0..2 {
        let npz = std::fs::read(out.join(format!("spot_f0000_v{i:02}_segments.npz"))).unwrap();
        let doc = read_json(&out.join(format!("spot_f0000_v{i:02}_segments.json")));
        let n = doc["segments"].as_array().unwrap().len();
        assert!(n > 0);
        assert_eq!(&npz[..4], b"PK\x03\x04", "a zip");
        let a = npy_header(&npz, "a");
        assert!(
            a.contains("'<f4'") && a.contains(&format!("({n}, 3)")),
            "{a}"
        );
        let faces = npy_header(&npz, "faces");
        assert!(
            faces.contains("'<i8'") && faces.contains(&format!("({n}, 4)")),
            "{faces}"
        );
        for name in ["family", "strength", "visible", "chain"] {
            let h = npy_header(&npz, name);
            assert!(h.contains(&format!("({n},)")), "{name}: {h}");
        }
        let files = &manifest["views"][i]["files"];
        assert_eq!(files[2]["name"], format!("spot_f0000_v{i:02}_segments.npz"));
    }
    // One picture has no --npz.
    let svg = d.join("one.svg");
    let one = no_gl(
        &d,
        &["lines", &spot(), "-o", svg.to_str().unwrap(), "--npz"],
    );
    failed_with(&one, &["--npz", "--views"]);
    // The pieces come from exact visibility.
    let o = d.join("depth");
    let depth = no_gl(
        &d,
        &[
            "lines",
            &spot(),
            "--views",
            "2",
            "--out",
            o.to_str().unwrap(),
            "--npz",
            "--visibility",
            "depth",
        ],
    );
    failed_with(&depth, &["--npz", "exact visibility"]);
    assert!(!o.exists());
}
