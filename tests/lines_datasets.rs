//! Line datasets a builder can trust (`shapecue lines --views N --out DIR`):
//! the same bytes on every run, a manifest that says what made the run and
//! names every file by its SHA-256, one run per folder (`--force` removes
//! the earlier run's files, and only those), `--resume` after an interrupt
//! giving the files of an uninterrupted run, inputs never overwritten, and
//! the limits and messages of cameras, degenerate faces and scenes.

mod common;

use common::{assert_succeeded, cli_no_gl, scratch, shared};
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

const EVERY_FAMILY: &str = "contours,suggestive,ridges,valleys,apparent-ridges,\
suggestive-highlights,principal-highlights,isophotes,k-zero,h-zero,dwkr-zero,boundaries";

fn spot() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/spot.obj")
}

fn no_gl(dir: &Path, args: &[&str]) -> Output {
    cli_no_gl(dir).args(args).output().unwrap()
}

fn failed_with(out: &Output, words: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "should have failed: {err}");
    for w in words {
        assert!(err.contains(w), "{w:?} not in: {err}");
    }
    assert!(!err.contains("Some(") && !err.contains("Err("), "{err}");
    err
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn sha256(p: &Path) -> String {
    let h = Sha256::digest(std::fs::read(p).unwrap());
    h.iter().map(|b| format!("{b:02x}")).collect()
}

/// Every file of a run's folder by name with its SHA-256, but the report
/// (its pass times) and the manifest, which is returned less its timing.
fn hashes(dir: &Path) -> (BTreeMap<String, String>, Value) {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if name == "manifest.json" || name.ends_with("_report.json") {
            continue;
        }
        assert!(!name.starts_with('.'), "a temporary file is left: {name}");
        out.insert(name, sha256(&p));
    }
    let mut m = read_json(&dir.join("manifest.json"));
    m.as_object_mut().unwrap().remove("timing");
    (out, m)
}

/// The mesh whose rows changed order from run to run (the Stanford
/// bunny, with every family), or Spot where the shared data is absent.
fn busy_mesh() -> (PathBuf, &'static str) {
    match shared("meshes/stanford-bunny.obj") {
        Some(p) => (p, EVERY_FAMILY),
        None => (spot(), EVERY_FAMILY),
    }
}

#[test]
fn three_runs_write_the_same_bytes() {
    let d = scratch("same-bytes");
    let (mesh, lines) = busy_mesh();
    let m = mesh.to_str().unwrap();
    let mut runs = Vec::new();
    for k in 0..3 {
        let out = d.join(format!("run{k}"));
        let o = out.to_str().unwrap();
        let args = [
            "lines",
            m,
            "--views",
            "3",
            "--lines",
            lines,
            "--out",
            o,
            "--npz",
            "--segments",
            "--fields",
        ];
        assert_succeeded(&no_gl(&d, &args));
        runs.push(hashes(&out));
    }
    let (files, manifest) = &runs[0];
    assert_eq!(
        files.len(),
        3 * 4,
        "an SVG, segments, NPZ and fields per view"
    );
    for (k, r) in runs.iter().enumerate().skip(1) {
        for (name, h) in files {
            assert_eq!(r.0.get(name), Some(h), "run {k} wrote another {name}");
        }
        assert_eq!(
            &r.1, manifest,
            "run {k}'s manifest differs (less its timing)"
        );
    }
    // The manifest names each file with its SHA-256, and what made the run.
    for v in manifest["views"].as_array().unwrap() {
        for f in v["files"].as_array().unwrap() {
            let name = f["name"].as_str().unwrap();
            assert_eq!(f["sha256"].as_str(), files.get(name).map(String::as_str));
        }
    }
    assert_eq!(manifest["mesh_sha256"].as_str().unwrap(), sha256(&mesh));
    assert_eq!(manifest["shapecue"], env!("CARGO_PKG_VERSION"));
    assert_eq!(manifest["complete"], true);
    assert_eq!(manifest["options"]["lines"].as_array().unwrap().len(), 12);
    // Every NPZ of pieces names its family codes.
    let npz = std::fs::read(
        d.join("run0")
            .join(files.keys().find(|n| n.ends_with("_segments.npz")).unwrap()),
    )
    .unwrap();
    for entry in ["family_codes.npy", "family_names.npy", "<U24"] {
        assert!(
            npz.windows(entry.len()).any(|w| w == entry.as_bytes()),
            "{entry}"
        );
    }
    // No polyline of one point (a line shorter than a hundredth of a pixel
    // draws nothing).
    for name in files.keys().filter(|n| n.ends_with(".svg")) {
        let svg = std::fs::read_to_string(d.join("run0").join(name)).unwrap();
        for pl in svg.split("<polyline points=\"").skip(1) {
            let pts = pl.split('"').next().unwrap();
            assert!(pts.contains(' '), "{name}: a one-point polyline {pts}");
        }
    }
}

/// Runs `args` and interrupts it (SIGINT) after `ms` milliseconds, if it
/// is still running then.
fn interrupted(dir: &Path, args: &[&str], ms: u64) {
    let mut child = cli_no_gl(dir)
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let t = std::time::Instant::now();
    while t.elapsed().as_millis() < u128::from(ms) {
        if child.try_wait().unwrap().is_some() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    // SAFETY: signals a child this test spawned and still waits for.
    unsafe {
        libc::kill(child.id() as i32, libc::SIGINT);
    }
    let out = child.wait_with_output().unwrap();
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--resume"),
            "the interrupt says how to go on: {err}"
        );
    }
}

/// Runs `shapecue` with `args` then `extra` to its end, or interrupted
/// after `ms` milliseconds.
fn call(dir: &Path, args: &[String], extra: &[&str], ms: Option<u64>) {
    let mut a: Vec<&str> = args.iter().map(String::as_str).collect();
    a.extend_from_slice(extra);
    match ms {
        Some(ms) => interrupted(dir, &a, ms),
        None => assert_succeeded(&no_gl(dir, &a)),
    }
}

#[test]
fn a_run_interrupted_at_random_points_and_resumed_writes_the_uninterrupted_files() {
    let d = scratch("resume");
    let m = spot();
    let args = |out: &Path| -> Vec<String> {
        [
            "lines",
            m.to_str().unwrap(),
            "--views",
            "24",
            "--lines",
            EVERY_FAMILY,
            "--out",
            out.to_str().unwrap(),
            "--npz",
            "--segments",
        ]
        .map(String::from)
        .to_vec()
    };
    let whole = d.join("whole");
    call(&d, &args(&whole), &[], None);
    let want = hashes(&whole);
    // Interrupts at points spread over a run (the kernels' build, the
    // pose, the views; the seed varies them from one test run to the
    // next), each followed by a --resume that is interrupted in turn, then
    // one that finishes.
    let seed = u64::from(std::process::id());
    let delays = common::random(3, 4000, seed);
    for (k, &first) in delays.iter().enumerate() {
        let first = u64::from(first) + 300;
        let out = d.join(format!("cut{k}"));
        let a = args(&out);
        call(&d, &a, &[], Some(first));
        if out.join("manifest.json").exists() {
            call(&d, &a, &["--resume"], Some(first / 2 + 300));
            call(&d, &a, &["--resume"], None);
        } else {
            // Interrupted before the run began: nothing to continue.
            assert!(!out.exists() || std::fs::read_dir(&out).unwrap().count() == 0);
            call(&d, &a, &[], None);
        }
        let got = hashes(&out);
        assert_eq!(got.0, want.0, "interrupted at {first} ms");
        assert_eq!(got.1, want.1, "interrupted at {first} ms: the manifest");
    }
}

#[test]
fn resume_refuses_another_run_and_a_folder_without_one() {
    let d = scratch("resume-refusals");
    let m = spot();
    let m = m.to_str().unwrap();
    let out = d.join("out");
    let o = out.to_str().unwrap();
    let base = ["lines", m, "--views", "2", "--out", o];
    failed_with(
        &no_gl(&d, &[&base[..], &["--resume"]].concat()),
        &["--resume", "no manifest.json"],
    );
    assert_succeeded(&no_gl(&d, &base));
    // The same run: nothing to compute.
    let again = no_gl(&d, &[&base[..], &["--resume"]].concat());
    assert_succeeded(&again);
    assert!(String::from_utf8_lossy(&again.stdout).contains("0 computed, 2 kept"));
    failed_with(
        &no_gl(
            &d,
            &[&base[..], &["--resume", "--sc-threshold", "0.02"]].concat(),
        ),
        &["--resume", "set of options", "sc_threshold"],
    );
    let more = ["lines", m, "--views", "3", "--out", o, "--resume"];
    failed_with(&no_gl(&d, &more), &["--resume", "options"]);
    // A view whose file changed is computed again.
    let svg = out.join("spot_f0000_v01.svg");
    let before = std::fs::read(&svg).unwrap();
    std::fs::write(&svg, "<svg/>").unwrap();
    let again = no_gl(&d, &[&base[..], &["--resume"]].concat());
    assert_succeeded(&again);
    assert!(String::from_utf8_lossy(&again.stdout).contains("1 computed, 1 kept"));
    assert_eq!(std::fs::read(&svg).unwrap(), before);
    // Without --resume or --force, an earlier run is refused, saying both.
    failed_with(&no_gl(&d, &base), &["exists", "--resume", "--force"]);
    failed_with(
        &no_gl(&d, &[&base[..], &["--resume", "--force"]].concat()),
        &["one or the other"],
    );
}

#[test]
fn force_replaces_the_earlier_run_and_only_its_files() {
    let d = scratch("force-stale");
    let m = spot();
    let m = m.to_str().unwrap();
    let out = d.join("out");
    let o = out.to_str().unwrap();
    assert_succeeded(&no_gl(
        &d,
        &["lines", m, "--views", "8", "--out", o, "--segments"],
    ));
    let mine = out.join("notes.txt");
    std::fs::write(&mine, "mine").unwrap();
    assert_succeeded(&no_gl(
        &d,
        &["lines", m, "--views", "4", "--out", o, "--force"],
    ));
    for v in 0..8 {
        let svg = out.join(format!("spot_f0000_v{v:02}.svg"));
        let seg = out.join(format!("spot_f0000_v{v:02}_segments.json"));
        assert_eq!(svg.exists(), v < 4, "view {v}'s SVG");
        assert!(!seg.exists(), "view {v}'s segments are of the earlier run");
    }
    assert_eq!(
        std::fs::read_to_string(&mine).unwrap(),
        "mine",
        "not the run's file"
    );
    let manifest = read_json(&out.join("manifest.json"));
    assert_eq!(manifest["views"].as_array().unwrap().len(), 4);
    assert_eq!(manifest["options"]["views"], 4);
    // The report names the curvature scheme that ran (gather, the default).
    let report = read_json(&out.join("spot_report.json"));
    let curvature = (report["passes"].as_array().unwrap().iter())
        .find(|p| p["pass"] == "curvature")
        .unwrap();
    let how = curvature["how"].as_str().unwrap();
    assert!(
        how.contains("gather accumulation") && how.contains("f32"),
        "{how}"
    );
}

#[test]
fn a_camera_file_named_like_an_output_survives_force() {
    let d = scratch("camera-input");
    let out = d.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let text = r#"{"cameras": [{"eye": [0, 0.5, 3], "target": [0, 0.5, 0]}]}"#;
    let m = spot();
    for name in [
        "manifest.json",
        "spot_report.json",
        "spot_f0000_v00_segments.json",
    ] {
        let cams = out.join(name);
        std::fs::write(&cams, text).unwrap();
        let args = [
            "lines",
            m.to_str().unwrap(),
            "--cameras",
            cams.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--segments",
            "--force",
        ];
        failed_with(&no_gl(&d, &args), &["input", "never overwritten"]);
        assert_eq!(std::fs::read_to_string(&cams).unwrap(), text, "{name}");
        std::fs::remove_file(&cams).unwrap();
    }
}

#[test]
fn fields_of_view_and_camera_values_are_refused_by_name() {
    let d = scratch("camera-limits");
    let m = spot();
    let m = m.to_str().unwrap();
    let svg = d.join("x.svg");
    for fov in ["1e-30", "179.9999", "0"] {
        let e = failed_with(
            &no_gl(&d, &["lines", m, "--fov", fov, "-o", svg.to_str().unwrap()]),
            &["--fov", "outside [0.01, 170]"],
        );
        assert!(!e.contains("inf"), "{e}");
    }
    let cams = d.join("cams.json");
    let out = d.join("out");
    let cases: [(&str, &[&str]); 4] = [
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0]}, {"eye": [0, 0, 1e30], "target": [0, 0, 0]}]}"#,
            &["cams.json", "camera 1", "eye has 1e+30"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "ortho": 1e300}]}"#,
            &["cams.json", "camera 0", "ortho has 1e+300"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "fov": 179.9999}]}"#,
            &["cams.json", "camera 0", "fov 179.9999"],
        ),
        (
            r#"{"cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "ortho": 1e-9}]}"#,
            &[
                "cams.json",
                "camera 0",
                "ortho 0.000000001",
                "field of view",
            ],
        ),
    ];
    for (text, words) in cases {
        std::fs::write(&cams, text).unwrap();
        let args = [
            "lines",
            m,
            "--cameras",
            cams.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        let e = failed_with(&no_gl(&d, &args), words);
        assert!(!e.contains(" inf") && !e.contains("NaN"), "{e}");
        assert!(!out.exists(), "a refused run makes no folder");
    }
    // A file far larger than any camera set is refused before it is read.
    let big = d.join("big.json");
    let f = std::fs::File::create(&big).unwrap();
    f.set_len(64 << 20).unwrap();
    let args = [
        "lines",
        m,
        "--cameras",
        big.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    failed_with(
        &no_gl(&d, &args),
        &["big.json", "67108864 bytes", "10000 cameras"],
    );
}

/// An icosphere (642 vertices) as OBJ text, with `extra` faces after its
/// own (1-based corner triples).
fn icosphere_obj(extra: impl Fn(&[[u32; 3]]) -> Vec<[u32; 3]>) -> String {
    let m = shapecue::mesh::icosphere(1.0, 3);
    let mut s = String::new();
    for p in &m.positions {
        s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    let faces: Vec<[u32; 3]> = m.faces.iter().map(|f| f.map(|v| v + 1)).collect();
    for f in faces.iter().chain(extra(&faces).iter()) {
        s.push_str(&format!("f {} {} {}\n", f[0], f[1], f[2]));
    }
    s
}

/// The contour pieces of a mesh file seen from one camera: pieces (a, b,
/// face, faces) and the number of visible contour chains.
fn contour_pieces(d: &Path, obj: &str, tag: &str) -> (Vec<Value>, usize) {
    let mesh = d.join(format!("{tag}.obj"));
    std::fs::write(&mesh, obj).unwrap();
    let seg = d.join(format!("{tag}.json"));
    let svg = d.join(format!("{tag}.svg"));
    let args = [
        "lines",
        mesh.to_str().unwrap(),
        "--lines",
        "contours",
        "--eye",
        "0.3,0.2,3",
        "--segments",
        seg.to_str().unwrap(),
        "-o",
        svg.to_str().unwrap(),
    ];
    assert_succeeded(&no_gl(d, &args));
    let doc = read_json(&seg);
    let chains = (doc["chains"].as_array().unwrap().iter())
        .filter(|c| c["visible"] == true)
        .count();
    (doc["segments"].as_array().unwrap().clone(), chains)
}

#[test]
fn faces_without_area_and_repeated_faces_change_no_line() {
    let d = scratch("degenerate");
    let (clean, chains) = contour_pieces(&d, &icosphere_obj(|_| vec![]), "clean");
    assert_eq!(chains, 1, "the sphere's contour is one closed chain");
    // A face with a repeated corner beside every face (`f a a b`): no area,
    // so no line, no provenance, no normal.
    let (degen, degen_chains) = contour_pieces(
        &d,
        &icosphere_obj(|f| f.iter().map(|t| [t[0], t[0], t[1]]).collect()),
        "repeated-vertex",
    );
    let n_faces = shapecue::mesh::icosphere(1.0, 3).faces.len() as u64;
    let ends = |v: &[Value]| -> Vec<(String, String)> {
        let mut e: Vec<(String, String)> = (v.iter())
            .map(|p| (p["a"].to_string(), p["b"].to_string()))
            .collect();
        e.sort();
        e
    };
    assert_eq!(
        ends(&degen),
        ends(&clean),
        "the same pieces as the clean sphere"
    );
    assert_eq!(degen_chains, 1);
    for p in &degen {
        let face = p["face"].as_u64().unwrap();
        assert!(
            face < n_faces,
            "provenance from a face with area, not {face}"
        );
        let faces: Vec<u64> = (p["faces"].as_array().unwrap().iter())
            .map(|f| f.as_u64().unwrap())
            .collect();
        let mut unique = faces.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), faces.len(), "a face listed twice: {faces:?}");
        assert_ne!(p["a"], p["b"], "a piece of no length");
    }
    // Fifty faces given twice: their lines are not doubled, and the
    // contour stays one chain.
    let (dup, dup_chains) = contour_pieces(
        &d,
        &icosphere_obj(|f| f.iter().step_by(13).take(50).copied().collect()),
        "duplicates",
    );
    assert_eq!(dup_chains, 1, "duplicated faces break no chain");
    let mut seen = std::collections::HashSet::new();
    for p in &dup {
        assert!(
            seen.insert((p["a"].to_string(), p["b"].to_string())),
            "a doubled piece"
        );
    }
    assert!(dup.len().abs_diff(clean.len()) <= clean.len() / 10);
}

#[test]
fn a_scene_with_line_cues_refuses_f64_curvature_where_it_is_written() {
    let text = "[input]\ngenerate = \"torus\"\n[effects]\nshading = {}\nridges = {}\n\
                [curvature]\nprecision = \"f64\"\n";
    let e = shapecue::api::Scene::from_str(Path::new("torus.toml"), text)
        .unwrap_err()
        .to_string();
    for w in ["torus.toml", "line 7", "precision", "f32"] {
        assert!(e.contains(w), "{w:?} not in {e}");
    }
    // Curvature colours alone read the curvature back: f64 is theirs.
    let ok = "[input]\ngenerate = \"torus\"\n[effects]\ncurvature_colors = {}\n\
              [curvature]\nprecision = \"f64\"\n";
    assert!(shapecue::api::Scene::from_str(Path::new("torus.toml"), ok).is_ok());
}

#[test]
fn every_lane_count_draws_the_same_bytes() {
    use shapecue::spec::curvature::{Accumulate, Lanes};
    use shapecue::{LinesPictureOptions, lines_picture_on};
    let mesh = match shared("meshes/stanford-bunny.obj") {
        Some(p) => shapecue::mesh::load(&p, &Default::default()).unwrap(),
        None => shapecue::mesh::load(&spot(), &Default::default()).unwrap(),
    };
    let gpu = common::gpu();
    let d = scratch("lanes");
    let mut seen: Option<(Vec<u8>, String)> = None;
    for lanes in [1, 4, 16] {
        let mut o = LinesPictureOptions {
            svg: true,
            image: false,
            ..Default::default()
        };
        o.lines = o
            .lines
            .with_families(shapecue::spec::feature_lines::FamilySet::parse(EVERY_FAMILY).unwrap());
        o.setup.curvature.accumulate = Accumulate::Gather;
        o.setup.curvature.lanes = Lanes::Fixed(lanes);
        let pic = lines_picture_on(&gpu, &mesh, &o).unwrap();
        let npz = d.join(format!("{lanes}.npz"));
        let arrays = shapecue::api::segment_arrays(pic.visible.as_ref().unwrap(), &mesh);
        shapecue::export::npz::write_segments(&npz, &arrays).unwrap();
        let [w, h] = o.shot.size;
        let svg = shapecue::export::svg::svg_layers_text(pic.layers.as_ref().unwrap(), w, h);
        let now = (std::fs::read(&npz).unwrap(), svg);
        match &seen {
            None => seen = Some(now),
            Some(first) => {
                assert!(first.0 == now.0, "{lanes} lanes: another NPZ");
                assert!(first.1 == now.1, "{lanes} lanes: another SVG");
            }
        }
    }
}
